//! Mesh placements: glTF meshes referenced by several nodes, and `EXT_mesh_gpu_instancing`
//! (per-instance TRANSLATION, ROTATION, SCALE accessors applied before the node's transform:
//! `world = node_world · T · R · S`).
//!
//! A mesh placed once is baked into world space as before; a mesh placed more often is stored
//! once in its object space and placed by [`crate::scene::Instance`]s. Placements that cannot
//! be rendered (non-finite or singular transforms, beyond the coordinate limit) are skipped
//! with one warning per node.

use glam::{Mat4, Quat, Vec3, Vec4};
use json::accessor::Type;
use std::collections::HashMap;

use super::{LoadError, LoadErrorKind, Loader, extension, invalid, json, member};
use crate::motion::TransformMotion;
use crate::scene::{Instance, instance::transform_bounds};

/// Most instances a file may place (about 0.5 GB of instance and BVH data).
pub(crate) const MAX_INSTANCES: usize = 1 << 22;

/// One node's use of a mesh, found by the node walk.
pub(crate) struct MeshUse {
    pub node: usize,
    pub mesh: usize,
    pub world: Mat4,
    /// `EXT_mesh_gpu_instancing` local transforms (`T · R · S`), empty without the extension.
    pub gpu: Vec<Mat4>,
    /// The add-on's `_TESELA_RANDOM` attribute: each instance's Object Info random (may be
    /// empty: then a hash of node and instance index).
    pub gpu_random: Vec<f32>,
    /// The node's world keys over the shutter (`TESELA_motion`), `None` when it stays still.
    pub motion: Option<Vec<(f32, Mat4)>>,
}

impl<'a> Loader<'a> {
    /// The `EXT_mesh_gpu_instancing` transforms of node `ni` (empty without the extension).
    /// Instances whose attributes are not finite or whose rotation is zero come back as a
    /// non-finite matrix, for [`Loader::place_meshes`] to skip.
    pub(crate) fn gpu_instances(&mut self, ni: usize) -> Result<(Vec<Mat4>, Vec<f32>), LoadError> {
        let Some(ext) = extension(self.raw_item("nodes", ni), "EXT_mesh_gpu_instancing") else {
            return Ok((Vec::new(), Vec::new()));
        };
        let Some(attrs) = member(ext, "attributes").and_then(|a| a.as_object()) else {
            return Err(invalid(format!(
                "node {ni}: EXT_mesh_gpu_instancing has no `attributes` object"
            )));
        };
        let mut count = None;
        let mut read = |name: &str, ty: Type| -> Result<Option<Vec<f32>>, LoadError> {
            let Some(v) = attrs.get(name) else {
                return Ok(None);
            };
            let what = format!("node {ni} EXT_mesh_gpu_instancing {name}");
            let ai = v
                .as_u64()
                .and_then(|a| usize::try_from(a).ok())
                .ok_or_else(|| invalid(format!("{what}: {v} is not an accessor index")))?;
            let n = self.root.accessors.get(ai).map(|a| a.count.0 as usize);
            let n = n.ok_or_else(|| {
                invalid(format!(
                    "{what}: accessor {ai} does not exist (the file has {})",
                    self.root.accessors.len()
                ))
            })?;
            if n > MAX_INSTANCES {
                return Err(LoadError::new(
                    LoadErrorKind::TooLarge,
                    format!(
                        "accessor {ai} ({what}): {n} instances exceed the limit of {MAX_INSTANCES}"
                    ),
                ));
            }
            if *count.get_or_insert(n) != n {
                return Err(invalid(format!(
                    "accessor {ai} ({what}): {n} elements where the other attributes have {}",
                    count.unwrap_or(0)
                )));
            }
            Ok(Some(self.reader.read_f32(ai, &what, ty)?.data))
        };
        let t = read("TRANSLATION", Type::Vec3)?;
        let r = read("ROTATION", Type::Vec4)?;
        let s = read("SCALE", Type::Vec3)?;
        let random = read("_TESELA_RANDOM", Type::Scalar)?.unwrap_or_default();
        let n = count.unwrap_or(0);
        let v3 = |d: &Option<Vec<f32>>, k: usize, def: Vec3| {
            d.as_ref()
                .map_or(def, |d| Vec3::from_slice(&d[3 * k..3 * k + 3]))
        };
        let transforms = (0..n)
            .map(|k| {
                let q = r
                    .as_ref()
                    .map_or(Quat::IDENTITY, |d| Quat::from_slice(&d[4 * k..4 * k + 4]));
                let len = q.length();
                if !(len.is_finite() && len > 1e-12) {
                    return Mat4::from_cols(Vec4::NAN, Vec4::NAN, Vec4::NAN, Vec4::NAN);
                }
                Mat4::from_scale_rotation_translation(
                    v3(&s, k, Vec3::ONE),
                    q / len,
                    v3(&t, k, Vec3::ZERO),
                )
            })
            .collect();
        Ok((transforms, random))
    }

    /// Turns the meshes the node walk found into scene meshes: baked where a geometry is placed
    /// once (or a node sets its own morph weights), else stored once and placed by instances.
    /// Meshes that share a geometry (see [`Loader::geometries`]) share one stored copy; an
    /// instance of a mesh other than the one stored carries its own materials.
    pub(crate) fn place_meshes(&mut self, uses: Vec<MeshUse>) -> Result<(), LoadError> {
        let mut meshes: Vec<usize> = uses.iter().map(|u| u.mesh).collect();
        meshes.sort_unstable();
        meshes.dedup();
        let geometry = self.geometries(&meshes)?;
        let mut placements: HashMap<usize, usize> = HashMap::new();
        let mut total = 0usize;
        for u in &uses {
            let n = u.gpu.len().max(1);
            *placements.entry(geometry[&u.mesh]).or_default() += n;
            total = total.saturating_add(n);
        }
        // Triangles of all the copies of each geometry, had they been baked.
        let mut baked_size: HashMap<usize, usize> = HashMap::new();
        for u in &uses {
            let n = u.gpu.len().max(1);
            let t = self.mesh_triangles(u.mesh).saturating_mul(n);
            let e = baked_size.entry(geometry[&u.mesh]).or_default();
            *e = e.saturating_add(t);
        }
        if total > MAX_INSTANCES {
            return Err(LoadError::new(
                LoadErrorKind::TooLarge,
                format!("the nodes place {total} meshes, beyond the limit of {MAX_INSTANCES}"),
            ));
        }
        // Geometry -> (the mesh stored for it, its scene meshes, their primitive indices).
        type Stored = (usize, std::ops::Range<usize>, Vec<usize>);
        let mut stored: HashMap<usize, Stored> = HashMap::new();
        // Mesh -> the materials of the stored primitives, for meshes placed on another's copy.
        let mut overrides: HashMap<usize, Vec<usize>> = HashMap::new();
        for u in uses {
            let own_weights = self.root.nodes[u.node].weights.is_some();
            let g = geometry[&u.mesh];
            let small = baked_size[&g] <= self.options.bake_triangles;
            // A skinned mesh is posed by its joints, in world space, whatever its node says.
            let skinning = self.skinning(u.node, u.world)?;
            if let Some(s) = &skinning {
                if u.motion.is_some() {
                    self.warn_once(format!(
                        "node {}: the motion of a skinned mesh is not rendered; it renders posed by its skin",
                        u.node
                    ));
                }
                if !u.gpu.is_empty() {
                    self.warn_once(format!(
                        "node {}: a skinned mesh placed by EXT_mesh_gpu_instancing is drawn once, posed by its skin",
                        u.node
                    ));
                }
                let (baked, _) =
                    self.instance_mesh(u.node, u.mesh, Mat4::IDENTITY, false, Some(s))?;
                let origins = &mut self.origins.mesh_node;
                origins.resize(baked.start, None);
                origins.resize(baked.end, Some(u.node));
                continue;
            }
            // A moving mesh is placed by an instance, whose transform follows the time.
            if u.gpu.is_empty()
                && u.motion.is_none()
                && (placements[&g] == 1 || own_weights || small)
            {
                let (baked, _) = self.instance_mesh(u.node, u.mesh, u.world, false, None)?;
                let origins = &mut self.origins.mesh_node;
                origins.resize(baked.start, None);
                origins.resize(baked.end, Some(u.node));
                continue;
            }
            let (owner, range, prims) = match stored.get(&g) {
                Some(s) => s.clone(),
                None => {
                    let (r, p) = self.instance_mesh(u.node, u.mesh, Mat4::IDENTITY, true, None)?;
                    stored.insert(g, (u.mesh, r.clone(), p.clone()));
                    (u.mesh, r, p)
                }
            };
            let materials: Option<Vec<usize>> = if owner == u.mesh {
                None
            } else if let Some(m) = overrides.get(&u.mesh) {
                Some(m.clone())
            } else {
                let mut m = Vec::with_capacity(prims.len());
                for &pi in &prims {
                    let prim = &self.root.meshes[u.mesh].primitives[pi];
                    // Same geometry: the primitive renders as the stored one does.
                    m.push(self.primitive_material(prim)?.unwrap_or_default());
                }
                overrides.insert(u.mesh, m.clone());
                Some(m)
            };
            let locals = if u.gpu.is_empty() {
                vec![Mat4::IDENTITY]
            } else {
                u.gpu
            };
            let extras = member(self.raw_item("nodes", u.node), "extras");
            let (mut skipped, mut why) = (0usize, "");
            for (k, local) in locals.iter().enumerate() {
                let world = u.world * *local;
                let keys: Option<Vec<(f32, Mat4)>> = (u.motion.as_ref())
                    .map(|keys| keys.iter().map(|(t, m)| (*t, *m * *local)).collect());
                let motion = keys.as_ref().and_then(|k| TransformMotion::new(k).ok());
                let problem = Instance::check(&world)
                    .or_else(|| {
                        let bad = keys.iter().flatten().find_map(|(_, m)| Instance::check(m));
                        bad.or_else(|| {
                            (keys.is_some() && motion.is_none())
                                .then_some("its motion keys are not valid")
                        })
                    })
                    .or_else(|| {
                        (range.clone())
                            .filter_map(|mi| self.scene.meshes[mi].bounds())
                            .map(|(lo, hi)| transform_bounds(&world, lo, hi))
                            .any(|(lo, hi)| {
                                lo.abs().max(hi.abs()).max_element() > crate::accel::MAX_COORD
                            })
                            .then_some("it reaches beyond the renderer's coordinate limit")
                    });
                if let Some(p) = problem {
                    skipped += 1;
                    why = p;
                    continue;
                }
                let mut object = self.object_info(u.node, extras, world);
                if locals.len() > 1 {
                    object.random = match u.gpu_random.get(k) {
                        Some(r) if r.is_finite() => *r,
                        _ => instance_random(u.node, k),
                    };
                }
                let motion = motion.map(std::sync::Arc::new);
                for (k, mesh) in range.clone().enumerate() {
                    self.origins.instance_node.push(u.node);
                    self.scene.instances.push(Instance {
                        motion: motion.clone(),
                        mesh,
                        to_world: world,
                        material: materials.as_ref().map(|m| m[k]),
                        object: object.clone(),
                    });
                }
            }
            if skipped > 0 {
                self.warn_once(format!(
                    "node {}: {skipped} of {} placements of mesh {} are skipped ({why})",
                    u.node,
                    locals.len(),
                    u.mesh
                ));
            }
        }
        Ok(())
    }
}

impl<'a> Loader<'a> {
    /// Geometry ids of the glTF meshes `meshes` (sorted, distinct): meshes whose primitives
    /// are the same JSON apart from `material` (the same accessors, mode, morph targets and
    /// extras) and whose materials read the same attributes are one geometry, stored once.
    /// This is how a file gives objects that share a mesh their own materials. Other meshes
    /// are each their own geometry.
    /// Triangles of glTF mesh `mi` as its primitives' index (or vertex) counts give them.
    fn mesh_triangles(&self, mi: usize) -> usize {
        let Some(mesh) = self.root.meshes.get(mi) else {
            return 0;
        };
        let count = |a: usize| self.root.accessors.get(a).map_or(0, |a| a.count.0 as usize);
        mesh.primitives
            .iter()
            .map(|p| {
                let n = match &p.indices {
                    Some(i) => count(i.value()),
                    None => p
                        .attributes
                        .get(&json::validation::Checked::Valid(
                            json::mesh::Semantic::Positions,
                        ))
                        .map_or(0, |a| count(a.value())),
                };
                n / 3
            })
            .fold(0usize, usize::saturating_add)
    }

    pub(crate) fn geometries(
        &mut self,
        meshes: &[usize],
    ) -> Result<HashMap<usize, usize>, LoadError> {
        let mut by_json: HashMap<String, Vec<usize>> = HashMap::new();
        for &mi in meshes {
            by_json.entry(self.geometry_json(mi)).or_default().push(mi);
        }
        let mut groups: Vec<Vec<usize>> = by_json.into_values().collect();
        groups.sort_unstable();
        let mut ids = HashMap::new();
        let mut next = 0usize;
        for group in groups {
            if group.len() == 1 {
                ids.insert(group[0], next);
                next += 1;
                continue;
            }
            // The stored copy holds what its materials read: meshes share it only when theirs
            // read the same.
            let mut by_needs: Vec<(Vec<Option<super::mesh::Needs>>, usize)> = Vec::new();
            for mi in group {
                let mut needs = Vec::new();
                for pi in 0..self.root.meshes[mi].primitives.len() {
                    let prim = &self.root.meshes[mi].primitives[pi];
                    let m = self.primitive_material(prim)?;
                    needs.push(m.map(|m| super::mesh::needs(&self.scene.materials[m])));
                }
                let id = match by_needs.iter().find(|(n, _)| *n == needs) {
                    Some((_, id)) => *id,
                    None => {
                        by_needs.push((needs, next));
                        next += 1;
                        next - 1
                    }
                };
                ids.insert(mi, id);
            }
        }
        Ok(ids)
    }

    /// Mesh `mi`'s primitives and morph weights as JSON, without their materials.
    fn geometry_json(&self, mi: usize) -> String {
        let mesh = self.raw_item("meshes", mi);
        let prims: Vec<serde_json::Value> = member(mesh, "primitives")
            .and_then(serde_json::Value::as_array)
            .map(|a| {
                a.iter()
                    .map(|p| {
                        let mut p = p.clone();
                        if let Some(o) = p.as_object_mut() {
                            o.remove("material");
                        }
                        p
                    })
                    .collect()
            })
            .unwrap_or_default();
        let weights = member(mesh, "weights").cloned();
        serde_json::json!([prims, weights]).to_string()
    }
}

/// Object Info random of instance `k` of node `ni`: a hash of both, uniform in `[0, 1)`.
fn instance_random(ni: usize, k: usize) -> f32 {
    let mut h = (ni as u64) << 32 ^ k as u64;
    h ^= h >> 33;
    h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
    h ^= h >> 33;
    h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    h ^= h >> 33;
    (h >> 40) as f32 / (1u64 << 24) as f32
}
