//! Materials as node graphs, compiled once into flat programs and evaluated per shading point
//! into closures (Cycles' SVM is the model).
//!
//! - [`graph`]: the graph as the scene file says it (Blender node types and socket identifiers).
//! - [`compile`]: graph → [`Program`], with Cycles' implicit conversions and closure weights.
//! - [`program`]: the operations and their evaluation; [`globals`]: what a shading point knows.
//! - [`closure`]: what a program produces; [`nodes`]: one file per node family; [`tex`]: the
//!   procedural textures' algorithms.
//! - [`preset`]: glTF metallic-roughness as a graph.

pub mod closure;
pub mod compile;
pub mod globals;
pub mod graph;
pub mod nodes;
pub mod preset;
pub mod program;
pub mod tex;

pub use closure::{Closure, ClosureKind, ClosureSet, Principled};
pub use compile::{CompileError, Compiled, compile};
pub use globals::{ShadeEnv, ShaderGlobals};
pub use graph::{Graph, Input, Node};
pub use program::{Program, Scratch};

use crate::scene::{Material, Texture};

/// The program of material `m`: its node graph if it has one (a graph that cannot be compiled
/// falls back to the glTF factors, with a warning), else the metallic-roughness preset.
pub fn material_program(m: &Material, textures: &[Texture]) -> Compiled {
    if let Some(g) = &m.graph {
        match compile(g, &m.name) {
            Ok(c) => return c,
            Err(CompileError(e)) => {
                let mut c = compile(&preset::metallic_roughness(m, textures), &m.name)
                    .expect("the preset graph compiles");
                c.warnings.insert(
                    0,
                    format!("{e}; the material renders with its glTF factors"),
                );
                return c;
            }
        }
    }
    compile(&preset::metallic_roughness(m, textures), &m.name).expect("the preset graph compiles")
}
