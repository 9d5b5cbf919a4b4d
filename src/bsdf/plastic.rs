//! The dielectric base of a Principled-style material: a specular coat (GGX, or a smooth
//! delta coat when alpha is tiny) over a Lambertian base.
//!
//! `f = F(wi) f_coat + (1 - max F(wi)) base/π`, with the coat's reflectance `F(wi)` per channel
//! from [`CoatFresnel`]: glTF's `specular · Schlick(F0, cos θi) · tint`, or Cycles' generalized
//! Schlick over the real dielectric Fresnel (its smooth Principled BSDF). Sampling picks the
//! coat with probability `max F(wi)`; `pdf` is the matching mixture density.

use super::microfacet::{ggx_d, ggx_g2, reflection_pdf, sample_reflection};
use super::thin_film::ThinFilm;
use super::{Bsdf, BsdfQueryRecord, DELTA_ALPHA, Measure, fresnel};
use crate::sampling::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Copy, Debug)]
pub struct Plastic {
    pub base: Vec3,
    pub alpha: f32,
    pub fresnel: CoatFresnel,
}

/// The coat's reflectance `F(cos θi)`, per channel, `cos θi` against the shading normal.
#[derive(Clone, Copy, Debug)]
pub enum CoatFresnel {
    /// glTF's metallic-roughness with KHR_materials_specular: `specular · Schlick(F0, cos)`
    /// tinted by the specular colour normalised to a maximum of 1, `F0 = F0(η) · max(colour)`.
    Schlick { f0: f32, specular: f32, tint: Vec3 },
    /// Cycles' Principled specular layer: `mix(F0 · tint, 1, s)`, `s = (F(cos, η) - F0) /
    /// (1 - F0)` with `F` the exact dielectric reflectance and `F0 = F0(η)`; a black tint keeps
    /// the white grazing reflection.
    Cycles { eta: f32, f0: f32, f0_tint: Vec3 },
    /// [`CoatFresnel::Cycles`] under a thin film: the film's reflectance with `F0` scaled
    /// by the tint ([`ThinFilm::principled`]).
    Film {
        eta: f32,
        f0_tint: Vec3,
        film: ThinFilm,
    },
}

impl Plastic {
    /// glTF's model ([`CoatFresnel::Schlick`]).
    pub fn new(base: Vec3, alpha: f32, ior: f32, specular: f32, specular_color: Vec3) -> Self {
        let m = specular_color.max_element();
        let (f0, tint) = if m > 0.0 {
            ((fresnel::f0_from_ior(ior) * m).min(1.0), specular_color / m)
        } else {
            (0.0, Vec3::ONE)
        };
        Plastic {
            base,
            alpha,
            fresnel: CoatFresnel::Schlick {
                f0,
                specular: specular.clamp(0.0, 1.0),
                tint,
            },
        }
    }

    /// Cycles' Principled BSDF dielectric base ([`CoatFresnel::Cycles`]); `eta` is the
    /// level-adjusted IOR ([`super::rough_dielectric::principled_specular_ior`]).
    pub fn cycles(base: Vec3, alpha: f32, eta: f32, specular_tint: Vec3) -> Self {
        let f0 = fresnel::f0_from_ior(eta);
        Plastic {
            base,
            alpha,
            fresnel: CoatFresnel::Cycles {
                eta,
                f0,
                f0_tint: (specular_tint.max(Vec3::ZERO) * f0).min(Vec3::ONE),
            },
        }
    }

    /// The same layer under a thin film (`None`: unchanged); a Cycles layer only.
    pub fn with_thin_film(self, film: Option<ThinFilm>) -> Self {
        match (self.fresnel, film) {
            (CoatFresnel::Cycles { eta, f0_tint, .. }, Some(film)) => Plastic {
                fresnel: CoatFresnel::Film { eta, f0_tint, film },
                ..self
            },
            _ => self,
        }
    }

    /// The coat's reflectance `F(cos θi)` per channel.
    #[inline]
    pub fn coat_fresnel(&self, cos_i: f32) -> Vec3 {
        match self.fresnel {
            CoatFresnel::Schlick { f0, specular, tint } => {
                specular * fresnel::schlick1(f0, cos_i) * tint
            }
            CoatFresnel::Film { eta, f0_tint, film } => {
                film.principled(cos_i.clamp(0.0, 1.0), eta, film.ior, f0_tint)
            }
            CoatFresnel::Cycles { eta, f0, f0_tint } => {
                let s = if f0 < 1.0 {
                    ((fresnel::dielectric(cos_i.clamp(0.0, 1.0), eta).0 - f0) / (1.0 - f0))
                        .clamp(0.0, 1.0)
                } else {
                    1.0
                };
                f0_tint + (Vec3::ONE - f0_tint) * s
            }
        }
    }

    /// The probability of sampling the coat, `max F(cos θi)`; the base keeps `1 -` this.
    #[inline]
    pub fn coat_share(&self, cos_i: f32) -> f32 {
        self.coat_fresnel(cos_i).max_element().min(1.0)
    }

    #[inline]
    fn smooth(&self) -> bool {
        self.alpha < DELTA_ALPHA
    }

    /// The non-delta BSDF split into its Lambertian base and its glossy coat, `(base, coat)`,
    /// per steradian (their sum is [`Bsdf::eval`]): Cycles shades the two as separate closures,
    /// and a bumped normal darkens only the diffuse one.
    #[inline]
    pub fn eval_parts(&self, rec: &BsdfQueryRecord) -> (Vec3, Vec3) {
        let (wi, wo) = (rec.wi, rec.wo);
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        let f = self.coat_fresnel(wi.z);
        let base = (1.0 - f.max_element().min(1.0)) * self.base * FRAC_1_PI;
        if self.smooth() {
            return (base, Vec3::ZERO);
        }
        let h = (wi + wo).normalize();
        let coat = f * ggx_d(h, self.alpha) * ggx_g2(wi, wo, self.alpha) / (4.0 * wi.z * wo.z);
        (base, coat)
    }
}

impl Bsdf for Plastic {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, u1: f32) -> Vec3 {
        let wi = rec.wi;
        if wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let f = self.coat_fresnel(wi.z);
        let s = f.max_element().min(1.0);
        rec.eta = 1.0;
        if self.smooth() && u1 < s {
            rec.wo = Vec3::new(-wi.x, -wi.y, wi.z);
            rec.measure = Measure::Discrete;
            rec.pdf = 0.0;
            return f / s;
        }
        rec.measure = Measure::SolidAngle;
        if self.smooth() {
            rec.wo = square_to_cosine_hemisphere(u);
            rec.pdf = (1.0 - s) * square_to_cosine_hemisphere_pdf(rec.wo);
            return if rec.pdf > 0.0 { self.base } else { Vec3::ZERO };
        }
        if u1 < s {
            match sample_reflection(wi, self.alpha, u) {
                Some((wo, _)) => rec.wo = wo,
                None => return Vec3::ZERO,
            }
        } else {
            rec.wo = square_to_cosine_hemisphere(u);
        }
        rec.pdf = self.pdf(rec);
        if rec.pdf <= 0.0 || rec.wo.z <= 0.0 {
            return Vec3::ZERO;
        }
        self.eval(rec) * rec.wo.z / rec.pdf
    }

    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        let (base, coat) = self.eval_parts(rec);
        base + coat
    }

    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        let (wi, wo) = (rec.wi, rec.wo);
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let s = self.coat_share(wi.z);
        let mut p = (1.0 - s) * square_to_cosine_hemisphere_pdf(wo);
        if !self.smooth() {
            p += s * reflection_pdf(wi, wo, self.alpha);
        }
        p
    }

    fn is_delta(&self) -> bool {
        false
    }

    /// The Lambertian base is diffuse, the coat glossy.
    fn eval_split(&self, rec: &BsdfQueryRecord) -> [Vec3; 2] {
        let f = self.eval(rec);
        if f == Vec3::ZERO {
            return [Vec3::ZERO; 2];
        }
        let diffuse = (1.0 - self.coat_share(rec.wi.z)) * self.base * FRAC_1_PI;
        [diffuse, (f - diffuse).max(Vec3::ZERO)]
    }
}
