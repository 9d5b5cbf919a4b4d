//! The Bevel node (Cycles' `svm_bevel`): the shading normal averaged over the object's own
//! surfaces within `Radius` of the point, so hard edges shade as if rounded.
//!
//! Each of `samples` probes picks an axis of the geometric frame (the normal with
//! probability ½, either tangent with ¼), a point on the disk about that axis with the planar
//! cubic falloff `10 (R - r)³ / (π R⁵)` (per unit disk area), and casts a local ray along the
//! axis through the sphere of radius `R`. Every surface of the object on it adds its shading
//! normal with the power-heuristic weight of the three axes and the falloff at its true
//! distance over the falloff the disk point was drawn with. Where nothing can be traced, or
//! for rays Cycles calls blurry (here: after a diffuse bounce), the node gives the shading
//! normal.

use crate::frame::Frame;
use crate::sampler::SobolSampler;
use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::{LocalHit, ShadeEnv, ShaderGlobals, ray};
use crate::shading::program::{Op, Slot, Slots};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Most probes one node casts (Blender's limit of the Samples property).
pub const MAX_SAMPLES: u32 = 16;

/// Most surfaces of the object one probe weighs (Cycles keeps a random 4 and reweights; all of
/// them, up to this many, have the same expectation).
const MAX_HITS: usize = 8;

#[derive(Clone, Copy, Debug)]
pub struct BevelOp {
    radius: Slot,
    /// The Normal input when linked: the bevel's change of normal is added to it.
    normal: Option<Slot>,
    samples: u32,
    out: Slot,
}

/// The cubic falloff `10 (R - r)³ / (π R⁵)`: a density per unit area of the disk of radius `R`.
#[inline]
pub fn cubic_pdf(radius: f32, r: f32) -> f32 {
    if r >= radius {
        return 0.0;
    }
    let f = radius - r;
    10.0 * f * f * f / (radius * radius * radius * radius * radius * PI)
}

/// The radius fraction `x` whose disk CDF `10x² - 20x³ + 15x⁴ - 4x⁵` is `xi` (Newton's
/// method from x = 0.25, as Cycles solves it).
fn cubic_radius_fraction(xi: f32) -> f32 {
    let mut x = 0.25f32;
    for _ in 0..10 {
        let (x2, nx) = (x * x, 1.0 - x);
        let f = 10.0 * x2 - 20.0 * x2 * x + 15.0 * x2 * x2 - 4.0 * x2 * x2 * x - xi;
        let df = 20.0 * (x * nx) * (nx * nx);
        if f.abs() < 1e-6 || df == 0.0 {
            break;
        }
        x = (x - f / df).clamp(0.0, 1.0);
    }
    x
}

/// The bevelled normal at `g` (Blender world space, on the side the ray came from), or
/// `g.n` when nothing is found.
pub fn bevel_normal(g: &ShaderGlobals, env: &ShadeEnv, radius: f32, samples: u32) -> Vec3 {
    let Some(tracer) = env.tracer else {
        return g.n;
    };
    let blurry = g.ray_depth > 1 && g.ray_flags & ray::DIFFUSE != 0;
    if radius.is_nan() || radius <= 0.0 || samples == 0 || g.object[0] == u32::MAX || blurry {
        return g.n;
    }
    // The frame of the outward geometric normal (Cycles' Ng before its backfacing flip).
    let ng = if g.backfacing { -g.ng } else { g.ng };
    let f = Frame::from_normal(ng);
    let mut sum = Vec3::ZERO;
    let mut hits = [LocalHit::default(); MAX_HITS];
    for k in 0..samples {
        let mut rng = SobolSampler::new(g.seed as u64, 0x0062_6576_656c, k as u64);
        let mut u = rng.next_2d();
        let (axis, t, b, pick) = if u.x < 0.5 {
            u.x *= 2.0;
            (f.n, f.s, f.t, [0.5, 0.25, 0.25])
        } else if u.x < 0.75 {
            u.x = (u.x - 0.5) * 4.0;
            (f.s, f.n, f.t, [0.25, 0.5, 0.25])
        } else {
            u.x = (u.x - 0.75) * 4.0;
            (f.t, f.s, f.n, [0.25, 0.25, 0.5])
        };
        let disk_r = cubic_radius_fraction(u.y) * radius;
        let height = (radius * radius - disk_r * disk_r).max(0.0).sqrt();
        let phi = 2.0 * PI * u.x;
        let disk = Vec2::new(disk_r * phi.cos(), disk_r * phi.sin());
        let o = g.p + axis * height + t * disk.x + b * disk.y;
        let disk_pdf = cubic_pdf(radius, disk_r);
        if disk_pdf <= 0.0 {
            continue;
        }
        let n = tracer.local_hits(g, o, -axis, 2.0 * height, &mut hits);
        for h in &hits[..n] {
            let pdf_n = pick[0] * axis.dot(h.ng).abs();
            let pdf_t = pick[1] * t.dot(h.ng).abs();
            let pdf_b = pick[2] * b.dot(h.ng).abs();
            let denom = pdf_n * pdf_n + pdf_t * pdf_t + pdf_b * pdf_b;
            if denom <= 0.0 {
                continue;
            }
            let w = pdf_n / denom * cubic_pdf(radius, (h.p - g.p).length()) / disk_pdf;
            sum += w * h.n;
        }
    }
    match sum.try_normalize() {
        Some(n) if g.backfacing => -n,
        Some(n) => n,
        None => g.n,
    }
}

impl BevelOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals, env: &ShadeEnv) {
        let n = bevel_normal(g, env, s.f(self.radius), self.samples);
        let n = match self.normal {
            // The input normal keeps its own direction and gains the bevel's change.
            Some(slot) => (s.v(slot) + (n - g.n)).try_normalize().unwrap_or(n),
            None => n,
        };
        s.set_v(self.out, n);
    }
}

pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    if kind != "ShaderNodeBevel" {
        return Ok(false);
    }
    let radius = cx.float("Radius", 0.05)?;
    let normal = cx.linked_vector("Normal")?;
    let samples = cx.prop_f32("samples", 4.0).clamp(1.0, MAX_SAMPLES as f32) as u32;
    let out = cx.output("Normal", SocketType::Vector)?;
    cx.emit(
        Op::Bevel(BevelOp {
            radius,
            normal,
            samples,
            out,
        }),
        true,
    );
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_radius_sampling_inverts_the_disk_cdf() {
        // CDF(x) = ∫₀ˣ 2π R² s · pdf(R s) ds over the unit-radius disk: the solver inverts it.
        for i in 1..50 {
            let xi = i as f32 / 50.0;
            let x = cubic_radius_fraction(xi);
            let cdf = 10.0 * x.powi(2) - 20.0 * x.powi(3) + 15.0 * x.powi(4) - 4.0 * x.powi(5);
            assert!((cdf - xi).abs() < 2e-4, "xi {xi}: x {x}, cdf {cdf}");
        }
        // The falloff integrates to 1 over the disk (midpoint rule).
        let (r, n) = (0.3f32, 20_000);
        let total: f32 = (0..n)
            .map(|i| {
                let s = (i as f32 + 0.5) / n as f32 * r;
                2.0 * PI * s * cubic_pdf(r, s) * r / n as f32
            })
            .sum();
        assert!((total - 1.0).abs() < 1e-3, "{total}");
    }
}
