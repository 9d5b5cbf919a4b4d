//! Point clouds (Blender's PointCloud geometry: Geometry Nodes points, Mesh to Points) as the
//! spheres Cycles renders, built as icospheres.
//!
//! Cycles intersects exact spheres. An icosphere with its vertices on the sphere lies inside
//! it and shows a smaller silhouette; its vertices are pushed out by the factor that gives the
//! mesh the sphere's surface area, and so (Cauchy's formula: a convex body's mean projected
//! area is a quarter of its surface area) the sphere's silhouette area averaged over view
//! directions. Vertex normals are the exact radial directions.

use glam::{Vec3, Vec4};

/// The vertex attribute layer of a point's sphere: the centre (`xyz`, the points' space) and
/// radius (`w`), the same on every vertex of the sphere (Point Info's Position and Radius).
pub const POINT_LAYER: &str = "tesela:point";
/// The vertex attribute layer holding Point Info's Random in `x`.
pub const POINT_RANDOM_LAYER: &str = "tesela:point_random";

/// Icosphere subdivision levels, finest first (20 · 4ᵏ triangles each).
const LEVELS: [u32; 4] = [3, 2, 1, 0];

/// The finest subdivision level whose spheres for `points` points stay within `budget`
/// triangles (the coarsest if none does).
pub fn level_within(points: usize, budget: usize) -> u32 {
    *LEVELS
        .iter()
        .find(|&&k| points.saturating_mul(20 << (2 * k)) <= budget)
        .unwrap_or(&0)
}

/// The vertices of one sphere at subdivision `level` (`10 · 4ᵏ + 2`).
pub fn sphere_vertices(level: u32) -> usize {
    10 * (1 << (2 * level)) + 2
}

/// The unit icosphere of subdivision `level`: vertices on the unit sphere, outward-facing
/// triangles (counter-clockwise seen from outside).
fn icosphere(level: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut verts: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut midpoints = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, verts: &mut Vec<Vec3>| -> u32 {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                verts.push((verts[a as usize] + verts[b as usize]).normalize());
                verts.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let ab = mid(a, b, &mut verts);
            let bc = mid(b, c, &mut verts);
            let ca = mid(c, a, &mut verts);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    (verts, tris)
}

/// The factor that gives the unit icosphere `(verts, tris)` the unit sphere's area `4π`.
fn area_scale(verts: &[Vec3], tris: &[[u32; 3]]) -> f32 {
    let area: f64 = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| verts[i as usize].as_dvec3());
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    (4.0 * std::f64::consts::PI / area).sqrt() as f32
}

/// Spheres in the points' space.
#[derive(Default)]
pub struct Spheres {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    /// See [`POINT_LAYER`].
    pub info: Vec<Vec4>,
    /// See [`POINT_RANDOM_LAYER`].
    pub random: Vec<Vec4>,
    pub tris: Vec<[u32; 3]>,
}

/// The spheres of the points `which` (indices into `centers`, `radii` and `random`) at
/// subdivision `level`. Points with a non-finite centre or radius, or a radius ≤ 0, are left
/// out.
pub fn spheres(
    centers: &[Vec3],
    radii: &[f32],
    random: &[f32],
    which: &[u32],
    level: u32,
) -> Spheres {
    let (unit, unit_tris) = icosphere(level);
    let scale = area_scale(&unit, &unit_tris);
    let mut out = Spheres::default();
    for &i in which {
        let i = i as usize;
        let (c, r) = (centers[i], radii[i]);
        if !(c.is_finite() && r.is_finite() && r > 0.0) {
            continue;
        }
        let base = out.positions.len() as u32;
        out.positions
            .extend(unit.iter().map(|&v| c + v * (r * scale)));
        out.normals.extend_from_slice(&unit);
        out.info
            .extend(std::iter::repeat_n(c.extend(r), unit.len()));
        out.random.extend(std::iter::repeat_n(
            Vec4::new(random[i], 0.0, 0.0, 0.0),
            unit.len(),
        ));
        out.tris
            .extend(unit_tris.iter().map(|t| t.map(|v| v + base)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosphere_is_closed_outward_and_has_the_spheres_area() {
        for level in 0..=3 {
            let (v, t) = icosphere(level);
            assert_eq!(t.len(), 20 << (2 * level));
            assert_eq!(v.len(), sphere_vertices(level));
            // Closed: V - E + F = 2, every edge in two triangles.
            assert_eq!(v.len() + t.len() - t.len() * 3 / 2, 2);
            for tri in &t {
                let [a, b, c] = tri.map(|i| v[i as usize]);
                assert!((b - a).cross(c - a).dot(a + b + c) > 0.0, "inward face");
            }
            let s = area_scale(&v, &t);
            assert!(
                s > 1.0 && s < [1.25, 1.07, 1.02, 1.005][level as usize],
                "{s}"
            );
            // The divergence theorem: the enclosed volume is below the sphere's, the area is
            // the sphere's.
            let scaled: Vec<Vec3> = v.iter().map(|p| *p * s).collect();
            assert!((area_scale(&scaled, &t) - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn level_keeps_the_budget() {
        assert_eq!(level_within(1, 1 << 22), 3);
        assert_eq!(level_within(5000, 1 << 22), 2);
        assert_eq!(level_within(100_000, 1 << 22), 0);
        assert_eq!(level_within(10_000_000, 1 << 22), 0);
    }

    #[test]
    fn spheres_carry_centre_radius_and_random_and_skip_bad_points() {
        let c = [Vec3::new(1.0, 2.0, 3.0), Vec3::NAN, Vec3::ZERO];
        let s = spheres(&c, &[0.5, 1.0, -1.0], &[0.25, 0.5, 0.75], &[0, 1, 2], 1);
        assert_eq!(s.tris.len(), 80);
        assert_eq!(s.positions.len(), 42);
        for (p, n) in s.positions.iter().zip(&s.normals) {
            let d = *p - c[0];
            assert!((d.normalize() - *n).length() < 1e-5);
            assert!(d.length() > 0.5 && d.length() < 0.5 * 1.07);
        }
        assert!(s.info.iter().all(|i| *i == c[0].extend(0.5)));
        assert!(s.random.iter().all(|r| r.x == 0.25));
    }
}
