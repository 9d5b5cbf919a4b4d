//! Node families: each file compiles its nodes into operations and evaluates them.

pub mod ao;
pub mod bevel;
pub mod bsdf;
pub mod bump;
pub mod color;
pub mod convert;
pub mod curves;
pub mod displacement;
pub mod environment;
pub mod image;
pub mod input;
pub mod light_falloff;
pub mod map_range;
pub mod math;
pub mod mix;
pub mod ramp;
pub mod sky;
pub mod texture;
pub mod transform;
pub mod utility;
pub mod vector;
pub mod vector_math;
pub mod wireframe;

use super::compile::{CompileError, NodeCx};

/// Compiles a non-shader node of type `kind`; `Ok(false)` when no family implements it.
pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    for family in [
        input::compile,
        image::compile,
        texture::compile,
        utility::compile,
        vector::compile,
        transform::compile,
        wireframe::compile,
        light_falloff::compile,
        ao::compile,
        bevel::compile,
        bump::compile,
        displacement::compile,
        convert::compile,
        environment::compile,
        sky::compile,
    ] {
        if family(kind, cx)? {
            return Ok(true);
        }
    }
    Ok(false)
}
