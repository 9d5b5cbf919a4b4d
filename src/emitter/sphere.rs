//! Point and spot lights with a radius (Blender's `shadow_soft_size`), in the two shapes of
//! Cycles 4.x/5.x, both of radiance `L = I / (π r²)` so that a distant light keeps the
//! intensity `I` of the point light:
//!
//! - **sphere** (Blender's "Soft Falloff" off): a ball of radius `r`. Seen from outside, its
//!   visible cap is the cone of half-angle `α`, `sin α = r / d`, sampled uniformly by solid
//!   angle (density `1 / (2π (1 - cos α))`); a spot samples the smaller of that cone and the
//!   cone of directions its beam can arrive from. Inside the ball, directions are uniform on
//!   the sphere and the spot's falloff does not apply (as in Cycles).
//! - **disk** (Soft Falloff on, Blender's default): a disk of radius `r` centred on the light
//!   and always facing the lit point, sampled uniformly by area. Near a surface it sinks below
//!   that surface's horizon gradually, hence the name.
//!
//! A spot's falloff is evaluated on the direction the light travels from the sampled point.

use super::spot::{spot_attenuation, spot_cos_outer};
use super::{Emitter, EmitterQueryRecord, emitted_luminance};
use crate::frame::Frame;
use crate::sampling::{square_to_uniform_disk, square_to_uniform_sphere};
use crate::scene::{Scene, SpotFalloff};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct SphereLight {
    pub position: Vec3,
    /// `> 0`.
    pub radius: f32,
    /// Radiance of the shape, W/(m² sr).
    pub radiance: Vec3,
    /// The ball (soft falloff off); otherwise the disk facing the lit point.
    pub sphere: bool,
    /// A spot's axis (unit, pointing away from the light) and falloff.
    pub spot: Option<(Vec3, SpotFalloff)>,
}

/// `1 - cos α` for `sin² α = s2` without cancellation for small angles.
#[inline]
pub fn one_minus_cos_from_sin2(s2: f32) -> f32 {
    let s2 = s2.clamp(0.0, 1.0);
    s2 / (1.0 + (1.0 - s2).sqrt())
}

/// A uniform direction in the cone around the unit `axis` with `1 - cos(half-angle)` =
/// `omc` (given directly, so that cones of a few micro-radians keep their shape in f32).
/// Density `1 / (2π omc)` per steradian.
#[inline]
pub fn sample_cone(axis: Vec3, omc: f32, u: Vec2) -> Vec3 {
    let t = u.x * omc;
    let cos = 1.0 - t;
    let sin = (t * (2.0 - t)).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let (sin_phi, cos_phi) = crate::trig::sin_cos(phi);
    Frame::from_normal(axis).to_world(Vec3::new(sin * cos_phi, sin * sin_phi, cos))
}

/// Whether the unit `w` lies in the cone around the unit `axis` with `1 - cos` = `omc`.
#[inline]
pub fn in_cone(axis: Vec3, omc: f32, w: Vec3) -> bool {
    // 1 - cos θ = |w - axis|² / 2, exact for small angles.
    0.5 * (w - axis).length_squared() <= omc
}

/// Nearest intersection `t ∈ (0, tmax)` of the ray `o + t d` (unit `d`) with the sphere.
#[inline]
pub fn ray_sphere(o: Vec3, d: Vec3, tmax: f32, c: Vec3, r: f32) -> Option<f32> {
    let oc = c - o;
    let d2 = oc.length_squared();
    let r2 = r * r;
    let tc = oc.dot(d);
    if d2 > r2 && tc < 0.0 {
        return None;
    }
    // Squared distance from the centre to the ray's line, computed from the perpendicular
    // (not as d2 - tc², which cancels for distant spheres).
    let h2 = (oc - tc * d).length_squared();
    if h2 > r2 {
        return None;
    }
    let half = (r2 - h2).sqrt();
    let t = if d2 > r2 { tc - half } else { tc + half };
    (t > 0.0 && t < tmax).then_some(t)
}

impl SphereLight {
    /// `1 - cos` of the cone a spot's light can arrive from (around `-axis`), or 2 (every
    /// direction) for a point light.
    #[inline]
    fn spread_omc(&self) -> f32 {
        match &self.spot {
            Some((_, f)) => (1.0 - spot_cos_outer(f)).clamp(0.0, 2.0),
            None => 2.0,
        }
    }

    /// The spot's falloff for light leaving along the unit `w`; 1 for a point light.
    #[inline]
    fn attenuation(&self, w: Vec3) -> f32 {
        match &self.spot {
            Some((axis, f)) => spot_attenuation(f, *axis, w),
            None => 1.0,
        }
    }

    /// The sampling cone seen from `ref_p` outside the ball: `(axis, 1 - cos, by_spread)`.
    #[inline]
    fn cone(&self, ref_p: Vec3) -> Option<(Vec3, f32, bool)> {
        let d = self.position - ref_p;
        let d2 = d.length_squared();
        let r2 = self.radius * self.radius;
        if d2 <= r2 {
            return None;
        }
        let omc_ball = one_minus_cos_from_sin2(r2 / d2);
        let omc_spread = self.spread_omc();
        Some(match &self.spot {
            Some((axis, _)) if omc_spread < omc_ball => (-*axis, omc_spread, true),
            _ => (d / d2.sqrt(), omc_ball, false),
        })
    }

    /// The disk's unit normal towards `ref_p`, its distance, or `None` at the centre.
    #[inline]
    fn disk_normal(&self, ref_p: Vec3) -> Option<(Vec3, f32)> {
        let v = ref_p - self.position;
        let d = v.length();
        (d > 0.0 && d.is_finite()).then(|| (v / d, d))
    }

    /// Nearest hit `t ∈ (0, tmax)` of the ray `o + t d` (unit `d`) with the light's shape as
    /// that ray sees it, with the shape's normal there.
    pub fn intersect(&self, o: Vec3, d: Vec3, tmax: f32) -> Option<(f32, Vec3)> {
        if self.sphere {
            // (Cycles also ignores a spot's ball for rays leaving from inside it, away from
            // its centre; here they see its inside, as emitter sampling does.)
            let t = ray_sphere(o, d, tmax, self.position, self.radius)?;
            let n = ((o + d * t) - self.position).normalize_or_zero();
            return Some((t, n));
        }
        // The disk faces the ray's origin: rays away from the centre never meet it (which is
        // Cycles' one-sided test for spots).
        let (n, dist) = self.disk_normal(o)?;
        let cos = -d.dot(n);
        if cos <= 0.0 {
            return None;
        }
        let t = dist / cos;
        let p = o + d * t;
        ((p - self.position).length_squared() <= self.radius * self.radius && t < tmax)
            .then_some((t, n))
    }
}

impl Emitter for SphereLight {
    fn sample(&self, _scene: &Scene, rec: &mut EmitterQueryRecord, u: Vec2) -> Vec3 {
        let ref_p = rec.ref_p;
        if !self.sphere {
            let Some((n, _)) = self.disk_normal(ref_p) else {
                return Vec3::ZERO;
            };
            let f = Frame::from_normal(n);
            let a = square_to_uniform_disk(u) * self.radius;
            let p = self.position + f.s * a.x + f.t * a.y;
            let v = p - ref_p;
            let dist = v.length();
            if dist <= 0.0 || !dist.is_finite() {
                return Vec3::ZERO;
            }
            rec.p = p;
            rec.n = n;
            rec.ng = n;
            rec.wi = v / dist;
            rec.dist = dist;
            rec.pdf = self.pdf(_scene, rec);
            if rec.pdf <= 0.0 || !rec.pdf.is_finite() {
                return Vec3::ZERO;
            }
            return self.eval(_scene, rec) / rec.pdf;
        }
        let r = self.radius;
        let c = self.position;
        let (wi, t) = match self.cone(ref_p) {
            Some((axis, omc, by_spread)) => {
                let wi = sample_cone(axis, omc, u);
                let t = if by_spread {
                    match ray_sphere(ref_p, wi, f32::INFINITY, c, r) {
                        Some(t) => t,
                        None => return Vec3::ZERO,
                    }
                } else {
                    // Law of cosines on the triangle (ref_p, centre, hit): the near root.
                    let oc = c - ref_p;
                    let tc = oc.dot(wi);
                    let h2 = (oc - tc * wi).length_squared();
                    tc - (r * r - h2).max(0.0).sqrt()
                };
                (wi, t)
            }
            None => {
                // Inside the ball: uniform directions, the far root.
                let wi = square_to_uniform_sphere(u);
                let oc = c - ref_p;
                let tc = oc.dot(wi);
                let h2 = (oc - tc * wi).length_squared();
                (wi, tc + (r * r - h2).max(0.0).sqrt())
            }
        };
        // Put the point back on the sphere (for tiny radii the ray's end drifts off it).
        let n = (ref_p + wi * t - c).normalize_or_zero();
        if n == Vec3::ZERO || t.is_nan() || t <= 0.0 {
            return Vec3::ZERO;
        }
        let p = c + n * r;
        let v = p - ref_p;
        let dist = v.length();
        if dist <= 0.0 || !dist.is_finite() {
            return Vec3::ZERO;
        }
        rec.p = p;
        rec.n = n;
        rec.ng = n;
        rec.wi = wi;
        rec.dist = dist;
        rec.pdf = self.pdf(_scene, rec);
        if rec.pdf <= 0.0 || !rec.pdf.is_finite() {
            return Vec3::ZERO;
        }
        self.eval(_scene, rec) / rec.pdf
    }

    fn eval(&self, _scene: &Scene, rec: &EmitterQueryRecord) -> Vec3 {
        if self.sphere && (self.position - rec.ref_p).length_squared() <= self.radius * self.radius
        {
            // Inside the ball: no spot falloff (Cycles).
            return self.radiance;
        }
        self.radiance * self.attenuation(-rec.wi)
    }

    fn pdf(&self, _scene: &Scene, rec: &EmitterQueryRecord) -> f32 {
        if !self.sphere {
            let Some((n, _)) = self.disk_normal(rec.ref_p) else {
                return 0.0;
            };
            let cos = -n.dot(rec.wi);
            if cos <= 0.0 {
                return 0.0;
            }
            return rec.dist * rec.dist / (cos * PI * self.radius * self.radius);
        }
        match self.cone(rec.ref_p) {
            Some((axis, omc, by_spread)) => {
                if by_spread && !in_cone(axis, omc, rec.wi) {
                    0.0
                } else {
                    1.0 / (2.0 * PI * omc)
                }
            }
            None => 0.25 / PI,
        }
    }

    fn power(&self, _scene: &Scene, _r: f32) -> f32 {
        let intensity = emitted_luminance(self.radiance) * PI * self.radius * self.radius;
        match &self.spot {
            Some((_, f)) => 2.0 * PI * (1.0 - spot_cos_outer(f)).max(0.0) * intensity,
            None => 4.0 * PI * intensity,
        }
    }

    fn is_delta(&self) -> bool {
        false
    }
}
