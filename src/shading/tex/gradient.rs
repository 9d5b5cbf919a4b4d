//! Blender's Gradient Texture node (`ShaderNodeTexGradient`), as Cycles 5.0 evaluates it
//! (`kernel/svm/gradient.h`). `Fac` is the value below clamped to `[0, 1]`, Color is
//! `(Fac, Fac, Fac)`:
//! - Linear `x`; Quadratic `max(x, 0)^2`; Easing `3t^2 - 2t^3` with `t = clamp(x, 0, 1)`;
//! - Diagonal `(x + y) / 2`; Radial `atan2(y, x) / 2pi + 1/2`;
//! - Spherical `r = max(0.999999 - |p|, 0)` and Quadratic Sphere `r^2` (the bias makes unit
//!   vectors give exactly 0).

use glam::Vec3;

/// The node's "Gradient Type" menu.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GradientType {
    #[default]
    Linear,
    Quadratic,
    Easing,
    Diagonal,
    Spherical,
    QuadraticSphere,
    Radial,
}

/// Cycles' `saturatef`: `min(max(x, 0), 1)`, with NaN going to 0 (`f32::clamp` keeps NaN).
#[inline]
#[allow(clippy::manual_clamp)]
fn saturate(x: f32) -> f32 {
    x.max(0.0).min(1.0)
}

/// The Gradient Texture node: returns `(Color, Fac)` at texture coordinate `p`.
pub fn gradient(p: Vec3, kind: GradientType) -> (Vec3, f32) {
    let f = saturate(gradient_raw(p, kind));
    (Vec3::splat(f), f)
}

/// `svm_gradient`: the gradient before clamping.
///
/// The `mul_add`s reproduce the FMAs that Cycles' x86 AVX2 kernel (built with GCC's fast math:
/// contraction, and `/ 2pi` as `* (1 / 2pi)`) computes; with them, all seven types match Cycles
/// renders bit for bit, without them about 10 % of pixels differ by an ulp.
fn gradient_raw(p: Vec3, kind: GradientType) -> f32 {
    let Vec3 { x, y, z } = p;
    match kind {
        GradientType::Linear => x,
        GradientType::Quadratic => {
            let r = x.max(0.0);
            r * r
        }
        GradientType::Easing => {
            let r = saturate(x);
            let t = r * r;
            3.0f32.mul_add(t, -(2.0 * t * r))
        }
        GradientType::Diagonal => (x + y) * 0.5,
        GradientType::Radial => y.atan2(x).mul_add(1.0 / core::f32::consts::TAU, 0.5),
        GradientType::Spherical | GradientType::QuadraticSphere => {
            let r = (0.999999 - z.mul_add(z, x.mul_add(x, y * y)).sqrt()).max(0.0);
            if kind == GradientType::Spherical {
                r
            } else {
                r * r
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [GradientType; 7] = [
        GradientType::Linear,
        GradientType::Quadratic,
        GradientType::Easing,
        GradientType::Diagonal,
        GradientType::Spherical,
        GradientType::QuadraticSphere,
        GradientType::Radial,
    ];

    #[test]
    fn values_measured_from_cycles() {
        // Measured from Cycles 5.0 renders (object coordinates in, Fac out).
        for &(kind, p, fac) in MEASURED {
            let got = gradient(Vec3::from_array(p), kind).1;
            assert!((got - fac).abs() <= 1e-7, "{kind:?} {p:?}: {got} vs {fac}");
        }
    }

    const A: [f32; 3] = [0.41650048, -0.80849963, 0.45006007];
    const B: [f32; 3] = [0.024500275, 0.024500275, 0.11343003];
    const C: [f32; 3] = [1.2495, 0.71049994, 0.40890002];
    const D: [f32; 3] = [0.6125, -0.122499846, 0.36479998];
    const MEASURED: &[(GradientType, [f32; 3], f32)] = &[
        (GradientType::Linear, A, 0.41650048),
        (GradientType::Linear, C, 1.0),
        (GradientType::Quadratic, A, 0.17347264),
        (GradientType::Quadratic, B, 0.0006002635),
        (GradientType::Easing, A, 0.37591505),
        (GradientType::Easing, B, 0.0017713772),
        (GradientType::Diagonal, A, 0.0),
        (GradientType::Diagonal, C, 0.98),
        (GradientType::Spherical, B, 0.88139504),
        (GradientType::Spherical, D, 0.27664465),
        (GradientType::QuadraticSphere, B, 0.7768572),
        (GradientType::QuadraticSphere, D, 0.07653226),
        (GradientType::Radial, A, 0.32570937),
        (GradientType::Radial, B, 0.625),
        (GradientType::Radial, C, 0.5822882),
    ];

    #[test]
    fn in_unit_range_and_never_nan() {
        for kind in ALL {
            for x in [
                f32::NAN,
                f32::INFINITY,
                -f32::INFINITY,
                -2.0,
                -0.3,
                0.0,
                0.4,
                1.0,
                7.0,
            ] {
                for p in [
                    Vec3::splat(x),
                    Vec3::new(x, 0.3, -0.2),
                    Vec3::new(0.1, x, 0.5),
                ] {
                    let (c, f) = gradient(p, kind);
                    assert!((0.0..=1.0).contains(&f), "{kind:?} {p:?} {f}");
                    assert_eq!(c, Vec3::splat(f));
                }
            }
        }
        assert_eq!(
            gradient(Vec3::new(0.6, 0.0, 0.8), GradientType::Spherical).1,
            0.0
        );
    }
}
