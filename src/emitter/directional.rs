//! Directional (sun) light: irradiance `E` (W/m²) on a surface facing it. A zero angular
//! diameter is a delta light; a positive one is a uniform cone of directions of half-angle
//! `angle/2` with radiance `E / Ω_cos`, Ω_cos = π sin²(angle/2), the cone's projected solid angle.

use super::{Emitter, EmitterQueryRecord, emitted_luminance};
use crate::frame::Frame;
use crate::sampling::{square_to_uniform_cone, square_to_uniform_cone_pdf};
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct Directional {
    /// Unit direction the light travels in.
    pub direction: Vec3,
    pub irradiance: Vec3,
    /// `cos(angle / 2)`; 1 for a delta light.
    pub cos_half: f32,
}

impl Directional {
    pub fn new(direction: Vec3, irradiance: Vec3, angle: f32) -> Self {
        let half = (angle * 0.5).clamp(0.0, PI * 0.5);
        Directional {
            direction: direction.normalize(),
            irradiance,
            cos_half: if half < 1e-4 { 1.0 } else { half.cos() },
        }
    }

    fn radiance(&self) -> Vec3 {
        let sin2 = 1.0 - self.cos_half * self.cos_half;
        self.irradiance / (PI * sin2)
    }
}

impl Emitter for Directional {
    fn sample(&self, _scene: &Scene, rec: &mut EmitterQueryRecord, u: Vec2) -> Vec3 {
        rec.dist = f32::INFINITY;
        if self.cos_half >= 1.0 {
            rec.wi = -self.direction;
            rec.pdf = 0.0;
            return self.irradiance;
        }
        let frame = Frame::from_normal(-self.direction);
        let local = square_to_uniform_cone(u, self.cos_half);
        rec.wi = frame.to_world(local);
        rec.pdf = square_to_uniform_cone_pdf(local, self.cos_half);
        if rec.pdf <= 0.0 {
            return Vec3::ZERO;
        }
        self.radiance() / rec.pdf
    }

    fn eval(&self, _scene: &Scene, rec: &EmitterQueryRecord) -> Vec3 {
        if self.cos_half < 1.0 && rec.wi.dot(-self.direction) >= self.cos_half {
            self.radiance()
        } else {
            Vec3::ZERO
        }
    }

    fn pdf(&self, _scene: &Scene, rec: &EmitterQueryRecord) -> f32 {
        if self.cos_half >= 1.0 {
            return 0.0;
        }
        let frame = Frame::from_normal(-self.direction);
        square_to_uniform_cone_pdf(frame.to_local(rec.wi), self.cos_half)
    }

    fn power(&self, _scene: &Scene, r: f32) -> f32 {
        emitted_luminance(self.irradiance) * PI * r * r
    }

    fn is_delta(&self) -> bool {
        self.cos_half >= 1.0
    }
}
