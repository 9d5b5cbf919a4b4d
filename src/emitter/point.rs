//! Isotropic point light: radiant intensity `I` (W/sr); incident radiance integral `I / d²`.

use super::{Emitter, EmitterQueryRecord, emitted_luminance};
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct PointLight {
    pub position: Vec3,
    pub intensity: Vec3,
}

impl Emitter for PointLight {
    fn sample(&self, _scene: &Scene, rec: &mut EmitterQueryRecord, _u: Vec2) -> Vec3 {
        let d = self.position - rec.ref_p;
        let dist2 = d.length_squared();
        if dist2 <= 0.0 {
            return Vec3::ZERO;
        }
        rec.dist = dist2.sqrt();
        rec.wi = d / rec.dist;
        rec.p = self.position;
        rec.n = -rec.wi;
        rec.ng = -rec.wi;
        rec.pdf = 0.0;
        self.intensity / dist2
    }

    fn eval(&self, _scene: &Scene, _rec: &EmitterQueryRecord) -> Vec3 {
        Vec3::ZERO
    }

    fn pdf(&self, _scene: &Scene, _rec: &EmitterQueryRecord) -> f32 {
        0.0
    }

    fn power(&self, _scene: &Scene, _r: f32) -> f32 {
        4.0 * PI * emitted_luminance(self.intensity)
    }

    fn is_delta(&self) -> bool {
        true
    }
}
