//! True displacement (Cycles' "Displacement Only" and "Displacement and Bump"): before the BVH
//! is built, the vertices of each mesh whose material displaces are moved by the material
//! output's Displacement evaluated at the vertex, as Cycles' `GeometryManager::displace` moves
//! its mesh vertices (no subdivision: the mesh's own vertices, as Cycles without adaptive
//! subdivision).
//!
//! - One displacement per Blender vertex: the loader's vertices are split where a UV seam or a
//!   sharp edge runs, so vertices at the same position take the displacement of the first
//!   triangle corner there (Cycles evaluates each vertex once, at its first triangle), and the
//!   surface does not crack along seams.
//! - "Displacement Only" then recomputes the normals from the displaced triangles: per group of
//!   vertices sharing position and normal (one smooth vertex of Blender's), the normalised sum
//!   of the unit normals of the triangles around it; a flat face keeps its own normal. "Both"
//!   keeps the interpolated normals, which its bump perturbs.
//! - Meshes placed by instances (object space) are not displaced: reported.

use crate::scene::{Mesh, Scene};
use crate::shading::compile::{CompileError, Displacer, compile_displacement};
use crate::shading::globals::{ShadeEnv, ShaderGlobals, from_blender, to_blender};
use crate::shading::program::with_scratch;
use glam::{Mat4, Vec2, Vec3};
use std::collections::HashMap;

/// Displaces the world-space meshes of `scene` whose material asks for it; returns what could
/// not be displaced, one line per material.
pub fn displace_meshes(scene: &mut Scene, camera_to_world: Mat4) -> Vec<String> {
    let mut warnings = Vec::new();
    let displacers: Vec<Option<Displacer>> = (scene.materials.iter())
        .map(|m| match compile_displacement(m.graph.as_ref()?, &m.name) {
            Ok(d) => d,
            Err(CompileError(e)) => {
                warnings.push(format!("{e}; the vertices are not displaced"));
                None
            }
        })
        .collect();
    if displacers.iter().all(Option::is_none) {
        return warnings;
    }
    let placed = scene.placed_meshes();
    let env = ShadeEnv {
        images: &scene.images,
        textures: &scene.textures,
        camera_to_world,
        window: &crate::camera::NO_WINDOW,
        tracer: None,
    };
    let mut moved = Vec::new();
    for (mi, mesh) in scene.meshes.iter().enumerate() {
        let Some(d) = displacers.get(mesh.material).and_then(Option::as_ref) else {
            continue;
        };
        if placed[mi] {
            let msg = format!(
                "material '{}': mesh '{}' is instanced; its vertices are not displaced ({})",
                scene.materials[mesh.material].name,
                mesh.name,
                if d.renormal {
                    "Displacement Only: the displacement is not rendered"
                } else {
                    "only the bump of Displacement and Bump renders"
                }
            );
            if !warnings.contains(&msg) {
                warnings.push(msg);
            }
            continue;
        }
        moved.push((mi, vertex_offsets(mesh, d, &env), d.renormal));
    }
    for (mi, offsets, renormal_after) in moved {
        let mesh = &mut scene.meshes[mi];
        let before = renormal_after.then(|| mesh.positions.clone());
        for (p, d) in mesh.positions.iter_mut().zip(&offsets) {
            *p += *d;
        }
        if let Some(before) = before {
            renormal(mesh, &before);
        }
    }
    warnings
}

/// The displacement of every vertex of `mesh` (renderer world space), one per position.
fn vertex_offsets(mesh: &Mesh, d: &Displacer, env: &ShadeEnv) -> Vec<Vec3> {
    let mut offsets = vec![Vec3::ZERO; mesh.positions.len()];
    let mut done = vec![false; mesh.positions.len()];
    let mut by_position: HashMap<[u32; 3], Vec3> = HashMap::new();
    const CORNERS: [Vec2; 3] = [Vec2::ZERO, Vec2::X, Vec2::Y];
    with_scratch(|scratch| {
        for (tri, idx) in mesh.indices.iter().enumerate() {
            let [a, b, c] = idx.map(|i| mesh.positions[i as usize]);
            let ng = (b - a).cross(c - a).normalize_or_zero();
            for (corner, &vi) in idx.iter().enumerate() {
                let vi = vi as usize;
                if done[vi] {
                    continue;
                }
                done[vi] = true;
                let p = mesh.positions[vi];
                let key = p.to_array().map(f32::to_bits);
                let off = *by_position.entry(key).or_insert_with(|| {
                    let bc = CORNERS[corner];
                    let n = mesh.shading_normal(tri as u32, bc.x, bc.y).unwrap_or(ng);
                    let uv = mesh.uvs.get(vi).copied().unwrap_or(Vec2::ZERO);
                    let mut g = ShaderGlobals::at(p, n, uv);
                    g.ng = to_blender(ng);
                    g.ray_flags = 0;
                    g.mesh = Some(mesh);
                    g.tri = tri as u32;
                    (g.b1, g.b2) = (bc.x, bc.y);
                    from_blender(d.at(&g, env, scratch))
                });
                offsets[vi] = off;
            }
        }
    });
    offsets
}

/// New unit normals (and tangents kept orthogonal to them) for `mesh` after its positions
/// moved from `before`: each vertex takes the normalised sum of the unit normals of the
/// triangles around every vertex that shared its position and normal.
fn renormal(mesh: &mut Mesh, before: &[Vec3]) {
    if mesh.normals.len() != mesh.positions.len() {
        return;
    }
    let key = |i: usize| {
        let (p, n) = (before[i].to_array(), mesh.normals[i].to_array());
        [p[0], p[1], p[2], n[0], n[1], n[2]].map(f32::to_bits)
    };
    let mut sums: HashMap<[u32; 6], Vec3> = HashMap::new();
    for idx in &mesh.indices {
        let [a, b, c] = idx.map(|i| mesh.positions[i as usize]);
        let n = (b - a).cross(c - a).normalize_or_zero();
        let mut seen: [Option<[u32; 6]>; 3] = [None; 3];
        for (k, &vi) in idx.iter().enumerate() {
            let key = key(vi as usize);
            // A triangle counts once per group, even if two of its corners are in it.
            if seen[..k].contains(&Some(key)) {
                continue;
            }
            seen[k] = Some(key);
            *sums.entry(key).or_insert(Vec3::ZERO) += n;
        }
    }
    let normals: Vec<Vec3> = (0..mesh.normals.len())
        .map(|i| {
            let s = sums.get(&key(i)).copied().unwrap_or(Vec3::ZERO);
            s.try_normalize().unwrap_or(mesh.normals[i])
        })
        .collect();
    for (t, n) in mesh.attrs.tangents.iter_mut().zip(&normals) {
        let v = t.truncate();
        if let Some(v) = (v - *n * n.dot(v)).try_normalize() {
            *t = v.extend(t.w);
        }
    }
    mesh.normals = normals;
}
