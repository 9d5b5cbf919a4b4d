//! Lambertian reflection: `f = albedo / π`, sampled with a cosine-weighted hemisphere.

use super::{Bsdf, BsdfQueryRecord, Measure};
use crate::sampling::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// A Lambertian reflector of the given albedo (reflects on the `+Z` side only, whichever side
/// the light comes from: as Cycles' diffuse closure, a mapped normal turned away from the
/// viewer still shades with its own cosine).
#[derive(Clone, Copy, Debug)]
pub struct Diffuse {
    pub albedo: Vec3,
}

impl Diffuse {
    pub fn new(albedo: Vec3) -> Self {
        Diffuse { albedo }
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
        // f cos / pdf = (albedo/π) cos / (cos/π)
        self.albedo
    }

    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        if rec.wo.z <= 0.0 {
            return Vec3::ZERO;
        }
        self.albedo * FRAC_1_PI
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
