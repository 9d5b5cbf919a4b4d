//! Principled BSDF layering as Cycles does it (`svm/closure.h`, `principled_bsdf_emission`):
//! a top lobe (coat, sheen) is added to the lobes below, which are scaled by an attenuation
//! that depends on `wi` only:
//!
//! `f(wi, wo) = f_top(wi, wo) + A(wi) ⊙ f_base(wi, wo)`.
//!
//! Cycles computes `A` once per shading point from the top closure's albedo estimate
//! (`closure_layering_weight`: `A = 1 - max(albedo)`), and for the coat also from its tint.
//! [`Layered`] is that sum as one [`Bsdf`]: sampling picks the top with probability
//! `p = Σ albedo_top / (Σ albedo_top + Σ A)` (a choice for variance only; `pdf` is the
//! matching mixture) and rescales `u1` for the chosen lobe's own choices.
//!
//! How a caller composes the Principled BSDF: build the base (metal, glass or specular over
//! diffuse), then `Layered::new(Coat::new(..), base)` and, for sheen above the coat, nest:
//! `Layered<Sheen, Layered<Coat, B>>` (Cycles' order: sheen on top, then coat). The top layer
//! only acts for `wi.z > 0` (the viewer's side); below it the base is seen alone (`A = 1`).
//! The layers' own `albedo`/`attenuation` are public for callers that prefer to pick one lobe
//! per hit instead (pick the top with probability `p`, else the base weighted by `A / (1-p)`).

use super::microfacet::Roughness;
use super::rough_dielectric::RoughDielectric;
use super::sheen::Sheen;
use super::tables::{dielectric_reflection_albedo, reflection_fresnel_s};
use super::{
    Bsdf, BsdfQueryRecord, DELTA_ALPHA, Dielectric, Diffuse, Measure, Mirror, Plastic,
    RoughConductor, Translucent, fresnel,
};
use crate::sampling::pick;
use glam::{Vec2, Vec3};

/// A lobe that sits on top of others.
pub trait Layer: Bsdf {
    /// `∫ f_top cos dωo` as the layering uses it (Cycles' albedo estimate).
    fn albedo(&self, wi: Vec3) -> Vec3;
    /// The factor `A(wi)` applied to everything below.
    fn attenuation(&self, wi: Vec3) -> Vec3;
    /// Precomputes what depends on the incident direction `wi` alone (nothing by default).
    fn prepare(&mut self, _wi: Vec3) {}
    /// `(albedo(wi), attenuation(wi))` together (a layer may share the work).
    fn albedo_attenuation(&self, wi: Vec3) -> (Vec3, Vec3) {
        (self.albedo(wi), self.attenuation(wi))
    }
}

/// The Principled BSDF's coat: a GGX reflection with the dielectric Fresnel of the coat IOR
/// (Cycles' `MicrofacetFresnel::DIELECTRIC`), weighted by Coat Weight and always energy
/// compensated (Cycles' `bsdf_microfacet_setup_fresnel_dielectric` does so whatever the
/// distribution), over a base attenuated by `(1 - weight · F̂(μ) · darkening(μ)) ·
/// mix(1, tint^(1/cos θt), weight)`, where `F̂` is Cycles' Fresnel estimate of the coat lobe
/// ([`dielectric_reflection_albedo`]), `darkening` its energy-compensation term (see
/// `impl Layer for RoughDielectric`) and `cos θt` the cosine of `wi` refracted into the coat
/// (Beer's law through a coat of unit thickness).
///
/// Below [`DELTA_ALPHA`] the coat is a delta reflection of weight `weight · F(μ)`.
#[derive(Clone, Copy, Debug)]
pub struct Coat {
    /// Coat Weight (≥ 0).
    pub weight: f32,
    /// Coat IOR (≥ 1).
    pub ior: f32,
    /// Coat Roughness² (isotropic).
    pub alpha: f32,
    /// Coat Tint.
    pub tint: Vec3,
    lobe: RoughDielectric,
}

impl Coat {
    /// Blender inputs: Coat Weight, Coat Roughness (alpha = roughness²), Coat IOR, Coat Tint.
    pub fn new(weight: f32, roughness: f32, ior: f32, tint: Vec3) -> Self {
        let weight = weight.max(0.0);
        let r = roughness.clamp(0.0, 1.0);
        let ior = if ior.is_finite() { ior.max(1.0) } else { 1.5 };
        let alpha = r * r;
        Coat {
            weight,
            ior,
            alpha,
            tint: tint.max(Vec3::ZERO),
            lobe: RoughDielectric::reflection(Vec3::splat(weight), ior, alpha, alpha)
                .multiscatter(),
        }
    }

    /// The same coat with its alpha raised to at least `blur` (Filter Glossy; `blur <= 0`
    /// changes nothing): a smooth coat becomes a rough one. Its albedo over the base and its
    /// energy compensation stay those of the roughness it was set up with, as in Cycles.
    #[inline]
    pub fn blurred(self, blur: f32) -> Self {
        if blur <= 0.0 {
            return self;
        }
        Coat {
            alpha: self.alpha.max(blur),
            lobe: self.lobe.blurred(blur),
            ..self
        }
    }

    #[inline]
    fn smooth(&self) -> bool {
        self.alpha < DELTA_ALPHA
    }

    /// The coat's GGX lobe (ignored when the coat is smooth).
    pub fn lobe(&self) -> &RoughDielectric {
        &self.lobe
    }

    pub fn roughness(&self) -> Roughness {
        self.lobe.roughness
    }
}

impl Layer for Coat {
    fn albedo(&self, wi: Vec3) -> Vec3 {
        Layer::albedo(&self.lobe, wi)
    }

    fn attenuation(&self, wi: Vec3) -> Vec3 {
        if wi.z <= 0.0 {
            return Vec3::ONE;
        }
        let a = self.lobe.attenuation(wi);
        if self.tint == Vec3::ONE {
            return a;
        }
        let mu = wi.z.min(1.0);
        let inv = 1.0 / self.ior;
        let cos_t = (1.0 - inv * inv * (1.0 - mu * mu)).max(0.0).sqrt();
        let through = self.tint.powf(1.0 / cos_t);
        a * (Vec3::ONE + (through - Vec3::ONE) * self.weight)
    }
}

/// A reflection-only dielectric lobe as a layer (Principled's specular layer over diffuse,
/// and the coat): Cycles' albedo estimate `reflection_tint ⊙ F̂(μ) ⊙ darkening(μ)`, with
/// `F̂ = mix(F0 · f0_tint, 1, s(√α, μ, z))` from the `ggx_gen_schlick_ior_s` table
/// ([`super::tables::reflection_fresnel_s`]; for `f0_tint = 1` and `ior ≤ 1` Cycles uses the
/// smooth Fresnel reflectance, as here) and, with energy compensation, Cycles' darkening
/// `factor · E(μ)` folded into the closure weight. The layers below are scaled by
/// `1 - max(albedo)`.
impl Layer for RoughDielectric {
    fn prepare(&mut self, wi: Vec3) {
        RoughDielectric::prepare(self, wi);
    }

    fn albedo(&self, wi: Vec3) -> Vec3 {
        if wi.z <= 0.0 || self.mode != super::DielectricMode::Reflection {
            return Vec3::ZERO;
        }
        let mu = wi.z.min(1.0);
        // Cycles finds the albedo when it sets the closure up, before any Filter Glossy.
        let r = &self.setup_roughness;
        let alpha = (r.alpha_x * r.alpha_y).sqrt();
        let f = if let Some(film) = &self.thin_film {
            // No table holds a film's albedo: Cycles takes the reflectance along the normal.
            self.film_reflectance(film, mu, self.ior)
        } else if self.f0_tint == Vec3::ONE {
            Vec3::splat(dielectric_reflection_albedo(alpha, mu, self.ior))
        } else {
            let f0 = (fresnel::f0_from_ior(self.ior) * self.f0_tint).min(Vec3::ONE);
            let s = reflection_fresnel_s(alpha, mu, self.ior);
            f0 + (Vec3::ONE - f0) * s
        };
        let darkening = match self.multiscatter_fss {
            Some(_) => self.energy_factor(mu, self.ior) * self.reflection_e(mu),
            None => Vec3::ONE,
        };
        self.reflection_tint * f * darkening
    }

    fn attenuation(&self, wi: Vec3) -> Vec3 {
        self.albedo_attenuation(wi).1
    }

    fn albedo_attenuation(&self, wi: Vec3) -> (Vec3, Vec3) {
        if wi.z <= 0.0 {
            return (Layer::albedo(self, wi), Vec3::ONE);
        }
        let a = Layer::albedo(self, wi);
        (a, Vec3::splat((1.0 - a.max_element()).clamp(0.0, 1.0)))
    }
}

impl Bsdf for Coat {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, u1: f32) -> Vec3 {
        if rec.wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        if self.smooth() {
            rec.wo = Vec3::new(-rec.wi.x, -rec.wi.y, rec.wi.z);
            rec.eta = 1.0;
            rec.measure = Measure::Discrete;
            rec.pdf = 0.0;
            return Vec3::splat(self.weight * fresnel::dielectric(rec.wi.z, self.ior).0);
        }
        self.lobe.sample(rec, u, u1)
    }

    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        if rec.wi.z <= 0.0 || self.smooth() {
            return Vec3::ZERO;
        }
        self.lobe.eval(rec)
    }

    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        if rec.wi.z <= 0.0 || self.smooth() {
            return 0.0;
        }
        self.lobe.pdf(rec)
    }

    fn eval_and_pdf(&self, rec: &BsdfQueryRecord) -> (Vec3, f32) {
        if rec.wi.z <= 0.0 || self.smooth() {
            return (Vec3::ZERO, 0.0);
        }
        self.lobe.eval_and_pdf(rec)
    }

    fn is_delta(&self) -> bool {
        self.smooth()
    }
}

impl Layer for Sheen {
    fn albedo(&self, wi: Vec3) -> Vec3 {
        Sheen::albedo(self, wi)
    }

    /// Cycles: `1 - max(weight · tint) · albedo(μ)`.
    fn attenuation(&self, wi: Vec3) -> Vec3 {
        if wi.z <= 0.0 {
            return Vec3::ONE;
        }
        let e = Sheen::albedo(self, wi).max_element();
        Vec3::splat((1.0 - e).clamp(0.0, 1.0))
    }
}

/// Whether a lobe's `sample` left a direction with a density in `rec`, whatever its weight.
#[inline]
pub fn sampled_direction(rec: &BsdfQueryRecord) -> bool {
    rec.measure == Measure::SolidAngle && rec.pdf > 0.0 && rec.pdf.is_finite()
}

/// `f_top + A(wi) ⊙ f_base` (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct Layered<T, B> {
    pub top: T,
    pub base: B,
    /// `(wi, split(wi))` computed once for the shading point's incident direction: the top's
    /// albedo estimate (table lookups) is the costly part of every query.
    prepared: Option<(Vec3, f32, Vec3)>,
}

impl<T: Layer, B: Bsdf> Layered<T, B> {
    pub fn new(top: T, base: B) -> Self {
        Layered {
            top,
            base,
            prepared: None,
        }
    }

    /// Computes the layering for the incident direction `wi` that the queries will use (the
    /// same values as without it, found once).
    #[inline]
    pub fn prepare(&mut self, wi: Vec3) {
        self.top.prepare(wi);
        self.prepared = None;
        let (p, att) = self.split(wi);
        self.prepared = Some((wi, p, att));
    }

    /// The probability with which `sample` picks the top lobe for `wi`.
    #[inline]
    pub fn top_probability(&self, wi: Vec3) -> f32 {
        self.split(wi).0
    }

    /// `sample`'s lobe choice for `wi` with the random number `u1`: `(top, u1')`, `u1'` the
    /// number rescaled for the chosen lobe's own choices.
    #[inline]
    pub fn pick(&self, wi: Vec3, u1: f32) -> (bool, f32) {
        pick(self.top_probability(wi), u1)
    }

    /// `A(wi)`, the factor on everything below the top.
    #[inline]
    pub fn attenuation_at(&self, wi: Vec3) -> Vec3 {
        match self.prepared {
            Some((w, _, att)) if w == wi => att,
            _ => self.top.attenuation(wi),
        }
    }

    /// `(probability of sampling the top, A(wi))`.
    #[inline]
    fn split(&self, wi: Vec3) -> (f32, Vec3) {
        if let Some((w, p, att)) = self.prepared
            && w == wi
        {
            return (p, att);
        }
        let (albedo, att) = self.top.albedo_attenuation(wi);
        let t = albedo.element_sum().max(0.0);
        let b = att.element_sum().max(0.0);
        let p = if t + b > 0.0 { t / (t + b) } else { 0.0 };
        (p, att)
    }
}

impl<T: Layer, B: Bsdf> Layer for Layered<T, B>
where
    B: Layer,
{
    fn albedo(&self, wi: Vec3) -> Vec3 {
        self.top.albedo(wi) + self.top.attenuation(wi) * self.base.albedo(wi)
    }

    fn attenuation(&self, wi: Vec3) -> Vec3 {
        self.top.attenuation(wi) * self.base.attenuation(wi)
    }
}

impl<T: Layer, B: Bsdf> Bsdf for Layered<T, B> {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, u1: f32) -> Vec3 {
        let (p, att) = self.split(rec.wi);
        let (top, u1) = pick(p, u1);
        let w = if top {
            self.top.sample(rec, u, u1)
        } else {
            self.base.sample(rec, u, u1)
        };
        // A lobe of zero weight (a black base) may still sample a direction the mixture
        // reflects: only a failed sample ends here.
        if w == Vec3::ZERO && !sampled_direction(rec) {
            return Vec3::ZERO;
        }
        match rec.measure {
            Measure::Discrete => {
                if top {
                    w / p
                } else {
                    att * w / (1.0 - p)
                }
            }
            Measure::SolidAngle => {
                let pdf = self.pdf(rec);
                if !(pdf > 0.0 && pdf.is_finite()) {
                    return Vec3::ZERO;
                }
                rec.pdf = pdf;
                self.eval(rec) * rec.wo.z.abs() / pdf
            }
        }
    }

    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        let att = self.attenuation_at(rec.wi);
        self.top.eval(rec) + att * self.base.eval(rec)
    }

    fn eval_split(&self, rec: &BsdfQueryRecord) -> [Vec3; 2] {
        let att = self.attenuation_at(rec.wi);
        let [td, tg] = self.top.eval_split(rec);
        let [bd, bg] = self.base.eval_split(rec);
        [td + att * bd, tg + att * bg]
    }

    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        let (p, _) = self.split(rec.wi);
        let mut pdf = 0.0;
        if p > 0.0 {
            pdf += p * self.top.pdf(rec);
        }
        if p < 1.0 {
            pdf += (1.0 - p) * self.base.pdf(rec);
        }
        pdf
    }

    fn eval_and_pdf(&self, rec: &BsdfQueryRecord) -> (Vec3, f32) {
        let (p, att) = self.split(rec.wi);
        let (ft, pt) = self.top.eval_and_pdf(rec);
        let (fb, pb) = self.base.eval_and_pdf(rec);
        let mut pdf = 0.0;
        if p > 0.0 {
            pdf += p * pt;
        }
        if p < 1.0 {
            pdf += (1.0 - p) * pb;
        }
        (ft + att * fb, pdf)
    }

    fn is_delta(&self) -> bool {
        self.top.is_delta() && self.base.is_delta()
    }
}

/// The lobes that can be layered on top (for [`super::BsdfInstance::Layered`]).
#[derive(Clone, Copy, Debug)]
pub enum TopLobe {
    Coat(Coat),
    Sheen(Sheen),
    /// A reflection-only [`RoughDielectric`] (Principled's specular layer).
    Specular(RoughDielectric),
}

/// The lobes that can lie below a [`TopLobe`].
#[derive(Clone, Copy, Debug)]
pub enum BaseLobe {
    Diffuse(Diffuse),
    Mirror(Mirror),
    Dielectric(Dielectric),
    RoughConductor(RoughConductor),
    Plastic(Plastic),
    RoughDielectric(RoughDielectric),
    Translucent(Translucent),
    /// A sheen below a coat is not Cycles' order; a coat below a sheen is
    /// (`Layered<Sheen, Layered<Coat, _>>`), given here over a diffuse base.
    CoatedDiffuse(Layered<Coat, Diffuse>),
    CoatedConductor(Layered<Coat, RoughConductor>),
    /// Principled's dielectric base: the specular layer over diffuse.
    SpecularDiffuse(Layered<RoughDielectric, Diffuse>),
}

macro_rules! dispatch_top {
    ($self:ident, $b:ident => $e:expr) => {
        match $self {
            TopLobe::Coat($b) => $e,
            TopLobe::Sheen($b) => $e,
            TopLobe::Specular($b) => $e,
        }
    };
}

macro_rules! dispatch_base {
    ($self:ident, $b:ident => $e:expr) => {
        match $self {
            BaseLobe::Diffuse($b) => $e,
            BaseLobe::Mirror($b) => $e,
            BaseLobe::Dielectric($b) => $e,
            BaseLobe::RoughConductor($b) => $e,
            BaseLobe::Plastic($b) => $e,
            BaseLobe::RoughDielectric($b) => $e,
            BaseLobe::Translucent($b) => $e,
            BaseLobe::CoatedDiffuse($b) => $e,
            BaseLobe::CoatedConductor($b) => $e,
            BaseLobe::SpecularDiffuse($b) => $e,
        }
    };
}

impl Bsdf for TopLobe {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, u1: f32) -> Vec3 {
        dispatch_top!(self, b => b.sample(rec, u, u1))
    }
    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        dispatch_top!(self, b => b.eval(rec))
    }
    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        dispatch_top!(self, b => b.pdf(rec))
    }
    fn is_delta(&self) -> bool {
        dispatch_top!(self, b => b.is_delta())
    }
    fn eval_split(&self, rec: &BsdfQueryRecord) -> [Vec3; 2] {
        dispatch_top!(self, b => b.eval_split(rec))
    }
    fn eval_and_pdf(&self, rec: &BsdfQueryRecord) -> (Vec3, f32) {
        dispatch_top!(self, b => b.eval_and_pdf(rec))
    }
}

impl Layer for TopLobe {
    fn albedo(&self, wi: Vec3) -> Vec3 {
        dispatch_top!(self, b => Layer::albedo(b, wi))
    }
    fn attenuation(&self, wi: Vec3) -> Vec3 {
        dispatch_top!(self, b => b.attenuation(wi))
    }
    fn prepare(&mut self, wi: Vec3) {
        dispatch_top!(self, b => Layer::prepare(b, wi))
    }
    fn albedo_attenuation(&self, wi: Vec3) -> (Vec3, Vec3) {
        dispatch_top!(self, b => b.albedo_attenuation(wi))
    }
}

impl Bsdf for BaseLobe {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, u1: f32) -> Vec3 {
        dispatch_base!(self, b => b.sample(rec, u, u1))
    }
    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        dispatch_base!(self, b => b.eval(rec))
    }
    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        dispatch_base!(self, b => b.pdf(rec))
    }
    fn is_delta(&self) -> bool {
        dispatch_base!(self, b => b.is_delta())
    }
    fn eval_split(&self, rec: &BsdfQueryRecord) -> [Vec3; 2] {
        dispatch_base!(self, b => b.eval_split(rec))
    }
    fn eval_and_pdf(&self, rec: &BsdfQueryRecord) -> (Vec3, f32) {
        dispatch_base!(self, b => b.eval_and_pdf(rec))
    }
}

impl BaseLobe {
    /// True for bases that transmit (the integrator must keep the geometric side).
    pub fn is_transmissive(&self) -> bool {
        match self {
            BaseLobe::Dielectric(_) | BaseLobe::Translucent(_) => true,
            BaseLobe::RoughDielectric(d) => d.mode != super::DielectricMode::Reflection,
            _ => false,
        }
    }
}
