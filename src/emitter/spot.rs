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
        SpotFalloff::Cycles { cos_half, smooth }
        | SpotFalloff::CyclesScaled {
            cos_half, smooth, ..
        } => {
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

/// A spot's falloff for light leaving it along the unit world direction `w`, `axis` the unit
/// beam axis.
#[inline]
pub fn spot_attenuation(falloff: &SpotFalloff, axis: Vec3, w: Vec3) -> f32 {
    let cos = match falloff {
        SpotFalloff::CyclesScaled { local, .. } => (*local * w).normalize_or_zero().z,
        _ => axis.dot(w),
    };
    spot_falloff(falloff, cos)
}

/// The cosine of a spot's outer half-angle: no light beyond it (for a scaled spot, of the
/// widest direction of its cone).
#[inline]
pub fn spot_cos_outer(falloff: &SpotFalloff) -> f32 {
    match *falloff {
        SpotFalloff::Gltf { cos_outer, .. } => cos_outer,
        SpotFalloff::Cycles { cos_half, .. } => cos_half,
        SpotFalloff::CyclesScaled {
            cos_half, local, ..
        } => {
            // A row of `local` has length 1/scale: tan θ' = tan θ · max(sx, sy) / sz.
            let (sx, sy) = (1.0 / local.row(0).length(), 1.0 / local.row(1).length());
            let sz = 1.0 / local.row(2).length();
            let sin = (1.0 - cos_half * cos_half).max(0.0).sqrt();
            let (x, z) = (sin * sx.max(sy), cos_half * sz);
            let c = z / (x * x + z * z).sqrt();
            if c.is_finite() { c } else { -1.0 }
        }
    }
}

/// Hermite smoothstep on `[0, 1]`.
#[inline]
fn smoothstep01(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

impl SpotLight {
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
        self.intensity * spot_attenuation(&self.falloff, self.direction, -rec.wi) / dist2
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

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat3;

    /// The falloff of a spot scaled by `s` along its x, y and beam axes (beam along +Z).
    fn scaled(s: Vec3) -> SpotFalloff {
        let cos_half = 0.8f32;
        SpotFalloff::CyclesScaled {
            cos_half,
            smooth: (1.0 - cos_half) * 0.3,
            local: Mat3::from_diagonal(1.0 / s),
        }
    }

    #[test]
    fn a_scaled_cone_stretches_as_its_scale_and_stays_inside_its_widest_cone() {
        let plain = SpotFalloff::Cycles {
            cos_half: 0.8,
            smooth: 0.2 * 0.3,
        };
        // An even scale changes nothing.
        for w in [Vec3::new(0.3, 0.1, 1.0), Vec3::new(-0.5, 0.4, 1.0)] {
            let w = w.normalize();
            let (a, b) = (
                spot_attenuation(&scaled(Vec3::splat(2.0)), Vec3::Z, w),
                spot_attenuation(&plain, Vec3::Z, w),
            );
            assert!((a - b).abs() < 1e-5, "{a} {b}");
        }
        // Twice as wide along x: a direction at 1.5 times the cone's half-angle tangent is lit
        // along x, dark along y.
        let tan = (1.0f32 - 0.64).sqrt() / 0.8;
        let f = scaled(Vec3::new(2.0, 1.0, 1.0));
        assert!(spot_attenuation(&f, Vec3::Z, Vec3::new(1.5 * tan, 0.0, 1.0).normalize()) > 0.0);
        assert_eq!(
            spot_attenuation(&f, Vec3::Z, Vec3::new(0.0, 1.5 * tan, 1.0).normalize()),
            0.0
        );
        // No light beyond the widest cone (what light choice and sampling bound it by).
        let cos_outer = spot_cos_outer(&f);
        let mut lit_outside = 0;
        for i in 0..2000 {
            let (a, z) = (i as f32 * 2.399, 1.0 - (i as f32 + 0.5) / 1000.0);
            let r = (1.0 - z * z).max(0.0).sqrt();
            let w = Vec3::new(r * a.cos(), r * a.sin(), z);
            if spot_attenuation(&f, Vec3::Z, w) > 0.0 && w.z < cos_outer - 1e-5 {
                lit_outside += 1;
            }
        }
        assert_eq!(lit_outside, 0);
        assert!(
            cos_outer < 0.8,
            "the widest cone is wider than the unscaled one"
        );
    }
}
