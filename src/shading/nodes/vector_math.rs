//! Vector Math node (`ShaderNodeVectorMath`), evaluated like Cycles' `svm_vector_math`
//! (`kernel/svm/math_util.h`, `util/math_float3.h`) as compiled for the x86-64 CPU kernel
//! (SSE4.2 paths: `min`/`max` are `_mm_min_ps`/`_mm_max_ps`, MODULO is
//! `a - trunc(a / b) * b`). Every function is total: NaN and infinities never panic.

use super::math::{cmax, cmin, compatible_sign, safe_pow};
use glam::Vec3;

/// Vector Math operation, named after Blender's `ShaderNodeVectorMath.operation` identifiers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum VectorMathOp {
    Add,
    Subtract,
    Multiply,
    Divide,
    MultiplyAdd,
    CrossProduct,
    Project,
    Reflect,
    Refract,
    Faceforward,
    DotProduct,
    Distance,
    Length,
    Scale,
    Normalize,
    Absolute,
    Power,
    Sign,
    Minimum,
    Maximum,
    Floor,
    Ceil,
    Fraction,
    Modulo,
    Wrap,
    Snap,
    Sine,
    Cosine,
    Tangent,
}

impl VectorMathOp {
    /// Every operation, in Blender's enum order.
    pub const ALL: [VectorMathOp; 29] = {
        use VectorMathOp::*;
        [
            Add,
            Subtract,
            Multiply,
            Divide,
            MultiplyAdd,
            CrossProduct,
            Project,
            Reflect,
            Refract,
            Faceforward,
            DotProduct,
            Distance,
            Length,
            Scale,
            Normalize,
            Absolute,
            Power,
            Sign,
            Minimum,
            Maximum,
            Floor,
            Ceil,
            Fraction,
            Modulo,
            Wrap,
            Snap,
            Sine,
            Cosine,
            Tangent,
        ]
    };

    /// Parses a Blender RNA identifier such as `"CROSS_PRODUCT"`.
    pub fn from_blender(s: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|op| op.blender_name() == s)
    }

    /// The Blender RNA identifier.
    pub fn blender_name(self) -> &'static str {
        use VectorMathOp::*;
        match self {
            Add => "ADD",
            Subtract => "SUBTRACT",
            Multiply => "MULTIPLY",
            Divide => "DIVIDE",
            MultiplyAdd => "MULTIPLY_ADD",
            CrossProduct => "CROSS_PRODUCT",
            Project => "PROJECT",
            Reflect => "REFLECT",
            Refract => "REFRACT",
            Faceforward => "FACEFORWARD",
            DotProduct => "DOT_PRODUCT",
            Distance => "DISTANCE",
            Length => "LENGTH",
            Scale => "SCALE",
            Normalize => "NORMALIZE",
            Absolute => "ABSOLUTE",
            Power => "POWER",
            Sign => "SIGN",
            Minimum => "MINIMUM",
            Maximum => "MAXIMUM",
            Floor => "FLOOR",
            Ceil => "CEIL",
            Fraction => "FRACTION",
            Modulo => "MODULO",
            Wrap => "WRAP",
            Snap => "SNAP",
            Sine => "SINE",
            Cosine => "COSINE",
            Tangent => "TANGENT",
        }
    }

    /// True for the operations whose result is the scalar `Value` output
    /// (DOT_PRODUCT, DISTANCE, LENGTH); all others produce the `Vector` output.
    pub fn outputs_value(self) -> bool {
        matches!(
            self,
            VectorMathOp::DotProduct | VectorMathOp::Distance | VectorMathOp::Length
        )
    }
}

/// `(x*x + y*y) + z*z`, the order of SSE4.1 `_mm_dp_ps(a, b, 0x7F)`.
#[inline]
pub fn dot(a: Vec3, b: Vec3) -> f32 {
    (a.x * b.x + a.y * b.y) + a.z * b.z
}

/// `sqrt(dot(a, a))`.
#[inline]
pub fn length(a: Vec3) -> f32 {
    dot(a, a).sqrt()
}

/// Cycles `safe_normalize`: `a * (1 / |a|)`, or `a` unchanged when `|a| == 0`.
#[inline]
pub fn safe_normalize(a: Vec3) -> Vec3 {
    let t = length(a);
    if t != 0.0 { a * (1.0 / t) } else { a }
}

/// Component-wise `b != 0 ? a / b : 0`.
#[inline]
pub fn safe_divide(a: Vec3, b: Vec3) -> Vec3 {
    let d = |a: f32, b: f32| if b != 0.0 { a / b } else { 0.0 };
    Vec3::new(d(a.x, b.x), d(a.y, b.y), d(a.z, b.z))
}

/// Component-wise Cycles `min` (`a < b ? a : b`).
#[inline]
pub fn vmin(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::new(cmin(a.x, b.x), cmin(a.y, b.y), cmin(a.z, b.z))
}

/// Component-wise Cycles `max` (`a > b ? a : b`).
#[inline]
pub fn vmax(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::new(cmax(a.x, b.x), cmax(a.y, b.y), cmax(a.z, b.z))
}

#[inline]
fn map(a: Vec3, f: impl Fn(f32) -> f32) -> Vec3 {
    Vec3::new(f(a.x), f(a.y), f(a.z))
}

#[inline]
fn zip(a: Vec3, b: Vec3, f: impl Fn(f32, f32) -> f32) -> Vec3 {
    Vec3::new(f(a.x, b.x), f(a.y, b.y), f(a.z, b.z))
}

/// Cross product with Cycles' component order.
#[inline]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::new(
        a.y * b.z - a.z * b.y,
        a.z * b.x - a.x * b.z,
        a.x * b.y - a.y * b.x,
    )
}

/// Evaluates the Vector Math node. Inputs are sockets 0..2 (`a`, `b`, `c`) and `Scale`
/// (which is also REFRACT's IOR). Returns `(Vector, Value)`; the output an operation
/// does not produce is zero.
///
/// Definitions that differ from textbook ones: DIVIDE and SNAP use a per-component safe
/// divide (0 where `b == 0`); NORMALIZE returns a zero vector unchanged; PROJECT gives 0
/// for `b == 0`; REFLECT and REFRACT normalize `b` first, REFRACT gives 0 on total
/// internal reflection; FACEFORWARD is `dot(c, b) < 0 ? a : -a`; MODULO is
/// `a - trunc(a / b) * b` (0 where `b == 0`); WRAP is floored `(a - c) mod (b - c) + c`
/// (`c` where `b == c`); POWER is the scalar [`safe_pow`] per component; SIGN gives 0 for 0.
pub fn vector_math(op: VectorMathOp, a: Vec3, b: Vec3, c: Vec3, scale: f32) -> (Vec3, f32) {
    use VectorMathOp::*;
    let v = match op {
        Add => a + b,
        Subtract => a - b,
        Multiply => a * b,
        Divide => safe_divide(a, b),
        MultiplyAdd => a * b + c,
        CrossProduct => cross(a, b),
        Project => {
            let len2 = dot(b, b);
            if len2 != 0.0 {
                b * (dot(a, b) / len2)
            } else {
                Vec3::ZERO
            }
        }
        Reflect => {
            let n = safe_normalize(b);
            a - (n * 2.0) * dot(a, n)
        }
        Refract => {
            let n = safe_normalize(b);
            let eta = scale;
            let d = dot(n, a);
            let k = 1.0 - eta * eta * (1.0 - d * d);
            if k < 0.0 {
                Vec3::ZERO
            } else {
                a * eta - n * (eta * d + k.sqrt())
            }
        }
        Faceforward => {
            if dot(c, b) < 0.0 {
                a
            } else {
                -a
            }
        }
        DotProduct => return (Vec3::ZERO, dot(a, b)),
        Distance => return (Vec3::ZERO, length(a - b)),
        Length => return (Vec3::ZERO, length(a)),
        Scale => a * scale,
        Normalize => safe_normalize(a),
        Absolute => a.abs(),
        Power => zip(a, b, safe_pow),
        Sign => map(a, compatible_sign),
        Minimum => vmin(a, b),
        Maximum => vmax(a, b),
        Floor => a.floor(),
        Ceil => a.ceil(),
        Fraction => a - a.floor(),
        Modulo => zip(a, b, |a, b| {
            if b == 0.0 {
                0.0
            } else {
                a - (a / b).trunc() * b
            }
        }),
        Wrap => wrap(a, b, c),
        Snap => safe_divide(a, b).floor() * b,
        Sine => map(a, f32::sin),
        Cosine => map(a, f32::cos),
        Tangent => map(a, f32::tan),
    };
    (v, 0.0)
}

/// Cycles vector `wrap(value, max, min) = floored_fmod(value - min, max - min) + min`,
/// per component, where `floored_fmod(a, b) = b == 0 ? 0 : a - floor(a / b) * b`.
#[inline]
pub fn wrap(value: Vec3, max: Vec3, min: Vec3) -> Vec3 {
    let f = |v: f32, hi: f32, lo: f32| {
        let a = v - lo;
        let b = hi - lo;
        let m = if b == 0.0 {
            0.0
        } else {
            a - (a / b).floor() * b
        };
        m + lo
    };
    Vec3::new(
        f(value.x, max.x, min.x),
        f(value.y, max.y, min.y),
        f(value.z, max.z, min.z),
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

    fn v(a: [f32; 3]) -> Vec3 {
        Vec3::from_array(a)
    }

    #[test]
    fn names_round_trip() {
        for op in VectorMathOp::ALL {
            assert_eq!(VectorMathOp::from_blender(op.blender_name()), Some(op));
        }
        assert_eq!(VectorMathOp::from_blender("DOT"), None);
        assert!(VectorMathOp::Length.outputs_value());
        assert!(!VectorMathOp::Scale.outputs_value());
    }

    #[test]
    fn edge_cases() {
        let z = Vec3::ZERO;
        let a = Vec3::new(3.0, -4.0, 5.0);
        let (r, _) = vector_math(VectorMathOp::Divide, a, Vec3::new(0.0, 2.0, -0.0), z, 0.0);
        assert_eq!(r, Vec3::new(0.0, -2.0, 0.0));
        assert_eq!(vector_math(VectorMathOp::Normalize, z, z, z, 0.0).0, z);
        assert_eq!(vector_math(VectorMathOp::Project, a, z, z, 0.0).0, z);
        assert_eq!(vector_math(VectorMathOp::Reflect, a, z, z, 0.0).0, a);
        let (m, _) = vector_math(
            VectorMathOp::Modulo,
            Vec3::new(-5.5, 5.5, 1.0),
            Vec3::new(2.0, -2.0, 0.0),
            z,
            0.0,
        );
        assert_eq!(m, Vec3::new(-1.5, 1.5, 0.0));
        let (w, _) = vector_math(
            VectorMathOp::Wrap,
            Vec3::new(5.5, -0.5, 1.0),
            Vec3::new(2.0, 2.0, 3.0),
            Vec3::new(0.0, 0.0, 3.0),
            0.0,
        );
        assert_eq!(w, Vec3::new(1.5, 1.5, 3.0));
        let (s, _) = vector_math(
            VectorMathOp::Snap,
            Vec3::new(-2.5, 2.5, 1.0),
            Vec3::new(2.0, 2.0, 0.0),
            z,
            0.0,
        );
        assert_eq!(s, Vec3::new(-4.0, 2.0, 0.0));
        let (sg, _) = vector_math(VectorMathOp::Sign, Vec3::new(-2.0, 0.0, 3.0), z, z, 0.0);
        assert_eq!(sg, Vec3::new(-1.0, 0.0, 1.0));
        // Total internal reflection gives zero.
        let (t, _) = vector_math(
            VectorMathOp::Refract,
            Vec3::new(1.0, 0.0, -0.1),
            Vec3::Z,
            z,
            1.5,
        );
        assert_eq!(t, z);
        let (f, _) = vector_math(VectorMathOp::Faceforward, a, Vec3::Z, Vec3::Z, 0.0);
        assert_eq!(f, -a);
        assert_eq!(
            vector_math(VectorMathOp::Length, a, z, z, 0.0),
            (z, 50f32.sqrt())
        );
        // Cycles min/max return the second operand when the first is NaN.
        let (mn, _) = vector_math(
            VectorMathOp::Minimum,
            Vec3::splat(f32::NAN),
            Vec3::ONE,
            z,
            0.0,
        );
        assert_eq!(mn, Vec3::ONE);
    }

    #[test]
    fn no_panics_on_non_finite() {
        let vals = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            0.0,
            -0.0,
            1e38,
            1.0,
        ];
        for op in VectorMathOp::ALL {
            for &x in &vals {
                for &y in &vals {
                    let a = Vec3::new(x, y, 1.0);
                    let b = Vec3::new(y, 0.0, x);
                    let _ = vector_math(op, a, b, a, x);
                }
            }
        }
    }

    /// Vector Math outputs measured from Cycles 5.0 renders.
    #[test]
    fn measured_from_cycles() {
        for &(op, a, b, c, scale, want) in CYCLES_MEASURED {
            let op = VectorMathOp::from_blender(op).unwrap();
            let (vec, val) = vector_math(op, v(a), v(b), v(c), scale);
            let got = if op.outputs_value() {
                Vec3::new(val, 0.0, 0.0)
            } else {
                vec
            };
            let want = v(want);
            let tol = 1e-5 * want.abs().max_element().max(1.0);
            assert!(
                (got - want).abs().max_element() <= tol,
                "{op:?}: {got} vs Cycles {want}"
            );
        }
    }

    /// (op, a, b, c, scale, Vector output or [Value, 0, 0]): measured from Cycles 5.0.
    #[rustfmt::skip]
    const CYCLES_MEASURED: &[(&str, [f32; 3], [f32; 3], [f32; 3], f32, [f32; 3])] = &[
        ("ABSOLUTE", [1.5, -1.5, -1.0], [1.5, -1.5, -4.0], [1.5, 2.0, -4.0], -0.5, [1.5, 1.5, 1.0]),
        ("ABSOLUTE", [-3.0, -2.0, 1.0], [2.5, 3.5, -1.5], [-0.5, 2.5, 4.0], -1.5, [3.0, 2.0, 1.0]),
        ("ABSOLUTE", [0.639698, 1.6266747, -3.5600967], [-0.8343582, 0.15261841, -3.295395], [-2.3084183, 0.5048065, 3.230545], 0.31730652, [0.639698, 1.6266747, 3.5600967]),
        ("ADD", [0.5, 3.0, 0.0], [0.5, 3.5, -2.0], [0.5, -3.0, -2.0], 0.0, [1.0, 6.5, -2.0]),
        ("ADD", [-0.5, 3.5, -4.0], [-3.0, 1.0, -1.0], [2.5, 3.5, -3.5], 1.0, [-3.5, 4.5, -5.0]),
        ("ADD", [-0.56300354, 3.3572235, -3.7837677], [-2.9447784, 0.9754791, -1.2467957], [2.673462, 3.5324707, -3.62854], 1.0824432, [-3.507782, 4.3327026, -5.0305634]),
        ("CEIL", [-3.0, -2.5, 0.0], [-1.0, -0.5, 0.0], [0.5, 3.0, 1.5], 0.5, [-3.0, -2.0, 0.0]),
        ("CEIL", [-4.0, -1.0, -2.0], [-3.5, -0.5, 2.0], [-3.5, 4.0, 2.0], -0.5, [-4.0, -1.0, -2.0]),
        ("CEIL", [0.4453888, 1.0742645, 3.5293922], [3.4870262, -3.8840942, -2.1002197], [-1.471344, 0.9837799, 0.9414139], 1.9462738, [1.0, 2.0, 4.0]),
        ("COSINE", [-1.5, 2.0, 1.0], [2.5, -2.0, 2.5], [-2.0, -3.0, -1.5], -1.0, [0.0707372, -0.41614684, 0.5403023]),
        ("COSINE", [1.5, 1.5, -1.0], [2.5, 2.0, 3.0], [3.0, 0.5, 3.5], 1.5, [0.0707372, 0.0707372, 0.5403023]),
        ("COSINE", [-1.6455269, 1.8580456, 0.7828646], [2.272688, -2.2237396, 2.6873322], [-1.8090954, -2.8842754, -1.3944511], -1.1092758, [-0.074661024, -0.28331527, 0.70889604]),
        ("CROSS_PRODUCT", [-4.0, -3.0, -3.0], [-2.0, -1.0, -0.5], [0.5, 0.0, 1.5], -0.5, [-1.5, 4.0, -2.0]),
        ("CROSS_PRODUCT", [-3.0, -3.5, -3.5], [-1.0, -1.5, 2.0], [1.5, 2.0, -3.5], 2.0, [-12.25, 9.5, 1.0]),
        ("CROSS_PRODUCT", [-0.36193085, 0.42367554, 0.28302765], [2.972393, 3.7579956, -2.4788895], [-1.6932907, -1.833931, 0.8554306], 0.9660568, [-2.1138616, -0.055917166, -2.6194649]),
        ("DISTANCE", [1.5, -1.5, -1.0], [1.5, -1.5, -4.0], [1.5, 2.0, -4.0], -0.5, [3.0, 0.0, 0.0]),
        ("DISTANCE", [-3.0, -2.0, 1.0], [2.5, 3.5, -1.5], [-0.5, 2.5, 4.0], -1.5, [8.170068, 0.0, 0.0]),
        ("DISTANCE", [0.639698, 1.6266747, -3.5600967], [-0.8343582, 0.15261841, -3.295395], [-2.3084183, 0.5048065, 3.230545], 0.31730652, [2.1013687, 0.0, 0.0]),
        ("DIVIDE", [-1.5, 2.0, 1.0], [2.5, -2.0, 2.5], [-2.0, -3.0, -1.5], -1.0, [-0.6, -1.0, 0.4]),
        ("DIVIDE", [1.5, 1.5, -1.0], [2.5, 2.0, 3.0], [3.0, 0.5, 3.5], 1.5, [0.6, 0.75, -0.33333334]),
        ("DIVIDE", [-1.6455269, 1.8580456, 0.7828646], [2.272688, -2.2237396, 2.6873322], [-1.8090954, -2.8842754, -1.3944511], -1.1092758, [-0.7240444, -0.83554995, 0.29131663]),
        ("DOT_PRODUCT", [2.5, -0.5, 3.5], [-3.0, 2.0, 2.5], [-1.0, 3.0, -3.5], 1.0, [0.25, 0.0, 0.0]),
        ("DOT_PRODUCT", [3.0, 0.0, -4.0], [1.5, -1.0, 3.5], [0.5, -3.5, 2.0], -1.0, [-9.5, 0.0, 0.0]),
        ("DOT_PRODUCT", [-1.8593826, 2.969574, -1.2302322], [1.6399612, -1.5310745, 0.3103714], [-2.860672, 0.9395294, 3.8097382], -1.360466, [-7.977783, 0.0, 0.0]),
        ("FACEFORWARD", [2.5, -0.5, 3.5], [-3.0, 2.0, 2.5], [-1.0, 3.0, -3.5], 1.0, [-2.5, 0.5, -3.5]),
        ("FACEFORWARD", [3.0, 0.0, -4.0], [1.5, -1.0, 3.5], [0.5, -3.5, 2.0], -1.0, [-3.0, 0.0, 4.0]),
        ("FACEFORWARD", [-1.8593826, 2.969574, -1.2302322], [1.6399612, -1.5310745, 0.3103714], [-2.860672, 0.9395294, 3.8097382], -1.360466, [-1.8593826, 2.969574, -1.2302322]),
        ("FLOOR", [-1.5, 2.5, 4.0], [2.0, -1.5, 1.5], [-2.0, -1.0, -2.5], -1.5, [-2.0, 2.0, 4.0]),
        ("FLOOR", [0.5, -2.0, 1.0], [2.0, -0.5, -2.0], [3.5, -1.5, -0.5], 0.5, [0.0, -2.0, 1.0]),
        ("FLOOR", [-3.8976593, 1.453537, -3.459015], [-1.1890717, -3.8378754, -3.8316803], [1.519516, -3.393036, -1.1230774], -1.630539, [-4.0, 1.0, -4.0]),
        ("FRACTION", [1.5, -1.5, -1.0], [1.5, -1.5, -4.0], [1.5, 2.0, -4.0], -0.5, [0.5, 0.5, 0.0]),
        ("FRACTION", [-3.0, -2.0, 1.0], [2.5, 3.5, -1.5], [-0.5, 2.5, 4.0], -1.5, [0.0, 0.0, 0.0]),
        ("FRACTION", [0.639698, 1.6266747, -3.5600967], [-0.8343582, 0.15261841, -3.295395], [-2.3084183, 0.5048065, 3.230545], 0.31730652, [0.639698, 0.62667465, 0.43990326]),
        ("LENGTH", [-1.5, 2.0, 1.0], [2.5, -2.0, 2.5], [-2.0, -3.0, -1.5], -1.0, [2.6925824, 0.0, 0.0]),
        ("LENGTH", [1.5, 1.5, -1.0], [2.5, 2.0, 3.0], [3.0, 0.5, 3.5], 1.5, [2.345208, 0.0, 0.0]),
        ("LENGTH", [-1.6455269, 1.8580456, 0.7828646], [2.272688, -2.2237396, 2.6873322], [-1.8090954, -2.8842754, -1.3944511], -1.1092758, [2.6024928, 0.0, 0.0]),
        ("MAXIMUM", [-4.0, -1.0, -2.0], [-2.5, 0.5, -4.0], [-1.0, -2.0, -2.5], -1.0, [-2.5, 0.5, -2.0]),
        ("MAXIMUM", [-4.0, 1.0, -3.0], [-0.5, -4.0, -2.0], [3.0, -1.0, 1.5], 1.5, [-0.5, 1.0, -2.0]),
        ("MAXIMUM", [-0.45568848, 2.4044952, 1.4059296], [2.2523727, -2.8874512, 2.1002426], [-3.039566, 3.961853, -3.1917114], 0.53685, [2.2523727, 2.4044952, 2.1002426]),
        ("MINIMUM", [-4.0, -1.0, -2.0], [-2.5, 0.5, -4.0], [-1.0, -2.0, -2.5], -1.0, [-4.0, -1.0, -4.0]),
        ("MINIMUM", [-4.0, 1.0, -3.0], [-0.5, -4.0, -2.0], [3.0, -1.0, 1.5], 1.5, [-4.0, -4.0, -3.0]),
        ("MINIMUM", [-0.45568848, 2.4044952, 1.4059296], [2.2523727, -2.8874512, 2.1002426], [-3.039566, 3.961853, -3.1917114], 0.53685, [-0.45568848, -2.8874512, 1.4059296]),
        ("MODULO", [-1.5, 2.0, 1.0], [2.5, -2.0, 2.5], [-2.0, -3.0, -1.5], -1.0, [-1.5, 0.0, 1.0]),
        ("MODULO", [1.5, 1.5, -1.0], [2.5, 2.0, 3.0], [3.0, 0.5, 3.5], 1.5, [1.5, 1.5, -1.0]),
        ("MODULO", [-1.6455269, 1.8580456, 0.7828646], [2.272688, -2.2237396, 2.6873322], [-1.8090954, -2.8842754, -1.3944511], -1.1092758, [-1.6455269, 1.8580456, 0.7828646]),
        ("MULTIPLY", [1.5, -1.5, -1.0], [1.5, -1.5, -4.0], [1.5, 2.0, -4.0], -0.5, [2.25, 2.25, 4.0]),
        ("MULTIPLY", [-3.0, -2.0, 1.0], [2.5, 3.5, -1.5], [-0.5, 2.5, 4.0], -1.5, [-7.5, -7.0, -1.5]),
        ("MULTIPLY", [0.639698, 1.6266747, -3.5600967], [-0.8343582, 0.15261841, -3.295395], [-2.3084183, 0.5048065, 3.230545], 0.31730652, [-0.5337373, 0.2482605, 11.731925]),
        ("MULTIPLY_ADD", [-2.5, 1.5, -2.0], [0.5, -3.5, 0.0], [4.0, 0.0, 3.0], -1.5, [2.75, -5.25, 3.0]),
        ("MULTIPLY_ADD", [-2.5, 0.5, 3.0], [-0.5, 3.0, -1.0], [2.0, -4.0, 1.0], -0.5, [3.25, -2.5, -2.0]),
        ("MULTIPLY_ADD", [-2.404255, 1.3455734, -2.235855], [0.67773056, -3.572441, 0.009887695], [3.7597122, 0.17829132, 3.0918732], -1.4967117, [2.1302752, -4.6286907, 3.0697658]),
        ("NORMALIZE", [-2.0, -0.5, -1.5], [1.0, 2.5, 2.5], [-4.0, 3.0, -2.0], -1.5, [-0.78446454, -0.19611613, -0.5883484]),
        ("NORMALIZE", [0.5, -0.5, -0.5], [-1.0, -2.0, -1.0], [-2.0, -2.0, -2.0], 2.0, [0.57735026, -0.57735026, -0.57735026]),
        ("NORMALIZE", [-2.2276764, -0.59316254, -1.5823822], [0.99838257, 2.6329117, 2.58992], [-3.7755432, 3.2352295, -2.1840057], -1.5647888, [-0.7967012, -0.21213733, -0.56591964]),
        ("POWER", [-1.0, 2.0, 3.0], [1.5, -1.0, 1.0], [-1.5, -0.5, -2.0], -1.5, [0.0, 0.5, 3.0]),
        ("POWER", [0.5, -1.5, 1.0], [1.5, -0.5, -1.5], [2.5, -1.0, -0.5], 0.5, [0.35355338, 0.0, 1.0]),
        ("POWER", [-2.9232445, 1.0901527, -2.5942612], [-0.89180374, -2.8784065, -2.8737602], [1.139637, -2.544777, -0.84230804], -1.630539, [0.0, 0.78000283, 0.0]),
        ("PROJECT", [-4.0, -1.0, -2.0], [-2.5, 0.5, -4.0], [-1.0, -2.0, -2.5], -1.0, [-1.9444444, 0.3888889, -3.1111112]),
        ("PROJECT", [-4.0, 1.0, -3.0], [-0.5, -4.0, -2.0], [3.0, -1.0, 1.5], 1.5, [-0.09876543, -0.79012346, -0.39506173]),
        ("PROJECT", [-0.45568848, 2.4044952, 1.4059296], [2.2523727, -2.8874512, 2.1002426], [-3.039566, 3.961853, -3.1917114], 0.53685, [-0.63400203, 0.81276506, -0.59118015]),
        ("REFLECT", [-4.0, -1.0, -2.0], [-2.5, 0.5, -4.0], [-1.0, -2.0, -2.5], -1.0, [-0.111111246, -1.7777778, 4.2222223]),
        ("REFLECT", [-4.0, 1.0, -3.0], [-0.5, -4.0, -2.0], [3.0, -1.0, 1.5], 1.5, [-3.802469, 2.580247, -2.2098765]),
        ("REFLECT", [-0.45568848, 2.4044952, 1.4059296], [2.2523727, -2.8874512, 2.1002426], [-3.039566, 3.961853, -3.1917114], 0.53685, [0.8123154, 0.7789653, 2.5882897]),
        ("REFRACT", [-4.0, -1.0, -2.0], [-2.5, 0.5, -4.0], [-1.0, -2.0, -2.5], 1.0, [-0.111111246, -1.7777778, 4.2222223]),
        ("REFRACT", [-4.0, 1.0, -3.0], [-0.5, -4.0, -2.0], [3.0, -1.0, 1.5], 2.0, [-7.757956, 3.9363513, -5.031824]),
        ("REFRACT", [-0.45568848, 2.4044952, 1.4059296], [2.2523727, -2.8874512, 2.1002426], [-3.039566, 3.961853, -3.1917114], 1.4513187, [-0.47040376, 3.2449048, 2.2185006]),
        ("SCALE", [-1.5, 2.5, 4.0], [2.0, -1.5, 1.5], [-2.0, -1.0, -2.5], -1.5, [2.25, -3.75, -6.0]),
        ("SCALE", [0.5, -2.0, 1.0], [2.0, -0.5, -2.0], [3.5, -1.5, -0.5], 0.5, [0.25, -1.0, 0.5]),
        ("SCALE", [-3.8976593, 1.453537, -3.459015], [-1.1890717, -3.8378754, -3.8316803], [1.519516, -3.393036, -1.1230774], -1.630539, [6.355285, -2.3700488, 5.6400585]),
        ("SIGN", [-3.0, -2.5, 0.0], [-1.0, -0.5, 0.0], [0.5, 3.0, 1.5], 0.5, [-1.0, -1.0, 0.0]),
        ("SIGN", [-4.0, -1.0, -2.0], [-3.5, -0.5, 2.0], [-3.5, 4.0, 2.0], -0.5, [-1.0, -1.0, -1.0]),
        ("SIGN", [0.4453888, 1.0742645, 3.5293922], [3.4870262, -3.8840942, -2.1002197], [-1.471344, 0.9837799, 0.9414139], 1.9462738, [1.0, 1.0, 1.0]),
        ("SINE", [-3.0, -2.5, 0.0], [-1.0, -0.5, 0.0], [0.5, 3.0, 1.5], 0.5, [-0.14112, -0.5984721, 0.0]),
        ("SINE", [-4.0, -1.0, -2.0], [-3.5, -0.5, 2.0], [-3.5, 4.0, 2.0], -0.5, [0.7568025, -0.84147096, -0.9092974]),
        ("SINE", [0.4453888, 1.0742645, 3.5293922], [3.4870262, -3.8840942, -2.1002197], [-1.471344, 0.9837799, 0.9414139], 1.9462738, [0.43080878, 0.87924004, -0.3781523]),
        ("SNAP", [-3.0, -2.5, 0.0], [-1.0, -0.5, 0.0], [0.5, 3.0, 1.5], 0.5, [-3.0, -2.5, 0.0]),
        ("SNAP", [-4.0, -1.0, -2.0], [-3.5, -0.5, 2.0], [-3.5, 4.0, 2.0], -0.5, [-3.5, -1.0, -2.0]),
        ("SNAP", [0.4453888, 1.0742645, 3.5293922], [3.4870262, -3.8840942, -2.1002197], [-1.471344, 0.9837799, 0.9414139], 1.9462738, [0.0, 3.8840942, 4.2004395]),
        ("SUBTRACT", [1.5, -1.5, -1.0], [1.5, -1.5, -4.0], [1.5, 2.0, -4.0], -0.5, [0.0, 0.0, 3.0]),
        ("SUBTRACT", [-3.0, -2.0, 1.0], [2.5, 3.5, -1.5], [-0.5, 2.5, 4.0], -1.5, [-5.5, -5.5, 2.5]),
        ("SUBTRACT", [0.639698, 1.6266747, -3.5600967], [-0.8343582, 0.15261841, -3.295395], [-2.3084183, 0.5048065, 3.230545], 0.31730652, [1.4740562, 1.4740562, -0.26470184]),
        ("TANGENT", [-4.0, -1.0, -2.0], [-2.5, 0.5, -4.0], [-1.0, -2.0, -2.5], -1.0, [-1.1578213, -1.5574077, 2.1850398]),
        ("TANGENT", [-4.0, 1.0, -3.0], [-0.5, -4.0, -2.0], [3.0, -1.0, 1.5], 1.5, [-1.1578213, 1.5574077, 0.14254655]),
        ("TANGENT", [-0.45568848, 2.4044952, 1.4059296], [2.2523727, -2.8874512, 2.1002426], [-3.039566, 3.961853, -3.1917114], 0.53685, [-0.4900903, -0.907781, 6.0104485]),
        ("WRAP", [-3.0, -2.5, 0.0], [-1.0, -0.5, 0.0], [0.5, 3.0, 1.5], 0.5, [0.0, 1.0, 1.5]),
        ("WRAP", [-4.0, -1.0, -2.0], [-3.5, -0.5, 2.0], [-3.5, 4.0, 2.0], -0.5, [-3.5, 3.5, 2.0]),
        ("WRAP", [0.4453888, 1.0742645, 3.5293922], [3.4870262, -3.8840942, -2.1002197], [-1.471344, 0.9837799, 0.9414139], 1.9462738, [0.4453888, -3.7936096, 0.48775864]),
    ];
}
