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
pub mod ies;
pub mod light_bvh;
pub mod light_tree;
pub mod point;
pub mod sphere;
pub mod spherical_triangle;
pub mod spot;

use crate::sampling::{DiscreteCdf, pick};
use crate::scene::Scene;
use glam::{Vec2, Vec3};

pub use area::AreaEmitter;
pub use area_light::AreaLight;
pub use background::Background;
pub use directional::Directional;
pub use environment::Environment;
pub use ies::IesLight;
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
    /// A point, spot or area light shaped by an IES profile.
    Ies(IesLight),
}

impl EmitterInstance {
    /// The emitter's shape: an IES light's own light, any other emitter itself.
    #[inline]
    pub fn shape(&self) -> &EmitterInstance {
        match self {
            EmitterInstance::Ies(l) => &l.light,
            e => e,
        }
    }
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
            EmitterInstance::Ies($e) => $body,
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

/// The luminance of what an emitter gives off, whatever its sign: a light of negative strength
/// (it removes light, as in Cycles) is chosen by the magnitude of its effect.
#[inline]
pub fn emitted_luminance(c: Vec3) -> f32 {
    luminance(c.abs())
}

/// How the integrators choose one light for a shadow ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LightChoice {
    /// Proportional to each emitter's power, refined per shading point by a light tree over
    /// the lights at finite positions that weighs their distance and orientation, against the
    /// lights at infinity by what each gives the point (see [`LightSampler::with_bounds`]).
    #[default]
    Power,
    /// Proportional to power, never through a light tree.
    Flat,
    /// The seed's uniform choice (every emitter with positive power equally likely).
    Uniform,
}

/// With this many lights at finite positions or more, [`LightChoice::Power`] uses a light tree
/// even without lights at infinity.
pub const TREE_MIN_LIGHTS: usize = 8;

/// A discrete distribution over the scene's emitters, possibly depending on the shading point.
#[derive(Clone, Debug, Default)]
pub struct LightSampler {
    cdf: DiscreteCdf,
    tree: Option<TreeChoice>,
}

/// Lights at finite positions in a light tree; the others (at infinity) chosen among
/// themselves by power, and against the tree as a group by importance at the point.
#[derive(Clone, Debug)]
struct TreeChoice {
    tree: light_tree::LightTree,
    /// Tree item → emitter, and emitter → tree item (`u32::MAX`: not in the tree).
    emitter_of: Vec<u32>,
    item_of: Vec<u32>,
    /// The emitters at infinity by power; entry → emitter, and emitter → entry.
    infinite: DiscreteCdf,
    infinite_emitter: Vec<u32>,
    infinite_of: Vec<u32>,
    /// The importance of the emitters at infinity against the tree's: the irradiance they
    /// give a facing surface, `E = power / (π r²)` (their power is what falls on a disc of
    /// the scene's radius `r`). The tree's `Φ / d²` is π times the irradiance of a facing
    /// emitter of power `Φ`, so a lamp counts π times a sun of equal irradiance: the lamp's
    /// importance is an upper bound and a sun is often shadowed indoors, and Cycles' light
    /// tree gives its distant lights the same handicap.
    infinite_importance: f32,
}

impl TreeChoice {
    /// Probability of choosing from the tree (rather than a light at infinity) at `p`.
    #[inline]
    fn tree_share(&self, p: Vec3) -> f32 {
        if self.infinite_importance <= 0.0 {
            return 1.0;
        }
        let wt = self.tree.importance(p);
        if wt > 0.0 {
            wt / (wt + self.infinite_importance)
        } else {
            0.0
        }
    }
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

    /// Builds the distribution for `choice`, for emitters of power `powers` (those at infinity:
    /// over a disc of the scene's radius `radius`). With [`LightChoice::Power`], the emitters
    /// with `bounds` (their `phi` their power) go into a light tree when there are
    /// [`TREE_MIN_LIGHTS`] of them, or any beside lights at infinity: a sun should not take
    /// the shadow rays of a lamp in the room by its power over the whole scene, but by what
    /// it gives the point against what the lamp gives it (as Cycles' light tree weighs its
    /// distant lights).
    pub fn with_bounds(
        powers: &[f32],
        bounds: &[Option<light_tree::LightBounds>],
        radius: f32,
        choice: LightChoice,
    ) -> Self {
        let mut flat = LightSampler::new(powers, choice);
        let usable = |p: f32| p > 0.0 && p.is_finite();
        let finite = bounds
            .iter()
            .zip(powers)
            .filter(|(b, p)| b.is_some() && usable(**p))
            .count();
        let infinite = bounds
            .iter()
            .zip(powers)
            .filter(|(b, p)| b.is_none() && usable(**p))
            .count();
        let wanted = finite >= TREE_MIN_LIGHTS || (finite > 0 && infinite > 0);
        if choice != LightChoice::Power || !wanted || flat.cdf.is_empty() {
            return flat;
        }
        let mut items = Vec::new();
        let mut emitter_of = Vec::new();
        let mut item_of = vec![u32::MAX; powers.len()];
        let mut infinite_weights = Vec::new();
        let mut infinite_emitter = Vec::new();
        let mut infinite_of = vec![u32::MAX; powers.len()];
        let mut infinite_power = 0.0f64;
        for (i, (b, &p)) in bounds.iter().zip(powers).enumerate() {
            if !usable(p) {
                continue;
            }
            match b {
                Some(b) => {
                    item_of[i] = items.len() as u32;
                    emitter_of.push(i as u32);
                    items.push(light_tree::LightBounds { phi: p, ..*b });
                }
                None => {
                    infinite_of[i] = infinite_weights.len() as u32;
                    infinite_weights.push(p);
                    infinite_emitter.push(i as u32);
                    infinite_power += p as f64;
                }
            }
        }
        let r2 = if radius > 0.0 && radius.is_finite() {
            (radius as f64) * (radius as f64)
        } else {
            1.0
        };
        flat.tree = Some(TreeChoice {
            tree: light_tree::LightTree::new(&items),
            emitter_of,
            item_of,
            infinite: DiscreteCdf::new(infinite_weights),
            infinite_emitter,
            infinite_of,
            infinite_importance: (infinite_power / (std::f64::consts::PI * r2)) as f32,
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
        let pt = t.tree_share(p);
        match pick(pt, u) {
            (true, u) => {
                let (item, pmf) = t.tree.sample(p, u)?;
                Some((t.emitter_of[item] as usize, pt * pmf))
            }
            (false, u) => {
                let (k, pk) = t.infinite.sample(u);
                Some((t.infinite_emitter[k] as usize, (1.0 - pt) * pk))
            }
        }
    }

    /// The probability that [`LightSampler::sample_at`] chooses emitter `i` at `p`.
    #[inline]
    pub fn pmf_at(&self, p: Vec3, i: usize) -> f32 {
        let Some(t) = &self.tree else {
            return self.pmf(i);
        };
        if t.infinite_of[i] != u32::MAX {
            return (1.0 - t.tree_share(p)) * t.infinite.pmf(t.infinite_of[i] as usize);
        }
        if t.item_of[i] == u32::MAX {
            return 0.0;
        }
        t.tree_share(p) * t.tree.pmf(p, t.item_of[i] as usize)
    }
}
