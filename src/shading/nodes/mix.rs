//! Mix node (`ShaderNodeMix`: float, vector, non-uniform vector and colour modes) and the
//! legacy MixRGB node (`ShaderNodeMixRGB`), evaluated like Cycles' `svm_mix` and
//! `svm_node_mix_*` (`kernel/svm/mix.h`, `kernel/svm/color_util.h`).
//! Every function is total: NaN and infinities never panic.

use super::color::{hsv_to_rgb, rgb_to_hsv};
use super::math::{cmax, cmin, saturate};
use glam::Vec3;

/// Colour blend mode, named after Blender's `blend_type` identifiers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Blend {
    Mix,
    Darken,
    Multiply,
    Burn,
    Lighten,
    Screen,
    Dodge,
    Add,
    Overlay,
    SoftLight,
    LinearLight,
    Difference,
    Exclusion,
    Subtract,
    Divide,
    Hue,
    Saturation,
    Color,
    Value,
}

impl Blend {
    /// Every blend mode, in Blender's enum order.
    pub const ALL: [Blend; 19] = {
        use Blend::*;
        [
            Mix,
            Darken,
            Multiply,
            Burn,
            Lighten,
            Screen,
            Dodge,
            Add,
            Overlay,
            SoftLight,
            LinearLight,
            Difference,
            Exclusion,
            Subtract,
            Divide,
            Hue,
            Saturation,
            Color,
            Value,
        ]
    };

    /// Parses a Blender identifier such as `"SOFT_LIGHT"`.
    pub fn from_blender(s: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|b| b.blender_name() == s)
    }

    /// The Blender RNA identifier.
    pub fn blender_name(self) -> &'static str {
        use Blend::*;
        match self {
            Mix => "MIX",
            Darken => "DARKEN",
            Multiply => "MULTIPLY",
            Burn => "BURN",
            Lighten => "LIGHTEN",
            Screen => "SCREEN",
            Dodge => "DODGE",
            Add => "ADD",
            Overlay => "OVERLAY",
            SoftLight => "SOFT_LIGHT",
            LinearLight => "LINEAR_LIGHT",
            Difference => "DIFFERENCE",
            Exclusion => "EXCLUSION",
            Subtract => "SUBTRACT",
            Divide => "DIVIDE",
            Hue => "HUE",
            Saturation => "SATURATION",
            Color => "COLOR",
            Value => "VALUE",
        }
    }
}

#[inline]
fn lerp(a: Vec3, b: Vec3, t: f32) -> Vec3 {
    a + (b - a) * t
}

#[inline]
fn per(a: Vec3, b: Vec3, f: impl Fn(f32, f32) -> f32) -> Vec3 {
    Vec3::new(f(a.x, b.x), f(a.y, b.y), f(a.z, b.z))
}

/// Blends colour `b` over `a` with factor `t` (used as is, not clamped), per `svm_mix`:
///
/// MIX `a + t (b - a)`; DARKEN/LIGHTEN lerp to `min`/`max`; MULTIPLY/ADD/SUBTRACT lerp to
/// `a*b`, `a+b`, `a-b`; SCREEN `1 - (1 - t + t (1 - b)) (1 - a)`; OVERLAY per channel
/// `a < 0.5 ? a (1 - t + 2 t b) : 1 - (1 - t + 2 t (1 - b)) (1 - a)`; DIVIDE
/// `(1 - t) a + t a / b` where `b != 0` (else `a`); DIFFERENCE lerp to `|a - b|`;
/// EXCLUSION `max(lerp(a, a + b - 2ab), 0)`; DODGE/BURN Blender's clamped formulas;
/// HUE/SATURATION/VALUE/COLOR swap HSV components (HUE/COLOR only if `b` is saturated,
/// SATURATION only if `a` is); SOFT_LIGHT `(1 - t) a + t ((1 - a) b a + a scr)` with
/// `scr = 1 - (1 - b)(1 - a)`; LINEAR_LIGHT `a + t (2b - 1)`.
pub fn mix_color(blend: Blend, t: f32, a: Vec3, b: Vec3) -> Vec3 {
    use Blend::*;
    let tm = 1.0 - t;
    match blend {
        Mix => lerp(a, b, t),
        Add => lerp(a, a + b, t),
        Multiply => lerp(a, a * b, t),
        Screen => Vec3::ONE - (Vec3::splat(tm) + (Vec3::ONE - b) * t) * (Vec3::ONE - a),
        Overlay => per(a, b, |a, b| {
            if a < 0.5 {
                a * (tm + 2.0 * t * b)
            } else {
                1.0 - (tm + 2.0 * t * (1.0 - b)) * (1.0 - a)
            }
        }),
        Subtract => lerp(a, a - b, t),
        Divide => per(a, b, |a, b| if b != 0.0 { tm * a + t * a / b } else { a }),
        Difference => lerp(a, (a - b).abs(), t),
        Exclusion => {
            let r = lerp(a, a + b - (a * 2.0) * b, t);
            Vec3::new(cmax(r.x, 0.0), cmax(r.y, 0.0), cmax(r.z, 0.0))
        }
        Darken => lerp(a, per(a, b, cmin), t),
        Lighten => lerp(a, per(a, b, cmax), t),
        Dodge => per(a, b, |a, b| {
            if a == 0.0 {
                return a;
            }
            let tmp = 1.0 - t * b;
            if tmp <= 0.0 {
                1.0
            } else {
                let q = a / tmp;
                if q > 1.0 { 1.0 } else { q }
            }
        }),
        Burn => per(a, b, |a, b| {
            let tmp = tm + t * b;
            if tmp <= 0.0 {
                0.0
            } else {
                let q = 1.0 - (1.0 - a) / tmp;
                q.clamp(0.0, 1.0) // NaN stays NaN, as in Cycles' if/else chain
            }
        }),
        Hue => {
            let hsv2 = rgb_to_hsv(b);
            if hsv2.y != 0.0 {
                let mut hsv = rgb_to_hsv(a);
                hsv.x = hsv2.x;
                lerp(a, hsv_to_rgb(hsv), t)
            } else {
                a
            }
        }
        Saturation => {
            let mut hsv = rgb_to_hsv(a);
            if hsv.y != 0.0 {
                let hsv2 = rgb_to_hsv(b);
                hsv.y = tm * hsv.y + t * hsv2.y;
                hsv_to_rgb(hsv)
            } else {
                a
            }
        }
        Value => {
            let mut hsv = rgb_to_hsv(a);
            let hsv2 = rgb_to_hsv(b);
            hsv.z = tm * hsv.z + t * hsv2.z;
            hsv_to_rgb(hsv)
        }
        Color => {
            let hsv2 = rgb_to_hsv(b);
            if hsv2.y != 0.0 {
                let mut hsv = rgb_to_hsv(a);
                hsv.x = hsv2.x;
                hsv.y = hsv2.y;
                lerp(a, hsv_to_rgb(hsv), t)
            } else {
                a
            }
        }
        SoftLight => {
            let scr = Vec3::ONE - (Vec3::ONE - b) * (Vec3::ONE - a);
            a * tm + ((Vec3::ONE - a) * b * a + a * scr) * t
        }
        LinearLight => a + (b * 2.0 + Vec3::splat(-1.0)) * t,
    }
}

/// Mix node in colour mode: `clamp_factor` clamps `t` to [0, 1] first, `clamp_result`
/// clamps the blended colour to [0, 1] (NaN to 0).
pub fn mix_color_node(
    blend: Blend,
    t: f32,
    a: Vec3,
    b: Vec3,
    clamp_factor: bool,
    clamp_result: bool,
) -> Vec3 {
    let t = if clamp_factor { saturate(t) } else { t };
    let r = mix_color(blend, t, a, b);
    if clamp_result { saturate3(r) } else { r }
}

/// Legacy MixRGB node: Cycles always clamps the factor to [0, 1]; `use_clamp` clamps the
/// result to [0, 1].
pub fn mix_rgb_legacy(blend: Blend, t: f32, a: Vec3, b: Vec3, use_clamp: bool) -> Vec3 {
    mix_color_node(blend, t, a, b, true, use_clamp)
}

/// Mix node in float mode: `a (1 - t) + b t`.
pub fn mix_float(t: f32, a: f32, b: f32, clamp_factor: bool) -> f32 {
    let t = if clamp_factor { saturate(t) } else { t };
    a * (1.0 - t) + b * t
}

/// Mix node in vector mode with a uniform factor: `a (1 - t) + b t`.
pub fn mix_vector(t: f32, a: Vec3, b: Vec3, clamp_factor: bool) -> Vec3 {
    let t = if clamp_factor { saturate(t) } else { t };
    a * (Vec3::ONE - Vec3::splat(t)) + b * t
}

/// Mix node in vector mode with a per-component (non-uniform) factor.
pub fn mix_vector_non_uniform(t: Vec3, a: Vec3, b: Vec3, clamp_factor: bool) -> Vec3 {
    let t = if clamp_factor { saturate3(t) } else { t };
    a * (Vec3::ONE - t) + b * t
}

/// Component-wise [`saturate`].
#[inline]
pub fn saturate3(v: Vec3) -> Vec3 {
    Vec3::new(saturate(v.x), saturate(v.y), saturate(v.z))
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

    fn close(got: Vec3, want: Vec3) -> bool {
        (got - want).abs().max_element() <= 1e-5 * want.abs().max_element().max(1.0)
    }

    #[test]
    fn names_round_trip() {
        for b in Blend::ALL {
            assert_eq!(Blend::from_blender(b.blender_name()), Some(b));
        }
        assert_eq!(Blend::from_blender("BLEND"), None);
    }

    #[test]
    fn edge_cases() {
        let a = Vec3::new(0.2, 0.5, 0.8);
        let b = Vec3::new(0.0, 0.25, 2.0);
        // DIVIDE by a zero channel keeps `a`.
        assert_eq!(mix_color(Blend::Divide, 1.0, a, b).x, 0.2);
        assert_eq!(mix_color(Blend::Divide, 1.0, a, b).y, 2.0);
        // Factor clamping, result clamping, legacy MixRGB always clamps the factor.
        assert_eq!(mix_color_node(Blend::Mix, 2.0, a, b, true, false), b);
        assert_eq!(
            mix_color_node(Blend::Mix, 2.0, a, b, false, false),
            Vec3::new(-0.2, 0.0, 3.2)
        );
        assert_eq!(
            mix_color_node(Blend::Add, 1.0, a, b, false, true),
            Vec3::new(0.2, 0.75, 1.0)
        );
        assert_eq!(mix_rgb_legacy(Blend::Mix, -1.0, a, b, false), a);
        // HUE/COLOR with a grey `b` leave `a` untouched.
        assert_eq!(mix_color(Blend::Hue, 1.0, a, Vec3::splat(0.5)), a);
        assert_eq!(mix_color(Blend::Color, 1.0, a, Vec3::splat(0.5)), a);
        assert_eq!(mix_float(0.25, 1.0, 3.0, false), 1.5);
        assert_eq!(mix_float(-1.0, 1.0, 3.0, true), 1.0);
        assert_eq!(
            mix_vector(0.5, Vec3::ZERO, Vec3::ONE, false),
            Vec3::splat(0.5)
        );
        assert_eq!(
            mix_vector_non_uniform(Vec3::new(0.0, 0.5, 2.0), Vec3::ZERO, Vec3::ONE, true),
            Vec3::new(0.0, 0.5, 1.0)
        );
        // NaN factor with clamp_factor behaves as 0; NaN results are clamped to 0.
        assert_eq!(mix_color_node(Blend::Mix, f32::NAN, a, b, true, false), a);
        assert_eq!(
            mix_color_node(Blend::Mix, f32::NAN, a, b, false, true),
            Vec3::ZERO
        );
        let vals = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, 1.0, -1.0];
        for blend in Blend::ALL {
            for &x in &vals {
                for &y in &vals {
                    let _ = mix_color_node(
                        blend,
                        x,
                        Vec3::new(x, y, 0.5),
                        Vec3::new(y, x, 0.0),
                        false,
                        true,
                    );
                }
            }
        }
    }

    /// Mix node (colour mode) measured from Cycles 5.0: (blend, clamp_factor, clamp_result,
    /// factor, A, B, result).
    #[test]
    fn measured_from_cycles() {
        for &(blend, cf, cr, t, a, b, want) in MIX {
            let got = mix_color_node(Blend::from_blender(blend).unwrap(), t, v(a), v(b), cf, cr);
            assert!(close(got, v(want)), "{blend}: {got} vs Cycles {want:?}");
        }
        for &(blend, t, a, b, want) in MIX_RGB_CLAMPED {
            let got = mix_rgb_legacy(Blend::from_blender(blend).unwrap(), t, v(a), v(b), true);
            assert!(
                close(got, v(want)),
                "MixRGB {blend}: {got} vs Cycles {want:?}"
            );
        }
    }

    #[rustfmt::skip]
    const MIX: &[(&str, bool, bool, f32, [f32; 3], [f32; 3], [f32; 3])] = &[
        ("ADD", false, false, 1.468626, [0.27083588, 0.78102493, 0.4168434], [0.9270325, 0.7169113, 1.0730362], [1.6322999, 1.8338995, 1.9927323]),
        ("ADD", false, false, 1.468934, [1.4326627, 1.2569077, 0.5024042], [0.3266492, 1.0962077, 1.3963906], [1.9124888, 2.8671649, 2.5536098]),
        ("BURN", false, false, 1.2911206, [0.26077873, 0.2347101, 0.75864196], [0.7325735, 0.09556681, 1.2304366], [0.0, 0.0, 0.8139853]),
        ("BURN", false, false, 0.7806127, [1.3896093, -0.23634243, 0.5070839], [0.8811321, 0.15549278, -0.0013942719], [1.0, 0.0, 0.0]),
        ("COLOR", false, false, 1.4373283, [1.1530237, 0.8531606, 0.16080189], [-0.13905954, 0.06263924, 0.86871815], [-0.7695369, -0.25361386, 1.5869504]),
        ("COLOR", false, false, 0.015993118, [0.5268917, 0.8825712, -0.39549828], [-0.039819717, 0.5280466, 1.0377903], [0.5179235, 0.8756382, -0.37505797]),
        ("DARKEN", false, false, 0.69967484, [-0.21164703, 0.10083842, 1.1764495], [1.488935, 1.3898575, 0.8770311], [-0.21164703, 0.10083842, 0.966954]),
        ("DARKEN", false, false, 0.5105653, [1.4286928, -0.34293175, 0.7735698], [1.001945, 0.99875665, 0.34681833], [1.2108102, -0.34293175, 0.55568534]),
        ("DIFFERENCE", false, false, 1.1887293, [-0.074189186, 0.6592264, -0.072357655], [0.6610584, 1.1179113, 0.6628914], [0.88801205, 0.42083687, 0.8876681]),
        ("DIFFERENCE", false, false, -0.2610159, [1.3935833, 1.3635035, 0.23592377], [0.20584393, 0.25295067, 1.0481834], [1.4473119, 1.4295276, 0.085490935]),
        ("DIVIDE", false, false, 0.69967484, [-0.21164703, 0.10083842, 1.1764495], [1.488935, 1.3898575, 0.8770311], [-0.16301931, 0.08104787, 1.2918613]),
        ("DIVIDE", false, false, 0.5105653, [1.4286928, -0.34293175, 0.7735698], [1.001945, 0.99875665, 0.34681833], [1.4272767, -0.34314972, 1.5174154]),
        ("DODGE", false, false, 1.4373283, [1.1530237, 0.8531606, 0.16080189], [-0.13905954, 0.06263924, 0.86871815], [0.9609538, 0.9375733, 1.0]),
        ("DODGE", false, false, 0.015993118, [0.5268917, 0.8825712, -0.39549828], [-0.039819717, 0.5280466, 1.0377903], [0.5265564, 0.8900881, -0.40217334]),
        ("EXCLUSION", false, false, 0.7620125, [0.36488724, 0.9672127, -0.13484192], [0.46748352, 0.79325104, -0.03224182], [0.4611492, 0.4023832, 0.0]),
        ("EXCLUSION", false, false, -0.07768631, [1.3298092, 0.60180855, 0.3975563], [-0.33044434, -0.0037574768, 0.7373047], [1.2872051, 0.6017491, 0.38582066]),
        ("HUE", false, false, 1.468626, [0.27083588, 0.78102493, 0.4168434], [0.9270325, 0.7169113, 1.0730362], [0.712925, 0.031748008, 0.9516899]),
        ("HUE", false, false, 1.468934, [1.4326627, 1.2569077, 0.5024042], [0.3266492, 1.0962077, 1.3963906], [0.06617431, 1.1316262, 1.8688927]),
        ("LIGHTEN", false, false, 0.9143057, [0.84239197, 1.2670116, -0.40587234], [0.018745422, -0.212574, 0.7704811], [0.84239197, 1.2670116, 0.66967434]),
        ("LIGHTEN", false, false, 1.0999546, [1.1694126, -0.3571949, 0.9674473], [1.4408379, 0.57016754, 1.2388725], [1.4679681, 0.6628617, 1.2660028]),
        ("LINEAR_LIGHT", false, false, -0.043759346, [0.00024795532, 0.14304924, -0.049149513], [0.093652725, 0.06926632, 0.044255257], [0.035810936, 0.1807465, -0.009263329]),
        ("LINEAR_LIGHT", false, false, -0.062013626, [-0.35991287, 1.3090057, -0.34332657], [1.3255959, -0.4395485, 1.342186], [-0.46230927, 1.4255353, -0.44778058]),
        ("MIX", false, false, 1.468626, [0.27083588, 0.78102493, 0.4168434], [0.9270325, 0.7169113, 1.0730362], [1.2345433, 0.686866, 1.3805453]),
        ("MIX", false, false, 1.468934, [1.4326627, 1.2569077, 0.5024042], [0.3266492, 1.0962077, 1.3963906], [-0.19199823, 1.0208501, 1.8156112]),
        ("MULTIPLY", false, false, 0.21814823, [-0.35580063, 0.42016315, -0.03075409], [0.74520683, 1.0646076, 1.0702534], [-0.33602428, 0.42608494, -0.031225415]),
        ("MULTIPLY", false, false, 1.3534994, [0.34004712, 0.5876062, -0.29045773], [-0.042898655, -0.026903152, 1.3265924], [-0.1399507, -0.22911519, -0.41885245]),
        ("OVERLAY", false, false, 0.9143057, [0.84239197, 1.2670116, -0.40587234], [0.018745422, -0.212574, 0.7704811], [0.70369256, 1.6149334, -0.60661876]),
        ("OVERLAY", false, false, 1.0999546, [1.1694126, -0.3571949, 0.9674473], [1.4408379, 0.57016754, 1.2388725], [0.8187695, -0.4123323, 1.0203602]),
        ("SATURATION", false, false, 1.1887293, [-0.074189186, 0.6592264, -0.072357655], [0.6610584, 1.1179113, 0.6628914], [0.47739527, 0.6592264, 0.47784933]),
        ("SATURATION", false, false, -0.2610159, [1.3935833, 1.3635035, 0.23592377], [0.20584393, 0.25295067, 1.0481834], [1.3935833, 1.3632474, 0.2260704]),
        ("SCREEN", false, false, 0.69967484, [-0.21164703, 0.10083842, 1.1764495], [1.488935, 1.3898575, 0.8770311], [1.0506109, 0.97522664, 1.0681736]),
        ("SCREEN", false, false, 0.5105653, [1.4286928, -0.34293175, 0.7735698], [1.001945, 0.99875665, 0.34681833], [1.2093915, 0.34187007, 0.8136646]),
        ("SOFT_LIGHT", false, false, 1.1887293, [-0.074189186, 0.6592264, -0.072357655], [0.6610584, 1.1179113, 0.6628914], [-0.10470449, 0.98924595, -0.10240702]),
        ("SOFT_LIGHT", false, false, -0.2610159, [1.3935833, 1.3635035, 0.23592377], [0.20584393, 0.25295067, 1.0481834], [1.3093576, 1.2995822, 0.18433784]),
        ("SUBTRACT", false, false, 0.21814823, [-0.35580063, 0.42016315, -0.03075409], [0.74520683, 1.0646076, 1.0702534], [-0.51836616, 0.18792088, -0.26422796]),
        ("SUBTRACT", false, false, 1.3534994, [0.34004712, 0.5876062, -0.29045773], [-0.042898655, -0.026903152, 1.3265924], [0.39811042, 0.62401956, -2.0859997]),
        ("VALUE", false, false, 1.4373283, [1.1530237, 0.8531606, 0.16080189], [-0.13905954, 0.06263924, 0.86871815], [0.74438334, 0.550794, 0.10381247]),
        ("VALUE", false, false, 0.015993118, [0.5268917, 0.8825712, -0.39549828], [-0.039819717, 0.5280466, 1.0377903], [0.5283738, 0.88505363, -0.39661065]),
        ("ADD", true, true, 1.5, [0.25, 0.75, 0.5], [1.0, 0.75, 1.0], [1.0, 1.0, 1.0]),
        ("ADD", true, true, 1.5, [1.5, 1.25, 0.5], [0.25, 1.0, 1.5], [1.0, 1.0, 1.0]),
        ("BURN", true, true, 1.25, [0.25, 0.25, 0.75], [0.75, 0.0, 1.25], [0.0, 0.0, 0.8]),
        ("BURN", true, true, 0.75, [1.5, -0.25, 0.5], [1.0, 0.25, 0.0], [1.0, 0.0, 0.0]),
        ("COLOR", true, true, 1.5, [1.25, 0.75, 0.25], [-0.25, 0.0, 0.75], [0.0, 0.0, 1.0]),
        ("COLOR", true, true, 0.0, [0.5, 1.0, -0.5], [0.0, 0.5, 1.0], [0.5, 1.0, 0.0]),
        ("DARKEN", true, true, 0.75, [-0.25, 0.0, 1.25], [1.5, 1.5, 1.0], [0.0, 0.0, 1.0]),
        ("DARKEN", true, true, 0.5, [1.5, -0.25, 0.75], [1.0, 1.0, 0.25], [1.0, 0.0, 0.5]),
        ("DIFFERENCE", true, true, 1.25, [0.0, 0.75, 0.0], [0.75, 1.0, 0.75], [0.75, 0.25, 0.75]),
        ("DIFFERENCE", true, true, -0.25, [1.5, 1.25, 0.25], [0.25, 0.25, 1.0], [1.0, 1.0, 0.25]),
        ("DIVIDE", true, true, 0.75, [-0.25, 0.0, 1.25], [1.5, 1.5, 1.0], [0.0, 0.0, 1.0]),
        ("DIVIDE", true, true, 0.5, [1.5, -0.25, 0.75], [1.0, 1.0, 0.25], [1.0, 0.0, 1.0]),
        ("DODGE", true, true, 1.5, [1.25, 0.75, 0.25], [-0.25, 0.0, 0.75], [1.0, 0.75, 1.0]),
        ("DODGE", true, true, 0.0, [0.5, 1.0, -0.5], [0.0, 0.5, 1.0], [0.5, 1.0, 0.0]),
        ("EXCLUSION", true, true, 0.75, [0.25, 1.0, -0.25], [0.5, 0.75, 0.0], [0.4375, 0.4375, 0.0]),
        ("EXCLUSION", true, true, 0.0, [1.25, 0.5, 0.5], [-0.25, 0.0, 0.75], [1.0, 0.5, 0.5]),
        ("HUE", true, true, 1.5, [0.25, 0.75, 0.5], [1.0, 0.75, 1.0], [0.75, 0.25, 0.75]),
        ("HUE", true, true, 1.5, [1.5, 1.25, 0.5], [0.25, 1.0, 1.5], [0.5, 1.0, 1.0]),
        ("LIGHTEN", true, true, 1.0, [0.75, 1.25, -0.5], [0.0, -0.25, 0.75], [0.75, 1.0, 0.75]),
        ("LIGHTEN", true, true, 1.0, [1.25, -0.25, 1.0], [1.5, 0.5, 1.25], [1.0, 0.5, 1.0]),
        ("LINEAR_LIGHT", true, true, 0.0, [0.0, 0.25, 0.0], [0.0, 0.0, 0.0], [0.0, 0.25, 0.0]),
        ("LINEAR_LIGHT", true, true, 0.0, [-0.25, 1.25, -0.25], [1.25, -0.5, 1.25], [0.0, 1.0, 0.0]),
        ("MIX", true, true, 1.5, [0.25, 0.75, 0.5], [1.0, 0.75, 1.0], [1.0, 0.75, 1.0]),
        ("MIX", true, true, 1.5, [1.5, 1.25, 0.5], [0.25, 1.0, 1.5], [0.25, 1.0, 1.0]),
        ("MULTIPLY", true, true, 0.25, [-0.25, 0.5, 0.0], [0.75, 1.0, 1.0], [0.0, 0.5, 0.0]),
        ("MULTIPLY", true, true, 1.25, [0.25, 0.5, -0.25], [0.0, 0.0, 1.25], [0.0, 0.0, 0.0]),
        ("OVERLAY", true, true, 1.0, [0.75, 1.25, -0.5], [0.0, -0.25, 0.75], [0.5, 1.0, 0.0]),
        ("OVERLAY", true, true, 1.0, [1.25, -0.25, 1.0], [1.5, 0.5, 1.25], [0.75, 0.0, 1.0]),
        ("SATURATION", true, true, 1.25, [0.0, 0.75, 0.0], [0.75, 1.0, 0.75], [0.5625, 0.75, 0.5625]),
        ("SATURATION", true, true, -0.25, [1.5, 1.25, 0.25], [0.25, 0.25, 1.0], [1.0, 1.0, 0.25000003]),
        ("SCREEN", true, true, 0.75, [-0.25, 0.0, 1.25], [1.5, 1.5, 1.0], [1.0, 1.0, 1.0]),
        ("SCREEN", true, true, 0.5, [1.5, -0.25, 0.75], [1.0, 1.0, 0.25], [1.0, 0.375, 0.78125]),
        ("SOFT_LIGHT", true, true, 1.25, [0.0, 0.75, 0.0], [0.75, 1.0, 0.75], [0.0, 0.9375, 0.0]),
        ("SOFT_LIGHT", true, true, -0.25, [1.5, 1.25, 0.25], [0.25, 0.25, 1.0], [1.0, 1.0, 0.25]),
        ("SUBTRACT", true, true, 0.25, [-0.25, 0.5, 0.0], [0.75, 1.0, 1.0], [0.0, 0.25, 0.0]),
        ("SUBTRACT", true, true, 1.25, [0.25, 0.5, -0.25], [0.0, 0.0, 1.25], [0.25, 0.5, 0.0]),
        ("VALUE", true, true, 1.5, [1.25, 0.75, 0.25], [-0.25, 0.0, 0.75], [0.75, 0.45000002, 0.14999999]),
        ("VALUE", true, true, 0.0, [0.5, 1.0, -0.5], [0.0, 0.5, 1.0], [0.5000001, 1.0, 0.0]),
    ];

    /// Legacy MixRGB with use_clamp, measured from Cycles 5.0: (blend, fac, color1, color2, result).
    #[rustfmt::skip]
    const MIX_RGB_CLAMPED: &[(&str, f32, [f32; 3], [f32; 3], [f32; 3])] = &[
        ("ADD", 1.0999546, [1.1694126, -0.3571949, 0.9674473], [1.4408379, 0.57016754, 1.2388725], [1.0, 0.21297264, 1.0]),
        ("BURN", -0.12032318, [-0.47851205, -0.23415017, 1.2202139], [1.4645753, 1.4773736, 1.1632967], [0.0, 0.0, 1.0]),
        ("COLOR", -0.07768631, [1.3298092, 0.60180855, 0.3975563], [-0.33044434, -0.0037574768, 0.7373047], [1.0, 0.60180855, 0.3975563]),
        ("DARKEN", -0.2850933, [1.1072521, -0.16252995, 1.4383135], [0.16853237, 0.62218857, 0.49959564], [1.0, 0.0, 1.0]),
        ("DIFFERENCE", 1.2331185, [1.3040112, 1.167438, 0.40774226], [0.2711711, 0.39178497, 1.374902], [1.0, 0.77565306, 0.96715975]),
        ("DIVIDE", -0.2850933, [1.1072521, -0.16252995, 1.4383135], [0.16853237, 0.62218857, 0.49959564], [1.0, 0.0, 1.0]),
        ("DODGE", -0.07768631, [1.3298092, 0.60180855, 0.3975563], [-0.33044434, -0.0037574768, 0.7373047], [1.0, 0.60180855, 0.3975563]),
        ("EXCLUSION", -0.30045843, [-0.04119587, -0.39384365, 0.26475906], [-0.08788872, 1.4372749, 0.21806717], [0.0, 0.0, 0.26475906]),
        ("HUE", 1.0999546, [1.1694126, -0.3571949, 0.9674473], [1.4408379, 0.57016754, 1.2388725], [1.0, 0.0, 0.815293]),
        ("LIGHTEN", -0.4098072, [0.45145035, 0.6182022, -0.20129776], [-0.0345459, 1.3412666, 1.312706], [0.45145035, 0.6182022, 0.0]),
        ("LINEAR_LIGHT", 0.71503925, [0.9367962, 0.3321495, 0.35000038], [-0.2546482, 0.57476616, 1.1585541], [0.0, 0.43907097, 1.0]),
        ("MIX", 1.0999546, [1.1694126, -0.3571949, 0.9674473], [1.4408379, 0.57016754, 1.2388725], [1.0, 0.57016754, 1.0]),
        ("MULTIPLY", -0.043759346, [0.00024795532, 0.14304924, -0.049149513], [0.093652725, 0.06926632, 0.044255257], [0.00024795532, 0.14304924, 0.0]),
        ("OVERLAY", -0.4098072, [0.45145035, 0.6182022, -0.20129776], [-0.0345459, 1.3412666, 1.312706], [0.45145035, 0.6182022, 0.0]),
        ("SATURATION", 1.2331185, [1.3040112, 1.167438, 0.40774226], [0.2711711, 0.39178497, 1.374902], [1.0, 1.0, 0.25718933]),
        ("SCREEN", -0.2850933, [1.1072521, -0.16252995, 1.4383135], [0.16853237, 0.62218857, 0.49959564], [1.0, 0.0, 1.0]),
        ("SOFT_LIGHT", 1.2331185, [1.3040112, 1.167438, 0.40774226], [0.2711711, 0.39178497, 1.374902], [1.0, 1.0, 0.83029985]),
        ("SUBTRACT", -0.043759346, [0.00024795532, 0.14304924, -0.049149513], [0.093652725, 0.06926632, 0.044255257], [0.00024795532, 0.14304924, 0.0]),
        ("VALUE", -0.07768631, [1.3298092, 0.60180855, 0.3975563], [-0.33044434, -0.0037574768, 0.7373047], [1.0, 0.6018085, 0.3975563]),
    ];
}
