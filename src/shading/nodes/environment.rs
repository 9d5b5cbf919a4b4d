//! World nodes: the Environment Texture (equirectangular and mirror-ball projections, as
//! Cycles' `svm_node_tex_environment`) and the Background shader; the shading point of a ray
//! that left the scene (Cycles' `shader_setup_from_background`: `P` is the ray's direction,
//! `N = Ng = I = -D`), so that Texture Coordinate's Generated/Object/Position read the view
//! direction, as in Cycles.

use super::bsdf::ClosureOp;
use super::input::{InputOp, Source};
use crate::scene::{Image, Texture, Wrap};
use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::{ShadeEnv, ShaderGlobals};
use crate::shading::program::{Op, Slot, Slots};
use crate::texture;
use glam::{Vec2, Vec3, Vec4};
use std::f32::consts::PI;

/// Blender-world direction → Cycles' equirectangular `(u, v)` (`v = 0` at the bottom of the
/// image, `-Z`; `u = 0.5` towards `+X`, `u` growing towards `-Y`): Cycles'
/// `direction_to_equirectangular`. `d` need not be unit: both angles are ratios of its
/// components. A zero direction (or one whose squared length overflows) gives `(0, 0)`.
#[inline(always)]
pub fn direction_to_equirectangular(d: Vec3) -> Vec2 {
    let rho2 = d.x * d.x + d.y * d.y;
    let len2 = rho2 + d.z * d.z;
    if len2 == 0.0 || !len2.is_finite() {
        return Vec2::ZERO;
    }
    // acos(z / |d|) as atan2(ρ, z): one inlined arctangent form for both angles.
    let rho = rho2.sqrt();
    let u = (crate::trig::atan2(d.y, d.x) - PI) / (-2.0 * PI);
    let v = (crate::trig::atan2(rho, d.z) - PI) / -PI;
    Vec2::new(u, v)
}

/// The inverse of [`direction_to_equirectangular`] (Cycles' `equirectangular_to_direction`).
#[inline]
pub fn equirectangular_to_direction(u: f32, v: f32) -> Vec3 {
    let phi = -2.0 * PI * u + PI;
    let theta = -PI * v + PI;
    let (st, ct) = crate::trig::sin_cos(theta);
    let (sp, cp) = crate::trig::sin_cos(phi);
    Vec3::new(st * cp, st * sp, ct)
}

/// Blender-world direction → mirror-ball image coordinates (Cycles' `direction_to_mirrorball`).
#[inline]
pub fn direction_to_mirrorball(mut d: Vec3) -> Vec2 {
    d.y -= 1.0;
    let div = 2.0 * (-0.5 * d.y).max(0.0).sqrt();
    if div > 0.0 {
        d /= div;
    }
    Vec2::new(0.5 * (d.x + 1.0), 0.5 * (d.z + 1.0))
}

/// The shading point of a ray leaving the scene along the unit direction `d` (renderer world,
/// Y up) from path vertex `depth - 1`, with Light Path bits `flags`.
#[inline]
pub fn background_globals(d: Vec3, depth: u32, flags: u32) -> ShaderGlobals<'static> {
    let mut g = ShaderGlobals::at(d, -d, Vec2::ZERO);
    g.ray_depth = depth;
    g.ray_flags = flags;
    g
}

#[derive(Clone, Debug)]
pub struct EnvironmentOp {
    /// Index into the scene's images.
    image: usize,
    sampler: Texture,
    srgb: bool,
    mirror_ball: bool,
    /// The direction; `None`: the shading point's position (the view direction), read
    /// straight from the globals rather than through a slot.
    vector: Option<Slot>,
    color: Slot,
    alpha: Slot,
}

impl EnvironmentOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals, env: &ShadeEnv) {
        let v = self.vector.map_or(g.p, |v| s.v(v));
        let c = self.color_at(v, env.images);
        s.set_v(self.color, c.truncate());
        s.set_f(self.alpha, c.w);
    }

    /// Colour and alpha towards `v` (Blender world, any length); magenta for a missing image.
    #[inline(always)]
    fn color_at(&self, v: Vec3, images: &[Image]) -> Vec4 {
        let Some(img) = images.get(self.image) else {
            return Vec4::new(1.0, 0.0, 1.0, 1.0);
        };
        let uv = if self.mirror_ball {
            let len = v.length();
            direction_to_mirrorball(if len > 0.0 && len.is_finite() {
                v / len
            } else {
                Vec3::ZERO
            })
        } else {
            // Scale-free: no normalisation needed.
            direction_to_equirectangular(v)
        };
        // Cycles' v runs up the image; the renderer's images run top to bottom.
        texture::lookup(&self.sampler, img, Vec2::new(uv.x, 1.0 - uv.y), self.srgb)
    }
}

/// A world that is only an Environment Texture (its Vector unlinked: the view direction) into
/// a Background of constant strength, as most HDRI worlds are: its emission found without
/// running the program, by the same operations in the same order (so to the same bits).
#[derive(Clone, Debug)]
pub struct ImageWorld {
    env: EnvironmentOp,
    /// Background Strength and the closure's weight, constants of the program.
    strength: f32,
    weight: f32,
}

impl ImageWorld {
    /// The world of `ops` with slot constants `init`, if it is an [`ImageWorld`].
    pub(crate) fn recognise(ops: &[Op], init: &[f32]) -> Option<ImageWorld> {
        let [Op::Environment(env), Op::Closure(closure)] = ops else {
            return None;
        };
        let (weight, color, strength) = closure.as_emission()?;
        let written = |s: Slot| (env.color..env.color + 3).contains(&s) || s == env.alpha;
        if env.vector.is_some() || color != env.color || written(weight) || written(strength) {
            return None;
        }
        Some(ImageWorld {
            env: env.clone(),
            strength: *init.get(strength as usize)?,
            weight: *init.get(weight as usize)?,
        })
    }

    /// The emission the program gives for a ray leaving along `d` (Blender world, unit), as
    /// [`crate::shading::Program::emission`] finds it.
    #[inline]
    pub fn emission(&self, d: Vec3, images: &[Image]) -> Vec3 {
        if self.weight == 0.0 {
            return Vec3::ZERO;
        }
        let c = self.env.color_at(d, images).truncate();
        let e = c.max(Vec3::ZERO) * self.strength * self.weight;
        if e.is_finite() {
            Vec3::ZERO + e.max(Vec3::ZERO)
        } else {
            Vec3::ZERO
        }
    }
}

/// The node's Vector input; unlinked, the shading point's position, which for the world is
/// the view direction.
pub(super) fn direction_input(cx: &mut NodeCx) -> Result<Slot, CompileError> {
    if cx.is_linked("Vector") {
        return cx.vector("Vector", Vec3::ZERO);
    }
    let out = cx.alloc(3)?;
    cx.emit(
        Op::Input(InputOp {
            src: Source::Position,
            out,
        }),
        true,
    );
    Ok(out)
}

/// Compiles the Environment Texture; `Ok(false)` for other kinds.
pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    if kind != "ShaderNodeTexEnvironment" {
        return Ok(false);
    }
    let vector = if cx.is_linked("Vector") {
        Some(cx.vector("Vector", Vec3::ZERO)?)
    } else {
        None
    };
    let color = cx.output("Color", SocketType::Color)?;
    let alpha = cx.output("Alpha", SocketType::Float)?;
    let Some(image) = cx.node().image else {
        // As Cycles renders a missing image: magenta.
        cx.warn("has no image (or its pixels could not be read); it renders magenta");
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
    let interp = cx.prop_str("interpolation").unwrap_or("Linear");
    if matches!(interp, "Cubic" | "Smart") {
        cx.warn("cubic interpolation renders as linear");
    }
    let mirror_ball = match cx.prop_str("projection").unwrap_or("EQUIRECTANGULAR") {
        "MIRROR_BALL" => true,
        "EQUIRECTANGULAR" => false,
        other => {
            let msg = format!("projection '{other}' renders as equirectangular");
            cx.warn(&msg);
            false
        }
    };
    if cx.prop("texture_mapping").is_some_and(|v| !v.is_null()) {
        cx.warn("the node's texture mapping is ignored");
    }
    let srgb = match cx.prop_str("colorspace").unwrap_or("Non-Color") {
        "sRGB" => true,
        "Non-Color" | "Linear" | "Linear Rec.709" | "Raw" | "Linear CIE-XYZ E" => false,
        other => {
            let msg = format!("colour space '{other}' is read as sRGB");
            cx.warn(&msg);
            true
        }
    };
    cx.emit(
        Op::Environment(EnvironmentOp {
            image,
            sampler: Texture {
                image,
                wrap_s: Wrap::Repeat,
                wrap_t: Wrap::Repeat,
                nearest: interp == "Closest",
            },
            srgb,
            mirror_ball,
            vector,
            color,
            alpha,
        }),
        true,
    );
    Ok(true)
}

/// Compiles the Background shader with weight slot `w`: emission of `Color · Strength` (Cycles
/// gathers background and emission closures alike).
pub fn compile_background(cx: &mut NodeCx, w: Slot) -> Result<bool, CompileError> {
    let color = cx.color("Color", Vec3::splat(0.8))?;
    let strength = cx.float("Strength", 1.0)?;
    cx.emits();
    cx.emit(Op::Closure(ClosureOp::emission(w, color, strength)), false);
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equirectangular_round_trip_and_cycles_orientation() {
        // +X is the image's centre column, +Y a quarter of the way in, -Y three quarters;
        // +Z the top row (Cycles' v = 1), -Z the bottom.
        let close = |a: Vec2, b: Vec2| (a - b).abs().max_element() < 1e-6;
        assert!(close(
            direction_to_equirectangular(Vec3::X),
            Vec2::new(0.5, 0.5)
        ));
        assert!(close(
            direction_to_equirectangular(Vec3::Y),
            Vec2::new(0.25, 0.5)
        ));
        assert!(close(
            direction_to_equirectangular(-Vec3::Y),
            Vec2::new(0.75, 0.5)
        ));
        assert!((direction_to_equirectangular(Vec3::Z).y - 1.0).abs() < 1e-6);
        assert!(direction_to_equirectangular(-Vec3::Z).y.abs() < 1e-6);
        for (u, v) in [(0.1, 0.2), (0.6, 0.9), (0.99, 0.5), (0.3, 0.01)] {
            let d = equirectangular_to_direction(u, v);
            assert!((d.length() - 1.0).abs() < 1e-5);
            let uv = direction_to_equirectangular(d);
            assert!(close(uv, Vec2::new(u, v)) || (uv - Vec2::new(u, v)).length() < 1e-5);
        }
        assert_eq!(direction_to_equirectangular(Vec3::ZERO), Vec2::ZERO);
    }

    #[test]
    fn mirror_ball_centre_and_edge() {
        // The ball is seen along +Y: its centre reflects the view back, towards -Y.
        let c = direction_to_mirrorball(-Vec3::Y);
        assert!((c - Vec2::splat(0.5)).length() < 1e-6, "{c}");
        // +X seen at 90° lands halfway to the right edge (the ball's normal at 45°).
        let r = direction_to_mirrorball(Vec3::X);
        assert!(r.x > 0.8 && r.x < 0.9 && (r.y - 0.5).abs() < 1e-6, "{r}");
    }
}
