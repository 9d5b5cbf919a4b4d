//! Perfect specular reflection off a conductor: `wo = (-wi.x, -wi.y, wi.z)`, weight = Schlick
//! Fresnel with `F0 = base colour` (white stays white at every angle).

use super::{Bsdf, BsdfQueryRecord, Measure, fresnel};
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct Mirror {
    pub f0: Vec3,
}

impl Mirror {
    pub fn new(f0: Vec3) -> Self {
        Mirror { f0 }
    }
}

impl Bsdf for Mirror {
    fn sample(&self, rec: &mut BsdfQueryRecord, _u: Vec2, _u1: f32) -> Vec3 {
        if rec.wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        rec.wo = Vec3::new(-rec.wi.x, -rec.wi.y, rec.wi.z);
        rec.eta = 1.0;
        rec.measure = Measure::Discrete;
        rec.pdf = 0.0;
        fresnel::schlick(self.f0, rec.wi.z)
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
