//! Ideal (smooth) dielectric interface: Fresnel-weighted choice between specular reflection and
//! refraction, for rays entering (`wi.z > 0`) and leaving (`wi.z < 0`), with total internal
//! reflection.
//!
//! Matching Cycles (measured, docs/blender-units.md): each refraction is tinted by
//! `sqrt(base colour)`, so a ray through a closed solid is tinted by the base colour once, and no
//! `1/η²` radiance scaling is applied (for closed meshes it cancels anyway; it would only show
//! with open sheets or a camera inside glass).

use super::{Bsdf, BsdfQueryRecord, Measure, fresnel};
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    /// `η_inside / η_outside`.
    pub ior: f32,
    /// Per-refraction transmission tint: `sqrt(base colour)`.
    pub tint: Vec3,
}

impl Dielectric {
    pub fn new(ior: f32, tint: Vec3) -> Self {
        let ior = if ior.is_finite() && ior > 0.0 {
            ior
        } else {
            1.5
        };
        Dielectric {
            ior,
            tint: tint.max(Vec3::ZERO).map(f32::sqrt),
        }
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
            self.tint
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
