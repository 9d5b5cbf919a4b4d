//! The Image Texture node: closest, bilinear (Cycles' "Linear", no mipmaps) or cubic B-spline
//! ("Cubic", "Smart") lookups with Blender's extension modes and colour spaces, and its flat,
//! box, sphere and tube projections.
//!
//! Alpha as Cycles has it: colour images (not Non-Color) whose alpha mode is Straight or
//! Premultiplied are held with associated (premultiplied) alpha — 8-bit ones premultiplied in
//! bytes when loaded (`c · a / 255`, truncated), float ones premultiplied already — so the
//! Color output is premultiplied, and divided by the filtered alpha only when the node's Alpha
//! output is used (the add-on's `alpha_linked`), before the sRGB decode.

use crate::scene::{Image, Texture, Wrap};
use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::{ShadeEnv, ShaderGlobals};
use crate::shading::program::{Op, Slot, Slots};
use crate::texture;
use glam::{Vec2, Vec3, Vec4};

#[derive(Clone, Debug)]
pub struct ImageOp {
    /// Index into the scene's images (a UDIM image's first tile).
    image: usize,
    /// A UDIM image's tiles, `(tile number, scene image)`; empty for a single image.
    tiles: Box<[(u32, usize)]>,
    /// Lookup parameters (wrap, filter), as for a glTF texture.
    sampler: Texture,
    /// Blender's CLIP extension: transparent black outside `[0, 1]²`.
    clip: bool,
    /// sRGB-encoded colour data (decoded after filtering).
    srgb: bool,
    /// The vector input is a glTF texture coordinate (`(0, 0)` top-left) rather than Blender's
    /// UV (`(0, 0)` bottom-left).
    gltf_uv: bool,
    /// Cycles associates the alpha (see the module's notes): 8-bit texels are premultiplied
    /// before filtering (float ones arrive premultiplied).
    associate: bool,
    /// The Alpha output is used: the filtered colour is un-premultiplied.
    unassociate: bool,
    /// Cubic B-spline filtering (Cycles' Cubic and Smart).
    cubic: bool,
    projection: Projection,
    vector: Slot,
    color: Slot,
    alpha: Slot,
}

/// How the Vector input becomes image coordinates (Cycles' `svm_node_tex_image_mapping` and
/// `svm_node_tex_image_box`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// `(x, y)`.
    Flat,
    /// Three flat lookups along the object-space axes, weighted by the object-space normal,
    /// blended over `blend` around the cube's edges.
    Box { blend: f32 },
    /// Longitude and latitude about the object's Z axis of `2 (co - 0.5)`.
    Sphere,
    /// Angle about Z and height of `2 (co - 0.5)`.
    Tube,
}

/// Cycles' box-projection weights of the three axis lookups for the unit object-space normal
/// `n` (barycentric in the triangle of the cube's three faces; single, double or triple mixes).
fn box_weights(n: Vec3, blend: f32) -> Vec3 {
    let a = n.abs();
    let sum = a.x + a.y + a.z;
    if sum.is_nan() || sum <= 0.0 {
        return Vec3::X;
    }
    let n = a / sum;
    let limit = 0.5 * (1.0 + blend);
    let mut w = Vec3::ZERO;
    if n.x > limit * (n.x + n.y) && n.x > limit * (n.x + n.z) {
        w.x = 1.0;
    } else if n.y > limit * (n.x + n.y) && n.y > limit * (n.y + n.z) {
        w.y = 1.0;
    } else if n.z > limit * (n.x + n.z) && n.z > limit * (n.y + n.z) {
        w.z = 1.0;
    } else if blend > 0.0 {
        let ramp = |x: f32| ((x - 0.5 * (1.0 - blend)) / blend).clamp(0.0, 1.0);
        if n.z < (1.0 - limit) * (n.y + n.x) {
            w.x = ramp(n.x / (n.x + n.y));
            w.y = 1.0 - w.x;
        } else if n.x < (1.0 - limit) * (n.y + n.z) {
            w.y = ramp(n.y / (n.y + n.z));
            w.z = 1.0 - w.y;
        } else if n.y < (1.0 - limit) * (n.x + n.z) {
            w.x = ramp(n.x / (n.x + n.z));
            w.z = 1.0 - w.x;
        } else {
            let k = |x: f32| ((2.0 - limit) * x + (limit - 1.0)) / (2.0 * limit - 1.0);
            w = Vec3::new(k(n.x), k(n.y), k(n.z));
        }
    } else {
        w.x = 1.0;
    }
    w
}

/// Cycles' `map_to_sphere` of a point (u from the angle about Z, v from the polar angle).
fn map_to_sphere(co: Vec3) -> Vec2 {
    let l = co.length_squared();
    if l.is_nan() || l <= 0.0 {
        return Vec2::ZERO;
    }
    let u = if co.x == 0.0 && co.y == 0.0 {
        0.0
    } else {
        0.5 - co.x.atan2(co.y) * 0.5 * std::f32::consts::FRAC_1_PI
    };
    let v = 1.0 - (co.z / l.sqrt()).clamp(-1.0, 1.0).acos() * std::f32::consts::FRAC_1_PI;
    Vec2::new(u, v)
}

/// Cycles' `map_to_tube`.
fn map_to_tube(co: Vec3) -> Vec2 {
    let r2 = co.x * co.x + co.y * co.y;
    if r2.is_nan() || r2 <= 0.0 {
        return Vec2::ZERO;
    }
    let u = (1.0 - co.x.atan2(co.y) * std::f32::consts::FRAC_1_PI) * 0.5;
    Vec2::new(u, (co.z + 1.0) * 0.5)
}

impl ImageOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals, env: &ShadeEnv) {
        let Some(img) = env.images.get(self.image) else {
            s.set_v(self.color, Vec3::new(1.0, 0.0, 1.0));
            s.set_f(self.alpha, 1.0);
            return;
        };
        let co = s.v(self.vector);
        let c = match self.projection {
            Projection::Flat => self.at_tile(img, env, Vec2::new(co.x, co.y)),
            Projection::Sphere => self.at_tile(img, env, map_to_sphere((co - 0.5) * 2.0)),
            Projection::Tube => self.at_tile(img, env, map_to_tube((co - 0.5) * 2.0)),
            // As in Cycles, box projection reads the first tile only.
            Projection::Box { blend } => {
                let n = g.normal_to_object(g.n);
                let w = box_weights(n, blend);
                // Mapped so that no face's image is mirrored (Cycles' choice).
                let mut c = Vec4::ZERO;
                if w.x > 0.0 {
                    let u = if n.x < 0.0 { 1.0 - co.y } else { co.y };
                    c += w.x * self.at(img, Vec2::new(u, co.z));
                }
                if w.y > 0.0 {
                    let u = if n.y > 0.0 { 1.0 - co.x } else { co.x };
                    c += w.y * self.at(img, Vec2::new(u, co.z));
                }
                if w.z > 0.0 {
                    let u = if n.z > 0.0 { 1.0 - co.y } else { co.y };
                    c += w.z * self.at(img, Vec2::new(u, co.x));
                }
                c
            }
        };
        s.set_v(self.color, c.truncate());
        s.set_f(self.alpha, c.w);
    }

    /// [`ImageOp::at`] in the UDIM tile `uv` falls in (Cycles' `svm_node_tex_image`): tile
    /// `1001 + 10 ty + tx` for `(tx, ty)` the coordinates truncated toward zero, `0 ≤ tx < 10`,
    /// `ty ≥ 0`, read at `uv - (tx, ty)`; outside every tile, Cycles' missing-image magenta.
    #[inline]
    fn at_tile(&self, img: &Image, env: &ShadeEnv, uv: Vec2) -> Vec4 {
        if self.tiles.is_empty() {
            return self.at(img, uv);
        }
        let (tx, ty) = (uv.x as i32, uv.y as i32);
        if (0..10).contains(&tx) && ty >= 0 {
            let tile = (ty as u32)
                .saturating_mul(10)
                .saturating_add(1001 + tx as u32);
            if let Some(&(_, i)) = self.tiles.iter().find(|t| t.0 == tile)
                && let Some(img) = env.images.get(i)
            {
                return self.at(img, uv - Vec2::new(tx as f32, ty as f32));
            }
        }
        Vec4::new(1.0, 0.0, 1.0, 1.0)
    }

    /// One lookup at image coordinates `uv` (Blender's, or glTF's for glTF graphs): linear
    /// colour and alpha.
    #[inline]
    fn at(&self, img: &Image, uv: Vec2) -> Vec4 {
        let uv = if self.gltf_uv {
            uv
        } else {
            Vec2::new(uv.x, 1.0 - uv.y)
        };
        let byte = img.float.is_empty();
        if !self.associate && !self.clip && !self.cubic {
            texture::lookup(&self.sampler, img, uv, self.srgb)
        } else {
            let premultiply = self.associate && byte;
            let mut c = lookup(&self.sampler, img, uv, premultiply, self.clip, self.cubic);
            if self.unassociate && c.w != 0.0 && c.w != 1.0 {
                c = (c.truncate() / c.w).extend(c.w);
            }
            if self.srgb {
                c = texture::decode(c, true);
            }
            c
        }
    }
}

/// Texel `(x, y)` (rows top to bottom) as stored, sRGB ones still encoded (decoded after
/// filtering, as [`texture::lookup`] does): 8-bit ones in `[0, 1]`, premultiplied in bytes as
/// Cycles' image loader does (`c * a / 255`, integer division) when `premultiply`.
#[inline]
fn texel(img: &Image, x: usize, y: usize, premultiply: bool) -> Vec4 {
    let i = y * img.width as usize + x;
    if let Some(f) = img.float.get(i) {
        return Vec4::from_array(*f);
    }
    let [r, g, b, a] = img.rgba8[i].map(u32::from);
    if premultiply {
        let pm = |c: u32| (c * a / 255) as f32;
        Vec4::new(pm(r), pm(g), pm(b), a as f32) / 255.0
    } else {
        Vec4::new(r as f32, g as f32, b as f32, a as f32) / 255.0
    }
}

/// Cycles' lookup (`kernel_tex_image_interp`) at glTF `uv`, sRGB results still encoded:
/// closest or bilinear, with texels premultiplied when `premultiply`; with `clip` (Blender's
/// CLIP), texels outside the image are transparent black, so bilinear lookups fade out over
/// the half texel around the border.
fn lookup(
    tex: &Texture,
    img: &Image,
    uv: Vec2,
    premultiply: bool,
    clip: bool,
    cubic: bool,
) -> Vec4 {
    let (w, h) = (img.width, img.height);
    if w == 0 || h == 0 || (img.rgba8.is_empty() && img.float.is_empty()) || !uv.is_finite() {
        return Vec4::ONE;
    }
    let fetch = |x: i64, y: i64| {
        if clip && (x < 0 || y < 0 || x >= w as i64 || y >= h as i64) {
            return Vec4::ZERO;
        }
        let xi = texture::wrap(x, w, tex.wrap_s);
        let yi = texture::wrap(y, h, tex.wrap_t);
        texel(img, xi, yi, premultiply)
    };
    if cubic && !tex.nearest {
        texture::filter_cubic(w, h, uv, fetch)
    } else {
        texture::filter(w, h, tex.nearest, uv, fetch)
    }
}

/// Colour spaces Cycles treats as data (no colour conversion, no alpha association).
fn is_data(colorspace: &str) -> bool {
    matches!(colorspace, "Non-Color" | "Raw" | "Generic Data")
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
    let projection = match cx.prop_str("projection").unwrap_or("FLAT") {
        "BOX" => Projection::Box {
            blend: cx.prop_f32("projection_blend", 0.0).clamp(0.0, 1.0),
        },
        "SPHERE" => Projection::Sphere,
        "TUBE" => Projection::Tube,
        _ => Projection::Flat,
    };
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
    // Cycles' alpha association (module notes). Only graphs from Blender say how the image's
    // alpha is to be read (`alpha_mode`); glTF textures (the preset graphs) keep straight alpha.
    // Float pixels arrive converted ("Non-Color"): their own colour space is `source_colorspace`.
    let source_cs = cx.prop_str("source_colorspace").unwrap_or(cs);
    let associate = cx
        .prop_str("alpha_mode")
        .is_some_and(|m| !matches!(m, "CHANNEL_PACKED" | "NONE"))
        && !is_data(source_cs);
    let unassociate = associate && cx.prop_bool("alpha_linked", false);
    cx.emit(
        Op::Image(ImageOp {
            image,
            tiles: cx.node().tiles.clone().into_boxed_slice(),
            sampler: Texture {
                image,
                wrap_s,
                wrap_t,
                nearest: interp == "Closest",
            },
            clip: ext == "CLIP",
            srgb,
            gltf_uv,
            associate,
            unassociate,
            cubic: matches!(interp, "Cubic" | "Smart"),
            projection,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn image() -> Image {
        // 2 x 1: a half-transparent orange texel and an opaque blue one.
        Image {
            width: 2,
            height: 1,
            rgba8: vec![[255, 101, 0, 128], [0, 0, 200, 255]],
            float: Vec::new(),
        }
    }

    fn tex(wrap: Wrap, nearest: bool) -> Texture {
        Texture {
            image: 0,
            wrap_s: wrap,
            wrap_t: wrap,
            nearest,
        }
    }

    #[test]
    fn bytes_are_premultiplied_with_truncation() {
        let img = image();
        let c = texel(&img, 0, 0, true) * 255.0;
        // 255 * 128 / 255 = 128, 101 * 128 / 255 = 50.7 -> 50 (Cycles' integer division).
        assert_eq!(c, Vec4::new(128.0, 50.0, 0.0, 128.0));
        let straight = texel(&img, 0, 0, false) * 255.0;
        assert_eq!(straight, Vec4::new(255.0, 101.0, 0.0, 128.0));
    }

    #[test]
    fn linear_clip_fades_to_transparent_black_over_half_a_texel() {
        let img = image();
        let t = tex(Wrap::ClampToEdge, false);
        // Texel centres at u = 0.25 and 0.75; at u = 0 the left texel is blended half with
        // the transparent outside, at u = -0.25 (a whole half texel out) nothing is left.
        let edge = lookup(&t, &img, Vec2::new(0.0, 0.5), false, true, false);
        assert!((edge - Vec4::new(0.5, 101.0 / 510.0, 0.0, 64.0 / 255.0)).length() < 1e-6);
        let out = lookup(&t, &img, Vec2::new(-0.25, 0.5), false, true, false);
        assert_eq!(out, Vec4::ZERO);
        // EXTEND holds the edge texel instead.
        let ext = lookup(&t, &img, Vec2::new(0.0, 0.5), false, false, false);
        assert!((ext - Vec4::new(1.0, 101.0 / 255.0, 0.0, 128.0 / 255.0)).length() < 1e-6);
    }

    #[test]
    fn closest_clip_is_black_outside_only() {
        let img = image();
        let t = tex(Wrap::ClampToEdge, true);
        let inside = lookup(&t, &img, Vec2::new(0.99, 0.5), false, true, false);
        assert_eq!(inside, Vec4::new(0.0, 0.0, 200.0 / 255.0, 1.0));
        let outside = lookup(&t, &img, Vec2::new(1.01, 0.5), false, true, false);
        assert_eq!(outside, Vec4::ZERO);
    }
}
