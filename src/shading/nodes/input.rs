//! Input nodes: what the shading point knows (Texture Coordinate, UV Map, Geometry, Object
//! Info, Light Path, Layer Weight, Fresnel, attributes) and constant Value/RGB nodes.

use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::{ShadeEnv, ShaderGlobals, from_blender, ray, to_blender};
use crate::shading::program::{Op, Slot, Slots};
use glam::{Mat3, Mat4, Vec2, Vec3};

/// The outputs of the Hair Info node that Tesela computes.
#[derive(Clone, Copy, Debug)]
pub enum HairOut {
    IsStrand,
    /// 0 at the root to 1 at the tip.
    Intercept,
    Length,
    /// The strand's diameter at the point, in world units.
    Thickness,
    /// Cycles' `hash_uint2_to_float(curve, 0)`.
    Random,
}

/// The outputs of the Point Info node (zero off point clouds, as in Cycles).
#[derive(Clone, Copy, Debug)]
pub enum PointOut {
    /// The point's centre, world space.
    Position,
    /// The radius in world units: `|M (r/√3)(1, 1, 1)|`, `M` the object's linear map.
    Radius,
    /// Cycles' `hash_uint2_to_float(index, 0)`.
    Random,
}

/// The outputs of the Particle Info node.
#[derive(Clone, Copy, Debug)]
pub enum ParticleOut {
    Index,
    /// Cycles' `hash_uint2_to_float(index, 0)`.
    Random,
    Age,
    Lifetime,
    Location,
    Size,
    Velocity,
    AngularVelocity,
}

/// Which value of the shading point an [`InputOp`] writes.
#[derive(Clone, Debug)]
pub enum Source {
    Generated,
    /// Object-space normal.
    ObjectNormal,
    /// A UV map by name (Blender convention), `""` = the first.
    Uv(String),
    /// UV set `n` in glTF's convention (the glTF preset graph's texture coordinates).
    GltfUv(usize),
    Object,
    /// The position in the space of another object: its world → object matrix (Blender's
    /// world), as Texture Coordinate's Object output with an object set.
    ObjectOf(Box<glam::Mat4>),
    Camera,
    Reflection,
    Position,
    Normal,
    TrueNormal,
    Incoming,
    Tangent,
    Parametric,
    Backfacing,
    ObjectLocation,
    ObjectColor,
    ObjectAlpha,
    ObjectIndex,
    ObjectRandom,
    /// A Hair Info output of a point on a strand (zero elsewhere; Is Strand 0).
    Hair(HairOut),
    Point(PointOut),
    /// A Particle Info output of the point's particle (Cycles' all-zero particle for an
    /// object no particle placed).
    Particle(ParticleOut),
    /// Light Path flag bit.
    RayFlag(u32),
    RayDepth,
    /// Light Path's Diffuse (0), Glossy (1), Transmission (2) or Transparent (3) Depth.
    KindDepth(u8),
    RayLength,
    /// Colour attribute by name: `(name, alpha?)`.
    Color(String, bool),
    /// A geometry attribute by name: a UV map (Blender convention) or a colour attribute.
    Attribute(String, AttrPart),
    /// The Attribute node's Object (`instancer` false) or Instancer type: the object's value
    /// of that name (zero when it has none).
    ObjectAttribute {
        name: String,
        instancer: bool,
        part: AttrPart,
    },
    /// Geometry > Random Per Island, from the face attribute [`ISLAND_ATTRIBUTE`].
    RandomPerIsland,
    /// Texture Coordinate > Window: the point's position in the camera frame.
    Window,
    /// Layer Weight (`fresnel` output or `facing`), blend slot, optional normal slot.
    LayerWeight {
        fresnel: bool,
        blend: Slot,
        normal: Option<Slot>,
    },
    /// Fresnel node: IOR slot, optional normal slot.
    Fresnel {
        ior: Slot,
        normal: Option<Slot>,
    },
}

/// Which part of an attribute the Attribute node's output carries.
/// The face attribute the add-on writes each face's island into (Random Per Island).
pub const ISLAND_ATTRIBUTE: &str = ".tesela.island";
/// The point attribute the add-on writes Cycles' Pointiness into.
pub const POINTINESS_ATTRIBUTE: &str = ".tesela.pointiness";

#[derive(Clone, Copy, Debug)]
pub enum AttrPart {
    Rgb,
    /// The first component (attributes the add-on derives, stored as `(v, v, v, 1)`).
    First,
    /// Cycles' Fac: the mean of the three components.
    Average,
    Alpha,
}

impl AttrPart {
    /// Writes this part of the RGBA value `v` to `out`.
    #[inline]
    fn write(self, s: &mut Slots, out: Slot, v: glam::Vec4) {
        match self {
            AttrPart::Rgb => s.set_v(out, v.truncate()),
            AttrPart::First => s.set_f(out, v.x),
            AttrPart::Average => s.set_f(out, (v.x + v.y + v.z) / 3.0),
            AttrPart::Alpha => s.set_f(out, v.w),
        }
    }
}

#[derive(Clone, Debug)]
pub struct InputOp {
    pub src: Source,
    pub out: Slot,
}

/// Dielectric Fresnel reflectance for cosine `cosi` and relative IOR `eta` (Cycles'
/// `fresnel_dielectric_cos`).
#[inline]
pub fn fresnel_dielectric_cos(cosi: f32, eta: f32) -> f32 {
    let c = cosi.abs();
    let g = eta * eta - 1.0 + c * c;
    if g > 0.0 {
        let g = g.sqrt();
        let a = (g - c) / (g + c);
        let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
        0.5 * a * a * (1.0 + b * b)
    } else {
        1.0
    }
}

/// Texture Coordinate > Normal: the world normal `n` (Blender coordinates) in object space as
/// Cycles computes it (`object_inverse_normal_transform`): `normalize(Mᵀ n)` for the object's
/// object-to-world matrix `M`, i.e. through the inverse transpose of `to_object` (world → object,
/// renderer world coordinates). With a non-uniform scale this differs from `M⁻¹ n`.
pub fn object_normal(to_object: &Mat4, n: Vec3) -> Vec3 {
    let m_t = Mat3::from_mat4(*to_object).inverse().transpose();
    unit_or(m_t * from_blender(n), n)
}

/// Texture Coordinate > Camera: the point in Cycles' camera space (x right, y up, **+z** along
/// the view direction, so points in front have z > 0), from Blender's camera-to-world matrix
/// (the camera looks down its local -Z).
pub fn camera_position(camera_to_world: &Mat4, p: Vec3) -> Vec3 {
    let c = camera_to_world.inverse().transform_point3(p);
    Vec3::new(c.x, c.y, -c.z)
}

fn unit_or(v: Vec3, fallback: Vec3) -> Vec3 {
    let l = v.length();
    if l > 1e-12 && l.is_finite() {
        v / l
    } else {
        fallback
    }
}

impl InputOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals, env: &ShadeEnv) {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let info = g.object_info();
        match &self.src {
            Source::Generated => s.set_v(self.out, g.generated()),
            Source::ObjectNormal => s.set_v(
                self.out,
                g.to_object().map_or(g.n, |m| object_normal(&m, g.n)),
            ),
            Source::Uv(name) => s.set_v(self.out, g.uv_named(name)),
            Source::GltfUv(set) => {
                let uv: Vec2 = g.uv_gltf(*set);
                s.set_v(self.out, uv.extend(0.0));
            }
            Source::Object => s.set_v(self.out, g.object_position()),
            Source::ObjectOf(m) => s.set_v(self.out, m.transform_point3(g.p)),
            Source::Camera => s.set_v(self.out, camera_position(&env.camera_to_world, g.p)),
            Source::Window => s.set_v(self.out, env.window.window(g.p)),
            Source::Reflection => s.set_v(self.out, 2.0 * g.n.dot(g.i) * g.n - g.i),
            Source::Position => s.set_v(self.out, g.p),
            Source::Normal => s.set_v(self.out, g.n),
            Source::TrueNormal => s.set_v(self.out, g.ng),
            Source::Incoming => s.set_v(self.out, g.i),
            Source::Tangent => s.set_v(self.out, g.tangent().map_or(Vec3::ZERO, |t| t.0)),
            Source::Parametric => s.set_v(self.out, Vec3::new(1.0 - g.b1 - g.b2, g.b1, 0.0)),
            Source::Backfacing => s.set_f(self.out, flag(g.backfacing)),
            Source::ObjectLocation => s.set_v(
                self.out,
                to_blender(info.map_or(Vec3::ZERO, |o| o.location)),
            ),
            Source::ObjectColor => {
                s.set_v(self.out, info.map_or(Vec3::ONE, |o| o.color.truncate()))
            }
            Source::ObjectAlpha => s.set_f(self.out, info.map_or(1.0, |o| o.color.w)),
            Source::ObjectIndex => s.set_f(self.out, info.map_or(0.0, |o| o.pass_index)),
            Source::ObjectRandom => s.set_f(self.out, info.map_or(0.0, |o| o.random)),
            Source::Hair(out) => {
                let info = g.color_attribute(crate::scene::curves::CURVE_LAYER);
                let v = info.unwrap_or(glam::Vec4::ZERO);
                let value = match out {
                    HairOut::IsStrand => flag(info.is_some()),
                    HairOut::Intercept => v.x,
                    HairOut::Length => v.y,
                    HairOut::Random => v.z,
                    HairOut::Thickness => {
                        // The object-space radius scaled to world units as Cycles scales it
                        // (the length of the object's x axis in the world).
                        let scale = g
                            .to_object()
                            .map_or(1.0, |m| 1.0 / m.x_axis.truncate().length().max(1e-12));
                        2.0 * v.w * scale
                    }
                };
                s.set_f(self.out, value);
            }
            Source::Point(out) => {
                use crate::scene::points::{POINT_LAYER, POINT_RANDOM_LAYER};
                let point = g.color_attribute(POINT_LAYER);
                let to_world = || g.to_object().map(|m| m.inverse()).filter(|m| m.is_finite());
                match (out, point) {
                    (PointOut::Position, Some(c)) => {
                        let m = to_world().unwrap_or(glam::Mat4::IDENTITY);
                        s.set_v(self.out, to_blender(m.transform_point3(c.truncate())));
                    }
                    (PointOut::Radius, Some(c)) => {
                        let m = to_world().unwrap_or(glam::Mat4::IDENTITY);
                        let d = Vec3::splat(c.w / 3f32.sqrt());
                        s.set_f(self.out, m.transform_vector3(d).length());
                    }
                    (PointOut::Random, Some(_)) => {
                        let r = g.color_attribute(POINT_RANDOM_LAYER).map_or(0.0, |v| v.x);
                        s.set_f(self.out, r);
                    }
                    (PointOut::Position, None) => s.set_v(self.out, Vec3::ZERO),
                    (_, None) => s.set_f(self.out, 0.0),
                }
            }
            Source::Particle(out) => {
                let none = crate::scene::Particle::default();
                let p = info.and_then(|o| o.particle.as_deref()).unwrap_or(&none);
                match out {
                    ParticleOut::Index => s.set_f(self.out, p.index as f32),
                    ParticleOut::Random => s.set_f(
                        self.out,
                        crate::shading::tex::hash::hash_uint2_to_float(p.index, 0),
                    ),
                    ParticleOut::Age => s.set_f(self.out, p.age),
                    ParticleOut::Lifetime => s.set_f(self.out, p.lifetime),
                    ParticleOut::Location => s.set_v(self.out, p.location),
                    ParticleOut::Size => s.set_f(self.out, p.size),
                    ParticleOut::Velocity => s.set_v(self.out, p.velocity),
                    ParticleOut::AngularVelocity => s.set_v(self.out, p.angular_velocity),
                }
            }
            Source::RayFlag(bit) => s.set_f(self.out, flag(g.ray_flags & bit != 0)),
            Source::RayDepth => s.set_f(self.out, g.ray_depth.saturating_sub(1) as f32),
            Source::KindDepth(kind) => {
                let d = &g.depths;
                let n = [d.diffuse, d.glossy, d.transmission, d.transparent][*kind as usize & 3];
                s.set_f(self.out, n as f32)
            }
            Source::RayLength => s.set_f(self.out, g.ray_length),
            Source::RandomPerIsland => {
                // The face's island (its representative vertex, in 16-bit halves), hashed as
                // Cycles does; 0 without the attribute, as Cycles reads a missing one.
                let v = match g.color_attribute(ISLAND_ATTRIBUTE) {
                    Some(c) => {
                        // Rounded: interpolation over the face may move it off the integer.
                        let half = |v: f32| (v.round().clamp(0.0, 65535.0)) as u32;
                        let id = half(c.x) | (half(c.y) << 16);
                        crate::shading::tex::hash::hash_uint_to_float(id)
                    }
                    None => 0.0,
                };
                s.set_f(self.out, v);
            }
            Source::Color(name, alpha) => {
                let c = g.color_attribute(name).unwrap_or(glam::Vec4::ZERO);
                if *alpha {
                    s.set_f(self.out, c.w);
                } else {
                    s.set_v(self.out, c.truncate());
                }
            }
            Source::Attribute(name, part) => {
                let is_uv = g
                    .mesh
                    .is_some_and(|m| m.attrs.uv_names.iter().any(|n| n == name));
                let v = if is_uv {
                    g.uv_named(name).extend(1.0)
                } else {
                    g.color_attribute(name).unwrap_or(glam::Vec4::ZERO)
                };
                part.write(s, self.out, v);
            }
            Source::ObjectAttribute {
                name,
                instancer,
                part,
            } => {
                let v = info
                    .and_then(|o| o.attributes.as_deref())
                    .and_then(|a| a.get(name, *instancer))
                    .unwrap_or(glam::Vec4::ZERO);
                part.write(s, self.out, v);
            }
            Source::LayerWeight {
                fresnel,
                blend,
                normal,
            } => {
                let n = normal.map_or(g.n, |n| unit_or(s.v(n), g.n));
                let b = s.f(*blend);
                let cos = g.i.dot(n);
                let f = if *fresnel {
                    let eta = (1.0 - b).max(1e-5);
                    let eta = if g.backfacing { eta } else { 1.0 / eta };
                    fresnel_dielectric_cos(cos, eta)
                } else {
                    let b = b.clamp(0.0, 1.0 - 1e-5);
                    let mut f = cos.abs();
                    if b != 0.5 {
                        let e = if b < 0.5 { 2.0 * b } else { 0.5 / (1.0 - b) };
                        f = f.powf(e);
                    }
                    1.0 - f
                };
                s.set_f(self.out, f);
            }
            Source::Fresnel { ior, normal } => {
                let n = normal.map_or(g.n, |n| unit_or(s.v(n), g.n));
                let eta = s.f(*ior).max(1e-5);
                let eta = if g.backfacing { 1.0 / eta } else { eta };
                s.set_f(self.out, fresnel_dielectric_cos(g.i.dot(n), eta));
            }
        }
    }
}

fn emit(cx: &mut NodeCx, id: &str, ty: SocketType, src: Source) -> Result<(), CompileError> {
    let out = cx.output(id, ty)?;
    cx.emit(Op::Input(InputOp { src, out }), true);
    Ok(())
}

/// The world → object matrix of an object whose `matrix_world` is `rows` (4 rows of 4, Blender
/// world), if it is one and invertible.
fn object_matrix(rows: &serde_json::Value) -> Option<glam::Mat4> {
    let rows = rows.as_array().filter(|r| r.len() == 4)?;
    let mut m = [[0.0f32; 4]; 4];
    for (i, row) in rows.iter().enumerate() {
        let row = row.as_array().filter(|r| r.len() == 4)?;
        for (j, v) in row.iter().enumerate() {
            // Column j, row i.
            m[j][i] = v.as_f64()? as f32;
        }
    }
    let m = glam::Mat4::from_cols_array_2d(&m);
    let det = m.determinant();
    (det.is_finite() && det.abs() > 1e-30).then(|| m.inverse())
}

/// Compiles input nodes; `Ok(false)` for other kinds.
pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    use SocketType::{Color, Float, Vector};
    match kind {
        "ShaderNodeTexCoord" => {
            let other = match cx.prop("object") {
                None | Some(serde_json::Value::Null) => None,
                Some(v) => {
                    let m = object_matrix(v);
                    if m.is_none() {
                        cx.warn("its object's matrix cannot be inverted (or is not a 4x4 matrix); the material's own object coordinates are used");
                    }
                    m
                }
            };
            emit(cx, "Generated", Vector, Source::Generated)?;
            emit(cx, "Normal", Vector, Source::ObjectNormal)?;
            emit(cx, "UV", Vector, Source::Uv(String::new()))?;
            match other {
                Some(m) => emit(cx, "Object", Vector, Source::ObjectOf(Box::new(m)))?,
                None => emit(cx, "Object", Vector, Source::Object)?,
            }
            emit(cx, "Camera", Vector, Source::Camera)?;
            emit(cx, "Reflection", Vector, Source::Reflection)?;
            emit(cx, "Window", Vector, Source::Window)?;
        }
        "TeselaGltfUv" => {
            let set = cx.prop_f32("set", 0.0).max(0.0) as usize;
            emit(cx, "UV", Vector, Source::GltfUv(set))?;
        }
        "ShaderNodeUVMap" => {
            if cx.prop_bool("from_instancer", false) {
                cx.warn("UVs from the instancer are not supported; the mesh's own are used");
            }
            let name = cx.prop_str("uv_map").unwrap_or("").to_string();
            emit(cx, "UV", Vector, Source::Uv(name))?;
        }
        "ShaderNodeNewGeometry" => {
            emit(cx, "Position", Vector, Source::Position)?;
            emit(cx, "Normal", Vector, Source::Normal)?;
            emit(cx, "Tangent", Vector, Source::Tangent)?;
            emit(cx, "True Normal", Vector, Source::TrueNormal)?;
            emit(cx, "Incoming", Vector, Source::Incoming)?;
            emit(cx, "Parametric", Vector, Source::Parametric)?;
            emit(cx, "Backfacing", Float, Source::Backfacing)?;
            emit(cx, "Random Per Island", Float, Source::RandomPerIsland)?;
            emit(
                cx,
                "Pointiness",
                Float,
                Source::Attribute(POINTINESS_ATTRIBUTE.to_string(), AttrPart::First),
            )?;
        }
        "ShaderNodeObjectInfo" => {
            emit(cx, "Location", Vector, Source::ObjectLocation)?;
            emit(cx, "Color", Color, Source::ObjectColor)?;
            emit(cx, "Alpha", Float, Source::ObjectAlpha)?;
            emit(cx, "Object Index", Float, Source::ObjectIndex)?;
            emit(cx, "Random", Float, Source::ObjectRandom)?;
            // The material's Pass Index, which the exporter gives the node.
            let index = cx.prop_f32("material_pass_index", 0.0);
            let index = cx.constant(&[index])?;
            cx.alias("Material Index", index, Float);
        }
        "ShaderNodePointInfo" => {
            emit(cx, "Position", Vector, Source::Point(PointOut::Position))?;
            emit(cx, "Radius", Float, Source::Point(PointOut::Radius))?;
            emit(cx, "Random", Float, Source::Point(PointOut::Random))?;
        }
        "ShaderNodeHairInfo" => {
            use HairOut as H;
            for (id, out) in [
                ("Is Strand", H::IsStrand),
                ("Intercept", H::Intercept),
                ("Length", H::Length),
                ("Thickness", H::Thickness),
                ("Random", H::Random),
            ] {
                emit(cx, id, Float, Source::Hair(out))?;
            }
            // Tangent Normal is not computed: the compiler reports it where it is used.
        }
        "ShaderNodeParticleInfo" => {
            use ParticleOut as P;
            for (id, ty, out) in [
                ("Index", Float, P::Index),
                ("Random", Float, P::Random),
                ("Age", Float, P::Age),
                ("Lifetime", Float, P::Lifetime),
                ("Location", Vector, P::Location),
                ("Size", Float, P::Size),
                ("Velocity", Vector, P::Velocity),
                ("Angular Velocity", Vector, P::AngularVelocity),
            ] {
                emit(cx, id, ty, Source::Particle(out))?;
            }
        }
        "ShaderNodeLightPath" => {
            for (id, bit) in [
                ("Is Camera Ray", ray::CAMERA),
                ("Is Shadow Ray", ray::SHADOW),
                ("Is Diffuse Ray", ray::DIFFUSE),
                ("Is Glossy Ray", ray::GLOSSY),
                ("Is Singular Ray", ray::SINGULAR),
                ("Is Reflection Ray", ray::REFLECTION),
                ("Is Transmission Ray", ray::TRANSMISSION),
                ("Is Volume Scatter Ray", ray::VOLUME),
            ] {
                emit(cx, id, Float, Source::RayFlag(bit))?;
            }
            emit(cx, "Ray Depth", Float, Source::RayDepth)?;
            emit(cx, "Ray Length", Float, Source::RayLength)?;
            for (id, kind) in [
                ("Diffuse Depth", 0),
                ("Glossy Depth", 1),
                ("Transmission Depth", 2),
                ("Transparent Depth", 3),
            ] {
                emit(cx, id, Float, Source::KindDepth(kind))?;
            }
            // Portals guide only Cycles' world sampling; no path passes one here.
            let zero = cx.constant(&[0.0])?;
            cx.alias("Portal Depth", zero, Float);
        }
        "ShaderNodeVertexColor" => {
            let name = cx.prop_str("layer_name").unwrap_or("").to_string();
            emit(cx, "Color", Color, Source::Color(name.clone(), false))?;
            emit(cx, "Alpha", Float, Source::Color(name, true))?;
        }
        "ShaderNodeAttribute" => {
            let name = cx.prop_str("attribute_name").unwrap_or("").to_string();
            let ty = cx
                .prop_str("attribute_type")
                .unwrap_or("GEOMETRY")
                .to_string();
            if ty == "VIEW_LAYER" {
                // One value for the whole render, which the add-on resolves (view layer,
                // scene, world); zero when none has it.
                let v = cx
                    .prop("value")
                    .and_then(|v| v.as_array())
                    .map(|a| {
                        let mut c = [0.0f32; 4];
                        for (o, x) in c.iter_mut().zip(a) {
                            *o = x.as_f64().unwrap_or(0.0) as f32;
                        }
                        c
                    })
                    .filter(|c| c.iter().all(|x| x.is_finite()))
                    .unwrap_or([0.0; 4]);
                let rgb = cx.constant(&v[..3])?;
                cx.alias("Color", rgb, Color);
                cx.alias("Vector", rgb, Vector);
                let fac = cx.constant(&[(v[0] + v[1] + v[2]) / 3.0])?;
                cx.alias("Fac", fac, Float);
                let alpha = cx.constant(&[v[3]])?;
                cx.alias("Alpha", alpha, Float);
                return Ok(true);
            }
            let per_object = match ty.as_str() {
                "OBJECT" => Some(false),
                "INSTANCER" => Some(true),
                _ => None,
            };
            for (id, t, part) in [
                ("Color", Color, AttrPart::Rgb),
                ("Vector", Vector, AttrPart::Rgb),
                ("Fac", Float, AttrPart::Average),
                ("Alpha", Float, AttrPart::Alpha),
            ] {
                let src = match per_object {
                    Some(instancer) => Source::ObjectAttribute {
                        name: name.clone(),
                        instancer,
                        part,
                    },
                    None => Source::Attribute(name.clone(), part),
                };
                emit(cx, id, t, src)?;
            }
        }
        "ShaderNodeLayerWeight" => {
            let blend = cx.float("Blend", 0.5)?;
            let normal = cx.linked_vector("Normal")?;
            for (id, fresnel) in [("Fresnel", true), ("Facing", false)] {
                emit(
                    cx,
                    id,
                    Float,
                    Source::LayerWeight {
                        fresnel,
                        blend,
                        normal,
                    },
                )?;
            }
        }
        "ShaderNodeFresnel" => {
            let ior = cx.float("IOR", 1.5)?;
            let normal = cx.linked_vector("Normal")?;
            emit(cx, "Fac", Float, Source::Fresnel { ior, normal })?;
        }
        "ShaderNodeValue" => {
            let v = cx.prop_f32("value", 0.5);
            let s = cx.constant(&[v])?;
            cx.alias("Value", s, Float);
        }
        "ShaderNodeRGB" => {
            let v: Vec<f32> = cx
                .prop("value")
                .and_then(|v| v.as_array())
                .map(|a| {
                    a.iter()
                        .filter_map(|x| x.as_f64())
                        .map(|x| x as f32)
                        .collect()
                })
                .unwrap_or_else(|| vec![0.5, 0.5, 0.5]);
            let c = [
                v.first().copied().unwrap_or(0.5),
                v.get(1).copied().unwrap_or(0.5),
                v.get(2).copied().unwrap_or(0.5),
            ];
            let s = cx.constant(&c)?;
            cx.alias("Color", s, Color);
        }
        _ => return Ok(false),
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    #[test]
    fn object_normal_uses_the_inverse_transpose() {
        // An object scaled (2, 1, 1) (Blender object space → renderer world: the scale, then
        // Blender's Z-up axes to the renderer's Y-up ones): a world normal at 45° in Blender's
        // XY is, in object space, normalize(Mᵀ n) ∝ (2, 1, 0), not M⁻¹ n ∝ (0.5, 1, 0).
        let axes = Mat4::from_cols(Vec4::X, -Vec4::Z, Vec4::Y, Vec4::W); // = from_blender
        let object_to_world = axes * Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0));
        let to_object = object_to_world.inverse();
        let n = Vec3::new(1.0, 1.0, 0.0).normalize(); // Blender world: X and Y
        let got = object_normal(&to_object, n);
        let want = Vec3::new(2.0, 1.0, 0.0).normalize();
        assert!((got - want).length() < 1e-6, "{got:?} != {want:?}");
    }

    #[test]
    fn camera_space_looks_down_plus_z() {
        // A camera at Blender (0, 0, 5) looking down -Z (identity rotation): the origin lies 5 in
        // front of it, at camera z = +5 as in Cycles; x and y keep their directions.
        let cam = Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0));
        let c = camera_position(&cam, Vec3::new(0.25, -0.5, 0.0));
        assert!((c - Vec3::new(0.25, -0.5, 5.0)).length() < 1e-6, "{c:?}");
    }
}
