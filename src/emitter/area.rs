//! Mesh area lights (the seed's core): a triangle is chosen with probability proportional to
//! its area (a discrete CDF), then a uniform point on it from barycentrics `(u, v)`,
//! `w = 1 - u - v`. Position, shading normal and texture coordinates are interpolated (the
//! geometric normal stands in when the mesh has no normals). The point density is `1/A` per
//! unit area (`A` = total area); per solid angle at the reference point it is
//! `p_A · d² / |cos θ_l|`.

use super::{Emitter, EmitterQueryRecord, luminance};
use crate::sampling::{DiscreteCdf, square_to_uniform_triangle};
use crate::scene::{Mesh, Scene};
use crate::texture;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Smallest barycentric weight of a sampled point (see [`AreaEmitter::sample_point`]).
pub const EDGE_MARGIN: f32 = 1e-5;

#[derive(Clone, Debug)]
pub struct AreaEmitter {
    /// Index of the emissive mesh in [`Scene::meshes`].
    pub mesh: usize,
    /// Triangle choice proportional to area.
    pub cdf: DiscreteCdf,
    /// Total area `A` (m²).
    pub area: f32,
    /// Emitted radiance factor (W m⁻² sr⁻¹), times the emissive texture if any.
    pub radiance: Vec3,
    pub two_sided: bool,
}

/// Geometric (unnormalised) normal of triangle `i` by the right-hand rule: its length is twice
/// the area.
#[inline]
pub fn triangle_cross(mesh: &Mesh, i: usize) -> Vec3 {
    let [a, b, c] = mesh.indices[i];
    let (p0, p1, p2) = (
        mesh.positions[a as usize],
        mesh.positions[b as usize],
        mesh.positions[c as usize],
    );
    (p1 - p0).cross(p2 - p0)
}

impl AreaEmitter {
    /// An emitter for `scene.meshes[mesh]`, or `None` if its emissive area is zero.
    pub fn new(scene: &Scene, mesh: usize) -> Option<AreaEmitter> {
        let m = &scene.meshes[mesh];
        let material = &scene.materials[m.material];
        let areas: Vec<f32> = (0..m.indices.len())
            .map(|i| 0.5 * triangle_cross(m, i).length())
            .collect();
        let cdf = DiscreteCdf::new(areas.iter().copied());
        if cdf.is_empty() {
            return None;
        }
        Some(AreaEmitter {
            mesh,
            area: cdf.sum(),
            cdf,
            radiance: material.emission,
            two_sided: material.emission_two_sided,
        })
    }

    /// Radiance factor at texture coordinates `uv` (before the sidedness test).
    #[inline]
    fn radiance_at(&self, scene: &Scene, uv: Vec2) -> Vec3 {
        let material = &scene.materials[scene.meshes[self.mesh].material];
        match material.emission_texture {
            Some(t) => {
                let tex = &scene.textures[t.texture];
                self.radiance * texture::lookup(tex, &scene.images[tex.image], uv, true).truncate()
            }
            None => self.radiance,
        }
    }

    /// Chooses a triangle with probability proportional to its area, and the two numbers that
    /// place the point on it. The triangle is chosen with a 48-bit number made of both
    /// coordinates of `u`, so that the choice stays proportional to area on meshes with millions
    /// of triangles (a 24-bit number alone quantises every probability to 2^-24); the rescaled
    /// remainder is split into its high bits and its next bits (for a mesh of one or two
    /// triangles these are `u.x` and `u.y` again).
    #[inline]
    pub fn choose_triangle(&self, u: Vec2) -> (usize, f32, f32) {
        let t = u.x as f64 + u.y as f64 * (1.0 / 16_777_216.0);
        let (tri, r) = self.cdf.sample_fine(t);
        // 2^⌊bits/2⌋ for the `bits = 48 + ⌊log2 pmf⌋` bits of `t` the triangle's interval
        // spans, from the exponent field of the (positive, normal) double `pmf`.
        let log2_pmf = ((self.cdf.pmf_fine(tri).to_bits() >> 52) & 0x7ff) as i64 - 1023;
        let bits = (48 + log2_pmf).max(2);
        let scale = (1u32 << (bits / 2).clamp(1, 24)) as f64;
        const BELOW_ONE: f32 = 1.0 - f32::EPSILON / 2.0;
        (
            tri,
            (r as f32).min(BELOW_ONE),
            // The fractional part (`r * scale < 2^24`: the integer conversion is exact and,
            // unlike `fract`, no library call on baseline x86-64).
            ((r * scale - (r * scale) as u64 as f64) as f32).min(BELOW_ONE),
        )
    }

    /// Uniform point on the mesh: `(position, shading normal, geometric unit normal, uv)`.
    #[inline]
    pub fn sample_point(&self, mesh: &Mesh, u: Vec2) -> (Vec3, Vec3, Vec3, Vec2) {
        let (tri, ua, ub) = self.choose_triangle(u);
        let b = square_to_uniform_triangle(Vec2::new(ua, ub));
        // Keep the point off the triangle's edges, where a light that touches other geometry
        // would end its shadow ray exactly on that geometry (a leak). This trims a band of
        // relative area 6e-5 next to the edges.
        let (b1, b2) = (
            b.x * (1.0 - 3.0 * EDGE_MARGIN) + EDGE_MARGIN,
            b.y * (1.0 - 3.0 * EDGE_MARGIN) + EDGE_MARGIN,
        );
        let b0 = 1.0 - b1 - b2;
        let [i0, i1, i2] = mesh.indices[tri].map(|i| i as usize);
        let (p0, p1, p2) = (mesh.positions[i0], mesh.positions[i1], mesh.positions[i2]);
        let p = p0 * b0 + p1 * b1 + p2 * b2;
        let ng = (p1 - p0).cross(p2 - p0).normalize();
        let mut n = ng;
        if !mesh.normals.is_empty() {
            let s = mesh.normals[i0] * b0 + mesh.normals[i1] * b1 + mesh.normals[i2] * b2;
            let l = s.length();
            if l > 1e-12 && l.is_finite() {
                n = s / l;
            }
        }
        let ng = if ng.dot(n) < 0.0 { -ng } else { ng };
        let uv = if mesh.uvs.is_empty() {
            Vec2::ZERO
        } else {
            mesh.uvs[i0] * b0 + mesh.uvs[i1] * b1 + mesh.uvs[i2] * b2
        };
        (p, n, ng, uv)
    }
}

impl Emitter for AreaEmitter {
    #[inline]
    fn sample(&self, scene: &Scene, rec: &mut EmitterQueryRecord, u: Vec2) -> Vec3 {
        let mesh = &scene.meshes[self.mesh];
        let (p, n, ng, uv) = self.sample_point(mesh, u);
        let d = p - rec.ref_p;
        let dist2 = d.length_squared();
        if dist2 <= 0.0 || !dist2.is_finite() {
            return Vec3::ZERO;
        }
        let dist = dist2.sqrt();
        rec.p = p;
        rec.n = n;
        rec.ng = ng;
        rec.uv = uv;
        rec.wi = d / dist;
        rec.dist = dist;
        rec.pdf = self.pdf(scene, rec);
        if rec.pdf <= 0.0 || !rec.pdf.is_finite() {
            return Vec3::ZERO;
        }
        self.eval(scene, rec) / rec.pdf
    }

    #[inline]
    fn eval(&self, scene: &Scene, rec: &EmitterQueryRecord) -> Vec3 {
        let cos = rec.n.dot(-rec.wi);
        if !self.two_sided && cos <= 0.0 {
            return Vec3::ZERO;
        }
        self.radiance_at(scene, rec.uv)
    }

    #[inline]
    fn pdf(&self, _scene: &Scene, rec: &EmitterQueryRecord) -> f32 {
        let cos = rec.ng.dot(rec.wi).abs();
        if cos <= 0.0 {
            return 0.0;
        }
        rec.dist * rec.dist / (cos * self.area)
    }

    fn power(&self, _scene: &Scene, _r: f32) -> f32 {
        let sides = if self.two_sided { 2.0 } else { 1.0 };
        luminance(self.radiance) * PI * self.area * sides
    }

    fn is_delta(&self) -> bool {
        false
    }
}
