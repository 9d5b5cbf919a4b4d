//! Vector nodes: Mapping and Normal Map.

use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::{ShaderGlobals, to_blender};
use crate::shading::program::{Op, Slot, Slots};
use glam::{Mat3, Vec3};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MappingType {
    Point,
    Texture,
    Vector,
    Normal,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NormalSpace {
    Tangent,
    Object,
    World,
}

#[derive(Clone, Copy, Debug)]
pub enum VectorOp {
    Mapping {
        kind: MappingType,
        vector: Slot,
        location: Slot,
        rotation: Slot,
        scale: Slot,
        out: Slot,
    },
    NormalMap {
        space: NormalSpace,
        strength: Slot,
        color: Slot,
        out: Slot,
    },
}

/// Blender's XYZ Euler rotation `Rz · Ry · Rx`.
pub fn euler_xyz(r: Vec3) -> Mat3 {
    Mat3::from_rotation_z(r.z) * Mat3::from_rotation_y(r.y) * Mat3::from_rotation_x(r.x)
}

/// `a / b` per component, 0 where `b` is 0 (Cycles' `safe_divide`).
fn safe_divide(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::select(b.cmpeq(Vec3::ZERO), Vec3::ZERO, a / b)
}

fn safe_normalize(v: Vec3) -> Vec3 {
    let l = v.length();
    if l > 0.0 && l.is_finite() {
        v / l
    } else {
        Vec3::ZERO
    }
}

/// Blender's Mapping node.
pub fn mapping(kind: MappingType, v: Vec3, loc: Vec3, rot: Vec3, scale: Vec3) -> Vec3 {
    let r = euler_xyz(rot);
    match kind {
        MappingType::Point => r * (v * scale) + loc,
        MappingType::Texture => safe_divide(r.transpose() * (v - loc), scale),
        MappingType::Vector => r * (v * scale),
        MappingType::Normal => safe_normalize(r * safe_divide(v, scale)),
    }
}

impl VectorOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals) {
        match *self {
            VectorOp::Mapping {
                kind,
                vector,
                location,
                rotation,
                scale,
                out,
            } => {
                let r = mapping(kind, s.v(vector), s.v(location), s.v(rotation), s.v(scale));
                s.set_v(out, r);
            }
            VectorOp::NormalMap {
                space,
                strength,
                color,
                out,
            } => {
                let c = s.v(color) * 2.0 - Vec3::ONE;
                let n = normal_map(space, c, g);
                let k = s.f(strength).max(0.0);
                let n = if k != 1.0 {
                    safe_normalize(g.n + (n - g.n) * k)
                } else {
                    n
                };
                s.set_v(out, if n == Vec3::ZERO { g.n } else { n });
            }
        }
    }
}

/// A normal-map texel `c` (already mapped to `[-1, 1]`) as a Blender-world normal on the side
/// of the shading normal.
fn normal_map(space: NormalSpace, c: Vec3, g: &ShaderGlobals) -> Vec3 {
    match space {
        NormalSpace::Tangent => {
            let Some((t, sign)) = g.tangent() else {
                return g.n;
            };
            // The tangent frame belongs to the surface's front: build it on the unflipped
            // normal, then flip the result with it.
            let n = if g.backfacing { -g.n } else { g.n };
            let t = safe_normalize(t - n * n.dot(t));
            let b = n.cross(t) * sign;
            let r = safe_normalize(c.x * t + c.y * b + c.z * n);
            if g.backfacing { -r } else { r }
        }
        NormalSpace::Object => match g.mesh {
            Some(m) => {
                // Object → world for normals: inverse transpose of object → world.
                let to_world_normal = Mat3::from_mat4(m.attrs.to_object).transpose();
                let r = safe_normalize(to_blender(to_world_normal * c));
                if g.backfacing { -r } else { r }
            }
            None => safe_normalize(c),
        },
        NormalSpace::World => {
            let r = safe_normalize(c);
            if g.backfacing { -r } else { r }
        }
    }
}

pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    match kind {
        "ShaderNodeMapping" => {
            let kind = match cx.prop_str("vector_type").unwrap_or("POINT") {
                "TEXTURE" => MappingType::Texture,
                "VECTOR" => MappingType::Vector,
                "NORMAL" => MappingType::Normal,
                _ => MappingType::Point,
            };
            let vector = cx.vector("Vector", Vec3::ZERO)?;
            let location = cx.vector("Location", Vec3::ZERO)?;
            let rotation = cx.vector("Rotation", Vec3::ZERO)?;
            let scale = cx.vector("Scale", Vec3::ONE)?;
            let out = cx.output("Vector", SocketType::Vector)?;
            cx.emit(
                Op::Vector(VectorOp::Mapping {
                    kind,
                    vector,
                    location,
                    rotation,
                    scale,
                    out,
                }),
                false,
            );
        }
        "ShaderNodeNormalMap" => {
            let space = match cx.prop_str("space").unwrap_or("TANGENT") {
                "OBJECT" | "BLENDER_OBJECT" => NormalSpace::Object,
                "WORLD" | "BLENDER_WORLD" => NormalSpace::World,
                _ => NormalSpace::Tangent,
            };
            let strength = cx.float("Strength", 1.0)?;
            let color = cx.color("Color", Vec3::new(0.5, 0.5, 1.0))?;
            let out = cx.output("Normal", SocketType::Vector)?;
            cx.emit(
                Op::Vector(VectorOp::NormalMap {
                    space,
                    strength,
                    color,
                    out,
                }),
                true,
            );
        }
        _ => return Ok(false),
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mapping_point_and_texture_are_inverse() {
        let (v, loc, rot, sc) = (
            Vec3::new(0.3, -1.2, 2.0),
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(0.4, -0.7, 1.1),
            Vec3::new(2.0, 0.5, 3.0),
        );
        let p = mapping(MappingType::Point, v, loc, rot, sc);
        let back = mapping(MappingType::Texture, p, loc, rot, sc);
        assert!((back - v).length() < 1e-5, "{back} vs {v}");
        // Rotation about Z by 90°: x → y.
        let r = mapping(
            MappingType::Vector,
            Vec3::X,
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, std::f32::consts::FRAC_PI_2),
            Vec3::ONE,
        );
        assert!((r - Vec3::Y).length() < 1e-6, "{r}");
    }
}
