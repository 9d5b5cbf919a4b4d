//! Compile glue and operations for the utility nodes whose algorithms live in their family
//! files: Math, Vector Math, Map Range, Clamp, Mix / MixRGB, the colour nodes, Color Ramp and
//! the curve nodes.

use super::color::{self, ColorMode};
use super::curves::{CurveTable, FloatCurveTable};
use super::map_range::{self, ClampType, MapRangeType};
use super::math::{self, MathOp};
use super::mix::{self, Blend};
use super::ramp::{HueInterpolation, Ramp, RampColorMode, RampInterpolation};
use super::vector_math::{self, VectorMathOp};
use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::program::{Op, Slot, Slots};
use glam::{Vec3, Vec4};
use serde_json::Value;

#[derive(Clone, Debug)]
pub enum UtilityOp {
    Math {
        op: MathOp,
        clamp: bool,
        a: Slot,
        b: Slot,
        c: Slot,
        out: Slot,
    },
    VectorMath {
        op: VectorMathOp,
        a: Slot,
        b: Slot,
        c: Slot,
        scale: Slot,
        out_v: Slot,
        out_f: Slot,
    },
    MapRange {
        ty: MapRangeType,
        clamp: bool,
        vector: bool,
        /// value, from min, from max, to min, to max, steps
        ins: [Slot; 6],
        out: Slot,
    },
    Clamp {
        ty: ClampType,
        value: Slot,
        min: Slot,
        max: Slot,
        out: Slot,
    },
    MixFloat {
        clamp: bool,
        t: Slot,
        a: Slot,
        b: Slot,
        out: Slot,
    },
    MixVector {
        clamp: bool,
        non_uniform: bool,
        t: Slot,
        a: Slot,
        b: Slot,
        out: Slot,
    },
    MixColor {
        blend: Blend,
        clamp_factor: bool,
        clamp_result: bool,
        t: Slot,
        a: Slot,
        b: Slot,
        out: Slot,
    },
    Separate {
        mode: ColorMode,
        color: Slot,
        out: [Slot; 3],
    },
    Combine {
        mode: ColorMode,
        ins: [Slot; 3],
        out: Slot,
    },
    HueSat {
        hue: Slot,
        sat: Slot,
        val: Slot,
        fac: Slot,
        color: Slot,
        out: Slot,
    },
    BrightContrast {
        color: Slot,
        bright: Slot,
        contrast: Slot,
        out: Slot,
    },
    Gamma {
        color: Slot,
        gamma: Slot,
        out: Slot,
    },
    Invert {
        fac: Slot,
        color: Slot,
        out: Slot,
    },
    RgbToBw {
        color: Slot,
        out: Slot,
    },
    Blackbody {
        t: Slot,
        out: Slot,
    },
    Wavelength {
        w: Slot,
        out: Slot,
    },
    Ramp {
        ramp: Box<Ramp>,
        fac: Slot,
        color: Slot,
        alpha: Slot,
    },
    Curves {
        table: Box<CurveTable>,
        fac: Slot,
        v: Slot,
        out: Slot,
    },
    FloatCurve {
        table: Box<FloatCurveTable>,
        fac: Slot,
        v: Slot,
        out: Slot,
    },
}

impl UtilityOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots) {
        match self {
            UtilityOp::Math {
                op,
                clamp,
                a,
                b,
                c,
                out,
            } => s.set_f(
                *out,
                math::math_node(*op, s.f(*a), s.f(*b), s.f(*c), *clamp),
            ),
            UtilityOp::VectorMath {
                op,
                a,
                b,
                c,
                scale,
                out_v,
                out_f,
            } => {
                let (v, f) = vector_math::vector_math(*op, s.v(*a), s.v(*b), s.v(*c), s.f(*scale));
                s.set_v(*out_v, v);
                s.set_f(*out_f, f);
            }
            UtilityOp::MapRange {
                ty,
                clamp,
                vector,
                ins,
                out,
            } => {
                if *vector {
                    let [v, a, b, c, d, st] = ins.map(|i| s.v(i));
                    let r = map_range::vector_map_range(*ty, v, a, b, c, d, st, *clamp);
                    s.set_v(*out, r);
                } else {
                    let [v, a, b, c, d, st] = ins.map(|i| s.f(i));
                    s.set_f(*out, map_range::map_range(*ty, v, a, b, c, d, st, *clamp));
                }
            }
            UtilityOp::Clamp {
                ty,
                value,
                min,
                max,
                out,
            } => s.set_f(
                *out,
                map_range::clamp_node(*ty, s.f(*value), s.f(*min), s.f(*max)),
            ),
            UtilityOp::MixFloat {
                clamp,
                t,
                a,
                b,
                out,
            } => s.set_f(*out, mix::mix_float(s.f(*t), s.f(*a), s.f(*b), *clamp)),
            UtilityOp::MixVector {
                clamp,
                non_uniform,
                t,
                a,
                b,
                out,
            } => {
                let r = if *non_uniform {
                    mix::mix_vector_non_uniform(s.v(*t), s.v(*a), s.v(*b), *clamp)
                } else {
                    mix::mix_vector(s.f(*t), s.v(*a), s.v(*b), *clamp)
                };
                s.set_v(*out, r);
            }
            UtilityOp::MixColor {
                blend,
                clamp_factor,
                clamp_result,
                t,
                a,
                b,
                out,
            } => s.set_v(
                *out,
                mix::mix_color_node(
                    *blend,
                    s.f(*t),
                    s.v(*a),
                    s.v(*b),
                    *clamp_factor,
                    *clamp_result,
                ),
            ),
            UtilityOp::Separate { mode, color, out } => {
                let v = color::separate_color(*mode, s.v(*color));
                s.set_f(out[0], v.x);
                s.set_f(out[1], v.y);
                s.set_f(out[2], v.z);
            }
            UtilityOp::Combine { mode, ins, out } => {
                let v = Vec3::new(s.f(ins[0]), s.f(ins[1]), s.f(ins[2]));
                s.set_v(*out, color::combine_color(*mode, v));
            }
            UtilityOp::HueSat {
                hue,
                sat,
                val,
                fac,
                color,
                out,
            } => s.set_v(
                *out,
                color::hue_saturation_value(
                    s.f(*hue),
                    s.f(*sat),
                    s.f(*val),
                    s.f(*fac),
                    s.v(*color),
                ),
            ),
            UtilityOp::BrightContrast {
                color,
                bright,
                contrast,
                out,
            } => s.set_v(
                *out,
                color::brightness_contrast(s.v(*color), s.f(*bright), s.f(*contrast)),
            ),
            UtilityOp::Gamma { color, gamma, out } => {
                s.set_v(*out, color::gamma(s.v(*color), s.f(*gamma)))
            }
            UtilityOp::Invert { fac, color, out } => {
                s.set_v(*out, color::invert(s.f(*fac), s.v(*color)))
            }
            UtilityOp::RgbToBw { color, out } => s.set_f(*out, color::rgb_to_bw(s.v(*color))),
            UtilityOp::Blackbody { t, out } => s.set_v(*out, color::blackbody(s.f(*t))),
            UtilityOp::Wavelength { w, out } => s.set_v(*out, color::wavelength(s.f(*w))),
            UtilityOp::Ramp {
                ramp,
                fac,
                color,
                alpha,
            } => {
                let c: Vec4 = ramp.lookup(s.f(*fac));
                s.set_v(*color, c.truncate());
                s.set_f(*alpha, c.w);
            }
            UtilityOp::Curves { table, fac, v, out } => {
                s.set_v(*out, table.evaluate(s.f(*fac), s.v(*v)))
            }
            UtilityOp::FloatCurve { table, fac, v, out } => {
                s.set_f(*out, table.float_curve(s.f(*fac), s.f(*v)))
            }
        }
    }
}

fn emit(cx: &mut NodeCx, op: UtilityOp) {
    cx.emit(Op::Utility(op), false);
}

/// Numbers from a JSON array.
fn numbers(v: Option<&Value>) -> Vec<f32> {
    v.and_then(Value::as_array)
        .map(|a| {
            a.iter()
                .filter_map(Value::as_f64)
                .map(|x| x as f32)
                .filter(|x| x.is_finite())
                .collect()
        })
        .unwrap_or_default()
}

/// Rows of `n` numbers from a JSON array of arrays (or a flat array).
fn rows(v: Option<&Value>, n: usize) -> Vec<Vec<f32>> {
    let Some(a) = v.and_then(Value::as_array) else {
        return Vec::new();
    };
    if a.first().is_some_and(Value::is_array) {
        a.iter()
            .map(|r| numbers(Some(r)))
            .filter(|r| r.len() >= n)
            .collect()
    } else {
        numbers(v).chunks_exact(n).map(<[f32]>::to_vec).collect()
    }
}

fn color_mode(cx: &NodeCx) -> Option<ColorMode> {
    ColorMode::from_blender(cx.prop_str("mode").unwrap_or("RGB"))
}

pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    use SocketType::{Color, Float, Vector};
    match kind {
        "ShaderNodeMath" => {
            let name = cx.prop_str("operation").unwrap_or("ADD");
            let Some(op) = MathOp::from_blender(name) else {
                cx.warn(&format!("unknown operation '{name}'; it renders as muted"));
                return Ok(false);
            };
            let a = cx.float("Value", 0.5)?;
            let b = cx.float("Value_001", 0.5)?;
            let c = cx.float("Value_002", 0.5)?;
            let out = cx.output("Value", Float)?;
            let clamp = cx.prop_bool("use_clamp", false);
            emit(
                cx,
                UtilityOp::Math {
                    op,
                    clamp,
                    a,
                    b,
                    c,
                    out,
                },
            );
        }
        "ShaderNodeVectorMath" => {
            let name = cx.prop_str("operation").unwrap_or("ADD");
            let Some(op) = VectorMathOp::from_blender(name) else {
                cx.warn(&format!("unknown operation '{name}'; it renders as muted"));
                return Ok(false);
            };
            let a = cx.vector("Vector", Vec3::ZERO)?;
            let b = cx.vector("Vector_001", Vec3::ZERO)?;
            let c = cx.vector("Vector_002", Vec3::ZERO)?;
            let scale = cx.float("Scale", 1.0)?;
            let out_v = cx.output("Vector", Vector)?;
            let out_f = cx.output("Value", Float)?;
            emit(
                cx,
                UtilityOp::VectorMath {
                    op,
                    a,
                    b,
                    c,
                    scale,
                    out_v,
                    out_f,
                },
            );
        }
        "ShaderNodeMapRange" => {
            let ty =
                MapRangeType::from_blender(cx.prop_str("interpolation_type").unwrap_or("LINEAR"))
                    .unwrap_or(MapRangeType::Linear);
            let clamp = cx.prop_bool("clamp", true);
            let vector = cx.prop_str("data_type") == Some("FLOAT_VECTOR");
            let ins = if vector {
                [
                    cx.vector("Vector", Vec3::ZERO)?,
                    cx.vector("From_Min_FLOAT3", Vec3::ZERO)?,
                    cx.vector("From_Max_FLOAT3", Vec3::ONE)?,
                    cx.vector("To_Min_FLOAT3", Vec3::ZERO)?,
                    cx.vector("To_Max_FLOAT3", Vec3::ONE)?,
                    cx.vector("Steps_FLOAT3", Vec3::splat(4.0))?,
                ]
            } else {
                [
                    cx.float("Value", 1.0)?,
                    cx.float("From Min", 0.0)?,
                    cx.float("From Max", 1.0)?,
                    cx.float("To Min", 0.0)?,
                    cx.float("To Max", 1.0)?,
                    cx.float("Steps", 4.0)?,
                ]
            };
            let out = if vector {
                cx.output("Vector", Vector)?
            } else {
                cx.output("Result", Float)?
            };
            emit(
                cx,
                UtilityOp::MapRange {
                    ty,
                    clamp,
                    vector,
                    ins,
                    out,
                },
            );
        }
        "ShaderNodeClamp" => {
            let ty = ClampType::from_blender(cx.prop_str("clamp_type").unwrap_or("MINMAX"))
                .unwrap_or(ClampType::MinMax);
            let value = cx.float("Value", 1.0)?;
            let min = cx.float("Min", 0.0)?;
            let max = cx.float("Max", 1.0)?;
            let out = cx.output("Result", Float)?;
            emit(
                cx,
                UtilityOp::Clamp {
                    ty,
                    value,
                    min,
                    max,
                    out,
                },
            );
        }
        "ShaderNodeMix" => {
            let clamp_factor = cx.prop_bool("clamp_factor", true);
            match cx.prop_str("data_type").unwrap_or("FLOAT") {
                "VECTOR" => {
                    let non_uniform = cx.prop_str("factor_mode") == Some("NON_UNIFORM");
                    let t = if non_uniform {
                        cx.vector("Factor_Vector", Vec3::splat(0.5))?
                    } else {
                        cx.float("Factor_Float", 0.5)?
                    };
                    let a = cx.vector("A_Vector", Vec3::ZERO)?;
                    let b = cx.vector("B_Vector", Vec3::ZERO)?;
                    let out = cx.output("Result_Vector", Vector)?;
                    emit(
                        cx,
                        UtilityOp::MixVector {
                            clamp: clamp_factor,
                            non_uniform,
                            t,
                            a,
                            b,
                            out,
                        },
                    );
                }
                "RGBA" => {
                    let blend = Blend::from_blender(cx.prop_str("blend_type").unwrap_or("MIX"))
                        .unwrap_or(Blend::Mix);
                    let t = cx.float("Factor_Float", 0.5)?;
                    let a = cx.color("A_Color", Vec3::splat(0.5))?;
                    let b = cx.color("B_Color", Vec3::splat(0.5))?;
                    let out = cx.output("Result_Color", Color)?;
                    let clamp_result = cx.prop_bool("clamp_result", false);
                    emit(
                        cx,
                        UtilityOp::MixColor {
                            blend,
                            clamp_factor,
                            clamp_result,
                            t,
                            a,
                            b,
                            out,
                        },
                    );
                }
                "FLOAT" => {
                    let t = cx.float("Factor_Float", 0.5)?;
                    let a = cx.float("A_Float", 0.0)?;
                    let b = cx.float("B_Float", 0.0)?;
                    let out = cx.output("Result_Float", Float)?;
                    emit(
                        cx,
                        UtilityOp::MixFloat {
                            clamp: clamp_factor,
                            t,
                            a,
                            b,
                            out,
                        },
                    );
                }
                other => {
                    cx.warn(&format!("mix of type {other} renders as muted"));
                    return Ok(false);
                }
            }
        }
        "ShaderNodeMixRGB" => {
            let blend = Blend::from_blender(cx.prop_str("blend_type").unwrap_or("MIX"))
                .unwrap_or(Blend::Mix);
            let t = cx.float("Fac", 0.5)?;
            let a = cx.color("Color1", Vec3::splat(0.5))?;
            let b = cx.color("Color2", Vec3::splat(0.5))?;
            let out = cx.output("Color", Color)?;
            let clamp_result = cx.prop_bool("use_clamp", false);
            emit(
                cx,
                UtilityOp::MixColor {
                    blend,
                    clamp_factor: true,
                    clamp_result,
                    t,
                    a,
                    b,
                    out,
                },
            );
        }
        "ShaderNodeSeparateColor" | "ShaderNodeSeparateHSV" => {
            let mode = if kind == "ShaderNodeSeparateHSV" {
                ColorMode::Hsv
            } else {
                color_mode(cx).unwrap_or(ColorMode::Rgb)
            };
            let color = cx.color("Color", Vec3::splat(0.8))?;
            let ids = if kind == "ShaderNodeSeparateHSV" {
                ["H", "S", "V"]
            } else {
                ["Red", "Green", "Blue"]
            };
            let out = [
                cx.output(ids[0], Float)?,
                cx.output(ids[1], Float)?,
                cx.output(ids[2], Float)?,
            ];
            emit(cx, UtilityOp::Separate { mode, color, out });
        }
        "ShaderNodeCombineColor" | "ShaderNodeCombineHSV" => {
            let (mode, ids) = if kind == "ShaderNodeCombineHSV" {
                (ColorMode::Hsv, ["H", "S", "V"])
            } else {
                (
                    color_mode(cx).unwrap_or(ColorMode::Rgb),
                    ["Red", "Green", "Blue"],
                )
            };
            let ins = [
                cx.float(ids[0], 0.0)?,
                cx.float(ids[1], 0.0)?,
                cx.float(ids[2], 0.0)?,
            ];
            let out = cx.output("Color", Color)?;
            emit(cx, UtilityOp::Combine { mode, ins, out });
        }
        "ShaderNodeHueSaturation" => {
            let hue = cx.float("Hue", 0.5)?;
            let sat = cx.float("Saturation", 1.0)?;
            let val = cx.float("Value", 1.0)?;
            let fac = cx.float("Fac", 1.0)?;
            let color = cx.color("Color", Vec3::splat(0.8))?;
            let out = cx.output("Color", Color)?;
            emit(
                cx,
                UtilityOp::HueSat {
                    hue,
                    sat,
                    val,
                    fac,
                    color,
                    out,
                },
            );
        }
        "ShaderNodeBrightContrast" => {
            let color = cx.color("Color", Vec3::ONE)?;
            let bright = cx.float("Bright", 0.0)?;
            let contrast = cx.float("Contrast", 0.0)?;
            let out = cx.output("Color", Color)?;
            emit(
                cx,
                UtilityOp::BrightContrast {
                    color,
                    bright,
                    contrast,
                    out,
                },
            );
        }
        "ShaderNodeGamma" => {
            let color = cx.color("Color", Vec3::ONE)?;
            let gamma = cx.float("Gamma", 1.0)?;
            let out = cx.output("Color", Color)?;
            emit(cx, UtilityOp::Gamma { color, gamma, out });
        }
        "ShaderNodeInvert" => {
            let fac = cx.float("Fac", 1.0)?;
            let color = cx.color("Color", Vec3::ZERO)?;
            let out = cx.output("Color", Color)?;
            emit(cx, UtilityOp::Invert { fac, color, out });
        }
        "ShaderNodeRGBToBW" => {
            let color = cx.color("Color", Vec3::splat(0.5))?;
            let out = cx.output("Val", Float)?;
            emit(cx, UtilityOp::RgbToBw { color, out });
        }
        "ShaderNodeBlackbody" => {
            let t = cx.float("Temperature", 6500.0)?;
            let out = cx.output("Color", Color)?;
            emit(cx, UtilityOp::Blackbody { t, out });
        }
        "ShaderNodeWavelength" => {
            let w = cx.float("Wavelength", 500.0)?;
            let out = cx.output("Color", Color)?;
            emit(cx, UtilityOp::Wavelength { w, out });
        }
        "ShaderNodeValToRGB" => {
            let elements: Vec<(f32, Vec4)> = cx
                .prop("elements")
                .and_then(Value::as_array)
                .map(|a| {
                    a.iter()
                        .filter_map(|e| {
                            let pos = e.get("position")?.as_f64()? as f32;
                            let c = numbers(e.get("color"));
                            (c.len() >= 3 && pos.is_finite()).then(|| {
                                (
                                    pos,
                                    Vec4::new(c[0], c[1], c[2], c.get(3).copied().unwrap_or(1.0)),
                                )
                            })
                        })
                        .collect()
                })
                .unwrap_or_default();
            if elements.is_empty() {
                cx.warn("colour ramp without elements renders black");
            }
            let interpolation =
                RampInterpolation::from_blender(cx.prop_str("interpolation").unwrap_or("LINEAR"))
                    .unwrap_or(RampInterpolation::Linear);
            let color_mode =
                RampColorMode::from_blender(cx.prop_str("color_mode").unwrap_or("RGB"))
                    .unwrap_or(RampColorMode::Rgb);
            let hue =
                HueInterpolation::from_blender(cx.prop_str("hue_interpolation").unwrap_or("NEAR"))
                    .unwrap_or(HueInterpolation::Near);
            let ramp = if elements.is_empty() {
                Ramp::from_table(vec![Vec4::new(0.0, 0.0, 0.0, 1.0)], false)
            } else {
                Ramp::from_elements(&elements, interpolation, color_mode, hue)
            };
            let fac = cx.float("Fac", 0.5)?;
            let color = cx.output("Color", Color)?;
            let alpha = cx.output("Alpha", Float)?;
            emit(
                cx,
                UtilityOp::Ramp {
                    ramp: Box::new(ramp),
                    fac,
                    color,
                    alpha,
                },
            );
        }
        "ShaderNodeRGBCurve" | "ShaderNodeVectorCurve" => {
            let table = rows(cx.prop("table"), 3);
            if table.is_empty() {
                cx.warn("curves without a baked table render as muted");
                return Ok(false);
            }
            let table = CurveTable::new(
                table.iter().map(|r| Vec3::new(r[0], r[1], r[2])).collect(),
                cx.prop_f32("min_x", 0.0),
                cx.prop_f32("max_x", 1.0),
                cx.prop_bool("extrapolate", false),
            );
            let fac = cx.float("Fac", 1.0)?;
            let (id, ty) = if kind == "ShaderNodeRGBCurve" {
                ("Color", Color)
            } else {
                ("Vector", Vector)
            };
            let v = cx.input(id, ty, &[if ty == Color { 1.0 } else { 0.0 }])?;
            let out = cx.output(id, ty)?;
            emit(
                cx,
                UtilityOp::Curves {
                    table: Box::new(table),
                    fac,
                    v,
                    out,
                },
            );
        }
        "ShaderNodeFloatCurve" => {
            let table = numbers(cx.prop("table"));
            if table.is_empty() {
                cx.warn("a curve without a baked table renders as muted");
                return Ok(false);
            }
            let table = FloatCurveTable::new(
                table,
                cx.prop_f32("min_x", 0.0),
                cx.prop_f32("max_x", 1.0),
                cx.prop_bool("extrapolate", false),
            );
            let fac = cx.float("Factor", 1.0)?;
            let v = cx.float("Value", 1.0)?;
            let out = cx.output("Value", Float)?;
            emit(
                cx,
                UtilityOp::FloatCurve {
                    table: Box::new(table),
                    fac,
                    v,
                    out,
                },
            );
        }
        _ => return Ok(false),
    }
    Ok(true)
}
