//! The glTF metallic-roughness material as a node graph: foreign glTF files and Blender
//! scenes take the same shading path.

use super::graph::{Graph, Node};
use crate::scene::{Material, TexRef, Texture};
use serde_json::json;

/// The graph of a glTF material: factors times textures into a Principled BSDF. `textures`
/// are the scene's textures (the `TexRef`s index them).
pub fn metallic_roughness(m: &Material, textures: &[Texture]) -> Graph {
    let mut g = Graph::default();
    let image = |g: &mut Graph, t: &TexRef, srgb: bool| -> Option<usize> {
        let tex = textures.get(t.texture)?;
        let uv = g.add(Node::new("TeselaGltfUv").prop("set", json!(t.texcoord)));
        let wrap = |w: crate::scene::Wrap| match w {
            crate::scene::Wrap::Repeat => "REPEAT",
            crate::scene::Wrap::MirroredRepeat => "MIRRORED_REPEAT",
            crate::scene::Wrap::ClampToEdge => "CLAMP_TO_EDGE",
        };
        let mut n = Node::new("ShaderNodeTexImage")
            .link("Vector", uv, "UV")
            .prop("gltf_uv", json!(true))
            .prop("wrap_s", json!(wrap(tex.wrap_s)))
            .prop("wrap_t", json!(wrap(tex.wrap_t)))
            .prop(
                "interpolation",
                json!(if tex.nearest { "Closest" } else { "Linear" }),
            )
            .prop("colorspace", json!(if srgb { "sRGB" } else { "Non-Color" }));
        n.image = Some(tex.image);
        Some(g.add(n))
    };
    let mul_color = |g: &mut Graph, a: [f32; 3], img: usize| -> usize {
        g.add(
            Node::new("TeselaMultiply")
                .with("A", &a)
                .link("B", img, "Color"),
        )
    };
    let mut principled = Node::new("ShaderNodeBsdfPrincipled")
        .prop("gltf", json!(true))
        .with("Metallic", &[m.metallic])
        .with("Roughness", &[m.roughness])
        .with("IOR", &[m.ior])
        .with("Transmission Weight", &[m.transmission])
        .with("Specular IOR Level", &[m.specular * 0.5])
        .with("Specular Tint", &m.specular_color.to_array());
    match m
        .base_color_texture
        .as_ref()
        .and_then(|t| image(&mut g, t, true))
    {
        Some(img) => {
            let c = mul_color(&mut g, m.base_color.to_array(), img);
            principled = principled.link("Base Color", c, "Color");
        }
        None => principled = principled.with("Base Color", &m.base_color.to_array()),
    }
    if let Some(img) = m
        .metallic_roughness_texture
        .as_ref()
        .and_then(|t| image(&mut g, t, false))
    {
        let sep = g.add(Node::new("ShaderNodeSeparateColor").link("Color", img, "Color"));
        let mul = |g: &mut Graph, a: f32, out: &str| {
            g.add(
                Node::new("TeselaMultiply")
                    .prop("float", json!(true))
                    .with("A", &[a])
                    .link("B", sep, out),
            )
        };
        let r = mul(&mut g, m.roughness, "Green");
        let mt = mul(&mut g, m.metallic, "Blue");
        principled = principled
            .link("Roughness", r, "Value")
            .link("Metallic", mt, "Value");
    }
    if m.emission.max_element() > 0.0 {
        principled = principled.with("Emission Strength", &[1.0]);
        match m
            .emission_texture
            .as_ref()
            .and_then(|t| image(&mut g, t, true))
        {
            Some(img) => {
                let c = mul_color(&mut g, m.emission.to_array(), img);
                principled = principled.link("Emission Color", c, "Color");
            }
            None => principled = principled.with("Emission Color", &m.emission.to_array()),
        }
    } else {
        principled = principled.with("Emission Strength", &[0.0]);
    }
    let p = g.add(principled);
    g.surface = Some((p, "BSDF".into()));
    g
}
