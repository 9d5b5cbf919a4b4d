//! Emitters: mesh area lights, punctual lights and the constant background.
//!
//! Queries follow nori's `EmitterQueryRecord`: a reference point `ref_p` (the shading point),
//! a point `p` on the emitter with normal `n`, and the unit direction `wi` **from `ref_p`
//! towards `p`**. Densities returned by `pdf` and stored by `sample` are per unit **solid angle
//! at `ref_p`** (zero for delta lights, which only `sample` can reach).

pub mod area;
pub mod background;
pub mod directional;
pub mod point;
pub mod spot;

use crate::sampling::DiscreteCdf;
use crate::scene::Scene;
use glam::{Vec2, Vec3};

pub use area::AreaEmitter;
pub use background::Background;
pub use directional::Directional;
pub use point::PointLight;
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
}

macro_rules! dispatch {
    ($self:ident, $e:ident => $body:expr) => {
        match $self {
            EmitterInstance::Area($e) => $body,
            EmitterInstance::Point($e) => $body,
            EmitterInstance::Spot($e) => $body,
            EmitterInstance::Directional($e) => $body,
            EmitterInstance::Background($e) => $body,
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
    /// Probability proportional to each emitter's power.
    #[default]
    Power,
    /// The seed's uniform choice (every emitter with positive power equally likely).
    Uniform,
}

/// A discrete distribution over the scene's emitters.
#[derive(Clone, Debug, Default)]
pub struct LightSampler {
    cdf: DiscreteCdf,
}

impl LightSampler {
    /// Builds the distribution; emitters with zero power are never chosen.
    pub fn new(powers: &[f32], choice: LightChoice) -> Self {
        let weights = powers.iter().map(|&p| match choice {
            LightChoice::Power => p,
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
        }
    }

    pub fn is_empty(&self) -> bool {
        self.cdf.is_empty()
    }

    /// `(emitter index, probability)`; `u` is rescaled for reuse.
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        self.cdf.sample(u)
    }

    /// Probability of choosing emitter `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        if self.cdf.is_empty() {
            0.0
        } else {
            self.cdf.pmf(i)
        }
    }
}
