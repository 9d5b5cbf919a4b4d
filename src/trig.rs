//! Trigonometry for the hot paths (direction sampling, equirectangular worlds): branch-light
//! polynomial forms that inline, in place of libm calls that cost several times more per
//! shading point.

use std::f32::consts::{FRAC_PI_2, PI};

/// Minimax coefficients of `atan(a) / a` as a polynomial in `a²` on `a ∈ [0, 1]`.
const ATAN: [f32; 9] = [
    0.999_999_9,
    -0.333_325_98,
    0.199_859_07,
    -0.141_612_29,
    0.104_989_47,
    -0.072_348_59,
    0.039_781_23,
    -0.014_401_361,
    0.002_456_725,
];

/// `atan2(y, x)` in radians, in `[-π, π]`, within 3.5e-7 rad (1.5 ulp of π) of the exact
/// value for finite arguments (the sign of a zero `y` is kept, as libm does:
/// `atan2(±0, -1) = ±π`).
/// `atan2(0, 0)` is 0; a NaN argument gives NaN; infinite arguments give the limit angle.
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    let a = if hi == 0.0 {
        0.0
    } else if hi.is_infinite() {
        if lo.is_infinite() { 1.0 } else { 0.0 }
    } else {
        lo / hi
    };
    let s = a * a;
    let mut p = ATAN[8];
    for c in ATAN[..8].iter().rev() {
        p = p * s + c;
    }
    let mut r = a * p;
    if ay > ax {
        r = FRAC_PI_2 - r;
    }
    if x.is_sign_negative() {
        r = PI - r;
    }
    if x.is_nan() || y.is_nan() {
        return f32::NAN;
    }
    r.copysign(y)
}

/// Taylor coefficients `(-1)^k / (2k + 3)!` of `(sin r - r) / r³` and `(-1)^(k+1) / (2k + 2)!`
/// of `(cos r - 1) / r²`, as powers of `r²`.
const SIN_TAYLOR: [f64; 5] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
];
const COS_TAYLOR: [f64; 6] = [
    -1.0 / 2.0,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
];

/// Beyond this |x| the quadrant reduction below loses accuracy: libm takes over.
const SIN_COS_LIMIT: f32 = 1.0e5;

/// `(sin x, cos x)` rounded from double precision (as libm's, within an ulp of the exact
/// values, and the same on every machine) for `|x| ≤ 1e5`: the argument is reduced to
/// `|r| ≤ π/4` (Cody and Waite's two-part π/2) and both Taylor series are summed to within
/// 1e-11. Beyond, and for NaN, libm's.
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    if x.is_nan() || x.abs() > SIN_COS_LIMIT {
        return x.sin_cos();
    }
    let k = (x * std::f32::consts::FRAC_2_PI).round();
    // π/2 in two parts, the first with 33 significant bits, so that `k · PIO2_HI` is exact.
    const PIO2_HI: f64 = 1.570_796_326_734_125_6;
    const PIO2_LO: f64 = 6.077_100_506_506_192e-11;
    let k64 = k as f64;
    let r = (x as f64 - k64 * PIO2_HI) - k64 * PIO2_LO;
    let r2 = r * r;
    let mut s = SIN_TAYLOR[4];
    for c in SIN_TAYLOR[..4].iter().rev() {
        s = s * r2 + c;
    }
    let s = r + r * r2 * s;
    let mut c = COS_TAYLOR[5];
    for k in COS_TAYLOR[..5].iter().rev() {
        c = c * r2 + k;
    }
    let c = 1.0 + r2 * c;
    let (s, c) = (s as f32, c as f32);
    // Quadrant q = k mod 4 gives (s, c), (c, -s), (-s, -c), (-c, s): a swap and two sign
    // flips, without branches (q is as random as the sampled angle).
    let q = k as i32;
    let (a, b) = if q & 1 != 0 { (c, s) } else { (s, c) };
    let flip = |v: f32, bit: i32| f32::from_bits(v.to_bits() ^ (((bit & 2) as u32) << 30));
    (flip(a, q), flip(b, q.wrapping_add(1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_cos_is_within_an_ulp_of_the_exact_values() {
        let mut worst = 0.0f64;
        let n = 200_000;
        for i in 0..n {
            // Densely over the sampling range [-2π, 2π], then sparsely out to ±1e5.
            let x = if i < n / 2 {
                ((i as f64 + 0.5) / (n / 2) as f64 * 4.0 - 2.0) * std::f64::consts::PI
            } else {
                ((i - n / 2) as f64 / (n / 2) as f64 * 2.0 - 1.0) * 1.0e5
            } as f32;
            let (s, c) = sin_cos(x);
            let (es, ec) = (x as f64).sin_cos();
            // In units of the last place of the exact value.
            let ulp = |e: f64| (e.abs() as f32).max(f32::MIN_POSITIVE) as f64 * f32::EPSILON as f64;
            worst = worst
                .max((s as f64 - es).abs() / ulp(es))
                .max((c as f64 - ec).abs() / ulp(ec));
        }
        assert!(worst <= 1.0, "max error {worst} ulp");
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        let (s, c) = sin_cos(f32::NAN);
        assert!(s.is_nan() && c.is_nan());
        assert_eq!(sin_cos(3.0e6), 3.0e6f32.sin_cos());
    }

    #[test]
    fn atan2_is_within_3e7_of_the_exact_angle_everywhere() {
        let mut worst = 0.0f64;
        let n = 20_000;
        for i in 0..n {
            // Angles around the whole circle, at radii from 1e-30 to 1e30.
            let t = (i as f64 + 0.37) / n as f64 * std::f64::consts::TAU - std::f64::consts::PI;
            let r = 10f64.powi((i % 61) - 30);
            let (y, x) = ((r * t.sin()) as f32, (r * t.cos()) as f32);
            let exact = (y as f64).atan2(x as f64);
            worst = worst.max((atan2(y, x) as f64 - exact).abs());
        }
        assert!(worst < 3.5e-7, "max error {worst}");
        for (y, x) in [(0.3f32, 0.7f32), (1.0, 1.0), (5.0, -0.001), (-2.0, -3.0)] {
            assert!((atan2(y, x) - y.atan2(x)).abs() < 2e-7, "({y}, {x})");
        }
    }

    #[test]
    fn atan2_edge_cases_follow_libm() {
        for (y, x) in [
            (0.0f32, 0.0f32),
            (0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (-0.0, 1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (1.0, -0.0),
            (f32::INFINITY, 1.0),
            (1.0, f32::INFINITY),
            (1.0, f32::NEG_INFINITY),
            (-1.0, f32::NEG_INFINITY),
            (f32::INFINITY, f32::INFINITY),
            (f32::INFINITY, f32::NEG_INFINITY),
        ] {
            let (got, want) = (atan2(y, x), y.atan2(x));
            assert!(
                (got - want).abs() < 2e-7 && got.is_sign_negative() == want.is_sign_negative(),
                "atan2({y}, {x}) = {got}, libm {want}"
            );
        }
        assert!(atan2(f32::NAN, 1.0).is_nan() && atan2(1.0, f32::NAN).is_nan());
    }
}
