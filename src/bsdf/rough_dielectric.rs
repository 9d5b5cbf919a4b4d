//! A rough dielectric interface (Walter et al. 2007, "Microfacet Models for Refraction through
//! Rough Surfaces") with GGX and visible-normal sampling: Cycles' Glass BSDF, the transmission
//! of its Principled BSDF, its Refraction BSDF, and reflection-only dielectric lobes (the
//! Principled specular layer and coat).
//!
//! Like [`super::Dielectric`], the frame is **not** flipped towards the viewer: `wi.z > 0`
//! enters (relative index `ior`), `wi.z < 0` leaves (relative index `1 / ior`); the lobe
//! mirrors the configuration through the surface plane so that Cycles' formulas (which always
//! have `wi` above, with `ior` inverted on back faces) apply unchanged.
//!
//! For a half vector `h` with `c = wi·h > 0` and the Fresnel reflectance `F(c)`:
//! - reflection (`wo` on `wi`'s side): `f = R(c) D G2 / (4 |cos θi| |cos θo|)`,
//! - refraction: `f = T(c) D G2 η² |wi·h| |wo·h| / (|cos θi| |cos θo| (wi·h + η wo·h)²)` with
//!   `η = η_o / η_i` and `h ∝ wi + η wo` (facing `wi`),
//!
//! where `R = F · reflection_tint` and `T = (1 - F) · transmission_tint` (see
//! [`DielectricMode`] for the reflection-only and refraction-only forms). As in Cycles (and
//! Tesela's smooth [`super::Dielectric`]) there is no `1/η²` radiance scaling: a sampled
//! refraction's weight is `T G2 / (G1(wi) P_t)`. Sampling picks reflection with Cycles'
//! probability `P_r = avg(R) / avg(R + T)` at the sampled microfacet.
//!
//! By default this is single scattering: light that would scatter between microfacets is lost
//! (Cycles' "GGX" distribution). [`RoughDielectric::multiscatter`] adds Cycles' "Multiscatter
//! GGX" energy compensation (the Principled default): `f` scaled by
//! [`tables::multiscatter_factor`]`(E(μ), E_avg, F_ss)` with the glass tables (Glass) or the
//! mirror tables (Reflection), and `F_ss` chosen as Cycles does (the transmission tint for
//! glass, the average Fresnel for reflection).

use super::microfacet::{Distribution, Roughness};
use super::thin_film::ThinFilm;
use super::{Bsdf, BsdfQueryRecord, Measure, fresnel, tables};
use glam::{Vec2, Vec3};

/// Which lobes a [`RoughDielectric`] has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DielectricMode {
    /// Reflection and refraction with Fresnel: `R = F · reflection_tint`,
    /// `T = (1 - F) · transmission_tint` (Glass BSDF, Principled transmission).
    Glass,
    /// Refraction only, no Fresnel: `T = transmission_tint`, zero beyond the critical angle of
    /// the microfacet (Cycles' Refraction BSDF, `fresnel_type = NONE`).
    Refraction,
    /// Reflection only with the dielectric Fresnel: `R = F · reflection_tint` (Principled
    /// specular layer and coat). Opaque: the integrator flips its frame towards the viewer.
    Reflection,
}

#[derive(Clone, Copy, Debug)]
pub struct RoughDielectric {
    /// `η_inside / η_outside`.
    pub ior: f32,
    pub roughness: Roughness,
    /// The roughness the lobe was set up with, where its energy compensation and its albedo
    /// as a layer are looked up: `roughness` unless Filter Glossy raised it
    /// ([`RoughDielectric::blurred`]).
    pub setup_roughness: Roughness,
    pub mode: DielectricMode,
    /// Cycles' generalised-Schlick `F0` scale: `F = mix(F0 · k, 1, s)` with
    /// `s = (F_real - F0) / (1 - F0)`, `F0 = ((η-1)/(η+1))²` (Principled's Specular Tint);
    /// `ONE` gives the exact Fresnel reflectance.
    pub f0_tint: Vec3,
    pub reflection_tint: Vec3,
    pub transmission_tint: Vec3,
    /// `F_ss` of Cycles' energy compensation, when enabled ([`RoughDielectric::multiscatter`]).
    pub multiscatter_fss: Option<Vec3>,
    /// `(cos θi, η, energy_factor, E(cos θi))` found once for the shading point's incident
    /// direction (`E` from the table the factor came from).
    energy_at: Option<(f32, f32, Vec3, f32)>,
    /// A thin film on the surface (the Principled BSDF's): its interference replaces the
    /// Fresnel reflectance of reflection and glass modes ([`ThinFilm::principled`]).
    pub thin_film: Option<ThinFilm>,
    /// The Beckmann distribution instead of GGX.
    pub beckmann: bool,
}

/// Relative index within this distance of 1 makes refraction a pass-through (Cycles treats it
/// as singular too).
const ETA_ONE: f32 = 1e-4;

impl RoughDielectric {
    /// The general constructor. `ior` = `η_inside / η_outside` (invalid values become 1.5);
    /// alphas are clamped to `[DELTA_ALPHA, 1]` (below `DELTA_ALPHA` the caller should use the
    /// delta [`super::Dielectric`]).
    pub fn new(
        ior: f32,
        alpha_x: f32,
        alpha_y: f32,
        mode: DielectricMode,
        reflection_tint: Vec3,
        transmission_tint: Vec3,
    ) -> Self {
        let ior = if ior.is_finite() && ior > 0.0 {
            ior
        } else {
            1.5
        };
        let roughness = Roughness::new(alpha_x, alpha_y);
        RoughDielectric {
            ior,
            roughness,
            setup_roughness: roughness,
            mode,
            f0_tint: Vec3::ONE,
            reflection_tint: reflection_tint.max(Vec3::ZERO),
            transmission_tint: transmission_tint.max(Vec3::ZERO),
            multiscatter_fss: None,
            energy_at: None,
            thin_film: None,
            beckmann: false,
        }
    }

    /// The same lobe with the Beckmann distribution (`on`) instead of GGX.
    pub fn with_beckmann(self, on: bool) -> Self {
        RoughDielectric {
            beckmann: on,
            ..self
        }
    }

    /// The lobe's roughness with its distribution.
    #[inline]
    pub fn distribution(&self) -> Distribution {
        Distribution {
            roughness: self.roughness,
            beckmann: self.beckmann,
        }
    }

    /// The same lobe under a thin film (`None`: none). Energy compensation keeps the
    /// film-less `F_ss`, as in Cycles.
    pub fn with_thin_film(self, thin_film: Option<ThinFilm>) -> Self {
        RoughDielectric { thin_film, ..self }
    }

    /// The film's reflectance at `c = wi·h` for relative index `eta` (`self.ior` seen from
    /// outside, its inverse from inside).
    #[inline]
    pub(crate) fn film_reflectance(&self, film: &ThinFilm, c: f32, eta: f32) -> Vec3 {
        film.on_dielectric(c, eta, eta != self.ior, self.f0_tint)
    }

    /// The same lobe with Cycles' Multiscatter GGX energy compensation (Glass and Reflection
    /// modes; Cycles' Refraction BSDF has none, so that mode is returned unchanged). `F_ss` as
    /// in Cycles' `bsdf_microfacet_setup_fresnel_*`: the transmission tint for glass; for
    /// reflection `mix(F0·k, 1, s)` with `s = (F̄ - F0) / (1 - F0)`, `F̄` the hemispherical
    /// average Fresnel ([`tables::fresnel_dielectric_fss`]); the reflection tint is treated as
    /// the closure's weight, not part of `F_ss`.
    pub fn multiscatter(self) -> Self {
        let fss = match self.mode {
            DielectricMode::Refraction => return self,
            DielectricMode::Glass => self.transmission_tint,
            DielectricMode::Reflection => {
                let f0 = fresnel::f0_from_ior(self.ior);
                let fbar = tables::fresnel_dielectric_fss(self.ior);
                let s = if f0 < 1.0 {
                    ((fbar - f0) / (1.0 - f0)).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                let f0t = (f0 * self.f0_tint).min(Vec3::ONE);
                f0t + (Vec3::ONE - f0t) * s
            }
        };
        RoughDielectric {
            multiscatter_fss: Some(fss),
            ..self
        }
    }

    /// Cycles' energy compensation ([`RoughDielectric::multiscatter`]) with `F_ss` given: the
    /// Glass BSDF's colour, which Tesela keeps in the closure weight and Cycles in the tints
    /// (for a Glass-mode lobe; a Refraction-mode lobe has no compensation in Cycles).
    pub fn multiscatter_with_fss(self, fss: Vec3) -> Self {
        RoughDielectric {
            multiscatter_fss: Some(fss),
            ..self
        }
    }

    /// The energy-compensation factor for `wi` (mirrored to `wi.z > 0`) and relative index
    /// `eta`; 1 without compensation.
    #[inline]
    pub fn energy_factor(&self, wi_z: f32, eta: f32) -> Vec3 {
        let Some(fss) = self.multiscatter_fss else {
            return Vec3::ONE;
        };
        if let Some((z, e, f, _)) = self.energy_at
            && z == wi_z
            && e == eta
        {
            return f;
        }
        self.energy_terms(wi_z, eta, fss).0
    }

    /// `(energy_factor, E(wi_z))` with compensation `fss`.
    #[inline]
    fn energy_terms(&self, wi_z: f32, eta: f32, fss: Vec3) -> (Vec3, f32) {
        let a = &self.setup_roughness;
        let (e, e_avg) = match self.mode {
            DielectricMode::Glass => tables::ggx_glass_e((a.alpha_x * a.alpha_y).sqrt(), wi_z, eta),
            _ => tables::ggx_e(a.alpha_x, a.alpha_y, wi_z),
        };
        (tables::multiscatter_factor(e, e_avg, fss), e)
    }

    /// `E(μ)` of the white single-scattering GGX mirror of the setup roughness (a reflection
    /// lobe's darkening as a layer), from the prepared values when they are for `μ`.
    #[inline]
    pub(crate) fn reflection_e(&self, mu: f32) -> f32 {
        if let Some((z, eta, _, e)) = self.energy_at
            && z == mu
            && eta == self.ior
            && self.mode == DielectricMode::Reflection
        {
            return e;
        }
        let r = &self.setup_roughness;
        tables::ggx_e(r.alpha_x, r.alpha_y, mu).0
    }

    /// The same lobe with its alphas raised to at least `blur` (Cycles' Filter Glossy,
    /// `bsdf_microfacet_blur`; `blur <= 0` changes nothing). Energy compensation and layer
    /// albedo stay those of the roughness the lobe was set up with, as in Cycles.
    #[inline]
    pub fn blurred(self, blur: f32) -> Self {
        if blur <= 0.0 {
            return self;
        }
        let r = self.roughness;
        RoughDielectric {
            roughness: Roughness::new(r.alpha_x.max(blur), r.alpha_y.max(blur)),
            energy_at: None,
            ..self
        }
    }

    /// Computes the energy compensation for the incident direction `wi` the queries will use
    /// (the same value, found once: it costs table lookups).
    pub fn prepare(&mut self, wi: Vec3) {
        if self.multiscatter_fss.is_none() || wi.z == 0.0 {
            return;
        }
        self.energy_at = None;
        let (flip, eta) = self.side(wi);
        let z = mirror(wi, flip).z;
        let Some(fss) = self.multiscatter_fss else {
            return;
        };
        let (f, e) = self.energy_terms(z, eta, fss);
        self.energy_at = Some((z, eta, f, e));
    }

    /// Blender's Glass BSDF (GGX): Color tints reflection and refraction alike (Cycles sets
    /// both tints to the colour); `alpha = Roughness²`.
    pub fn glass(color: Vec3, ior: f32, alpha: f32) -> Self {
        RoughDielectric::new(ior, alpha, alpha, DielectricMode::Glass, color, color)
    }

    /// Principled BSDF transmission (Cycles 4.x/5.x, not thin-walled): reflection untinted
    /// except for `F0 · specular_tint`, each refraction tinted by `sqrt(base colour)` (a closed
    /// solid transmits the base colour once), `alpha = Roughness²`.
    pub fn principled_transmission(
        base_color: Vec3,
        specular_tint: Vec3,
        ior: f32,
        alpha: f32,
    ) -> Self {
        let base = base_color.clamp(Vec3::ZERO, Vec3::ONE);
        RoughDielectric {
            f0_tint: specular_tint.max(Vec3::ZERO),
            ..RoughDielectric::new(
                ior,
                alpha,
                alpha,
                DielectricMode::Glass,
                Vec3::ONE,
                base.map(f32::sqrt),
            )
        }
    }

    /// Blender's Refraction BSDF (GGX): refraction only, weight Color, no Fresnel.
    pub fn refraction(color: Vec3, ior: f32, alpha: f32) -> Self {
        RoughDielectric::new(
            ior,
            alpha,
            alpha,
            DielectricMode::Refraction,
            Vec3::ZERO,
            color,
        )
    }

    /// Principled BSDF's specular layer (dielectric base): reflection only, `F0` scaled by
    /// Specular Tint, with the IOR from [`principled_specular_ior`]`(IOR, Specular IOR Level)`
    /// and `(alpha_x, alpha_y)` from [`super::microfacet::anisotropy::principled`]. Layer it over
    /// the diffuse base with [`super::Layered`]; add [`RoughDielectric::multiscatter`] for
    /// Cycles' default distribution.
    pub fn principled_specular(specular_tint: Vec3, ior: f32, alpha_x: f32, alpha_y: f32) -> Self {
        RoughDielectric {
            f0_tint: specular_tint.max(Vec3::ZERO),
            ..RoughDielectric::reflection(Vec3::ONE, ior, alpha_x, alpha_y)
        }
    }

    /// A reflection-only lobe with the dielectric Fresnel of `ior`, tinted by `tint`
    /// (coat: `tint` = Coat weight, `alpha = Coat Roughness²`).
    pub fn reflection(tint: Vec3, ior: f32, alpha_x: f32, alpha_y: f32) -> Self {
        RoughDielectric::new(
            ior,
            alpha_x,
            alpha_y,
            DielectricMode::Reflection,
            tint,
            Vec3::ZERO,
        )
    }

    /// Relative index seen from `wi` and whether the configuration must be mirrored.
    #[inline]
    fn side(&self, wi: Vec3) -> (bool, f32) {
        if wi.z < 0.0 {
            (true, 1.0 / self.ior)
        } else {
            (false, self.ior)
        }
    }

    /// `(R, T, cos θt)` at `c = wi·h > 0` for relative index `eta`.
    #[inline]
    pub fn fresnel(&self, c: f32, eta: f32) -> (Vec3, Vec3, f32) {
        let (f, cos_t, _) = fresnel::dielectric(c, eta);
        match self.mode {
            DielectricMode::Refraction => {
                let t = if f >= 1.0 {
                    Vec3::ZERO
                } else {
                    self.transmission_tint
                };
                (Vec3::ZERO, t, cos_t)
            }
            DielectricMode::Glass | DielectricMode::Reflection => {
                let fv = if let Some(film) = &self.thin_film {
                    self.film_reflectance(film, c, eta)
                } else if self.f0_tint == Vec3::ONE {
                    Vec3::splat(f)
                } else {
                    let f0 = fresnel::f0_from_ior(eta);
                    let s = if f0 < 1.0 {
                        ((f - f0) / (1.0 - f0)).clamp(0.0, 1.0)
                    } else {
                        1.0
                    };
                    let f0t = (f0 * self.f0_tint).min(Vec3::ONE);
                    f0t + (Vec3::ONE - f0t) * s
                };
                let r = fv * self.reflection_tint;
                let t = if self.mode == DielectricMode::Glass {
                    (Vec3::ONE - fv) * self.transmission_tint
                } else {
                    Vec3::ZERO
                };
                (r, t, cos_t)
            }
        }
    }

    /// Probability of choosing reflection given `R` and `T` (Cycles' `pdf_reflect`).
    #[inline]
    fn p_reflect(r: Vec3, t: Vec3) -> Option<f32> {
        let total = (r + t).element_sum();
        (total > 0.0).then(|| r.element_sum() / total)
    }

    /// The half vector of a refraction pair (`wi.z > 0 > wo.z`),
    /// facing `wi`, or `None` when the pair cannot come from one microfacet.
    #[inline]
    fn refraction_half(wi: Vec3, wo: Vec3, eta: f32) -> Option<Vec3> {
        let ht = wi + eta * wo;
        let len = ht.length();
        if len <= 0.0 || !len.is_finite() {
            return None;
        }
        let mut h = ht / len;
        if h.z < 0.0 {
            h = -h;
        }
        (wi.dot(h) > 0.0 && wo.dot(h) < 0.0).then_some(h)
    }

    /// `(f, pdf)` for a pair with `wi.z > 0` in the mirrored configuration.
    fn eval_pdf(&self, wi: Vec3, wo: Vec3, eta: f32) -> (Vec3, f32) {
        let zero = (Vec3::ZERO, 0.0);
        if wo.z == 0.0 {
            return zero;
        }
        let a = self.distribution();
        if wo.z > 0.0 {
            if self.mode == DielectricMode::Refraction {
                return zero;
            }
            let h = (wi + wo).normalize();
            let c = wi.dot(h);
            let (r, t, _) = self.fresnel(c, eta);
            let Some(pr) = Self::p_reflect(r, t) else {
                return zero;
            };
            let d = a.d(h);
            let f = r * d * a.g2(wi, wo) / (4.0 * wi.z * wo.z);
            (
                f * self.energy_factor(wi.z, eta),
                pr * a.g1(wi) * d / (4.0 * wi.z),
            )
        } else {
            if self.mode == DielectricMode::Reflection || (eta - 1.0).abs() < ETA_ONE {
                return zero;
            }
            let Some(h) = Self::refraction_half(wi, wo, eta) else {
                return zero;
            };
            let (hi, ho) = (wi.dot(h), wo.dot(h));
            let (r, t, _) = self.fresnel(hi, eta);
            let Some(pr) = Self::p_reflect(r, t) else {
                return zero;
            };
            let denom = hi + eta * ho;
            let jac = eta * eta * (-ho) / (denom * denom);
            let d = a.d(h);
            let f = t * d * a.g2(wi, wo) * hi * jac / (wi.z * -wo.z);
            (
                f * self.energy_factor(wi.z, eta),
                (1.0 - pr) * a.g1(wi) * hi * d / wi.z * jac,
            )
        }
    }
}

/// Cycles' Specular IOR Level adjustment (`svm/closure.h`): `F0(ior)` scaled by `2 · level`
/// and turned back into an IOR (`level` 0.5 keeps `ior`; 0 gives 1, no specular layer).
pub fn principled_specular_ior(ior: f32, level: f32) -> f32 {
    let ior = ior.max(1e-5);
    let level = level.max(0.0);
    if level == 0.5 {
        return ior;
    }
    let f0 = fresnel::f0_from_ior(ior) * 2.0 * level;
    let eta = super::tables::ior_from_f0(f0);
    if ior < 1.0 { 1.0 / eta } else { eta }
}

#[inline]
fn mirror(w: Vec3, flip: bool) -> Vec3 {
    if flip { Vec3::new(w.x, w.y, -w.z) } else { w }
}

impl Bsdf for RoughDielectric {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, u1: f32) -> Vec3 {
        if rec.wi.z == 0.0 {
            return Vec3::ZERO;
        }
        let (flip, eta) = self.side(rec.wi);
        let wi = mirror(rec.wi, flip);
        let a = self.distribution();
        let h = a.sample_visible_normal(wi, u);
        let c = wi.dot(h);
        if c <= 0.0 {
            return Vec3::ZERO;
        }
        let (r, t, cos_t) = self.fresnel(c, eta);
        let Some(pr) = Self::p_reflect(r, t) else {
            return Vec3::ZERO;
        };
        let wo = if u1 < pr {
            let wo = 2.0 * c * h - wi;
            if wo.z <= 0.0 {
                return Vec3::ZERO;
            }
            wo
        } else {
            if t == Vec3::ZERO {
                return Vec3::ZERO;
            }
            if (eta - 1.0).abs() < ETA_ONE {
                // Index-matched: the microfacets do not bend the ray.
                rec.wo = -rec.wi;
                rec.pdf = 0.0;
                rec.eta = 1.0;
                rec.measure = Measure::Discrete;
                return t / (1.0 - pr) * self.energy_factor(wi.z, eta);
            }
            let wo = ((c / eta - cos_t) * h - wi / eta).normalize();
            if wo.z >= 0.0 || wo.dot(h) >= 0.0 {
                return Vec3::ZERO;
            }
            wo
        };
        // Value and density from the pair, as `eval` and `pdf` compute them (the half vector
        // recomputed from `wi` and `wo`), so that MIS sees the same density both ways.
        let (f, pdf) = self.eval_pdf(wi, wo, eta);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return Vec3::ZERO;
        }
        rec.wo = mirror(wo, flip);
        rec.pdf = pdf;
        rec.eta = if wo.z > 0.0 { 1.0 } else { eta };
        rec.measure = Measure::SolidAngle;
        f * wo.z.abs() / pdf
    }

    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        if rec.wi.z == 0.0 {
            return Vec3::ZERO;
        }
        let (flip, eta) = self.side(rec.wi);
        self.eval_pdf(mirror(rec.wi, flip), mirror(rec.wo, flip), eta)
            .0
    }

    /// Reflection is glossy, refraction transmission.
    fn eval_split(&self, rec: &BsdfQueryRecord) -> [Vec3; 2] {
        if rec.wi.z * rec.wo.z > 0.0 {
            [Vec3::ZERO, self.eval(rec)]
        } else {
            [Vec3::ZERO; 2]
        }
    }

    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        if rec.wi.z == 0.0 {
            return 0.0;
        }
        let (flip, eta) = self.side(rec.wi);
        self.eval_pdf(mirror(rec.wi, flip), mirror(rec.wo, flip), eta)
            .1
    }

    fn eval_and_pdf(&self, rec: &BsdfQueryRecord) -> (Vec3, f32) {
        if rec.wi.z == 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let (flip, eta) = self.side(rec.wi);
        self.eval_pdf(mirror(rec.wi, flip), mirror(rec.wo, flip), eta)
    }

    fn is_delta(&self) -> bool {
        false
    }
}
