//! The GGX (Trowbridge–Reitz) microfacet distribution with visible-normal sampling
//! (Heitz 2018), and a rough conductor built on it.
//!
//! Conventions: `alpha` = perceptual roughness²; half vectors live in the local frame (+Z up).
//! `D` is the normal distribution (per steradian of microfacet normals, projected area
//! normalised: ∫ D(h) cos θh dh = 1); `G1`/`G2` are Smith's masking and height-correlated
//! masking-shadowing functions.

use super::{Bsdf, BsdfQueryRecord, Measure, fresnel};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// GGX normal distribution `D(h)`.
#[inline]
pub fn ggx_d(h: Vec3, alpha: f32) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let c2 = h.z * h.z;
    let d = c2 * (a2 - 1.0) + 1.0;
    a2 / (PI * d * d)
}

/// Smith's `Λ(w)` for GGX.
#[inline]
fn ggx_lambda(w: Vec3, alpha: f32) -> f32 {
    let c2 = w.z * w.z;
    if c2 <= 0.0 {
        return f32::INFINITY;
    }
    let t2 = (1.0 - c2).max(0.0) / c2;
    0.5 * (-1.0 + (1.0 + alpha * alpha * t2).sqrt())
}

/// Smith masking `G1(w)`.
#[inline]
pub fn ggx_g1(w: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(w, alpha))
}

/// Height-correlated masking-shadowing `G2(wi, wo)`.
#[inline]
pub fn ggx_g2(wi: Vec3, wo: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(wi, alpha) + ggx_lambda(wo, alpha))
}

/// Samples a microfacet normal visible from `wi` (which must have `wi.z > 0`) with density
/// `D_wi(h) = G1(wi) max(0, wi·h) D(h) / wi.z`.
#[inline]
pub fn sample_visible_normal(wi: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    let vh = Vec3::new(alpha * wi.x, alpha * wi.y, wi.z).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 {
        Vec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
    } else {
        Vec3::X
    };
    let t2 = vh.cross(t1);
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let p1 = r * phi.cos();
    let mut p2 = r * phi.sin();
    let s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(1e-7)).normalize()
}

/// Solid-angle density of the reflected direction `wo` when `h` is sampled with
/// [`sample_visible_normal`]: `G1(wi) D(h) / (4 wi.z)`.
#[inline]
pub fn reflection_pdf(wi: Vec3, wo: Vec3, alpha: f32) -> f32 {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    let h = (wi + wo).normalize();
    ggx_g1(wi, alpha) * ggx_d(h, alpha) / (4.0 * wi.z)
}

/// Samples a reflected direction: `(wo, pdf)`, or `None` when it falls below the horizon.
#[inline]
pub fn sample_reflection(wi: Vec3, alpha: f32, u: Vec2) -> Option<(Vec3, f32)> {
    let h = sample_visible_normal(wi, alpha, u);
    let wo = 2.0 * wi.dot(h) * h - wi;
    if wo.z <= 0.0 {
        return None;
    }
    let pdf = reflection_pdf(wi, wo, alpha);
    (pdf > 0.0 && pdf.is_finite()).then_some((wo, pdf))
}

/// A rough conductor: `f = F(wi·h) D(h) G2 / (4 cos θi cos θo)`, Schlick `F0` = base colour.
#[derive(Clone, Copy, Debug)]
pub struct RoughConductor {
    pub f0: Vec3,
    pub alpha: f32,
}

impl RoughConductor {
    pub fn new(f0: Vec3, alpha: f32) -> Self {
        RoughConductor {
            f0,
            alpha: alpha.max(super::DELTA_ALPHA),
        }
    }
}

impl Bsdf for RoughConductor {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, _u1: f32) -> Vec3 {
        if rec.wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let Some((wo, pdf)) = sample_reflection(rec.wi, self.alpha, u) else {
            return Vec3::ZERO;
        };
        rec.wo = wo;
        rec.pdf = pdf;
        rec.eta = 1.0;
        rec.measure = Measure::SolidAngle;
        let h = (rec.wi + wo).normalize();
        // f cos / pdf = F G2 / G1(wi)
        fresnel::schlick(self.f0, rec.wi.dot(h)) * ggx_g2(rec.wi, wo, self.alpha)
            / ggx_g1(rec.wi, self.alpha)
    }

    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        let (wi, wo) = (rec.wi, rec.wo);
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Vec3::ZERO;
        }
        let h = (wi + wo).normalize();
        fresnel::schlick(self.f0, wi.dot(h)) * ggx_d(h, self.alpha) * ggx_g2(wi, wo, self.alpha)
            / (4.0 * wi.z * wo.z)
    }

    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        reflection_pdf(rec.wi, rec.wo, self.alpha)
    }

    fn is_delta(&self) -> bool {
        false
    }
}
