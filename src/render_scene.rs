//! A scene prepared for rendering: the BVH, the emitters and the light-selection
//! distribution, with the surface queries the integrators need.

use crate::accel::{Accel, offset_origin};
use crate::bsdf::SurfaceParams;
use crate::emitter::{
    AreaEmitter, Background, Directional, Emitter, EmitterInstance, EmitterQueryRecord,
    LightChoice, LightSampler, PointLight, SpotLight,
};
use crate::frame::Frame;
use crate::scene::{Light, Scene};
use crate::texture;
use glam::{Vec2, Vec3};

/// A ray–surface intersection with everything shading needs (world space).
#[derive(Clone, Copy, Debug)]
pub struct Intersection {
    /// Distance along the (unit) ray.
    pub t: f32,
    pub p: Vec3,
    /// Unit geometric normal, flipped if needed to lie on the same side as `ns`.
    pub ng: Vec3,
    /// Unit shading normal (interpolated vertex normals, or `ng`).
    pub ns: Vec3,
    pub uv: Vec2,
    pub mesh: u32,
    pub material: u32,
    /// Index into [`RenderScene::emitters`] if the surface emits.
    pub emitter: Option<u32>,
}

impl Intersection {
    /// Shading frame around `ns`.
    pub fn frame(&self) -> Frame {
        Frame::from_normal(self.ns)
    }
}

/// Per-path-sample state: the random stream and counters.
pub struct Ctx {
    pub sampler: crate::sampler::SobolSampler,
    /// Rays traced (camera, bounce and shadow rays).
    pub rays: u64,
}

pub struct RenderScene {
    pub scene: Scene,
    accel: Accel,
    /// Global triangle index → (mesh, triangle within the mesh).
    tri_map: Vec<(u32, u32)>,
    pub emitters: Vec<EmitterInstance>,
    /// Mesh index → its area emitter.
    mesh_emitter: Vec<Option<u32>>,
    /// Index of the background emitter, if the background is not black.
    pub background: Option<u32>,
    pub lights: LightSampler,
    /// Radius of the scene's bounding sphere.
    pub radius: f32,
}

impl RenderScene {
    /// Builds the BVH and the emitters. Emissive meshes of zero area are skipped with a warning.
    pub fn new(mut scene: Scene, choice: LightChoice) -> RenderScene {
        let n = scene.triangle_count();
        // Triangles go straight from the meshes into the builder, and the map is made after
        // the build: neither adds to the build's peak memory.
        let accel = Accel::build_from(
            n,
            scene
                .meshes
                .iter()
                .flat_map(|m| m.indices.iter().map(|t| t.map(|i| m.positions[i as usize]))),
        );
        let mut tri_map = Vec::with_capacity(n);
        for (mi, m) in scene.meshes.iter().enumerate() {
            tri_map.extend((0..m.indices.len() as u32).map(|ti| (mi as u32, ti)));
        }
        let radius = match scene.bounds() {
            Some((lo, hi)) => ((hi - lo) * 0.5).length().max(1e-3),
            None => 1.0,
        };

        let mut emitters = Vec::new();
        let mut mesh_emitter = vec![None; scene.meshes.len()];
        let mut warnings = Vec::new();
        for (mi, m) in scene.meshes.iter().enumerate() {
            if !scene.materials[m.material].is_emissive() {
                continue;
            }
            match AreaEmitter::new(&scene, mi) {
                Some(e) => {
                    mesh_emitter[mi] = Some(emitters.len() as u32);
                    emitters.push(EmitterInstance::Area(e));
                }
                None => warnings.push(format!(
                    "emissive mesh `{}` has zero area; it does not light the scene",
                    m.name
                )),
            }
        }
        for l in &scene.lights {
            emitters.push(match *l {
                Light::Point {
                    position,
                    intensity,
                } => EmitterInstance::Point(PointLight {
                    position,
                    intensity,
                }),
                Light::Spot {
                    position,
                    direction,
                    intensity,
                    falloff,
                } => EmitterInstance::Spot(SpotLight {
                    position,
                    direction: direction.normalize(),
                    intensity,
                    falloff,
                }),
                Light::Directional {
                    direction,
                    irradiance,
                    angle,
                } => EmitterInstance::Directional(Directional::new(direction, irradiance, angle)),
            });
        }
        let mut background = None;
        if scene.background.max_element() > 0.0 {
            background = Some(emitters.len() as u32);
            emitters.push(EmitterInstance::Background(Background {
                radiance: scene.background,
            }));
        }
        let powers: Vec<f32> = emitters.iter().map(|e| e.power(&scene, radius)).collect();
        let lights = LightSampler::new(&powers, choice);
        scene.warnings.extend(warnings);
        RenderScene {
            scene,
            accel,
            tri_map,
            emitters,
            mesh_emitter,
            background,
            lights,
            radius,
        }
    }

    /// Closest surface along the unit direction `d` from `o`.
    #[inline]
    pub fn intersect(&self, ctx: &mut Ctx, o: Vec3, d: Vec3) -> Option<Intersection> {
        ctx.rays += 1;
        let hit = self.accel.intersect(o, d, 0.0, f32::INFINITY)?;
        let (mi, ti) = self.tri_map[hit.triangle as usize];
        let mesh = &self.scene.meshes[mi as usize];
        let [i0, i1, i2] = mesh.indices[ti as usize].map(|i| i as usize);
        let (b1, b2) = (hit.u, hit.v);
        let b0 = 1.0 - b1 - b2;
        let (p0, p1, p2) = (mesh.positions[i0], mesh.positions[i1], mesh.positions[i2]);
        let p = p0 * b0 + p1 * b1 + p2 * b2;
        let cross = (p1 - p0).cross(p2 - p0);
        let len = cross.length();
        let mut ng = if len > 0.0 && len.is_finite() {
            cross / len
        } else {
            -d
        };
        let mut ns = ng;
        if !mesh.normals.is_empty() {
            let s = mesh.normals[i0] * b0 + mesh.normals[i1] * b1 + mesh.normals[i2] * b2;
            let l = s.length();
            if l > 1e-12 && l.is_finite() {
                ns = s / l;
            }
        }
        if ng.dot(ns) < 0.0 {
            ng = -ng;
        }
        let uv = if mesh.uvs.is_empty() {
            Vec2::ZERO
        } else {
            mesh.uvs[i0] * b0 + mesh.uvs[i1] * b1 + mesh.uvs[i2] * b2
        };
        Some(Intersection {
            t: hit.t,
            p,
            ng,
            ns,
            uv,
            mesh: mi,
            material: mesh.material as u32,
            emitter: self.mesh_emitter[mi as usize],
        })
    }

    /// Like [`RenderScene::intersect`] for the ray leaving path vertex `depth - 1`; camera rays
    /// (`depth == 1`) pass through meshes hidden from the camera.
    #[inline]
    pub fn trace(&self, ctx: &mut Ctx, o: Vec3, d: Vec3, depth: u32) -> Option<Intersection> {
        let mut its = self.intersect(ctx, o, d)?;
        if depth != 1 {
            return Some(its);
        }
        for _ in 0..64 {
            if !self.scene.meshes[its.mesh as usize].hidden_from_camera {
                return Some(its);
            }
            its = self.intersect(ctx, offset_origin(its.p, its.ng, d), d)?;
        }
        Some(its)
    }

    /// True when nothing blocks the segment from surface point `p` (geometric normal `ng`)
    /// to the emitter sample `rec` (a point, or a direction at infinity).
    #[inline]
    pub fn unoccluded(&self, ctx: &mut Ctx, p: Vec3, ng: Vec3, rec: &EmitterQueryRecord) -> bool {
        ctx.rays += 1;
        let o = offset_origin(p, ng, rec.wi);
        if rec.dist.is_finite() {
            // Aim at the light point moved off its own surface, and stop just short of it.
            let target = offset_origin(rec.p, rec.ng, -rec.wi);
            let d = target - o;
            let dist = d.length();
            if dist <= 0.0 || !dist.is_finite() {
                return true;
            }
            !self.accel.occluded(o, d / dist, 0.0, dist * (1.0 - 1e-6))
        } else {
            !self.accel.occluded(o, rec.wi, 0.0, f32::INFINITY)
        }
    }

    /// Material parameters at a hit, textures applied.
    pub fn surface_params(&self, its: &Intersection) -> SurfaceParams {
        let scene = &self.scene;
        let m = &scene.materials[its.material as usize];
        let mut base = m.base_color;
        let mut metallic = m.metallic;
        let mut roughness = m.roughness;
        if let Some(t) = m.base_color_texture {
            let tex = &scene.textures[t.texture];
            base *= texture::lookup(tex, &scene.images[tex.image], its.uv, true).truncate();
        }
        if let Some(t) = m.metallic_roughness_texture {
            let tex = &scene.textures[t.texture];
            let s = texture::lookup(tex, &scene.images[tex.image], its.uv, false);
            roughness *= s.y;
            metallic *= s.z;
        }
        SurfaceParams {
            base_color: base,
            metallic,
            roughness,
            transmission: m.transmission,
            ior: m.ior,
            specular: m.specular,
            specular_color: m.specular_color,
        }
    }

    /// Radiance emitted by the hit surface towards `from` (the ray's origin), with the
    /// emitter's index for MIS.
    #[inline]
    pub fn emitted(
        &self,
        its: &Intersection,
        from: Vec3,
    ) -> Option<(u32, Vec3, EmitterQueryRecord)> {
        let e = its.emitter?;
        let rec = EmitterQueryRecord::between(from, its.p, its.ns, its.ng, its.uv);
        let le = self.emitters[e as usize].eval(&self.scene, &rec);
        Some((e, le, rec))
    }

    /// Background radiance for a ray leaving the scene along `d` from `from`.
    #[inline]
    pub fn background_radiance(
        &self,
        d: Vec3,
        from: Vec3,
    ) -> Option<(u32, Vec3, EmitterQueryRecord)> {
        let b = self.background?;
        let rec = EmitterQueryRecord::towards(from, d);
        Some((b, self.emitters[b as usize].eval(&self.scene, &rec), rec))
    }

    /// Light-selection probability times the emitter's solid-angle density of `rec` — the
    /// density of emitter sampling producing this direction, for MIS.
    #[inline]
    pub fn light_pdf(&self, emitter: u32, rec: &EmitterQueryRecord) -> f32 {
        self.lights.pmf(emitter as usize) * self.emitters[emitter as usize].pdf(&self.scene, rec)
    }

    /// Chooses an emitter and samples it from `ref_p`. Returns the record and the weight
    /// `Le / (pmf · pdf)` (zero when no light could be sampled).
    #[inline]
    pub fn sample_light(
        &self,
        ref_p: Vec3,
        u_choice: f32,
        u: Vec2,
    ) -> (u32, EmitterQueryRecord, Vec3) {
        let mut rec = EmitterQueryRecord::from_ref(ref_p);
        if self.lights.is_empty() {
            return (0, rec, Vec3::ZERO);
        }
        let (i, pmf) = self.lights.sample(u_choice);
        let w = self.emitters[i].sample(&self.scene, &mut rec, u);
        rec.pdf *= pmf;
        (i as u32, rec, w / pmf)
    }

    /// Whether emitter `i` is a delta light.
    pub fn is_delta_light(&self, i: u32) -> bool {
        self.emitters[i as usize].is_delta()
    }

    pub fn triangle_count(&self) -> usize {
        self.tri_map.len()
    }
}
