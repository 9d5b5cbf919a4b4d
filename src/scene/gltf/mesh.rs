//! Mesh primitives: attributes, morph targets, triangulation, and flattening to world space.

use std::rc::Rc;

use ::gltf::json;
use glam::{Mat4, Vec3};
use json::accessor::Type;
use json::mesh::{Mode, Semantic};
use json::validation::Checked;

use super::{LoadError, LoadErrorKind, Loader, LocalPrim, MAX_TRIANGLES, MAX_VERTICES, invalid};
use crate::scene::Mesh;

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

impl<'a> Loader<'a> {
    pub(crate) fn instance_mesh(
        &mut self,
        ni: usize,
        mi: usize,
        world: Mat4,
    ) -> Result<(), LoadError> {
        let root = self.root;
        let mesh = root.meshes.get(mi).ok_or_else(|| {
            invalid(format!(
                "node {ni}: mesh {mi} does not exist (the file has {})",
                root.meshes.len()
            ))
        })?;
        let node = &root.nodes[ni];
        let weights: Option<&[f32]> = node.weights.as_deref().or(mesh.weights.as_deref());
        let cacheable = node.weights.is_none();
        let base_name = mesh
            .name
            .clone()
            .or_else(|| node.name.clone())
            .unwrap_or_else(|| format!("mesh{mi}"));
        for (pi, prim) in mesh.primitives.iter().enumerate() {
            let local = if cacheable {
                if let Some(c) = self.prim_cache.get(&(mi, pi)) {
                    c.clone()
                } else {
                    let l = self.local_prim(mi, pi, prim, weights)?.map(Rc::new);
                    self.prim_cache.insert((mi, pi), l.clone());
                    l
                }
            } else {
                self.local_prim(mi, pi, prim, weights)?.map(Rc::new)
            };
            let Some(local) = local else { continue };
            if local.tris.is_empty() {
                continue;
            }
            let (positions, normals, indices) = to_world(&local, world).ok_or_else(|| {
                invalid(format!(
                    "mesh {mi} primitive {pi} on node {ni}: positions are not finite in world space"
                ))
            })?;
            if let Some((i, p)) = positions
                .iter()
                .enumerate()
                .find(|(_, p)| p.abs().max_element() > crate::accel::MAX_COORD)
            {
                return Err(invalid(format!(
                    "mesh {mi} primitive {pi} on node {ni}: vertex {i} at {p} in world space is farther than {:e} m from the origin (the renderer's coordinate limit)",
                    crate::accel::MAX_COORD
                )));
            }
            self.tri_total = self.tri_total.saturating_add(indices.len());
            self.vert_total = self.vert_total.saturating_add(positions.len());
            if self.tri_total > MAX_TRIANGLES || self.vert_total > MAX_VERTICES {
                return Err(LoadError::new(
                    LoadErrorKind::TooLarge,
                    format!(
                        "the scene exceeds the limit of {MAX_TRIANGLES} triangles / {MAX_VERTICES} vertices (at mesh {mi} on node {ni})"
                    ),
                ));
            }
            let material = self.material(prim.material.map(|m| m.value()))?;
            let name = if mesh.primitives.len() > 1 {
                format!("{base_name}.{pi}")
            } else {
                base_name.clone()
            };
            let uvs = local.uvs.clone();
            self.scene.meshes.push(Mesh {
                name,
                positions,
                normals,
                uvs,
                indices,
                material,
                hidden_from_camera: false,
                attrs: Default::default(),
            });
        }
        Ok(())
    }

    /// Reads and triangulates one primitive in local space; `None` for skipped modes.
    fn local_prim(
        &mut self,
        mi: usize,
        pi: usize,
        prim: &json::mesh::Primitive,
        weights: Option<&[f32]>,
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
        let rd = &self.reader;
        let what = |a: &str| format!("{a} of mesh {mi} primitive {pi}");
        let pos = rd.read_f32(pos_ai, &what("POSITION"), Type::Vec3)?;
        let count = pos.count;
        let mut positions = pos.vec3();
        let mut normals = match attr(Semantic::Normals) {
            Some(ai) => {
                let v = rd.read_f32(ai, &what("NORMAL"), Type::Vec3)?;
                if v.count != count {
                    return Err(invalid(format!(
                        "accessor {ai} ({}): count {} differs from POSITION's {count}",
                        what("NORMAL"),
                        v.count
                    )));
                }
                v.vec3()
            }
            None => Vec::new(),
        };
        let uvs = match attr(Semantic::TexCoords(0)) {
            Some(ai) => {
                let v = rd.read_f32(ai, &what("TEXCOORD_0"), Type::Vec2)?;
                if v.count != count {
                    return Err(invalid(format!(
                        "accessor {ai} ({}): count {} differs from POSITION's {count}",
                        what("TEXCOORD_0"),
                        v.count
                    )));
                }
                v.vec2()
                    .into_iter()
                    .map(|t| if t.is_finite() { t } else { glam::Vec2::ZERO })
                    .collect()
            }
            None => Vec::new(),
        };
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
            }
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
                triangulate(mode, &idx)
            }
            None => {
                let idx: Vec<u32> = (0..vcount).collect();
                triangulate(mode, &idx)
            }
        };
        Ok(Some(LocalPrim {
            positions,
            normals,
            uvs,
            tris,
        }))
    }
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
