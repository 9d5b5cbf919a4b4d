//! Blender's area lights as Cycles renders them: a rectangle or an ellipse emitting from its
//! front side only, radiance `L = P / (π A)`, collimated by the light's `spread`.
//!
//! **Spread** (Cycles' soft-box grid model): light leaving at angle `θ` from the normal is
//! scaled by `max(0, tan(s/2) - tan θ) / (tan(s/2) - s/2)`, `s` the spread; the factor keeps
//! the emitted power (`∫ f cos dω = π` over the hemisphere). A point at height `h` in front of
//! the light therefore only sees the disk of radius `h tan(s/2)` around its foot on the light's
//! plane: sampling is restricted to the light ∩ that disk's bounding square. A spread of 0 is a
//! parallel beam (a delta light): a point receives `π L` = `P / A` from its foot if the foot
//! lies on the light.
//!
//! **Sampling**: rectangles (and the square regions of a spread) by solid angle, with the
//! spherical-rectangle map of Ureña, Fajardo and King (2013); an ellipse by area, or by the
//! solid angle of its spread-clamped bounding rectangle when that is smaller (points outside the
//! ellipse are rejected). Tiny or grazing rectangles fall back to uniform area sampling, whose
//! density is exact at any size.

use super::{Emitter, EmitterQueryRecord, emitted_luminance};
use crate::sampling::square_to_uniform_disk;
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Half-spreads below this are a parallel beam (Cycles: `tan(s/2) == 0`).
pub const COLLIMATED_HALF_SPREAD: f32 = 1e-4;

#[derive(Clone, Debug)]
pub struct AreaLight {
    pub center: Vec3,
    /// Orthonormal in-plane axes and the unit normal of the emitting side.
    pub axis_u: Vec3,
    pub axis_v: Vec3,
    pub normal: Vec3,
    /// Half extents along `axis_u`, `axis_v` (the semi-axes of an ellipse).
    pub half_u: f32,
    pub half_v: f32,
    pub ellipse: bool,
    /// Radiance along the normal, W/(m² sr).
    pub radiance: Vec3,
    pub area: f32,
    /// `tan(spread/2)` and the normalisation `1 / (tan(s/2) - s/2)`; `None` = Lambertian.
    spread: Option<(f32, f32)>,
    collimated: bool,
}

/// A region of the light's plane that sampling draws from: `[u0, u1] × [v0, v1]` in the
/// light's `(axis_u, axis_v)` coordinates around its centre.
#[derive(Clone, Copy, Debug)]
struct Region {
    u0: f32,
    u1: f32,
    v0: f32,
    v1: f32,
    /// Sampled as the whole ellipse by area (otherwise as the rectangle, by solid angle).
    ellipse: bool,
}

/// A spherical rectangle as seen from a point: the rectangle `[x0, x1] × [y0, y1]` at signed
/// height `z0 < 0` in a frame centred on the point, with the quantities of Ureña et al.
struct SphericalRect {
    x0: f32,
    x1: f32,
    y0: f32,
    y1: f32,
    z0: f32,
    /// z components of the unit normals of the four planes through the point and each edge
    /// (edges y0, x1, y1, x0, in turn).
    nz: [f32; 4],
    /// The interior-angle terms `asin(-nz_i nz_{i+1})`; the solid angle is minus their sum
    /// (the paper's `Σ acos(...) - 2π`, without its cancellation for small rectangles).
    g: [f32; 4],
    solid_angle: f32,
}

impl SphericalRect {
    fn new(x0: f32, x1: f32, y0: f32, y1: f32, z0: f32) -> SphericalRect {
        let raw = [-y0, x1, y1, -x0];
        let nz = raw.map(|a| a / (a * a + z0 * z0).sqrt());
        let g = [0, 1, 2, 3].map(|i| (-nz[i] * nz[(i + 1) % 4]).clamp(-1.0, 1.0).asin());
        SphericalRect {
            x0,
            x1,
            y0,
            y1,
            z0,
            nz,
            g,
            solid_angle: -(g[0] + g[1] + g[2] + g[3]),
        }
    }

    /// Whether the single-precision solid angle is trustworthy (else: sample by area).
    fn usable(&self) -> bool {
        self.solid_angle > 1e-4 && self.nz.iter().any(|n| n * n <= 0.9999)
    }

    /// The point `(x, y)` (at height `z0`) for the uniform sample `u`.
    fn sample(&self, u: Vec2) -> (f32, f32) {
        // The azimuthal coordinate: the partial solid angle u.x · S fixes the angle of the
        // plane through the point that cuts the rectangle at x = xu.
        let (b0, b1) = (self.nz[0], self.nz[2]);
        let au = u.x * self.solid_angle + self.g[2] + self.g[3];
        let (s, c) = crate::trig::sin_cos(au);
        let fu = if s != 0.0 {
            (c * b0 + b1) / s
        } else {
            f32::MAX
        };
        let cu = (1.0 / (fu * fu + b0 * b0).sqrt())
            .copysign(fu)
            .clamp(-1.0, 1.0);
        let xu = (-(cu * self.z0) / (1.0 - cu * cu).sqrt().max(1e-7)).clamp(self.x0, self.x1);
        // Then y uniformly in the projected height seen along that cut.
        let d2 = xu * xu + self.z0 * self.z0;
        let h0 = self.y0 / (d2 + self.y0 * self.y0).sqrt();
        let h1 = self.y1 / (d2 + self.y1 * self.y1).sqrt();
        let hv = h0 + u.y * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-6 {
            hv * (d2 / (1.0 - hv2)).sqrt()
        } else {
            self.y1
        };
        (xu, yv.clamp(self.y0, self.y1))
    }
}

impl AreaLight {
    /// An area light; `spread` (radians) outside `[0, π]` or NaN means π (the caller warns).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        center: Vec3,
        axis_u: Vec3,
        axis_v: Vec3,
        normal: Vec3,
        size_u: f32,
        size_v: f32,
        ellipse: bool,
        radiance: Vec3,
        spread: f32,
    ) -> AreaLight {
        let area = size_u * size_v * if ellipse { PI / 4.0 } else { 1.0 };
        let half = if spread.is_finite() && (0.0..PI).contains(&spread) {
            0.5 * spread
        } else {
            0.5 * PI
        };
        let collimated = half < COLLIMATED_HALF_SPREAD;
        let spread = (!collimated && half < 0.5 * PI - 1e-6).then(|| {
            let t = half.tan();
            // 1 / (tan h - h), by its Taylor series 3 / h³ where the difference cancels.
            let norm = if half > 0.05 {
                1.0 / (t - half)
            } else {
                3.0 / (half * half * half)
            };
            (t, norm)
        });
        AreaLight {
            center,
            axis_u,
            axis_v,
            normal,
            half_u: 0.5 * size_u,
            half_v: 0.5 * size_v,
            ellipse,
            radiance,
            area,
            spread,
            collimated,
        }
    }

    /// Whether the in-plane point `(u, v)` lies on the light.
    #[inline]
    fn contains(&self, u: f32, v: f32) -> bool {
        if self.ellipse {
            let (a, b) = (u / self.half_u, v / self.half_v);
            a * a + b * b <= 1.0 + 1e-6
        } else {
            u.abs() <= self.half_u * (1.0 + 1e-6) && v.abs() <= self.half_v * (1.0 + 1e-6)
        }
    }

    /// The spread's factor for light leaving along the unit `w`.
    #[inline]
    fn spread_factor(&self, w: Vec3) -> f32 {
        let Some((tan_half, norm)) = self.spread else {
            return 1.0;
        };
        let cos = w.dot(self.normal);
        if cos <= 0.0 {
            return 0.0;
        }
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        ((tan_half - sin / cos) * norm).max(0.0)
    }

    /// Height of `p` in front of the light (negative behind it).
    #[inline]
    fn height(&self, p: Vec3) -> f32 {
        (p - self.center).dot(self.normal)
    }

    /// The region sampled from `ref_p` (in front of the light), or `None` when no point of
    /// the light can reach it.
    fn region(&self, ref_p: Vec3) -> Option<Region> {
        let (hu, hv) = (self.half_u, self.half_v);
        let whole = Region {
            u0: -hu,
            u1: hu,
            v0: -hv,
            v1: hv,
            ellipse: self.ellipse,
        };
        let Some((tan_half, _)) = self.spread else {
            return Some(whole);
        };
        let h = self.height(ref_p);
        let r = h * tan_half;
        let rel = ref_p - self.center;
        let (su, sv) = (rel.dot(self.axis_u), rel.dot(self.axis_v));
        let (u0, u1) = ((su - r).max(-hu), (su + r).min(hu));
        let (v0, v1) = ((sv - r).max(-hv), (sv + r).min(hv));
        if !(u0 < u1 && v0 < v1) {
            return None;
        }
        let rect = Region {
            u0,
            u1,
            v0,
            v1,
            ellipse: false,
        };
        if self.ellipse && (u1 - u0) * (v1 - v0) >= self.area {
            return Some(whole);
        }
        Some(rect)
    }

    /// The spherical rectangle of `region` seen from `ref_p`, in the frame `(axis_u, axis_v,
    /// -normal)` centred on `ref_p` (the light lies at negative height `z0` there).
    fn spherical(&self, ref_p: Vec3, g: &Region) -> SphericalRect {
        let rel = self.center - ref_p;
        let (xc, yc) = (rel.dot(self.axis_u), rel.dot(self.axis_v));
        // z = axis_u × axis_v; the light's plane lies at z0 = -height in the frame with z
        // pointing from the light towards ref_p, i.e. (axis_u, axis_v, ±normal).
        let z0 = -self.height(ref_p);
        SphericalRect::new(xc + g.u0, xc + g.u1, yc + g.v0, yc + g.v1, z0)
    }

    /// The point of the plane at in-plane coordinates `(u, v)`.
    #[inline]
    fn point(&self, u: f32, v: f32) -> Vec3 {
        self.center + self.axis_u * u + self.axis_v * v
    }

    /// Density (per unit area of the plane) of sampling `region` uniformly.
    #[inline]
    fn region_area(&self, g: &Region) -> f32 {
        if g.ellipse {
            self.area
        } else {
            (g.u1 - g.u0) * (g.v1 - g.v0)
        }
    }

    /// Nearest hit `t ∈ (0, tmax)` of the ray `o + t d` (unit `d`) with the light's front face.
    pub fn intersect(&self, o: Vec3, d: Vec3, tmax: f32) -> Option<f32> {
        if self.collimated {
            return None;
        }
        let cos = d.dot(self.normal);
        if cos >= 0.0 {
            return None;
        }
        let t = (self.center - o).dot(self.normal) / cos;
        if !(t > 0.0 && t < tmax) {
            return None;
        }
        let rel = o + d * t - self.center;
        self.contains(rel.dot(self.axis_u), rel.dot(self.axis_v))
            .then_some(t)
    }

    /// Half the spread: the largest angle from the normal light leaves at (a small angle for a
    /// parallel beam).
    pub fn half_spread(&self) -> f32 {
        match self.spread {
            _ if self.collimated => COLLIMATED_HALF_SPREAD,
            Some((tan_half, _)) => tan_half.atan(),
            None => 0.5 * PI,
        }
    }

    /// The corners of the light's bounding rectangle.
    pub fn corners(&self) -> [Vec3; 4] {
        let (u, v) = (self.axis_u * self.half_u, self.axis_v * self.half_v);
        let c = self.center;
        [c - u - v, c + u - v, c + u + v, c - u + v]
    }
}

impl Emitter for AreaLight {
    fn sample(&self, scene: &Scene, rec: &mut EmitterQueryRecord, u: Vec2) -> Vec3 {
        let ref_p = rec.ref_p;
        let h = self.height(ref_p);
        if h.is_nan() || h <= 0.0 {
            return Vec3::ZERO;
        }
        if self.collimated {
            let rel = ref_p - self.center;
            let (fu, fv) = (rel.dot(self.axis_u), rel.dot(self.axis_v));
            if !self.contains(fu, fv) {
                return Vec3::ZERO;
            }
            rec.p = self.point(fu, fv);
            rec.n = self.normal;
            rec.ng = self.normal;
            rec.wi = -self.normal;
            rec.dist = h;
            rec.pdf = 0.0;
            return self.radiance * PI;
        }
        let Some(g) = self.region(ref_p) else {
            return Vec3::ZERO;
        };
        let (pu, pv) = if g.ellipse {
            let a = square_to_uniform_disk(u);
            (a.x * self.half_u, a.y * self.half_v)
        } else {
            let s = self.spherical(ref_p, &g);
            if s.usable() {
                let rel = self.center - ref_p;
                let (xu, yv) = s.sample(u);
                (xu - rel.dot(self.axis_u), yv - rel.dot(self.axis_v))
            } else {
                (g.u0 + u.x * (g.u1 - g.u0), g.v0 + u.y * (g.v1 - g.v0))
            }
        };
        if !self.contains(pu, pv) {
            return Vec3::ZERO;
        }
        let p = self.point(pu, pv);
        let v = p - ref_p;
        let dist = v.length();
        if dist <= 0.0 || !dist.is_finite() {
            return Vec3::ZERO;
        }
        rec.p = p;
        rec.n = self.normal;
        rec.ng = self.normal;
        rec.wi = v / dist;
        rec.dist = dist;
        rec.pdf = self.pdf(scene, rec);
        if rec.pdf <= 0.0 || !rec.pdf.is_finite() {
            return Vec3::ZERO;
        }
        self.eval(scene, rec) / rec.pdf
    }

    fn eval(&self, _scene: &Scene, rec: &EmitterQueryRecord) -> Vec3 {
        if self.collimated || self.normal.dot(-rec.wi) <= 0.0 {
            return Vec3::ZERO;
        }
        self.radiance * self.spread_factor(-rec.wi)
    }

    fn pdf(&self, _scene: &Scene, rec: &EmitterQueryRecord) -> f32 {
        if self.collimated {
            return 0.0;
        }
        let h = self.height(rec.ref_p);
        let cos = -self.normal.dot(rec.wi);
        if h.is_nan() || h <= 0.0 || cos <= 0.0 {
            return 0.0;
        }
        let Some(g) = self.region(rec.ref_p) else {
            return 0.0;
        };
        let rel = rec.p - self.center;
        let (pu, pv) = (rel.dot(self.axis_u), rel.dot(self.axis_v));
        let eps = 1e-5 * (self.half_u + self.half_v);
        if !g.ellipse && (pu < g.u0 - eps || pu > g.u1 + eps || pv < g.v0 - eps || pv > g.v1 + eps)
        {
            return 0.0;
        }
        if !g.ellipse {
            let s = self.spherical(rec.ref_p, &g);
            if s.usable() {
                return 1.0 / s.solid_angle;
            }
        }
        rec.dist * rec.dist / (cos * self.region_area(&g))
    }

    fn power(&self, _scene: &Scene, _r: f32) -> f32 {
        emitted_luminance(self.radiance) * PI * self.area
    }

    fn is_delta(&self) -> bool {
        self.collimated
    }
}
