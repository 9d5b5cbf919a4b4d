//! The dielectric base of glTF's metallic-roughness model: a specular coat (GGX, or a smooth
//! delta coat when alpha is tiny) over a Lambertian base.
//!
//! `f = s(wi) f_coat + (1 - s(wi)) base/π`, with the coat's share `s(wi) = specular ·
//! Schlick(F0, cos θi)`, `F0 = ((η-1)/(η+1))² · max(specular colour)` (KHR_materials_specular).
//! Sampling picks the coat with probability `s(wi)`; `pdf` is the matching mixture density.

use super::microfacet::{ggx_d, ggx_g2, reflection_pdf, sample_reflection};
use super::{Bsdf, BsdfQueryRecord, DELTA_ALPHA, Measure, fresnel};
use crate::sampling::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Copy, Debug)]
pub struct Plastic {
    pub base: Vec3,
    pub alpha: f32,
    pub f0: f32,
    pub specular: f32,
    /// Coat tint (specular colour normalised to a maximum of 1).
    pub coat_tint: Vec3,
}

impl Plastic {
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
            f0,
            specular: specular.clamp(0.0, 1.0),
            coat_tint: tint,
        }
    }

    #[inline]
    pub(crate) fn coat_share(&self, cos_i: f32) -> f32 {
        self.specular * fresnel::schlick1(self.f0, cos_i)
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
        let s = self.coat_share(wi.z);
        let base = (1.0 - s) * self.base * FRAC_1_PI;
        if self.smooth() {
            return (base, Vec3::ZERO);
        }
        let h = (wi + wo).normalize();
        let coat = s * self.coat_tint * ggx_d(h, self.alpha) * ggx_g2(wi, wo, self.alpha)
            / (4.0 * wi.z * wo.z);
        (base, coat)
    }
}

impl Bsdf for Plastic {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, u1: f32) -> Vec3 {
        let wi = rec.wi;
        if wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let s = self.coat_share(wi.z);
        rec.eta = 1.0;
        if self.smooth() && u1 < s {
            rec.wo = Vec3::new(-wi.x, -wi.y, wi.z);
            rec.measure = Measure::Discrete;
            rec.pdf = 0.0;
            return self.coat_tint;
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
