//! Map Range node (`ShaderNodeMapRange`, float and vector) and Clamp node
//! (`ShaderNodeClamp`), evaluated like Cycles' `svm_node_map_range`,
//! `svm_node_vector_map_range` (`kernel/svm/map_range.h`) and `svm_node_clamp`.
//! The float Map Range `clamp` option is a Clamp node in RANGE mode between
//! `to_min` and `to_max`, as Cycles inserts it.

use super::math::{clamp as cclamp, cmax, cmin};
use glam::Vec3;

/// `ShaderNodeMapRange.interpolation_type`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MapRangeType {
    Linear,
    Stepped,
    SmoothStep,
    SmootherStep,
}

impl MapRangeType {
    /// Parses `"LINEAR"`, `"STEPPED"`, `"SMOOTHSTEP"` or `"SMOOTHERSTEP"`.
    pub fn from_blender(s: &str) -> Option<Self> {
        Some(match s {
            "LINEAR" => Self::Linear,
            "STEPPED" => Self::Stepped,
            "SMOOTHSTEP" => Self::SmoothStep,
            "SMOOTHERSTEP" => Self::SmootherStep,
            _ => return None,
        })
    }
}

/// `ShaderNodeClamp.clamp_type`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ClampType {
    /// `min(max(value, min), max)`.
    MinMax,
    /// Like MINMAX, but the bounds are swapped when `min > max`.
    Range,
}

impl ClampType {
    /// Parses `"MINMAX"` or `"RANGE"`.
    pub fn from_blender(s: &str) -> Option<Self> {
        Some(match s {
            "MINMAX" => Self::MinMax,
            "RANGE" => Self::Range,
            _ => return None,
        })
    }
}

/// Clamp node: `min(max(value, min), max)` (Cycles' NaN-to-`min` semantics); RANGE swaps
/// the bounds when `min > max`.
pub fn clamp_node(ty: ClampType, value: f32, min: f32, max: f32) -> f32 {
    if ty == ClampType::Range && min > max {
        cclamp(value, max, min)
    } else {
        cclamp(value, min, max)
    }
}

/// Cycles `smoothstep(edge0, edge1, x)`: 0 below `edge0`, 1 at or above `edge1`,
/// `(3 - 2t) t^2` with `t = (x - edge0) / (edge1 - edge0)` in between.
#[inline]
pub fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    if x < edge0 {
        0.0
    } else if x >= edge1 {
        1.0
    } else {
        let t = (x - edge0) / (edge1 - edge0);
        (3.0 - 2.0 * t) * (t * t)
    }
}

/// Cycles `smootherstep(edge0, edge1, x)`: `t^3 (t (6t - 15) + 10)` with
/// `t = clamp(safe_divide(x - edge0, edge1 - edge0), 0, 1)`.
#[inline]
pub fn smootherstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    let d = edge1 - edge0;
    let t = cclamp(if d != 0.0 { (x - edge0) / d } else { 0.0 }, 0.0, 1.0);
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Float Map Range: `to_min + factor * (to_max - to_min)` where `factor` is
/// LINEAR `(value - from_min) / (from_max - from_min)`, STEPPED
/// `floor(linear * (steps + 1)) / steps` (0 if `steps <= 0`), SMOOTHSTEP / SMOOTHERSTEP of
/// `value` between the from bounds (reversed bounds give `1 - step(from_max, from_min)`).
/// The result is 0 when `from_min == from_max`. With `clamp` the result is clamped to the
/// to-range (either orientation).
#[allow(clippy::too_many_arguments)]
pub fn map_range(
    ty: MapRangeType,
    value: f32,
    from_min: f32,
    from_max: f32,
    to_min: f32,
    to_max: f32,
    steps: f32,
    clamp: bool,
) -> f32 {
    let result = if from_max != from_min {
        let factor = match ty {
            MapRangeType::Linear => (value - from_min) / (from_max - from_min),
            MapRangeType::Stepped => {
                let f = (value - from_min) / (from_max - from_min);
                if steps > 0.0 {
                    (f * (steps + 1.0)).floor() / steps
                } else {
                    0.0
                }
            }
            MapRangeType::SmoothStep => {
                if from_min > from_max {
                    1.0 - smoothstep(from_max, from_min, value)
                } else {
                    smoothstep(from_min, from_max, value)
                }
            }
            MapRangeType::SmootherStep => {
                if from_min > from_max {
                    1.0 - smootherstep(from_max, from_min, value)
                } else {
                    smootherstep(from_min, from_max, value)
                }
            }
        };
        to_min + factor * (to_max - to_min)
    } else {
        0.0
    };
    if clamp {
        clamp_node(ClampType::Range, result, to_min, to_max)
    } else {
        result
    }
}

/// Vector Map Range, per component: the factor uses a safe divide (0 where
/// `from_min == from_max`); SMOOTHSTEP/SMOOTHERSTEP clamp the linear factor to [0, 1]
/// and apply `(3 - 2t) t^2` / `t^3 (t (6t - 15) + 10)`; STEPPED as the float version with
/// per-component `steps`. `clamp` (ignored for the smooth types) clamps each component to
/// its to-range.
#[allow(clippy::too_many_arguments)]
pub fn vector_map_range(
    ty: MapRangeType,
    value: Vec3,
    from_min: Vec3,
    from_max: Vec3,
    to_min: Vec3,
    to_max: Vec3,
    steps: Vec3,
    clamp: bool,
) -> Vec3 {
    let use_clamp = clamp && !matches!(ty, MapRangeType::SmoothStep | MapRangeType::SmootherStep);
    let comp = |v: f32, fmin: f32, fmax: f32, tmin: f32, tmax: f32, st: f32| {
        let d = fmax - fmin;
        let lin = if d != 0.0 { (v - fmin) / d } else { 0.0 };
        let factor = match ty {
            MapRangeType::Linear => lin,
            MapRangeType::Stepped => {
                if st > 0.0 {
                    (lin * (st + 1.0)).floor() / st
                } else {
                    0.0
                }
            }
            MapRangeType::SmoothStep => {
                let t = cmin(cmax(lin, 0.0), 1.0);
                (3.0 - 2.0 * t) * (t * t)
            }
            MapRangeType::SmootherStep => {
                let t = cmin(cmax(lin, 0.0), 1.0);
                t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
            }
        };
        let r = tmin + factor * (tmax - tmin);
        if use_clamp {
            if tmin > tmax {
                cclamp(r, tmax, tmin)
            } else {
                cclamp(r, tmin, tmax)
            }
        } else {
            r
        }
    };
    Vec3::new(
        comp(value.x, from_min.x, from_max.x, to_min.x, to_max.x, steps.x),
        comp(value.y, from_min.y, from_max.y, to_min.y, to_max.y, steps.y),
        comp(value.z, from_min.z, from_max.z, to_min.z, to_max.z, steps.z),
    )
}

#[cfg(test)]
#[allow(
    clippy::approx_constant,
    clippy::excessive_precision,
    clippy::type_complexity
)]
mod tests {
    use super::*;

    #[test]
    fn parse() {
        assert_eq!(
            MapRangeType::from_blender("SMOOTHERSTEP"),
            Some(MapRangeType::SmootherStep)
        );
        assert_eq!(MapRangeType::from_blender("linear"), None);
        assert_eq!(ClampType::from_blender("RANGE"), Some(ClampType::Range));
    }

    #[test]
    fn edge_cases() {
        use MapRangeType::*;
        // Degenerate from-range: 0 for floats, `to_min` for vectors (safe divide).
        assert_eq!(map_range(Linear, 0.3, 1.0, 1.0, 2.0, 5.0, 4.0, false), 0.0);
        assert_eq!(map_range(Linear, 0.3, 1.0, 1.0, 2.0, 5.0, 4.0, true), 2.0);
        let v = vector_map_range(
            Linear,
            Vec3::splat(0.3),
            Vec3::ONE,
            Vec3::ONE,
            Vec3::splat(2.0),
            Vec3::splat(5.0),
            Vec3::ONE,
            false,
        );
        assert_eq!(v, Vec3::splat(2.0));
        // Clamp with a reversed to-range.
        assert_eq!(map_range(Linear, 2.0, 0.0, 1.0, 1.0, 0.0, 4.0, true), 0.0);
        assert_eq!(map_range(Linear, -2.0, 0.0, 1.0, 1.0, 0.0, 4.0, true), 1.0);
        // Steps <= 0 gives factor 0.
        assert_eq!(map_range(Stepped, 0.7, 0.0, 1.0, 3.0, 5.0, 0.0, false), 3.0);
        assert_eq!(
            map_range(Stepped, 0.7, 0.0, 1.0, 0.0, 1.0, 4.0, false),
            0.75
        );
        // Reversed from-range smoothstep.
        assert_eq!(
            map_range(SmoothStep, 0.25, 1.0, 0.0, 0.0, 1.0, 0.0, false),
            1.0 - smoothstep(0.0, 1.0, 0.25)
        );
        assert_eq!(
            map_range(SmootherStep, 2.0, 0.0, 1.0, 0.0, 1.0, 0.0, false),
            1.0
        );
        assert_eq!(clamp_node(ClampType::MinMax, 0.5, 1.0, 0.0), 0.0);
        assert_eq!(clamp_node(ClampType::Range, 0.5, 1.0, 0.0), 0.5);
        assert_eq!(clamp_node(ClampType::MinMax, f32::NAN, -1.0, 1.0), -1.0);
        for ty in [Linear, Stepped, SmoothStep, SmootherStep] {
            for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0] {
                let _ = map_range(ty, x, x, 1.0, x, 2.0, x, true);
                let _ = vector_map_range(
                    ty,
                    Vec3::splat(x),
                    Vec3::ZERO,
                    Vec3::splat(x),
                    Vec3::ZERO,
                    Vec3::ONE,
                    Vec3::splat(x),
                    true,
                );
            }
        }
    }

    fn close(got: f32, want: f32) -> bool {
        (got - want).abs() <= 1e-5 * want.abs().max(1.0)
    }

    /// Float Map Range measured from Cycles 5.0 (quantized rows include `from_min == from_max`).
    #[test]
    fn measured_from_cycles() {
        for &(ty, clamp, v, fmin, fmax, tmin, tmax, steps, want) in MAP_RANGE {
            let got = map_range(
                MapRangeType::from_blender(ty).unwrap(),
                v,
                fmin,
                fmax,
                tmin,
                tmax,
                steps,
                clamp,
            );
            assert!(close(got, want), "{ty} {clamp}: {got} vs Cycles {want}");
        }
        for &(ty, clamp, v, fmin, fmax, tmin, tmax, steps, want) in VECTOR_MAP_RANGE {
            let f = Vec3::from_array;
            let got = vector_map_range(
                MapRangeType::from_blender(ty).unwrap(),
                f(v),
                f(fmin),
                f(fmax),
                f(tmin),
                f(tmax),
                f(steps),
                clamp,
            );
            for k in 0..3 {
                assert!(
                    close(got[k], want[k]),
                    "{ty} {clamp}: {got} vs Cycles {want:?}"
                );
            }
        }
        for &(ty, v, lo, hi, want) in CLAMP {
            let got = clamp_node(ClampType::from_blender(ty).unwrap(), v, lo, hi);
            assert_eq!(got, want, "{ty}");
        }
    }

    /// (type, clamp, value, from_min, from_max, to_min, to_max, steps, result): Cycles 5.0.
    #[rustfmt::skip]
    const MAP_RANGE: &[(&str, bool, f32, f32, f32, f32, f32, f32, f32)] = &[
        ("LINEAR", false, -1.631278, -0.8019161, -1.1863127, -1.3510637, -1.4242244, 0.75086784, -1.5089128),
        ("LINEAR", false, -1.6860409, -1.78619, -1.0908508, -2.6295147, -1.9249477, -0.50969505, -2.5280364),
        ("LINEAR", true, -1.631278, -0.8019161, -1.1863127, -1.3510637, -1.4242244, 0.75086784, -1.4242244),
        ("LINEAR", true, -1.6860409, -1.78619, -1.0908508, -2.6295147, -1.9249477, -0.50969505, -2.5280364),
        ("LINEAR", false, -1.5, -1.0, -1.0, -1.5, -1.5, 1.0, 0.0),
        ("LINEAR", false, -1.5, -2.0, -1.0, -2.5, -2.0, -0.5, -2.25),
        ("LINEAR", false, -0.5, -1.0, -1.0, -2.5, 2.5, 5.5, 0.0),
        ("LINEAR", true, -1.5, -1.0, -1.0, -1.5, -1.5, 1.0, -1.5),
        ("LINEAR", true, -1.5, -2.0, -1.0, -2.5, -2.0, -0.5, -2.25),
        ("LINEAR", true, -0.5, -1.0, -1.0, -2.5, 2.5, 5.5, 0.0),
        ("SMOOTHERSTEP", false, 2.7127118, -0.5836792, 0.5629177, -2.7438583, 0.3625989, 4.1191006, 0.3625989),
        ("SMOOTHERSTEP", false, 0.08133316, 1.2215652, 0.6651535, 2.748745, -1.4036865, -0.22400093, -1.4036865),
        ("SMOOTHERSTEP", true, 2.7127118, -0.5836792, 0.5629177, -2.7438583, 0.3625989, 4.1191006, 0.3625989),
        ("SMOOTHERSTEP", true, 0.08133316, 1.2215652, 0.6651535, 2.748745, -1.4036865, -0.22400093, -1.4036865),
        ("SMOOTHERSTEP", false, 2.5, -0.5, 0.5, -2.5, 0.5, 4.0, 0.5),
        ("SMOOTHERSTEP", false, 0.0, 1.0, 0.5, 2.5, -1.5, 0.0, -1.5),
        ("SMOOTHERSTEP", false, -0.5, -1.0, -1.0, -2.5, 2.5, 5.5, 0.0),
        ("SMOOTHERSTEP", true, 2.5, -0.5, 0.5, -2.5, 0.5, 4.0, 0.5),
        ("SMOOTHERSTEP", true, 0.0, 1.0, 0.5, 2.5, -1.5, 0.0, -1.5),
        ("SMOOTHERSTEP", true, -0.5, -1.0, -1.0, -2.5, 2.5, 5.5, 0.0),
        ("SMOOTHSTEP", false, -0.9891014, -1.438179, -0.20695114, -1.4785881, -1.1420631, 1.5667744, -1.3769379),
        ("SMOOTHSTEP", false, -0.93341446, -1.82518, 1.5456696, 0.5141487, -2.988018, -0.10625458, -0.09149044),
        ("SMOOTHSTEP", true, -0.9891014, -1.438179, -0.20695114, -1.4785881, -1.1420631, 1.5667744, -1.3769379),
        ("SMOOTHSTEP", true, -0.93341446, -1.82518, 1.5456696, 0.5141487, -2.988018, -0.10625458, -0.09149044),
        ("SMOOTHSTEP", false, -1.0, -1.5, 0.0, -1.5, -1.0, 1.5, -1.3703704),
        ("SMOOTHSTEP", false, -1.0, -2.0, 1.5, 0.5, -3.0, 0.0, -0.1938776),
        ("SMOOTHSTEP", false, -0.5, -1.0, -1.0, -2.5, 2.5, 5.5, 0.0),
        ("SMOOTHSTEP", true, -1.0, -1.5, 0.0, -1.5, -1.0, 1.5, -1.3703704),
        ("SMOOTHSTEP", true, -1.0, -2.0, 1.5, 0.5, -3.0, 0.0, -0.1938776),
        ("SMOOTHSTEP", true, -0.5, -1.0, -1.0, -2.5, 2.5, 5.5, 0.0),
        ("STEPPED", false, 2.020091, 0.6478262, 1.3001766, 0.9019146, -0.51300144, 3.47077, -2.7670825),
        ("STEPPED", false, -0.97859, -1.3929176, -0.6871948, -2.1415787, 0.5098171, -0.059404373, -2.1415787),
        ("STEPPED", true, 2.020091, 0.6478262, 1.3001766, 0.9019146, -0.51300144, 3.47077, -0.51300144),
        ("STEPPED", true, -0.97859, -1.3929176, -0.6871948, -2.1415787, 0.5098171, -0.059404373, -2.1415787),
        ("STEPPED", false, 2.0, 0.5, 1.5, 1.0, -0.5, 3.5, -1.5714285),
        ("STEPPED", false, -1.0, -1.5, -0.5, -2.0, 0.5, 0.0, -2.0),
        ("STEPPED", false, -0.5, -1.0, -1.0, -2.5, 2.5, 5.5, 0.0),
        ("STEPPED", true, 2.0, 0.5, 1.5, 1.0, -0.5, 3.5, -0.5),
        ("STEPPED", true, -1.0, -1.5, -0.5, -2.0, 0.5, 0.0, -2.0),
        ("STEPPED", true, -0.5, -1.0, -1.0, -2.5, 2.5, 5.5, 0.0),
    ];

    /// Vector Map Range rows: measured from Cycles 5.0.
    #[rustfmt::skip]
    const VECTOR_MAP_RANGE: &[(&str, bool, [f32; 3], [f32; 3], [f32; 3], [f32; 3], [f32; 3], [f32; 3], [f32; 3])] = &[
        ("LINEAR", false, [-1.4835119, -2.5414524, 2.0340385], [-1.0823917, -1.7876873, -0.47048187], [-1.1757774, 1.8745499, -0.56386566], [-1.9037418, 2.671749, -0.9858856], [-2.4103832, -0.06801224, -1.4925156], [-0.47552872, 2.2572308, 0.5953102], [-4.079922, 3.2356493, 12.601751]),
        ("LINEAR", true, [-1.4835119, -2.5414524, 2.0340385], [-1.0823917, -1.7876873, -0.47048187], [-1.1757774, 1.8745499, -0.56386566], [-1.9037418, 2.671749, -0.9858856], [-2.4103832, -0.06801224, -1.4925156], [-0.47552872, 2.2572308, 0.5953102], [-2.4103832, 2.671749, -0.9858856]),
        ("SMOOTHERSTEP", false, [1.1216927, 1.8115253, -0.06458473], [-0.7000389, -0.24015045, 1.3922424], [1.8521271, 0.601387, -0.055595398], [0.60643387, -1.2696762, -2.2551613], [1.8687401, 0.883255, -0.9928436], [2.146494, 0.9967613, 5.8079796], [1.6853126, 0.883255, -0.9928436]),
        ("SMOOTHERSTEP", true, [1.1216927, 1.8115253, -0.06458473], [-0.7000389, -0.24015045, 1.3922424], [1.8521271, 0.601387, -0.055595398], [0.60643387, -1.2696762, -2.2551613], [1.8687401, 0.883255, -0.9928436], [2.146494, 0.9967613, 5.8079796], [1.6853126, 0.883255, -0.9928436]),
        ("SMOOTHSTEP", false, [-0.16272354, 1.2239571, 0.44971848], [-1.0150986, -0.09063721, 1.1538239], [-1.9217072, 1.5621185, 0.24720764], [1.757515, 0.98327637, -0.98908997], [-1.7633514, 2.2642822, 1.4900436], [5.8561783, 3.5550842, 2.6517792], [1.757515, 2.1253464, 1.1742201]),
        ("SMOOTHSTEP", true, [-0.16272354, 1.2239571, 0.44971848], [-1.0150986, -0.09063721, 1.1538239], [-1.9217072, 1.5621185, 0.24720764], [1.757515, 0.98327637, -0.98908997], [-1.7633514, 2.2642822, 1.4900436], [5.8561783, 3.5550842, 2.6517792], [1.757515, 2.1253464, 1.1742201]),
        ("STEPPED", false, [-0.48945522, -0.8991709, -0.537323], [1.6080225, 1.3348761, -0.18451548], [-0.4576578, -0.21643007, 1.749804], [2.2149873, 2.576829, -0.47382724], [-0.11197829, 2.8373652, -2.800774], [5.7544203, 2.1953351, 2.6174793], [-0.21128547, 3.0515378, 0.4151757]),
        ("STEPPED", true, [-0.48945522, -0.8991709, -0.537323], [1.6080225, 1.3348761, -0.18451548], [-0.4576578, -0.21643007, 1.749804], [2.2149873, 2.576829, -0.47382724], [-0.11197829, 2.8373652, -2.800774], [5.7544203, 2.1953351, 2.6174793], [-0.11197829, 2.8373652, -0.47382724]),
    ];

    /// (clamp_type, value, min, max, result): measured from Cycles 5.0.
    #[rustfmt::skip]
    const CLAMP: &[(&str, f32, f32, f32, f32)] = &[
        ("MINMAX", 1.0, 0.0, -2.0, -2.0),
        ("MINMAX", 2.0, -1.5, 0.5, 0.5),
        ("MINMAX", 3.0, -1.5, -0.5, -0.5),
        ("RANGE", 1.0, 0.5, 1.0, 1.0),
        ("RANGE", -2.5, 1.0, -1.0, -1.0),
        ("RANGE", -0.5, 0.5, 1.0, 0.5),
        ("MINMAX", 1.2334521, 0.22897148, -1.8206043, -1.8206043),
        ("MINMAX", 1.7624431, -1.2619543, 0.53863025, 0.53863025),
        ("MINMAX", 2.9694471, -1.3026161, -0.523612, -0.523612),
        ("RANGE", 0.794829, 0.4841435, 0.8671515, 0.794829),
        ("RANGE", -2.3005085, 0.874527, -1.0035248, -1.0035248),
        ("RANGE", -0.7366948, 0.26336193, 1.0853558, 0.26336193),
    ];
}
