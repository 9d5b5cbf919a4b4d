//! What a material's program reads at a shading point (Cycles' `ShaderData`) and the
//! scene-wide data it may look up (images, the camera).
//!
//! Graph programs work in **Blender's coordinates** (Z up), as the node graph was authored:
//! positions, normals and directions are converted from the renderer's Y-up world once, here,
//! and BSDF normals back when the closures are read.

use crate::scene::{Image, Instance, Mesh, ObjectInfo, Texture};
use glam::{Mat4, Vec2, Vec3, Vec4};

/// Renderer world (glTF, Y up) → Blender world (Z up).
#[inline(always)]
pub fn to_blender(v: Vec3) -> Vec3 {
    Vec3::new(v.x, -v.z, v.y)
}

/// Blender world (Z up) → renderer world (glTF, Y up).
#[inline(always)]
pub fn from_blender(v: Vec3) -> Vec3 {
    Vec3::new(v.x, v.z, -v.y)
}

/// Bits of [`ShaderGlobals::ray_flags`]: what kind of ray reached the point (Light Path node).
pub mod ray {
    pub const CAMERA: u32 = 1;
    pub const SHADOW: u32 = 2;
    pub const DIFFUSE: u32 = 4;
    pub const GLOSSY: u32 = 8;
    pub const SINGULAR: u32 = 16;
    pub const REFLECTION: u32 = 32;
    pub const TRANSMISSION: u32 = 64;
    /// Not a Light Path bit: the world is being evaluated for its importance map, which leaves
    /// out a sun disc that is sampled apart (Cycles' `PATH_RAY_IMPORTANCE_BAKE`).
    pub const IMPORTANCE_BAKE: u32 = 128;
    /// A ray scattered inside a volume (Cycles' `PATH_RAY_VOLUME_SCATTER`; the Light Path
    /// node's ray kinds are all false for it, as in Cycles).
    pub const VOLUME: u32 = 256;
}

/// A surface of one object met by a local ray ([`Tracer::local_hits`]), Blender world space.
#[derive(Clone, Copy, Debug, Default)]
pub struct LocalHit {
    pub p: Vec3,
    /// Unit shading normal as interpolated (not turned towards the ray).
    pub n: Vec3,
    /// Unit geometric normal.
    pub ng: Vec3,
}

/// Rays a program may cast (the Ambient Occlusion and Bevel nodes): the scene's geometry.
pub trait Tracer: Sync {
    /// Whether a surface lies on the segment from shading point `g` (moved off its surface)
    /// along the unit direction `d` (Blender world space) up to distance `tmax`; with
    /// `only_local`, only the surfaces of `g`'s own object count.
    fn blocked(&self, g: &ShaderGlobals, d: Vec3, tmax: f32, only_local: bool) -> bool;

    /// The surfaces of `g`'s object on the segment from `o` along the unit direction `d` up
    /// to `tmax` (Blender world space), nearest first, as many as `hits` holds; returns how
    /// many were written.
    fn local_hits(
        &self,
        g: &ShaderGlobals,
        o: Vec3,
        d: Vec3,
        tmax: f32,
        hits: &mut [LocalHit],
    ) -> usize;
}

/// Scene data a program may look up.
#[derive(Clone, Copy)]
pub struct ShadeEnv<'a> {
    pub images: &'a [Image],
    pub textures: &'a [Texture],
    /// Camera to world, Blender coordinates (the camera looks down its local -Z).
    pub camera_to_world: Mat4,
    /// The camera's Window coordinates.
    pub window: &'a crate::camera::WindowMap,
    /// The scene's geometry for the rays a program casts; `None` where there is none to
    /// trace (emitters' set-up, tests): such rays see nothing.
    pub tracer: Option<&'a dyn Tracer>,
}

/// A shading point. Vectors in Blender's world space unless said otherwise.
#[derive(Clone, Copy)]
pub struct ShaderGlobals<'a> {
    pub p: Vec3,
    /// Unit shading normal, flipped to the side the ray came from (Cycles' `N`).
    pub n: Vec3,
    /// `n` is no longer the interpolated normal: a displacement rendered as bump replaced it.
    pub n_displaced: bool,
    /// Unit geometric normal, on the same side as `n`.
    pub ng: Vec3,
    /// Unit direction from the point towards the ray's origin (Cycles' `I`).
    pub i: Vec3,
    /// The ray met the back of the surface (the side its geometric normal points away from).
    pub backfacing: bool,
    /// The mesh, triangle and barycentrics `(b1, b2)` of the point, when on a mesh.
    pub mesh: Option<&'a Mesh>,
    /// The instance placing `mesh` (then the mesh's data is in its object space).
    pub instance: Option<&'a Instance>,
    pub tri: u32,
    pub b1: f32,
    pub b2: f32,
    /// UV set 0 at the point, glTF convention (already interpolated).
    pub uv0: Vec2,
    /// World-space size of the offsets a Bump node differentiates over (a small fraction of
    /// the pixel footprint; Cycles uses ray differentials and a 0.1-pixel filter width).
    pub bump_step: f32,
    /// Path vertex index of the point (1 = seen from the camera).
    pub ray_depth: u32,
    /// The path's bounces of each kind before the point.
    pub depths: PathDepths,
    /// Distance from the ray's origin to the point (Light Path's Ray Length; 0 without a ray).
    pub ray_length: f32,
    pub ray_flags: u32,
    /// `[mesh, instance]` of the point's object (scene indices; `u32::MAX` for none).
    pub object: [u32; 2],
    /// Scrambles the random numbers of the rays the program casts at this point; kept by the
    /// Bump node's offset points so their rays agree.
    pub seed: u32,
    /// The path's shutter time (motion blur): where a moving instance is.
    pub time: f32,
}

/// Bounces of each kind a path has made before the current vertex, as Cycles' path state
/// counts them (what Light Path's Diffuse, Glossy, Transmission and Transparent Depth read): a
/// scattering bounce counts as transmission when it crosses the surface, else as diffuse or
/// glossy; passing straight through a transparent surface counts as transparent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PathDepths {
    pub diffuse: u16,
    pub glossy: u16,
    pub transmission: u16,
    pub transparent: u16,
}

impl<'a> ShaderGlobals<'a> {
    /// A point with only position, normal and UV (tests, emitters without mesh data).
    pub fn at(p: Vec3, n: Vec3, uv0: Vec2) -> ShaderGlobals<'static> {
        let (p, n) = (to_blender(p), to_blender(n));
        ShaderGlobals {
            p,
            n,
            n_displaced: false,
            ng: n,
            i: n,
            backfacing: false,
            mesh: None,
            instance: None,
            tri: 0,
            b1: 0.0,
            b2: 0.0,
            uv0,
            bump_step: 1e-4,
            ray_depth: 1,
            depths: PathDepths::default(),
            ray_length: 0.0,
            ray_flags: ray::CAMERA,
            object: [u32::MAX; 2],
            seed: 0,
            time: 0.5,
        }
    }

    /// The two surface directions a Bump node differentiates along (Blender world space,
    /// orthogonal to `ng`, of length `bump_step`).
    #[inline]
    pub fn bump_axes(&self) -> (Vec3, Vec3) {
        let f = crate::frame::Frame::from_normal(self.ng);
        (f.s * self.bump_step, f.t * self.bump_step)
    }

    /// The shading point moved along bump axis 1 or 2: position, barycentrics and UV set 0
    /// move with it (so every attribute is read at the moved point); the normals stay.
    pub fn offset(&self, axis: u8) -> ShaderGlobals<'a> {
        let (dx, dy) = self.bump_axes();
        let dp = if axis == 1 { dx } else { dy };
        let mut g = *self;
        g.p += dp;
        if let Some(m) = self.mesh {
            let [i0, i1, i2] = m.corners(self.tri);
            let (e1, e2) = (
                self.mesh_to_world(m.positions[i1] - m.positions[i0]),
                self.mesh_to_world(m.positions[i2] - m.positions[i0]),
            );
            // dP = db1 e1 + db2 e2 in the triangle's plane (least squares, glTF space).
            let d = from_blender(dp);
            let (a, b, c) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
            let (r1, r2) = (d.dot(e1), d.dot(e2));
            let det = a * c - b * b;
            if det.abs() > 1e-30 && det.is_finite() {
                g.b1 += (c * r1 - b * r2) / det;
                g.b2 += (a * r2 - b * r1) / det;
                g.uv0 = m.uv(0, g.tri, g.b1, g.b2);
            }
        }
        g
    }

    /// UV set `set` in glTF's convention (`(0, 0)` top-left).
    #[inline]
    pub fn uv_gltf(&self, set: usize) -> Vec2 {
        if set == 0 {
            return self.uv0;
        }
        match self.mesh {
            Some(m) => m.uv(set, self.tri, self.b1, self.b2),
            None => Vec2::ZERO,
        }
    }

    /// A UV map by name (`""`: the first) in Blender's convention: `(u, 1 - v_glTF, 0)`.
    #[inline]
    pub fn uv_named(&self, name: &str) -> Vec3 {
        let set = self.mesh.and_then(|m| m.uv_set(name)).unwrap_or(0);
        let uv = self.uv_gltf(set);
        Vec3::new(uv.x, 1.0 - uv.y, 0.0)
    }

    /// A colour attribute by name (`""`: the first), linear RGBA; black without one.
    pub fn color_attribute(&self, name: &str) -> Option<Vec4> {
        let m = self.mesh?;
        let set = if name.is_empty() {
            m.attrs.colors.first()
        } else {
            m.attrs.colors.iter().find(|(n, _)| n == name)
        }?;
        m.interpolate(&set.1, self.tri, self.b1, self.b2)
    }

    /// A vector of the mesh's space in the renderer's world space (glTF axes).
    #[inline(always)]
    fn mesh_to_world(&self, v: Vec3) -> Vec3 {
        match self.instance {
            Some(i) => i.to_world_at(self.time).transform_vector3(v),
            None => v,
        }
    }

    /// The corners of the point's triangle, Blender world space, when on a mesh.
    #[inline]
    pub fn triangle(&self) -> Option<[Vec3; 3]> {
        let m = self.mesh?;
        let corners = m.corners(self.tri).map(|i| m.positions[i]);
        Some(corners.map(|p| {
            to_blender(match self.instance {
                Some(i) => i.to_world_at(self.time).transform_point3(p),
                None => p,
            })
        }))
    }

    /// Renderer world (glTF axes) → object space, when on a mesh: the instance's inverse
    /// transform followed by the mesh's own world → object map.
    #[inline]
    pub fn to_object(&self) -> Option<Mat4> {
        let m = self.mesh?;
        Some(match self.instance {
            Some(i) => m.attrs.to_object * i.to_world_at(self.time).inverse(),
            None => m.attrs.to_object,
        })
    }

    /// The linear part of the object → world map (object axes as the add-on wrote them, the
    /// renderer's world axes), when on an object with an invertible transform.
    #[inline]
    pub fn object_to_world_linear(&self) -> Option<glam::Mat3> {
        let a = glam::Mat3::from_mat4(self.to_object()?).inverse();
        a.is_finite().then_some(a)
    }

    /// A world normal `n` (Blender axes) in object space, unit (Cycles'
    /// `object_inverse_normal_transform`: the transposed object map); `n` off an object.
    #[inline]
    pub fn normal_to_object(&self, n: Vec3) -> Vec3 {
        match self.object_to_world_linear() {
            Some(a) => (a.transpose() * from_blender(n)).normalize_or_zero(),
            None => n,
        }
    }

    /// Blender's Object Info of the point's object (the instance's own, if placed).
    #[inline]
    pub fn object_info(&self) -> Option<&'a ObjectInfo> {
        match (self.instance, self.mesh) {
            (Some(i), _) => Some(&i.object),
            (None, Some(m)) => Some(&m.attrs.object),
            _ => None,
        }
    }

    /// Position in object space (the object's own coordinates, as the add-on wrote them).
    #[inline]
    pub fn object_position(&self) -> Vec3 {
        match self.to_object() {
            Some(m) => m.transform_point3(from_blender(self.p)),
            None => self.p,
        }
    }

    /// World → object transform for directions (unnormalised).
    #[inline]
    pub fn object_direction(&self, v: Vec3) -> Vec3 {
        match self.to_object() {
            Some(m) => m.transform_vector3(from_blender(v)),
            None => v,
        }
    }

    /// Blender's Generated coordinates: the object-space position (before deform modifiers,
    /// where the mesh carries that) normalised to the texture space (the mesh's bounds unless
    /// the add-on says otherwise).
    pub fn generated(&self) -> Vec3 {
        let Some(m) = self.mesh else {
            return self.object_position();
        };
        let po = m
            .interpolate(&m.attrs.orco, self.tri, self.b1, self.b2)
            .unwrap_or_else(|| self.object_position());
        match m.attrs.texspace {
            Some((loc, size)) => {
                let s = Vec3::select(size.cmpeq(Vec3::ZERO), Vec3::ONE, size);
                (po - loc) / s * 0.5 + Vec3::splat(0.5)
            }
            None => po,
        }
    }

    /// Unit tangent (along +u of UV set 0) and bitangent sign, Blender world space: the mesh's
    /// vertex tangents when it has them, else the triangle's `dp/du`.
    pub fn tangent(&self) -> Option<(Vec3, f32)> {
        let m = self.mesh?;
        // A mirroring instance flips the bitangent's handedness (as baking it does).
        let mirror = self.instance.is_some_and(|i| i.mirrors());
        if let Some(t) = m.interpolate(&m.attrs.tangents, self.tri, self.b1, self.b2) {
            let v = to_blender(self.mesh_to_world(t.truncate()));
            let l = v.length();
            if l > 1e-12 && l.is_finite() {
                return Some((v / l, if (t.w < 0.0) != mirror { -1.0 } else { 1.0 }));
            }
        }
        // dp/du from the triangle (glTF uv: v runs down, Blender's up).
        if m.uvs.is_empty() {
            return None;
        }
        let [i0, i1, i2] = m.corners(self.tri);
        let (p0, p1, p2) = (m.positions[i0], m.positions[i1], m.positions[i2]);
        let (e1, e2) = (self.mesh_to_world(p1 - p0), self.mesh_to_world(p2 - p0));
        let (t0, t1, t2) = (m.uvs[i0], m.uvs[i1], m.uvs[i2]);
        let (du1, dv1) = (t1.x - t0.x, t0.y - t1.y);
        let (du2, dv2) = (t2.x - t0.x, t0.y - t2.y);
        let det = du1 * dv2 - du2 * dv1;
        if det.abs() < 1e-20 {
            return None;
        }
        let dpdu = (e1 * dv2 - e2 * dv1) / det;
        let dpdv = (e2 * du1 - e1 * du2) / det;
        // The front side's normal: a mirrored instance's edges turn the other way.
        let ng = e1.cross(e2);
        let sign = if (ng.cross(dpdu).dot(dpdv) < 0.0) != mirror {
            -1.0
        } else {
            1.0
        };
        let v = to_blender(dpdu);
        let l = v.length();
        (l > 1e-20 && l.is_finite()).then(|| (v / l, sign))
    }
}
