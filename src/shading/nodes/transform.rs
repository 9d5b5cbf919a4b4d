//! Nodes that move vectors between frames: Vector Rotate, Vector Transform (world, object and
//! camera space), Normal (a fixed direction and its dot product), Camera Data and Tangent, as
//! Cycles' `svm_node_vector_rotate`, `svm_node_vector_transform`, `svm_node_normal`,
//! `svm_node_camera` and `svm_node_tangent` compute them. Vectors are in Blender's world
//! axes (Z up) unless a node converts them.

use super::bump::safe_normalize;
use super::vector::euler_xyz;
use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::{ShadeEnv, ShaderGlobals, from_blender};
use crate::shading::program::{Op, Slot, Slots};
use glam::{Mat3, Mat4, Vec3};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RotateType {
    AxisAngle,
    X,
    Y,
    Z,
    EulerXyz,
}

/// What a Vector Transform moves: a point (translation applies), a direction, or a normal
/// (through the inverse transpose, then normalised).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VectorKind {
    Point,
    Vector,
    Normal,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Space {
    World,
    Object,
    Camera,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TangentSource {
    UvMap,
    /// Around the object's X, Y or Z axis through the texture space's centre (0, 1, 2).
    Radial(u8),
}

#[derive(Clone, Copy, Debug)]
pub enum TransformOp {
    Rotate {
        kind: RotateType,
        invert: bool,
        vector: Slot,
        center: Slot,
        axis: Slot,
        angle: Slot,
        rotation: Slot,
        out: Slot,
    },
    Transform {
        kind: VectorKind,
        from: Space,
        to: Space,
        vector: Slot,
        out: Slot,
    },
    /// The Normal node: its unit `direction`, and `direction · normalize(input)`.
    Normal {
        direction: Vec3,
        normal: Slot,
        out_normal: Slot,
        out_dot: Slot,
    },
    Camera {
        view_vector: Slot,
        z_depth: Slot,
        distance: Slot,
    },
    Tangent {
        source: TangentSource,
        out: Slot,
    },
}

/// `p` rotated by `angle` (radians, right-handed) about the unit `axis` through the origin.
pub fn rotate_around_axis(p: Vec3, axis: Vec3, angle: f32) -> Vec3 {
    Mat3::from_axis_angle(axis, angle) * p
}

/// Blender's Vector Rotate node.
pub fn vector_rotate(
    kind: RotateType,
    invert: bool,
    v: Vec3,
    c: Vec3,
    axis: Vec3,
    angle: f32,
    rot: Vec3,
) -> Vec3 {
    if kind == RotateType::EulerXyz {
        let r = euler_xyz(rot);
        let r = if invert { r.transpose() } else { r };
        return r * (v - c) + c;
    }
    let axis = match kind {
        RotateType::X => Vec3::X,
        RotateType::Y => Vec3::Y,
        RotateType::Z => Vec3::Z,
        _ => axis,
    };
    let len = axis.length();
    if len == 0.0 || !len.is_finite() {
        return v;
    }
    let angle = if invert { -angle } else { angle };
    rotate_around_axis(v - c, axis / len, angle) + c
}

/// An affine map of Blender-world vectors and how it moves each kind of vector.
struct Affine(Mat4);

impl Affine {
    fn apply(&self, kind: VectorKind, v: Vec3) -> Vec3 {
        match kind {
            VectorKind::Point => self.0.transform_point3(v),
            VectorKind::Vector => self.0.transform_vector3(v),
            // Normals go through the inverse transpose of the map that moves points.
            VectorKind::Normal => safe_normalize(Mat3::from_mat4(self.0).inverse().transpose() * v),
        }
    }
}

/// Blender world → Cycles' camera space (x right, y up, +z along the view).
fn world_to_camera(env: &ShadeEnv) -> Affine {
    Affine(Mat4::from_scale(Vec3::new(1.0, 1.0, -1.0)) * env.camera_to_world.inverse())
}

/// Blender world → the object's own coordinates, when the point is on an object.
fn world_to_object(g: &ShaderGlobals) -> Option<Affine> {
    let to_object = g.to_object()?;
    // Renderer world (glTF axes) ↔ Blender world: a rotation about X.
    let blender_to_renderer = Mat4::from_mat3(Mat3::from_cols(
        from_blender(Vec3::X),
        from_blender(Vec3::Y),
        from_blender(Vec3::Z),
    ));
    let m = to_object * blender_to_renderer;
    m.is_finite().then_some(Affine(m))
}

fn inverse(a: Affine) -> Option<Affine> {
    let m = a.0.inverse();
    m.is_finite().then_some(Affine(m))
}

/// Blender's Vector Transform node. Off an object (the world), object space is world space.
pub fn vector_transform(
    kind: VectorKind,
    from: Space,
    to: Space,
    v: Vec3,
    g: &ShaderGlobals,
    env: &ShadeEnv,
) -> Vec3 {
    if from == to {
        return v;
    }
    let to_world = |v: Vec3| match from {
        Space::World => v,
        Space::Camera => inverse(world_to_camera(env)).map_or(v, |m| m.apply(kind, v)),
        Space::Object => world_to_object(g)
            .and_then(inverse)
            .map_or(v, |m| m.apply(kind, v)),
    };
    let w = to_world(v);
    match to {
        Space::World => w,
        Space::Camera => world_to_camera(env).apply(kind, w),
        Space::Object => world_to_object(g).map_or(w, |m| m.apply(kind, w)),
    }
}

impl TransformOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals, env: &ShadeEnv) {
        match *self {
            TransformOp::Rotate {
                kind,
                invert,
                vector,
                center,
                axis,
                angle,
                rotation,
                out,
            } => {
                let r = vector_rotate(
                    kind,
                    invert,
                    s.v(vector),
                    s.v(center),
                    s.v(axis),
                    s.f(angle),
                    s.v(rotation),
                );
                s.set_v(out, r);
            }
            TransformOp::Transform {
                kind,
                from,
                to,
                vector,
                out,
            } => s.set_v(out, vector_transform(kind, from, to, s.v(vector), g, env)),
            TransformOp::Normal {
                direction,
                normal,
                out_normal,
                out_dot,
            } => {
                s.set_v(out_normal, direction);
                s.set_f(out_dot, direction.dot(safe_normalize(s.v(normal))));
            }
            TransformOp::Camera {
                view_vector,
                z_depth,
                distance,
            } => {
                let c = world_to_camera(env).apply(VectorKind::Point, g.p);
                s.set_v(view_vector, safe_normalize(c));
                s.set_f(z_depth, c.z);
                s.set_f(distance, c.length());
            }
            TransformOp::Tangent { source, out } => {
                let t = match source {
                    TangentSource::UvMap => match g.tangent() {
                        Some((t, _)) => t,
                        None => {
                            s.set_v(out, Vec3::ZERO);
                            return;
                        }
                    },
                    TangentSource::Radial(axis) => {
                        let q = g.generated() - Vec3::splat(0.5);
                        let t = match axis {
                            0 => Vec3::new(0.0, -q.z, q.y),
                            1 => Vec3::new(-q.z, 0.0, q.x),
                            _ => Vec3::new(-q.y, q.x, 0.0),
                        };
                        // Object → world as a normal (Cycles' object_normal_transform).
                        match world_to_object(g) {
                            Some(m) => safe_normalize(Mat3::from_mat4(m.0).transpose() * t),
                            None => t,
                        }
                    }
                };
                // Orthogonal to the shading normal, in the plane of the normal and `t`.
                s.set_v(out, g.n.cross(safe_normalize(t.cross(g.n))));
            }
        }
    }
}

pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    use SocketType::{Float, Vector};
    match kind {
        "ShaderNodeVectorRotate" => {
            let kind = match cx.prop_str("rotation_type").unwrap_or("AXIS_ANGLE") {
                "X_AXIS" => RotateType::X,
                "Y_AXIS" => RotateType::Y,
                "Z_AXIS" => RotateType::Z,
                "EULER_XYZ" => RotateType::EulerXyz,
                _ => RotateType::AxisAngle,
            };
            let invert = cx.prop_bool("invert", false);
            let vector = cx.vector("Vector", Vec3::ZERO)?;
            let center = cx.vector("Center", Vec3::ZERO)?;
            let axis = cx.vector("Axis", Vec3::Z)?;
            let angle = cx.float("Angle", 0.0)?;
            let rotation = cx.vector("Rotation", Vec3::ZERO)?;
            let out = cx.output("Vector", Vector)?;
            cx.emit(
                Op::Transform(TransformOp::Rotate {
                    kind,
                    invert,
                    vector,
                    center,
                    axis,
                    angle,
                    rotation,
                    out,
                }),
                false,
            );
        }
        "ShaderNodeVectorTransform" => {
            let space = |cx: &NodeCx, key: &str| match cx.prop_str(key).unwrap_or("WORLD") {
                "OBJECT" => Space::Object,
                "CAMERA" => Space::Camera,
                _ => Space::World,
            };
            let (from, to) = (space(cx, "convert_from"), space(cx, "convert_to"));
            let kind = match cx.prop_str("vector_type").unwrap_or("VECTOR") {
                "POINT" => VectorKind::Point,
                "NORMAL" => VectorKind::Normal,
                _ => VectorKind::Vector,
            };
            let vector = cx.vector("Vector", Vec3::ZERO)?;
            let out = cx.output("Vector", Vector)?;
            // Object space differs per object, camera space is fixed: only the former varies.
            let varying = from == Space::Object || to == Space::Object;
            cx.emit(
                Op::Transform(TransformOp::Transform {
                    kind,
                    from,
                    to,
                    vector,
                    out,
                }),
                varying,
            );
        }
        "ShaderNodeNormal" => {
            let mut d = Vec3::Z;
            if let Some(a) = cx.prop("direction").and_then(|v| v.as_array()) {
                let c: Vec<f32> = a
                    .iter()
                    .filter_map(|x| x.as_f64())
                    .map(|x| x as f32)
                    .collect();
                if c.len() == 3 {
                    d = Vec3::new(c[0], c[1], c[2]);
                }
            }
            let direction = safe_normalize(d);
            let normal = cx.vector("Normal", Vec3::Z)?;
            let out_normal = cx.output("Normal", Vector)?;
            let out_dot = cx.output("Dot", Float)?;
            cx.emit(
                Op::Transform(TransformOp::Normal {
                    direction,
                    normal,
                    out_normal,
                    out_dot,
                }),
                false,
            );
        }
        "ShaderNodeCameraData" => {
            let view_vector = cx.output("View Vector", Vector)?;
            let z_depth = cx.output("View Z Depth", Float)?;
            let distance = cx.output("View Distance", Float)?;
            cx.emit(
                Op::Transform(TransformOp::Camera {
                    view_vector,
                    z_depth,
                    distance,
                }),
                true,
            );
        }
        "ShaderNodeTangent" => {
            let source = if cx.prop_str("direction_type") == Some("UV_MAP") {
                TangentSource::UvMap
            } else {
                TangentSource::Radial(match cx.prop_str("axis").unwrap_or("Z") {
                    "X" => 0,
                    "Y" => 1,
                    _ => 2,
                })
            };
            let out = cx.output("Tangent", Vector)?;
            cx.emit(Op::Transform(TransformOp::Tangent { source, out }), true);
        }
        _ => return Ok(false),
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::FRAC_PI_2;

    #[test]
    fn rotate_matches_blender_conventions() {
        let v = Vec3::new(1.0, 0.0, 0.5);
        let c = Vec3::new(0.0, 0.0, 0.5);
        // 90° about Z through c: +X goes to +Y (right-handed), the centre stays.
        let r = vector_rotate(
            RotateType::Z,
            false,
            v,
            c,
            Vec3::ZERO,
            FRAC_PI_2,
            Vec3::ZERO,
        );
        assert!((r - Vec3::new(0.0, 1.0, 0.5)).length() < 1e-6, "{r}");
        let back = vector_rotate(RotateType::Z, true, r, c, Vec3::ZERO, FRAC_PI_2, Vec3::ZERO);
        assert!((back - v).length() < 1e-6, "{back}");
        // An unnormalised axis is normalised; a zero axis leaves the vector alone.
        let a = vector_rotate(
            RotateType::AxisAngle,
            false,
            v,
            c,
            Vec3::new(0.0, 0.0, 7.0),
            FRAC_PI_2,
            Vec3::ZERO,
        );
        assert!((a - r).length() < 1e-6, "{a}");
        let z = vector_rotate(
            RotateType::AxisAngle,
            false,
            v,
            c,
            Vec3::ZERO,
            1.0,
            Vec3::ZERO,
        );
        assert_eq!(z, v);
        // Euler XYZ is the Mapping node's rotation; inverted, its transpose.
        let rot = Vec3::new(0.3, -0.8, 1.4);
        let e = vector_rotate(RotateType::EulerXyz, false, v, c, Vec3::ZERO, 0.0, rot);
        assert!((e - (euler_xyz(rot) * (v - c) + c)).length() < 1e-6);
        let ei = vector_rotate(RotateType::EulerXyz, true, e, c, Vec3::ZERO, 0.0, rot);
        assert!((ei - v).length() < 1e-5, "{ei}");
    }

    #[test]
    fn camera_space_looks_down_plus_z_and_round_trips() {
        // A camera at (0, -5, 1) looking along +Y (Blender: rotated 90° about X).
        let cam =
            Mat4::from_translation(Vec3::new(0.0, -5.0, 1.0)) * Mat4::from_rotation_x(FRAC_PI_2);
        let env = ShadeEnv {
            images: &[],
            textures: &[],
            camera_to_world: cam,
            window: &crate::camera::NO_WINDOW,
            tracer: None,
        };
        let g = ShaderGlobals::at(Vec3::ZERO, Vec3::Y, glam::Vec2::ZERO);
        let p = Vec3::new(0.0, 3.0, 1.0);
        let c = vector_transform(VectorKind::Point, Space::World, Space::Camera, p, &g, &env);
        assert!((c - Vec3::new(0.0, 0.0, 8.0)).length() < 1e-5, "{c}");
        let w = vector_transform(VectorKind::Point, Space::Camera, Space::World, c, &g, &env);
        assert!((w - p).length() < 1e-5, "{w}");
        // Directions ignore the translation; normals stay unit.
        let d = vector_transform(
            VectorKind::Vector,
            Space::World,
            Space::Camera,
            Vec3::Z,
            &g,
            &env,
        );
        assert!((d - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-5, "{d}");
        let n = vector_transform(
            VectorKind::Normal,
            Space::World,
            Space::Camera,
            Vec3::new(0.0, 3.0, 0.0),
            &g,
            &env,
        );
        assert!((n - Vec3::Z).length() < 1e-5, "{n}");
        // Off an object, object space is world space.
        let o = vector_transform(VectorKind::Point, Space::World, Space::Object, p, &g, &env);
        assert_eq!(o, p);
    }
}
