//! Mesh primitives: attributes (POSITION, NORMAL, TEXCOORD_n, COLOR_n, TANGENT, as far as the
//! material reads them), morph targets, triangulation, MikkTSpace tangents, flattening to world
//! space, and the per-object data shading reads (object space, texture space, Object Info).

use std::rc::Rc;

use ::gltf::json;
use glam::{Mat4, Vec2, Vec3};
use json::accessor::Type;
use json::mesh::{Mode, Semantic};
use json::validation::Checked;
use serde_json::Value;

use super::accessor::{Comp, Values, decode_f32};
use super::{
    LoadError, LoadErrorKind, Loader, LocalPrim, MAX_TRIANGLES, MAX_VERTICES, invalid, member,
};
use crate::scene::{Material, Mesh, MeshAttributes, ObjectInfo, TexRef};
use crate::shading::globals::from_blender;

fn mode_name(m: Mode) -> &'static str {
    match m {
        Mode::Points => "POINTS",
        Mode::Lines => "LINES",
        Mode::LineLoop => "LINE_LOOP",
        Mode::LineStrip => "LINE_STRIP",
        Mode::Triangles => "TRIANGLES",
        Mode::TriangleStrip => "TRIANGLE_STRIP",
        Mode::TriangleFan => "TRIANGLE_FAN",
    }
}

/// Turns an index list into triangles (counter-clockwise as in the file).
pub(crate) fn triangulate(mode: Mode, idx: &[u32]) -> Vec<[u32; 3]> {
    let n = idx.len();
    match mode {
        Mode::Triangles => idx.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .map(|i| {
                if i % 2 == 0 {
                    [idx[i], idx[i + 1], idx[i + 2]]
                } else {
                    [idx[i + 1], idx[i], idx[i + 2]]
                }
            })
            .collect(),
        Mode::TriangleFan => (1..n.saturating_sub(1))
            .map(|i| [idx[i], idx[i + 1], idx[0]])
            .collect(),
        _ => Vec::new(),
    }
}

/// World-space positions, normals (possibly empty) and triangles.
pub(crate) type WorldPrim = (Vec<Vec3>, Vec<Vec3>, Vec<[u32; 3]>);

/// Transforms local primitive data to world space. A negative determinant reverses the
/// winding so that front faces stay front. Normals go through the inverse transpose; if
/// any is zero or not finite, the primitive's normals are dropped.
pub(crate) fn to_world(local: &LocalPrim, m: Mat4) -> Option<WorldPrim> {
    let positions: Vec<Vec3> = local
        .positions
        .iter()
        .map(|&p| m.transform_point3(p))
        .collect();
    if positions.iter().any(|p| !p.is_finite()) {
        return None;
    }
    let mut normals = Vec::new();
    if !local.normals.is_empty()
        && let Some(nm) = super::normal_matrix(m)
    {
        normals.reserve(local.normals.len());
        for &n in &local.normals {
            match (nm * n).try_normalize() {
                Some(n) => normals.push(n),
                None => {
                    normals.clear();
                    break;
                }
            }
        }
    }
    let flip = glam::Mat3::from_mat4(m).determinant() < 0.0;
    let tris = if flip {
        local.tris.iter().map(|t| [t[0], t[2], t[1]]).collect()
    } else {
        local.tris.clone()
    };
    Some((positions, normals, tris))
}

/// What of a primitive's optional attributes its material reads (only that is stored).
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub(crate) struct Needs {
    /// Every UV and colour set and the file's TANGENT: node graphs read them by name.
    all: bool,
    /// TEXCOORD sets the material's textures read.
    uv_sets: Vec<u32>,
    /// COLOR_0 multiplies the base colour.
    color0: bool,
    /// Tangents for this UV set: the file's TANGENT, else MikkTSpace.
    tangent_set: Option<u32>,
}

impl Needs {
    fn uv(&self, k: u32) -> bool {
        self.all || self.uv_sets.contains(&k)
    }
}

/// The textures of a material with their slot names (for messages).
pub(crate) fn texture_slots(m: &Material) -> Vec<(&'static str, TexRef)> {
    let mut v = Vec::new();
    let mut add = |slot: &'static str, t: &Option<TexRef>| {
        if let Some(t) = t {
            v.push((slot, *t));
        }
    };
    add("baseColorTexture", &m.base_color_texture);
    add("metallicRoughnessTexture", &m.metallic_roughness_texture);
    add("normalTexture", &m.normal_texture);
    add("emissiveTexture", &m.emission_texture);
    add("transmissionTexture", &m.transmission_texture);
    add("specularTexture", &m.specular_texture);
    add("specularColorTexture", &m.specular_color_texture);
    add("specularGlossinessTexture", &m.glossiness_texture);
    if let Some(c) = &m.clearcoat {
        add("clearcoatTexture", &c.texture);
        add("clearcoatRoughnessTexture", &c.roughness_texture);
        add("clearcoatNormalTexture", &c.normal_texture);
    }
    if let Some(s) = &m.sheen {
        add("sheenColorTexture", &s.color_texture);
        add("sheenRoughnessTexture", &s.roughness_texture);
    }
    if let Some(a) = &m.anisotropy {
        add("anisotropyTexture", &a.texture);
    }
    v
}

pub(crate) fn needs(m: &Material) -> Needs {
    if m.graph.is_some() {
        return Needs {
            all: true,
            ..Default::default()
        };
    }
    let slots = texture_slots(m);
    let mut uv_sets: Vec<u32> = slots.iter().map(|(_, t)| t.texcoord).collect();
    uv_sets.sort_unstable();
    uv_sets.dedup();
    let coat_normal = m.clearcoat.as_ref().and_then(|c| c.normal_texture);
    let aniso = m.anisotropy.as_ref().filter(|a| a.strength > 0.0);
    let tangent_set = m
        .normal_texture
        .or(coat_normal)
        .or(aniso.and_then(|a| a.texture))
        .map(|t| t.texcoord)
        .or(aniso.map(|_| 0));
    Needs {
        all: false,
        uv_sets,
        color0: m.vertex_color,
        tangent_set,
    }
}

/// Blender's automatic texture space of local bounds `(lo, hi)`: centre and half extents, a
/// zero extent taken as 1 and tiny ones raised to 1e-5 (`BKE_mesh_texspace_calc`).
pub(crate) fn auto_texspace(lo: Vec3, hi: Vec3) -> (Vec3, Vec3) {
    let loc = (lo + hi) * 0.5;
    let size = ((hi - lo) * 0.5).to_array().map(|s| {
        if s == 0.0 {
            1.0
        } else if s.abs() < 1e-5 {
            1e-5f32.copysign(s)
        } else {
            s
        }
    });
    (loc, Vec3::from_array(size))
}

/// `v` as `[f32; N]` of finite numbers.
/// How a primitive is placed in the scene ([`Loader::push_world_mesh`]).
pub(crate) struct PlacedPrim {
    /// Names the primitive in messages.
    pub what: String,
    pub name: String,
    pub material: usize,
    /// Local to world.
    pub world: Mat4,
    /// World to object (Blender's object coordinates).
    pub to_object: Mat4,
    pub texspace: Option<(Vec3, Vec3)>,
    pub object: ObjectInfo,
}

/// World → object for a node placed by `world`: its inverse, or the identity where `world` is
/// singular.
pub(crate) fn object_from_world(world: Mat4) -> Mat4 {
    Some(world.inverse())
        .filter(|m| m.is_finite())
        .unwrap_or(Mat4::IDENTITY)
}

fn floats<const N: usize>(v: Option<&Value>) -> Option<[f32; N]> {
    let a = v?.as_array().filter(|a| a.len() == N)?;
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = x.as_f64().map(|x| x as f32).filter(|x| x.is_finite())?;
    }
    Some(out)
}

/// Names from a primitive's `extras` list `key` (one per set; non-strings are `None`).
fn extra_names(extras: Option<&Value>, key: &str) -> Vec<Option<String>> {
    extras
        .and_then(|e| member(e, key))
        .and_then(Value::as_array)
        .map(|a| a.iter().map(|n| n.as_str().map(str::to_string)).collect())
        .unwrap_or_default()
}

/// Blender's default name of set `k` of a kind (`UVMap`, `UVMap.001`, ...).
fn default_name(base: &str, k: usize) -> String {
    if k == 0 {
        base.to_string()
    } else {
        format!("{base}.{k:03}")
    }
}

impl<'a> Loader<'a> {
    /// Bakes mesh `mi` of node `ni` into world space by `world`; with `object_space`, stores it
    /// in its own space instead (identity `world`, for instances to place). Returns the range
    /// of [`crate::scene::Scene::meshes`] its primitives became and, for each of those, the
    /// index of the primitive it came from.
    pub(crate) fn instance_mesh(
        &mut self,
        ni: usize,
        mi: usize,
        world: Mat4,
        object_space: bool,
        skin: Option<&super::skin::Skinning>,
    ) -> Result<(std::ops::Range<usize>, Vec<usize>), LoadError> {
        let first = self.scene.meshes.len();
        let root = self.root;
        let mesh = root.meshes.get(mi).ok_or_else(|| {
            invalid(format!(
                "node {ni}: mesh {mi} does not exist (the file has {})",
                root.meshes.len()
            ))
        })?;
        let node = &root.nodes[ni];
        let weights: Option<&[f32]> = node.weights.as_deref().or(mesh.weights.as_deref());
        let cacheable = node.weights.is_none() && skin.is_none();
        let base_name = mesh
            .name
            .clone()
            .or_else(|| node.name.clone())
            .unwrap_or_else(|| format!("mesh{mi}"));
        let mut prims: Vec<(usize, Rc<LocalPrim>, usize)> = Vec::new();
        for (pi, prim) in mesh.primitives.iter().enumerate() {
            let has = |s: Semantic| prim.attributes.contains_key(&Checked::Valid(s));
            let material = self.primitive_material(prim)?;
            let needs = material
                .map(|m| needs(&self.scene.materials[m]))
                .unwrap_or_default();
            let local = if cacheable {
                if let Some(c) = self.prim_cache.get(&(mi, pi)) {
                    c.clone()
                } else {
                    let l = self
                        .local_prim(mi, pi, prim, weights, skin, &needs)?
                        .map(Rc::new);
                    self.prim_cache.insert((mi, pi), l.clone());
                    l
                }
            } else {
                self.local_prim(mi, pi, prim, weights, skin, &needs)?
                    .map(Rc::new)
            };
            let (Some(local), Some(material)) = (local, material) else {
                continue;
            };
            if local.tris.is_empty() {
                continue;
            }
            for (slot, t) in texture_slots(&self.scene.materials[material]) {
                let k = t.texcoord;
                if !has(Semantic::TexCoords(k)) {
                    let fallback = if k > 0 && has(Semantic::TexCoords(0)) {
                        "TEXCOORD_0 is used instead"
                    } else {
                        "it reads UV (0, 0)"
                    };
                    let mname = self.scene.materials[material].name.clone();
                    self.warn_once(format!(
                        "material `{mname}` {slot} reads TEXCOORD_{k}, which mesh {mi} primitive {pi} does not have; {fallback}"
                    ));
                }
            }
            prims.push((pi, local, material));
        }
        if prims.is_empty() {
            return Ok((first..first, Vec::new()));
        }
        let kept = prims.iter().map(|(pi, _, _)| *pi).collect();
        // Per-object data: the node's extras (written by the add-on) or what the file implies.
        let extras = member(self.raw_item("nodes", ni), "extras");
        let texspace = match extras.and_then(|e| member(e, "tesela_texspace")) {
            Some(t) => match (
                floats::<3>(member(t, "location")),
                floats::<3>(member(t, "size")),
            ) {
                (Some(l), Some(s)) => Some((Vec3::from_array(l), Vec3::from_array(s))),
                _ => {
                    self.warn_once(format!(
                        "node {ni}: extras.tesela_texspace is not {{location: [x, y, z], size: [x, y, z]}}; the mesh bounds are used"
                    ));
                    None
                }
            },
            None => None,
        };
        let texspace = texspace.or_else(|| {
            let mut lo = Vec3::splat(f32::INFINITY);
            let mut hi = Vec3::splat(f32::NEG_INFINITY);
            for (_, l, _) in &prims {
                for &p in &l.positions {
                    lo = lo.min(p);
                    hi = hi.max(p);
                }
            }
            (lo.cmple(hi).all()).then(|| auto_texspace(lo, hi))
        });
        let object = if object_space {
            ObjectInfo::default()
        } else {
            self.object_info(ni, extras, world)
        };
        let to_object = object_from_world(world);
        let single = mesh.primitives.len() == 1;
        for (pi, local, material) in prims {
            let name = if single {
                base_name.clone()
            } else {
                format!("{base_name}.{pi}")
            };
            let placed = PlacedPrim {
                what: format!("mesh {mi} primitive {pi} on node {ni}"),
                name,
                material,
                world,
                to_object,
                texspace,
                object: object.clone(),
            };
            self.push_world_mesh(&local, placed)?;
        }
        Ok((first..self.scene.meshes.len(), kept))
    }

    /// Adds a mesh the loader built for node `ni` from one of its extensions (strand tubes,
    /// point spheres) as [`Self::push_world_mesh`] does, its Generated coordinates spanning
    /// its bounds unless `placed` gives a texture space, and records the node it came from.
    pub(crate) fn push_built_mesh(
        &mut self,
        ni: usize,
        local: &LocalPrim,
        mut placed: PlacedPrim,
    ) -> Result<(), LoadError> {
        if placed.texspace.is_none() {
            let (lo, hi) = local.positions.iter().fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(l, h), p| (l.min(*p), h.max(*p)),
            );
            placed.texspace = Some(auto_texspace(lo, hi));
        }
        let first = self.scene.meshes.len();
        self.push_world_mesh(local, placed)?;
        let origins = &mut self.origins.mesh_node;
        origins.resize(first, None);
        origins.resize(first + 1, Some(ni));
        Ok(())
    }

    /// Adds primitive `local` to the scene as a world-space mesh placed as `placed` says,
    /// counting it against the scene's limits.
    pub(crate) fn push_world_mesh(
        &mut self,
        local: &LocalPrim,
        placed: PlacedPrim,
    ) -> Result<(), LoadError> {
        let PlacedPrim {
            what,
            name,
            material,
            world,
            to_object,
            texspace,
            object,
        } = placed;
        let (positions, normals, indices) = to_world(local, world)
            .ok_or_else(|| invalid(format!("{what}: positions are not finite in world space")))?;
        if let Some((i, p)) = positions
            .iter()
            .enumerate()
            .find(|(_, p)| p.abs().max_element() > crate::accel::MAX_COORD)
        {
            return Err(invalid(format!(
                "{what}: vertex {i} at {p} in world space is farther than {:e} m from the origin (the renderer's coordinate limit)",
                crate::accel::MAX_COORD
            )));
        }
        self.tri_total = self.tri_total.saturating_add(indices.len());
        self.vert_total = self.vert_total.saturating_add(positions.len());
        if self.tri_total > MAX_TRIANGLES || self.vert_total > MAX_VERTICES {
            return Err(LoadError::new(
                LoadErrorKind::TooLarge,
                format!(
                    "the scene exceeds the limit of {MAX_TRIANGLES} triangles / {MAX_VERTICES} vertices (at {what})"
                ),
            ));
        }
        let mut colors = local.colors.clone();
        let orco = match colors
            .iter()
            .position(|(n, _)| n == crate::scene::ORCO_LAYER)
        {
            Some(i) => colors.remove(i).1.iter().map(|c| c.truncate()).collect(),
            None => Vec::new(),
        };
        let attrs = MeshAttributes {
            uv_names: local.uv_names.clone(),
            extra_uvs: local.extra_uvs.clone(),
            colors,
            tangents: super::tangents::to_world(&local.tangents, world),
            to_object,
            texspace,
            orco,
            object,
        };
        self.scene.meshes.push(Mesh {
            name,
            positions,
            normals,
            uvs: local.uvs.clone(),
            indices,
            material,
            attrs,
        });
        Ok(())
    }

    /// The scene material of a primitive that renders (triangles with positions), else `None`.
    pub(crate) fn primitive_material(
        &mut self,
        prim: &json::mesh::Primitive,
    ) -> Result<Option<usize>, LoadError> {
        let has = |s: Semantic| prim.attributes.contains_key(&Checked::Valid(s));
        let renders = matches!(
            prim.mode,
            Checked::Valid(Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan)
        ) && has(Semantic::Positions);
        if !renders {
            return Ok(None);
        }
        let vc = has(Semantic::Colors(0));
        self.material(prim.material.map(|m| m.value()), vc)
            .map(Some)
    }

    /// Object Info data of node `ni`: `extras.tesela_object` (Blender's world coordinates),
    /// else defaults with the node's origin as the location.
    pub(crate) fn object_info(
        &mut self,
        ni: usize,
        extras: Option<&Value>,
        world: Mat4,
    ) -> ObjectInfo {
        let mut info = ObjectInfo {
            location: world.w_axis.truncate(),
            links: self.links_of(ni),
            ..Default::default()
        };
        let Some(o) = extras.and_then(|e| member(e, "tesela_object")) else {
            return info;
        };
        let mut bad = Vec::new();
        match member(o, "random").map(|v| v.as_f64().map(|x| x as f32)) {
            None => {}
            Some(Some(r)) if r.is_finite() => info.random = r,
            Some(_) => bad.push("random"),
        }
        match member(o, "pass_index").map(|v| v.as_f64().map(|x| x as f32)) {
            None => {}
            Some(Some(p)) if p.is_finite() => info.pass_index = p,
            Some(_) => bad.push("pass_index"),
        }
        match member(o, "color") {
            None => {}
            Some(c) => match floats::<4>(Some(c))
                .or_else(|| floats::<3>(Some(c)).map(|[r, g, b]| [r, g, b, 1.0]))
            {
                Some(c) => info.color = glam::Vec4::from_array(c),
                None => bad.push("color"),
            },
        }
        match member(o, "location") {
            None => {}
            Some(l) => match floats::<3>(Some(l)) {
                Some(l) => info.location = from_blender(Vec3::from_array(l)),
                None => bad.push("location"),
            },
        }
        match member(o, "visibility") {
            None => {}
            Some(v) => match visibility_bits(v) {
                Some(bits) => info.visibility = bits,
                None => bad.push("visibility"),
            },
        }
        match member(o, "holdout").map(|v| v.as_bool()) {
            None => {}
            Some(Some(h)) => info.holdout = h,
            Some(None) => bad.push("holdout"),
        }
        match member(o, "particle") {
            None => {}
            Some(p) => match particle(p) {
                Some(p) => info.particle = Some(Box::new(p)),
                None => bad.push("particle"),
            },
        }
        match member(o, "attributes") {
            None => {}
            Some(a) => match object_attributes(a) {
                Some(a) => info.attributes = Some(Box::new(a)),
                None => bad.push("attributes"),
            },
        }
        match member(o, "shadow_catcher").map(|v| v.as_bool()) {
            None => {}
            Some(Some(c)) => info.shadow_catcher = c,
            Some(None) => bad.push("shadow_catcher"),
        }
        if !bad.is_empty() {
            self.warn_once(format!(
                "node {ni}: extras.tesela_object has an invalid {}; defaults are used for it",
                bad.join(", ")
            ));
        }
        info
    }

    /// A float attribute of `count` elements of type `ty` (count checked).
    fn attribute(
        &self,
        ai: usize,
        what: &str,
        ty: Type,
        count: usize,
    ) -> Result<Values<f32>, LoadError> {
        let v = self.reader.read_f32(ai, what, ty)?;
        if v.count != count {
            return Err(invalid(format!(
                "accessor {ai} ({what}): count {} differs from POSITION's {count}",
                v.count
            )));
        }
        Ok(v)
    }

    /// COLOR_n: VEC3 or VEC4 of FLOAT or normalized UNSIGNED_BYTE/UNSIGNED_SHORT, as linear
    /// RGBA (alpha 1 for VEC3). Non-finite components read as 0, with a warning.
    fn color_attribute(
        &mut self,
        ai: usize,
        what: &str,
        count: usize,
    ) -> Result<Vec<glam::Vec4>, LoadError> {
        let (acc, comp, ty) = self.reader.describe(ai, what)?;
        let width = match ty {
            Type::Vec3 => 3,
            Type::Vec4 => 4,
            other => {
                return Err(invalid(format!(
                    "accessor {ai} ({what}): type {} where VEC3 or VEC4 is expected",
                    super::accessor::type_name(other)
                )));
            }
        };
        match comp {
            Comp::F32 => {}
            Comp::U8 | Comp::U16 => {
                if !acc.normalized {
                    self.warn_once(format!(
                        "accessor {ai} ({what}): integer colours must be normalized; read as normalized"
                    ));
                }
            }
            _ => {
                return Err(invalid(format!(
                    "accessor {ai} ({what}): componentType must be FLOAT, UNSIGNED_BYTE or UNSIGNED_SHORT"
                )));
            }
        }
        let v = self
            .reader
            .read(ai, what, &|b, c, _| decode_f32(b, c, c != Comp::F32))?;
        if v.count != count {
            return Err(invalid(format!(
                "accessor {ai} ({what}): count {} differs from POSITION's {count}",
                v.count
            )));
        }
        let mut bad = 0usize;
        let out = v
            .data
            .chunks_exact(width)
            .map(|c| {
                let mut px = [0.0, 0.0, 0.0, 1.0];
                for (o, &x) in px.iter_mut().zip(c) {
                    if x.is_finite() {
                        *o = x;
                    } else {
                        *o = 0.0;
                        bad += 1;
                    }
                }
                glam::Vec4::from_array(px)
            })
            .collect();
        if bad > 0 {
            self.warn_once(format!(
                "accessor {ai} ({what}): {bad} components are not finite and read as 0"
            ));
        }
        Ok(out)
    }

    /// Reads and triangulates one primitive in local space; `None` for skipped modes. Reads
    /// the optional attributes `needs` asks for. A Draco-compressed primitive is decoded
    /// first, and its accessors read from the decoded data.
    fn local_prim(
        &mut self,
        mi: usize,
        pi: usize,
        prim: &json::mesh::Primitive,
        weights: Option<&[f32]>,
        skin: Option<&super::skin::Skinning>,
        needs: &Needs,
    ) -> Result<Option<LocalPrim>, LoadError> {
        let raw_prim = member(self.raw_item("meshes", mi), "primitives")
            .and_then(|p| p.get(pi))
            .unwrap_or(&Value::Null);
        let who = format!("mesh {mi} primitive {pi}");
        // The scene's own limits bound one decode; the loader counts the scene's total.
        let limits = (MAX_VERTICES, MAX_TRIANGLES);
        let decoded = super::draco::decode(&self.reader, raw_prim, prim, &who, limits)?;
        let Some(decoded) = decoded else {
            return self.read_prim(mi, pi, prim, weights, skin, needs);
        };
        self.reader.decoded = decoded;
        let prim_data = self.read_prim(mi, pi, prim, weights, skin, needs);
        self.reader.decoded.clear();
        prim_data
    }

    /// [`Self::local_prim`] once the primitive's data is readable through the accessors.
    fn read_prim(
        &mut self,
        mi: usize,
        pi: usize,
        prim: &json::mesh::Primitive,
        weights: Option<&[f32]>,
        skin: Option<&super::skin::Skinning>,
        needs: &Needs,
    ) -> Result<Option<LocalPrim>, LoadError> {
        let mode = match prim.mode {
            Checked::Valid(m) => m,
            Checked::Invalid => {
                return Err(invalid(format!("mesh {mi} primitive {pi}: invalid mode")));
            }
        };
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            self.warn_once(format!(
                "mesh {mi} primitive {pi}: mode {} is not rendered (skipped)",
                mode_name(mode)
            ));
            return Ok(None);
        }
        let attr = |s: Semantic| prim.attributes.get(&Checked::Valid(s)).map(|a| a.value());
        let Some(pos_ai) = attr(Semantic::Positions) else {
            self.warn_once(format!(
                "mesh {mi} primitive {pi}: no POSITION attribute (skipped)"
            ));
            return Ok(None);
        };
        let what = |a: &str| format!("{a} of mesh {mi} primitive {pi}");
        let pos = self
            .reader
            .read_f32(pos_ai, &what("POSITION"), Type::Vec3)?;
        let count = pos.count;
        let mut positions = pos.vec3();
        let mut normals = match attr(Semantic::Normals) {
            Some(ai) => self
                .attribute(ai, &what("NORMAL"), Type::Vec3, count)?
                .vec3(),
            None => Vec::new(),
        };
        let read_uv = |this: &Self, k: u32, ai: usize| -> Result<Vec<Vec2>, LoadError> {
            let d = this.attribute(ai, &what(&format!("TEXCOORD_{k}")), Type::Vec2, count)?;
            Ok(d.vec2()
                .into_iter()
                .map(|t| if t.is_finite() { t } else { Vec2::ZERO })
                .collect())
        };
        let uvs = match attr(Semantic::TexCoords(0)) {
            Some(ai) => read_uv(self, 0, ai)?,
            None => Vec::new(),
        };
        // Further UV sets and colour sets, as far as the file has them and the material reads
        // them.
        let max_set = |f: fn(&Semantic) -> Option<u32>| {
            prim.attributes
                .keys()
                .filter_map(|k| match k {
                    Checked::Valid(s) => f(s),
                    Checked::Invalid => None,
                })
                .max()
        };
        let extras = member(self.raw_item("meshes", mi), "primitives")
            .and_then(|p| p.get(pi))
            .and_then(|p| member(p, "extras"));
        let max_uv = max_set(|s| match s {
            Semantic::TexCoords(k) => Some(*k),
            _ => None,
        });
        let mut extra_uvs: Vec<Vec<Vec2>> = Vec::new();
        let mut uv_names = Vec::new();
        if let Some(max_uv) = max_uv {
            let names = extra_names(extras, "tesela_uv_names");
            for k in 0..=max_uv {
                uv_names.push(
                    names
                        .get(k as usize)
                        .cloned()
                        .flatten()
                        .unwrap_or_else(|| default_name("UVMap", k as usize)),
                );
                if k == 0 {
                    continue;
                }
                let set = match attr(Semantic::TexCoords(k)) {
                    Some(ai) if needs.uv(k) => read_uv(self, k, ai)?,
                    _ => Vec::new(),
                };
                extra_uvs.push(set);
            }
            while extra_uvs.last().is_some_and(Vec::is_empty) {
                extra_uvs.pop();
            }
        }
        let mut colors = Vec::new();
        if let Some(max_col) = max_set(|s| match s {
            Semantic::Colors(k) => Some(*k),
            _ => None,
        }) {
            let names = extra_names(extras, "tesela_color_names");
            for k in 0..=max_col {
                let Some(ai) = attr(Semantic::Colors(k)) else {
                    continue;
                };
                if !(needs.all || (k == 0 && needs.color0)) {
                    continue;
                }
                let data = self.color_attribute(ai, &what(&format!("COLOR_{k}")), count)?;
                let name = names
                    .get(k as usize)
                    .cloned()
                    .flatten()
                    .unwrap_or_else(|| default_name("Col", k as usize));
                colors.push((name, data));
            }
        }
        let want_tangents = needs.all || needs.tangent_set.is_some();
        let mut tangents = match attr(Semantic::Tangents) {
            Some(ai) if want_tangents => {
                let d = self.attribute(ai, &what("TANGENT"), Type::Vec4, count)?;
                let mut bad = 0usize;
                let t: Vec<glam::Vec4> = d
                    .data
                    .chunks_exact(4)
                    .map(|c| {
                        let v = glam::Vec4::new(c[0], c[1], c[2], c[3]);
                        if v.is_finite() {
                            v
                        } else {
                            bad += 1;
                            glam::Vec4::new(0.0, 0.0, 0.0, 1.0)
                        }
                    })
                    .collect();
                if bad > 0 {
                    self.warn_once(format!(
                        "accessor {ai} ({}): {bad} tangents are not finite; those vertices use the triangle's UV direction",
                        what("TANGENT")
                    ));
                }
                t
            }
            _ => Vec::new(),
        };
        let rd = &self.reader;
        // Morph targets at the default weights.
        if let (Some(targets), Some(weights)) = (&prim.targets, weights) {
            for (ti, (t, &w)) in targets.iter().zip(weights.iter()).enumerate() {
                if w == 0.0 || !w.is_finite() {
                    continue;
                }
                if let Some(ai) = t.positions {
                    let d = rd.read_f32(
                        ai.value(),
                        &what(&format!("POSITION of morph target {ti}")),
                        Type::Vec3,
                    )?;
                    if d.count != count {
                        return Err(invalid(format!(
                            "accessor {} (morph target {ti} POSITION of mesh {mi} primitive {pi}): count {} differs from POSITION's {count}",
                            ai.value(),
                            d.count
                        )));
                    }
                    for (p, dp) in positions.iter_mut().zip(d.vec3()) {
                        *p += w * dp;
                    }
                }
                if let Some(ai) = t.normals
                    && !normals.is_empty()
                {
                    let d = rd.read_f32(
                        ai.value(),
                        &what(&format!("NORMAL of morph target {ti}")),
                        Type::Vec3,
                    )?;
                    if d.count != count {
                        return Err(invalid(format!(
                            "accessor {} (morph target {ti} NORMAL of mesh {mi} primitive {pi}): count {} differs from POSITION's {count}",
                            ai.value(),
                            d.count
                        )));
                    }
                    for (n, dn) in normals.iter_mut().zip(d.vec3()) {
                        *n += w * dn;
                    }
                }
                if let Some(ai) = t.tangents
                    && !tangents.is_empty()
                {
                    let d = rd.read_f32(
                        ai.value(),
                        &what(&format!("TANGENT of morph target {ti}")),
                        Type::Vec3,
                    )?;
                    if d.count != count {
                        return Err(invalid(format!(
                            "accessor {} (morph target {ti} TANGENT of mesh {mi} primitive {pi}): count {} differs from POSITION's {count}",
                            ai.value(),
                            d.count
                        )));
                    }
                    for (t, dt) in tangents.iter_mut().zip(d.vec3()) {
                        let v = t.truncate() + w * dt;
                        if v.is_finite() {
                            *t = v.extend(t.w);
                        }
                    }
                }
            }
        }
        if let Some(s) = skin {
            self.skin_vertices(
                prim,
                (mi, pi),
                s,
                &mut positions,
                &mut normals,
                &mut tangents,
            )?;
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(invalid(format!(
                "accessor {pos_ai} ({}): vertex {i} is not finite ({})",
                what("POSITION"),
                positions[i]
            )));
        }
        if normals
            .iter()
            .any(|n| !n.is_finite() || n.length_squared() == 0.0)
        {
            normals.clear();
        }
        let vcount = u32::try_from(count).map_err(|_| {
            LoadError::new(
                LoadErrorKind::TooLarge,
                format!("mesh {mi} primitive {pi}: too many vertices ({count})"),
            )
        })?;
        let tris = match prim.indices {
            Some(ai) => {
                let ai = ai.value();
                let idx = rd.read_indices(ai, &what("indices"))?;
                if let Some((k, &bad)) = idx.iter().enumerate().find(|&(_, &i)| i >= vcount) {
                    return Err(invalid(format!(
                        "accessor {ai} ({}): index {bad} at position {k} is out of range for {count} vertices",
                        what("indices")
                    )));
                }
                if mode == Mode::Triangles && idx.len() % 3 != 0 {
                    self.warn_once(format!(
                        "accessor {ai} ({}): {} indices are not a multiple of 3 for TRIANGLES; the last {} are dropped",
                        what("indices"),
                        idx.len(),
                        idx.len() % 3
                    ));
                }
                triangulate(mode, &idx)
            }
            None => {
                if mode == Mode::Triangles && count % 3 != 0 {
                    self.warn_once(format!(
                        "mesh {mi} primitive {pi}: {count} vertices without indices are not a multiple of 3 for TRIANGLES; the last {} are dropped",
                        count % 3
                    ));
                }
                let idx: Vec<u32> = (0..vcount).collect();
                triangulate(mode, &idx)
            }
        };
        let mut local = LocalPrim {
            positions,
            normals,
            uvs,
            tris,
            extra_uvs,
            uv_names,
            colors,
            tangents,
        };
        if let Some(set) = needs.tangent_set
            && local.tangents.is_empty()
            && !local.tris.is_empty()
        {
            // The glTF specification: without TANGENT, MikkTSpace on the normal texture's UVs.
            if let Err(e) = super::tangents::generate(&mut local, set as usize) {
                self.warn_once(format!(
                    "mesh {mi} primitive {pi}: no tangents for its normal map ({e}); each triangle's UV direction is used"
                ));
            }
        }
        Ok(Some(local))
    }
}

/// `extras.tesela_object.visibility` (`{"camera": bool, "shadow": bool, "diffuse": bool,
/// "glossy": bool, "transmission": bool}`, a missing member is true) as
/// `tesela_object.particle`: `{index, age, lifetime, location, size, velocity,
/// angular_velocity}` (Blender's world coordinates, frames); every member optional, `None` if
/// one is malformed.
fn particle(v: &Value) -> Option<crate::scene::Particle> {
    v.as_object()?;
    let num = |k: &str| -> Option<f32> {
        match member(v, k) {
            None => Some(0.0),
            Some(x) => x.as_f64().map(|x| x as f32).filter(|x| x.is_finite()),
        }
    };
    let vec = |k: &str| -> Option<Vec3> {
        match member(v, k) {
            None => Some(Vec3::ZERO),
            Some(x) => floats::<3>(Some(x))
                .map(Vec3::from_array)
                .filter(|v| v.is_finite()),
        }
    };
    let index = match member(v, "index") {
        None => 0,
        Some(i) => u32::try_from(i.as_u64()?).ok()?,
    };
    Some(crate::scene::Particle {
        index,
        age: num("age")?,
        lifetime: num("lifetime")?,
        location: vec("location")?,
        size: num("size")?,
        velocity: vec("velocity")?,
        angular_velocity: vec("angular_velocity")?,
    })
}

/// `tesela_object.attributes`: `{"object": {name: [r, g, b, a]}, "instancer": {...}}` (both
/// optional); `None` if malformed.
fn object_attributes(v: &Value) -> Option<crate::scene::ObjectAttributes> {
    v.as_object()?;
    let list = |k: &str| -> Option<Vec<(String, glam::Vec4)>> {
        let Some(m) = member(v, k) else {
            return Some(Vec::new());
        };
        m.as_object()?
            .iter()
            .map(|(name, c)| {
                let c = floats::<4>(Some(c)).map(glam::Vec4::from_array)?;
                c.is_finite().then(|| (name.clone(), c))
            })
            .collect()
    };
    Some(crate::scene::ObjectAttributes {
        object: list("object")?,
        instancer: list("instancer")?,
    })
}

/// [`ObjectInfo::visibility`] bits; None unless it is an object of booleans.
fn visibility_bits(v: &Value) -> Option<u32> {
    use crate::shading::globals::ray;
    let o = v.as_object()?;
    let mut bits = ObjectInfo::VISIBLE_TO_ALL;
    for (name, bit) in [
        ("camera", ray::CAMERA),
        ("shadow", ray::SHADOW),
        ("diffuse", ray::DIFFUSE),
        ("glossy", ray::GLOSSY),
        ("transmission", ray::TRANSMISSION),
    ] {
        if let Some(b) = o.get(name)
            && !b.as_bool()?
        {
            bits &= !bit;
        }
    }
    Some(bits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans() {
        assert_eq!(
            triangulate(Mode::TriangleStrip, &[0, 1, 2, 3, 4]),
            vec![[0, 1, 2], [2, 1, 3], [2, 3, 4]]
        );
        assert_eq!(
            triangulate(Mode::TriangleFan, &[0, 1, 2, 3]),
            vec![[1, 2, 0], [2, 3, 0]]
        );
        assert_eq!(triangulate(Mode::Triangles, &[0, 1, 2, 3]), vec![[0, 1, 2]]);
        assert!(triangulate(Mode::TriangleStrip, &[0, 1]).is_empty());
        assert!(triangulate(Mode::TriangleFan, &[]).is_empty());
    }

    fn tri() -> LocalPrim {
        LocalPrim {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: vec![Vec3::Z; 3],
            uvs: vec![],
            tris: vec![[0, 1, 2]],
            ..Default::default()
        }
    }

    fn geometric_normal(p: &[Vec3], t: [u32; 3]) -> Vec3 {
        let [a, b, c] = t.map(|i| p[i as usize]);
        (b - a).cross(c - a).normalize()
    }

    #[test]
    fn negative_determinant_flips_winding() {
        let l = tri();
        // Positive scale: same winding, normal +Z.
        let (p, n, t) = to_world(&l, Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0))).unwrap();
        assert_eq!(t, vec![[0, 1, 2]]);
        assert!(geometric_normal(&p, t[0]).abs_diff_eq(Vec3::Z, 1e-6));
        assert!(n[0].abs_diff_eq(Vec3::Z, 1e-6));
        // Mirror in X: winding reversed, so the geometric normal still agrees with the
        // transformed shading normal (+Z).
        let (p, n, t) = to_world(&l, Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0))).unwrap();
        assert_eq!(t, vec![[0, 2, 1]]);
        assert!(geometric_normal(&p, t[0]).abs_diff_eq(n[0], 1e-6));
        // Mirror in Z: the face now looks down -Z, and so does its normal.
        let (p, n, t) = to_world(&l, Mat4::from_scale(Vec3::new(1.0, 1.0, -1.0))).unwrap();
        assert!(geometric_normal(&p, t[0]).abs_diff_eq(-Vec3::Z, 1e-6));
        assert!(n[0].abs_diff_eq(-Vec3::Z, 1e-6));
    }

    #[test]
    fn normals_use_inverse_transpose_and_degenerate_ones_are_dropped() {
        let mut l = tri();
        l.normals = vec![Vec3::new(1.0, 1.0, 0.0).normalize(); 3];
        // Non-uniform scale (2, 1, 1): the normal (1,1,0) becomes (0.5,1,0) normalized.
        let (_, n, _) = to_world(&l, Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0))).unwrap();
        assert!(
            n[0].abs_diff_eq(Vec3::new(0.5, 1.0, 0.0).normalize(), 1e-6),
            "{n:?}"
        );
        // A singular transform drops normals.
        let (_, n, _) = to_world(&l, Mat4::from_scale(Vec3::new(1.0, 1.0, 0.0))).unwrap();
        assert!(n.is_empty());
        // Positions overflowing to infinity are refused.
        l.positions[1] = Vec3::X * f32::MAX;
        assert!(to_world(&l, Mat4::from_scale(Vec3::splat(4.0))).is_none());
    }
}
