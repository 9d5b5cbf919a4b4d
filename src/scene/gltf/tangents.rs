//! MikkTSpace tangents for primitives whose material needs them (a normal map, a clearcoat
//! normal map, anisotropy) and which carry no TANGENT, as the glTF specification asks, with the
//! `mikktspace` crate; and the world-space transform of tangents.
//!
//! Texture coordinates go to MikkTSpace with v flipped (`1 - v`, Blender's convention, as
//! Blender's importer does): the bitangent sign then follows glTF's rule, `bitangent =
//! w · cross(normal, tangent)` pointing towards the image's top row, the "+Y up" of glTF normal
//! maps. MikkTSpace gives each triangle corner its own tangent; a vertex whose corners disagree
//! (UV seams, mirrored halves) is split, copying its attributes.

use std::collections::HashMap;

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

use super::LocalPrim;

struct Geometry<'a> {
    positions: &'a [Vec3],
    /// Vertex normals, or empty (then each face's own normal).
    normals: &'a [Vec3],
    uvs: &'a [Vec2],
    tris: &'a [[u32; 3]],
    /// One tangent per triangle corner.
    out: Vec<[f32; 4]>,
}

impl Geometry<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.tris[face][vert] as usize
    }
}

impl mikktspace::Geometry for Geometry<'_> {
    fn num_faces(&self) -> usize {
        self.tris.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[self.vertex(face, vert)].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        if let Some(n) = self.normals.get(self.vertex(face, vert)) {
            return n.to_array();
        }
        let [a, b, c] = self.tris[face].map(|i| self.positions[i as usize]);
        (b - a).cross(c - a).normalize_or_zero().to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let t = self.uvs[self.vertex(face, vert)];
        [t.x, 1.0 - t.y]
    }

    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        if let Some(o) = self.out.get_mut(face * 3 + vert) {
            *o = tangent;
        }
    }
}

/// Computes MikkTSpace tangents of `prim` for UV set `set` into `prim.tangents`, splitting
/// vertices where corners disagree. `Err` says why none could be computed (the primitive is
/// left as it was).
pub(crate) fn generate(prim: &mut LocalPrim, set: usize) -> Result<(), String> {
    let uvs: &[Vec2] = match set.checked_sub(1).and_then(|k| prim.extra_uvs.get(k)) {
        Some(v) if !v.is_empty() => v,
        _ => &prim.uvs,
    };
    if uvs.is_empty() {
        return Err("the primitive has no texture coordinates".into());
    }
    let n = prim.positions.len();
    if uvs.len() != n || (!prim.normals.is_empty() && prim.normals.len() != n) {
        return Err("attribute counts differ".into());
    }
    let mut geo = Geometry {
        positions: &prim.positions,
        normals: &prim.normals,
        uvs,
        tris: &prim.tris,
        out: vec![[0.0; 4]; prim.tris.len() * 3],
    };
    // The crate is a translation of the C reference; catch anything it might do on odd input
    // rather than take the process down.
    let ok = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        mikktspace::generate_tangents(&mut geo)
    }));
    match ok {
        Ok(true) => {}
        Ok(false) => return Err("MikkTSpace found no usable triangles".into()),
        Err(_) => return Err("MikkTSpace failed on this geometry".into()),
    }
    let corners = geo.out;
    split_by_corner(prim, &corners);
    Ok(())
}

/// Sets one tangent per vertex from per-corner tangents, duplicating vertices (with all their
/// attributes) whose corners carry different tangents.
fn split_by_corner(prim: &mut LocalPrim, corners: &[[f32; 4]]) {
    let clean = |t: [f32; 4]| -> Vec4 {
        let v = Vec4::from_array(t);
        if v.is_finite() {
            Vec4::new(v.x, v.y, v.z, if v.w < 0.0 { -1.0 } else { 1.0 })
        } else {
            Vec4::new(0.0, 0.0, 0.0, 1.0)
        }
    };
    let n = prim.positions.len();
    let mut assigned: Vec<Option<Vec4>> = vec![None; n];
    let mut extra: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
    let mut tangents: Vec<Vec4> = vec![Vec4::ZERO; n];
    for (c, &t) in corners.iter().enumerate() {
        let (f, k) = (c / 3, c % 3);
        let Some(tri) = prim.tris.get_mut(f) else {
            break;
        };
        let v = tri[k] as usize;
        let t = clean(t);
        match assigned[v] {
            None => {
                assigned[v] = Some(t);
                tangents[v] = t;
            }
            Some(a) if a.to_array().map(f32::to_bits) == t.to_array().map(f32::to_bits) => {}
            Some(_) => {
                let key = (v as u32, t.to_array().map(f32::to_bits));
                let new = *extra.entry(key).or_insert_with(|| {
                    let i = prim.positions.len() as u32;
                    prim.positions.push(prim.positions[v]);
                    if !prim.normals.is_empty() {
                        prim.normals.push(prim.normals[v]);
                    }
                    if !prim.uvs.is_empty() {
                        prim.uvs.push(prim.uvs[v]);
                    }
                    for set in prim.extra_uvs.iter_mut().filter(|s| !s.is_empty()) {
                        set.push(set[v]);
                    }
                    for (_, c) in prim.colors.iter_mut() {
                        c.push(c[v]);
                    }
                    tangents.push(t);
                    i
                });
                tri[k] = new;
            }
        }
    }
    prim.tangents = tangents;
}

/// Local tangents → world space: `xyz` by the linear part of `m` (normalised; zero where it
/// degenerates), `w` times the sign of `m`'s determinant, so that `w · cross(n, t)` stays the
/// transformed bitangent when `m` mirrors (the winding and the normals flip with it).
pub(crate) fn to_world(tangents: &[Vec4], m: Mat4) -> Vec<Vec4> {
    let l = Mat3::from_mat4(m);
    let flip = if l.determinant() < 0.0 { -1.0 } else { 1.0 };
    tangents
        .iter()
        .map(|t| {
            let v = (l * t.truncate()).normalize_or_zero();
            v.extend(if t.w < 0.0 { -flip } else { flip })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit quad in the XY plane facing +Z, glTF UVs with v down: (0,0) at the top left.
    fn quad() -> LocalPrim {
        LocalPrim {
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            normals: vec![Vec3::Z; 4],
            uvs: vec![
                Vec2::new(0.0, 1.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.0, 0.0),
            ],
            tris: vec![[0, 1, 2], [0, 2, 3]],
            ..Default::default()
        }
    }

    #[test]
    fn quad_tangent_is_plus_u_and_bitangent_points_to_the_image_top() {
        let mut q = quad();
        generate(&mut q, 0).unwrap();
        assert_eq!(q.positions.len(), 4, "no split on a plain quad");
        for t in &q.tangents {
            assert!(t.truncate().abs_diff_eq(Vec3::X, 1e-5), "{t}");
            // bitangent = w · n × t = +Y: towards v = 0, the image's top row.
            assert_eq!(t.w, 1.0);
            assert!(
                (Vec3::Z.cross(t.truncate()) * t.w).abs_diff_eq(Vec3::Y, 1e-5),
                "{t}"
            );
        }
    }

    #[test]
    fn mirrored_uvs_flip_the_sign_and_seams_split_vertices() {
        // Two quads sharing the edge x = 1; the right one has its image mirrored in u.
        let mut q = quad();
        q.positions
            .extend([Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 0.0)]);
        q.normals.extend([Vec3::Z; 2]);
        q.uvs.extend([Vec2::new(0.0, 1.0), Vec2::new(0.0, 0.0)]);
        q.tris.extend([[1, 4, 5], [1, 5, 2]]);
        q.colors.push(("Col".into(), vec![Vec4::ONE; 6]));
        generate(&mut q, 0).unwrap();
        // Vertices 1 and 2 lie on the mirror seam: split into two each.
        assert_eq!(q.positions.len(), 8);
        assert_eq!(q.colors[0].1.len(), 8);
        assert_eq!(q.uvs.len(), 8);
        for (f, tri) in q.tris.iter().enumerate() {
            for &v in tri {
                let t = q.tangents[v as usize];
                if f < 2 {
                    assert!(t.truncate().abs_diff_eq(Vec3::X, 1e-5) && t.w == 1.0, "{t}");
                } else {
                    // u runs along -X there; the bitangent still points up, so w = -1.
                    assert!(
                        t.truncate().abs_diff_eq(-Vec3::X, 1e-5) && t.w == -1.0,
                        "{t}"
                    );
                }
            }
        }
    }

    #[test]
    fn without_uvs_it_is_an_error_and_the_primitive_is_untouched() {
        let mut q = quad();
        q.uvs.clear();
        assert!(generate(&mut q, 0).is_err());
        assert!(q.tangents.is_empty());
        // A missing set falls back to set 0.
        let mut q = quad();
        generate(&mut q, 3).unwrap();
        assert_eq!(q.tangents.len(), 4);
    }

    #[test]
    fn mirroring_transforms_flip_the_sign() {
        let t = [Vec4::new(1.0, 0.0, 0.0, 1.0)];
        let w = to_world(&t, Mat4::from_scale(Vec3::new(-2.0, 1.0, 1.0)));
        assert!(
            w[0].abs_diff_eq(Vec4::new(-1.0, 0.0, 0.0, -1.0), 1e-6),
            "{}",
            w[0]
        );
        // The bitangent w · n × t stays the mirrored +Y (a mirror in X keeps +Y).
        let b = Vec3::Z.cross(w[0].truncate()) * w[0].w;
        assert!(b.abs_diff_eq(Vec3::Y, 1e-6), "{b}");
        let w = to_world(&t, Mat4::from_rotation_z(std::f32::consts::FRAC_PI_2));
        assert!(
            w[0].abs_diff_eq(Vec4::new(0.0, 1.0, 0.0, 1.0), 1e-6),
            "{}",
            w[0]
        );
        assert_eq!(
            to_world(&[Vec4::ZERO], Mat4::IDENTITY)[0].truncate(),
            Vec3::ZERO
        );
    }
}
