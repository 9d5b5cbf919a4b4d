//! Diffuse reflection: Lambertian, `f = albedo / π`, or with a roughness Blender's
//! Oren–Nayar (Fujii's improved form with the energy-preserving multiple-scattering term of
//! OpenPBR, as Cycles renders it); both sampled with a cosine-weighted hemisphere.

use super::{Bsdf, BsdfQueryRecord, Measure};
use crate::sampling::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, PI};

/// A diffuse reflector of the given albedo (reflects on the `+Z` side only, whichever side
/// the light comes from: as Cycles' diffuse closure, a mapped normal turned away from the
/// viewer still shades with its own cosine).
#[derive(Clone, Copy, Debug)]
pub struct Diffuse {
    pub albedo: Vec3,
    /// The rough model's constants; `None` for Lambert.
    oren_nayar: Option<OrenNayar>,
}

/// Oren–Nayar constants of one closure: `f = A + B·s(wi, wo)` for single scattering, with
/// `A = 1 / (π + σ (π/2 − 2/3))`, `B = σ A`, plus `ems · (1 − E(wi)) (1 − E(wo))` for the
/// energy lost to it (`E` the single-scattering directional albedo).
#[derive(Clone, Copy, Debug)]
struct OrenNayar {
    a: f32,
    b: f32,
    /// `ρ² E_avg / ((1 − E_avg) π (1 − ρ (1 − E_avg)))`, `ρ` the clamped colour.
    ems: Vec3,
}

impl OrenNayar {
    /// `E(μ) = π A + B G(μ)`: the single-scattering albedo at cosine `μ` (clamped to ≥ 0).
    #[inline]
    fn albedo(&self, mu: f32) -> f32 {
        self.a * PI + self.b * oren_nayar_g(mu.max(0.0))
    }
}

/// Fujii's `G(μ)`, with which `∫ s cos = G(μ)` (a Taylor expansion near grazing, where the
/// tangent misbehaves).
fn oren_nayar_g(mu: f32) -> f32 {
    if mu < 1e-6 {
        return (FRAC_PI_2 - 2.0 / 3.0) - mu;
    }
    let sin = (1.0 - mu * mu).max(0.0).sqrt();
    let theta = mu.clamp(-1.0, 1.0).acos();
    sin * (theta - 2.0 / 3.0 - sin * mu) + 2.0 / 3.0 * (sin / mu) * (1.0 - sin * sin * sin)
}

impl Diffuse {
    /// Lambertian reflection of `albedo`.
    pub fn new(albedo: Vec3) -> Self {
        Diffuse {
            albedo,
            oren_nayar: None,
        }
    }

    /// Oren–Nayar reflection of `albedo` at `roughness` (σ, clamped to `[0, 1]`; below 1e-5
    /// Lambert, as Cycles switches), whose multiple-scattering term takes the colour `color`
    /// (Cycles' closure carries the colour in its weight and passes it again for that term).
    pub fn oren_nayar(albedo: Vec3, roughness: f32, color: Vec3) -> Self {
        let sigma = if roughness.is_finite() {
            roughness.clamp(0.0, 1.0)
        } else {
            0.0
        };
        if sigma < 1e-5 {
            return Diffuse::new(albedo);
        }
        let a = 1.0 / (PI + sigma * (FRAC_PI_2 - 2.0 / 3.0));
        let b = sigma * a;
        let rho = color.clamp(Vec3::ZERO, Vec3::ONE);
        let e_avg = a * PI + ((2.0 * PI - 5.6) / 3.0) * b;
        let ems =
            FRAC_1_PI * rho * rho * (e_avg / (1.0 - e_avg)) / (Vec3::ONE - rho * (1.0 - e_avg));
        Diffuse {
            albedo,
            oren_nayar: Some(OrenNayar { a, b, ems }),
        }
    }

    /// `f` (per steradian) for local directions `wi` (towards the viewer) and `wo` (`wo.z > 0`).
    #[inline]
    fn value(&self, wi: Vec3, wo: Vec3) -> Vec3 {
        let Some(on) = &self.oren_nayar else {
            return self.albedo * FRAC_1_PI;
        };
        let (nl, nv) = (wo.z.max(0.0), wi.z.max(0.0));
        let mut t = wi.dot(wo) - nl * nv;
        if t > 0.0 {
            t /= nl.max(nv) + f32::MIN_POSITIVE;
        }
        let single = on.a + on.b * t;
        let multi = on.ems * (1.0 - on.albedo(nv)) * (1.0 - on.albedo(nl));
        self.albedo * (Vec3::splat(single) + multi)
    }
}

impl Bsdf for Diffuse {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, _u1: f32) -> Vec3 {
        rec.wo = square_to_cosine_hemisphere(u);
        rec.eta = 1.0;
        rec.measure = Measure::SolidAngle;
        rec.pdf = square_to_cosine_hemisphere_pdf(rec.wo);
        if rec.pdf <= 0.0 {
            return Vec3::ZERO;
        }
        // f cos / pdf = f π (Lambert: the albedo itself).
        match self.oren_nayar {
            None => self.albedo,
            Some(_) => self.value(rec.wi, rec.wo) * PI,
        }
    }

    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        if rec.wo.z <= 0.0 {
            return Vec3::ZERO;
        }
        self.value(rec.wi, rec.wo)
    }

    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        square_to_cosine_hemisphere_pdf(rec.wo)
    }

    fn is_delta(&self) -> bool {
        false
    }

    /// Cycles counts this lobe among the diffuse closures.
    fn eval_split(&self, rec: &BsdfQueryRecord) -> [Vec3; 2] {
        [self.eval(rec), Vec3::ZERO]
    }
}
