//! Blender's Toon BSDF (Cycles' `bsdf_toon`, after OSL): a flat-shaded lobe of uniform
//! density in a cone, about the normal (Diffuse) or the mirror direction of `wi` (Glossy).
//!
//! With `size` and `smooth` in radians (the node's inputs times π/2) and `θ` the angle of
//! `wo` from the cone's axis, the intensity is 1 for `θ < size`, falls linearly to 0 over
//! `smooth`, and `f · cos θo = colour · intensity(θ) / (2π (1 - cos θmax))` with
//! `θmax = min(size + smooth, π/2)`: the lobe is sampled uniformly in that cone (density
//! `1 / (2π (1 - cos θmax))` per steradian), so a sample's weight is `colour · intensity`.
//! Both directions must lie above the surface (the frame is turned towards `wi`).

use super::{Bsdf, BsdfQueryRecord, Measure};
use crate::frame::Frame;
use crate::sampling::square_to_uniform_cone;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_PI_2, PI};

#[derive(Clone, Copy, Debug)]
pub struct Toon {
    pub color: Vec3,
    /// Full-intensity half-angle (radians).
    size: f32,
    /// Width of the linear fall-off beyond `size` (radians).
    smooth: f32,
    /// About the mirror direction (Glossy) rather than the normal (Diffuse).
    pub glossy: bool,
}

impl Toon {
    /// The node's Color, Size and Smooth (fractions of a right angle, clamped as Cycles
    /// clamps them), Diffuse or Glossy component.
    pub fn new(color: Vec3, size: f32, smooth: f32, glossy: bool) -> Toon {
        let size = if size.is_nan() {
            1e-5
        } else {
            size.clamp(1e-5, 1.0)
        };
        let smooth = if smooth.is_nan() {
            0.0
        } else {
            smooth.clamp(0.0, 1.0)
        };
        Toon {
            color,
            size: size * FRAC_PI_2,
            smooth: smooth * FRAC_PI_2,
            glossy,
        }
    }

    /// The cone's half-angle `θmax`.
    #[inline]
    fn cone(&self) -> f32 {
        (self.size + self.smooth).min(FRAC_PI_2)
    }

    /// Cycles' intensity at an angle inside the cone: 1 up to `size`, then linear to 0 at
    /// `size + smooth` (without a fall-off the cone is `size` itself, all of it at 1, so a
    /// direction on its rim is not lost to rounding).
    #[inline]
    fn intensity(&self, angle: f32) -> f32 {
        if angle < self.size || self.smooth == 0.0 {
            1.0
        } else {
            (1.0 - (angle - self.size) / self.smooth).max(0.0)
        }
    }

    /// The cone's density per steradian.
    #[inline]
    fn cone_pdf(&self) -> f32 {
        1.0 / (2.0 * PI * (1.0 - self.cone().cos()))
    }

    /// `(wi, wo)` turned to the side of `wi`, and the cone's axis there.
    #[inline]
    fn oriented(&self, rec: &BsdfQueryRecord) -> (Vec3, Vec3, Vec3) {
        let s = if rec.wi.z < 0.0 { -1.0 } else { 1.0 };
        let (wi, wo) = (
            rec.wi * Vec3::new(1.0, 1.0, s),
            rec.wo * Vec3::new(1.0, 1.0, s),
        );
        let axis = if self.glossy {
            Vec3::new(-wi.x, -wi.y, wi.z)
        } else {
            Vec3::Z
        };
        (wi, wo, axis)
    }

    /// `(f · cos θo, pdf)` of a pair.
    fn eval_cos_pdf(&self, rec: &BsdfQueryRecord) -> (f32, f32) {
        let (wi, wo, axis) = self.oriented(rec);
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return (0.0, 0.0);
        }
        // Inside the cone in cosines, with the slack of the sampler's rotation into the frame
        // (a sampled direction on the rim must not fall outside by rounding).
        let (cos, cos_max) = (axis.dot(wo), self.cone().cos());
        if cos < cos_max - 1e-6 {
            return (0.0, 0.0);
        }
        let angle = cos.clamp(cos_max, 1.0).acos().min(self.cone());
        let pdf = self.cone_pdf();
        (pdf * self.intensity(angle), pdf)
    }
}

impl Bsdf for Toon {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, _u1: f32) -> Vec3 {
        let s = if rec.wi.z < 0.0 { -1.0 } else { 1.0 };
        let (wi, _, axis) = self.oriented(rec);
        if wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let cos_max = self.cone().cos();
        let local = square_to_uniform_cone(u, cos_max);
        let wo = Frame::from_normal(axis).to_world(local);
        if wo.z <= 0.0 {
            return Vec3::ZERO;
        }
        rec.wo = wo * Vec3::new(1.0, 1.0, s);
        rec.eta = 1.0;
        rec.measure = Measure::SolidAngle;
        // The intensity from the direction as stored, as `eval` finds it (not from the cone's
        // own coordinate): weight and eval · cos / pdf agree to the last bit of the angle.
        let (f_cos, pdf) = self.eval_cos_pdf(rec);
        rec.pdf = pdf;
        if pdf == 0.0 {
            return Vec3::ZERO;
        }
        self.color * (f_cos / pdf)
    }

    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        let (f_cos, _) = self.eval_cos_pdf(rec);
        let cos = rec.wo.z.abs();
        if f_cos == 0.0 || cos == 0.0 {
            return Vec3::ZERO;
        }
        self.color * (f_cos / cos)
    }

    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        self.eval_cos_pdf(rec).1
    }

    fn is_delta(&self) -> bool {
        false
    }

    /// Diffuse Toon counts among Cycles' diffuse closures, Glossy Toon among the glossy ones.
    fn eval_split(&self, rec: &BsdfQueryRecord) -> [Vec3; 2] {
        if self.glossy {
            [Vec3::ZERO, self.eval(rec)]
        } else {
            [self.eval(rec), Vec3::ZERO]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_weight_is_eval_cos_over_pdf() {
        let u = [
            Vec2::new(0.3, 0.7),
            Vec2::new(0.9, 0.1),
            Vec2::new(0.05, 0.5),
        ];
        for glossy in [false, true] {
            for (size, smooth) in [(0.5, 0.0), (0.3, 0.4), (0.9, 0.5)] {
                let b = Toon::new(Vec3::new(0.8, 0.5, 0.2), size, smooth, glossy);
                let wi = Vec3::new(0.3, -0.2, 0.9).normalize();
                for &u in &u {
                    let mut rec = BsdfQueryRecord::new(wi);
                    let w = b.sample(&mut rec, u, 0.0);
                    if w == Vec3::ZERO {
                        continue;
                    }
                    let pair = BsdfQueryRecord::pair(wi, rec.wo);
                    let expect = b.eval(&pair) * rec.wo.z / b.pdf(&pair);
                    assert!((w - expect).abs().max_element() < 1e-4, "{w} vs {expect}");
                    assert!((rec.pdf - b.pdf(&pair)).abs() < 1e-5);
                }
            }
        }
    }

    #[test]
    fn intensity_is_flat_then_linear_then_zero() {
        let b = Toon::new(Vec3::ONE, 0.5, 0.2, false);
        let (size, smooth) = (0.5 * FRAC_PI_2, 0.2 * FRAC_PI_2);
        assert_eq!(b.intensity(0.9 * size), 1.0);
        assert!((b.intensity(size + 0.5 * smooth) - 0.5).abs() < 1e-5);
        assert!(b.intensity(size + smooth) < 1e-6);
        // From below: the same as from above, mirrored.
        let wi = Vec3::new(0.2, 0.1, 0.97).normalize();
        let wo = Vec3::new(-0.1, 0.3, 0.95).normalize();
        let flip = Vec3::new(1.0, 1.0, -1.0);
        let up = b.eval(&BsdfQueryRecord::pair(wi, wo));
        let down = b.eval(&BsdfQueryRecord::pair(wi * flip, wo * flip));
        assert_eq!(up, down);
        assert!(up.x > 0.0);
    }
}
