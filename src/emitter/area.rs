//! Mesh area lights (the seed's core): a triangle is chosen with probability proportional to
//! its area (a discrete CDF), then a point on it. Position, shading normal and texture
//! coordinates are interpolated (the geometric normal stands in when the mesh has no normals).
//!
//! The point is uniform in area, barycentrics `(u, v)`, `w = 1 - u - v`: density `1/A` per unit
//! area (`A` = total area), per solid angle at the reference point `d² / (A |cos θ_l|)`. Where
//! the triangle is large against its distance (its longest edge longer than the reference
//! point's distance to its plane, Cycles' rule), `d² / cos θ_l` varies too much and the
//! direction is drawn uniformly over the triangle's solid angle `Ω` instead: density
//! `(A_t / A) / Ω` per solid angle for a triangle of area `A_t`
//! ([`super::spherical_triangle`]).

use super::spherical_triangle::{SphericalTriangle, barycentrics_along};
use super::{Emitter, EmitterQueryRecord, emitted_luminance};
use crate::sampling::{DiscreteCdf, square_to_uniform_triangle};
use crate::scene::{Mesh, Scene};
use crate::shading::Program;
use crate::shading::globals::{ShadeEnv, ShaderGlobals, to_blender};
use glam::{Mat4, Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

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
    /// Mean emitted radiance (W m⁻² sr⁻¹) over the mesh, for the light choice.
    pub radiance: Vec3,
    /// The material's shading program, which gives the radiance at each point.
    pub program: Arc<Program>,
    pub two_sided: bool,
    /// Camera to world, Blender coordinates, for the program's camera-space inputs.
    pub camera_to_world: Mat4,
    /// The camera's Window coordinates, shared with the render scene.
    pub window: Arc<crate::camera::WindowMap>,
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
        let program =
            crate::shading::material_program(&scene.materials[m.material], &scene.textures);
        AreaEmitter::with_program(scene, mesh, Arc::new(program.program))
    }

    /// An emitter for `scene.meshes[mesh]` whose radiance is `program`'s emission.
    pub fn with_program(scene: &Scene, mesh: usize, program: Arc<Program>) -> Option<AreaEmitter> {
        let m = &scene.meshes[mesh];
        let material = &scene.materials[m.material];
        let areas: Vec<f32> = (0..m.indices.len())
            .map(|i| 0.5 * triangle_cross(m, i).length())
            .collect();
        let cdf = DiscreteCdf::new(areas.iter().copied());
        if cdf.is_empty() {
            return None;
        }
        let area = cdf.sum();
        // Mean radiance: area-weighted over (up to 4096) triangle centroids.
        let step = (m.indices.len() / 4096).max(1);
        let (mut sum, mut weight) = (Vec3::ZERO, 0.0f32);
        let varying = if program.is_empty() {
            0
        } else {
            m.indices.len()
        };
        let env = ShadeEnv {
            images: &scene.images,
            textures: &scene.textures,
            camera_to_world: Mat4::IDENTITY,
            window: &crate::camera::NO_WINDOW,
            tracer: None,
        };
        for i in (0..varying).step_by(step) {
            let third = 1.0 / 3.0;
            let le = radiance(&program, m, i as u32, Vec2::splat(third), None, &env);
            sum += le * areas[i];
            weight += areas[i];
        }
        let radiance = if program.is_empty() {
            radiance(&program, m, 0, Vec2::ZERO, None, &env)
        } else if weight > 0.0 {
            sum / weight
        } else {
            Vec3::ZERO
        };
        Some(AreaEmitter {
            mesh,
            area,
            cdf,
            radiance,
            program,
            two_sided: material.emission_two_sided,
            camera_to_world: Mat4::IDENTITY,
            window: Arc::new(crate::camera::WindowMap::none()),
        })
    }

    /// The emitter with the camera its program's camera-space inputs refer to.
    pub fn with_camera(
        self,
        camera_to_world: Mat4,
        window: Arc<crate::camera::WindowMap>,
    ) -> AreaEmitter {
        AreaEmitter {
            camera_to_world,
            window,
            ..self
        }
    }

    /// Radiance at the point of `rec` towards `rec.ref_p` (before the sidedness test).
    #[inline]
    fn radiance_at(&self, scene: &Scene, rec: &EmitterQueryRecord) -> Vec3 {
        let env = ShadeEnv {
            images: &scene.images,
            textures: &scene.textures,
            camera_to_world: self.camera_to_world,
            window: &self.window,
            tracer: None,
        };
        let m = &scene.meshes[self.mesh];
        radiance(&self.program, m, rec.tri, rec.bary, Some(rec), &env)
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

    /// Uniform point on the mesh: `(position, shading normal, geometric unit normal, uv,
    /// triangle, barycentrics)`.
    #[inline]
    pub fn sample_point(&self, mesh: &Mesh, u: Vec2) -> (Vec3, Vec3, Vec3, Vec2, u32, Vec2) {
        let (tri, ua, ub) = self.choose_triangle(u);
        let b = square_to_uniform_triangle(Vec2::new(ua, ub));
        let (p, n, ng, uv, bary) = point_at(mesh, tri, b);
        (p, n, ng, uv, tri as u32, bary)
    }

    /// When triangle `tri` is sampled by solid angle from `ref_p` (see the module notes): the
    /// spherical triangle, the triangle's vertices and the density of its directions, `(A_t /
    /// A) / Ω` per unit solid angle; `None` when it is sampled by area.
    #[inline]
    fn solid_angle_sampling(
        &self,
        mesh: &Mesh,
        tri: usize,
        ref_p: Vec3,
    ) -> Option<(SphericalTriangle, [Vec3; 3], f32)> {
        let v = mesh.indices[tri].map(|i| mesh.positions[i as usize]);
        let (e0, e1, e2) = (v[1] - v[0], v[2] - v[0], v[2] - v[1]);
        let longest2 = e0
            .length_squared()
            .max(e1.length_squared())
            .max(e2.length_squared());
        let n = e0.cross(e1);
        // Distance to the plane, squared: (n · (v0 − p))² / |n|².
        let h = n.dot(v[0] - ref_p);
        if longest2 * n.length_squared() <= h * h {
            return None;
        }
        let st = SphericalTriangle::new(ref_p, v)?;
        let share = 0.5 * n.length() / self.area;
        Some((st, v, share / st.solid_angle()))
    }

    /// The solid-angle density of `rec`'s point: `solid` when its triangle is sampled by
    /// solid angle, else the area density `1/A` converted, `d² / (A |cos θ_l|)`; 0 seen edge-on.
    #[inline]
    fn density(&self, rec: &EmitterQueryRecord, solid: Option<f32>) -> f32 {
        let cos = rec.ng.dot(rec.wi).abs();
        if cos <= 0.0 {
            return 0.0;
        }
        solid.unwrap_or_else(|| rec.dist * rec.dist / (cos * self.area))
    }
}

/// The point at barycentrics `b` of triangle `tri`, moved off its edges: `(position, shading
/// normal, geometric unit normal on the shading normal's side, uv, barycentrics)`.
#[inline]
fn point_at(mesh: &Mesh, tri: usize, b: Vec2) -> (Vec3, Vec3, Vec3, Vec2, Vec2) {
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
    let tri = tri as u32;
    let n = mesh.shading_normal(tri, b1, b2).unwrap_or(ng);
    let ng = if ng.dot(n) < 0.0 { -ng } else { ng };
    let uv = mesh
        .interpolate(&mesh.uvs, tri, b1, b2)
        .unwrap_or(Vec2::ZERO);
    (p, n, ng, uv, Vec2::new(b1, b2))
}

/// The emission of `program` at barycentrics `b` of triangle `tri` of `mesh`, seen along
/// `rec.wi` from `rec.ref_p` (`rec.n`, `rec.ng`: the shading and geometric normals there, on
/// one side). The shading point is the one a ray from `rec.ref_p` hitting the point would
/// have ([`crate::render_scene::RenderScene::globals`]): incoming direction `-rec.wi`,
/// normals flipped towards it, backfacing when `rec.ng · rec.wi > 0`, ray length `rec.dist`;
/// so a light sample and a BSDF ray reaching the same point from the same side see the same
/// radiance. Without `rec` (the mean radiance for the light choice) the point is seen along
/// its normal.
#[inline]
fn radiance(
    program: &Program,
    mesh: &Mesh,
    tri: u32,
    b: Vec2,
    rec: Option<&EmitterQueryRecord>,
    env: &ShadeEnv,
) -> Vec3 {
    if program.is_empty() {
        return program.emission(&ShaderGlobals::at(Vec3::ZERO, Vec3::Z, Vec2::ZERO), &ENV0);
    }
    let p = mesh
        .interpolate(&mesh.positions, tri, b.x, b.y)
        .unwrap_or(Vec3::ZERO);
    let uv = mesh
        .interpolate(&mesh.uvs, tri, b.x, b.y)
        .unwrap_or(Vec2::ZERO);
    let mut g = match rec {
        Some(rec) => {
            let backfacing = rec.ng.dot(rec.wi) > 0.0;
            let (n, ng) = if backfacing {
                (-rec.n, -rec.ng)
            } else {
                (rec.n, rec.ng)
            };
            let mut g = ShaderGlobals::at(p, n, uv);
            g.ng = to_blender(ng);
            g.i = to_blender(-rec.wi);
            g.backfacing = backfacing;
            g.ray_length = rec.dist;
            g.ray_flags = rec.ray_flags;
            g.ray_depth = rec.depth.max(1);
            g.depths = rec.depths;
            g.bump_step = rec.dist.max(1e-3) * 1e-4;
            g
        }
        None => {
            let ng = triangle_cross(mesh, tri as usize).normalize_or_zero();
            let n = mesh.shading_normal(tri, b.x, b.y).unwrap_or(ng);
            let mut g = ShaderGlobals::at(p, n, uv);
            g.ng = to_blender(if ng.dot(n) < 0.0 { -ng } else { ng });
            // No ray: a nominal metre, so an emission scaled by the ray length (Light
            // Falloff's Linear and Constant) still counts in the light choice.
            g.ray_length = 1.0;
            g.ray_flags = 0;
            g
        }
    };
    g.mesh = Some(mesh);
    g.tri = tri;
    g.b1 = b.x;
    g.b2 = b.y;
    program.emission(&g, env)
}

const ENV0: ShadeEnv<'static> = ShadeEnv {
    images: &[],
    textures: &[],
    camera_to_world: Mat4::IDENTITY,
    window: &crate::camera::NO_WINDOW,
    tracer: None,
};

impl Emitter for AreaEmitter {
    #[inline]
    fn sample(&self, scene: &Scene, rec: &mut EmitterQueryRecord, u: Vec2) -> Vec3 {
        let mesh = &scene.meshes[self.mesh];
        let (tri, ua, ub) = self.choose_triangle(u);
        // The solid-angle density, when sampled by solid angle (the same as `pdf` gives).
        let (b, solid_pdf) = match self.solid_angle_sampling(mesh, tri, rec.ref_p) {
            Some((st, v, pdf)) => {
                match barycentrics_along(rec.ref_p, st.sample(Vec2::new(ua, ub)), v) {
                    Some(b) => (b, Some(pdf)),
                    None => return Vec3::ZERO,
                }
            }
            None => (square_to_uniform_triangle(Vec2::new(ua, ub)), None),
        };
        let (p, n, ng, uv, bary) = point_at(mesh, tri, b);
        let tri = tri as u32;
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
        rec.tri = tri;
        rec.bary = bary;
        rec.wi = d / dist;
        rec.dist = dist;
        rec.pdf = self.density(rec, solid_pdf);
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
        self.radiance_at(scene, rec)
    }

    #[inline]
    fn pdf(&self, scene: &Scene, rec: &EmitterQueryRecord) -> f32 {
        let mesh = &scene.meshes[self.mesh];
        let tri = rec.tri as usize;
        let solid = (tri < mesh.indices.len())
            .then(|| self.solid_angle_sampling(mesh, tri, rec.ref_p))
            .flatten();
        self.density(rec, solid.map(|(_, _, pdf)| pdf))
    }

    fn power(&self, _scene: &Scene, _r: f32) -> f32 {
        let sides = if self.two_sided { 2.0 } else { 1.0 };
        emitted_luminance(self.radiance) * PI * self.area * sides
    }

    fn is_delta(&self) -> bool {
        false
    }
}
