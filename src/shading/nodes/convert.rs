//! Conversions between socket types (Cycles' implicit ones), Separate/Combine XYZ and RGB, and
//! the few arithmetic operations the compiler and presets emit themselves.

use crate::shading::compile::{CompileError, NodeCx, SocketType, luminance};
use crate::shading::program::{Op, Slot, Slots};
use glam::Vec3;

#[derive(Clone, Copy, Debug)]
pub enum ConvertOp {
    FloatToVec {
        a: Slot,
        out: Slot,
    },
    ColorToFloat {
        a: Slot,
        out: Slot,
    },
    VectorToFloat {
        a: Slot,
        out: Slot,
    },
    Copy1 {
        a: Slot,
        out: Slot,
    },
    Copy3 {
        a: Slot,
        out: Slot,
    },
    /// Components of a vector into three floats.
    Separate {
        a: Slot,
        x: Slot,
        y: Slot,
        z: Slot,
    },
    /// Three floats into a vector.
    Combine {
        x: Slot,
        y: Slot,
        z: Slot,
        out: Slot,
    },
    MulF {
        a: Slot,
        b: Slot,
        out: Slot,
    },
    MulV {
        a: Slot,
        b: Slot,
        out: Slot,
    },
    /// glTF `alphaMode: MASK`: 1 where `a >= cutoff`, else 0 (NaN: 0).
    AlphaCutoff {
        a: Slot,
        cutoff: f32,
        out: Slot,
    },
}

impl ConvertOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots) {
        match *self {
            ConvertOp::FloatToVec { a, out } => s.set_v(out, Vec3::splat(s.f(a))),
            ConvertOp::ColorToFloat { a, out } => s.set_f(out, luminance(s.v(a))),
            ConvertOp::VectorToFloat { a, out } => {
                let v = s.v(a);
                s.set_f(out, (v.x + v.y + v.z) * (1.0 / 3.0));
            }
            ConvertOp::Copy1 { a, out } => s.set_f(out, s.f(a)),
            ConvertOp::Copy3 { a, out } => s.set_v(out, s.v(a)),
            ConvertOp::Separate { a, x, y, z } => {
                let v = s.v(a);
                s.set_f(x, v.x);
                s.set_f(y, v.y);
                s.set_f(z, v.z);
            }
            ConvertOp::Combine { x, y, z, out } => s.set_v(out, Vec3::new(s.f(x), s.f(y), s.f(z))),
            ConvertOp::MulF { a, b, out } => s.set_f(out, s.f(a) * s.f(b)),
            ConvertOp::MulV { a, b, out } => s.set_v(out, s.v(a) * s.v(b)),
            ConvertOp::AlphaCutoff { a, cutoff, out } => {
                s.set_f(out, if s.f(a) >= cutoff { 1.0 } else { 0.0 })
            }
        }
    }
}

pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    use SocketType::{Color, Float, Vector};
    match kind {
        "ShaderNodeSeparateXYZ" => {
            let a = cx.vector("Vector", Vec3::ZERO)?;
            let x = cx.output("X", Float)?;
            let y = cx.output("Y", Float)?;
            let z = cx.output("Z", Float)?;
            cx.emit(Op::Convert(ConvertOp::Separate { a, x, y, z }), false);
        }
        "ShaderNodeCombineXYZ" => {
            let x = cx.float("X", 0.0)?;
            let y = cx.float("Y", 0.0)?;
            let z = cx.float("Z", 0.0)?;
            let out = cx.output("Vector", Vector)?;
            cx.emit(Op::Convert(ConvertOp::Combine { x, y, z, out }), false);
        }
        "ShaderNodeSeparateRGB" => {
            let a = cx.color("Image", Vec3::splat(0.8))?;
            let x = cx.output("R", Float)?;
            let y = cx.output("G", Float)?;
            let z = cx.output("B", Float)?;
            cx.emit(Op::Convert(ConvertOp::Separate { a, x, y, z }), false);
        }
        "ShaderNodeCombineRGB" => {
            let x = cx.float("R", 0.0)?;
            let y = cx.float("G", 0.0)?;
            let z = cx.float("B", 0.0)?;
            let out = cx.output("Image", Color)?;
            cx.emit(Op::Convert(ConvertOp::Combine { x, y, z, out }), false);
        }
        "TeselaMultiply" => {
            // Internal (presets): component-wise product of two colours or two floats.
            if cx.prop_bool("float", false) {
                let a = cx.float("A", 1.0)?;
                let b = cx.float("B", 1.0)?;
                let out = cx.output("Value", Float)?;
                cx.emit(Op::Convert(ConvertOp::MulF { a, b, out }), false);
            } else {
                let a = cx.color("A", Vec3::ONE)?;
                let b = cx.color("B", Vec3::ONE)?;
                let out = cx.output("Color", Color)?;
                cx.emit(Op::Convert(ConvertOp::MulV { a, b, out }), false);
            }
        }
        "TeselaAlphaCutoff" => {
            // Internal (glTF preset): alpha masking at `props.cutoff`.
            let a = cx.float("Alpha", 1.0)?;
            let cutoff = cx.prop_f32("cutoff", 0.5);
            let out = cx.output("Alpha", Float)?;
            cx.emit(
                Op::Convert(ConvertOp::AlphaCutoff { a, cutoff, out }),
                false,
            );
        }
        _ => return Ok(false),
    }
    Ok(true)
}
