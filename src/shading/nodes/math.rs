//! Math node (`ShaderNodeMath`), evaluated exactly like Cycles' SVM `svm_math`
//! (`intern/cycles/kernel/svm/math_util.h`, `util/math_base.h`).
//!
//! Also holds the small scalar helpers with Cycles' exact semantics that the other
//! node modules share (`cmin`/`cmax`/`clamp`/`saturate`, `float_to_int`, ...).
//! Every function is total: NaN and infinities never panic.

/// Cycles `min(a, b)` for floats: `a < b ? a : b` (returns `b` when either is NaN).
/// This is also what SSE `_mm_min_ps(a, b)` computes per lane.
#[inline]
pub fn cmin(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// Cycles `max(a, b)` for floats: `a > b ? a : b` (returns `b` when either is NaN).
#[inline]
pub fn cmax(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// Cycles `clamp(a, lo, hi) = min(max(a, lo), hi)`; NaN maps to `lo`.
#[inline]
pub fn clamp(a: f32, lo: f32, hi: f32) -> f32 {
    cmin(cmax(a, lo), hi)
}

/// Cycles `saturatef`: clamp to [0, 1]; NaN maps to 0.
#[inline]
pub fn saturate(a: f32) -> f32 {
    clamp(a, 0.0, 1.0)
}

/// C `(int)f` as compiled for x86-64 (`cvttss2si`): truncation toward zero, and
/// `i32::MIN` for NaN or values outside the `i32` range (Rust's `as` saturates instead).
#[inline]
pub fn float_to_int(f: f32) -> i32 {
    if (-2147483648.0..2147483648.0).contains(&f) {
        f as i32
    } else {
        i32::MIN
    }
}

/// `x - floor(x)`.
#[inline]
pub fn fract(x: f32) -> f32 {
    x - x.floor()
}

/// `b != 0 ? a / b : 0`.
#[inline]
pub fn safe_divide(a: f32, b: f32) -> f32 {
    if b != 0.0 { a / b } else { 0.0 }
}

/// `b != 0 ? fmodf(a, b) : 0` (truncated remainder, sign of `a`).
#[inline]
pub fn safe_modulo(a: f32, b: f32) -> f32 {
    if b != 0.0 { a % b } else { 0.0 }
}

/// `b != 0 ? a - floor(a / b) * b : 0` (floored remainder, sign of `b`).
#[inline]
pub fn safe_floored_modulo(a: f32, b: f32) -> f32 {
    if b != 0.0 {
        a - (a / b).floor() * b
    } else {
        0.0
    }
}

/// Cycles `compatible_powf`: `x^0 = 1` (also `0^0`), `0^y = 0`, otherwise `powf`.
#[inline]
pub fn compatible_pow(x: f32, y: f32) -> f32 {
    if y == 0.0 {
        1.0
    } else if x == 0.0 {
        0.0
    } else {
        x.powf(y)
    }
}

/// Cycles `safe_powf`: 0 for a negative base with a non-integer exponent (the integer
/// test is `b != (float)(int)b`, so |b| >= 2^31 also counts as non-integer), otherwise
/// [`compatible_pow`].
#[inline]
pub fn safe_pow(a: f32, b: f32) -> f32 {
    if a < 0.0 && b != float_to_int(b) as f32 {
        return 0.0;
    }
    compatible_pow(a, b)
}

/// Cycles `safe_logf`: `log(a) / log(b)`, 0 when `a <= 0`, `b <= 0` or `log(b) == 0`.
#[inline]
pub fn safe_log(a: f32, b: f32) -> f32 {
    if a <= 0.0 || b <= 0.0 {
        return 0.0;
    }
    safe_divide(a.ln(), b.ln())
}

/// `sqrt(max(a, 0))` (NaN maps to 0).
#[inline]
pub fn safe_sqrt(a: f32) -> f32 {
    cmax(a, 0.0).sqrt()
}

/// `a > 0 ? 1 / sqrt(a) : 0`.
#[inline]
pub fn inverse_sqrt(a: f32) -> f32 {
    if a > 0.0 { 1.0 / a.sqrt() } else { 0.0 }
}

/// Cycles `wrapf(value, max, min)`: `value - range * floor((value - min) / range)` with
/// `range = max - min`; returns `min` when the range is 0.
#[inline]
pub fn wrap(value: f32, max: f32, min: f32) -> f32 {
    let range = max - min;
    if range != 0.0 {
        value - range * ((value - min) / range).floor()
    } else {
        min
    }
}

/// Cycles `pingpongf`: `|fract((a - b) / 2b) * 2b - b|`, 0 when `b == 0`.
#[inline]
pub fn pingpong(a: f32, b: f32) -> f32 {
    if b != 0.0 {
        (fract((a - b) / (b * 2.0)) * b * 2.0 - b).abs()
    } else {
        0.0
    }
}

/// Polynomial smooth minimum (`smoothminf`): `min(a, b) - h^3 k / 6` with
/// `h = max(k - |a - b|, 0) / k`; plain `fminf` when `k == 0`.
#[inline]
pub fn smooth_min(a: f32, b: f32, k: f32) -> f32 {
    if k != 0.0 {
        let h = (k - (a - b).abs()).max(0.0) / k;
        a.min(b) - h * h * h * k * (1.0 / 6.0)
    } else {
        a.min(b)
    }
}

/// Signum with `sign(0) = 0` (`compatible_signf`); NaN gives 1 (as `signf` does).
#[inline]
pub fn compatible_sign(f: f32) -> f32 {
    if f == 0.0 {
        0.0
    } else if f < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// `atan2(y, x)` except `atan2(0, 0) = 0` for every zero sign (`compatible_atan2`).
#[inline]
pub fn compatible_atan2(y: f32, x: f32) -> f32 {
    if x == 0.0 && y == 0.0 {
        0.0
    } else {
        y.atan2(x)
    }
}

/// Math node operation, named after Blender's `ShaderNodeMath.operation` identifiers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MathOp {
    Add,
    Subtract,
    Multiply,
    Divide,
    MultiplyAdd,
    Power,
    Logarithm,
    Sqrt,
    InverseSqrt,
    Absolute,
    Exponent,
    Minimum,
    Maximum,
    LessThan,
    GreaterThan,
    Sign,
    Compare,
    SmoothMin,
    SmoothMax,
    Round,
    Floor,
    Ceil,
    Trunc,
    Fract,
    Modulo,
    FlooredModulo,
    Wrap,
    Snap,
    PingPong,
    Sine,
    Cosine,
    Tangent,
    Arcsine,
    Arccosine,
    Arctangent,
    Arctan2,
    Sinh,
    Cosh,
    Tanh,
    Radians,
    Degrees,
}

impl MathOp {
    /// Every operation, in Blender's enum order.
    pub const ALL: [MathOp; 41] = [
        MathOp::Add,
        MathOp::Subtract,
        MathOp::Multiply,
        MathOp::Divide,
        MathOp::MultiplyAdd,
        MathOp::Power,
        MathOp::Logarithm,
        MathOp::Sqrt,
        MathOp::InverseSqrt,
        MathOp::Absolute,
        MathOp::Exponent,
        MathOp::Minimum,
        MathOp::Maximum,
        MathOp::LessThan,
        MathOp::GreaterThan,
        MathOp::Sign,
        MathOp::Compare,
        MathOp::SmoothMin,
        MathOp::SmoothMax,
        MathOp::Round,
        MathOp::Floor,
        MathOp::Ceil,
        MathOp::Trunc,
        MathOp::Fract,
        MathOp::Modulo,
        MathOp::FlooredModulo,
        MathOp::Wrap,
        MathOp::Snap,
        MathOp::PingPong,
        MathOp::Sine,
        MathOp::Cosine,
        MathOp::Tangent,
        MathOp::Arcsine,
        MathOp::Arccosine,
        MathOp::Arctangent,
        MathOp::Arctan2,
        MathOp::Sinh,
        MathOp::Cosh,
        MathOp::Tanh,
        MathOp::Radians,
        MathOp::Degrees,
    ];

    /// Parses a Blender RNA identifier such as `"MULTIPLY_ADD"`.
    pub fn from_blender(s: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|op| op.blender_name() == s)
    }

    /// The Blender RNA identifier.
    pub fn blender_name(self) -> &'static str {
        use MathOp::*;
        match self {
            Add => "ADD",
            Subtract => "SUBTRACT",
            Multiply => "MULTIPLY",
            Divide => "DIVIDE",
            MultiplyAdd => "MULTIPLY_ADD",
            Power => "POWER",
            Logarithm => "LOGARITHM",
            Sqrt => "SQRT",
            InverseSqrt => "INVERSE_SQRT",
            Absolute => "ABSOLUTE",
            Exponent => "EXPONENT",
            Minimum => "MINIMUM",
            Maximum => "MAXIMUM",
            LessThan => "LESS_THAN",
            GreaterThan => "GREATER_THAN",
            Sign => "SIGN",
            Compare => "COMPARE",
            SmoothMin => "SMOOTH_MIN",
            SmoothMax => "SMOOTH_MAX",
            Round => "ROUND",
            Floor => "FLOOR",
            Ceil => "CEIL",
            Trunc => "TRUNC",
            Fract => "FRACT",
            Modulo => "MODULO",
            FlooredModulo => "FLOORED_MODULO",
            Wrap => "WRAP",
            Snap => "SNAP",
            PingPong => "PINGPONG",
            Sine => "SINE",
            Cosine => "COSINE",
            Tangent => "TANGENT",
            Arcsine => "ARCSINE",
            Arccosine => "ARCCOSINE",
            Arctangent => "ARCTANGENT",
            Arctan2 => "ARCTAN2",
            Sinh => "SINH",
            Cosh => "COSH",
            Tanh => "TANH",
            Radians => "RADIANS",
            Degrees => "DEGREES",
        }
    }

    /// Number of inputs (1, 2 or 3) the operation reads.
    pub fn arity(self) -> usize {
        use MathOp::*;
        match self {
            MultiplyAdd | Compare | SmoothMin | SmoothMax | Wrap => 3,
            Sqrt | InverseSqrt | Absolute | Exponent | Sign | Round | Floor | Ceil | Trunc
            | Fract | Sine | Cosine | Tangent | Arcsine | Arccosine | Arctangent | Sinh | Cosh
            | Tanh | Radians | Degrees => 1,
            _ => 2,
        }
    }
}

/// Evaluates the Math node on inputs `a`, `b`, `c` (sockets 0, 1, 2), without clamping.
///
/// Notable definitions: DIVIDE/SNAP/MODULO/FLOORED_MODULO/PINGPONG give 0 for `b == 0`;
/// POWER is [`safe_pow`]; LOGARITHM is `log_b(a)` ([`safe_log`]); SQRT clamps negatives
/// to 0; INVERSE_SQRT gives 0 for `a <= 0`; ROUND is `floor(a + 0.5)`; MODULO is `fmodf`;
/// FLOORED_MODULO is `a - floor(a/b) b`; WRAP is `wrap(a, max = b, min = c)`;
/// COMPARE is `a == b || |a - b| <= max(c, FLT_EPSILON)`; SMOOTH_MAX is
/// `-smooth_min(-a, -b, c)`; ARCSINE/ARCCOSINE clamp to [-1, 1]; ARCTAN2 is `atan2(a, b)`.
pub fn math(op: MathOp, a: f32, b: f32, c: f32) -> f32 {
    use MathOp::*;
    match op {
        Add => a + b,
        Subtract => a - b,
        Multiply => a * b,
        Divide => safe_divide(a, b),
        MultiplyAdd => a * b + c,
        Power => safe_pow(a, b),
        Logarithm => safe_log(a, b),
        Sqrt => safe_sqrt(a),
        InverseSqrt => inverse_sqrt(a),
        Absolute => a.abs(),
        Exponent => a.exp(),
        Minimum => a.min(b),
        Maximum => a.max(b),
        LessThan => (a < b) as u8 as f32,
        GreaterThan => (a > b) as u8 as f32,
        Sign => compatible_sign(a),
        Compare => {
            if a == b || (a - b).abs() <= c.max(f32::EPSILON) {
                1.0
            } else {
                0.0
            }
        }
        SmoothMin => smooth_min(a, b, c),
        SmoothMax => -smooth_min(-a, -b, c),
        Round => (a + 0.5).floor(),
        Floor => a.floor(),
        Ceil => a.ceil(),
        Trunc => {
            if a >= 0.0 {
                a.floor()
            } else {
                a.ceil()
            }
        }
        Fract => fract(a),
        Modulo => safe_modulo(a, b),
        FlooredModulo => safe_floored_modulo(a, b),
        Wrap => wrap(a, b, c),
        Snap => safe_divide(a, b).floor() * b,
        PingPong => pingpong(a, b),
        Sine => a.sin(),
        Cosine => a.cos(),
        Tangent => a.tan(),
        Arcsine => clamp(a, -1.0, 1.0).asin(),
        Arccosine => clamp(a, -1.0, 1.0).acos(),
        Arctangent => a.atan(),
        Arctan2 => compatible_atan2(a, b),
        Sinh => a.sinh(),
        Cosh => a.cosh(),
        Tanh => a.tanh(),
        Radians => a * (std::f32::consts::PI / 180.0),
        Degrees => a * (180.0 / std::f32::consts::PI),
    }
}

/// The Math node with its `use_clamp` option: the result is clamped to [0, 1]
/// (Cycles appends a Clamp node; NaN results become 0).
pub fn math_node(op: MathOp, a: f32, b: f32, c: f32, use_clamp: bool) -> f32 {
    let r = math(op, a, b, c);
    if use_clamp { saturate(r) } else { r }
}

#[cfg(test)]
#[allow(
    clippy::approx_constant,
    clippy::excessive_precision,
    clippy::type_complexity
)]
mod tests {
    use super::*;

    fn m(op: &str, a: f32, b: f32, c: f32) -> f32 {
        math(MathOp::from_blender(op).unwrap(), a, b, c)
    }

    #[test]
    fn names_round_trip() {
        for op in MathOp::ALL {
            assert_eq!(MathOp::from_blender(op.blender_name()), Some(op));
        }
        assert_eq!(MathOp::from_blender("multiply"), None);
        assert_eq!(
            MathOp::from_blender("MULTIPLY_ADD"),
            Some(MathOp::MultiplyAdd)
        );
    }

    #[test]
    fn division_by_zero_and_friends() {
        assert_eq!(m("DIVIDE", 3.0, 0.0, 0.0), 0.0);
        assert_eq!(m("DIVIDE", 3.0, -0.0, 0.0), 0.0);
        assert_eq!(m("MODULO", 3.0, 0.0, 0.0), 0.0);
        assert_eq!(m("FLOORED_MODULO", 3.0, 0.0, 0.0), 0.0);
        assert_eq!(m("SNAP", 3.0, 0.0, 0.0), 0.0);
        assert_eq!(m("PINGPONG", 3.0, 0.0, 0.0), 0.0);
        assert_eq!(m("WRAP", 3.0, 2.0, 2.0), 2.0);
        assert_eq!(m("LOGARITHM", -1.0, 2.0, 0.0), 0.0);
        assert_eq!(m("LOGARITHM", 8.0, 1.0, 0.0), 0.0);
        assert_eq!(m("INVERSE_SQRT", 0.0, 0.0, 0.0), 0.0);
        assert_eq!(m("SQRT", -4.0, 0.0, 0.0), 0.0);
    }

    #[test]
    fn modulo_semantics() {
        assert_eq!(m("MODULO", -5.5, 2.0, 0.0), -1.5);
        assert_eq!(m("FLOORED_MODULO", -5.5, 2.0, 0.0), 0.5);
        assert_eq!(m("MODULO", 5.5, -2.0, 0.0), 1.5);
        assert_eq!(m("FLOORED_MODULO", 5.5, -2.0, 0.0), -0.5);
        assert_eq!(m("WRAP", 5.5, 2.0, 0.0), 1.5);
        assert_eq!(m("WRAP", -0.5, 2.0, 0.0), 1.5);
        assert_eq!(m("PINGPONG", 3.0, 2.0, 0.0), 1.0);
        assert_eq!(m("PINGPONG", 5.0, 2.0, 0.0), 1.0);
        assert_eq!(m("SNAP", -2.5, 2.0, 0.0), -4.0);
        assert_eq!(m("TRUNC", -2.5, 0.0, 0.0), -2.0);
        assert_eq!(m("ROUND", -2.5, 0.0, 0.0), -2.0);
        assert_eq!(m("FRACT", -2.25, 0.0, 0.0), 0.75);
    }

    #[test]
    fn power_edge_cases() {
        assert_eq!(m("POWER", -2.0, 3.0, 0.0), -8.0);
        assert_eq!(m("POWER", -2.0, 0.5, 0.0), 0.0);
        assert_eq!(m("POWER", 0.0, 0.0, 0.0), 1.0);
        assert_eq!(m("POWER", 0.0, -1.0, 0.0), 0.0);
        // (int)3e9 is INT_MIN on x86, so Cycles treats it as non-integer: measured from
        // Cycles 5.0, (-1)^3e9 renders 0 while 1^3e9 renders 1.
        assert_eq!(m("POWER", -1.0, 3.0e9, 0.0), 0.0);
        assert_eq!(m("POWER", 1.0, 3.0e9, 0.0), 1.0);
    }

    #[test]
    fn sign_compare_smooth() {
        assert_eq!(m("SIGN", 0.0, 0.0, 0.0), 0.0);
        assert_eq!(m("SIGN", -0.0, 0.0, 0.0), 0.0);
        assert_eq!(m("SIGN", -3.0, 0.0, 0.0), -1.0);
        assert_eq!(m("COMPARE", 1.0, 1.0 + 1e-7, 0.0), 1.0);
        assert_eq!(m("COMPARE", 1.0, 1.1, 0.05), 0.0);
        assert_eq!(m("COMPARE", 1.0, 1.1, 0.2), 1.0);
        assert_eq!(m("SMOOTH_MIN", 1.0, 1.0, 0.0), 1.0);
        assert!((m("SMOOTH_MIN", 1.0, 1.0, 1.0) - (1.0 - 1.0 / 6.0)).abs() < 1e-7);
        assert!((m("SMOOTH_MAX", 1.0, 1.0, 1.0) - (1.0 + 1.0 / 6.0)).abs() < 1e-7);
        assert_eq!(m("ARCTAN2", 0.0, -0.0, 0.0), 0.0);
        assert_eq!(m("ARCSINE", 2.0, 0.0, 0.0), std::f32::consts::FRAC_PI_2);
    }

    #[test]
    fn clamp_option() {
        assert_eq!(math_node(MathOp::Add, 0.7, 0.7, 0.0, true), 1.0);
        assert_eq!(math_node(MathOp::Subtract, 0.0, 0.7, 0.0, true), 0.0);
        assert_eq!(math_node(MathOp::Sqrt, f32::NAN, 0.0, 0.0, true), 0.0);
        assert_eq!(saturate(f32::NAN), 0.0);
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
            -1e-45,
        ];
        for op in MathOp::ALL {
            for &a in &vals {
                for &b in &vals {
                    for &c in &vals {
                        let _ = math_node(op, a, b, c, true);
                        let _ = math(op, a, b, c);
                    }
                }
            }
        }
        assert_eq!(float_to_int(f32::NAN), i32::MIN);
        assert_eq!(float_to_int(-3.7), -3);
    }

    /// Math node outputs measured from Cycles 5.0 renders (Emission colour = Math(a, b, c),
    /// inputs read back from the same render); quantized inputs include `b == 0`, `a == b`.
    #[test]
    fn measured_from_cycles() {
        for &(op, a, b, c, want) in CYCLES_MEASURED {
            let got = m(op, a, b, c);
            let tol = 1e-5 * want.abs().max(1.0);
            assert!(
                (got - want).abs() <= tol,
                "{op}({a}, {b}, {c}) = {got}, Cycles {want}"
            );
        }
    }

    /// (op, a, b, c, result): measured from Cycles 5.0.
    #[rustfmt::skip]
    const CYCLES_MEASURED: &[(&str, f32, f32, f32, f32)] = &[
        ("ABSOLUTE", 1.5, -1.0, 3.0, 1.5),
        ("ABSOLUTE", 1.5, -1.0, -2.0, 1.5),
        ("ABSOLUTE", 2.5, 0.0, 2.5, 2.5),
        ("ABSOLUTE", 3.0, 3.0, 1.0, 3.0),
        ("ABSOLUTE", -1.5, 4.0, 4.0, 1.5),
        ("ABSOLUTE", 3.5810432, 0.84832764, -1.511879, 3.5810432),
        ("ADD", -1.0, -4.0, 3.0, -5.0),
        ("ADD", -3.0, 2.0, -1.5, -1.0),
        ("ADD", 2.5, 0.0, 2.5, 2.5),
        ("ADD", 3.0, 3.0, 1.0, 6.0),
        ("ADD", -1.5, 4.0, 4.0, 2.5),
        ("ADD", -1.0437088, -3.866188, 2.0088348, -4.909897),
        ("ARCCOSINE", 0.5, -0.5, 3.5, 1.0471976),
        ("ARCCOSINE", -1.5, -2.0, 3.0, 3.1415927),
        ("ARCCOSINE", 1.0, 0.0, 2.5, 0.0),
        ("ARCCOSINE", 1.0, 1.0, -3.0, 0.0),
        ("ARCCOSINE", -0.5, 4.0, 4.0, 2.0943952),
        ("ARCCOSINE", -0.60466003, 0.121398926, -1.422287, 2.2201352),
        ("ARCSINE", -1.5, -2.0, -0.5, -1.5707964),
        ("ARCSINE", -0.5, 3.0, 2.5, -0.5235988),
        ("ARCSINE", 1.0, 0.0, 2.5, 1.5707964),
        ("ARCSINE", 1.0, 1.0, -3.0, 1.5707964),
        ("ARCSINE", -0.5, 4.0, 4.0, -0.5235988),
        ("ARCSINE", -1.4678679, -1.9823799, -0.6729431, -1.5707964),
        ("ARCTAN2", -2.0, 0.0, -1.5, -1.5707964),
        ("ARCTAN2", -2.0, -3.5, 2.0, -2.6224465),
        ("ARCTAN2", 2.5, 0.0, 2.5, 1.5707964),
        ("ARCTAN2", 3.0, 3.0, 1.0, 0.7853982),
        ("ARCTAN2", -1.5, 4.0, 4.0, -0.35877067),
        ("ARCTAN2", -2.2377248, -3.254198, 1.7693233, -2.5392087),
        ("ARCTANGENT", -4.0, 1.5, -2.5, -1.3258177),
        ("ARCTANGENT", -2.0, -2.5, -3.0, -1.1071488),
        ("ARCTANGENT", 2.5, 0.0, 2.5, 1.19029),
        ("ARCTANGENT", 3.0, 3.0, 1.0, 1.2490457),
        ("ARCTANGENT", -1.5, 4.0, 4.0, -0.98279375),
        ("ARCTANGENT", 0.20108032, -0.274086, 0.38324738, 0.19843411),
        ("CEIL", -1.0, -1.0, 4.0, -1.0),
        ("CEIL", 3.0, -3.5, 3.5, 3.0),
        ("CEIL", 2.5, 0.0, 2.5, 3.0),
        ("CEIL", 3.0, 3.0, 1.0, 3.0),
        ("CEIL", -1.5, 4.0, 4.0, -1.0),
        ("CEIL", 3.1215782, -3.3406029, 3.57972, 4.0),
        ("COMPARE", 3.5, 2.0, 0.5, 0.0),
        ("COMPARE", 3.0, 1.5, 1.0, 0.0),
        ("COMPARE", 2.5, 0.0, 1.0, 0.0),
        ("COMPARE", 3.0, 3.0, 0.5, 1.0),
        ("COMPARE", -1.5, 4.0, 1.0, 0.0),
        ("COMPARE", -2.8990822, 3.4505882, 0.11598539, 0.0),
        ("COSH", -5.0, -1.5, 3.0, 74.20995),
        ("COSH", -6.5, -1.0, -2.0, 332.5716),
        ("COSH", 5.5, 0.0, 2.5, 122.34801),
        ("COSH", 4.0, 4.0, 1.5, 27.308231),
        ("COSH", -2.5, -4.0, 1.5, 6.1322894),
        ("COSH", -6.526581, -1.0053406, -2.1398926, 341.5301),
        ("COSINE", -1.5, -2.0, 0.0, 0.0707372),
        ("COSINE", 2.0, 0.5, -4.0, -0.41614684),
        ("COSINE", 2.5, 0.0, 2.5, -0.8011436),
        ("COSINE", 3.0, 3.0, 1.0, -0.9899925),
        ("COSINE", -1.5, 4.0, 4.0, 0.0707372),
        ("COSINE", -3.8528519, 2.410553, -0.51104736, -0.75754046),
        ("DEGREES", 2.5, -3.0, 1.0, 143.23944),
        ("DEGREES", -3.5, -1.0, -4.0, -200.53522),
        ("DEGREES", 2.5, 0.0, 2.5, 143.23944),
        ("DEGREES", 3.0, 3.0, 1.0, 171.88733),
        ("DEGREES", -1.5, 4.0, 4.0, -85.943665),
        ("DEGREES", -3.171711, -1.0446815, -3.745144, -181.72565),
        ("DIVIDE", -1.0, 1.0, 1.0, -1.0),
        ("DIVIDE", -3.5, -2.5, 3.0, 1.4),
        ("DIVIDE", 2.5, 0.0, 2.5, 0.0),
        ("DIVIDE", 3.0, 3.0, 1.0, 1.0),
        ("DIVIDE", -1.5, 4.0, 4.0, -0.375),
        ("DIVIDE", -3.5268135, -2.4398766, 3.0845642, 1.4454885),
        ("EXPONENT", 4.0, -4.0, 0.5, 54.59815),
        ("EXPONENT", 3.5, 2.5, -2.0, 33.11545),
        ("EXPONENT", 5.5, 0.0, 2.5, 244.69193),
        ("EXPONENT", 4.0, 4.0, 1.5, 54.59815),
        ("EXPONENT", -2.5, -4.0, 1.5, 0.082085),
        ("EXPONENT", 7.4615173, -3.4422493, 1.1947479, 1739.7859),
        ("FLOOR", -1.0, -2.5, 0.0, -1.0),
        ("FLOOR", 1.0, 2.0, -3.0, 1.0),
        ("FLOOR", 2.5, 0.0, 2.5, 2.0),
        ("FLOOR", 3.0, 3.0, 1.0, 3.0),
        ("FLOOR", -1.5, 4.0, 4.0, -2.0),
        ("FLOOR", 1.1026711, -0.630908, 3.3105092, 1.0),
        ("FLOORED_MODULO", -3.5, 4.0, 3.5, 0.5),
        ("FLOORED_MODULO", -2.5, -1.0, 0.5, -0.5),
        ("FLOORED_MODULO", 2.5, 0.0, 2.5, 0.0),
        ("FLOORED_MODULO", 3.0, 3.0, 1.0, 0.0),
        ("FLOORED_MODULO", -1.5, 4.0, 4.0, 2.5),
        ("FLOORED_MODULO", -2.6577911, -0.87932587, 0.38664246, -0.019813538),
        ("FRACT", 1.5, -1.5, -4.0, 0.5),
        ("FRACT", -2.5, 3.0, -2.0, 0.5),
        ("FRACT", 2.5, 0.0, 2.5, 0.5),
        ("FRACT", 3.0, 3.0, 1.0, 0.0),
        ("FRACT", -1.5, 4.0, 4.0, 0.5),
        ("FRACT", 3.5705338, 0.5948181, -0.50089264, 0.57053375),
        ("GREATER_THAN", 2.5, -1.0, -2.0, 1.0),
        ("GREATER_THAN", 2.5, 1.5, 3.5, 1.0),
        ("GREATER_THAN", 2.5, 0.0, 2.5, 1.0),
        ("GREATER_THAN", 3.0, 3.0, 1.0, 0.0),
        ("GREATER_THAN", -1.5, 4.0, 4.0, 0.0),
        ("GREATER_THAN", -3.4966888, 1.1278687, 1.3174286, 0.0),
        ("INVERSE_SQRT", 0.5, 2.0, 2.5, 1.4142135),
        ("INVERSE_SQRT", -1.0, -1.0, -2.5, 0.0),
        ("INVERSE_SQRT", 2.5, 0.0, 2.5, 0.6324555),
        ("INVERSE_SQRT", 3.0, 3.0, 1.0, 0.57735026),
        ("INVERSE_SQRT", -1.5, 4.0, 4.0, 0.0),
        ("INVERSE_SQRT", 1.0702744, 1.2217865, 0.72330475, 0.9666126),
        ("LESS_THAN", -1.0, 0.5, -3.0, 1.0),
        ("LESS_THAN", -2.5, 1.5, -3.5, 1.0),
        ("LESS_THAN", 2.5, 0.0, 2.5, 0.0),
        ("LESS_THAN", 3.0, 3.0, 1.0, 0.0),
        ("LESS_THAN", -1.5, 4.0, 4.0, 1.0),
        ("LESS_THAN", -0.77108, 0.6290817, -2.960762, 1.0),
        ("LOGARITHM", 9.0, 3.0, 0.5, 2.0),
        ("LOGARITHM", 9.0, 1.5, -2.5, 5.419023),
        ("LOGARITHM", 3.0, 0.0, 1.5, 0.0),
        ("LOGARITHM", 0.0, 0.0, -3.0, 0.0),
        ("LOGARITHM", -0.5, 2.5, 0.5, 0.0),
        ("LOGARITHM", 1.0034809, 2.8549423, 1.113739, 0.003312389),
        ("MAXIMUM", 1.5, -3.0, -1.0, 1.5),
        ("MAXIMUM", 2.5, -1.5, -2.5, 2.5),
        ("MAXIMUM", 2.5, 0.0, 2.5, 2.5),
        ("MAXIMUM", 3.0, 3.0, 1.0, 3.0),
        ("MAXIMUM", -1.5, 4.0, 4.0, 4.0),
        ("MAXIMUM", 3.5183563, -0.8020401, 2.630062, 3.5183563),
        ("MINIMUM", 2.0, -3.0, 0.5, -3.0),
        ("MINIMUM", -3.0, 3.5, 2.5, -3.0),
        ("MINIMUM", 2.5, 0.0, 2.5, 0.0),
        ("MINIMUM", 3.0, 3.0, 1.0, 3.0),
        ("MINIMUM", -1.5, 4.0, 4.0, -1.5),
        ("MINIMUM", -0.9810333, -2.215828, -2.133133, -2.215828),
        ("MODULO", 1.0, 2.0, 3.5, 1.0),
        ("MODULO", -2.0, -4.0, -1.0, -2.0),
        ("MODULO", 2.5, 0.0, 2.5, 0.0),
        ("MODULO", 3.0, 3.0, 1.0, 0.0),
        ("MODULO", -1.5, 4.0, 4.0, -1.5),
        ("MODULO", 0.34973907, -1.8867874, 2.4316864, 0.34973907),
        ("MULTIPLY", -4.0, -3.0, -2.5, 12.0),
        ("MULTIPLY", -1.5, 3.0, 3.5, -4.5),
        ("MULTIPLY", 2.5, 0.0, 2.5, 0.0),
        ("MULTIPLY", 3.0, 3.0, 1.0, 9.0),
        ("MULTIPLY", -1.5, 4.0, 4.0, -6.0),
        ("MULTIPLY", 0.59680176, -3.0576553, -1.2245941, -1.8248141),
        ("MULTIPLY_ADD", -3.0, 2.0, -1.5, -7.5),
        ("MULTIPLY_ADD", 1.5, -3.5, 2.5, -2.75),
        ("MULTIPLY_ADD", 2.5, 0.0, 2.5, 2.5),
        ("MULTIPLY_ADD", 3.0, 3.0, 1.0, 10.0),
        ("MULTIPLY_ADD", -1.5, 4.0, 4.0, -2.0),
        ("MULTIPLY_ADD", 3.5926018, -1.5760498, -1.8647003, -7.5268197),
        ("PINGPONG", 2.0, -2.0, 2.5, 2.0),
        ("PINGPONG", 2.0, 1.0, -0.5, 0.0),
        ("PINGPONG", 2.5, 0.0, 2.5, 0.0),
        ("PINGPONG", 3.0, 3.0, 1.0, 3.0),
        ("PINGPONG", -1.5, 4.0, 4.0, 1.5),
        ("PINGPONG", 3.8559608, -0.076833725, -2.1271286, 0.014274724),
        ("POWER", 1.5, 2.0, -1.0, 2.25),
        ("POWER", -0.5, 1.5, -3.5, 0.0),
        ("POWER", 1.0, 0.0, 4.0, 1.0),
        ("POWER", 2.5, 2.5, -1.0, 9.882117),
        ("POWER", -1.0, -3.0, 1.5, -1.0),
        ("POWER", 2.8823833, -2.1824284, 2.5295258, 0.099225834),
        ("RADIANS", -1.0, -2.0, 1.5, -0.017453292),
        ("RADIANS", -3.5, -2.5, 2.0, -0.061086524),
        ("RADIANS", 2.5, 0.0, 2.5, 0.04363323),
        ("RADIANS", 3.0, 3.0, 1.0, 0.05235988),
        ("RADIANS", -1.5, 4.0, 4.0, -0.02617994),
        ("RADIANS", -1.2247772, -0.40080643, -2.6268272, -0.021376396),
        ("ROUND", -3.0, 0.0, 0.0, -3.0),
        ("ROUND", 3.0, -4.0, 0.0, 3.0),
        ("ROUND", 2.5, 0.0, 2.5, 3.0),
        ("ROUND", 3.0, 3.0, 1.0, 3.0),
        ("ROUND", -1.5, 4.0, 4.0, -1.0),
        ("ROUND", -2.900299, -1.806839, 3.5891113, -3.0),
        ("SIGN", -1.5, -3.5, -0.5, -1.0),
        ("SIGN", 1.5, 1.0, 3.0, 1.0),
        ("SIGN", 2.5, 0.0, 2.5, 1.0),
        ("SIGN", 3.0, 3.0, 1.0, 1.0),
        ("SIGN", -1.5, 4.0, 4.0, -1.0),
        ("SIGN", -1.441719, -3.662201, -0.7376785, -1.0),
        ("SINE", 4.0, -2.0, -2.0, -0.7568025),
        ("SINE", 1.5, 1.5, -0.5, 0.997495),
        ("SINE", 2.5, 0.0, 2.5, 0.5984721),
        ("SINE", 3.0, 3.0, 1.0, 0.14112),
        ("SINE", -1.5, 4.0, 4.0, -0.997495),
        ("SINE", 3.7829323, -2.045391, -1.9362144, -0.5982694),
        ("SINH", -4.5, -1.5, -2.5, -45.003014),
        ("SINH", -2.0, -3.5, -0.5, -3.6268604),
        ("SINH", 5.5, 0.0, 2.5, 122.34392),
        ("SINH", 4.0, 4.0, 1.5, 27.289919),
        ("SINH", -2.5, -4.0, 1.5, -6.0502048),
        ("SINH", 2.3261585, -1.5601101, 2.8142118, 5.070432),
        ("SMOOTH_MAX", -0.5, 4.0, 0.0, 4.0),
        ("SMOOTH_MAX", -2.5, 1.0, 2.0, 1.0),
        ("SMOOTH_MAX", 2.5, 0.0, 2.5, 2.5),
        ("SMOOTH_MAX", 3.0, 3.0, 1.5, 3.25),
        ("SMOOTH_MAX", -1.5, 4.0, 3.0, 4.0),
        ("SMOOTH_MAX", 1.7617474, -1.9152622, 1.7201157, 1.7617474),
        ("SMOOTH_MIN", 0.5, -1.0, 0.0, -1.0),
        ("SMOOTH_MIN", -2.0, 3.0, 1.5, -2.0),
        ("SMOOTH_MIN", 2.5, 0.0, 2.5, 0.0),
        ("SMOOTH_MIN", 3.0, 3.0, 1.5, 2.75),
        ("SMOOTH_MIN", -1.5, 4.0, 3.0, -1.5),
        ("SMOOTH_MIN", 0.19879913, -2.853653, -0.9855499, -2.853653),
        ("SNAP", -2.5, -1.5, -2.5, -1.5),
        ("SNAP", -1.0, -3.5, -0.5, 0.0),
        ("SNAP", 2.5, 0.0, 2.5, 0.0),
        ("SNAP", 3.0, 3.0, 1.0, 3.0),
        ("SNAP", -1.5, 4.0, 4.0, -4.0),
        ("SNAP", 1.1630793, -1.5601101, 2.8142118, 1.5601101),
        ("SQRT", 0.0, -4.0, 3.0, 0.0),
        ("SQRT", 2.0, 0.0, 1.0, 1.4142135),
        ("SQRT", 2.5, 0.0, 2.5, 1.5811388),
        ("SQRT", 3.0, 3.0, 1.0, 1.7320508),
        ("SQRT", -1.5, 4.0, 4.0, 0.0),
        ("SQRT", 3.939476, 2.1452065, -3.3290634, 1.9848113),
        ("SUBTRACT", 1.5, 3.5, -0.5, -2.0),
        ("SUBTRACT", 4.0, -3.0, -4.0, 7.0),
        ("SUBTRACT", 2.5, 0.0, 2.5, 2.5),
        ("SUBTRACT", 3.0, 3.0, 1.0, 0.0),
        ("SUBTRACT", -1.5, 4.0, 4.0, -5.5),
        ("SUBTRACT", 1.6573868, 3.291008, -0.29786682, -1.6336212),
        ("TANGENT", -2.5, -2.5, 2.5, 0.74702233),
        ("TANGENT", -2.0, 2.0, -4.0, 2.1850398),
        ("TANGENT", 2.5, 0.0, 2.5, -0.74702233),
        ("TANGENT", 3.0, 3.0, 1.0, -0.14254655),
        ("TANGENT", -1.5, 4.0, 4.0, -14.10142),
        ("TANGENT", -2.5091248, -2.4920273, 2.4350815, 0.7329014),
        ("TANH", -2.0, -2.0, -1.5, -0.9640276),
        ("TANH", -4.0, 0.0, 1.5, -0.9993293),
        ("TANH", 2.5, 0.0, 2.5, 0.9866143),
        ("TANH", 3.0, 3.0, 1.0, 0.9950548),
        ("TANH", -1.5, 4.0, 4.0, -0.90514827),
        ("TANH", -3.9468765, -0.06498718, 1.701889, -0.99925417),
        ("TRUNC", 3.5, -3.5, 2.0, 3.0),
        ("TRUNC", -2.0, 2.0, 4.0, -2.0),
        ("TRUNC", 2.5, 0.0, 2.5, 2.0),
        ("TRUNC", 3.0, 3.0, 1.0, 3.0),
        ("TRUNC", -1.5, 4.0, 4.0, -1.0),
        ("TRUNC", -0.040210724, -3.944172, -0.718132, 0.0),
        ("WRAP", 1.0, -3.0, -1.0, -1.0),
        ("WRAP", 2.0, -3.5, -3.5, -3.5),
        ("WRAP", 2.5, 0.0, 2.5, 2.5),
        ("WRAP", 3.0, 3.0, 1.0, 1.0),
        ("WRAP", -1.5, 4.0, 4.0, 4.0),
        ("WRAP", 0.91356564, -2.9041252, -0.9218159, -1.0687437),
    ];
}
