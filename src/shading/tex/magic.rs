//! Blender's Magic Texture node (`ShaderNodeTexMagic`), as Cycles 5.0 evaluates it
//! (`kernel/svm/magic.h`): a psychedelic pattern of nested sines and cosines.
//!
//! With `q = p mod 2pi` (per axis, C's `fmod`, so that large coordinates neither lose precision
//! nor overflow; note that the Scale is applied after it, so the pattern repeats every 2pi of `p`) and `s = 5 scale`:
//! `x = sin((q.x + q.y + q.z) s)`, `y = cos((-q.x + q.y - q.z) s)`, `z = -cos((-q.x - q.y + q.z) s)`;
//! then, for Depth > 0, the three are scaled by Distortion and fed through up to ten further
//! rounds (`y = -cos(x - y + z)`, `x = cos(x - y - z)`, ...), each rescaled by Distortion.
//! Finally, unless Distortion is 0, they are divided by `2 distortion`;
//! Color = `0.5 - (x, y, z)` and Fac is the mean of Color's components.
//!
//! Rounding follows Cycles' x86 AVX2 kernel (one FMA, division as multiplication by the
//! reciprocal): the chaotic high-depth, high-distortion patterns then match bit for bit, where
//! plain arithmetic drifts by up to 5e-4 at depth 10.

use glam::Vec3;

/// The Magic Texture node: returns `(Color, Fac)` at texture coordinate `p`, for the node's
/// Depth (`turbulence_depth`, 0 to 10 in Blender), Scale and Distortion.
pub fn magic(p: Vec3, depth: i32, scale: f32, distortion: f32) -> (Vec3, f32) {
    let c = magic_color(p, scale, depth, distortion);
    (c, (c.x + c.y + c.z) * (1.0 / 3.0))
}

/// `svm_magic` (the scale multiplies the angles only, after the `mod 2pi`).
fn magic_color(p: Vec3, scale: f32, n: i32, distortion: f32) -> Vec3 {
    const TWO_PI: f32 = core::f32::consts::TAU;
    let (px, py, pz) = (p.x % TWO_PI, p.y % TWO_PI, p.z % TWO_PI);
    let mut x = ((px + py + pz) * 5.0 * scale).sin();
    let mut y = ((-px + py - pz) * 5.0 * scale).cos();
    let mut z = -((-px - py + pz) * 5.0 * scale).cos();

    if n > 0 {
        x *= distortion;
        z *= distortion;
        // `x - y * distortion + z`: Cycles' x86 AVX2 kernel fuses this product (the only one
        // whose value has no other use) into an FMA; measured, it matters at high distortion.
        y = -((-y).mul_add(distortion, x) + z).cos();
        y *= distortion;
        // The rounds of depth 2 to 10, in order; each recomputes one of x, y, z.
        for round in 2..=n.min(10) {
            match round {
                2 => x = (x - y - z).cos() * distortion,
                3 => z = (-x - y - z).sin() * distortion,
                4 => x = -(-x + y - z).cos() * distortion,
                5 => y = -(-x + y + z).sin() * distortion,
                6 => y = -(-x + y + z).cos() * distortion,
                7 => x = (x + y + z).cos() * distortion,
                8 => z = (x + y - z).sin() * distortion,
                9 => x = -(-x - y + z).cos() * distortion,
                _ => y = -(x - y + z).sin() * distortion,
            }
        }
    }

    if distortion != 0.0 {
        let inv = 1.0 / (distortion * 2.0);
        x *= inv;
        y *= inv;
        z *= inv;
    }
    Vec3::new(0.5 - x, 0.5 - y, 0.5 - z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_measured_from_cycles() {
        // Measured from Cycles 5.0 renders: (depth, scale, distortion, p, Color).
        for &(depth, scale, distortion, p, c) in MEASURED {
            let got = magic(Vec3::from_array(p), depth, scale, distortion).0;
            assert!(
                (got - Vec3::from_array(c)).abs().max_element() < 1e-6,
                "{p:?}: {got} vs {c:?}"
            );
        }
    }

    /// (depth, scale, distortion, p, Color).
    type Case = (i32, f32, f32, [f32; 3], [f32; 3]);

    const MEASURED: &[Case] = &[
        (
            10,
            3.1,
            2.3,
            [1.0045003, -1.2004997, 0.75778],
            [0.6093223, 0.52646554, 0.0038413703],
        ),
        (
            10,
            3.1,
            2.3,
            [0.6125, 0.12250023, 0.30844995],
            [0.52992153, 0.25657573, 0.87674034],
        ),
        (
            10,
            3.1,
            2.3,
            [1.3965002, 1.3965002, 0.30551],
            [0.46690074, 0.79344714, 0.010581434],
        ),
        (
            3,
            1.7,
            1.0,
            [1.0045003, -1.2004997, 0.75778],
            [0.42640707, 0.41270348, 0.770753],
        ),
        (
            3,
            1.7,
            1.0,
            [0.6125, 0.12250023, 0.30844995],
            [0.06161189, 0.92972726, 0.89241534],
        ),
        (
            0,
            1.7,
            1.0,
            [1.0045003, -1.2004997, 0.75778],
            [0.99901605, 0.00064727664, 0.37477568],
        ),
        (
            0,
            1.7,
            1.0,
            [1.3965002, 1.3965002, 0.30551],
            [0.033151954, 0.9276265, 0.16906264],
        ),
    ];

    #[test]
    fn finite_for_any_coordinate() {
        for depth in [-1, 0, 1, 2, 5, 10, 11] {
            for x in [0.0, 1e-3, -7.5, 1e30, -f32::MAX] {
                let (c, f) = magic(Vec3::new(x, 0.3, -x), depth, 5.0, 1.0);
                assert!(c.is_finite() && f.is_finite());
                // With distortion 1 the components stay in [0, 1].
                assert!(c.cmpge(Vec3::ZERO).all() && c.cmple(Vec3::ONE).all());
            }
        }
        assert!(magic(Vec3::splat(f32::NAN), 3, 5.0, 1.0).0.is_nan());
    }
}
