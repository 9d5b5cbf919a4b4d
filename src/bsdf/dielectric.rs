//! Ideal (smooth) dielectric interface: Fresnel-weighted choice between specular reflection and
//! refraction, for rays entering (`wi.z > 0`) and leaving (`wi.z < 0`), with total internal
//! reflection. Transmission is tinted by the base colour (glTF) and carries the radiance scale
//! `1/η²` (η = `η_t/η_i`), so radiance is compressed when entering a denser medium and expanded
//! again when leaving it.

use super::{Bsdf, BsdfQueryRecord, Measure, fresnel};
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    /// `η_inside / η_outside`.
    pub ior: f32,
    /// Transmission tint.
    pub tint: Vec3,
}

impl Dielectric {
    pub fn new(ior: f32, tint: Vec3) -> Self {
        let ior = if ior.is_finite() && ior > 0.0 {
            ior
        } else {
            1.5
        };
        Dielectric { ior, tint }
    }
}

impl Bsdf for Dielectric {
    fn sample(&self, rec: &mut BsdfQueryRecord, _u: Vec2, u1: f32) -> Vec3 {
        let cos_i = rec.wi.z;
        if cos_i == 0.0 {
            return Vec3::ZERO;
        }
        let (r, cos_t, eta) = fresnel::dielectric(cos_i, self.ior);
        rec.measure = Measure::Discrete;
        rec.pdf = 0.0;
        if u1 < r {
            rec.wo = Vec3::new(-rec.wi.x, -rec.wi.y, rec.wi.z);
            rec.eta = 1.0;
            Vec3::ONE
        } else {
            // Refraction: wo = -wi / eta + n (cos_i / eta - cos_t), with n on wi's side.
            let sign = cos_i.signum();
            let wo = Vec3::new(-rec.wi.x / eta, -rec.wi.y / eta, -sign * cos_t);
            rec.wo = wo.normalize();
            rec.eta = eta;
            self.tint / (eta * eta)
        }
    }

    fn eval(&self, _rec: &BsdfQueryRecord) -> Vec3 {
        Vec3::ZERO
    }

    fn pdf(&self, _rec: &BsdfQueryRecord) -> f32 {
        0.0
    }

    fn is_delta(&self) -> bool {
        true
    }
}
