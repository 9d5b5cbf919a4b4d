//! Materials as node graphs, compiled once into flat programs and evaluated per shading point
//! into closures (Cycles' SVM is the model).
//!
//! - [`graph`]: the graph as the scene file says it (Blender node types and socket identifiers).
//! - [`compile`]: graph → [`Program`], with Cycles' implicit conversions and closure weights.
//! - [`program`]: the operations and their evaluation; [`globals`]: what a shading point knows.
//! - [`closure`]: what a program produces; [`nodes`]: one file per node family; [`tex`]: the
//!   procedural textures' algorithms.
//! - [`preset`]: glTF metallic-roughness as a graph; [`sky`]: the Sky Texture's atmosphere.

pub mod closure;
pub mod compile;
pub mod globals;
pub mod graph;
pub mod nodes;
pub mod preset;
pub mod program;
pub mod sky;
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
    let mut c = compile(&preset::metallic_roughness(m, textures), &m.name)
        .expect("the preset graph compiles");
    c.program.medium =
        crate::medium::Medium::absorbing(m.volume.map_or(glam::Vec3::ZERO, |v| v.absorption()));
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec3};
    use serde_json::json;

    fn env() -> ShadeEnv<'static> {
        ShadeEnv {
            images: &[],
            textures: &[],
            camera_to_world: glam::Mat4::IDENTITY,
            window: &crate::camera::NO_WINDOW,
            tracer: None,
        }
    }

    /// Emission of `graph` at a point whose UV is `uv`.
    fn emission_at(graph: &Graph, uv: Vec2) -> Vec3 {
        let c = compile(graph, "m").unwrap();
        let g = ShaderGlobals::at(Vec3::ZERO, Vec3::Y, uv);
        let mut s = Scratch::default();
        c.program.eval(&g, &env(), &mut s).emission
    }

    fn graph(v: serde_json::Value) -> Graph {
        Graph::from_json(&v).unwrap()
    }

    #[test]
    fn math_chain_and_conversions_reach_the_emission() {
        // Emission colour = (u * 2 + 0.25), a float into a colour socket.
        let g = graph(json!({
            "nodes": [
                {"type": "ShaderNodeUVMap"},
                {"type": "ShaderNodeSeparateXYZ", "inputs": {"Vector": {"link": [0, "UV"]}}},
                {"type": "ShaderNodeMath", "props": {"operation": "MULTIPLY_ADD"},
                 "inputs": {"Value": {"link": [1, "X"]}, "Value_001": 2.0, "Value_002": 0.25}},
                {"type": "ShaderNodeEmission", "inputs": {"Color": {"link": [2, "Value"]}, "Strength": 1.0}}
            ],
            "surface": [3, "Emission"]
        }));
        let e = emission_at(&g, Vec2::new(0.5, 0.0));
        assert!((e - Vec3::splat(1.25)).abs().max_element() < 1e-6, "{e}");
        let e = emission_at(&g, Vec2::new(0.0, 0.0));
        assert!((e - Vec3::splat(0.25)).abs().max_element() < 1e-6, "{e}");
    }

    #[test]
    fn mix_shader_splits_weights_and_constant_programs_fold() {
        let g = graph(json!({
            "nodes": [
                {"type": "ShaderNodeBsdfDiffuse", "inputs": {"Color": [0.5, 0.5, 0.5, 1.0]}},
                {"type": "ShaderNodeEmission", "inputs": {"Color": [1.0, 2.0, 3.0, 1.0], "Strength": 2.0}},
                {"type": "ShaderNodeMixShader", "inputs": {"Fac": 0.25,
                    "Shader": {"link": [0, "BSDF"]}, "Shader_001": {"link": [1, "Emission"]}}}
            ],
            "surface": [2, "Shader"]
        }));
        let c = compile(&g, "m").unwrap();
        assert!(c.program.is_empty(), "a constant graph runs no operations");
        assert!(c.program.may_emit());
        let g0 = ShaderGlobals::at(Vec3::ZERO, Vec3::Y, Vec2::ZERO);
        let mut s = Scratch::default();
        let set = c.program.eval(&g0, &env(), &mut s);
        assert_eq!(set.len, 1);
        assert!((set.closures[0].weight - Vec3::splat(0.5 * 0.75)).length() < 1e-6);
        assert!((set.emission - Vec3::new(0.5, 1.0, 1.5)).length() < 1e-6);
    }

    #[test]
    fn cycles_are_errors_and_unknown_nodes_are_reported_and_muted() {
        let g = graph(json!({
            "nodes": [
                {"type": "ShaderNodeMath", "name": "a", "inputs": {"Value": {"link": [1, "Value"]}}},
                {"type": "ShaderNodeMath", "name": "b", "inputs": {"Value": {"link": [0, "Value"]}}},
                {"type": "ShaderNodeEmission", "inputs": {"Strength": {"link": [0, "Value"]}}}
            ],
            "surface": [2, "Emission"]
        }));
        let e = compile(&g, "loop").err().unwrap();
        assert!(e.0.contains("cycle") && e.0.contains("loop"), "{}", e.0);

        let g = graph(json!({
            "nodes": [
                {"type": "ShaderNodeTexSky", "name": "Sky", "props": {"sky_type": "HOSEK_WILKIE"},
                 "inputs": {}},
                {"type": "ShaderNodeFancy", "name": "Fancy", "inputs": {"Color": [0.2, 0.3, 0.4, 1.0]},
                 "internal_links": {"Color": "Color"}},
                {"type": "ShaderNodeEmission", "inputs": {"Color": {"link": [1, "Color"]},
                    "Strength": {"link": [0, "Color"]}}}
            ],
            "surface": [2, "Emission"]
        }));
        let c = compile(&g, "mat").unwrap();
        assert!(
            c.warnings
                .iter()
                .any(|w| w.contains("'Fancy'") && w.contains("'mat'"))
        );
        assert!(c.warnings.iter().any(|w| w.contains("'Sky'")));
        // Fancy passes its colour through; the sky (no internal link) reads as zero.
        let e = emission_at(&g, Vec2::ZERO);
        assert_eq!(e, Vec3::ZERO);
    }

    #[test]
    fn noise_fac_alone_skips_the_colour_and_colour_compiles_again() {
        let g = graph(json!({
            "nodes": [
                {"type": "ShaderNodeTexNoise", "inputs": {"Scale": 3.0}},
                {"type": "ShaderNodeCombineXYZ", "inputs": {"X": {"link": [0, "Fac"]}}},
                {"type": "ShaderNodeMix", "props": {"data_type": "RGBA", "blend_type": "ADD"},
                 "inputs": {"Factor_Float": 1.0, "A_Color": {"link": [1, "Vector"]},
                            "B_Color": {"link": [0, "Color"]}}},
                {"type": "ShaderNodeEmission", "inputs": {"Color": {"link": [2, "Result_Color"]}}}
            ],
            "surface": [3, "Emission"]
        }));
        let c = compile(&g, "m").unwrap();
        assert!(c.warnings.is_empty(), "{:?}", c.warnings);
        let e = emission_at(&g, Vec2::ZERO);
        // x = fac + colour.r, y and z = colour: all noise values in (0, 1].
        assert!(
            e.x > e.y.min(e.z) && e.min_element() > 0.0 && e.x < 2.0,
            "{e}"
        );
    }
}
