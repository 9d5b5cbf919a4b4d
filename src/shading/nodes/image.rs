//! The Image Texture node: bilinear (Cycles' "Linear", no mipmaps) or closest lookups with
//! Blender's extension modes and colour spaces.

use crate::scene::{Texture, Wrap};
use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::ShadeEnv;
use crate::shading::program::{Op, Slot, Slots};
use crate::texture;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct ImageOp {
    /// Index into the scene's images.
    image: usize,
    /// Lookup parameters (wrap, filter), as for a glTF texture.
    sampler: Texture,
    /// Blender's CLIP extension: transparent black outside `[0, 1]²`.
    clip: bool,
    /// sRGB-encoded colour data (decoded after filtering).
    srgb: bool,
    /// The vector input is a glTF texture coordinate (`(0, 0)` top-left) rather than Blender's
    /// UV (`(0, 0)` bottom-left).
    gltf_uv: bool,
    vector: Slot,
    color: Slot,
    alpha: Slot,
}

impl ImageOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, env: &ShadeEnv) {
        let v = s.v(self.vector);
        let uv = if self.gltf_uv {
            Vec2::new(v.x, v.y)
        } else {
            Vec2::new(v.x, 1.0 - v.y)
        };
        let Some(img) = env.images.get(self.image) else {
            s.set_v(self.color, Vec3::new(1.0, 0.0, 1.0));
            s.set_f(self.alpha, 1.0);
            return;
        };
        if self.clip && !(v.x >= 0.0 && v.x <= 1.0 && v.y >= 0.0 && v.y <= 1.0) {
            s.set_v(self.color, Vec3::ZERO);
            s.set_f(self.alpha, 0.0);
            return;
        }
        let c = texture::lookup(&self.sampler, img, uv, self.srgb);
        s.set_v(self.color, c.truncate());
        s.set_f(self.alpha, c.w);
    }
}

pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    if kind != "ShaderNodeTexImage" {
        return Ok(false);
    }
    let gltf_uv = cx.prop_bool("gltf_uv", false);
    let vector = if cx.is_linked("Vector") {
        cx.vector("Vector", Vec3::ZERO)?
    } else {
        // Unlinked: the first UV map.
        let out = cx.alloc(3)?;
        let src = if gltf_uv {
            super::input::Source::GltfUv(0)
        } else {
            super::input::Source::Uv(String::new())
        };
        cx.emit(Op::Input(super::input::InputOp { src, out }), true);
        out
    };
    let color = cx.output("Color", SocketType::Color)?;
    let alpha = cx.output("Alpha", SocketType::Float)?;
    let Some(image) = cx.node().image else {
        cx.warn("has no image; it renders magenta");
        let c = cx.constant(&[1.0, 0.0, 1.0])?;
        let a = cx.constant(&[1.0])?;
        cx.emit(
            Op::Convert(super::convert::ConvertOp::Copy3 { a: c, out: color }),
            false,
        );
        cx.emit(
            Op::Convert(super::convert::ConvertOp::Copy1 { a, out: alpha }),
            false,
        );
        return Ok(true);
    };
    let ext = cx.prop_str("extension").unwrap_or("REPEAT");
    let wrap = match ext {
        "EXTEND" | "CLIP" => Wrap::ClampToEdge,
        "MIRROR" => Wrap::MirroredRepeat,
        _ => Wrap::Repeat,
    };
    let (wrap_s, wrap_t) = match (
        cx.prop_str("wrap_s").map(gltf_wrap),
        cx.prop_str("wrap_t").map(gltf_wrap),
    ) {
        (Some(s), Some(t)) => (s, t),
        _ => (wrap, wrap),
    };
    let interp = cx.prop_str("interpolation").unwrap_or("Linear");
    if matches!(interp, "Cubic" | "Smart") {
        cx.warn("cubic interpolation renders as linear");
    }
    if cx.prop_str("projection").is_some_and(|p| p != "FLAT") {
        cx.warn("box/sphere/tube projection renders as flat");
    }
    let cs = cx.prop_str("colorspace").unwrap_or("sRGB");
    let srgb = match cs {
        "sRGB" => true,
        "Non-Color" | "Linear" | "Linear Rec.709" | "Raw" | "Linear CIE-XYZ E" => false,
        other => {
            let msg = format!("colour space '{other}' is read as sRGB");
            cx.warn(&msg);
            true
        }
    };
    cx.emit(
        Op::Image(ImageOp {
            image,
            sampler: Texture {
                image,
                wrap_s,
                wrap_t,
                nearest: interp == "Closest",
            },
            clip: ext == "CLIP",
            srgb,
            gltf_uv,
            vector,
            color,
            alpha,
        }),
        true,
    );
    Ok(true)
}

fn gltf_wrap(s: &str) -> Wrap {
    match s {
        "CLAMP_TO_EDGE" => Wrap::ClampToEdge,
        "MIRRORED_REPEAT" => Wrap::MirroredRepeat,
        _ => Wrap::Repeat,
    }
}
