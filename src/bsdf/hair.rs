//! Cycles' Principled Hair BSDF, Chiang model (Chiang, Bitterli, Tappan and Burley 2016, "A
//! Practical and Controllable Hair and Fur Model for Production Path Tracing"; d'Eon et al.'s
//! longitudinal term, a logistic azimuthal term), with Cycles' parameter mappings.
//!
//! **Frame.** Local +X is the unit curve tangent (Cycles' `normalize(dPdu)`); +Y and +Z are any
//! two unit vectors completing a **right-handed** frame (`Y × Z = X`; the project's
//! [`crate::frame::Frame`] with `s` = tangent, `n` ⊥ tangent and `t = n × s`). The model is
//! symmetric about the fibre, so the choice of Z only matters for the integrator's cosine: the
//! lobe's value is `F(wi, wo)` per steradian *including* the cosine (Cycles' eval), and
//! [`Bsdf::eval`] returns `F / |wo.z|` so that the integrator's `eval · |wo.z|` is `F` (pbrt's
//! hair BSDF does the same). Choosing `n` as the viewer's direction perpendicular to the
//! tangent keeps `|wo.z|` away from zero where the lobe is brightest.
//!
//! Angles (directions point away from the fibre, `wi` towards the viewer, `wo` towards the
//! light): `sin θ = w.x` (longitude: the angle to the normal plane), `φ = atan2(w.z, w.y)`
//! (azimuth about the tangent).
//!
//! **h** is the offset across the fibre at which the viewer's ray hit it, in `[-1, 1]`: 0
//! through the axis, ±1 grazing either edge. For a thick (cylinder) curve with outward unit
//! normal `ng` at the hit, `h = ng · normalize(wi × tangent)` (Cycles' `dot(cross(Ng, X), Z)`
//! with its `Y = normalize(X × wi)`, `Z = X × Y`), see [`offset_h`]; for a ribbon, `h = -v`,
//! the hit's parametric coordinate across the ribbon.
//!
//! The lobe: `F = Σ_{p<3} A_p M_p(θi - d_p, θo) N_p(φ) + A_3 M(θi, θo; 4v) / 2π`, with
//! `φ = φi - φo`; `A_p` the attenuations (Fresnel at `cos θo cos γo`, transmittance
//! `T = exp(-2 σ_a cos γt / cos θt)`); `M_p` d'Eon's longitudinal scattering with variances
//! `(m0, v/4, 4v)` for R, TT, TRT (`m0` the Coat-reduced one) and the cuticle tilt
//! `d_p = (-2α, α, 4α)`; `N_p` a logistic of scale `s` about
//! `Δφ_p = 2p γt - 2γo + pπ`, trimmed to `[-π, π]`.
//!
//! Sampling follows Cycles: a lobe `p` with probability `A_p`'s share of luminance, `θi` from
//! `M_p` exactly (a von Mises–Fisher draw) shifted by the tilt, `φ` from the trimmed logistic (the
//! residual: uniform). The reported pdf (solid angle) is the density of that sampler.
//!
//! **Deliberate differences from Cycles**, all where Cycles' own pdf is not the density of its
//! sampler or its `M_p` is not normalised; none changes what the lobe converges to:
//! - Cycles reports `Σ w_p M_p N_p` as the pdf, the density of its sampler only without tilt.
//!   Shifting `θ` by `d_p` keeps `dθ` but not `cos θ`, so the density is
//!   `Σ w_p N_p M_p(θ') cos θ' / cos θi`, plus the preimage that folds over a pole, which is
//!   what [`Bsdf::pdf`] returns.
//! - Cycles samples R's longitude with `v` and evaluates it with `m0` (they differ when Coat
//!   is above 0); here R is sampled with `m0`, the variance it is evaluated with.
//! - Cycles' Bessel `I0` stops its series after ten terms (up to 2% low for arguments 10–12)
//!   and its large-argument branch halves the `1/(8x)` term; here `I0` is summed to double
//!   precision, so that `∫ M cos θ dθ = 1` and a white fibre without tilt keeps all energy.

use super::fresnel;
use super::{Bsdf, BsdfQueryRecord, Measure};
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// Rec. 709 luminance, Cycles' `spectrum_to_gray` for linear sRGB scenes.
const LUMINANCE: Vec3 = Vec3::new(0.212_672_9, 0.715_152_2, 0.072_175);

/// Cycles' Chiang hair closure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChiangHair {
    /// Absorption coefficient per channel, per fibre diameter.
    pub sigma_a: Vec3,
    /// Longitudinal variance `v` (after Cycles' roughness mapping).
    pub v: f32,
    /// Logistic scale `s` (after Cycles' radial-roughness mapping).
    pub s: f32,
    /// R's longitudinal variance (roughness reduced by Coat, then mapped like `v`).
    pub m0: f32,
    /// Cuticle tilt α, radians (Blender's Offset).
    pub alpha: f32,
    /// Index of refraction of the fibre.
    pub eta: f32,
    /// Offset across the fibre, `[-1, 1]` (see the module documentation).
    pub h: f32,
    /// `(sin, cos)` of the tilts `d_p = (-2α, α, 4α)` of R, TT and TRT.
    tilt: [(f32, f32); 3],
}

/// Cycles' mapping of a roughness in `[0, 1]` to the longitudinal variance.
#[inline]
fn variance(r: f32) -> f32 {
    let x = 0.726 * r + 0.812 * r * r + 3.7 * r.powi(20);
    x * x
}

/// [`offset_h`]'s definition evaluated from world-space vectors: the unit curve tangent `t`,
/// the unit direction `wi` towards the viewer and the outward unit normal `ng` of the (thick)
/// curve at the hit. `h = ng · normalize(wi × t)`, clamped to `[-1, 1]`; 0 when `wi` runs along
/// the tangent.
pub fn offset_h(t: Vec3, wi: Vec3, ng: Vec3) -> f32 {
    match wi.cross(t).try_normalize() {
        Some(b) => ng.dot(b).clamp(-1.0, 1.0),
        None => 0.0,
    }
}

impl ChiangHair {
    /// The closure as Cycles sets it up from the node's values (after the Random input's
    /// effect, see [`PrincipledHair`]): `roughness` and `radial_roughness` are clamped to
    /// `[0.001, 1]`, R's roughness is `roughness · (1 - Coat)` clamped alike, and they are
    /// mapped to `v = (0.726 r + 0.812 r² + 3.7 r²⁰)²`,
    /// `s = (0.265 r + 1.194 r² + 5.372 r²²) √(π/8)`. `alpha` is the tilt in radians, `h` the
    /// offset across the fibre.
    pub fn new(
        sigma_a: Vec3,
        roughness: f32,
        radial_roughness: f32,
        coat: f32,
        eta: f32,
        alpha: f32,
        h: f32,
    ) -> ChiangHair {
        let clamp = |x: f32| if x.is_nan() { 1.0 } else { x.clamp(0.001, 1.0) };
        let r = clamp(roughness);
        let rr = clamp(radial_roughness);
        let coat = if coat.is_nan() {
            0.0
        } else {
            coat.clamp(0.0, 1.0)
        };
        let r0 = clamp(r * (1.0 - coat));
        let s = (0.265 * rr + 1.194 * rr * rr + 5.372 * rr.powi(22)) * (PI / 8.0).sqrt();
        let alpha = if alpha.is_finite() { alpha } else { 0.0 };
        ChiangHair {
            sigma_a: sigma_a.max(Vec3::ZERO),
            v: variance(r),
            s,
            m0: variance(r0),
            alpha,
            eta,
            h: if h.is_nan() { 0.0 } else { h.clamp(-1.0, 1.0) },
            tilt: [-2.0 * alpha, alpha, 4.0 * alpha].map(|d| d.sin_cos()),
        }
    }

    /// Cycles' Filter Glossy: `v`, `s` and `m0` raised to at least `blur` (in the mapped units,
    /// as Cycles' `bsdf_hair_chiang_blur` does).
    pub fn blurred(mut self, blur: f32) -> ChiangHair {
        if blur > 0.0 {
            self.v = self.v.max(blur);
            self.s = self.s.max(blur);
            self.m0 = self.m0.max(blur);
        }
        self
    }

    /// Cycles' albedo estimate of the closure (its Color passes and denoising albedo):
    /// `exp(-√σ_a · k(v)) + F(cos θo cos γo)`, `k` the roughness scale polynomial taken at
    /// the mapped variance, as Cycles does. Not the directional albedo.
    pub fn albedo_estimate(&self, wi: Vec3) -> Vec3 {
        let cos_o = cos_from_sin(wi.x);
        let cos_go = cos_from_sin(self.h);
        let f = fresnel::dielectric(cos_o * cos_go, self.eta).0;
        let k = albedo_roughness_scale(self.v);
        Vec3::new(
            (-self.sigma_a.x.sqrt() * k).exp(),
            (-self.sigma_a.y.sqrt() * k).exp(),
            (-self.sigma_a.z.sqrt() * k).exp(),
        ) + Vec3::splat(f)
    }

    /// What depends on `wi` only; `None` where the lobe is black (every attenuation zero, or
    /// an IOR that cannot refract this `wi`).
    #[inline]
    fn setup(&self, wi: Vec3) -> Option<Setup> {
        let sin_o = wi.x.clamp(-1.0, 1.0);
        let cos_o = cos_from_sin(sin_o);
        let phi_o = wi.z.atan2(wi.y);
        let sin_t = sin_o / self.eta;
        let cos_t = cos_from_sin(sin_t);
        let sin_go = self.h;
        let cos_go = cos_from_sin(sin_go);
        let gamma_o = sin_go.clamp(-1.0, 1.0).asin();
        let sin_gt = sin_go * cos_o / (self.eta * self.eta - sin_o * sin_o).sqrt();
        if !sin_gt.is_finite() {
            return None;
        }
        let cos_gt = cos_from_sin(sin_gt);
        let gamma_t = sin_gt.clamp(-1.0, 1.0).asin();
        let t = (-self.sigma_a * (2.0 * cos_gt / cos_t)).exp();
        let f = fresnel::dielectric(cos_o * cos_go, self.eta).0;
        // R, TT, TRT, and the residual TRRT+ as a geometric series.
        let a0 = Vec3::splat(f);
        let a1 = (1.0 - f) * (1.0 - f) * t;
        let a2 = a1 * t * f;
        let tf = t * f;
        let a3 = a2 * safe_div3(tf, Vec3::ONE - tf);
        let ap = [a0, a1, a2, a3];
        let mut w = ap.map(|a| a.dot(LUMINANCE));
        let total: f32 = w.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        for x in &mut w {
            *x /= total;
        }
        let delta = [0, 1, 2].map(|p| {
            let p = p as f32;
            2.0 * p * gamma_t - 2.0 * gamma_o + p * PI
        });
        Some(Setup {
            sin_o,
            cos_o,
            phi_o,
            ap,
            w,
            delta,
        })
    }

    /// The variance lobe `p` is evaluated and sampled with.
    #[inline]
    fn lobe_variance(&self, p: usize) -> f32 {
        match p {
            0 => self.m0,
            1 => 0.25 * self.v,
            _ => 4.0 * self.v,
        }
    }

    /// `(F, pdf)` at local `wo`: the value with the cosine (Cycles' eval) and the sampler's
    /// solid-angle density.
    #[inline]
    fn value_and_density(&self, su: &Setup, wo: Vec3) -> (Vec3, f32) {
        let sin_i = wo.x.clamp(-1.0, 1.0);
        let cos_i = cos_from_sin(sin_i);
        let phi = wo.z.atan2(wo.y) - su.phi_o;
        let (mut f, mut pdf_cos) = (Vec3::ZERO, 0.0f64);
        for p in 0..3 {
            let v = self.lobe_variance(p);
            let (sd, cd) = self.tilt[p];
            let n = trimmed_logistic(wrap_angle(phi - su.delta[p]), self.s);
            // θi - d_p: the untilted angle the lobe is evaluated at (folded over the pole as
            // Cycles' |cos| does) and, within (-π/2, π/2), the sampler's direct preimage.
            let s_minus = sin_i * cd - cos_i * sd;
            let c_minus = cos_i * cd + sin_i * sd;
            let m = longitudinal(s_minus, c_minus.abs(), su.sin_o, su.cos_o, v);
            f += su.ap[p] * (m as f32 * n);
            let mut q = if c_minus >= 0.0 {
                m * c_minus as f64
            } else {
                0.0
            };
            // A sampled θ' + d_p beyond a pole lands at the mirrored latitude, azimuth kept:
            // the second preimage, at θ' = ±π - (θi + d_p).
            let c_plus = cos_i * cd - sin_i * sd;
            if c_plus < 0.0 {
                let s_plus = sin_i * cd + cos_i * sd;
                q += longitudinal(s_plus, -c_plus, su.sin_o, su.cos_o, v) * (-c_plus) as f64;
            }
            pdf_cos += su.w[p] as f64 * q * n as f64;
        }
        let m3 = longitudinal(sin_i, cos_i, su.sin_o, su.cos_o, 4.0 * self.v);
        let n3 = 1.0 / TAU;
        f += su.ap[3] * (m3 as f32 * n3);
        let pdf = if cos_i > 0.0 {
            (pdf_cos / cos_i as f64 + su.w[3] as f64 * m3 * n3 as f64) as f32
        } else {
            0.0
        };
        (f, pdf)
    }

    /// `F(wi, wo)` including the cosine, and the sampling density, for a query.
    #[inline]
    fn query(&self, rec: &BsdfQueryRecord) -> (Vec3, f32) {
        match self.setup(rec.wi) {
            Some(su) => self.value_and_density(&su, rec.wo),
            None => (Vec3::ZERO, 0.0),
        }
    }
}

/// Cycles' Principled Hair BSDF node (Chiang model) as the shader gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipledHair {
    pub color: HairColor,
    pub roughness: f32,
    pub radial_roughness: f32,
    pub coat: f32,
    pub ior: f32,
    /// Offset: the cuticle tilt, radians.
    pub offset: f32,
    pub random_color: f32,
    pub random_roughness: f32,
    /// The Random input where it is linked; else Cycles reads the curve's random attribute
    /// (Hair Info > Random), and the socket's value only where the geometry has none.
    pub random: f32,
}

/// The node's colour parametrizations (its `parametrization` property).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HairColor {
    /// 'ABSORPTION': the Absorption Coefficient input, σ_a as it is.
    Absorption(Vec3),
    /// 'MELANIN': Melanin, Melanin Redness and Tint.
    Melanin {
        melanin: f32,
        redness: f32,
        tint: Vec3,
    },
    /// 'COLOR': direct colouring from the Color input.
    Reflectance(Vec3),
}

/// Cycles' randomisation factor `1 + 2 (random - ½) amount`: the parameter varies by
/// `± amount / 2` of itself as `random` runs over `[0, 1]`.
#[inline]
pub fn random_factor(random: f32, amount: f32) -> f32 {
    1.0 + 2.0 * (random - 0.5) * amount
}

/// Cycles' `bsdf_principled_hair_albedo_roughness_scale`: the polynomial (Chiang et al.'s fit)
/// relating an azimuthal roughness to the exponent of a fibre's multiple-scattering colour.
#[inline]
pub fn albedo_roughness_scale(x: f32) -> f32 {
    (((((0.245 * x) + 5.574) * x - 10.73) * x + 2.532) * x - 0.215) * x + 5.969
}

/// Direct colouring: the σ_a whose fibre shows `color` (Chiang et al.'s inverted fit),
/// `(ln(max(color, 0)) / k(radial roughness))²` per channel (a black channel gives ∞).
pub fn sigma_a_from_reflectance(color: Vec3, radial_roughness: f32) -> Vec3 {
    let k = albedo_roughness_scale(radial_roughness);
    let c = color.max(Vec3::ZERO);
    let s = Vec3::new(c.x.ln(), c.y.ln(), c.z.ln()) / k;
    s * s
}

/// σ_a of eumelanin and pheomelanin concentrations (Cycles' RGB absorption of each pigment).
pub fn sigma_a_from_concentration(eumelanin: f32, pheomelanin: f32) -> Vec3 {
    eumelanin * Vec3::new(0.506, 0.841, 1.653) + pheomelanin * Vec3::new(0.343, 0.733, 1.924)
}

/// The melanin parametrization: Melanin scaled by [`random_factor`] (`random_color` clamped
/// to `[0, 1]`), mapped from `[0, 1]` to a concentration `-ln(max(1 - m, 10⁻⁴))`, split by
/// Redness into pheomelanin (`m · redness`) and eumelanin (the rest), plus the Tint's σ_a by
/// [`sigma_a_from_reflectance`] at `radial_roughness` (already randomised, as Cycles passes it).
pub fn sigma_a_from_melanin(
    melanin: f32,
    redness: f32,
    tint: Vec3,
    radial_roughness: f32,
    random_color: f32,
    random: f32,
) -> Vec3 {
    let m = melanin * random_factor(random, random_color.clamp(0.0, 1.0));
    let m = -(1.0 - m).max(1e-4).ln();
    sigma_a_from_concentration(m * (1.0 - redness), m * redness)
        + sigma_a_from_reflectance(tint, radial_roughness)
}

impl PrincipledHair {
    /// Blender's defaults for the node (Melanin parametrization).
    pub fn blender_default() -> PrincipledHair {
        PrincipledHair {
            color: HairColor::Melanin {
                melanin: 0.8,
                redness: 1.0,
                tint: Vec3::ONE,
            },
            roughness: 0.3,
            radial_roughness: 0.3,
            coat: 0.0,
            ior: 1.55,
            offset: 2f32.to_radians(),
            random_color: 0.0,
            random_roughness: 0.0,
            random: 0.0,
        }
    }

    /// `(roughness, radial roughness, σ_a)` after the Random input, as Cycles' shader
    /// computes them: both roughnesses scaled by `random_factor(random, Random Roughness)`,
    /// the colour per its parametrization.
    pub fn resolved(&self) -> (f32, f32, Vec3) {
        let k = random_factor(self.random, self.random_roughness);
        let (r, rr) = (self.roughness * k, self.radial_roughness * k);
        let sigma = match self.color {
            HairColor::Absorption(s) => s,
            HairColor::Melanin {
                melanin,
                redness,
                tint,
            } => sigma_a_from_melanin(melanin, redness, tint, rr, self.random_color, self.random),
            HairColor::Reflectance(c) => sigma_a_from_reflectance(c, rr),
        };
        (r, rr, sigma)
    }

    /// The fibre's albedo estimate seen across it (the colour passes and the denoiser's
    /// albedo).
    pub fn hair_albedo(&self) -> Vec3 {
        self.lobe(0.0).albedo_estimate(Vec3::Z)
    }

    /// The lobe at a hit with offset `h` across the fibre.
    pub fn lobe(&self, h: f32) -> ChiangHair {
        let (r, rr, sigma) = self.resolved();
        ChiangHair::new(sigma, r, rr, self.coat, self.ior, self.offset, h)
    }
}

struct Setup {
    sin_o: f32,
    cos_o: f32,
    phi_o: f32,
    /// Attenuations of R, TT, TRT and the residual.
    ap: [Vec3; 4],
    /// Their luminance shares: the lobe-choice probabilities.
    w: [f32; 4],
    /// The azimuthal centres `Δφ_p` of R, TT, TRT.
    delta: [f32; 3],
}

#[inline]
fn cos_from_sin(s: f32) -> f32 {
    (1.0 - s * s).max(0.0).sqrt()
}

#[inline]
fn safe_div3(a: Vec3, b: Vec3) -> Vec3 {
    let d = |a: f32, b: f32| if b != 0.0 { a / b } else { 0.0 };
    Vec3::new(d(a.x, b.x), d(a.y, b.y), d(a.z, b.z))
}

/// `a` wrapped into `[-π, π)`.
#[inline]
fn wrap_angle(a: f32) -> f32 {
    a - TAU * ((a + PI) / TAU).floor()
}

#[inline]
fn logistic(x: f32, s: f32) -> f32 {
    let v = (-x.abs() / s).exp();
    v / (s * (1.0 + v) * (1.0 + v))
}

#[inline]
fn logistic_cdf(x: f32, s: f32) -> f32 {
    let arg = -x / s;
    // exp overflows past 88.
    if arg > 88.0 {
        0.0
    } else {
        1.0 / (1.0 + arg.exp())
    }
}

/// The logistic of scale `s` restricted to `[-π, π]` and renormalised there.
#[inline]
fn trimmed_logistic(x: f32, s: f32) -> f32 {
    let norm = 1.0 - 2.0 * logistic_cdf(-PI, s);
    if norm > 0.0 {
        logistic(x, s) / norm
    } else {
        0.0
    }
}

/// Inverse CDF of [`trimmed_logistic`].
#[inline]
fn sample_trimmed_logistic(u: f32, s: f32) -> f32 {
    let c = logistic_cdf(-PI, s);
    let x = -s * (1.0 / (u * (1.0 - 2.0 * c) + c) - 1.0).ln();
    x.clamp(-PI, PI)
}

/// `ln I0(x)` for `x ≥ 0` to double precision: the power series up to 20, the asymptotic
/// series (four terms) beyond.
fn ln_bessel_i0(x: f64) -> f64 {
    if x <= 20.0 {
        let q = 0.25 * x * x;
        let (mut term, mut sum) = (1.0f64, 1.0f64);
        for k in 1..200 {
            term *= q / (k * k) as f64;
            sum += term;
            if term < sum * 1e-17 {
                break;
            }
        }
        sum.ln()
    } else {
        let r = 1.0 / x;
        let tail = 1.0 + r * (1.0 / 8.0 + r * (9.0 / 128.0 + r * (225.0 / 3072.0)));
        x - 0.5 * (std::f64::consts::TAU * x).ln() + tail.ln()
    }
}

/// d'Eon's longitudinal scattering `M(θi, θo; v) = exp(-sin θi sin θo / v) I0(cos θi cos θo / v)
/// / (2 v sinh(1/v))`, normalised so that `∫ M cos θi dθi = 1` over `[-π/2, π/2]` (the
/// `-sin θi sin θo` pairs `θi` with the mirror longitude `-θo`).
fn longitudinal(sin_i: f32, cos_i: f32, sin_o: f32, cos_o: f32, v: f32) -> f64 {
    let v = v as f64;
    let inv_v = 1.0 / v;
    let a = cos_i as f64 * cos_o as f64 * inv_v;
    let b = sin_i as f64 * sin_o as f64 * inv_v;
    // 1 / (2 v sinh(1/v)) = exp(-1/v) / (v (1 - exp(-2/v))), kept in the exponent.
    let ln_norm = -inv_v - v.ln() - (-(-2.0 * inv_v).exp()).ln_1p();
    (ln_bessel_i0(a) - b + ln_norm).exp()
}

impl Bsdf for ChiangHair {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, u1: f32) -> Vec3 {
        let Some(su) = self.setup(rec.wi) else {
            return Vec3::ZERO;
        };
        // Lobe choice by luminance share, reusing u1 for the longitude as Cycles does.
        let mut p = 0;
        let mut r = u1;
        while p < 3 && r >= su.w[p] {
            r -= su.w[p];
            p += 1;
        }
        if su.w[p] <= 0.0 {
            return Vec3::ZERO;
        }
        let r = (r / su.w[p]).clamp(1e-5, 1.0);
        let v = if p < 3 {
            self.lobe_variance(p)
        } else {
            4.0 * self.v
        };
        // A von Mises–Fisher direction about the mirror longitude: its longitude has density
        // M(θ', θo; v) cos θ'.
        let fac = 1.0 + v * (r + (1.0 - r) * (-2.0 / v).exp()).ln();
        let mut sin_i = -fac * su.sin_o + cos_from_sin(fac) * (TAU * u.y).cos() * su.cos_o;
        let mut cos_i = cos_from_sin(sin_i);
        if p < 3 {
            // Tilted by d_p; past a pole the |cos| folds the longitude back.
            let (sd, cd) = self.tilt[p];
            let (s, c) = (sin_i * cd + cos_i * sd, (cos_i * cd - sin_i * sd).abs());
            sin_i = s;
            cos_i = c;
        }
        let phi = if p < 3 {
            su.delta[p] + sample_trimmed_logistic(u.x, self.s)
        } else {
            TAU * u.x
        };
        let (sp, cp) = (su.phi_o + phi).sin_cos();
        let wo = Vec3::new(sin_i, cos_i * cp, cos_i * sp);
        let (f, pdf) = self.value_and_density(&su, wo);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return Vec3::ZERO;
        }
        rec.wo = wo;
        rec.pdf = pdf;
        rec.eta = 1.0;
        rec.measure = Measure::SolidAngle;
        f / pdf
    }

    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        self.eval_and_pdf(rec).0
    }

    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        self.query(rec).1
    }

    fn is_delta(&self) -> bool {
        false
    }

    /// Cycles counts the hair closure among the glass closures: glossy where `wo` lies on the
    /// side of its `N = normalize(X × wi)`, transmission on the other (a plane through the
    /// tangent and `wi`, whatever the lobe).
    fn eval_split(&self, rec: &BsdfQueryRecord) -> [Vec3; 2] {
        let f = self.eval(rec);
        let (wi, wo) = (rec.wi, rec.wo);
        if wi.y * wo.z - wi.z * wo.y > 0.0 {
            [Vec3::ZERO, f]
        } else {
            [Vec3::ZERO, Vec3::ZERO]
        }
    }

    fn eval_and_pdf(&self, rec: &BsdfQueryRecord) -> (Vec3, f32) {
        let (f, pdf) = self.query(rec);
        let c = rec.wo.z.abs();
        // F carries the cosine; the integrator multiplies by |wo.z|.
        (if c > 0.0 { f / c } else { Vec3::ZERO }, pdf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Sampler;
    use crate::sampling::square_to_uniform_sphere;

    fn close(a: f32, b: f32, rel: f32) -> bool {
        (a - b).abs() <= rel * a.abs().max(b.abs()) + 1e-7
    }

    /// Melanin 0.8, redness 1, white tint: concentration `-ln 0.2 = 1.609438`, all of it
    /// pheomelanin, so σ_a = 1.609438 · (0.343, 0.733, 1.924).
    #[test]
    fn melanin_gives_cycles_sigma() {
        let s = sigma_a_from_melanin(0.8, 1.0, Vec3::ONE, 0.3, 0.0, 0.0);
        for (got, want) in s
            .to_array()
            .into_iter()
            .zip([0.552_037, 1.179_718, 3.096_559])
        {
            assert!(close(got, want, 1e-5), "{s}");
        }
        // Redness 0.25, melanin 0.5: m = ln 2; eumelanin 0.75 m, pheomelanin 0.25 m.
        let s = sigma_a_from_melanin(0.5, 0.25, Vec3::ONE, 0.3, 0.0, 0.0);
        let m = 2f32.ln();
        let want = Vec3::new(
            0.75 * m * 0.506 + 0.25 * m * 0.343,
            0.75 * m * 0.841 + 0.25 * m * 0.733,
            0.75 * m * 1.653 + 0.25 * m * 1.924,
        );
        assert!((s - want).abs().max_element() < 1e-5, "{s} vs {want}");
        // Random Color 1 at Random 1 scales melanin by 2 (0.4 -> 0.8); at Random 0.5 not at
        // all; a Random Color above 1 counts as 1.
        let a = sigma_a_from_melanin(0.4, 1.0, Vec3::ONE, 0.3, 1.0, 1.0);
        let b = sigma_a_from_melanin(0.8, 1.0, Vec3::ONE, 0.3, 0.0, 0.0);
        assert!((a - b).abs().max_element() < 1e-5);
        let c = sigma_a_from_melanin(0.4, 1.0, Vec3::ONE, 0.3, 5.0, 1.0);
        assert!((c - b).abs().max_element() < 1e-5);
        let d = sigma_a_from_melanin(0.8, 1.0, Vec3::ONE, 0.3, 1.0, 0.5);
        assert!((d - b).abs().max_element() < 1e-6);
        // Melanin at or past 1 saturates at -ln(1e-4).
        let e = sigma_a_from_melanin(1.0, 0.0, Vec3::ONE, 0.3, 0.0, 0.0);
        assert!(close(e.x, 9.210_34 * 0.506, 1e-5), "{e}");
        // A tint adds its direct-colouring σ_a.
        let t = Vec3::new(0.5, 1.0, 1.0);
        let f = sigma_a_from_melanin(0.8, 1.0, t, 0.3, 0.0, 0.0) - b;
        assert!((f - sigma_a_from_reflectance(t, 0.3)).abs().max_element() < 1e-6);
    }

    /// Colour 0.5 at radial roughness 0.3: `k(0.3) = 5.888415` (the polynomial by hand),
    /// σ_a = (ln 0.5 / k)² = 0.013_856_6; at radial roughness 1, `k = 3.375`.
    #[test]
    fn reflectance_gives_cycles_sigma() {
        assert!(close(albedo_roughness_scale(0.3), 5.888_415, 1e-6));
        assert!(close(albedo_roughness_scale(1.0), 3.375, 1e-6));
        let s = sigma_a_from_reflectance(Vec3::new(0.5, 1.0, 0.1), 0.3);
        assert!(close(s.x, 0.013_856_6, 1e-4), "{s}");
        assert_eq!(s.y, 0.0);
        assert!(close(s.z, (0.1f32.ln() / 5.888_415).powi(2), 1e-5));
        let s = sigma_a_from_reflectance(Vec3::new(0.5, 0.0, -1.0), 1.0);
        assert!(close(s.x, (0.5f32.ln() / 3.375).powi(2), 1e-5));
        assert!(
            s.y.is_infinite() && s.z.is_infinite(),
            "black absorbs everything"
        );
    }

    /// Random Roughness scales both roughnesses by `1 + 2 (random - ½) amount`, before the
    /// radial roughness sets the colour's σ_a; the absorption parametrization is left as is.
    #[test]
    fn random_input_scales_roughness_and_colour() {
        let node = PrincipledHair {
            color: HairColor::Reflectance(Vec3::splat(0.4)),
            roughness: 0.4,
            radial_roughness: 0.6,
            random_roughness: 0.5,
            random: 1.0,
            ..PrincipledHair::blender_default()
        };
        let (r, rr, sigma) = node.resolved();
        assert!(close(r, 0.6, 1e-6) && close(rr, 0.9, 1e-6), "{r} {rr}");
        assert_eq!(sigma, sigma_a_from_reflectance(Vec3::splat(0.4), rr));
        let low = PrincipledHair {
            random: 0.0,
            ..node
        }
        .resolved();
        assert!(close(low.0, 0.2, 1e-6) && close(low.1, 0.3, 1e-6));
        let abs = PrincipledHair {
            color: HairColor::Absorption(Vec3::new(0.1, 0.2, 0.3)),
            ..node
        };
        assert_eq!(abs.resolved().2, Vec3::new(0.1, 0.2, 0.3));
        // Cycles' defaults: roughness 0.3 -> v = (0.726·0.3 + 0.812·0.09 + 3.7·0.3²⁰)².
        let l = PrincipledHair::blender_default().lobe(0.0);
        assert!(close(l.v, (0.2178f32 + 0.07308).powi(2), 1e-5), "{}", l.v);
        assert_eq!(l.m0, l.v);
        let coated = PrincipledHair {
            coat: 0.5,
            ..PrincipledHair::blender_default()
        }
        .lobe(0.0);
        assert!(close(coated.m0, variance(0.15), 1e-6));
        assert!(close(
            l.s,
            (0.265 * 0.3 + 1.194 * 0.09) * (PI / 8.0).sqrt(),
            1e-5
        ));
    }

    /// `h` from world vectors: 0 through the axis, ±1 at the edges, and the sign that makes a
    /// mirrored set-up (Y → -Y) the mirrored lobe.
    #[test]
    fn offset_h_across_the_fibre() {
        let t = Vec3::X;
        let wi = Vec3::new(0.3, 0.0, 1.0).normalize();
        assert!(offset_h(t, wi, Vec3::Z).abs() < 1e-6);
        // wi × t = (0, 0.958, 0): the edge along +Y has h = 1.
        assert!(close(offset_h(t, wi, Vec3::Y), 1.0, 1e-6));
        assert!(close(offset_h(t, wi, -Vec3::Y), -1.0, 1e-6));
        let ng = Vec3::new(0.0, 0.6, 0.8);
        assert!(close(offset_h(t, wi, ng), 0.6, 1e-6));
        assert_eq!(offset_h(t, t, Vec3::Z), 0.0);
    }

    /// The lobe is symmetric about the fibre: turning the frame about X leaves `eval · |wo.z|`
    /// and `pdf` unchanged; mirroring Y with `h → -h` gives the same values.
    #[test]
    fn frame_about_the_tangent_is_free_and_mirror_flips_h() {
        let mut rng = Sampler::new(7, 0, 0);
        let b = ChiangHair::new(Vec3::new(0.2, 0.5, 1.0), 0.35, 0.5, 0.2, 1.55, 0.05, 0.4);
        let m = ChiangHair { h: -0.4, ..b };
        for _ in 0..2000 {
            let wi = square_to_uniform_sphere(rng.next_2d());
            let wo = square_to_uniform_sphere(rng.next_2d());
            let rot = |w: Vec3, a: f32| {
                let (s, c) = a.sin_cos();
                Vec3::new(w.x, c * w.y - s * w.z, s * w.y + c * w.z)
            };
            let r = BsdfQueryRecord::pair(wi, wo);
            let (f, p) = b.eval_and_pdf(&r);
            let a = 1.234;
            let r2 = BsdfQueryRecord::pair(rot(wi, a), rot(wo, a));
            let (f2, p2) = b.eval_and_pdf(&r2);
            let (g, g2) = (f * wo.z.abs(), f2 * r2.wo.z.abs());
            assert!(
                (g - g2).abs().max_element() <= 2e-3 * g.max_element() + 1e-6,
                "{g} {g2}"
            );
            assert!(close(p, p2, 2e-3), "{p} {p2}");
            let flip = |w: Vec3| Vec3::new(w.x, -w.y, w.z);
            let (fm, pm) = m.eval_and_pdf(&BsdfQueryRecord::pair(flip(wi), flip(wo)));
            assert!((f - fm).abs().max_element() <= 2e-3 * f.max_element() + 1e-6);
            assert!(close(p, pm, 2e-3));
        }
    }

    /// `∫ M(θi, θo; v) cos θi dθi = 1` from rough to very smooth (the accurate `I0`), and `M` is
    /// symmetric in `(θi, θo)`: the reciprocity the model keeps (its attenuations, `γt` and `h`
    /// belong to the viewer's side, so the whole lobe is not reciprocal).
    #[test]
    fn longitudinal_term_is_normalised_and_symmetric() {
        for v in [1e-4f32, 0.002, 0.03, 0.09, 0.11, 0.5, 2.0] {
            for theta_o in [0.0f32, 0.4, -1.0, 1.45] {
                let (so, co) = theta_o.sin_cos();
                let n = 200_000;
                let mut sum = 0.0f64;
                for k in 0..n {
                    let t = -PI / 2.0 + PI * (k as f32 + 0.5) / n as f32;
                    let (si, ci) = t.sin_cos();
                    sum += longitudinal(si, ci, so, co, v) * ci as f64;
                }
                let integral = sum * PI as f64 / n as f64;
                assert!(
                    (integral - 1.0).abs() < 2e-3,
                    "v {v} θo {theta_o}: {integral}"
                );
            }
        }
        let (a, b) = (0.3f32.sin_cos(), (-1.1f32).sin_cos());
        for v in [0.01f32, 0.2] {
            let x = longitudinal(a.0, a.1, b.0, b.1, v);
            let y = longitudinal(b.0, b.1, a.0, a.1, v);
            assert!((x - y).abs() <= 1e-9 * x.abs().max(1e-30));
        }
    }

    /// The trimmed logistic integrates to 1 over `[-π, π]` and its sampler inverts its CDF.
    #[test]
    fn trimmed_logistic_sampling_inverts_its_cdf() {
        for s in [0.002f32, 0.05, 0.3, 1.2] {
            let n = 400_000;
            let h = TAU / n as f32;
            let total: f32 = (0..n)
                .map(|k| trimmed_logistic(-PI + (k as f32 + 0.5) * h, s) * h)
                .sum();
            assert!((total - 1.0).abs() < 2e-3, "s {s}: {total}");
            for u in [0.01f32, 0.3, 0.5, 0.77, 0.99] {
                let x = sample_trimmed_logistic(u, s);
                let c = logistic_cdf(-PI, s);
                let cdf = (logistic_cdf(x, s) - c) / (1.0 - 2.0 * c);
                assert!((cdf - u).abs() < 1e-3, "s {s} u {u}: {cdf}");
            }
        }
    }

    /// Cycles' albedo estimate: white fibre `1 + F`, black fibre `F`.
    #[test]
    fn albedo_estimate_is_cycles() {
        let wi = Vec3::new(0.0, 0.0, 1.0);
        let f0 = ((1.55f32 - 1.0) / 2.55).powi(2);
        let b = ChiangHair::new(Vec3::ZERO, 0.3, 0.3, 0.0, 1.55, 0.0, 0.0);
        assert!(
            (b.albedo_estimate(wi) - Vec3::splat(1.0 + f0))
                .abs()
                .max_element()
                < 1e-5
        );
        let b = ChiangHair::new(Vec3::splat(f32::INFINITY), 0.3, 0.3, 0.0, 1.55, 0.0, 0.0);
        assert!(
            (b.albedo_estimate(wi) - Vec3::splat(f0))
                .abs()
                .max_element()
                < 1e-5
        );
    }
}
