//! The Light Falloff node (Cycles' `svm_node_light_falloff`): its Strength as is (Quadratic:
//! the inverse-square law the renderer applies anyway), times the ray length (Linear: an
//! inverse-distance fall-off) or its square (Constant: none), and with Smooth `s > 0` times
//! `d² / (s + d²)`, which softens the blow-up close to the light. Distant rays (an infinite
//! length) get the strength unchanged.

use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::ShaderGlobals;
use crate::shading::program::{Op, Slot, Slots};

#[derive(Clone, Copy, Debug)]
pub struct LightFalloffOp {
    strength: Slot,
    smooth: Slot,
    /// Quadratic, Linear, Constant.
    out: [Slot; 3],
}

/// `[quadratic, linear, constant]` for `strength`, `smooth` and the ray length `d`.
pub fn light_falloff(strength: f32, smooth: f32, d: f32) -> [f32; 3] {
    if !d.is_finite() || d == f32::MAX {
        return [strength; 3];
    }
    let soft = if smooth > 0.0 {
        d * d / (smooth + d * d)
    } else {
        1.0
    };
    [strength, strength * d, strength * (d * d)].map(|x| x * soft)
}

impl LightFalloffOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals) {
        let v = light_falloff(s.f(self.strength), s.f(self.smooth), g.ray_length);
        for (slot, x) in self.out.iter().zip(v) {
            s.set_f(*slot, x);
        }
    }
}

pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    if kind != "ShaderNodeLightFalloff" {
        return Ok(false);
    }
    let strength = cx.float("Strength", 100.0)?;
    let smooth = cx.float("Smooth", 0.0)?;
    let out = [
        cx.output("Quadratic", SocketType::Float)?,
        cx.output("Linear", SocketType::Float)?,
        cx.output("Constant", SocketType::Float)?,
    ];
    cx.emit(
        Op::LightFalloff(LightFalloffOp {
            strength,
            smooth,
            out,
        }),
        true,
    );
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn falloffs_scale_with_distance_and_smooth_softens() {
        assert_eq!(light_falloff(10.0, 0.0, 2.0), [10.0, 20.0, 40.0]);
        let [q, l, c] = light_falloff(10.0, 4.0, 2.0);
        assert!((q - 5.0).abs() < 1e-6 && (l - 10.0).abs() < 1e-6 && (c - 20.0).abs() < 1e-6);
        assert_eq!(light_falloff(3.0, 1.0, f32::INFINITY), [3.0; 3]);
    }
}
