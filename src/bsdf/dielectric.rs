//! Ideal (smooth) dielectric interface: Fresnel-weighted choice between specular reflection and
//! refraction, for rays entering (`wi.z > 0`) and leaving (`wi.z < 0`), with total internal
//! reflection.
//!
//! Matching Cycles (measured, docs/blender-units.md): each refraction is tinted by
//! `sqrt(base colour)`, so a ray through a closed solid is tinted by the base colour once, and no
//! `1/η²` radiance scaling is applied (for closed meshes it cancels anyway; it would only show
//! with open sheets or a camera inside glass).

use super::thin_film::ThinFilm;
use super::{Bsdf, BsdfQueryRecord, Measure, fresnel};
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    /// `η_inside / η_outside`.
    pub ior: f32,
    /// Per-refraction transmission tint: `sqrt(base colour)`.
    pub tint: Vec3,
    /// A thin film on the surface and the Specular Tint that scales its `F0` (the Principled
    /// BSDF's): reflection then takes the film's coloured reflectance
    /// ([`ThinFilm::principled`]) and is chosen with probability `avg R / avg (R + T)`.
    pub film: Option<(ThinFilm, Vec3)>,
}

impl Dielectric {
    pub fn new(ior: f32, tint: Vec3) -> Self {
        let ior = if ior.is_finite() && ior > 0.0 {
            ior
        } else {
            1.5
        };
        Dielectric {
            ior,
            tint: tint.max(Vec3::ZERO).map(f32::sqrt),
            film: None,
        }
    }

    /// The same interface under a thin film whose `F0` Specular Tint `f0_tint` scales.
    pub fn with_thin_film(self, film: Option<ThinFilm>, f0_tint: Vec3) -> Self {
        Dielectric {
            film: film.map(|f| (f, f0_tint.max(Vec3::ZERO))),
            ..self
        }
    }

    /// Sampling under a film: `(cos θt, η)` from the plain Fresnel, the reflectance from
    /// the film's.
    fn sample_film(&self, rec: &mut BsdfQueryRecord, u1: f32, film: &ThinFilm, k: Vec3) -> Vec3 {
        let cos_i = rec.wi.z;
        let (r, cos_t, eta) = fresnel::dielectric(cos_i, self.ior);
        rec.measure = Measure::Discrete;
        rec.pdf = 0.0;
        let (refl, trans) = if r >= 1.0 {
            (Vec3::ONE, Vec3::ZERO)
        } else {
            let f = film.on_dielectric(cos_i.abs(), eta, cos_i < 0.0, k);
            (f, (Vec3::ONE - f) * self.tint)
        };
        let total = (refl + trans).element_sum();
        if total <= 0.0 {
            return Vec3::ZERO;
        }
        let p = refl.element_sum() / total;
        if u1 < p {
            rec.wo = Vec3::new(-rec.wi.x, -rec.wi.y, rec.wi.z);
            rec.eta = 1.0;
            refl / p
        } else {
            let sign = cos_i.signum();
            let wo = Vec3::new(-rec.wi.x / eta, -rec.wi.y / eta, -sign * cos_t);
            rec.wo = wo.normalize();
            rec.eta = eta;
            trans / (1.0 - p)
        }
    }
}

impl Bsdf for Dielectric {
    fn sample(&self, rec: &mut BsdfQueryRecord, _u: Vec2, u1: f32) -> Vec3 {
        let cos_i = rec.wi.z;
        if cos_i == 0.0 {
            return Vec3::ZERO;
        }
        if let Some((film, k)) = &self.film {
            return self.sample_film(rec, u1, film, *k);
        }
        let (r, cos_t, eta) = fresnel::dielectric(cos_i, self.ior);
        rec.measure = Measure::Discrete;
        rec.pdf = 0.0;
        if u1 < r {
            rec.wo = Vec3::new(-rec.wi.x, -rec.wi.y, rec.wi.z);
            rec.eta = 1.0;
            Vec3::ONE
        } else {
            // Refraction: wo = -wi / eta + n (cos_i / eta - cos_t), with n on wi's side.
            let sign = cos_i.signum();
            let wo = Vec3::new(-rec.wi.x / eta, -rec.wi.y / eta, -sign * cos_t);
            rec.wo = wo.normalize();
            rec.eta = eta;
            self.tint
        }
    }

    fn eval(&self, _rec: &BsdfQueryRecord) -> Vec3 {
        Vec3::ZERO
    }

    fn pdf(&self, _rec: &BsdfQueryRecord) -> f32 {
        0.0
    }

    fn is_delta(&self) -> bool {
        true
    }
}
