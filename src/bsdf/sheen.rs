//! Cycles 4.x/5.x sheen ("microfiber"; Principled BSDF's Sheen and the Sheen BSDF node):
//! Zeltner, Burley and Chiang 2022, "Practical Multiple-Scattering Sheen Using Linearly
//! Transformed Cosines".
//!
//! The lobe is a linearly transformed cosine in a frame whose +X is `wi` projected on the
//! surface: with the inverse transform `M⁻¹ = [[a, 0, b], [0, a, 0], [0, 0, 1]]`,
//! `f · cos θo = albedo(μ, r) · colour · cos θo (a / |M⁻¹ wo|²)² / π`, `μ = cos θi`. Sampling
//! draws a cosine-distributed direction and maps it through `M` (exactly as Cycles'
//! `bsdf_sheen_sample`), so `pdf = cos θo (a / |M⁻¹ wo|²)² / π` and the sample weight is
//! `albedo · colour`.
//!
//! **Approximation vs Cycles:** Cycles reads `a`, `b` and the albedo from a 32×32 table fitted
//! to the paper's volumetric reference. Tesela uses the paper's published closed-form fits of
//! that table (rational fits for `a` and `b`, a Gaussian fit for the albedo; the same ones
//! MaterialX uses). Measured against Cycles' table: the albedo agrees within 0.01 for
//! roughness ≥ 0.25 and within 0.06 everywhere; `a` differs most at low roughness, where the
//! table itself is noisy.

use super::{Bsdf, BsdfQueryRecord, Measure};
use crate::sampling::square_to_cosine_hemisphere;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// Directional albedo of the sheen lobe: Zeltner et al.'s Gaussian fit, clamped to `[0, 1]`.
/// `x = cos θi`, `y` = roughness.
pub fn albedo(x: f32, y: f32) -> f32 {
    let s = y * (0.0206607 + 1.58491 * y) / (0.0379424 + y * (1.32227 + y));
    let m = y * (-0.193854 + y * (-1.14885 + y * (1.7932 - 0.95943 * y * y))) / (0.046391 + y);
    let o = y * (0.000654023 + (-0.0207818 + 0.119681 * y) * y) / (1.26264 + y * (-1.92021 + y));
    let t = (x - m) / s;
    ((-0.5 * t * t).exp() / (s * (2.0 * PI).sqrt()) + o).clamp(0.0, 1.0)
}

/// The LTC's inverse-matrix coefficient `a` (rational fit).
pub fn ltc_a(x: f32, y: f32) -> f32 {
    (2.58126 * x + 0.813703 * y) * y / (1.0 + 0.310327 * x * x + 2.60994 * x * y)
}

/// The LTC's inverse-matrix coefficient `b` (rational fit; ≤ 0).
pub fn ltc_b(x: f32, y: f32) -> f32 {
    (1.0 - x).max(0.0).sqrt() * (y - 1.0) * y * y * y
        / (0.0000254053 + 1.71228 * x - 1.71506 * x * y + 1.34174 * y * y)
}

#[derive(Clone, Copy, Debug)]
pub struct Sheen {
    /// Weight × tint (Principled: Sheen Weight × Sheen Tint; Sheen BSDF: Color).
    pub color: Vec3,
    /// Sheen roughness, clamped to `[1e-3, 1]` as in Cycles.
    pub roughness: f32,
}

/// The lobe's parameters for one `wi`: `(a, b, albedo)`, or `None` when Cycles would drop the
/// closure (`|a| < 1e-5` or albedo `< 1e-5`).
#[inline]
fn ltc(mu: f32, r: f32) -> Option<(f32, f32, f32)> {
    let mu = mu.clamp(0.0, 1.0);
    let (a, b, e) = (ltc_a(mu, r), ltc_b(mu, r), albedo(mu, r));
    (a.abs() >= 1e-5 && e >= 1e-5 && a.is_finite() && b.is_finite()).then_some((a, b, e))
}

/// `wo` in the frame whose +X is `wi`'s tangential direction (Cycles'
/// `make_orthonormals_safe_tangent(N, wi)`; any frame at normal incidence).
#[inline]
fn to_ltc_frame(wi: Vec3, w: Vec3) -> Vec3 {
    let r2 = wi.x * wi.x + wi.y * wi.y;
    if r2 < 1e-12 {
        return w;
    }
    let r = r2.sqrt();
    let (cx, cy) = (wi.x / r, wi.y / r);
    Vec3::new(cx * w.x + cy * w.y, -cy * w.x + cx * w.y, w.z)
}

#[inline]
fn from_ltc_frame(wi: Vec3, w: Vec3) -> Vec3 {
    let r2 = wi.x * wi.x + wi.y * wi.y;
    if r2 < 1e-12 {
        return w;
    }
    let r = r2.sqrt();
    let (cx, cy) = (wi.x / r, wi.y / r);
    Vec3::new(cx * w.x - cy * w.y, cy * w.x + cx * w.y, w.z)
}

impl Sheen {
    pub fn new(color: Vec3, roughness: f32) -> Self {
        let roughness = if roughness.is_nan() {
            1.0
        } else {
            roughness.clamp(1e-3, 1.0)
        };
        Sheen {
            color: color.max(Vec3::ZERO),
            roughness,
        }
    }

    /// `∫ f cos dωo` for this `wi`: `colour · albedo(cos θi)` (zero where Cycles drops the
    /// lobe). The Principled BSDF attenuates the layers below by
    /// `1 - max(colour) · albedo` (see [`super::layered::Layer`]). A `wi` below the lobe's
    /// normal (a normal map tilted away from the viewer) reads the grazing parameters, as
    /// Cycles' table lookup clamps `cos θi` to 0: the lobe stays, reflecting above its normal.
    pub fn albedo(&self, wi: Vec3) -> Vec3 {
        match ltc(wi.z, self.roughness) {
            Some((_, _, e)) => self.color * e,
            None => Vec3::ZERO,
        }
    }

    /// The LTC density of `wo` for coefficients `a`, `b` (`wo` in the LTC frame).
    #[inline]
    fn density(a: f32, b: f32, o: Vec3) -> f32 {
        if o.z <= 0.0 {
            return 0.0;
        }
        let x = a * o.x + b * o.z;
        let y = a * o.y;
        let len2 = x * x + y * y + o.z * o.z;
        let k = a / len2;
        FRAC_1_PI * o.z * k * k
    }
}

impl Bsdf for Sheen {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, _u1: f32) -> Vec3 {
        let wi = rec.wi;
        let Some((a, b, e)) = ltc(wi.z, self.roughness) else {
            return Vec3::ZERO;
        };
        let c = square_to_cosine_hemisphere(u);
        if c.z <= 0.0 {
            return Vec3::ZERO;
        }
        let o = Vec3::new(c.x - c.z * b, c.y, c.z * a).normalize();
        let pdf = Self::density(a, b, o);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return Vec3::ZERO;
        }
        rec.wo = from_ltc_frame(wi, o);
        rec.pdf = pdf;
        rec.eta = 1.0;
        rec.measure = Measure::SolidAngle;
        self.color * e
    }

    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        let (wi, wo) = (rec.wi, rec.wo);
        if wo.z <= 0.0 {
            return Vec3::ZERO;
        }
        let Some((a, b, e)) = ltc(wi.z, self.roughness) else {
            return Vec3::ZERO;
        };
        self.color * (e * Self::density(a, b, to_ltc_frame(wi, wo)) / wo.z)
    }

    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        let wi = rec.wi;
        let Some((a, b, _)) = ltc(wi.z, self.roughness) else {
            return 0.0;
        };
        Self::density(a, b, to_ltc_frame(wi, rec.wo))
    }

    fn is_delta(&self) -> bool {
        false
    }

    /// Cycles counts this lobe among the diffuse closures.
    fn eval_split(&self, rec: &BsdfQueryRecord) -> [Vec3; 2] {
        [self.eval(rec), Vec3::ZERO]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A viewer below the lobe's normal (a tilted normal map) still sees the lobe, with the
    /// grazing parameters, reflecting above the normal: Cycles clamps `cos θi` in its table
    /// lookups and drops nothing.
    #[test]
    fn a_viewer_below_the_normal_sees_the_grazing_lobe() {
        let s = Sheen::new(Vec3::ONE, 0.5);
        let below = Vec3::new(0.6, 0.0, -0.8);
        let grazing = Vec3::new(1.0, 0.0, 0.0);
        assert!(s.albedo(below).x > 0.0);
        assert_eq!(s.albedo(below), s.albedo(grazing));
        let wo = Vec3::new(-0.3, 0.2, 0.9).normalize();
        let f = s.eval(&BsdfQueryRecord::pair(below, wo));
        assert!(f.x > 0.0 && f == s.eval(&BsdfQueryRecord::pair(grazing, wo)));
        let mut rec = BsdfQueryRecord::pair(below, Vec3::ZERO);
        let w = s.sample(&mut rec, Vec2::new(0.3, 0.7), 0.5);
        assert!(w.x > 0.0 && rec.wo.z > 0.0 && rec.pdf > 0.0);
        // Below the lobe's normal on the way out, nothing.
        assert_eq!(s.eval(&BsdfQueryRecord::pair(below, -wo)), Vec3::ZERO);
    }
}
