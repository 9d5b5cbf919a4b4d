//! Blender's Checker Texture node (`ShaderNodeTexChecker`), as Cycles 5.0 evaluates it
//! (`kernel/svm/checker.h`).
//!
//! With `q = (p * scale + 1e-6) * 0.999999` (a nudge so that coordinates 0 and 1, e.g. the faces
//! of a unit cube, fall consistently into the cell between them), the cells `i = |floor(q)|` alternate:
//! `Fac = ((i.x mod 2 == i.y mod 2) == i.z mod 2) ? 1 : 0`, Color is Color1 where Fac is 1,
//! Color2 elsewhere. The absolute value makes the pattern mirror around zero, as in Cycles.

use glam::Vec3;

/// C's `(int)f` as x86 computes it: truncation, and `i32::MIN` for NaN and out of range.
#[inline]
fn float_to_int(f: f32) -> i32 {
    if (-2_147_483_648.0..2_147_483_648.0).contains(&f) {
        f as i32
    } else {
        i32::MIN
    }
}

/// `svm_checker`: 1 on the "Color1" cells, 0 on the others, at point `p` and Scale `scale`.
pub fn checker_fac(p: Vec3, scale: f32) -> f32 {
    // `p * scale + 1e-6` is one FMA, as Cycles' x86 AVX2 kernel compiles it (measured on the
    // same expression in the Wave texture).
    let nudge = |x: f32| x.mul_add(scale, 1e-6) * 0.999999;
    let q = Vec3::new(nudge(p.x), nudge(p.y), nudge(p.z));
    let parity = |x: f32| float_to_int(x.floor()).unsigned_abs() % 2;
    let (xi, yi, zi) = (parity(q.x), parity(q.y), parity(q.z));
    if ((xi == yi) as u32) == zi { 1.0 } else { 0.0 }
}

/// The Checker Texture node: returns `(Color, Fac)` at texture coordinate `p`.
pub fn checker(p: Vec3, color1: Vec3, color2: Vec3, scale: f32) -> (Vec3, f32) {
    let f = checker_fac(p, scale);
    (if f == 1.0 { color1 } else { color2 }, f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_measured_from_cycles() {
        // Measured from Cycles 5.0 renders (Scale 2.3, object coordinates).
        for &(p, fac) in MEASURED {
            assert_eq!(
                checker(Vec3::from_array(p), Vec3::ONE, Vec3::ZERO, 2.3).1,
                fac,
                "{p:?}"
            );
        }
    }

    const MEASURED: &[([f32; 3], f32)] = &[
        ([-1.5434997, -1.5434997, -0.10608995], 1.0),
        ([-1.1024997, -0.9554997, -0.078159966], 1.0),
        ([0.024500275, 0.024500275, 0.11343003], 0.0),
        ([1.2495, 0.71049994, 0.40890002], 1.0),
        ([1.5435002, 1.5435002, 0.32609], 0.0),
    ];

    #[test]
    fn alternates_and_never_panics() {
        let (c1, c2) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0));
        assert_eq!(checker(Vec3::new(0.25, 0.25, 0.25), c1, c2, 1.0), (c2, 0.0));
        assert_eq!(checker(Vec3::new(1.25, 0.25, 0.25), c1, c2, 1.0), (c1, 1.0));
        // The nudge maps 1 to 0.99999994 and 0 to 1e-6: the faces of a unit cube all fall inside it.
        assert_eq!(checker_fac(Vec3::new(1.0, 0.5, 0.5), 1.0), 0.0);
        assert_eq!(checker_fac(Vec3::new(1.0, 1.0, 1.0), 1.0), 0.0);
        assert_eq!(checker_fac(Vec3::new(0.0, 0.0, 0.0), 1.0), 0.0);
        for x in [
            f32::NAN,
            f32::INFINITY,
            -f32::INFINITY,
            f32::MAX,
            -1e12,
            -0.0,
        ] {
            let f = checker(Vec3::splat(x), c1, c2, 3.0).1;
            assert!(f == 0.0 || f == 1.0);
        }
    }
}
