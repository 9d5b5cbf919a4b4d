//! Lambertian transmission (Blender's Translucent BSDF): `f = colour / π` for `wo` on the side
//! opposite `wi`, sampled with a cosine-weighted hemisphere there. Works from either side (the
//! frame is not flipped towards the viewer; Cycles flips its normal, which is the same thing).

use super::{Bsdf, BsdfQueryRecord, Measure};
use crate::sampling::square_to_cosine_hemisphere;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Copy, Debug)]
pub struct Translucent {
    pub color: Vec3,
}

impl Translucent {
    /// `color` = the node's Color input.
    pub fn new(color: Vec3) -> Self {
        Translucent { color }
    }
}

impl Bsdf for Translucent {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, _u1: f32) -> Vec3 {
        if rec.wi.z == 0.0 {
            return Vec3::ZERO;
        }
        let w = square_to_cosine_hemisphere(u);
        if w.z <= 0.0 {
            return Vec3::ZERO;
        }
        rec.wo = Vec3::new(w.x, w.y, -rec.wi.z.signum() * w.z);
        rec.eta = 1.0;
        rec.measure = Measure::SolidAngle;
        rec.pdf = w.z * FRAC_1_PI;
        self.color
    }

    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        if rec.wi.z * rec.wo.z < 0.0 {
            self.color * FRAC_1_PI
        } else {
            Vec3::ZERO
        }
    }

    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        if rec.wi.z * rec.wo.z < 0.0 {
            rec.wo.z.abs() * FRAC_1_PI
        } else {
            0.0
        }
    }

    fn is_delta(&self) -> bool {
        false
    }

    /// Cycles counts this lobe among the diffuse closures.
    fn eval_split(&self, rec: &BsdfQueryRecord) -> [Vec3; 2] {
        [self.eval(rec), Vec3::ZERO]
    }
}
