//! Spot light: a point light whose intensity `I` (W/sr) is scaled by an angular falloff around
//! its axis (glTF's quadratic ramp, or Cycles' smoothstep of the blend region).

use super::{Emitter, EmitterQueryRecord, emitted_luminance};
use crate::scene::{Scene, SpotFalloff};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct SpotLight {
    pub position: Vec3,
    /// Unit axis, pointing away from the light.
    pub direction: Vec3,
    pub intensity: Vec3,
    pub falloff: SpotFalloff,
}

/// A spot's falloff factor for a direction at cosine `cos` from its axis.
#[inline]
pub fn spot_falloff(falloff: &SpotFalloff, cos: f32) -> f32 {
    match *falloff {
        SpotFalloff::Gltf {
            cos_inner,
            cos_outer,
        } => {
            if cos <= cos_outer {
                0.0
            } else if cos >= cos_inner || cos_inner <= cos_outer {
                1.0
            } else {
                let t = (cos - cos_outer) / (cos_inner - cos_outer);
                t * t
            }
        }
        SpotFalloff::Cycles { cos_half, smooth } => {
            if cos <= cos_half {
                0.0
            } else if smooth <= 0.0 {
                1.0
            } else {
                smoothstep01((cos - cos_half) / smooth)
            }
        }
    }
}

/// The cosine of a spot's outer half-angle: no light beyond it.
#[inline]
pub fn spot_cos_outer(falloff: &SpotFalloff) -> f32 {
    match *falloff {
        SpotFalloff::Gltf { cos_outer, .. } => cos_outer,
        SpotFalloff::Cycles { cos_half, .. } => cos_half,
    }
}

/// Hermite smoothstep on `[0, 1]`.
#[inline]
fn smoothstep01(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

impl SpotLight {
    /// Falloff factor for a direction at cosine `cos` from the axis.
    #[inline]
    pub fn falloff(&self, cos: f32) -> f32 {
        spot_falloff(&self.falloff, cos)
    }

    fn cos_outer(&self) -> f32 {
        spot_cos_outer(&self.falloff)
    }
}

impl Emitter for SpotLight {
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
        self.intensity * self.falloff(self.direction.dot(-rec.wi)) / dist2
    }

    fn eval(&self, _scene: &Scene, _rec: &EmitterQueryRecord) -> Vec3 {
        Vec3::ZERO
    }

    fn pdf(&self, _scene: &Scene, _rec: &EmitterQueryRecord) -> f32 {
        0.0
    }

    fn power(&self, _scene: &Scene, _r: f32) -> f32 {
        2.0 * PI * (1.0 - self.cos_outer()).max(0.0) * emitted_luminance(self.intensity)
    }

    fn is_delta(&self) -> bool {
        true
    }
}
