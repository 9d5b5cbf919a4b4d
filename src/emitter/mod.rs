//! Emitters: mesh area lights, punctual lights and the constant background.
//!
//! Queries follow nori's `EmitterQueryRecord`: a reference point `ref_p` (the shading point),
//! a point `p` on the emitter with normal `n`, and the unit direction `wi` **from `ref_p`
//! towards `p`**. Densities returned by `pdf` and stored by `sample` are per unit **solid angle
//! at `ref_p`** (zero for delta lights, which only `sample` can reach).

pub mod area;
pub mod area_light;
pub mod background;
pub mod directional;
pub mod environment;
pub mod light_bvh;
pub mod light_tree;
pub mod point;
pub mod sphere;
pub mod spot;

use crate::sampling::DiscreteCdf;
use crate::scene::Scene;
use glam::{Vec2, Vec3};

pub use area::AreaEmitter;
pub use area_light::AreaLight;
pub use background::Background;
pub use directional::Directional;
pub use environment::Environment;
pub use point::PointLight;
pub use sphere::SphereLight;
pub use spot::SpotLight;

/// An emitter query (nori's `EmitterQueryRecord`).
#[derive(Clone, Copy, Debug, Default)]
pub struct EmitterQueryRecord {
    /// The point being lit (world space).
    pub ref_p: Vec3,
    /// Point on the emitter (meaningless for lights at infinity).
    pub p: Vec3,
    /// Shading normal at `p`: decides which side emits.
    pub n: Vec3,
    /// Geometric normal at `p`: converts area density to solid angle.
    pub ng: Vec3,
    /// Texture coordinates at `p`.
    pub uv: Vec2,
    /// Triangle and barycentrics `(b1, b2)` of `p` on an emissive mesh.
    pub tri: u32,
    pub bary: Vec2,
    /// Unit direction from `ref_p` towards the emitter.
    pub wi: Vec3,
    /// Distance from `ref_p` to `p` (`f32::INFINITY` for lights at infinity).
    pub dist: f32,
    /// Solid-angle density of the sample (0 for delta lights).
    pub pdf: f32,
    /// Light Path bits the emitter's shader sees: none for light sampling (as Cycles
    /// evaluates emission for its light samples), the ray's own for a ray that hits it.
    pub ray_flags: u32,
    /// The path vertex the emitter's point is, for its shader's Light Path Ray Depth (1: seen
    /// from the camera; 0 counts as 1), and the path's bounces of each kind before it: as
    /// Cycles, a light sample from vertex `k` sees vertex `k + 1` and the bounces made
    /// before `k`.
    pub depth: u32,
    pub depths: crate::shading::globals::PathDepths,
}

impl EmitterQueryRecord {
    /// A record for sampling from `ref_p`.
    pub fn from_ref(ref_p: Vec3) -> Self {
        EmitterQueryRecord {
            ref_p,
            ..Default::default()
        }
    }

    /// A record for `eval`/`pdf` of a surface point `p` (normals `n`, `ng`) seen from `ref_p`.
    pub fn between(ref_p: Vec3, p: Vec3, n: Vec3, ng: Vec3, uv: Vec2) -> Self {
        let d = p - ref_p;
        let dist = d.length();
        EmitterQueryRecord {
            ref_p,
            p,
            n,
            ng,
            uv,
            tri: 0,
            bary: Vec2::ZERO,
            wi: d / dist,
            dist,
            pdf: 0.0,
            ray_flags: 0,
            depth: 0,
            depths: Default::default(),
        }
    }

    /// A record for `eval`/`pdf` of a direction to a light at infinity.
    pub fn towards(ref_p: Vec3, wi: Vec3) -> Self {
        EmitterQueryRecord {
            ref_p,
            wi,
            dist: f32::INFINITY,
            ..Default::default()
        }
    }

    /// The same emitter point seen from `origin`, a point behind `ref_p` on the same line
    /// (the vertex a ray left before it passed straight through transparent surfaces): the
    /// densities of light sampling are those of `origin`.
    pub fn seen_from(&self, origin: Vec3) -> Self {
        let mut r = *self;
        r.ref_p = origin;
        if r.dist.is_finite() {
            r.dist = (r.p - origin).length();
        }
        r
    }
}

/// One emitter.
pub trait Emitter {
    /// Samples a point/direction on the emitter as seen from `rec.ref_p`; fills `p`, `n`, `ng`,
    /// `wi`, `dist`, `pdf`, and returns the radiance divided by the solid-angle density
    /// (for delta lights: the incident radiance integral, e.g. `I / d²`). Zero on failure.
    fn sample(&self, scene: &Scene, rec: &mut EmitterQueryRecord, u: Vec2) -> Vec3;
    /// Radiance leaving the emitter at `rec.p` towards `rec.ref_p` (along `-rec.wi`).
    fn eval(&self, scene: &Scene, rec: &EmitterQueryRecord) -> Vec3;
    /// Solid-angle density with which `sample` produces `rec` (0 for delta lights).
    fn pdf(&self, scene: &Scene, rec: &EmitterQueryRecord) -> f32;
    /// Total emitted power (W, luminance-weighted), an estimate used for light selection.
    fn power(&self, scene: &Scene, scene_radius: f32) -> f32;
    /// True for point-like or direction-like lights that BSDF sampling can never hit.
    fn is_delta(&self) -> bool;
}

/// Every kind of emitter, stored by value.
#[derive(Clone, Debug)]
pub enum EmitterInstance {
    Area(AreaEmitter),
    Point(PointLight),
    Spot(SpotLight),
    Directional(Directional),
    Background(Background),
    /// A world that varies with direction (a node graph).
    Environment(Environment),
    /// A point or spot light with a radius.
    Sphere(SphereLight),
    /// A Blender area light.
    AreaLight(AreaLight),
}

macro_rules! dispatch {
    ($self:ident, $e:ident => $body:expr) => {
        match $self {
            EmitterInstance::Area($e) => $body,
            EmitterInstance::Point($e) => $body,
            EmitterInstance::Spot($e) => $body,
            EmitterInstance::Directional($e) => $body,
            EmitterInstance::Background($e) => $body,
            EmitterInstance::Environment($e) => $body,
            EmitterInstance::Sphere($e) => $body,
            EmitterInstance::AreaLight($e) => $body,
        }
    };
}

impl Emitter for EmitterInstance {
    #[inline]
    fn sample(&self, scene: &Scene, rec: &mut EmitterQueryRecord, u: Vec2) -> Vec3 {
        dispatch!(self, e => e.sample(scene, rec, u))
    }
    #[inline]
    fn eval(&self, scene: &Scene, rec: &EmitterQueryRecord) -> Vec3 {
        dispatch!(self, e => e.eval(scene, rec))
    }
    #[inline]
    fn pdf(&self, scene: &Scene, rec: &EmitterQueryRecord) -> f32 {
        dispatch!(self, e => e.pdf(scene, rec))
    }
    fn power(&self, scene: &Scene, scene_radius: f32) -> f32 {
        dispatch!(self, e => e.power(scene, scene_radius))
    }
    #[inline]
    fn is_delta(&self) -> bool {
        dispatch!(self, e => e.is_delta())
    }
}

/// Luminance of a linear Rec.709 colour (weights for light selection and Russian roulette).
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// How the integrators choose one light for a shadow ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LightChoice {
    /// Proportional to each emitter's power; in scenes with at least [`TREE_MIN_LIGHTS`]
    /// lights at finite positions, through a light tree that also weighs their distance and
    /// orientation at each shading point.
    #[default]
    Power,
    /// Proportional to power, never through a light tree.
    Flat,
    /// The seed's uniform choice (every emitter with positive power equally likely).
    Uniform,
}

/// With this many lights at finite positions or more, [`LightChoice::Power`] uses a light tree.
pub const TREE_MIN_LIGHTS: usize = 8;

/// A discrete distribution over the scene's emitters, possibly depending on the shading point.
#[derive(Clone, Debug, Default)]
pub struct LightSampler {
    cdf: DiscreteCdf,
    tree: Option<TreeChoice>,
}

/// Lights at finite positions in a light tree; the others (at infinity) chosen by power, against
/// the tree as a whole by its total power.
#[derive(Clone, Debug)]
struct TreeChoice {
    tree: light_tree::LightTree,
    /// Tree item → emitter, and emitter → tree item (`u32::MAX`: not in the tree).
    emitter_of: Vec<u32>,
    item_of: Vec<u32>,
    /// Entries: the emitters at infinity, then the tree.
    top: DiscreteCdf,
    /// Top entry → emitter (`u32::MAX` for the tree), and emitter → top entry.
    top_emitter: Vec<u32>,
    top_of: Vec<u32>,
}

impl LightSampler {
    /// Builds the distribution; emitters with zero power are never chosen.
    pub fn new(powers: &[f32], choice: LightChoice) -> Self {
        let weights = powers.iter().map(|&p| match choice {
            LightChoice::Power | LightChoice::Flat => p,
            LightChoice::Uniform => {
                if p > 0.0 && p.is_finite() {
                    1.0
                } else {
                    0.0
                }
            }
        });
        LightSampler {
            cdf: DiscreteCdf::new(weights),
            tree: None,
        }
    }

    /// Builds the distribution for `choice`, with a light tree over the emitters that have
    /// `bounds` (their `phi` their power) when `choice` is [`LightChoice::Power`] and there are
    /// enough of them.
    pub fn with_bounds(
        powers: &[f32],
        bounds: &[Option<light_tree::LightBounds>],
        choice: LightChoice,
    ) -> Self {
        let mut flat = LightSampler::new(powers, choice);
        let usable = |p: f32| p > 0.0 && p.is_finite();
        let finite = bounds
            .iter()
            .zip(powers)
            .filter(|(b, p)| b.is_some() && usable(**p))
            .count();
        if choice != LightChoice::Power || finite < TREE_MIN_LIGHTS || flat.cdf.is_empty() {
            return flat;
        }
        let mut items = Vec::new();
        let mut emitter_of = Vec::new();
        let mut item_of = vec![u32::MAX; powers.len()];
        let mut top_weights = Vec::new();
        let mut top_emitter = Vec::new();
        let mut top_of = vec![u32::MAX; powers.len()];
        let mut tree_power = 0.0f64;
        for (i, (b, &p)) in bounds.iter().zip(powers).enumerate() {
            if !usable(p) {
                continue;
            }
            match b {
                Some(b) => {
                    item_of[i] = items.len() as u32;
                    emitter_of.push(i as u32);
                    items.push(light_tree::LightBounds { phi: p, ..*b });
                    tree_power += p as f64;
                }
                None => {
                    top_of[i] = top_weights.len() as u32;
                    top_weights.push(p);
                    top_emitter.push(i as u32);
                }
            }
        }
        top_weights.push(tree_power as f32);
        top_emitter.push(u32::MAX);
        flat.tree = Some(TreeChoice {
            tree: light_tree::LightTree::new(&items),
            emitter_of,
            item_of,
            top: DiscreteCdf::new(top_weights),
            top_emitter,
            top_of,
        });
        flat
    }

    pub fn is_empty(&self) -> bool {
        self.cdf.is_empty()
    }

    /// Whether the choice depends on the shading point (a light tree).
    pub fn uses_tree(&self) -> bool {
        self.tree.is_some()
    }

    /// `(emitter index, probability)`; `u` is rescaled for reuse. Ignores a light tree.
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        self.cdf.sample(u)
    }

    /// Probability of choosing emitter `i`, ignoring a light tree.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        if self.cdf.is_empty() {
            0.0
        } else {
            self.cdf.pmf(i)
        }
    }

    /// Chooses an emitter for a shading point at `p`: `(emitter index, probability)`, or
    /// `None` when there is none (or none can reach `p`).
    #[inline]
    pub fn sample_at(&self, p: Vec3, u: f32) -> Option<(usize, f32)> {
        if self.cdf.is_empty() {
            return None;
        }
        let Some(t) = &self.tree else {
            return Some(self.cdf.sample(u));
        };
        let (k, u) = t.top.sample_reuse(u);
        let pk = t.top.pmf(k);
        let e = t.top_emitter[k];
        if e != u32::MAX {
            return Some((e as usize, pk));
        }
        let (item, pmf) = t.tree.sample(p, u)?;
        Some((t.emitter_of[item] as usize, pk * pmf))
    }

    /// The probability that [`LightSampler::sample_at`] chooses emitter `i` at `p`.
    #[inline]
    pub fn pmf_at(&self, p: Vec3, i: usize) -> f32 {
        let Some(t) = &self.tree else {
            return self.pmf(i);
        };
        if t.top_of[i] != u32::MAX {
            return t.top.pmf(t.top_of[i] as usize);
        }
        if t.item_of[i] == u32::MAX {
            return 0.0;
        }
        t.top.pmf(t.top.len() - 1) * t.tree.pmf(p, t.item_of[i] as usize)
    }
}
