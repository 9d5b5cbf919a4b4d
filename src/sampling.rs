//! Warps from the unit square to common domains, their densities, and a discrete CDF.
//!
//! Every `square_to_*` function maps a uniform sample in `[0,1)²` to its domain; the matching
//! `*_pdf` gives the density of the result **with respect to the domain's own measure**
//! (solid angle for directions, area for points).

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// Uniform point on the unit disk (Shirley–Chiu concentric map). Density `1/π` per unit area.
#[inline]
pub fn square_to_uniform_disk(u: Vec2) -> Vec2 {
    let a = 2.0 * u - Vec2::ONE;
    if a.x == 0.0 && a.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, phi) = if a.x.abs() > a.y.abs() {
        (a.x, PI / 4.0 * (a.y / a.x))
    } else {
        (a.y, PI / 2.0 - PI / 4.0 * (a.x / a.y))
    };
    let (s, c) = crate::trig::sin_cos(phi);
    Vec2::new(r * c, r * s)
}

/// Cosine-weighted direction on the +Z hemisphere. Density `cos θ / π` per steradian.
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = square_to_uniform_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Density of [`square_to_cosine_hemisphere`] (per steradian).
#[inline]
pub fn square_to_cosine_hemisphere_pdf(v: Vec3) -> f32 {
    if v.z > 0.0 { v.z * FRAC_1_PI } else { 0.0 }
}

/// Uniform direction on the unit sphere. Density `1/(4π)` per steradian.
#[inline]
pub fn square_to_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let (s, c) = crate::trig::sin_cos(phi);
    Vec3::new(r * c, r * s, z)
}

/// Density of [`square_to_uniform_sphere`].
#[inline]
pub fn square_to_uniform_sphere_pdf() -> f32 {
    0.25 * FRAC_1_PI
}

/// Uniform direction in the cone around +Z of half-angle `acos(cos_max)`.
/// Density `1 / (2π (1 - cos_max))` per steradian.
#[inline]
pub fn square_to_uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    let z = 1.0 - u.x * (1.0 - cos_max);
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let (s, c) = crate::trig::sin_cos(phi);
    Vec3::new(r * c, r * s, z)
}

/// Density of [`square_to_uniform_cone`] for a direction inside the cone.
#[inline]
pub fn square_to_uniform_cone_pdf(v: Vec3, cos_max: f32) -> f32 {
    if v.z >= cos_max && cos_max < 1.0 {
        1.0 / (2.0 * PI * (1.0 - cos_max))
    } else {
        0.0
    }
}

/// Uniform barycentric coordinates `(u, v)` on a triangle; the third is `w = 1 - u - v`.
/// Uniform in area: density `1/A` on a triangle of area `A`.
#[inline]
pub fn square_to_uniform_triangle(s: Vec2) -> Vec2 {
    let su = s.x.sqrt();
    Vec2::new(1.0 - su, s.y * su)
}

/// Uniform point in the regular polygon of `corners ≥ 3` vertices inscribed in the unit circle,
/// its vertices at angles `rotation ± π/corners + 2πk/corners` (an edge's midpoint at angle
/// `rotation`), as Cycles' `regular_polygon_sample`: `u.x` picks one of the `corners`
/// triangles fanning from the centre and is reused, with `u.y`, for a uniform point in it.
/// Density `1/A` per unit area, `A = corners/2 · sin(2π/corners)`.
#[inline]
pub fn square_to_regular_polygon(u: Vec2, corners: u32, rotation: f32) -> Vec2 {
    let n = corners as f32;
    let corner = (u.x * n).floor().min(n - 1.0);
    let t = square_to_uniform_triangle(Vec2::new(u.x * n - corner, u.y));
    // Barycentric weights of the triangle's two outer vertices (at angles ±π/n before
    // rotation); the centre takes the rest.
    let (a, b) = (t.x, t.y);
    let half = PI / n;
    let p = Vec2::new((a + b) * half.cos(), (a - b) * half.sin());
    let (s, c) = (rotation + corner * 2.0 * half).sin_cos();
    Vec2::new(c * p.x - s * p.y, s * p.x + c * p.y)
}

/// A binary choice made with one uniform number `u` in `[0, 1)`: the first part (`true`) with
/// probability `p`, when `u < p`. Also returns `u` rescaled to `[0, 1)` within the chosen
/// part, so the same number can drive a further choice.
#[inline]
pub fn pick(p: f32, u: f32) -> (bool, f32) {
    if u < p {
        (true, (u / p).min(1.0 - f32::EPSILON / 2.0))
    } else {
        (
            false,
            ((u - p) / (1.0 - p)).clamp(0.0, 1.0 - f32::EPSILON / 2.0),
        )
    }
}

/// A discrete distribution over `n` items proportional to non-negative weights (a CDF table).
#[derive(Clone, Debug, Default)]
pub struct DiscreteCdf {
    /// `cdf[i]` = sum of weights `[0, i)` normalised; `cdf.len() == n + 1`, `cdf[n] == 1`.
    cdf: Vec<f32>,
    /// The same table in double precision, for [`DiscreteCdf::sample_fine`].
    cdf64: Vec<f64>,
    sum: f64,
}

impl DiscreteCdf {
    /// Builds the table. Negative or non-finite weights count as zero. If every weight is zero
    /// the distribution is empty ([`DiscreteCdf::is_empty`]).
    pub fn new(weights: impl IntoIterator<Item = f32>) -> DiscreteCdf {
        let mut acc = 0.0f64;
        let mut cdf = vec![0.0f32];
        let mut raw = vec![0.0f64];
        for w in weights {
            let w = if w.is_finite() && w > 0.0 {
                w as f64
            } else {
                0.0
            };
            acc += w;
            raw.push(acc);
        }
        if acc > 0.0 {
            cdf.clear();
            cdf.extend(raw.iter().map(|c| (*c / acc) as f32));
            *cdf.last_mut().unwrap() = 1.0;
        } else {
            cdf = vec![0.0; raw.len()];
        }
        let cdf64 = if acc > 0.0 {
            let mut c: Vec<f64> = raw.iter().map(|c| c / acc).collect();
            *c.last_mut().unwrap() = 1.0;
            c
        } else {
            vec![0.0; raw.len()]
        };
        DiscreteCdf {
            cdf,
            cdf64,
            sum: acc,
        }
    }

    /// Number of items.
    pub fn len(&self) -> usize {
        self.cdf.len().saturating_sub(1)
    }

    /// True when no item has positive weight.
    pub fn is_empty(&self) -> bool {
        self.sum <= 0.0
    }

    /// The sum of the weights.
    pub fn sum(&self) -> f32 {
        self.sum as f32
    }

    /// Probability of item `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.cdf[i + 1] - self.cdf[i]
    }

    /// Samples an item: returns `(index, pmf)` for `u` in `[0,1)`. Items of zero weight are
    /// never returned. Must not be called on an empty distribution.
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let (i, _) = self.sample_reuse(u);
        (i, self.pmf(i))
    }

    /// Like [`DiscreteCdf::sample`] but returns `u` rescaled to `[0,1)` within the chosen item,
    /// so the same random number can drive a further choice.
    #[inline]
    pub fn sample_reuse(&self, u: f32) -> (usize, f32) {
        let n = self.len();
        // First index with cdf[i+1] > u.
        let i = self.cdf[1..].partition_point(|&c| c <= u).min(n - 1);
        // Skip zero-weight items at the end that rounding could land on.
        let mut i = i;
        while self.pmf(i) <= 0.0 && i > 0 {
            i -= 1;
        }
        let p = self.pmf(i);
        let r = if p > 0.0 {
            ((u - self.cdf[i]) / p).clamp(0.0, 1.0 - f32::EPSILON / 2.0)
        } else {
            0.0
        };
        (i, r)
    }
}

impl DiscreteCdf {
    /// Probability of item `i` in double precision.
    #[inline]
    pub fn pmf_fine(&self, i: usize) -> f64 {
        self.cdf64[i + 1] - self.cdf64[i]
    }

    /// Like [`DiscreteCdf::sample_reuse`] with a uniform `u` in `[0,1)` of up to 53 bits, for
    /// distributions over so many items (the triangles of a dense emissive mesh) that a 24-bit
    /// `f32` cannot resolve their probabilities. Returns `(index, u rescaled to [0,1))`.
    #[inline]
    pub fn sample_fine(&self, u: f64) -> (usize, f64) {
        let n = self.len();
        if n == 1 {
            return (0, u.clamp(0.0, 1.0 - f64::EPSILON));
        }
        let mut i = self.cdf64[1..].partition_point(|&c| c <= u).min(n - 1);
        while self.pmf_fine(i) <= 0.0 && i > 0 {
            i -= 1;
        }
        let p = self.pmf_fine(i);
        let r = if p > 0.0 {
            ((u - self.cdf64[i]) / p).clamp(0.0, 1.0 - f64::EPSILON)
        } else {
            0.0
        };
        (i, r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discrete_cdf_pmf_and_bounds() {
        let d = DiscreteCdf::new([1.0, 0.0, 3.0]);
        assert_eq!(d.len(), 3);
        assert!((d.pmf(0) - 0.25).abs() < 1e-6);
        assert_eq!(d.pmf(1), 0.0);
        assert_eq!(d.sample(0.0).0, 0);
        assert_eq!(d.sample(0.2499).0, 0);
        assert_eq!(d.sample(0.25).0, 2);
        assert_eq!(d.sample(0.999_999_9).0, 2);
        let (i, r) = d.sample_reuse(0.625);
        assert_eq!(i, 2);
        assert!((r - 0.5).abs() < 1e-5);
        assert!(DiscreteCdf::new([0.0, f32::NAN]).is_empty());
    }

    #[test]
    fn triangle_warp_stays_inside() {
        for i in 0..64 {
            for j in 0..64 {
                let b = square_to_uniform_triangle(Vec2::new(i as f32 / 63.0, j as f32 / 63.0));
                assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-6);
            }
        }
    }
}
