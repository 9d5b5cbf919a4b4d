//! Node families: each file compiles its nodes into operations and evaluates them.

pub mod bsdf;
pub mod convert;
pub mod image;
pub mod input;
pub mod vector;

use super::compile::{CompileError, NodeCx};

/// Compiles a non-shader node of type `kind`; `Ok(false)` when no family implements it.
pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    for family in [
        input::compile,
        image::compile,
        vector::compile,
        convert::compile,
    ] {
        if family(kind, cx)? {
            return Ok(true);
        }
    }
    Ok(false)
}
