//! `TESELA_points` (node): a point cloud (Blender's PointCloud geometry) in the node's space,
//! rendered as the spheres of [`crate::scene::points`].
//!
//! ```json
//! {"points": 3, "radius": 4, "material": 0, "attributes": {"heat": 5}}
//! ```
//! `points`: VEC3 float accessor of the centres; `radius`: SCALAR float per point (optional:
//! Cycles' default 0.01); `material`: the glTF material of the object's first slot (Cycles
//! shades every point with it; absent or null: the default surface); `attributes`: VEC4 float
//! accessors, one value per point, that the Attribute node reads by name.

use glam::{Mat4, Vec4};
use json::accessor::Type;
use serde_json::Value;

use super::mesh::PlacedPrim;
use super::{LoadError, Loader, LocalPrim, extension, invalid, member};
use crate::scene::points::{
    POINT_LAYER, POINT_RANDOM_LAYER, level_within, sphere_vertices, spheres,
};
use crate::shading::tex::hash::hash_uint2_to_float;
use ::gltf::json;

pub(crate) const EXTENSION: &str = "TESELA_points";

/// Cycles' radius for points without a radius attribute.
const DEFAULT_RADIUS: f32 = 0.01;

/// Triangles the spheres of one node may take: the finest icosphere that stays within it is
/// used.
const TRIANGLE_BUDGET: usize = 1 << 22;

impl<'a> Loader<'a> {
    /// The points of node `ni`, if it has any, as a world-space mesh of spheres.
    pub(crate) fn node_points(&mut self, ni: usize, world: Mat4) -> Result<(), LoadError> {
        let node = self.raw_item("nodes", ni);
        let Some(ext) = extension(node, EXTENSION) else {
            return Ok(());
        };
        let tag = format!("node {ni}: {EXTENSION}");
        let accessor = |v: &Value, k: &str| -> Result<usize, LoadError> {
            v.as_u64()
                .and_then(|i| usize::try_from(i).ok())
                .ok_or_else(|| invalid(format!("{tag}: {k} is not an accessor index")))
        };
        let pa = member(ext, "points")
            .ok_or_else(|| invalid(format!("{tag}: points is missing")))
            .and_then(|v| accessor(v, "points"))?;
        let centers = self
            .reader
            .read_f32(pa, &format!("points of {tag}"), Type::Vec3)?
            .vec3();
        let n = centers.len();
        let radii = match member(ext, "radius") {
            Some(v) => {
                let ra = accessor(v, "radius")?;
                let r = self
                    .reader
                    .read_f32(ra, &format!("radius of {tag}"), Type::Scalar)?;
                if r.count != n {
                    return Err(invalid(format!(
                        "{tag}: radius has {} values for {n} points",
                        r.count
                    )));
                }
                r.data
            }
            None => vec![DEFAULT_RADIUS; n],
        };
        let material = match member(ext, "material") {
            None | Some(Value::Null) => None,
            Some(v) => Some(
                v.as_u64()
                    .and_then(|i| usize::try_from(i).ok())
                    .ok_or_else(|| invalid(format!("{tag}: material is not an index")))?,
            ),
        };
        let mut attributes: Vec<(String, Vec<Vec4>)> = Vec::new();
        match member(ext, "attributes") {
            None => {}
            Some(Value::Object(map)) => {
                for (name, v) in map {
                    let what = format!("attribute '{name}' of {tag}");
                    let a = self
                        .reader
                        .read_f32(accessor(v, &what)?, &what, Type::Vec4)?;
                    if a.count != n {
                        return Err(invalid(format!(
                            "{tag}: attribute '{name}' has {} values for {n} points",
                            a.count
                        )));
                    }
                    let values = a
                        .data
                        .chunks_exact(4)
                        .map(|c| Vec4::from_slice(c))
                        .collect();
                    attributes.push((name.clone(), values));
                }
            }
            Some(_) => return Err(invalid(format!("{tag}: attributes is not an object"))),
        }
        let bad = (0..n)
            .filter(|&i| !(centers[i].is_finite() && radii[i].is_finite() && radii[i] >= 0.0))
            .count();
        if bad > 0 {
            self.warn_once(format!(
                "{tag}: {bad} points have a non-finite position or radius, or a negative radius; they are left out"
            ));
        }
        // Points of radius 0 are invisible in Cycles too: left out without a word.
        let kept: Vec<u32> = (0..n as u32)
            .filter(|&i| {
                let (c, r) = (centers[i as usize], radii[i as usize]);
                c.is_finite() && r.is_finite() && r > 0.0
            })
            .collect();
        let random: Vec<f32> = (0..n as u32).map(|i| hash_uint2_to_float(i, 0)).collect();
        let level = level_within(n, TRIANGLE_BUDGET);
        let s = spheres(&centers, &radii, &random, &kept, level);
        if s.tris.is_empty() {
            return Ok(());
        }
        // Each attribute's value on every vertex of its point's sphere (the spheres are those
        // of `kept`, in its order, each of the same vertex count).
        let verts = sphere_vertices(level);
        let mut colors = vec![
            (POINT_LAYER.to_string(), s.info),
            (POINT_RANDOM_LAYER.to_string(), s.random),
        ];
        for (name, values) in attributes {
            let expanded = kept
                .iter()
                .flat_map(|&i| std::iter::repeat_n(values[i as usize], verts))
                .collect();
            colors.push((name, expanded));
        }
        let material = self.material(material, false)?;
        let object = self.object_info(ni, member(node, "extras"), world);
        let name = member(node, "name")
            .and_then(Value::as_str)
            .unwrap_or("points")
            .to_string();
        let local = LocalPrim {
            positions: s.positions,
            normals: s.normals,
            uvs: Vec::new(),
            tris: s.tris,
            extra_uvs: Vec::new(),
            uv_names: Vec::new(),
            colors,
            tangents: Vec::new(),
        };
        let placed = PlacedPrim {
            what: tag,
            name,
            material,
            world,
            to_object: super::mesh::object_from_world(world),
            texspace: None,
            object,
        };
        self.push_built_mesh(ni, &local, placed)
    }
}

#[cfg(test)]
mod tests {
    use serde_json::{Value, json};

    use super::super::load_from_slice;
    use super::super::tests_load::{Bin, load};
    use crate::scene::points::{POINT_LAYER, POINT_RANDOM_LAYER};

    /// A document with one node carrying `TESELA_points` made by `ext(points, radius,
    /// attribute)` from three points (radii 0.5, 0.25, 1; an attribute 0, 1, 2).
    fn doc(ext: impl Fn(usize, usize, usize) -> Value) -> Vec<u8> {
        let mut b = Bin::default();
        let p = b.vec3(&[[0., 0., 0.], [3., 0., 0.], [0., 4., 0.]]);
        let r = b.floats(&[0.5, 0.25, 1.0], "SCALAR");
        let a = b.floats(&[0., 0., 0., 1., 1., 1., 1., 1., 2., 2., 2., 1.], "VEC4");
        b.finish(json!({
            "scenes": [{"nodes": [0]}],
            "nodes": [{"name": "Dots", "extensions": {"TESELA_points": ext(p, r, a)}}],
            "extensionsUsed": ["TESELA_points"]
        }))
    }

    #[test]
    fn points_become_spheres_with_point_info_and_attributes() {
        let s = load(&doc(
            |p, r, a| json!({"points": p, "radius": r, "attributes": {"heat": a}}),
        ));
        assert_eq!(s.meshes.len(), 1);
        let m = &s.meshes[0];
        let layer = |name: &str| &m.attrs.colors.iter().find(|(n, _)| n == name).unwrap().1;
        let (info, random, heat) = (layer(POINT_LAYER), layer(POINT_RANDOM_LAYER), layer("heat"));
        assert_eq!(info.len(), m.positions.len());
        // Every vertex lies just outside its point's sphere and carries its point's values.
        for (k, p) in m.positions.iter().enumerate() {
            let c = info[k];
            let d = (*p - c.truncate()).length();
            assert!(d > c.w && d < c.w * 1.01, "{d} for radius {}", c.w);
            let i = [0.5, 0.25, 1.0].iter().position(|&r| r == c.w).unwrap();
            assert_eq!(heat[k].x, i as f32);
            assert_eq!(
                random[k].x,
                crate::shading::tex::hash::hash_uint2_to_float(i as u32, 0)
            );
        }
    }

    #[test]
    fn malformed_points_are_clear_errors() {
        for (ext, want) in [
            (json!({}), "points is missing"),
            (json!({"points": "x"}), "points is not an accessor index"),
            (json!({"points": 0, "radius": 2}), "radius"),
            (
                json!({"points": 0, "attributes": [1]}),
                "attributes is not an object",
            ),
            (
                json!({"points": 0, "attributes": {"t": 0}}),
                "attribute 't'",
            ),
            (json!({"points": 0, "material": 7}), "material"),
        ] {
            let bytes = doc(|_, _, _| ext.clone());
            let err = load_from_slice(&bytes, None, "p.gltf")
                .err()
                .map(|e| e.to_string());
            let err = err.unwrap_or_else(|| panic!("{ext} loaded"));
            assert!(err.contains(want), "{ext}: {err}");
        }
    }
}
