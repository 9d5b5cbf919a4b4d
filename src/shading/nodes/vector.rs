//! Vector nodes: Mapping and Normal Map, and the glTF preset's texture transform, normal map
//! (with glTF's `scale`) and anisotropy direction.

use super::bump::safe_normalize;
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
        /// glTF's `normalTexture.scale` on the texel's X and Y (1 for Blender's node).
        xy_scale: f32,
        out: Slot,
    },
    /// `KHR_texture_transform` on a glTF texture coordinate: `(u, v) → M (u, v, 1)`.
    UvTransform {
        vector: Slot,
        m: [f32; 6],
        out: Slot,
    },
    /// `KHR_materials_anisotropy`'s direction as a Blender-world tangent: the texel's RG
    /// (`2c - 1`, or `(1, 0)` without a texture) rotated by `rotation` in the tangent frame.
    GltfAnisotropy {
        color: Option<Slot>,
        rotation: f32,
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
                xy_scale,
                out,
            } => {
                let mut c = s.v(color) * 2.0 - Vec3::ONE;
                if xy_scale != 1.0 {
                    c.x *= xy_scale;
                    c.y *= xy_scale;
                }
                let k = s.f(strength).max(0.0);
                // Cycles blends the tangent-space normal with N before normalising it.
                let n = if k != 1.0 && space == NormalSpace::Tangent {
                    normal_map_raw(c, g)
                } else {
                    normal_map(space, c, g)
                };
                let n = if k != 1.0 {
                    safe_normalize(g.n + (n - g.n) * k)
                } else {
                    n
                };
                s.set_v(out, if n == Vec3::ZERO { g.n } else { n });
            }
            VectorOp::UvTransform { vector, m, out } => {
                let v = s.v(vector);
                let u = m[0] * v.x + m[1] * v.y + m[2];
                let w = m[3] * v.x + m[4] * v.y + m[5];
                s.set_v(out, Vec3::new(u, w, v.z));
            }
            VectorOp::GltfAnisotropy {
                color,
                rotation,
                out,
            } => {
                let mut d = match color {
                    Some(c) => {
                        let c = s.v(c);
                        glam::Vec2::new(c.x * 2.0 - 1.0, c.y * 2.0 - 1.0)
                            .try_normalize()
                            .unwrap_or(glam::Vec2::X)
                    }
                    None => glam::Vec2::X,
                };
                if rotation != 0.0 {
                    d = glam::Vec2::from_angle(rotation).rotate(d);
                }
                let t = match tangent_frame(g) {
                    Some((t, b, _)) => safe_normalize(d.x * t + d.y * b),
                    None => Vec3::ZERO,
                };
                s.set_v(out, t);
            }
        }
    }
}

/// The unit tangent, bitangent and normal of the surface's front side at `g` (Blender world):
/// the tangent orthogonalised against the shading normal, the bitangent `sign · n × t` (along
/// Blender's +v, the image's up). `None` without a tangent.
fn tangent_frame(g: &ShaderGlobals) -> Option<(Vec3, Vec3, Vec3)> {
    let (t, sign) = g.tangent()?;
    let n = if g.backfacing { -g.n } else { g.n };
    let t = safe_normalize(t - n * n.dot(t));
    Some((t, n.cross(t) * sign, n))
}

/// A normal-map texel `c` (already mapped to `[-1, 1]`) as a Blender-world normal on the side
/// of the shading normal.
/// The tangent-space texel `c` as an unnormalised Blender-world vector (`g.n` without a
/// tangent frame).
fn normal_map_raw(c: Vec3, g: &ShaderGlobals) -> Vec3 {
    let Some((t, b, n)) = tangent_frame(g) else {
        return g.n;
    };
    let r = c.x * t + c.y * b + c.z * n;
    if g.backfacing { -r } else { r }
}

fn normal_map(space: NormalSpace, c: Vec3, g: &ShaderGlobals) -> Vec3 {
    match space {
        NormalSpace::Tangent => {
            // The tangent frame belongs to the surface's front: build it on the unflipped
            // normal, then flip the result with it.
            let Some((t, b, n)) = tangent_frame(g) else {
                return g.n;
            };
            let r = safe_normalize(c.x * t + c.y * b + c.z * n);
            if g.backfacing { -r } else { r }
        }
        NormalSpace::Object => match g.to_object() {
            Some(to_object) => {
                // Object → world for normals: inverse transpose of object → world.
                let to_world_normal = Mat3::from_mat4(to_object).transpose();
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
                    xy_scale: 1.0,
                    out,
                }),
                true,
            );
        }
        "TeselaGltfNormalMap" => {
            // Internal (glTF preset): a tangent-space normal texture with glTF's `scale`:
            // `normalize((2c - 1) · (scale, scale, 1))` in the (T, B, N) frame.
            let strength = cx.constant(&[1.0])?;
            let color = cx.color("Color", Vec3::new(0.5, 0.5, 1.0))?;
            let xy_scale = cx.prop_f32("scale", 1.0);
            let out = cx.output("Normal", SocketType::Vector)?;
            cx.emit(
                Op::Vector(VectorOp::NormalMap {
                    space: NormalSpace::Tangent,
                    strength,
                    color,
                    xy_scale,
                    out,
                }),
                true,
            );
        }
        "TeselaUvTransform" => {
            // Internal (glTF preset): KHR_texture_transform's 2×3 matrix, row-major.
            let mut m = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
            if let Some(a) = cx.prop("matrix").and_then(|v| v.as_array()) {
                for (k, x) in m.iter_mut().enumerate() {
                    if let Some(v) = a.get(k).and_then(|v| v.as_f64()).map(|v| v as f32)
                        && v.is_finite()
                    {
                        *x = v;
                    }
                }
            }
            let vector = cx.vector("Vector", Vec3::ZERO)?;
            let out = cx.output("Vector", SocketType::Vector)?;
            cx.emit(Op::Vector(VectorOp::UvTransform { vector, m, out }), false);
        }
        "TeselaGltfAnisotropy" => {
            // Internal (glTF preset): the anisotropy direction as a tangent.
            let color = if cx.is_linked("Color") {
                Some(cx.color("Color", Vec3::new(1.0, 0.5, 1.0))?)
            } else {
                None
            };
            let rotation = cx.prop_f32("rotation", 0.0);
            let out = cx.output("Tangent", SocketType::Vector)?;
            cx.emit(
                Op::Vector(VectorOp::GltfAnisotropy {
                    color,
                    rotation,
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
