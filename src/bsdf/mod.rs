//! Bidirectional scattering distribution functions.
//!
//! All BSDF queries happen in the **local shading frame** (normal = +Z). Both directions
//! point **away** from the surface: `wi` towards where the light goes (the camera side, the
//! previous path vertex), `wo` towards where it comes from (the sampled or queried direction).
//! `eval` returns `f(wi, wo)` **without** the cosine; `pdf` is per unit **solid angle** of `wo`;
//! `sample` returns the weight `f · |cos θo| / pdf` (for delta lobes, the lobe's weight).

pub mod closure;
pub mod dielectric;
pub mod diffuse;
pub mod fresnel;
pub mod hair;
pub mod layered;
pub mod microfacet;
pub mod mirror;
pub mod plastic;
pub mod rough_dielectric;
pub mod sheen;
pub mod tables;
pub mod thin_film;
pub mod toon;
pub mod translucent;
pub mod transparent;

use glam::{Vec2, Vec3};

pub use closure::from_closure;
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use hair::{ChiangHair, HairColor, PrincipledHair};
pub use layered::{BaseLobe, Coat, Layer, Layered, TopLobe};
pub use microfacet::{ConductorFresnel, RoughConductor, Roughness};
pub use mirror::Mirror;
pub use plastic::Plastic;
pub use rough_dielectric::{DielectricMode, RoughDielectric, principled_specular_ior};
pub use sheen::Sheen;
pub use toon::Toon;
pub use translucent::Translucent;
pub use transparent::Transparent;

/// Which measure a sampled direction's density is expressed in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Measure {
    /// A density per steradian (non-delta lobes).
    SolidAngle,
    /// A discrete choice: the direction was picked from a delta lobe.
    Discrete,
}

/// A BSDF query (nori's `BSDFQueryRecord`).
#[derive(Clone, Copy, Debug)]
pub struct BsdfQueryRecord {
    /// Local direction towards the previous vertex (away from the surface).
    pub wi: Vec3,
    /// Local sampled/queried direction (away from the surface).
    pub wo: Vec3,
    /// Relative index of refraction `η_o / η_i` of the sampled event (1 for reflection).
    pub eta: f32,
    /// Measure of the sampled direction.
    pub measure: Measure,
    /// Density of `wo` reported by `sample` (per steradian; 0 for delta lobes).
    pub pdf: f32,
}

impl BsdfQueryRecord {
    /// A record for sampling: only `wi` is known.
    pub fn new(wi: Vec3) -> Self {
        BsdfQueryRecord {
            wi,
            wo: Vec3::ZERO,
            eta: 1.0,
            measure: Measure::SolidAngle,
            pdf: 0.0,
        }
    }

    /// A record for `eval`/`pdf` of a known pair.
    pub fn pair(wi: Vec3, wo: Vec3) -> Self {
        BsdfQueryRecord {
            wo,
            ..BsdfQueryRecord::new(wi)
        }
    }
}

/// A BSDF: sampling separated from evaluation, as in nori, pbrt and Mitsuba.
pub trait Bsdf {
    /// Samples `wo` given `rec.wi`; fills `wo`, `eta`, `measure` and `pdf`, and returns the
    /// weight `f · |cos θo| / pdf` (zero when sampling failed). `u` drives the direction,
    /// `u1` a discrete choice between lobes.
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, u1: f32) -> Vec3;
    /// `f(wi, wo)` without the cosine factor; zero for delta lobes.
    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3;
    /// Solid-angle density with which `sample` produces `rec.wo`; zero for delta lobes.
    fn pdf(&self, rec: &BsdfQueryRecord) -> f32;
    /// True when every lobe is a Dirac delta (emitter sampling cannot contribute).
    fn is_delta(&self) -> bool;
    /// The parts of `eval` that Cycles' light passes call diffuse and glossy, as
    /// `[diffuse, glossy]` in the units of `eval`; what remains of `eval` is transmission
    /// (Cycles' closure classes: translucent and sheen are diffuse, a glass lobe is glossy on
    /// the side of `wi` and transmission across). By default the whole value is glossy.
    fn eval_split(&self, rec: &BsdfQueryRecord) -> [Vec3; 2] {
        [Vec3::ZERO, self.eval(rec)]
    }
    /// `(eval(rec), pdf(rec))` at once (the same values; a lobe may share their work).
    fn eval_and_pdf(&self, rec: &BsdfQueryRecord) -> (Vec3, f32) {
        (self.eval(rec), self.pdf(rec))
    }
}

/// The BSDF chosen at one surface hit: a closed set of variants, built on the stack.
///
/// Lobes that live in a tangent frame (anisotropic [`RoughConductor`], [`RoughDielectric`]
/// with `alpha_x != alpha_y`) take local +X as the tangent: the caller builds the shading frame
/// from the (rotated) tangent for them.
// Built on the stack once per hit and never stored in bulk: boxing the large layered variant
// would put an allocation in the hot loop.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub enum BsdfInstance {
    Diffuse(Diffuse),
    Mirror(Mirror),
    Dielectric(Dielectric),
    RoughConductor(RoughConductor),
    Plastic(Plastic),
    RoughDielectric(RoughDielectric),
    Translucent(Translucent),
    Toon(Toon),
    Transparent(Transparent),
    Sheen(Sheen),
    /// Principled Hair (Chiang) on a strand, in a frame whose +X is the strand.
    ChiangHair(hair::ChiangHair),
    /// A coat or sheen over a base lobe ([`layered`]).
    Layered(Layered<TopLobe, BaseLobe>),
}

macro_rules! dispatch {
    ($self:ident, $b:ident => $e:expr) => {
        match $self {
            BsdfInstance::Diffuse($b) => $e,
            BsdfInstance::Mirror($b) => $e,
            BsdfInstance::Dielectric($b) => $e,
            BsdfInstance::RoughConductor($b) => $e,
            BsdfInstance::Plastic($b) => $e,
            BsdfInstance::RoughDielectric($b) => $e,
            BsdfInstance::Translucent($b) => $e,
            BsdfInstance::Toon($b) => $e,
            BsdfInstance::Transparent($b) => $e,
            BsdfInstance::Sheen($b) => $e,
            BsdfInstance::ChiangHair($b) => $e,
            BsdfInstance::Layered($b) => $e,
        }
    };
}

impl Bsdf for BsdfInstance {
    #[inline]
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, u1: f32) -> Vec3 {
        dispatch!(self, b => b.sample(rec, u, u1))
    }
    #[inline]
    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        dispatch!(self, b => b.eval(rec))
    }
    #[inline]
    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        dispatch!(self, b => b.pdf(rec))
    }
    #[inline]
    fn is_delta(&self) -> bool {
        dispatch!(self, b => b.is_delta())
    }
    #[inline]
    fn eval_split(&self, rec: &BsdfQueryRecord) -> [Vec3; 2] {
        dispatch!(self, b => b.eval_split(rec))
    }
    #[inline]
    fn eval_and_pdf(&self, rec: &BsdfQueryRecord) -> (Vec3, f32) {
        dispatch!(self, b => b.eval_and_pdf(rec))
    }
}

impl BsdfInstance {
    /// True for BSDFs that transmit (the shading frame must not be flipped towards `wi`).
    pub fn is_transmissive(&self) -> bool {
        match self {
            BsdfInstance::Dielectric(_)
            | BsdfInstance::Translucent(_)
            | BsdfInstance::Transparent(_)
            | BsdfInstance::ChiangHair(_) => true,
            BsdfInstance::RoughDielectric(d) => d.mode != DielectricMode::Reflection,
            BsdfInstance::Layered(l) => l.base.is_transmissive(),
            _ => false,
        }
    }

    /// `alpha_x · alpha_y` of the lobe a transmitted ray leaves through (Cycles'
    /// `bsdf_get_specular_roughness_squared`): 0 for a smooth dielectric, the GGX alphas'
    /// product for a rough one (after Filter Glossy), 1 for every other lobe.
    pub fn transmission_alpha2(&self) -> f32 {
        let rough = |d: &RoughDielectric| d.roughness.alpha_x * d.roughness.alpha_y;
        match self {
            BsdfInstance::Dielectric(_) => 0.0,
            BsdfInstance::RoughDielectric(d) => rough(d),
            BsdfInstance::Layered(l) => match &l.base {
                BaseLobe::Dielectric(_) => 0.0,
                BaseLobe::RoughDielectric(d) => rough(d),
                _ => 1.0,
            },
            _ => 1.0,
        }
    }

    /// A glossy layer over a diffuse base evaluated as its two parts, `(diffuse, glossy)` per
    /// steradian (their sum is `eval`), for the corrections Cycles applies to its diffuse
    /// closures alone; `None` for BSDFs that are not such a pair.
    #[inline]
    pub fn diffuse_parts(&self, rec: &BsdfQueryRecord) -> Option<(Vec3, Vec3)> {
        match self {
            BsdfInstance::Plastic(p) => Some(p.eval_parts(rec)),
            BsdfInstance::Layered(l) if matches!(l.base, BaseLobe::Diffuse(_)) => {
                let att = l.attenuation_at(rec.wi);
                Some((att * l.base.eval(rec), l.top.eval(rec)))
            }
            _ => None,
        }
    }
}

/// Below this GGX alpha a lobe is treated as a perfect (delta) reflection.
pub const DELTA_ALPHA: f32 = 1e-3;

/// Material parameters at a surface point (after textures), from which the BSDF is chosen.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceParams {
    pub base_color: Vec3,
    pub metallic: f32,
    pub roughness: f32,
    pub transmission: f32,
    pub ior: f32,
    pub specular: f32,
    pub specular_color: Vec3,
}

/// Chooses one component of the glTF metallic-roughness model, with probability equal to its
/// mixture weight (transmission, then metal, then the dielectric base), so that the chosen
/// BSDF's weight estimates the whole mixture without bias. `u` is uniform in `[0,1)`.
///
/// - transmission → [`Dielectric`] (alpha below [`DELTA_ALPHA`]) or [`RoughDielectric`]
///   (GGX, Cycles' Principled transmission: `sqrt(base colour)` per refraction),
/// - metal → [`Mirror`] (alpha below [`DELTA_ALPHA`]) or [`RoughConductor`] (GGX),
/// - dielectric base → [`Plastic`] (GGX or smooth coat over Lambert) or [`Diffuse`] when
///   `specular · max(specular colour)` is 0 (Blender's Specular IOR Level 0: 4.x writes
///   `specularFactor: 0`, 3.x `specularColorFactor: [0, 0, 0]`).
pub fn choose(p: &SurfaceParams, u: f32) -> BsdfInstance {
    let alpha = (p.roughness * p.roughness).clamp(0.0, 1.0);
    let transmission = p.transmission.clamp(0.0, 1.0) * (1.0 - p.metallic.clamp(0.0, 1.0));
    let metallic = p.metallic.clamp(0.0, 1.0);
    if u < transmission {
        return if alpha < DELTA_ALPHA {
            BsdfInstance::Dielectric(Dielectric::new(p.ior, p.base_color))
        } else {
            BsdfInstance::RoughDielectric(RoughDielectric::principled_transmission(
                p.base_color,
                Vec3::ONE,
                p.ior,
                alpha,
            ))
        };
    }
    let u = if transmission > 0.0 {
        (u - transmission) / (1.0 - transmission)
    } else {
        u
    };
    if u < metallic {
        if alpha < DELTA_ALPHA {
            BsdfInstance::Mirror(Mirror::new(p.base_color))
        } else {
            BsdfInstance::RoughConductor(RoughConductor::new(p.base_color, alpha))
        }
    } else if p.specular * p.specular_color.max_element() <= 0.0 {
        BsdfInstance::Diffuse(Diffuse::new(p.base_color))
    } else {
        BsdfInstance::Plastic(Plastic::new(
            p.base_color,
            alpha,
            p.ior,
            p.specular,
            p.specular_color,
        ))
    }
}
