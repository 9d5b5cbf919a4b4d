//! The glTF metallic-roughness material as a node graph: foreign glTF files and Blender
//! scenes take the same shading path, Cycles' Principled BSDF, so a file renders as it does
//! imported into Blender and rendered by Cycles.
//!
//! Every factor multiplies its texture (glTF's rule), each texture reads its own `texCoord`
//! set through its `KHR_texture_transform`; the result feeds a Principled BSDF, the way
//! Blender's glTF importer builds it:
//! - base colour = factor × texture × COLOR_0 (when the primitive has one), alpha likewise;
//!   `alphaMode` OPAQUE ignores alpha, MASK turns it into exactly 0 or 1 at `alphaCutoff`,
//!   BLEND passes it on (the Principled `Alpha`);
//! - metallic = factor × B, roughness = factor × G of the metallic-roughness texture;
//! - `normalTexture` → a tangent-space normal map with glTF's `scale` → `Normal`;
//! - emission = factor × strength × texture; transmission = factor × R; specular level =
//!   ½ factor × A, specular tint = colour factor × texture;
//! - `KHR_materials_clearcoat` → `Coat Weight` (× R), `Coat Roughness` (× G), `Coat IOR` 1.5,
//!   `Coat Normal`; `KHR_materials_sheen` → `Sheen Weight` 1, `Sheen Tint` (× RGB),
//!   `Sheen Roughness` (× A); `KHR_materials_anisotropy` → `Anisotropic` (× B) and a `Tangent`
//!   turned by the rotation and the texture's RG direction.
//!
//! The occlusion texture is not part of the graph: a path tracer computes occlusion itself.

use super::graph::{Graph, Node};
use crate::scene::{AlphaMode, Material, TexRef, Texture};
use serde_json::json;

/// A value feeding a socket: a constant or a node's output.
#[derive(Clone)]
enum Val {
    Const(Vec<f32>),
    Link(usize, &'static str),
}

struct Builder<'a> {
    g: Graph,
    textures: &'a [Texture],
}

impl Builder<'_> {
    /// An Image Texture node reading `t` (its UV set, its transform); `None` for a texture
    /// index the scene does not have.
    fn image(&mut self, t: &TexRef, srgb: bool) -> Option<usize> {
        let tex = self.textures.get(t.texture)?;
        let mut uv = (
            self.g
                .add(Node::new("TeselaGltfUv").prop("set", json!(t.texcoord))),
            "UV",
        );
        if let Some(tr) = &t.transform {
            let n = Node::new("TeselaUvTransform")
                .prop("matrix", json!(tr.matrix()))
                .link("Vector", uv.0, uv.1);
            uv = (self.g.add(n), "Vector");
        }
        let wrap = |w: crate::scene::Wrap| match w {
            crate::scene::Wrap::Repeat => "REPEAT",
            crate::scene::Wrap::MirroredRepeat => "MIRRORED_REPEAT",
            crate::scene::Wrap::ClampToEdge => "CLAMP_TO_EDGE",
        };
        let mut n = Node::new("ShaderNodeTexImage")
            .link("Vector", uv.0, uv.1)
            .prop("gltf_uv", json!(true))
            .prop("wrap_s", json!(wrap(tex.wrap_s)))
            .prop("wrap_t", json!(wrap(tex.wrap_t)))
            .prop(
                "interpolation",
                json!(if tex.nearest { "Closest" } else { "Linear" }),
            )
            .prop("colorspace", json!(if srgb { "sRGB" } else { "Non-Color" }));
        n.image = Some(tex.image);
        Some(self.g.add(n))
    }

    /// One channel (`Red`, `Green`, `Blue`) of image node `img`.
    fn channel(&mut self, img: usize, which: &'static str) -> Val {
        let sep = self
            .g
            .add(Node::new("ShaderNodeSeparateColor").link("Color", img, "Color"));
        Val::Link(sep, which)
    }

    /// `a × b`, colours or floats; constants fold.
    fn mul(&mut self, a: Val, b: Val, float: bool) -> Val {
        match (a, b) {
            (Val::Const(x), Val::Const(y)) => {
                Val::Const(x.iter().zip(&y).map(|(x, y)| x * y).collect())
            }
            (a, b) => {
                let mut n = Node::new("TeselaMultiply");
                if float {
                    n = n.prop("float", json!(true));
                }
                for (id, v) in [("A", a), ("B", b)] {
                    n = match v {
                        Val::Const(c) => n.with(id, &c),
                        Val::Link(node, out) => n.link(id, node, out),
                    };
                }
                Val::Link(self.g.add(n), if float { "Value" } else { "Color" })
            }
        }
    }

    /// `factor × texture` (the texture's colour when `which` is `None`, else that channel or
    /// `Alpha`).
    fn factor_tex(
        &mut self,
        factor: &[f32],
        tex: Option<&TexRef>,
        srgb: bool,
        which: Option<&'static str>,
    ) -> Val {
        let Some(img) = tex.and_then(|t| self.image(t, srgb)) else {
            return Val::Const(factor.to_vec());
        };
        let v = match which {
            None => Val::Link(img, "Color"),
            Some("Alpha") => Val::Link(img, "Alpha"),
            Some(ch) => self.channel(img, ch),
        };
        self.mul(Val::Const(factor.to_vec()), v, which.is_some())
    }

    /// Base colour (factor × texture × COLOR_0) and, unless the material is opaque, alpha
    /// (likewise; MASK turns it into exactly 0 or 1 at the cutoff).
    fn base_color_and_alpha(&mut self, m: &Material) -> (Val, Option<Val>) {
        let base_img = m
            .base_color_texture
            .as_ref()
            .and_then(|t| self.image(t, true));
        let mut base = match base_img {
            Some(img) => self.mul(
                Val::Const(m.base_color.to_array().to_vec()),
                Val::Link(img, "Color"),
                false,
            ),
            None => Val::Const(m.base_color.to_array().to_vec()),
        };
        let vcol = m.vertex_color.then(|| {
            self.g
                .add(Node::new("ShaderNodeVertexColor").prop("layer_name", json!("")))
        });
        if let Some(vc) = vcol {
            base = self.mul(base, Val::Link(vc, "Color"), false);
        }
        if m.alpha_mode == AlphaMode::Opaque {
            return (base, None);
        }
        let mut alpha = Val::Const(vec![m.alpha]);
        if let Some(img) = base_img {
            alpha = self.mul(alpha, Val::Link(img, "Alpha"), true);
        }
        if let Some(vc) = vcol {
            alpha = self.mul(alpha, Val::Link(vc, "Alpha"), true);
        }
        if let AlphaMode::Mask { cutoff } = m.alpha_mode {
            alpha = match alpha {
                Val::Const(a) => Val::Const(vec![if a[0] >= cutoff { 1.0 } else { 0.0 }]),
                link => {
                    let n = set(
                        Node::new("TeselaAlphaCutoff").prop("cutoff", json!(cutoff)),
                        "Alpha",
                        link,
                    );
                    Val::Link(self.g.add(n), "Alpha")
                }
            };
        }
        (base, Some(alpha))
    }

    /// A tangent-space normal map of texture `t` with glTF's `scale`.
    fn normal_map(&mut self, t: &TexRef, scale: f32) -> Option<usize> {
        let img = self.image(t, false)?;
        Some(
            self.g.add(
                Node::new("TeselaGltfNormalMap")
                    .prop("scale", json!(scale))
                    .link("Color", img, "Color"),
            ),
        )
    }
}

fn set(n: Node, id: &str, v: Val) -> Node {
    match v {
        Val::Const(c) => n.with(id, &c),
        Val::Link(node, out) => n.link(id, node, out),
    }
}

/// The graph of a glTF material: factors times textures into a Principled BSDF. `textures`
/// are the scene's textures (the `TexRef`s index them).
pub fn metallic_roughness(m: &Material, textures: &[Texture]) -> Graph {
    let mut b = Builder {
        g: Graph::default(),
        textures,
    };
    if m.unlit {
        return unlit(b, m);
    }
    let mut principled = Node::new("ShaderNodeBsdfPrincipled")
        .with("Metallic", &[m.metallic])
        .with("Roughness", &[m.roughness])
        .with("IOR", &[m.ior])
        .with("Transmission Weight", &[m.transmission])
        .with("Specular IOR Level", &[m.specular * 0.5])
        .with("Specular Tint", &m.specular_color.to_array());
    let (base, alpha) = b.base_color_and_alpha(m);
    principled = set(principled, "Base Color", base);
    if let Some(alpha) = alpha {
        principled = set(principled, "Alpha", alpha);
    }
    if let Some(img) = m
        .metallic_roughness_texture
        .as_ref()
        .and_then(|t| b.image(t, false))
    {
        let sep =
            b.g.add(Node::new("ShaderNodeSeparateColor").link("Color", img, "Color"));
        let r = b.mul(Val::Const(vec![m.roughness]), Val::Link(sep, "Green"), true);
        let mt = b.mul(Val::Const(vec![m.metallic]), Val::Link(sep, "Blue"), true);
        principled = set(set(principled, "Roughness", r), "Metallic", mt);
    }
    if let Some(img) = m.glossiness_texture.as_ref().and_then(|t| b.image(t, true)) {
        // KHR_materials_pbrSpecularGlossiness: roughness = 1 - glossiness x alpha.
        let gloss = b.mul(
            Val::Const(vec![1.0 - m.roughness]),
            Val::Link(img, "Alpha"),
            true,
        );
        let rough = set(
            Node::new("ShaderNodeMath")
                .prop("operation", json!("SUBTRACT"))
                .with("Value", &[1.0]),
            "Value_001",
            gloss,
        );
        principled = principled.link("Roughness", b.g.add(rough), "Value");
    }
    if let Some(n) = m
        .normal_texture
        .as_ref()
        .and_then(|t| b.normal_map(t, m.normal_scale))
    {
        principled = principled.link("Normal", n, "Normal");
    }
    if m.emission.max_element() > 0.0 {
        principled = principled.with("Emission Strength", &[1.0]);
        let e = b.factor_tex(
            &m.emission.to_array(),
            m.emission_texture.as_ref(),
            true,
            None,
        );
        principled = set(principled, "Emission Color", e);
    } else {
        principled = principled.with("Emission Strength", &[0.0]);
    }
    if m.transmission_texture.is_some() {
        let t = b.factor_tex(
            &[m.transmission],
            m.transmission_texture.as_ref(),
            false,
            Some("Red"),
        );
        principled = set(principled, "Transmission Weight", t);
    }
    if m.specular_texture.is_some() {
        let s = b.factor_tex(
            &[m.specular * 0.5],
            m.specular_texture.as_ref(),
            false,
            Some("Alpha"),
        );
        principled = set(principled, "Specular IOR Level", s);
    }
    if m.specular_color_texture.is_some() {
        let s = b.factor_tex(
            &m.specular_color.to_array(),
            m.specular_color_texture.as_ref(),
            true,
            None,
        );
        principled = set(principled, "Specular Tint", s);
    }
    if let Some(c) = &m.clearcoat {
        let w = b.factor_tex(&[c.factor], c.texture.as_ref(), false, Some("Red"));
        let r = b.factor_tex(
            &[c.roughness],
            c.roughness_texture.as_ref(),
            false,
            Some("Green"),
        );
        principled = set(set(principled, "Coat Weight", w), "Coat Roughness", r)
            .with("Coat IOR", &[1.5])
            .with("Coat Tint", &[1.0, 1.0, 1.0]);
        if let Some(n) = c
            .normal_texture
            .as_ref()
            .and_then(|t| b.normal_map(t, c.normal_scale))
        {
            principled = principled.link("Coat Normal", n, "Normal");
        }
    }
    if let Some(s) = &m.sheen {
        let visible = s.color.max_element() > 0.0;
        let tint = b.factor_tex(&s.color.to_array(), s.color_texture.as_ref(), true, None);
        let r = b.factor_tex(
            &[s.roughness],
            s.roughness_texture.as_ref(),
            false,
            Some("Alpha"),
        );
        principled = set(set(principled, "Sheen Tint", tint), "Sheen Roughness", r)
            .with("Sheen Weight", &[if visible { 1.0 } else { 0.0 }]);
    }
    if let Some(a) = &m.anisotropy {
        let tex_img = a.texture.as_ref().and_then(|t| b.image(t, false));
        let strength = match tex_img {
            Some(img) => {
                let blue = b.channel(img, "Blue");
                b.mul(Val::Const(vec![a.strength]), blue, true)
            }
            None => Val::Const(vec![a.strength]),
        };
        let mut dir = Node::new("TeselaGltfAnisotropy").prop("rotation", json!(a.rotation));
        if let Some(img) = tex_img {
            dir = dir.link("Color", img, "Color");
        }
        let dir = b.g.add(dir);
        principled = set(principled, "Anisotropic", strength)
            .with("Anisotropic Rotation", &[0.0])
            .link("Tangent", dir, "Tangent");
    }
    let p = b.g.add(principled);
    b.g.surface = Some((p, "BSDF".into()));
    b.g
}

/// `KHR_materials_unlit`, as Blender's glTF importer builds it (so that a file renders as the
/// same file imported into Blender and rendered by Cycles): the base colour is emitted with
/// strength 1 to camera rays, and every other ray passes through (Light Path's Is Camera Ray
/// mixing a Transparent BSDF and the Emission), so the surface shows its colour unshaded and
/// neither lights, shadows nor reflects. Alpha (BLEND, MASK) mixes in a Transparent BSDF.
fn unlit(mut b: Builder, m: &Material) -> Graph {
    let (base, alpha) = b.base_color_and_alpha(m);
    let emission = set(
        Node::new("ShaderNodeEmission").with("Strength", &[1.0]),
        "Color",
        base,
    );
    let emission = b.g.add(emission);
    let path = b.g.add(Node::new("ShaderNodeLightPath"));
    let clear =
        b.g.add(Node::new("ShaderNodeBsdfTransparent").with("Color", &[1.0; 3]));
    let mut out = b.g.add(
        Node::new("ShaderNodeMixShader")
            .link("Fac", path, "Is Camera Ray")
            .link("Shader", clear, "BSDF")
            .link("Shader_001", emission, "Emission"),
    );
    if let Some(alpha) = alpha {
        let mix = set(Node::new("ShaderNodeMixShader"), "Fac", alpha)
            .link("Shader", clear, "BSDF")
            .link("Shader_001", out, "Shader");
        out = b.g.add(mix);
    }
    b.g.surface = Some((out, "Shader".into()));
    b.g
}
