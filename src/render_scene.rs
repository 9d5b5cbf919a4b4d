//! A scene prepared for rendering: the BVH, the emitters and the light-selection
//! distribution, with the surface queries the integrators need.

use crate::accel::{Accel, Hit, NO_INSTANCE, Traversal, offset_origin};
use crate::emitter::light_bvh::LightBvh;
use crate::emitter::light_tree::LightBounds;
use crate::emitter::{
    AreaEmitter, Directional, Emitter, EmitterInstance, EmitterQueryRecord, LightChoice,
    LightSampler, PointLight, SpotLight,
};
use crate::emitter::{AreaLight, IesLight, SphereLight};
use crate::frame::Frame;
use crate::instancing::InstanceAccel;
use crate::integrator::MAX_TRANSPARENT;
use crate::integrator::mis_weight;
use crate::medium::{self, Medium};
use crate::scene::{Light, LightLinks, ObjectInfo, Scene};
use crate::scene::{LightShape, LightVisibility};
use crate::shading::globals::ray;
use crate::shading::globals::{ShadeEnv, ShaderGlobals, to_blender};
use crate::shading::{ClosureKind, Program};
use glam::{Mat4, Vec2, Vec3};
use std::sync::Arc;

/// A ray–surface intersection with everything shading needs (world space).
#[derive(Clone, Copy, Debug)]
pub struct Intersection {
    /// Distance along the (unit) ray.
    pub t: f32,
    pub p: Vec3,
    /// Unit geometric normal, flipped if needed to lie on the same side as `ns`.
    pub ng: Vec3,
    /// Whether `ng` was flipped so (it then points against the triangle's winding: the
    /// face's front is `-ng`).
    pub ng_flipped: bool,
    /// Unit shading normal (interpolated vertex normals, or `ng`).
    pub ns: Vec3,
    pub uv: Vec2,
    pub mesh: u32,
    /// The instance placing the mesh ([`NO_INSTANCE`] for a world-space mesh).
    pub instance: u32,
    /// Triangle index within the mesh and barycentrics `(b1, b2)` of the hit.
    pub tri: u32,
    pub b1: f32,
    pub b2: f32,
    pub material: u32,
    /// Index into [`RenderScene::emitters`] if the surface emits.
    pub emitter: Option<u32>,
    /// The shutter time of the ray that found it (motion blur).
    pub time: f32,
}

impl Intersection {
    /// The face's front normal (unit, along the triangle's winding).
    #[inline]
    pub fn face_normal(&self) -> Vec3 {
        if self.ng_flipped { -self.ng } else { self.ng }
    }

    /// Shading frame around `ns`.
    pub fn frame(&self) -> Frame {
        Frame::from_normal(self.ns)
    }
}

/// Emitted radiance met by a ray: `(emitter index, radiance, record for MIS)`.
pub type Emitted = Option<(u32, Vec3, EmitterQueryRecord)>;

/// Most surfaces of other objects a local ray ([`RenderScene::intersect_local`]) steps over.
pub const MAX_LOCAL_SKIPS: u32 = 16;

/// Every triangle of the meshes for which `keep(mesh index)` holds, with its key
/// `[mesh index, triangle index]`, for [`Accel::build_from`].
fn mesh_triangles<'a>(
    scene: &'a Scene,
    keep: impl Fn(usize) -> bool + Copy + 'a,
) -> (
    usize,
    impl Iterator<Item = [Vec3; 3]> + 'a,
    impl Iterator<Item = [u32; 2]> + 'a,
) {
    let meshes = || {
        scene
            .meshes
            .iter()
            .enumerate()
            .filter(move |(i, _)| keep(*i))
    };
    let n = meshes().map(|(_, m)| m.indices.len()).sum();
    let tris =
        meshes().flat_map(|(_, m)| m.indices.iter().map(|t| t.map(|i| m.positions[i as usize])));
    let keys =
        meshes().flat_map(|(mi, m)| (0..m.indices.len() as u32).map(move |ti| [mi as u32, ti]));
    (n, tris, keys)
}

/// The BVH over the emissive triangles of `scene` (of `n` triangles in all), unless they are
/// more than half of the scene (then it would save little).
fn emitter_accel(scene: &Scene, mesh_emitter: &[Option<u32>], n: usize) -> Option<Accel> {
    let (count, tris, keys) = mesh_triangles(scene, |i| mesh_emitter[i].is_some());
    (count * 2 <= n).then(|| Accel::build_from(count, tris, keys))
}

/// What a recorded ray asks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// The closest hit (camera and bounce rays).
    Closest,
    /// Whether anything lies on the segment (shadow rays).
    Any,
    /// The emission met by the last segment of a path: a plain renderer finds it with a
    /// closest-hit query; Tesela with [`RenderScene::emission_along`].
    Emission,
}

/// One ray cast by an integrator, as recorded for the traversal benchmark.
#[derive(Clone, Copy, Debug)]
pub struct RayQuery {
    pub o: Vec3,
    /// Unit direction.
    pub d: Vec3,
    /// The query covers `t` in `(0, tmax)`.
    pub tmax: f32,
    pub kind: RayKind,
}

/// A hash of a hit point's coordinates: the seed of the rays its shading program casts.
#[inline]
fn point_seed(p: Vec3) -> u32 {
    let bits =
        (p.x.to_bits() as u64) ^ ((p.y.to_bits() as u64) << 21) ^ ((p.z.to_bits() as u64) << 42);
    crate::sampler::hash32(bits)
}

impl crate::shading::globals::Tracer for RenderScene {
    fn blocked(&self, g: &ShaderGlobals, d: Vec3, tmax: f32, only_local: bool) -> bool {
        use crate::shading::globals::from_blender;
        let d = from_blender(d);
        let o = offset_origin(from_blender(g.p), from_blender(g.ng), d);
        if !only_local {
            let (mut trav, mut top) = (Traversal::default(), Traversal::default());
            return self.occluded_with(&mut trav, &mut top, o, d, tmax, g.time);
        }
        let mut found = false;
        self.each_local_hit(g.object, o, d, tmax, MAX_LOCAL_SKIPS, g.time, |_| {
            found = true;
            false
        });
        found
    }

    fn local_hits(
        &self,
        g: &ShaderGlobals,
        o: Vec3,
        d: Vec3,
        tmax: f32,
        hits: &mut [crate::shading::globals::LocalHit],
    ) -> usize {
        use crate::shading::globals::{LocalHit, from_blender};
        let (o, d) = (from_blender(o), from_blender(d));
        if hits.is_empty() {
            return 0;
        }
        let mut n = 0;
        // Other objects' surfaces count towards the steps too: a bounded walk.
        let steps = hits.len() as u32 + MAX_LOCAL_SKIPS;
        self.each_local_hit(g.object, o, d, tmax, steps, g.time, |hit| {
            let its = self.intersection(hit, d, g.time);
            hits[n] = LocalHit {
                p: to_blender(its.p),
                n: to_blender(its.ns),
                ng: to_blender(its.ng),
            };
            n += 1;
            n < hits.len()
        });
        n
    }
}

/// Per-path-sample state: the random stream and counters.
pub struct Ctx {
    pub sampler: crate::sampler::SobolSampler,
    /// The shading program's slots and closures, reused by every shading point of the thread.
    pub shade: crate::shading::Scratch,
    /// What kind of ray the current path segment is (Light Path node bits), set when a BSDF
    /// is sampled; camera rays are recognised by their depth.
    pub ray_flags: u32,
    /// Path vertex the current ray leads to (1: a camera ray), set by the integrators'
    /// `trace_emitted`: what the world's Light Path node reads as the ray depth.
    pub depth: u32,
    /// The current path's bounces of each kind, kept by the path integrators (zero for
    /// the others): what shading programs read as the Light Path depths.
    pub depths: crate::shading::globals::PathDepths,
    /// Rays cast: camera, bounce and shadow rays, and the last segments of paths however
    /// they are answered ([`RenderScene::emission_along`] may need no traversal at all).
    pub rays: u64,
    /// When set, every ray cast is appended (`benches/traversal.rs` replays them).
    pub log: Option<Vec<RayQuery>>,
    /// BVH traversal scratch, reused by every ray of the thread.
    pub trav: Traversal,
    /// Where the current camera ray ends (the camera's far clip), world space; `None`: it
    /// does not end. Camera-ray segments (path vertex 1, also past transparent surfaces)
    /// stop there.
    pub camera_end: Option<Vec3>,
    /// The top level's traversal scratch, for scenes with instances.
    pub trav_top: Traversal,
    /// Caustics the path integrator switched off ([`crate::integrator::light_paths::caustics`]
    /// bits), for the shading of rays that left a diffuse bounce.
    pub no_caustics: u8,
    /// The least GGX alpha of the microfacet lobes at the next hit the path integrator
    /// shades (Cycles' Filter Glossy, [`crate::integrator::filter_glossy`]); 0 = none.
    pub blur: f32,
    /// The integrator walks subsurface closures ([`crate::integrator::subsurface`]); without
    /// it they render as diffuse.
    pub walks_subsurface: bool,
    /// Where the current ray's direction was sampled, when the ray has since passed straight
    /// through transparent surfaces (its origin is then not that vertex): MIS weights of the
    /// emission it meets take light sampling's densities from there. `None`: the origin.
    pub mis_from: Option<Vec3>,
    /// Whose light the current ray carries ([`RenderScene::receiver_at`]): the receiver set
    /// plus one of the object whose closure scattered it; 0 for camera rays, rays scattered
    /// in media and scenes without light linking (every light reaches them).
    pub receiver: u8,
    /// The medium the current path segment travels in ([`crate::medium`]); clear outside
    /// interiors with a volume. Shadow rays start in it.
    pub medium: Medium,
    /// Whether camera-ray segments are remembered in [`Ctx::camera_hit`]: the render loop
    /// turns it on while it renders a pixel's samples (clearing the memo at each sample) when
    /// the film's data passes or coverage follow the camera ray the integrator traced, so that
    /// they take its hit instead of traversing again.
    pub camera_memo: bool,
    /// The last camera-ray segment traced while [`Ctx::camera_memo`] is on, `(origin,
    /// direction, length, hit)` (a camera segment's hit depends on nothing else while the
    /// scene stays as it is).
    pub camera_hit: Option<(Vec3, Vec3, f32, Option<Intersection>)>,
    /// The path is a shadow catcher's second path ([`crate::film::catcher`]): every ray it
    /// casts sees the shadow catchers alone, as Cycles' catcher-pass paths do.
    pub catchers_only: bool,
    /// The path's shutter time in `[0, 1)` (motion blur): every ray of the path sees the
    /// scene as it is then. 0.5 in scenes without motion, where nothing reads it.
    pub time: f32,
    /// The path still has Cycles' transparent-background state (Film > Transparent Glass,
    /// [`RenderScene::transparent_glass`]): it has gone from the camera through transparent
    /// surfaces and transmissions no rougher than the threshold only. Where such a path
    /// escapes past its first vertex the world adds no colour, and the path integrators add
    /// its throughput's mean to [`Ctx::see_through`]. Always false without the setting.
    pub clear_path: bool,
    /// The share of the current camera sample that reached the world through transmission
    /// with [`Ctx::clear_path`] kept (what the film's coverage loses beyond
    /// [`RenderScene::camera_coverage`]).
    pub see_through: f32,
    /// Cycles' `transparent_max_bounces` for the current path, set by the integrator (the
    /// film's coverage and data passes read it after the path: they follow the same camera
    /// ray).
    pub transparent_max: u32,
    /// Transparent surfaces the current path has passed straight through so far.
    pub transparent: u32,
}

/// A path vertex's index and the path's bounces of each kind before it: what an emitter's
/// shader reads as its Light Path depths.
pub type PathAt = (u32, crate::shading::globals::PathDepths);

impl Ctx {
    /// Where the current ray's hit is on the path: vertex [`Ctx::depth`] after the bounces
    /// counted so far.
    #[inline]
    pub fn path_at(&self) -> PathAt {
        (self.depth, self.depths)
    }

    /// What a light sample from the current vertex sees: the next vertex, the same bounces
    /// (Cycles counts a light sample's vertex one bounce further, its kinds not).
    #[inline]
    pub fn light_sample_at(&self) -> PathAt {
        (self.depth + 1, self.depths)
    }

    /// A context with `sampler`, no rays counted, not recording.
    pub fn new(sampler: crate::sampler::SobolSampler) -> Ctx {
        Ctx {
            sampler,
            shade: Default::default(),
            ray_flags: 0,
            depth: 1,
            depths: Default::default(),
            rays: 0,
            log: None,
            trav: Traversal::default(),
            camera_end: None,
            trav_top: Traversal::default(),
            no_caustics: 0,
            blur: 0.0,
            walks_subsurface: false,
            mis_from: None,
            receiver: 0,
            medium: Medium::default(),
            camera_memo: false,
            camera_hit: None,
            catchers_only: false,
            time: 0.5,
            clear_path: false,
            see_through: 0.0,
            transparent_max: MAX_TRANSPARENT,
            transparent: 0,
        }
    }

    /// Starts a path that may pass straight through `max` transparent surfaces.
    #[inline]
    pub fn start_transparent(&mut self, max: u32) {
        self.transparent_max = max;
        self.transparent = 0;
    }

    /// Transparent surfaces a shadow ray from the current vertex may pass straight through,
    /// Cycles' `transparent_max_bounces` minus the path's pass-throughs so far: one more
    /// blocks the light as an opaque surface would.
    #[inline]
    pub fn shadow_transparent_left(&self) -> u32 {
        self.transparent_max.saturating_sub(self.transparent)
    }

    /// Transparent surfaces the path's current ray may still pass straight through; the
    /// surface after them ends the path (its emission counts, nothing else), as Cycles ends
    /// a path whose count reached `transparent_max_bounces` at the next surface (a limit of
    /// 0 still lets the camera ray through one, as Cycles does).
    #[inline]
    pub fn path_transparent_left(&self) -> u32 {
        self.transparent_max.max(1).saturating_sub(self.transparent)
    }

    /// Length left of the camera-ray segment from `o` along the unit `d` before the camera's
    /// far clip (`f32::INFINITY` without one; never negative).
    #[inline]
    pub fn camera_tmax(&self, o: Vec3, d: Vec3) -> f32 {
        self.camera_end
            .map_or(f32::INFINITY, |end| (end - o).dot(d).max(0.0))
    }

    /// The bit that the visibility queries of a catchers-only path
    /// ([`Ctx::catchers_only`]) add to the ray kinds they ask for.
    #[inline]
    fn catcher_kind(&self) -> u32 {
        if self.catchers_only { CATCHERS_ONLY } else { 0 }
    }

    /// Counts a ray and records it if recording.
    #[inline(always)]
    fn cast(&mut self, o: Vec3, d: Vec3, tmax: f32, kind: RayKind) {
        self.rays += 1;
        if let Some(log) = &mut self.log {
            log.push(RayQuery { o, d, tmax, kind });
        }
    }
}

pub struct RenderScene {
    pub scene: Scene,
    /// Each material's compiled shading program (indexed like `scene.materials`).
    pub programs: Vec<Arc<Program>>,
    /// Some material may be transparent: shadow rays and last path segments look through.
    passes: bool,
    /// Some material has an interior with a volume ([`crate::medium`]).
    pub absorbs: bool,
    /// The medium the camera is in (the world's unless it sits inside a mesh with a volume).
    pub camera_medium: Medium,
    /// The medium filling the world outside meshes with a volume (the World Output's Volume;
    /// clear without one).
    pub world_medium: Medium,
    /// The ray kinds (Light Path bits) some object is hidden from ([`ObjectInfo::visibility`]):
    /// rays of those kinds step over such objects' surfaces.
    hides: u32,
    /// Some object is a holdout ([`ObjectInfo::holdout`]).
    holdouts: bool,
    /// Some object is a shadow catcher ([`ObjectInfo::shadow_catcher`]).
    catchers: bool,
    /// The camera in Blender's coordinates, for the graph's Camera coordinates.
    camera_to_world: Mat4,
    /// The camera's Window coordinates (shared with the mesh emitters).
    window: Arc<crate::camera::WindowMap>,
    /// The world-space meshes.
    accel: Accel,
    /// The instances (two levels), if any.
    instances: Option<InstanceAccel>,
    /// A BVH over the emissive triangles alone: rays whose only use is the emission they meet
    /// find it here first (see [`RenderScene::emission_along`]). `None` when emissive
    /// triangles are most of the scene.
    emitter_accel: Option<Accel>,
    pub emitters: Vec<EmitterInstance>,
    /// Mesh index → its area emitter.
    mesh_emitter: Vec<Option<u32>>,
    /// Index of the background emitter, if the background is not black.
    pub background: Option<u32>,
    /// Which rays see each emitter (the default for everything but Blender lights).
    visibility: Vec<LightVisibility>,
    /// Emitters with a finite shape rays can hit (lights with a radius, area lights), which
    /// are not in `accel`: lights never occlude. Indexed by `light_bvh`'s items.
    light_shapes: Vec<u32>,
    light_bvh: LightBvh,
    /// Distant lights of non-zero angle, which rays leaving the scene can meet.
    suns: Vec<u32>,
    /// The light choice of emitter sampling on its own (`direct_ems`).
    pub lights: LightSampler,
    /// The light choice of emitter sampling combined with BSDF sampling by MIS, when it
    /// differs from `lights`: a constant world is left to BSDF sampling, as Cycles does (a
    /// uniform world is found well by the BSDF's samples, and choosing it as a light would
    /// take shadow rays from the other lights). `None`: the same as `lights`.
    mis_lights: Option<LightSampler>,
    /// Radius of the scene's bounding sphere.
    pub radius: f32,
    /// Number of triangles.
    triangles: usize,
    /// How shadow rays choose a light (kept to rebuild the emitters).
    choice: LightChoice,
    /// Light and shadow linking; `None` in scenes without it.
    linking: Option<Box<Linking>>,
}

/// Light and shadow linking over the emitters ([`LightLinks`]).
struct Linking {
    /// Each emitter's receiver sets and blocker sets (bit masks).
    lights: Vec<u64>,
    shadowed_by: Vec<u64>,
    /// Each receiver set's light choices, as [`RenderScene::lights`] and
    /// [`RenderScene::mis_lights`] over the emitters that light the set alone: an unlinked
    /// emitter is never chosen, so its emission met by a BSDF-sampled ray has no emitter-sampling
    /// share either.
    choices: Vec<(LightSampler, Option<LightSampler>)>,
}

impl Linking {
    /// The linking of `emitters` (with their `links`, `powers` and `bounds`), or `None` when
    /// no emitter is linked.
    fn new(
        scene: &Scene,
        links: &[LightLinks],
        (powers, bounds): (&[f32], &[Option<LightBounds>]),
        constant_world: Option<u32>,
        radius: f32,
        choice: LightChoice,
    ) -> Option<Box<Linking>> {
        let unlinked =
            |l: &LightLinks| l.lights == LightLinks::ALL && l.shadowed_by == LightLinks::ALL;
        if links.iter().all(unlinked) {
            return None;
        }
        let objects = (scene.meshes.iter().map(|m| &m.attrs.object))
            .chain(scene.instances.iter().map(|i| &i.object));
        let sets = objects
            .map(|o| o.links.receiver_set as usize + 1)
            .max()
            .unwrap_or(1);
        let choices = (0..sets)
            .map(|s| {
                let mut p: Vec<f32> = (powers.iter().zip(links))
                    .map(|(&p, l)| if l.lights >> s & 1 != 0 { p } else { 0.0 })
                    .collect();
                let lights = LightSampler::with_bounds(&p, bounds, radius, choice);
                let mis = constant_world.map(|b| {
                    p[b as usize] = 0.0;
                    LightSampler::with_bounds(&p, bounds, radius, choice)
                });
                (lights, mis)
            })
            .collect();
        Some(Box::new(Linking {
            lights: links.iter().map(|l| l.lights).collect(),
            shadowed_by: links.iter().map(|l| l.shadowed_by).collect(),
            choices,
        }))
    }
}

/// Each material's compiled program, and what the compiler reported (once each).
fn compile_programs(scene: &Scene) -> (Vec<Arc<Program>>, Vec<String>) {
    let mut warnings = Vec::new();
    let programs = (scene.materials.iter())
        .map(|m| {
            let c = crate::shading::material_program(m, &scene.textures);
            for w in c.warnings {
                if !warnings.contains(&w) {
                    warnings.push(w);
                }
            }
            Arc::new(c.program)
        })
        .collect();
    (programs, warnings)
}

/// The medium of the world's Volume (clear without one, or when its graph does not compile:
/// the world's emitter reports that graph's problems).
fn world_medium(scene: &Scene) -> Medium {
    let Some(graph) = scene.world.graph.as_ref().filter(|g| g.volume.is_some()) else {
        return Medium::default();
    };
    crate::shading::compile(graph, &scene.world.name)
        .map_or(Medium::default(), |c| *c.program.medium())
}

/// A ray-kind bit beyond the Light Path bits: the query is a catchers-only path's
/// ([`Ctx::catchers_only`]), which sees shadow catchers alone.
const CATCHERS_ONLY: u32 = 1 << 31;

/// The ray kinds some world-space mesh or instance is hidden from. With a shadow catcher in
/// the scene, every kind: a catchers-only path's rays of any kind step over the other objects,
/// so every query takes the filtering way.
fn hidden_rays(scene: &Scene) -> u32 {
    if any_catcher(scene) || any_strands(scene) {
        return ObjectInfo::VISIBLE_TO_ALL;
    }
    let meshes = scene.meshes.iter().map(|m| m.attrs.object.visibility);
    let instances = scene.instances.iter().map(|i| i.object.visibility);
    meshes
        .chain(instances)
        .fold(0, |h, v| h | (ObjectInfo::VISIBLE_TO_ALL & !v))
}

/// Whether some world-space mesh or instance is strands (their tubes' walls are seen from
/// outside only, which takes the filtering way).
fn any_strands(scene: &Scene) -> bool {
    scene.meshes.iter().any(|m| m.attrs.object.strands)
        || scene.instances.iter().any(|i| i.object.strands)
}

/// Whether some world-space mesh or instance is a shadow catcher.
fn any_catcher(scene: &Scene) -> bool {
    scene.meshes.iter().any(|m| m.attrs.object.shadow_catcher)
        || scene.instances.iter().any(|i| i.object.shadow_catcher)
}

/// Whether some world-space mesh or instance is a holdout.
fn any_holdout(scene: &Scene) -> bool {
    scene.meshes.iter().any(|m| m.attrs.object.holdout)
        || scene.instances.iter().any(|i| i.object.holdout)
}

/// What a ray scattered with the Light Path bits `flags` sees objects as (Cycles'
/// `path_state_ray_visibility`: transmission rays are only that; reflected ones diffuse or
/// glossy); every kind but shadow when `flags` says nothing of a bounce.
#[inline]
fn bounce_visibility(flags: u32) -> u32 {
    if flags & ray::TRANSMISSION != 0 {
        return ray::TRANSMISSION;
    }
    match flags & (ray::DIFFUSE | ray::GLOSSY) {
        0 => ObjectInfo::VISIBLE_TO_ALL & !ray::SHADOW,
        kind => kind,
    }
}

/// Most surfaces of hidden objects one ray steps over.
const MAX_HIDDEN_SKIPS: usize = 64;

/// The camera in Blender's coordinates (for the graph's Camera coordinates).
fn blender_camera_to_world(scene: &Scene) -> Mat4 {
    scene.camera.map_or(Mat4::IDENTITY, |c| {
        crate::camera::GLTF_TO_BLENDER * c.to_world
    })
}

/// The emitters of a scene and how rays and light choice find them: everything a change of
/// a material, a light or the world rebuilds (the scene's BVH stays).
struct LightParts {
    emitter_accel: Option<Accel>,
    emitters: Vec<EmitterInstance>,
    mesh_emitter: Vec<Option<u32>>,
    background: Option<u32>,
    visibility: Vec<LightVisibility>,
    light_shapes: Vec<u32>,
    light_bvh: LightBvh,
    suns: Vec<u32>,
    lights: LightSampler,
    mis_lights: Option<LightSampler>,
    linking: Option<Box<Linking>>,
}

impl LightParts {
    /// The emitters of `scene` whose materials compiled to `programs`, for a scene of
    /// `triangles` world-space triangles and bounding radius `radius`.
    fn new(
        scene: &Scene,
        programs: &[Arc<Program>],
        (camera_to_world, window): (Mat4, &Arc<crate::camera::WindowMap>),
        (triangles, radius): (usize, f32),
        choice: LightChoice,
        warnings: &mut Vec<String>,
    ) -> LightParts {
        let placed = scene.placed_meshes();
        let mut emitters = Vec::new();
        let mut mesh_emitter = vec![None; scene.meshes.len()];
        let mut visibility = Vec::new();
        let mut links = Vec::new();
        for (mi, m) in scene.meshes.iter().enumerate() {
            let program = &programs[m.material];
            // Placed meshes emit through their baked copies; a mesh emptied by the baking
            // has no positions left.
            if placed[mi] || m.positions.is_empty() || !program.may_emit() {
                continue;
            }
            match AreaEmitter::with_program(scene, mi, program.clone()) {
                Some(e) => {
                    mesh_emitter[mi] = Some(emitters.len() as u32);
                    links.push(m.attrs.object.links);
                    emitters.push(EmitterInstance::Area(
                        e.with_camera(camera_to_world, window.clone()),
                    ));
                    // An object hidden from a closure's rays does not light it by emitter
                    // sampling either (Cycles' SHADER_EXCLUDE_* of mesh lights).
                    let v = m.attrs.object.visibility;
                    visibility.push(LightVisibility {
                        diffuse: v & ray::DIFFUSE != 0,
                        glossy: v & ray::GLOSSY != 0,
                        transmission: v & ray::TRANSMISSION != 0,
                        ..LightVisibility::default()
                    });
                }
                None => warnings.push(format!(
                    "emissive mesh `{}` has zero area; it does not light the scene",
                    m.name
                )),
            }
        }
        for (li, l) in scene.lights.iter().enumerate() {
            links.push(scene.light_links.get(li).copied().unwrap_or_default());
            visibility.push(match l {
                Light::Blender { visibility, .. } => *visibility,
                _ => LightVisibility::default(),
            });
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
                Light::Blender {
                    shape, ref profile, ..
                } => {
                    let light = blender_emitter(&shape);
                    match profile {
                        Some(p) => EmitterInstance::Ies(IesLight::new(
                            light,
                            p.profile.clone(),
                            p.to_local,
                        )),
                        None => light,
                    }
                }
            });
        }
        let mut background = None;
        if let Some(world) =
            crate::emitter::environment::world_emitter(scene, camera_to_world, warnings)
        {
            background = Some(emitters.len() as u32);
            emitters.push(world);
        }
        visibility.resize(emitters.len(), LightVisibility::default());
        if let Some(b) = background {
            let w = &scene.world;
            visibility[b as usize] = LightVisibility {
                diffuse: w.visible_diffuse,
                glossy: w.visible_glossy,
                transmission: w.visible_transmission,
                ..LightVisibility::default()
            };
        }
        let (mut light_shapes, mut bounds, mut suns) = (Vec::new(), Vec::new(), Vec::new());
        for (i, e) in emitters.iter().enumerate() {
            match e.shape() {
                EmitterInstance::Sphere(s) => {
                    light_shapes.push(i as u32);
                    bounds.push((s.position - s.radius, s.position + s.radius));
                }
                EmitterInstance::AreaLight(a) if !a.is_delta() => {
                    light_shapes.push(i as u32);
                    let c = a.corners();
                    let lo = c.iter().fold(c[0], |m, p| m.min(*p));
                    let hi = c.iter().fold(c[0], |m, p| m.max(*p));
                    bounds.push((lo, hi));
                }
                EmitterInstance::Directional(d) if !d.is_delta() => suns.push(i as u32),
                _ => {}
            }
        }
        let light_bvh = LightBvh::new(&bounds);
        let emitter_accel = emitter_accel(scene, &mesh_emitter, triangles);
        let powers: Vec<f32> = emitters.iter().map(|e| e.power(scene, radius)).collect();
        let bounds: Vec<_> = emitters.iter().map(|e| light_bounds(scene, e)).collect();
        let lights = LightSampler::with_bounds(&powers, &bounds, radius, choice);
        let constant_world = background
            .filter(|&b| matches!(emitters[b as usize], EmitterInstance::Background(_)))
            .filter(|&b| powers[b as usize] > 0.0);
        let mis_lights = constant_world.map(|b| {
            let mut powers = powers.clone();
            powers[b as usize] = 0.0;
            LightSampler::with_bounds(&powers, &bounds, radius, choice)
        });
        // The world is never linked.
        links.resize(emitters.len(), LightLinks::default());
        let linking = Linking::new(
            scene,
            &links,
            (&powers, &bounds),
            constant_world,
            radius,
            choice,
        );
        LightParts {
            emitter_accel,
            emitters,
            mesh_emitter,
            background,
            visibility,
            light_shapes,
            light_bvh,
            suns,
            lights,
            mis_lights,
            linking,
        }
    }
}

impl RenderScene {
    /// Builds the BVH and the emitters. Emissive meshes of zero area are skipped with a warning.
    pub fn new(mut scene: Scene, choice: LightChoice) -> RenderScene {
        let (programs, mut warnings) = compile_programs(&scene);
        if bake_emissive_instances(&mut scene, &programs) {
            warnings.push(
                "an emissive mesh moves over the shutter: emitters are not motion blurred; it \
                 renders at its frame transform"
                    .into(),
            );
        }
        let to_world = blender_camera_to_world(&scene);
        for w in crate::displace::displace_meshes(&mut scene, to_world) {
            if !warnings.contains(&w) {
                warnings.push(w);
            }
        }
        // Triangles go straight from the meshes into the builder: no copy of the scene at the
        // build's peak memory.
        let placed = scene.placed_meshes();
        let (n, tris, keys) = mesh_triangles(&scene, |i| !placed[i]);
        let accel = Accel::build_from(n, tris, keys);
        let instances = InstanceAccel::new(&scene, |_| true);
        let radius = match scene.bounds() {
            Some((lo, hi)) => ((hi - lo) * 0.5).length().max(1e-3),
            None => 1.0,
        };
        let camera_to_world = blender_camera_to_world(&scene);
        let window = Arc::new(crate::camera::WindowMap::new(&scene));
        if !window.supported() {
            for m in &scene.materials {
                let node = m
                    .graph
                    .as_ref()
                    .and_then(|g| g.node_with_linked_output("ShaderNodeTexCoord", "Window"));
                if let Some(n) = node {
                    scene.warnings.push(format!(
                        "material '{}': node '{}': Window coordinates are not rendered for a panoramic camera; they read as (0, 0, 0)",
                        m.name, n.name
                    ));
                }
            }
        }
        let parts = LightParts::new(
            &scene,
            &programs,
            (camera_to_world, &window),
            (n, radius),
            choice,
            &mut warnings,
        );
        scene.warnings.extend(warnings);
        let passes = programs.iter().any(|p| p.may_pass());
        let world_medium = world_medium(&scene);
        let absorbs = programs.iter().any(|p| !p.medium().is_clear()) || !world_medium.is_clear();
        let hides = hidden_rays(&scene);
        let holdouts = any_holdout(&scene);
        let catchers = any_catcher(&scene);
        let mut rs = RenderScene {
            window,
            scene,
            passes,
            absorbs,
            camera_medium: Medium::default(),
            world_medium,
            hides,
            holdouts,
            catchers,
            programs,
            camera_to_world,
            accel,
            instances,
            emitter_accel: parts.emitter_accel,
            triangles: n,
            emitters: parts.emitters,
            mesh_emitter: parts.mesh_emitter,
            background: parts.background,
            visibility: parts.visibility,
            light_shapes: parts.light_shapes,
            light_bvh: parts.light_bvh,
            suns: parts.suns,
            lights: parts.lights,
            mis_lights: parts.mis_lights,
            radius,
            choice,
            linking: parts.linking,
        };
        rs.camera_medium = rs.camera_medium();
        rs
    }

    /// The medium around the camera's position: the interior of the first mesh with a volume
    /// that a ray from there meets from behind (meshes are closed: Cycles' volume stack
    /// initialisation, from the camera's position instead of each ray's origin).
    fn camera_medium(&self) -> Medium {
        let Some(camera) = self.scene.camera.as_ref() else {
            return self.world_medium;
        };
        if !self.absorbs {
            return self.world_medium;
        }
        let mut ctx = Ctx::new(crate::sampler::SobolSampler::new(0, 0, 0));
        // Any direction does for a closed mesh; this one is off every axis and diagonal.
        let d = Vec3::new(0.2673, 0.5345, 0.8018).normalize();
        let mut o = camera.to_world.w_axis.truncate();
        for _ in 0..MAX_HIDDEN_SKIPS {
            let Some(its) = self.intersect(&mut ctx, o, d) else {
                break;
            };
            let m = self.programs[its.material as usize].medium();
            if !m.is_clear() {
                return if d.dot(its.ng) > 0.0 {
                    *m
                } else {
                    self.world_medium
                };
            }
            o = offset_origin(its.p, its.ng, d);
        }
        self.world_medium
    }

    fn set_lights(&mut self, p: LightParts) {
        self.emitter_accel = p.emitter_accel;
        self.emitters = p.emitters;
        self.mesh_emitter = p.mesh_emitter;
        self.background = p.background;
        self.visibility = p.visibility;
        self.light_shapes = p.light_shapes;
        self.light_bvh = p.light_bvh;
        self.suns = p.suns;
        self.lights = p.lights;
        self.mis_lights = p.mis_lights;
        self.linking = p.linking;
    }

    /// Whether [`RenderScene::refresh_shading`] can take the scene's materials as they stand
    /// now: false when a material of an instance starts or stops emitting (instances that
    /// emit are baked into world space: the BVH must be built again, by [`RenderScene::new`]).
    pub fn shading_keeps_geometry(&self) -> bool {
        let mut checked: std::collections::HashMap<usize, bool> = Default::default();
        self.scene.instances.iter().all(|i| {
            let Some(mesh) = self.scene.meshes.get(i.mesh) else {
                return true;
            };
            let m = i.material.unwrap_or(mesh.material);
            *checked.entry(m).or_insert_with(|| {
                let old = self.programs.get(m).is_some_and(|p| p.may_emit());
                let new = (self.scene.materials.get(m)).is_some_and(|mat| {
                    crate::shading::material_program(mat, &self.scene.textures)
                        .program
                        .may_emit()
                });
                old == new
            })
        })
    }

    /// Compiles the materials again and rebuilds the emitters from the scene's materials,
    /// lights and world as they stand (after an edit of `scene`); the BVH stays. Returns what
    /// the compiler and the emitters reported.
    pub fn refresh_shading(&mut self) -> Vec<String> {
        let (programs, mut warnings) = compile_programs(&self.scene);
        self.programs = programs;
        self.passes = self.programs.iter().any(|p| p.may_pass());
        self.world_medium = world_medium(&self.scene);
        self.absorbs =
            self.programs.iter().any(|p| !p.medium().is_clear()) || !self.world_medium.is_clear();
        self.hides = hidden_rays(&self.scene);
        self.holdouts = any_holdout(&self.scene);
        self.catchers = any_catcher(&self.scene);
        self.camera_medium = self.camera_medium();
        warnings.extend(self.refresh_lights());
        warnings
    }

    /// Whether some instance's material may emit (such instances are baked into world space,
    /// so moving one means building the world's BVH again).
    pub fn instances_emit(&self) -> bool {
        self.scene.instances.iter().any(|i| {
            let m = (self.scene.meshes.get(i.mesh))
                .map_or(0, |mesh| i.material.unwrap_or(mesh.material));
            self.programs.get(m).is_none_or(|p| p.may_emit())
        })
    }

    /// After `scene.instances` changed (moved, added, removed) and the meshes `changed` got new
    /// triangles: builds the top level again (and the bottom levels of `changed`), the
    /// scene's radius and the emitters; the world-space BVH stays. Needs
    /// `!instances_emit()` before and after.
    pub fn refresh_instances(&mut self, changed: &[usize]) -> Vec<String> {
        self.instances = InstanceAccel::rebuilt(&self.scene, self.instances.take(), changed);
        self.radius = match self.scene.bounds() {
            Some((lo, hi)) => ((hi - lo) * 0.5).length().max(1e-3),
            None => 1.0,
        };
        self.refresh_shading()
    }

    /// Takes world-space meshes out of the world's BVH without building it again (see
    /// [`Accel::remove_mesh`]): for a mesh that instances place from now on.
    pub fn remove_world_meshes(&mut self, meshes: &[usize]) {
        for &m in meshes {
            self.accel.remove_mesh(m as u32);
        }
    }

    /// Rebuilds the emitters only (lights or the world changed; the materials did not).
    pub fn refresh_lights(&mut self) -> Vec<String> {
        let mut warnings = Vec::new();
        let parts = LightParts::new(
            &self.scene,
            &self.programs,
            (self.camera_to_world, &self.window),
            (self.triangles, self.radius),
            self.choice,
            &mut warnings,
        );
        self.set_lights(parts);
        warnings
    }

    /// Moves the camera without touching the BVH. Shading's Camera coordinates follow it; an
    /// environment's importance map stays as it was built (a world graph that reads Camera
    /// coordinates samples by the old map, still unbiased where it is not zero).
    pub fn set_camera(&mut self, camera: Option<crate::scene::Camera>) {
        self.scene.camera = camera;
        self.camera_to_world = blender_camera_to_world(&self.scene);
        let (w, h) = self.window.resolution();
        let window = crate::camera::WindowMap::new(&self.scene);
        window.set_resolution(w, h);
        self.window = Arc::new(window);
        for e in &mut self.emitters {
            if let EmitterInstance::Area(a) = e {
                a.camera_to_world = self.camera_to_world;
                a.window = self.window.clone();
            }
        }
    }

    /// Whether a ray leaving path vertex `depth - 1` with Light Path bits `flags` sees
    /// emitter `e` when it meets its shape (Cycles: camera rays the lights visible to the
    /// camera; other rays those with multiple importance sampling, unless the kind of
    /// scattering that made the ray is excluded).
    #[inline]
    fn ray_sees(&self, e: u32, depth: u32, flags: u32) -> bool {
        let v = &self.visibility[e as usize];
        if depth <= 1 {
            return v.camera;
        }
        let glossy_reflection = ray::GLOSSY | ray::REFLECTION;
        let diffuse_ok = v.diffuse || flags & ray::DIFFUSE == 0;
        let glossy_ok = v.glossy || flags & glossy_reflection != glossy_reflection;
        let transmission_ok = v.transmission || flags & ray::TRANSMISSION == 0;
        v.mis && diffuse_ok && glossy_ok && transmission_ok
    }

    /// Whether emitter sampling of light `e` reaches a closure of the kinds `class` (Light Path
    /// bits `DIFFUSE`, `GLOSSY`, `TRANSMISSION`; a closure of several kinds is excluded only
    /// when all are, as Cycles treats glass).
    #[inline]
    pub fn light_reaches(&self, e: u32, class: u32) -> bool {
        let v = &self.visibility[e as usize];
        (class & ray::DIFFUSE != 0 && v.diffuse)
            || (class & ray::GLOSSY != 0 && v.glossy)
            || (class & ray::TRANSMISSION != 0 && v.transmission)
    }

    /// Whether shadow rays towards light `e` test occlusion.
    #[inline]
    pub fn casts_shadow(&self, e: u32) -> bool {
        self.visibility[e as usize].cast_shadow
    }

    /// Whether emitter samples of light `e` are weighted against BSDF sampling (a light that
    /// rays can hit, with multiple importance sampling on).
    #[inline]
    pub fn light_uses_mis(&self, e: u32) -> bool {
        !self.emitters[e as usize].is_delta()
            && self.visibility[e as usize].mis
            && self.blockers_of(e) == LightLinks::ALL
    }

    /// The receiver of light at `its`: the receiver set of its object plus one; 0 in scenes
    /// without light linking (every light reaches it).
    #[inline]
    pub fn receiver_at(&self, its: &Intersection) -> u8 {
        if self.linking.is_none() {
            return 0;
        }
        let o = match self.scene.instances.get(its.instance as usize) {
            Some(i) => &i.object,
            None => &self.scene.meshes[its.mesh as usize].attrs.object,
        };
        o.links.receiver_set.saturating_add(1)
    }

    /// Whether emitter `e` lights `receiver` ([`Ctx::receiver`]).
    #[inline]
    pub fn lights_receiver(&self, e: u32, receiver: u8) -> bool {
        match &self.linking {
            Some(l) if receiver > 0 => l.lights[e as usize] >> (receiver - 1) & 1 != 0,
            _ => true,
        }
    }

    /// The blocker sets whose objects shadow emitter `e` ([`LightLinks::shadowed_by`]).
    #[inline]
    fn blockers_of(&self, e: u32) -> u64 {
        self.linking
            .as_ref()
            .map_or(LightLinks::ALL, |l| l.shadowed_by[e as usize])
    }

    /// Whether the object of `hit` is in one of the blocker sets `blockers`.
    #[inline]
    fn blocks(&self, hit: &Hit, blockers: u64) -> bool {
        if blockers == LightLinks::ALL {
            return true;
        }
        let o = match self.scene.instances.get(hit.instance as usize) {
            Some(i) => &i.object,
            None => &self.scene.meshes[hit.key[0] as usize].attrs.object,
        };
        blockers >> o.links.blocker_set & 1 != 0
    }

    /// Whether any surface may let rays straight through (a transparent closure, or the
    /// boundary of a volume without a surface shader).
    #[inline]
    pub fn has_passing_surfaces(&self) -> bool {
        self.passes
    }

    /// Whether the scene has lights whose shapes rays can meet (radius, area or angle).
    #[inline]
    pub fn has_light_shapes(&self) -> bool {
        !self.light_shapes.is_empty() || !self.suns.is_empty()
    }

    /// The radiance of the Blender lights' shapes that the ray `o + t d` (unit `d`) meets for
    /// `t ∈ (0, tmax)` — and, when `tmax` is infinite, of the suns it leaves the scene towards —
    /// for a ray leaving path vertex `depth - 1` (Light Path bits in `ctx.ray_flags`), each
    /// weighted against emitter sampling by the power heuristic with the BSDF density
    /// `bsdf_pdf` (infinite: weight 1). Lights are transparent: a ray passes through every one
    /// it meets. With `occlusion`, `tmax` is not the first surface's distance and each light
    /// met is tested for what lies before it.
    #[allow(clippy::too_many_arguments)]
    pub fn lights_on_ray(
        &self,
        ctx: &mut Ctx,
        o: Vec3,
        d: Vec3,
        tmax: f32,
        depth: u32,
        bsdf_pdf: f32,
        occlusion: bool,
    ) -> Vec3 {
        if !self.has_light_shapes() {
            return Vec3::ZERO;
        }
        let (flags, receiver) = (ctx.ray_flags, ctx.receiver);
        let mut hits = [(0u32, 0.0f32, Vec3::ZERO); 8];
        let mut n = 0;
        self.light_bvh.visit(o, d, tmax, |k| {
            let e = self.light_shapes[k as usize];
            if n == hits.len()
                || !self.ray_sees(e, depth, flags)
                || !self.lights_receiver(e, receiver)
            {
                return;
            }
            let hit = match self.emitters[e as usize].shape() {
                EmitterInstance::Sphere(s) => s.intersect(o, d, tmax),
                EmitterInstance::AreaLight(a) => a.intersect(o, d, tmax).map(|t| (t, a.normal)),
                _ => None,
            };
            if let Some((t, normal)) = hit {
                hits[n] = (e, t, normal);
                n += 1;
            }
        });
        let mut sum = Vec3::ZERO;
        for &(e, t, normal) in &hits[..n] {
            let rec = EmitterQueryRecord {
                ref_p: o,
                p: o + d * t,
                n: normal,
                ng: normal,
                wi: d,
                dist: t,
                ..Default::default()
            };
            let le = self.emitters[e as usize].eval(&self.scene, &rec);
            if le == Vec3::ZERO {
                continue;
            }
            let tr = if occlusion {
                let blockers = self.blockers_of(e);
                let left = ctx.path_transparent_left();
                self.segment_transmittance(ctx, (o, d, t), Medium::default(), blockers, left)
            } else {
                Vec3::ONE
            };
            sum += le * tr * self.hit_weight(ctx, e, &rec, bsdf_pdf);
        }
        if tmax.is_infinite() {
            sum += self.suns_on_ray(ctx, o, d, depth, bsdf_pdf, occlusion);
        }
        sum
    }

    /// The radiance of the suns a ray along `d` leaves the scene towards (see
    /// [`RenderScene::lights_on_ray`]); for a camera ray that escapes past the far clip, as
    /// the world, the suns still show.
    pub fn suns_on_ray(
        &self,
        ctx: &mut Ctx,
        o: Vec3,
        d: Vec3,
        depth: u32,
        bsdf_pdf: f32,
        occlusion: bool,
    ) -> Vec3 {
        let flags = ctx.ray_flags;
        let mut sum = Vec3::ZERO;
        for &e in &self.suns {
            if !self.ray_sees(e, depth, flags) || !self.lights_receiver(e, ctx.receiver) {
                continue;
            }
            let rec = EmitterQueryRecord::towards(o, d);
            let le = self.emitters[e as usize].eval(&self.scene, &rec);
            if le == Vec3::ZERO {
                continue;
            }
            let tr = if occlusion {
                let blockers = self.blockers_of(e);
                let left = ctx.path_transparent_left();
                let ray = (o, d, f32::INFINITY);
                self.segment_transmittance(ctx, ray, Medium::default(), blockers, left)
            } else {
                Vec3::ONE
            };
            sum += le * tr * self.hit_weight(ctx, e, &rec, bsdf_pdf);
        }
        sum
    }

    /// MIS weight of light `e` met by the current ray, a BSDF sample of density `bsdf_pdf`
    /// (infinite: weight 1) taken at [`Ctx::mis_from`] if given, else at the record's
    /// reference point, for [`Ctx::receiver`]. A light with shadow linking is left to emitter
    /// sampling (weight 0, its samples weight 1): the surface a BSDF-sampled ray stops at may
    /// be one that does not shadow it.
    #[inline]
    pub fn hit_weight(&self, ctx: &Ctx, e: u32, rec: &EmitterQueryRecord, bsdf_pdf: f32) -> f32 {
        if bsdf_pdf.is_infinite() {
            1.0
        } else if self.blockers_of(e) != LightLinks::ALL {
            0.0
        } else {
            let pdf = match ctx.mis_from {
                None => self.light_pdf(e, rec, ctx.receiver),
                Some(o) => self.light_pdf(e, &rec.seen_from(o), ctx.receiver),
            };
            mis_weight(bsdf_pdf, pdf)
        }
    }

    /// Closest surface along the unit direction `d` from `o`.
    #[inline]
    pub fn intersect(&self, ctx: &mut Ctx, o: Vec3, d: Vec3) -> Option<Intersection> {
        ctx.cast(o, d, f32::INFINITY, RayKind::Closest);
        let hit = if !self.hides_from_bounces() {
            self.closest(ctx, o, d, f32::INFINITY)?
        } else {
            let kind = bounce_visibility(ctx.ray_flags) | ctx.catcher_kind();
            self.closest_seen(ctx, o, d, f32::INFINITY, kind, LightLinks::ALL)?
        };
        Some(self.intersection(&hit, d, ctx.time))
    }

    /// Whether some object is hidden from rays that closures scatter (diffuse, glossy or
    /// transmission rays).
    #[inline]
    fn hides_from_bounces(&self) -> bool {
        self.hides & !(ray::CAMERA | ray::SHADOW) != 0
    }

    /// Whether rays of the kinds `kind` (Light Path bits, and [`CATCHERS_ONLY`] for a
    /// catchers-only path) along `d` see the object of `hit` (a strand's tube only from
    /// outside).
    #[inline]
    fn sees(&self, hit: &Hit, kind: u32, d: Vec3) -> bool {
        let o = self.object(hit.key[0], hit.instance);
        o.visibility & kind != 0
            && (kind & CATCHERS_ONLY == 0 || o.shadow_catcher)
            && !(o.strands && hit.ng.dot(d) > 0.0)
    }

    /// Whether the camera's first hit `its` splits the path at a shadow catcher: a catcher
    /// that is no holdout (Cycles holds a holdout catcher out).
    #[inline]
    pub fn catcher_at(&self, its: &Intersection) -> bool {
        self.catchers
            && match self.scene.instances.get(its.instance as usize) {
                Some(i) => i.object.shadow_catcher && !i.object.holdout,
                None => {
                    let o = &self.scene.meshes[its.mesh as usize].attrs.object;
                    o.shadow_catcher && !o.holdout
                }
            }
    }

    /// Whether some object is a shadow catcher.
    #[inline]
    pub fn has_catchers(&self) -> bool {
        self.catchers
    }

    /// Whether the object `its` hit is a holdout ([`ObjectInfo::holdout`]).
    #[inline]
    fn holdout_at(&self, its: &Intersection) -> bool {
        self.holdouts
            && match self.scene.instances.get(its.instance as usize) {
                Some(i) => i.object.holdout,
                None => self.scene.meshes[its.mesh as usize].attrs.object.holdout,
            }
    }

    /// The [`ObjectInfo`] of world-space mesh `mesh`, or of `instance` when it is one.
    #[inline]
    fn object(&self, mesh: u32, instance: u32) -> &ObjectInfo {
        if instance == NO_INSTANCE {
            &self.scene.meshes[mesh as usize].attrs.object
        } else {
            &self.scene.instances[instance as usize].object
        }
    }

    /// [`Self::closest`] among the objects rays of the kinds `kind` see and of the blocker
    /// sets `blockers`: the surfaces of others are stepped over (up to [`MAX_HIDDEN_SKIPS`];
    /// `t` stays measured from `o`).
    #[inline(never)]
    fn closest_seen(
        &self,
        ctx: &mut Ctx,
        o: Vec3,
        d: Vec3,
        tmax: f32,
        kind: u32,
        blockers: u64,
    ) -> Option<Hit> {
        let mut tmin = 0.0;
        for _ in 0..MAX_HIDDEN_SKIPS {
            let hit = self.closest_after(ctx, o, d, tmin, tmax)?;
            if self.sees(&hit, kind, d) && self.blocks(&hit, blockers) {
                return Some(hit);
            }
            tmin = hit.t;
        }
        None
    }

    /// The closest surface that casts shadows in `(0, tmax)`, of the blocker sets `blockers`.
    #[inline]
    fn closest_shadowing(
        &self,
        ctx: &mut Ctx,
        o: Vec3,
        d: Vec3,
        tmax: f32,
        blockers: u64,
    ) -> Option<Hit> {
        if self.hides & ray::SHADOW == 0 && blockers == LightLinks::ALL {
            self.closest(ctx, o, d, tmax)
        } else {
            let kind = ray::SHADOW | ctx.catcher_kind();
            self.closest_seen(ctx, o, d, tmax, kind, blockers)
        }
    }

    /// The closest hit in `(0, tmax)` over the world-space meshes and the instances.
    #[inline(always)]
    fn closest(&self, ctx: &mut Ctx, o: Vec3, d: Vec3, tmax: f32) -> Option<Hit> {
        self.closest_after(ctx, o, d, 0.0, tmax)
    }

    /// [`Self::closest`] in `(tmin, tmax)`.
    #[inline(always)]
    fn closest_after(&self, ctx: &mut Ctx, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        self.closest_with(&mut ctx.trav, &mut ctx.trav_top, o, d, tmin, tmax, ctx.time)
    }

    /// [`Self::closest_after`] on the given traversal states (bottom level, top level), at
    /// shutter time `time`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn closest_with(
        &self,
        trav: &mut Traversal,
        top: &mut Traversal,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
        time: f32,
    ) -> Option<Hit> {
        let hit = self.accel.intersect_with(trav, o, d, tmin, tmax);
        let Some(inst) = &self.instances else {
            return hit;
        };
        let t = hit.map_or(tmax, |h| h.t);
        inst.intersect_with(top, trav, o, d, tmin, t, time).or(hit)
    }

    /// The closest surface of one object — mesh `mesh` placed by `instance` — along the unit
    /// direction `d` from `o`, in `(tmin, tmax)` (Cycles' local intersection, for walks
    /// inside that object): other objects' surfaces on the way are stepped over, up to
    /// [`MAX_LOCAL_SKIPS`] of them.
    #[allow(clippy::too_many_arguments)]
    pub fn intersect_local(
        &self,
        ctx: &mut Ctx,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
        mesh: u32,
        instance: u32,
    ) -> Option<Intersection> {
        let mut tmin = tmin;
        for _ in 0..MAX_LOCAL_SKIPS {
            ctx.cast(o, d, tmax, RayKind::Closest);
            let hit = self.closest_after(ctx, o, d, tmin, tmax)?;
            if hit.key[0] == mesh && hit.instance == instance {
                return Some(self.intersection(&hit, d, ctx.time));
            }
            tmin = hit.t;
        }
        None
    }

    /// Whether anything lies on the ray in `(0, tmax)`.
    #[inline(always)]
    fn occluded(&self, ctx: &mut Ctx, o: Vec3, d: Vec3, tmax: f32) -> bool {
        self.occluded_with(&mut ctx.trav, &mut ctx.trav_top, o, d, tmax, ctx.time)
    }

    /// [`Self::occluded`] on the given traversal states (bottom level, top level), at
    /// shutter time `time`.
    #[inline(always)]
    fn occluded_with(
        &self,
        trav: &mut Traversal,
        top: &mut Traversal,
        o: Vec3,
        d: Vec3,
        tmax: f32,
        time: f32,
    ) -> bool {
        self.accel.occluded_with(trav, o, d, 0.0, tmax)
            || (self.instances.as_ref())
                .is_some_and(|inst| inst.occluded_with(top, trav, o, d, 0.0, tmax, time))
    }

    /// Walks the surfaces on the ray `o + t d` (renderer space, `t` in `(0, tmax)`) nearest
    /// first, at most `steps` of them of any object, calling `visit` on those of `object`
    /// (`[mesh, instance]`) until it returns false; at shutter time `time`.
    #[allow(clippy::too_many_arguments)]
    fn each_local_hit(
        &self,
        object: [u32; 2],
        o: Vec3,
        d: Vec3,
        tmax: f32,
        steps: u32,
        time: f32,
        mut visit: impl FnMut(&Hit) -> bool,
    ) {
        let (mut trav, mut top) = (Traversal::default(), Traversal::default());
        let mut tmin = 0.0;
        for _ in 0..steps {
            let Some(hit) = self.closest_with(&mut trav, &mut top, o, d, tmin, tmax, time) else {
                return;
            };
            tmin = hit.t;
            if [hit.key[0], hit.instance] == object && !visit(&hit) {
                return;
            }
        }
    }

    /// The radiance a ray from `o` along the unit direction `d` meets — the emission of the
    /// first surface it hits, or the background if it escapes — when nothing else about that
    /// surface is needed (the last segment of a path). Equal to [`RenderScene::emitted`] /
    /// [`RenderScene::background_radiance`] after [`RenderScene::intersect`], but it looks for
    /// the nearest *emissive* triangle in a small BVH first and then only asks whether anything
    /// blocks the ray before it (an any-hit query); a ray that meets no emitter and no
    /// background costs no scene traversal at all. Not for camera rays (hidden meshes).
    #[inline]
    pub fn emission_along(&self, ctx: &mut Ctx, o: Vec3, d: Vec3) -> Emitted {
        if self.passes || self.hides_from_bounces() {
            return self.emission_through(ctx, o, d);
        }
        let Some(emissive) = &self.emitter_accel else {
            let (path, flags) = (ctx.path_at(), ctx.ray_flags);
            let receiver = ctx.receiver;
            let hit = self.intersect(ctx, o, d);
            return self.emission_at(hit.as_ref(), o, d, path, flags, receiver);
        };
        ctx.cast(o, d, f32::INFINITY, RayKind::Emission);
        if let Some(hit) = emissive.intersect_with(&mut ctx.trav, o, d, 0.0, f32::INFINITY) {
            let its = self.intersection(&hit, d, ctx.time);
            let (e, le, rec) = self.emitted(&its, o, ctx.ray_flags, ctx.path_at(), ctx.receiver)?;
            if le == Vec3::ZERO {
                return None;
            }
            // Only a nearer surface can block it (`t < hit.t` excludes the emitter itself:
            // both BVHs hold the same triangle, intersected with the same arithmetic).
            if self.occluded(ctx, o, d, hit.t) {
                return None;
            }
            return Some((e, le, rec));
        }
        self.background?;
        if self.occluded(ctx, o, d, f32::INFINITY) {
            return None;
        }
        self.background_radiance(d, o, ctx.depth, ctx.ray_flags)
    }

    /// [`RenderScene::emission_along`] in a scene with transparent surfaces: the first emission
    /// or background behind the transparent surfaces the path may still pass
    /// ([`Ctx::path_transparent_left`]), times their transmittance.
    fn emission_through(&self, ctx: &mut Ctx, o: Vec3, d: Vec3) -> Emitted {
        let mut tr = Vec3::ONE;
        let mut p = o;
        let mut m = ctx.medium;
        for _ in 0..=ctx.path_transparent_left() {
            let hit = self.intersect(ctx, p, d);
            if self.absorbs {
                let t = hit.as_ref().map_or(f32::INFINITY, |h| h.t);
                tr *= medium::transmittance(m.sigma_t(), t);
            }
            let (e, le, rec) = match &hit {
                Some(its) => match self.emitted(its, o, ctx.ray_flags, ctx.path_at(), ctx.receiver)
                {
                    Some(x) => x,
                    None => (0, Vec3::ZERO, EmitterQueryRecord::default()),
                },
                None => {
                    return self
                        .background_radiance(d, o, ctx.depth, ctx.ray_flags)
                        .map(|(e, le, r)| (e, le * tr, r));
                }
            };
            if le != Vec3::ZERO {
                return Some((e, le * tr, rec));
            }
            let its = hit?;
            tr *= self.transparency(ctx, &its, d);
            if tr == Vec3::ZERO {
                return None;
            }
            if self.absorbs {
                m = medium::after(self, &its, d, d, m);
            }
            p = offset_origin(its.p, its.ng, d);
        }
        None
    }

    /// The straight-through transmittance of the surface at `its` for a shadow ray along `d`.
    fn transparency(&self, ctx: &mut Ctx, its: &Intersection, d: Vec3) -> Vec3 {
        let program = &self.programs[its.material as usize];
        if !program.may_pass() {
            return Vec3::ZERO;
        }
        let g = self.globals(its, d, 2, crate::shading::globals::ray::SHADOW);
        program.transparency(&g, &self.shade_env(), &mut ctx.shade)
    }

    /// The fraction of light from the sample `rec` of emitter `light` that reaches surface
    /// point `p` (geometric normal `ng`): 1 or 0 for opaque scenes, the product of the
    /// transparent surfaces' and the absorbing interiors' transmittance in between otherwise
    /// (starting in `ctx.medium`). With shadow linking only the light's blockers stop it.
    #[inline]
    pub fn transmittance(
        &self,
        ctx: &mut Ctx,
        p: Vec3,
        ng: Vec3,
        (light, rec): (u32, &EmitterQueryRecord),
    ) -> Vec3 {
        let blockers = self.blockers_of(light);
        if !self.passes
            && self.hides & ray::SHADOW == 0
            && ctx.medium.is_clear()
            && blockers == LightLinks::ALL
        {
            return if self.unoccluded(ctx, p, ng, rec) {
                Vec3::ONE
            } else {
                Vec3::ZERO
            };
        }
        let o = offset_origin(p, ng, rec.wi);
        let (d, tmax) = if rec.dist.is_finite() {
            let target = offset_origin(rec.p, rec.ng, -rec.wi);
            let v = target - o;
            let dist = v.length();
            if dist <= 0.0 || !dist.is_finite() {
                return Vec3::ONE;
            }
            (v / dist, dist * (1.0 - 1e-6))
        } else {
            (rec.wi, f32::INFINITY)
        };
        let left = ctx.shadow_transparent_left();
        self.segment_transmittance(ctx, (o, d, tmax), ctx.medium, blockers, left)
    }

    /// The transmittance of the segment `o + t d`, `t ∈ (0, tmax)`, which starts in medium
    /// `m`: 1 or 0 in opaque scenes, the product of the transparent surfaces' transmittance
    /// and of the interiors' extinction ([`crate::medium`]) otherwise; only objects of the
    /// blocker sets `blockers` stop it. More than `passes` transparent surfaces block it as
    /// an opaque one does (Cycles' transparent bounce limit).
    fn segment_transmittance(
        &self,
        ctx: &mut Ctx,
        (o, d, tmax): (Vec3, Vec3, f32),
        m: Medium,
        blockers: u64,
        passes: u32,
    ) -> Vec3 {
        if !self.passes && self.hides & ray::SHADOW == 0 && blockers == LightLinks::ALL {
            ctx.cast(o, d, tmax, RayKind::Any);
            return if self.occluded(ctx, o, d, tmax) {
                Vec3::ZERO
            } else {
                medium::transmittance(m.sigma_t(), tmax)
            };
        }
        // The segment ends where it ended at the start: each origin moved off a surface is
        // a little further along, so the length left is measured to that end (subtracting
        // the hit distances would let the offsets add up and reach the light itself).
        let end = o + d * tmax;
        let (mut o, mut tmax) = (o, tmax);
        let (mut tr, mut m) = (Vec3::ONE, m);
        for _ in 0..=passes {
            ctx.cast(o, d, tmax, RayKind::Closest);
            let Some(hit) = self.closest_shadowing(ctx, o, d, tmax, blockers) else {
                return tr * medium::transmittance(m.sigma_t(), tmax);
            };
            let its = self.intersection(&hit, d, ctx.time);
            tr *= self.transparency(ctx, &its, d);
            if tr == Vec3::ZERO {
                return tr;
            }
            if self.absorbs {
                tr *= medium::transmittance(m.sigma_t(), hit.t);
                m = medium::after(self, &its, d, d, m);
            }
            o = offset_origin(its.p, its.ng, d);
            if tmax.is_finite() {
                tmax = (end - o).dot(d);
            }
            if tmax <= 0.0 {
                return tr;
            }
        }
        Vec3::ZERO
    }

    /// The full intersection record of `hit` (a hit of a ray along `d`).
    #[inline]
    fn intersection(&self, hit: &Hit, d: Vec3, time: f32) -> Intersection {
        let [mi, ti] = hit.key;
        let mesh = &self.scene.meshes[mi as usize];
        let (b1, b2) = (hit.u, hit.v);
        let len = hit.ng.length();
        let mut ng = if len > 0.0 && len.is_finite() {
            hit.ng / len
        } else {
            -d
        };
        // Vertex attributes only when the mesh has them (position and geometric normal come
        // with the hit).
        let (ns, material) = if hit.instance == NO_INSTANCE {
            (mesh.shading_normal(ti, b1, b2).unwrap_or(ng), mesh.material)
        } else {
            let inst = &self.scene.instances[hit.instance as usize];
            let ns = mesh
                .interpolate(&mesh.normals, ti, b1, b2)
                .and_then(|n| (inst.normal_matrix_at(time) * n).try_normalize())
                .unwrap_or(ng);
            (ns, inst.material.unwrap_or(mesh.material))
        };
        let ng_flipped = ng.dot(ns) < 0.0;
        if ng_flipped {
            ng = -ng;
        }
        let uv = mesh
            .interpolate(&mesh.uvs, ti, b1, b2)
            .unwrap_or(Vec2::ZERO);
        Intersection {
            t: hit.t,
            p: hit.p,
            ng,
            ng_flipped,
            ns,
            uv,
            mesh: mi,
            instance: hit.instance,
            tri: ti,
            b1,
            b2,
            material: material as u32,
            emitter: self.mesh_emitter[mi as usize],
            time,
        }
    }

    /// Like [`RenderScene::intersect`] for the ray leaving path vertex `depth - 1`; camera rays
    /// (`depth == 1`) see the objects visible to the camera, whatever Light Path bits the
    /// context holds from an earlier path, and end at the camera's far clip
    /// ([`Ctx::camera_end`]).
    #[inline]
    pub fn trace(&self, ctx: &mut Ctx, o: Vec3, d: Vec3, depth: u32) -> Option<Intersection> {
        if depth != 1 {
            return self.intersect(ctx, o, d);
        }
        let tmax = ctx.camera_tmax(o, d);
        if let Some((o0, d0, t0, its)) = ctx.camera_hit
            && (o0, d0, t0) == (o, d, tmax)
        {
            return its;
        }
        ctx.cast(o, d, tmax, RayKind::Closest);
        let hit = if self.hides & ray::CAMERA == 0 {
            self.closest(ctx, o, d, tmax)
        } else {
            let kind = ray::CAMERA | ctx.catcher_kind();
            self.closest_seen(ctx, o, d, tmax, kind, LightLinks::ALL)
        };
        let its = hit.map(|h| self.intersection(&h, d, ctx.time));
        if ctx.camera_memo {
            ctx.camera_hit = Some((o, d, tmax, its));
        }
        its
    }

    /// True when nothing blocks the segment from surface point `p` (geometric normal `ng`)
    /// to the emitter sample `rec` (a point, or a direction at infinity).
    #[inline]
    pub fn unoccluded(&self, ctx: &mut Ctx, p: Vec3, ng: Vec3, rec: &EmitterQueryRecord) -> bool {
        let o = offset_origin(p, ng, rec.wi);
        if rec.dist.is_finite() {
            // Aim at the light point moved off its own surface, and stop just short of it.
            let target = offset_origin(rec.p, rec.ng, -rec.wi);
            let d = target - o;
            let dist = d.length();
            if dist <= 0.0 || !dist.is_finite() {
                return true;
            }
            let (d, tmax) = (d / dist, dist * (1.0 - 1e-6));
            ctx.cast(o, d, tmax, RayKind::Any);
            !self.occluded(ctx, o, d, tmax)
        } else {
            ctx.cast(o, rec.wi, f32::INFINITY, RayKind::Any);
            !self.occluded(ctx, o, rec.wi, f32::INFINITY)
        }
    }

    /// The image size Window coordinates span (each render sets its own).
    pub fn set_window_resolution(&self, width: u32, height: u32) {
        self.window.set_resolution(width, height);
    }

    /// The scene data shading programs may read.
    #[inline]
    pub fn shade_env(&self) -> ShadeEnv<'_> {
        ShadeEnv {
            images: &self.scene.images,
            textures: &self.scene.textures,
            camera_to_world: self.camera_to_world,
            window: &self.window,
            tracer: Some(self),
        }
    }

    /// The shading point of a hit seen along the unit direction `d` at path vertex `depth`.
    #[inline]
    pub fn globals<'a>(
        &'a self,
        its: &Intersection,
        d: Vec3,
        depth: u32,
        flags: u32,
    ) -> ShaderGlobals<'a> {
        let backfacing = its.ng.dot(d) > 0.0;
        let (n, ng) = if backfacing {
            (-its.ns, -its.ng)
        } else {
            (its.ns, its.ng)
        };
        ShaderGlobals {
            p: to_blender(its.p),
            n: to_blender(n),
            n_displaced: false,
            ng: to_blender(ng),
            i: to_blender(-d),
            backfacing,
            mesh: Some(&self.scene.meshes[its.mesh as usize]),
            instance: self.scene.instances.get(its.instance as usize),
            tri: its.tri,
            b1: its.b1,
            b2: its.b2,
            uv0: its.uv,
            // About a tenth of a pixel at a typical field of view.
            bump_step: its.t.max(1e-3) * 1e-4,
            ray_depth: depth,
            depths: Default::default(),
            ray_length: its.t,
            ray_flags: flags,
            object: [its.mesh, its.instance],
            seed: point_seed(its.p),
            time: its.time,
        }
    }

    /// Evaluates the hit's material and chooses one BSDF closure with the random number `u`
    /// (reused for the closure's own lobe choice): `(closure, 1 / choice probability)`, or
    /// `None` when the material has no BSDF there.
    #[inline]
    pub fn choose_closure<'a>(
        &'a self,
        ctx: &'a mut Ctx,
        its: &Intersection,
        d: Vec3,
        depth: u32,
        u: f32,
    ) -> Option<(&'a crate::shading::Closure, f32, f32)> {
        if depth <= 1 && self.holdout_at(its) {
            // A holdout object keeps only its transparency for camera rays (Cycles'
            // surface_shader_apply_holdout): the path goes on through that, or ends.
            let t = self.closures_at(ctx, its, d, depth).transparency();
            if t.max_element() <= 0.0 {
                return None;
            }
            let set = &mut ctx.shade.set;
            set.clear();
            set.push_transparent(t);
            return Some((&set.closures[0], 1.0, u));
        }
        let set = self.closures_at(ctx, its, d, depth);
        let (i, p, u) = set.choose(u)?;
        Some((&set.closures[i], 1.0 / p, u))
    }

    /// The closures of the hit's material at path vertex `depth`.
    #[inline]
    fn closures_at<'a>(
        &'a self,
        ctx: &'a mut Ctx,
        its: &Intersection,
        d: Vec3,
        depth: u32,
    ) -> &'a crate::shading::ClosureSet {
        let program = &self.programs[its.material as usize];
        // Constant materials (most of them) need no shading point at all.
        match program.constant_set() {
            Some(set) => set,
            None => {
                let flags = if depth <= 1 {
                    crate::shading::globals::ray::CAMERA
                } else {
                    ctx.ray_flags
                };
                let mut g = self.globals(its, d, depth, flags);
                g.depths = ctx.depths;
                let env = self.shade_env();
                program.eval(&g, &env, &mut ctx.shade)
            }
        }
    }

    /// Surface albedo at a hit (the debug view): the chosen closure's colour.
    pub fn albedo(&self, ctx: &mut Ctx, its: &Intersection, d: Vec3) -> Vec3 {
        let Some((c, _, _)) = self.choose_closure(ctx, its, d, 1, 0.5) else {
            return Vec3::ZERO;
        };
        c.weight
            * match c.kind {
                ClosureKind::Principled(p) => p.base_color,
                ClosureKind::Diffuse { color, .. }
                | ClosureKind::Glossy { color, .. }
                | ClosureKind::Glass { color, .. }
                | ClosureKind::Refraction { color, .. }
                | ClosureKind::Translucent { color }
                | ClosureKind::Toon { color, .. }
                | ClosureKind::Transparent { color } => color,
                ClosureKind::Subsurface { .. } => Vec3::ONE,
                ClosureKind::Hair(h) => h.hair_albedo(),
            }
    }

    /// Radiance emitted by the hit surface towards `from` (the ray's origin) along a ray of
    /// Light Path bits `flags`, the hit being path vertex `path.0` after the bounces `path.1`,
    /// with the emitter's index for MIS.
    #[inline]
    pub fn emitted(
        &self,
        its: &Intersection,
        from: Vec3,
        flags: u32,
        path: PathAt,
        receiver: u8,
    ) -> Emitted {
        let e = its.emitter?;
        if !self.lights_receiver(e, receiver) {
            return None;
        }
        if flags & crate::shading::globals::ray::CAMERA != 0 && self.holdout_at(its) {
            return None;
        }
        let mut rec = EmitterQueryRecord::between(from, its.p, its.ns, its.ng, its.uv);
        rec.ray_flags = flags;
        (rec.depth, rec.depths) = path;
        rec.tri = its.tri;
        rec.bary = Vec2::new(its.b1, its.b2);
        let le = self.emitters[e as usize].eval(&self.scene, &rec);
        Some((e, le, rec))
    }

    /// The radiance a ray from `o` along `d` meets at `hit`: that surface's emission, or the
    /// background's if the ray escaped (`hit` is `None`; the ray leads to path vertex `depth`
    /// and has Light Path bits `flags`).
    #[inline]
    pub fn emission_at(
        &self,
        hit: Option<&Intersection>,
        o: Vec3,
        d: Vec3,
        (depth, depths): PathAt,
        flags: u32,
        receiver: u8,
    ) -> Emitted {
        match hit {
            Some(its) => self.emitted(its, o, flags, (depth, depths), receiver),
            None => self.background_radiance(d, o, depth, flags),
        }
    }

    /// Background radiance for a ray leaving the scene along `d` from `from`, leading to path
    /// vertex `depth` with Light Path bits `flags`. Camera rays see nothing when the world is
    /// hidden from the camera or the film is transparent; rays scattered by a kind of closure
    /// the world is hidden from (diffuse, glossy, transmission) neither.
    #[inline]
    pub fn background_radiance(&self, d: Vec3, from: Vec3, depth: u32, flags: u32) -> Emitted {
        let b = self.background?;
        if flags & crate::shading::globals::ray::CAMERA != 0
            && (!self.scene.world.visible_camera || self.scene.settings.film_transparent)
        {
            return None;
        }
        // Closures the world is hidden from do not see it along the rays they scatter.
        if depth > 1 && !self.ray_sees(b, depth, flags) {
            return None;
        }
        let rec = EmitterQueryRecord::towards(from, d);
        let le = match &self.emitters[b as usize] {
            EmitterInstance::Environment(env) => env.radiance(&self.scene, d, depth, flags),
            e => e.eval(&self.scene, &rec),
        };
        Some((b, le, rec))
    }

    /// The world's radiance along `d` (from `from`) as the camera sees it with an opaque film
    /// (the Environment pass); zero when the world is hidden from the camera.
    pub fn world_radiance(&self, d: Vec3, from: Vec3) -> Vec3 {
        let Some(b) = self.background else {
            return Vec3::ZERO;
        };
        if !self.scene.world.visible_camera {
            return Vec3::ZERO;
        }
        let flags = crate::shading::globals::ray::CAMERA;
        match &self.emitters[b as usize] {
            EmitterInstance::Environment(env) => env.radiance(&self.scene, d, 1, flags),
            e => e.eval(&self.scene, &EmitterQueryRecord::towards(from, d)),
        }
    }

    /// Cycles' Film > Transparent Glass, on with a transparent film: the most
    /// `alpha_x · alpha_y` (GGX alphas, each the roughness squared) of a transmission that keeps
    /// a camera path's transparent background, i.e. the roughness threshold to the fourth
    /// power (Cycles' `transparent_roughness_squared_threshold`); `None` when off.
    #[inline]
    pub fn transparent_glass(&self) -> Option<f32> {
        let s = &self.scene.settings;
        if !s.film_transparent {
            return None;
        }
        s.film_transparent_glass.map(|t| (t * t) * (t * t))
    }

    /// The film's coverage along a camera ray (its alpha): 1 without `film_transparent`;
    /// with it, 1 where the ray meets an opaque surface, 0 where it escapes to the world, and
    /// one minus the mean transmittance of the transparent surfaces it passes on the way out
    /// (Cycles' `1 - average(throughput)`). Deterministic: it draws no random numbers.
    pub fn camera_coverage(&self, ctx: &mut Ctx, o: Vec3, d: Vec3) -> f32 {
        if !self.scene.settings.film_transparent {
            return 1.0;
        }
        // `held`: the share taken out by holdouts seen through the transparent surfaces so
        // far (Cycles' `average(holdout_weight · throughput)`).
        let (mut tr, mut held) = (Vec3::ONE, 0.0f32);
        let mut p = o;
        // The camera path passes as many transparent surfaces (the integrator's limit).
        for _ in 0..=ctx.transparent_max.max(1) {
            let Some(its) = self.trace(ctx, p, d, 1) else {
                return (1.0 - (tr.x + tr.y + tr.z) / 3.0 - held).clamp(0.0, 1.0);
            };
            let program = &self.programs[its.material as usize];
            let holdout = self.holdout_at(&its);
            if !program.may_pass() && !holdout {
                return (1.0 - held).clamp(0.0, 1.0);
            }
            let g = self.globals(&its, d, 1, crate::shading::globals::ray::CAMERA);
            let set = program.eval(&g, &self.shade_env(), &mut ctx.shade);
            let through = set.transparency();
            // A holdout object holds out all but its transparency.
            let cut = if holdout {
                Vec3::ONE - through
            } else {
                set.holdout
            };
            held += (tr * cut).element_sum() / 3.0;
            tr *= through;
            if tr.max_element() <= 0.0 {
                return (1.0 - held).clamp(0.0, 1.0);
            }
            p = offset_origin(its.p, its.ng, d);
        }
        (1.0 - held).clamp(0.0, 1.0)
    }

    /// Light-selection probability times the emitter's solid-angle density of `rec` — the
    /// density of emitter sampling producing this direction, for MIS.
    #[inline]
    pub fn light_pdf(&self, emitter: u32, rec: &EmitterQueryRecord, receiver: u8) -> f32 {
        self.light_choice(true, receiver)
            .pmf_at(rec.ref_p, emitter as usize)
            * self.emitters[emitter as usize].pdf(&self.scene, rec)
    }

    /// The light choice of emitter sampling combined with BSDF sampling by MIS (`mis`), or on
    /// its own, for `receiver` ([`Ctx::receiver`]: among the lights linked to it).
    #[inline]
    pub fn light_choice(&self, mis: bool, receiver: u8) -> &LightSampler {
        if let Some(l) = &self.linking
            && let Some((lights, mis_lights)) = l.choices.get((receiver as usize).wrapping_sub(1))
        {
            return match mis_lights {
                Some(m) if mis => m,
                _ => lights,
            };
        }
        match &self.mis_lights {
            Some(l) if mis => l,
            _ => &self.lights,
        }
    }

    /// Chooses an emitter and samples it from `ref_p`, the path being at the vertex and
    /// bounces `path` its emitter's shader sees ([`Ctx::light_sample_at`]); `mis`: the sample
    /// is combined with BSDF sampling by MIS ([`Self::light_choice`]), among the lights linked
    /// to `receiver`. Returns the record and the weight `Le / (pmf · pdf)` (zero when no light
    /// could be sampled).
    #[inline]
    pub fn sample_light(
        &self,
        ref_p: Vec3,
        (u_choice, u): (f32, Vec2),
        (depth, depths): PathAt,
        (mis, receiver): (bool, u8),
    ) -> (u32, EmitterQueryRecord, Vec3) {
        let mut rec = EmitterQueryRecord::from_ref(ref_p);
        (rec.depth, rec.depths) = (depth, depths);
        let Some((i, pmf)) = self.light_choice(mis, receiver).sample_at(ref_p, u_choice) else {
            return (0, rec, Vec3::ZERO);
        };
        let w = self.emitters[i].sample(&self.scene, &mut rec, u);
        rec.pdf *= pmf;
        (i as u32, rec, w / pmf)
    }

    /// Whether emitter `i` is a delta light.
    pub fn is_delta_light(&self, i: u32) -> bool {
        self.emitters[i as usize].is_delta()
    }

    /// The BVH over every triangle.
    pub fn accel(&self) -> &Accel {
        &self.accel
    }

    /// Triangles rendered: world-space meshes once, placed meshes once per instance.
    pub fn triangle_count(&self) -> u64 {
        self.triangles as u64 + self.instances.as_ref().map_or(0, |i| i.triangles())
    }
}

/// Replaces each instance whose material may emit by a world-space copy of its mesh, so
/// that area emitters sample the instance's own triangles (areas under its scale). Returns
/// whether a moving instance was baked (at its frame transform: its motion is dropped).
fn bake_emissive_instances(scene: &mut Scene, programs: &[Arc<Program>]) -> bool {
    let emits = |scene: &Scene, i: &crate::scene::Instance| {
        let Some(mesh) = scene.meshes.get(i.mesh) else {
            return false;
        };
        let m = i.material.unwrap_or(mesh.material);
        programs.get(m).is_some_and(|p| p.may_emit())
    };
    if !scene.instances.iter().any(|i| emits(scene, i)) {
        return false;
    }
    let mut dropped_motion = false;
    let was_placed = scene.placed_meshes();
    let instances = std::mem::take(&mut scene.instances);
    for inst in instances {
        if emits(scene, &inst) {
            dropped_motion |= inst.motion.is_some();
            let baked = scene.meshes[inst.mesh].placed(&inst);
            scene.meshes.push(baked);
        } else {
            scene.instances.push(inst);
        }
    }
    // A mesh whose every instance was baked must not be drawn in its object space.
    let placed = scene.placed_meshes();
    for (mi, was) in was_placed.into_iter().enumerate() {
        if was && !placed[mi] {
            let m = &mut scene.meshes[mi];
            m.indices = Vec::new();
            m.positions = Vec::new();
        }
    }
    dropped_motion
}

/// Where emitter `e` emits from and in which directions, for a light tree; `None` for
/// emitters at infinity.
fn light_bounds(scene: &Scene, e: &EmitterInstance) -> Option<LightBounds> {
    use crate::emitter::spot::spot_cos_outer;
    let spot = |lo: Vec3, hi: Vec3, axis: Vec3, f: &crate::scene::SpotFalloff| LightBounds {
        lo,
        hi,
        phi: 1.0,
        axis,
        theta_o: spot_cos_outer(f).clamp(-1.0, 1.0).acos(),
        theta_e: 0.0,
    };
    Some(match e.shape() {
        EmitterInstance::Area(a) => {
            let m = &scene.meshes[a.mesh];
            let lo = m.positions.iter().fold(Vec3::INFINITY, |l, p| l.min(*p));
            let hi = m
                .positions
                .iter()
                .fold(Vec3::NEG_INFINITY, |h, p| h.max(*p));
            LightBounds::omni(lo, hi, 1.0)
        }
        EmitterInstance::Point(p) => LightBounds::omni(p.position, p.position, 1.0),
        EmitterInstance::Spot(s) => spot(s.position, s.position, s.direction, &s.falloff),
        EmitterInstance::Sphere(s) => {
            let (lo, hi) = (s.position - s.radius, s.position + s.radius);
            match &s.spot {
                Some((axis, f)) => spot(lo, hi, *axis, f),
                None => LightBounds::omni(lo, hi, 1.0),
            }
        }
        EmitterInstance::AreaLight(a) => {
            let c = a.corners();
            LightBounds {
                lo: c.iter().fold(c[0], |m, p| m.min(*p)),
                hi: c.iter().fold(c[0], |m, p| m.max(*p)),
                phi: 1.0,
                axis: a.normal,
                theta_o: 0.0,
                theta_e: a.half_spread(),
            }
        }
        _ => return None,
    })
}

/// The emitter of a Blender light. A point or spot light of zero radius (or one so small that
/// its radiance overflows) stays a delta light.
fn blender_emitter(shape: &LightShape) -> EmitterInstance {
    use std::f32::consts::PI;
    match *shape {
        LightShape::Point {
            position,
            intensity,
            radius,
            soft_falloff,
            spot,
        } => {
            let radiance = intensity / (PI * radius * radius);
            if radius > 0.0 && radiance.is_finite() {
                return EmitterInstance::Sphere(SphereLight {
                    position,
                    radius,
                    radiance,
                    sphere: !soft_falloff,
                    spot: spot.map(|(d, f)| (d.normalize(), f)),
                });
            }
            match spot {
                Some((direction, falloff)) => EmitterInstance::Spot(SpotLight {
                    position,
                    direction: direction.normalize(),
                    intensity,
                    falloff,
                }),
                None => EmitterInstance::Point(PointLight {
                    position,
                    intensity,
                }),
            }
        }
        LightShape::Sun {
            direction,
            irradiance,
            angle,
        } => EmitterInstance::Directional(Directional::new(direction, irradiance, angle)),
        LightShape::Area {
            center,
            axis_u,
            axis_v,
            normal,
            size_u,
            size_v,
            ellipse,
            radiance,
            spread,
        } => EmitterInstance::AreaLight(AreaLight::new(
            center, axis_u, axis_v, normal, size_u, size_v, ellipse, radiance, spread,
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{Sampler, SobolSampler};
    use crate::sampling::square_to_uniform_sphere;
    use crate::scene::builtin;

    /// Camera rays (path vertex 1) end at `Ctx::camera_end`, also past a transparent surface
    /// or a hidden mesh (a segment from a later origin on the same ray); other rays do not.
    #[test]
    fn camera_rays_end_at_the_far_clip() {
        let rs = RenderScene::new(builtin::by_name("cornell-box").unwrap(), LightChoice::Power);
        let mut ctx = Ctx::new(SobolSampler::new(0, 0, 0));
        let (o, d) = (Vec3::new(0.0, 0.0, 0.5), Vec3::new(0.0, 0.0, -1.0));
        let wall = rs.intersect(&mut ctx, o, d).expect("the back wall").t;
        for (end, hits) in [(0.9 * wall, false), (1.1 * wall, true)] {
            ctx.camera_end = Some(o + d * end);
            assert_eq!(
                rs.trace(&mut ctx, o, d, 1).is_some(),
                hits,
                "end {end}, wall {wall}"
            );
            // A later segment of the same camera ray: the end stays where it was.
            let o2 = o + d * (0.5 * wall);
            assert_eq!(rs.trace(&mut ctx, o2, d, 1).is_some(), hits);
            assert!(
                rs.trace(&mut ctx, o, d, 2).is_some(),
                "bounce rays are not clipped"
            );
        }
        ctx.camera_end = None;
        assert!(rs.trace(&mut ctx, o, d, 1).is_some());
    }

    /// Camera rays see what the camera sees whatever bits an earlier path left in the context,
    /// and bounce rays what their kind sees, with and without a far clip.
    #[test]
    fn camera_and_bounce_rays_see_by_their_own_kind() {
        let mut rs = RenderScene::new(builtin::by_name("cornell-box").unwrap(), LightChoice::Power);
        let mut ctx = Ctx::new(SobolSampler::new(0, 0, 0));
        let (o, d) = (Vec3::new(0.0, 0.0, 0.5), Vec3::new(0.0, 0.0, -1.0));
        let wall = rs.intersect(&mut ctx, o, d).expect("the back wall");
        let seen = |rs: &RenderScene, ctx: &mut Ctx, depth| {
            rs.trace(ctx, o, d, depth)
                .is_some_and(|h| h.mesh == wall.mesh)
        };
        let bounce = ray::DIFFUSE | ray::REFLECTION;
        for end in [None, Some(o + d * (2.0 * wall.t))] {
            ctx.camera_end = end;
            rs.scene.meshes[wall.mesh as usize].attrs.object.visibility =
                ObjectInfo::VISIBLE_TO_ALL & !ray::DIFFUSE;
            rs.refresh_shading();
            ctx.ray_flags = bounce; // left by the previous sample's last bounce
            assert!(
                seen(&rs, &mut ctx, 1),
                "the camera sees a wall hidden from diffuse rays"
            );
            assert!(!seen(&rs, &mut ctx, 2), "diffuse rays pass through it");
            rs.scene.meshes[wall.mesh as usize].attrs.object.visibility =
                ObjectInfo::VISIBLE_TO_ALL & !ray::CAMERA;
            rs.refresh_shading();
            assert!(
                !seen(&rs, &mut ctx, 1),
                "camera rays pass through a camera-hidden wall"
            );
            assert!(seen(&rs, &mut ctx, 2), "diffuse rays see it");
        }
    }

    /// An emissive graph that reads the viewing direction and the side it is seen from
    /// (emission colour |Incoming|, strength 1 + Backfacing, on a two-sided triangle) must give
    /// the same radiance to a light sample and to a ray that hits the same point (the two MIS
    /// strategies), and that radiance must be the analytic one.
    #[test]
    fn emission_graphs_see_the_same_point_from_light_samples_and_hits() {
        use crate::emitter::{Emitter, EmitterQueryRecord};
        use crate::shading::globals::to_blender;
        let graph = serde_json::json!({
            "nodes": [
                {"type": "ShaderNodeNewGeometry"},
                {"type": "ShaderNodeVectorMath", "props": {"operation": "ABSOLUTE"},
                 "inputs": {"Vector": {"link": [0, "Incoming"]}}},
                {"type": "ShaderNodeMath", "props": {"operation": "ADD"},
                 "inputs": {"Value": {"link": [0, "Backfacing"]}, "Value_001": 1.0}},
                {"type": "ShaderNodeEmission", "inputs": {"Color": {"link": [1, "Vector"]},
                 "Strength": {"link": [2, "Value"]}}}
            ],
            "surface": [3, "Emission"]
        });
        let mut light = crate::scene::Material::emitter("light", Vec3::ONE, true);
        light.graph = Some(std::sync::Arc::new(
            crate::shading::Graph::from_json(&graph).unwrap(),
        ));
        let mut mesh = crate::scene::Mesh {
            name: "light".into(),
            ..Default::default()
        };
        // A tilted triangle; its normal (right-hand rule) points to +y mostly.
        mesh.positions = vec![
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(-0.2, 0.3, 1.2),
            Vec3::new(1.3, -0.2, -0.6),
        ];
        mesh.indices = vec![[0, 1, 2]];
        let ng = (mesh.positions[1] - mesh.positions[0])
            .cross(mesh.positions[2] - mesh.positions[0])
            .normalize();
        let scene = crate::scene::Scene {
            meshes: vec![mesh],
            materials: vec![light],
            ..Default::default()
        };
        let rs = RenderScene::new(scene, LightChoice::Power);
        let emitter = &rs.emitters[rs.mesh_emitter[0].unwrap() as usize];
        let mut rng = Sampler::new(3, 0, 0);
        let mut ctx = Ctx::new(SobolSampler::new(0, 0, 0));
        let (mut front, mut back) = (0, 0);
        for _ in 0..2000 {
            let ref_p = (Vec3::new(rng.next_1d(), rng.next_1d(), rng.next_1d()) - 0.5) * 6.0;
            let mut rec = EmitterQueryRecord::from_ref(ref_p);
            let weight = emitter.sample(&rs.scene, &mut rec, rng.next_2d());
            if rec.pdf <= 0.0 || weight == Vec3::ZERO {
                continue;
            }
            let sampled = weight * rec.pdf;
            let its = rs
                .intersect(&mut ctx, ref_p, rec.wi)
                .expect("the ray hits the light");
            let (_, hit, _) = rs
                .emitted(&its, ref_p, 0, (1, Default::default()), 0)
                .unwrap();
            let backfacing = ng.dot(rec.wi) > 0.0;
            let expected = to_blender(-rec.wi).abs() * if backfacing { 2.0 } else { 1.0 };
            let tol = 1e-4 * expected.max_element();
            assert!(
                (sampled - hit).abs().max_element() <= tol,
                "{sampled} vs {hit}"
            );
            assert!(
                (sampled - expected).abs().max_element() <= tol,
                "{sampled} vs {expected}"
            );
            if backfacing {
                back += 1;
            } else {
                front += 1;
            }
        }
        assert!(front > 500 && back > 500, "{front} front, {back} back");
    }

    /// `emission_along` must return what a full closest-hit trace returns, for rays that hit
    /// the light, rays blocked before it (by the spheres), rays that escape to the background
    /// and rays that hit nothing emissive; with and without a background.
    #[test]
    fn emission_along_equals_a_full_trace() {
        for background in [Vec3::ZERO, Vec3::new(0.2, 0.3, 0.4)] {
            let mut scene = builtin::by_name("cornell-spheres").unwrap();
            scene.background = background;
            // A ball hanging just under the light blocks rays right before they reach it.
            let m = scene.meshes[0].material;
            let ball = builtin::sphere("ball", m, Vec3::new(0.05, 0.85, 0.0), 0.08, 16, 32);
            scene.meshes.push(ball);
            let rs = RenderScene::new(scene, LightChoice::Power);
            assert!(rs.emitter_accel.is_some());
            let (lo, hi) = rs.scene.bounds().unwrap();
            let mut rng = Sampler::new(7, 0, 0);
            let mut ctx = Ctx::new(SobolSampler::new(0, 0, 0));
            let (mut lit, mut blocked, mut escaped) = (0, 0, 0);
            for _ in 0..400_000 {
                let u = Vec3::new(rng.next_1d(), rng.next_1d(), rng.next_1d());
                // Origins inside (and a little outside) the box, all directions.
                let o = lo - (hi - lo) * 0.05 + (hi - lo) * 1.1 * u;
                let d = square_to_uniform_sphere(rng.next_2d());
                let fast = rs.emission_along(&mut ctx, o, d);
                let hit = rs.intersect(&mut ctx, o, d);
                let full = rs.emission_at(hit.as_ref(), o, d, ctx.path_at(), ctx.ray_flags, 0);
                let full = full.filter(|(_, le, _)| *le != Vec3::ZERO);
                match (&fast, &full) {
                    (Some((a, la, ra)), Some((b, lb, rb))) => {
                        assert_eq!(a, b);
                        assert_eq!(la, lb, "radiance along {o} {d}");
                        assert_eq!(ra.pdf, rb.pdf);
                        assert_eq!(ra.p, rb.p);
                        if rs.background == Some(*a) {
                            escaped += 1;
                        } else {
                            lit += 1;
                        }
                    }
                    (None, None) => {
                        if rs
                            .emitter_accel
                            .as_ref()
                            .unwrap()
                            .intersect(o, d, 0.0, f32::INFINITY)
                            .is_some()
                        {
                            blocked += 1;
                        }
                    }
                    _ => panic!("ray {o} {d}: fast {fast:?}, full {full:?}"),
                }
            }
            assert!(lit > 2000 && blocked > 500, "lit {lit}, blocked {blocked}");
            assert_eq!(
                escaped > 1000,
                background != Vec3::ZERO,
                "escaped {escaped}"
            );
        }
    }
}
