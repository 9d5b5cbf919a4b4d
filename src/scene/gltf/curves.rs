//! `TESELA_curves` (node): strands (Blender's Curves objects: hair, fur, grass) in the node's
//! space, rendered as the tubes of [`crate::scene::curves`].
//!
//! ```json
//! {"points": 3, "radius": 4, "offsets": 5, "linear": false,
//!  "materials": [0, null], "material_index": 6}
//! ```
//! `points`: VEC3 float accessor of the control points (glTF axes); `radius`: SCALAR float per
//! point (optional: Cycles' default 0.005); `offsets`: SCALAR unsigned, one more than the
//! curves, curve `c` being points `offsets[c]..offsets[c + 1]`; `linear`: straight segments
//! (Blender's poly curves); `materials`: the object's material slots (glTF material indices,
//! null for an empty slot); `material_index`: SCALAR per curve, its slot (optional: 0).

use glam::Mat4;
use json::accessor::Type;
use serde_json::Value;

use super::mesh::PlacedPrim;
use super::{LoadError, Loader, LocalPrim, extension, invalid, member};
use crate::scene::curves::{CURVE_LAYER, Detail, Strands, tessellate};
use ::gltf::json;

pub(crate) const EXTENSION: &str = "TESELA_curves";

/// Cycles' radius for curves without a radius attribute.
const DEFAULT_RADIUS: f32 = 0.005;

/// Triangles the tubes of one node may take: the finest detail that stays within it is used.
const TRIANGLE_BUDGET: usize = 1 << 23;

impl<'a> Loader<'a> {
    /// The strands of node `ni`, if it has any, as world-space tube meshes (one per material).
    pub(crate) fn node_curves(&mut self, ni: usize, world: Mat4) -> Result<(), LoadError> {
        let node = self.raw_item("nodes", ni);
        let Some(ext) = extension(node, EXTENSION) else {
            return Ok(());
        };
        let tag = format!("node {ni}: {EXTENSION}");
        let index = |k: &str| -> Result<Option<usize>, LoadError> {
            match member(ext, k) {
                None => Ok(None),
                Some(v) => v
                    .as_u64()
                    .and_then(|i| usize::try_from(i).ok())
                    .map(Some)
                    .ok_or_else(|| invalid(format!("{tag}: {k} is not an accessor index"))),
            }
        };
        let pa = index("points")?.ok_or_else(|| invalid(format!("{tag}: points is missing")))?;
        let oa = index("offsets")?.ok_or_else(|| invalid(format!("{tag}: offsets is missing")))?;
        let points = self
            .reader
            .read_f32(pa, &format!("points of {tag}"), Type::Vec3)?
            .vec3();
        let radii = match index("radius")? {
            Some(ra) => {
                let r = self
                    .reader
                    .read_f32(ra, &format!("radius of {tag}"), Type::Scalar)?;
                if r.count != points.len() {
                    return Err(invalid(format!(
                        "{tag}: radius has {} values for {} points",
                        r.count,
                        points.len()
                    )));
                }
                r.data
            }
            None => vec![DEFAULT_RADIUS; points.len()],
        };
        let offsets = self.reader.read_indices(oa, &format!("offsets of {tag}"))?;
        let curves = offsets.len().saturating_sub(1);
        if let Some(k) = offsets
            .windows(2)
            .position(|w| w[0] > w[1] || w[1] as usize > points.len())
        {
            return Err(invalid(format!(
                "{tag}: offsets {}..{} of curve {k} are out of order or past the {} points",
                offsets[k],
                offsets[k + 1],
                points.len()
            )));
        }
        let slots: Vec<Option<usize>> = match member(ext, "materials") {
            None => vec![None],
            Some(Value::Array(a)) => a
                .iter()
                .map(|m| m.as_u64().and_then(|i| usize::try_from(i).ok()))
                .collect(),
            Some(_) => return Err(invalid(format!("{tag}: materials is not an array"))),
        };
        let per_curve: Vec<usize> = match index("material_index")? {
            Some(ma) => {
                let m =
                    self.reader
                        .read_f32(ma, &format!("material_index of {tag}"), Type::Scalar)?;
                if m.count != curves {
                    return Err(invalid(format!(
                        "{tag}: material_index has {} values for {curves} curves",
                        m.count
                    )));
                }
                // Blender clamps a slot past the last to the last.
                m.data
                    .iter()
                    .map(|&i| (i.max(0.0) as usize).min(slots.len().saturating_sub(1)))
                    .collect()
            }
            None => vec![0; curves],
        };
        let linear = member(ext, "linear")
            .and_then(Value::as_bool)
            .unwrap_or(false);
        let bad = points.iter().filter(|p| !p.is_finite()).count()
            + radii.iter().filter(|r| !r.is_finite()).count();
        if bad > 0 {
            self.warn_once(format!(
                "{tag}: {bad} point coordinates or radii are not finite; their strands are left out"
            ));
        }
        let extras = member(node, "extras");
        let mut object = self.object_info(ni, extras, world);
        object.strands = true;
        let to_object = super::mesh::object_from_world(world);
        let segments = offsets
            .windows(2)
            .map(|w| (w[1] - w[0]).saturating_sub(1) as usize)
            .sum();
        let detail = Detail::within(curves, segments, linear, TRIANGLE_BUDGET);
        let name = member(node, "name")
            .and_then(Value::as_str)
            .unwrap_or("curves")
            .to_string();
        for (slot, gltf_material) in slots.iter().enumerate() {
            let strands: Vec<(u32, u32, u32)> = (0..curves)
                .filter(|&c| per_curve[c] == slot)
                .map(|c| (c as u32, offsets[c], offsets[c + 1]))
                .collect();
            if strands.is_empty() {
                continue;
            }
            let tubes = tessellate(&Strands {
                detail,
                points: &points,
                radii: &radii,
                curves: &strands,
                linear,
            });
            if tubes.tris.is_empty() {
                continue;
            }
            let material = self.material(*gltf_material, false)?;
            let local = LocalPrim {
                positions: tubes.positions,
                normals: tubes.normals,
                uvs: Vec::new(),
                tris: tubes.tris,
                extra_uvs: Vec::new(),
                uv_names: Vec::new(),
                colors: vec![(CURVE_LAYER.to_string(), tubes.info)],
                tangents: tubes.tangents,
            };
            let placed = PlacedPrim {
                what: format!("{tag} (material slot {slot})"),
                name: if slots.len() == 1 {
                    name.clone()
                } else {
                    format!("{name}.{slot}")
                },
                material,
                world,
                to_object,
                texspace: None,
                object: object.clone(),
            };
            self.push_built_mesh(ni, &local, placed)?;
        }
        Ok(())
    }
}
