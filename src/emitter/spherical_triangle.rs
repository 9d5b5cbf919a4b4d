//! A triangle as seen from a point: the spherical triangle of the directions towards it, and
//! directions drawn uniformly over it (Arvo 1995, "Stratified sampling of spherical
//! triangles"), density `1/Ω` per unit solid angle.
//!
//! Area sampling weighs a sample by `d² / cos θ_l`, which varies without bound over a triangle
//! that is large against its distance (a wall beside a ceiling light); uniform directions
//! leave only the cosines at the receiver and the emission to vary.

use glam::{Vec2, Vec3};

/// The directions from a point towards a triangle's vertices (unit, world space, pointing
/// away from the point) and the solid angle `Ω` (steradians) the triangle subtends.
#[derive(Clone, Copy, Debug)]
pub struct SphericalTriangle {
    a: Vec3,
    b: Vec3,
    c: Vec3,
    omega: f32,
}

impl SphericalTriangle {
    /// The spherical triangle of `v` seen from `p`, or `None` when the directions are too
    /// close to one plane (`|a · (b × c)| ≤ 1e-4`: a tiny or edge-on triangle, or `p` in its
    /// plane), where single precision loses the solid angle and area sampling does as well.
    #[inline]
    pub fn new(p: Vec3, v: [Vec3; 3]) -> Option<SphericalTriangle> {
        let a = (v[0] - p).normalize_or_zero();
        let b = (v[1] - p).normalize_or_zero();
        let c = (v[2] - p).normalize_or_zero();
        // Van Oosterom and Strackee: tan(Ω/2) = |a · (b × c)| / (1 + a·b + b·c + c·a), which
        // stays accurate for small triangles where the angle excess α + β + γ − π cancels.
        let triple = a.dot(b.cross(c)).abs();
        // (NaN directions fail the test too.)
        if triple.is_nan() || triple <= 1e-4 {
            return None;
        }
        let omega = 2.0 * triple.atan2(1.0 + a.dot(b) + b.dot(c) + c.dot(a));
        omega
            .is_finite()
            .then_some(SphericalTriangle { a, b, c, omega })
    }

    /// The solid angle `Ω` in steradians.
    #[inline]
    pub fn solid_angle(&self) -> f32 {
        self.omega
    }

    /// A direction uniform over the spherical triangle for `u` in `[0, 1)²`: `u.x` fixes the
    /// area `u.x · Ω` of the sub-triangle `a b ĉ` (ĉ on the arc from `a` to `c`), `u.y` the
    /// point on the arc from `b` to `ĉ`, at cosine `1 − u.y (1 − ĉ·b)` from `b`.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let (a, b, c) = (self.a, self.b, self.c);
        // The interior angle α at `a`, between the great circles through a, b and a, c: its
        // cosine and (non-negative) sine from their unit normals.
        let (n_ab, n_ac) = (
            a.cross(b).normalize_or_zero(),
            a.cross(c).normalize_or_zero(),
        );
        let cos_alpha = n_ab.dot(n_ac).clamp(-1.0, 1.0);
        let sin_alpha = n_ab.cross(n_ac).length().min(1.0);
        // The sub-triangle's area Â = u.x · Ω = α + β̂ + γ̂ − π gives the arc length from a
        // to ĉ; s, t are the sine and cosine of Â − α.
        let (sin_area, cos_area) = (u.x * self.omega).sin_cos();
        let s = sin_area * cos_alpha - cos_area * sin_alpha;
        let t = cos_area * cos_alpha + sin_area * sin_alpha;
        let cos_c = a.dot(b);
        let k1 = t - cos_alpha;
        let k2 = s + sin_alpha * cos_c;
        let cos_b_hat = ((k2 * t - k1 * s) * cos_alpha - k2) / ((k2 * s + k1 * t) * sin_alpha);
        let cos_b_hat = if cos_b_hat.is_finite() {
            cos_b_hat.clamp(-1.0, 1.0)
        } else {
            1.0
        };
        let c_hat =
            a * cos_b_hat + orthogonal(c, a) * (1.0 - cos_b_hat * cos_b_hat).max(0.0).sqrt();
        let z = (1.0 - u.y * (1.0 - c_hat.dot(b))).clamp(-1.0, 1.0);
        (b * z + orthogonal(c_hat, b) * (1.0 - z * z).max(0.0).sqrt()).normalize_or_zero()
    }
}

/// The unit component of `v` orthogonal to the unit `axis` (zero if `v` lies along it).
#[inline]
fn orthogonal(v: Vec3, axis: Vec3) -> Vec3 {
    (v - axis * v.dot(axis)).normalize_or_zero()
}

/// Barycentrics `(b1, b2)` (weights of `v[1]`, `v[2]`) where the ray from `p` along `w` meets
/// the plane of `v`, clamped into the triangle; `None` for a ray parallel to the plane.
#[inline]
pub fn barycentrics_along(p: Vec3, w: Vec3, v: [Vec3; 3]) -> Option<Vec2> {
    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
    let s1 = w.cross(e2);
    let det = s1.dot(e1);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let s = p - v[0];
    let b1 = (s.dot(s1) / det).max(0.0);
    let b2 = (w.dot(s.cross(e1)) / det).max(0.0);
    let sum = b1 + b2;
    if !sum.is_finite() {
        return None;
    }
    Some(if sum > 1.0 {
        Vec2::new(b1 / sum, b2 / sum)
    } else {
        Vec2::new(b1, b2)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    #[test]
    fn octant_has_an_eighth_of_the_sphere() {
        let t = SphericalTriangle::new(Vec3::ZERO, [Vec3::X, Vec3::Y, Vec3::Z]).unwrap();
        assert!((t.solid_angle() - PI / 2.0).abs() < 1e-6);
        // Samples stay inside the octant, and u = (1, 0) reaches the third vertex's arc.
        for i in 0..16 {
            for j in 0..16 {
                let w = t.sample(Vec2::new(i as f32 / 16.0 + 0.01, j as f32 / 16.0 + 0.01));
                assert!(
                    w.min_element() > -1e-6 && (w.length() - 1.0).abs() < 1e-5,
                    "{w}"
                );
            }
        }
    }

    #[test]
    fn small_far_triangle_matches_projected_area() {
        // At distance 10 a unit right triangle facing the point subtends about A / d².
        let d = 10.0;
        let v = [
            Vec3::new(0.0, 0.0, d),
            Vec3::new(1.0, 0.0, d),
            Vec3::new(0.0, 1.0, d),
        ];
        let t = SphericalTriangle::new(Vec3::new(0.3, 0.3, 0.0), v).unwrap();
        let want = 0.5 / (d * d);
        assert!(
            (t.solid_angle() / want - 1.0).abs() < 2e-2,
            "{}",
            t.solid_angle()
        );
        let w = t.sample(Vec2::new(0.4, 0.6));
        let b = barycentrics_along(Vec3::new(0.3, 0.3, 0.0), w, v).unwrap();
        assert!(b.x > 0.0 && b.y > 0.0 && b.x + b.y < 1.0, "{b}");
        assert!(
            SphericalTriangle::new(Vec3::new(0.2, 0.2, d), v).is_none(),
            "in the plane"
        );
        assert!(SphericalTriangle::new(Vec3::NAN, v).is_none());
        // A direction along the plane meets it nowhere; one that barely leaves it, far away.
        let o = Vec3::new(0.3, 0.3, d - 1.0);
        assert!(barycentrics_along(o, Vec3::X, v).is_none());
        let b = barycentrics_along(o, Vec3::new(1.0, 0.0, 1e-40), v);
        assert!(
            b.is_none_or(|b| b.is_finite() && b.x + b.y <= 1.0 + 1e-6),
            "{b:?}"
        );
    }
}
