//! The Displacement and Vector Displacement nodes, and the material output's Displacement
//! rendered as Cycles' "Bump Only" method: the displacement vector `d` is evaluated at the point
//! and at its two bump offsets, the heights `h = d·N` feed the Bump node's surface-gradient
//! formula (distance 1, strength 1), and the result replaces the shading normal `N` for the
//! whole surface graph (Cycles' `bump_from_displacement` and its Set Normal node).

use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::{ShaderGlobals, to_blender};
use crate::shading::program::{Slot, Slots};
use glam::{Mat3, Vec3};

/// The space a displacement is given in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Space {
    /// The object's own axes and units (the object's transform scales and turns it).
    Object,
    World,
    /// Vector Displacement only: x along the tangent, y along the normal, z along the
    /// bitangent (Cycles' convention).
    Tangent,
}

#[derive(Clone, Copy, Debug)]
pub enum DisplacementOp {
    /// Displacement node: `d = (height - midlevel) · scale · n̂` in world space, with `n̂` the
    /// Normal input (else `N`) taken through the object's transform in object space.
    Scalar {
        height: Slot,
        midlevel: Slot,
        scale: Slot,
        normal: Option<Slot>,
        space: Space,
        out: Slot,
    },
    /// Vector Displacement node: `d = (vector - midlevel) · scale` in `space`.
    Vector {
        vector: Slot,
        midlevel: Slot,
        scale: Slot,
        space: Space,
        out: Slot,
    },
    /// The displaced shading normal from the displacement at the point and its two offsets.
    Normal { d: [Slot; 3], out: Slot },
}

#[inline]
fn object_to_world(g: &ShaderGlobals) -> Option<Mat3> {
    g.object_to_world_linear()
}

use super::bump::safe_normalize;

impl DisplacementOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals) {
        match *self {
            DisplacementOp::Scalar {
                height,
                midlevel,
                scale,
                normal,
                space,
                out,
            } => {
                let n = normal.map_or(g.n, |n| s.v(n));
                let k = (s.f(height) - s.f(midlevel)) * s.f(scale);
                let d = match (space, object_to_world(g)) {
                    (Space::Object, Some(a)) => {
                        // Cycles: the normal into object space (transposed map, normalised),
                        // scaled there, and back out through the object's transform.
                        to_blender(a * (g.normal_to_object(n) * k))
                    }
                    _ => n * k,
                };
                s.set_v(out, if d.is_finite() { d } else { Vec3::ZERO });
            }
            DisplacementOp::Vector {
                vector,
                midlevel,
                scale,
                space,
                out,
            } => {
                let v = (s.v(vector) - Vec3::splat(s.f(midlevel))) * s.f(scale);
                let d = match space {
                    Space::World => v,
                    Space::Object => match object_to_world(g) {
                        Some(a) => to_blender(a * v),
                        None => v,
                    },
                    Space::Tangent => {
                        let (t, sign) = g.tangent().unwrap_or((Vec3::ZERO, 1.0));
                        let b = safe_normalize(g.n.cross(t)) * sign;
                        t * v.x + g.n * v.y + b * v.z
                    }
                };
                s.set_v(out, if d.is_finite() { d } else { Vec3::ZERO });
            }
            DisplacementOp::Normal { d, out } => {
                let n = g.n;
                let h = [s.v(d[0]).dot(n), s.v(d[1]).dot(n), s.v(d[2]).dot(n)];
                let m = super::bump::bumped_normal(g, n, h, 1.0, 1.0);
                s.set_v(out, m);
            }
        }
    }
}

fn space(cx: &NodeCx, default: &str) -> Space {
    match cx.prop_str("space").unwrap_or(default) {
        "WORLD" => Space::World,
        "TANGENT" => Space::Tangent,
        _ => Space::Object,
    }
}

pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    let op = match kind {
        "ShaderNodeDisplacement" => {
            let height = cx.float("Height", 0.0)?;
            let midlevel = cx.float("Midlevel", 0.5)?;
            let scale = cx.float("Scale", 1.0)?;
            let normal = cx.linked_vector("Normal")?;
            let space = space(cx, "OBJECT");
            let out = cx.output("Displacement", SocketType::Vector)?;
            DisplacementOp::Scalar {
                height,
                midlevel,
                scale,
                normal,
                space,
                out,
            }
        }
        "ShaderNodeVectorDisplacement" => {
            let vector = cx.color("Vector", Vec3::ZERO)?;
            let midlevel = cx.float("Midlevel", 0.0)?;
            let scale = cx.float("Scale", 1.0)?;
            let space = space(cx, "TANGENT");
            let out = cx.output("Displacement", SocketType::Vector)?;
            DisplacementOp::Vector {
                vector,
                midlevel,
                scale,
                space,
                out,
            }
        }
        _ => return Ok(false),
    };
    cx.emit(crate::shading::program::Op::Displacement(op), true);
    Ok(true)
}
