//! Fresnel reflectance.

use glam::Vec3;

/// Unpolarised Fresnel reflectance of a dielectric interface.
///
/// `cos_i` is the cosine between the incident direction and the normal on the side of the
/// **outside** medium (negative when the ray arrives from inside); `eta` = `η_inside / η_outside`.
/// Returns `(R, cos_t, eta_rel)` where `cos_t ≥ 0` is the cosine of the transmitted direction and
/// `eta_rel` the relative index `η_t / η_i` of the transmission (R = 1 on total internal reflection).
#[inline]
pub fn dielectric(cos_i: f32, eta: f32) -> (f32, f32, f32) {
    let (cos_i, eta) = if cos_i < 0.0 {
        (-cos_i, 1.0 / eta)
    } else {
        (cos_i, eta)
    };
    if eta == 1.0 {
        return (0.0, cos_i, 1.0);
    }
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return (1.0, 0.0, eta);
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    (0.5 * (rs * rs + rp * rp), cos_t, eta)
}

/// Schlick's approximation `F0 + (1 - F0)(1 - cos)^5` (for conductors and glTF's model).
#[inline]
pub fn schlick(f0: Vec3, cos: f32) -> Vec3 {
    let m = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
    f0 + (Vec3::ONE - f0) * m
}

/// Scalar Schlick.
#[inline]
pub fn schlick1(f0: f32, cos: f32) -> f32 {
    let m = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
    f0 + (1.0 - f0) * m
}

/// Normal-incidence reflectance `((η - 1) / (η + 1))²` of an interface of relative index `η`.
#[inline]
pub fn f0_from_ior(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// Unpolarised Fresnel reflectance of a conductor of complex index `eta + i k` (relative to
/// the outside medium, index 1) at `cos_i = cos θ` in `[0, 1]`, per channel: the mean of the
/// s- and p-polarised reflectances.
pub fn conductor(cos_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    let one = |eta: f32, k: f32| {
        let c = cos_i.clamp(0.0, 1.0);
        let (eta2, k2) = (eta * eta, k * k);
        let t1 = eta2 - k2 - (1.0 - c * c);
        let t2 = (t1 * t1 + 4.0 * eta2 * k2).sqrt();
        let u2 = (0.5 * (t2 + t1)).max(0.0);
        let v2 = (0.5 * (t2 - t1)).max(0.0);
        let (u, v) = (u2.sqrt(), v2.sqrt());
        let div = |a: f32, b: f32| if b > 0.0 { a / b } else { 0.0 };
        let rs = div((c - u) * (c - u) + v2, (c + u) * (c + u) + v2);
        let (t3, t4) = ((eta2 - k2) * c, 2.0 * eta * k * c);
        let rp = div(
            (t3 - u) * (t3 - u) + (t4 - v) * (t4 - v),
            (t3 + u) * (t3 + u) + (t4 + v) * (t4 + v),
        );
        0.5 * (rs + rp)
    };
    Vec3::new(one(eta.x, k.x), one(eta.y, k.y), one(eta.z, k.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conductor_reduces_to_its_known_limits() {
        // Normal incidence: ((n - 1)² + k²) / ((n + 1)² + k²); grazing: 1.
        let (eta, k) = (Vec3::new(0.18, 0.42, 1.37), Vec3::new(3.42, 2.35, 1.77));
        let f0 = conductor(1.0, eta, k);
        let want = ((eta - Vec3::ONE) * (eta - Vec3::ONE) + k * k)
            / ((eta + Vec3::ONE) * (eta + Vec3::ONE) + k * k);
        assert!((f0 - want).abs().max_element() < 1e-6, "{f0} vs {want}");
        assert!((conductor(0.0, eta, k) - Vec3::ONE).abs().max_element() < 1e-6);
        // Without absorption it is the dielectric's reflectance at every angle.
        for c in [0.05f32, 0.3, 0.7, 1.0] {
            let d = dielectric(c, 1.7).0;
            let r = conductor(c, Vec3::splat(1.7), Vec3::ZERO);
            assert!((r.x - d).abs() < 1e-5, "cos {c}: {} vs {d}", r.x);
        }
    }

    #[test]
    fn normal_incidence_matches_f0() {
        let (r, cos_t, _) = dielectric(1.0, 1.5);
        assert!((r - f0_from_ior(1.5)).abs() < 1e-6);
        assert!((cos_t - 1.0).abs() < 1e-6);
        // Symmetric from the inside.
        let (r2, _, eta) = dielectric(-1.0, 1.5);
        assert!((r2 - r).abs() < 1e-6);
        assert!((eta - 1.0 / 1.5).abs() < 1e-6);
    }

    #[test]
    fn total_internal_reflection_beyond_critical_angle() {
        let critical = (1.0f32 / 1.5).asin();
        let below = (critical - 0.01).cos();
        let above = (critical + 0.01).cos();
        assert!(dielectric(-below, 1.5).0 < 1.0);
        assert_eq!(dielectric(-above, 1.5).0, 1.0);
    }

    #[test]
    fn snell_and_grazing() {
        for k in 1..90 {
            let theta_i = (k as f32).to_radians();
            let (r, cos_t, eta) = dielectric(theta_i.cos(), 1.33);
            assert!((0.0..=1.0).contains(&r));
            let sin_t = (1.0 - cos_t * cos_t).sqrt();
            assert!(
                (theta_i.sin() - eta * sin_t).abs() < 1e-4,
                "Snell at {k} deg"
            );
        }
        assert!(dielectric(1e-4, 1.5).0 > 0.99);
    }
}
