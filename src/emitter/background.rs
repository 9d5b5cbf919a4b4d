//! Constant background ("world") radiance `L` from every direction; sampled uniformly over the
//! sphere (density `1/(4π)` per steradian).

use super::{Emitter, EmitterQueryRecord, luminance};
use crate::sampling::{square_to_uniform_sphere, square_to_uniform_sphere_pdf};
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct Background {
    pub radiance: Vec3,
}

impl Emitter for Background {
    fn sample(&self, _scene: &Scene, rec: &mut EmitterQueryRecord, u: Vec2) -> Vec3 {
        rec.wi = square_to_uniform_sphere(u);
        rec.dist = f32::INFINITY;
        rec.pdf = square_to_uniform_sphere_pdf();
        self.radiance / rec.pdf
    }

    fn eval(&self, _scene: &Scene, _rec: &EmitterQueryRecord) -> Vec3 {
        self.radiance
    }

    fn pdf(&self, _scene: &Scene, _rec: &EmitterQueryRecord) -> f32 {
        square_to_uniform_sphere_pdf()
    }

    /// The irradiance `π L` of a facing surface over the cross-section `π r²` (as
    /// [`super::environment::Environment`]'s).
    fn power(&self, _scene: &Scene, r: f32) -> f32 {
        luminance(self.radiance) * PI * PI * r * r
    }

    fn is_delta(&self) -> bool {
        false
    }
}
