//! The GGX (Trowbridge–Reitz) microfacet distribution with visible-normal sampling
//! (Heitz 2018), and a rough conductor built on it.
//!
//! Conventions: `alpha` = perceptual roughness²; half vectors live in the local frame (+Z up).
//! Anisotropic variants (`*_aniso`) take `alpha_x` along local **+X, the tangent** and `alpha_y`
//! along +Y (the bitangent); the caller builds the shading frame from its tangent.
//! `D` is the normal distribution (per steradian of microfacet normals, projected area
//! normalised: ∫ D(h) cos θh dh = 1); `G1`/`G2` are Smith's masking and height-correlated
//! masking-shadowing functions.

use super::{Bsdf, BsdfQueryRecord, Measure, fresnel, tables};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// GGX normal distribution `D(h)`.
#[inline]
pub fn ggx_d(h: Vec3, alpha: f32) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let c2 = h.z * h.z;
    let d = c2 * (a2 - 1.0) + 1.0;
    a2 / (PI * d * d)
}

/// Smith's `Λ(w)` for GGX.
#[inline]
fn ggx_lambda(w: Vec3, alpha: f32) -> f32 {
    let c2 = w.z * w.z;
    if c2 <= 0.0 {
        return f32::INFINITY;
    }
    let t2 = (1.0 - c2).max(0.0) / c2;
    0.5 * (-1.0 + (1.0 + alpha * alpha * t2).sqrt())
}

/// Smith masking `G1(w)`.
#[inline]
pub fn ggx_g1(w: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(w, alpha))
}

/// Height-correlated masking-shadowing `G2(wi, wo)`.
#[inline]
pub fn ggx_g2(wi: Vec3, wo: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(wi, alpha) + ggx_lambda(wo, alpha))
}

/// Samples a microfacet normal visible from `wi` (which must have `wi.z > 0`) with density
/// `D_wi(h) = G1(wi) max(0, wi·h) D(h) / wi.z`.
#[inline]
pub fn sample_visible_normal(wi: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    let vh = Vec3::new(alpha * wi.x, alpha * wi.y, wi.z).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 {
        Vec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
    } else {
        Vec3::X
    };
    let t2 = vh.cross(t1);
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let (sin_phi, cos_phi) = crate::trig::sin_cos(phi);
    let p1 = r * cos_phi;
    let mut p2 = r * sin_phi;
    let s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(1e-7)).normalize()
}

/// Solid-angle density of the reflected direction `wo` when `h` is sampled with
/// [`sample_visible_normal`]: `G1(wi) D(h) / (4 wi.z)`.
#[inline]
pub fn reflection_pdf(wi: Vec3, wo: Vec3, alpha: f32) -> f32 {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    let h = (wi + wo).normalize();
    ggx_g1(wi, alpha) * ggx_d(h, alpha) / (4.0 * wi.z)
}

/// Samples a reflected direction: `(wo, pdf)`, or `None` when it falls below the horizon.
#[inline]
pub fn sample_reflection(wi: Vec3, alpha: f32, u: Vec2) -> Option<(Vec3, f32)> {
    let h = sample_visible_normal(wi, alpha, u);
    let wo = 2.0 * wi.dot(h) * h - wi;
    if wo.z <= 0.0 {
        return None;
    }
    let pdf = reflection_pdf(wi, wo, alpha);
    (pdf > 0.0 && pdf.is_finite()).then_some((wo, pdf))
}

/// Anisotropic GGX `D(h)`: `1 / (π αx αy (hx²/αx² + hy²/αy² + hz²)²)`.
#[inline]
pub fn ggx_d_aniso(h: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let (x, y) = (h.x / alpha_x, h.y / alpha_y);
    let l = x * x + y * y + h.z * h.z;
    1.0 / (PI * alpha_x * alpha_y * l * l)
}

/// Anisotropic Smith `Λ(w)`: `(sqrt(1 + (αx² wx² + αy² wy²) / wz²) - 1) / 2`.
#[inline]
pub fn ggx_lambda_aniso(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    let c2 = w.z * w.z;
    if c2 <= 0.0 {
        return f32::INFINITY;
    }
    let (x, y) = (alpha_x * w.x, alpha_y * w.y);
    0.5 * (-1.0 + (1.0 + (x * x + y * y) / c2).sqrt())
}

/// Anisotropic Smith masking `G1(w)`.
#[inline]
pub fn ggx_g1_aniso(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda_aniso(w, alpha_x, alpha_y))
}

/// Anisotropic height-correlated `G2(wi, wo)`.
#[inline]
pub fn ggx_g2_aniso(wi: Vec3, wo: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda_aniso(wi, alpha_x, alpha_y) + ggx_lambda_aniso(wo, alpha_x, alpha_y))
}

/// Visible-normal sampling for anisotropic GGX (Heitz 2018: stretch `wi`, sample the
/// hemisphere's projected area, unstretch). Density `G1(wi) max(0, wi·h) D(h) / wi.z`.
#[inline]
pub fn sample_visible_normal_aniso(wi: Vec3, alpha_x: f32, alpha_y: f32, u: Vec2) -> Vec3 {
    let vh = Vec3::new(alpha_x * wi.x, alpha_y * wi.y, wi.z).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 {
        Vec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
    } else {
        Vec3::X
    };
    let t2 = vh.cross(t1);
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let (sin_phi, cos_phi) = crate::trig::sin_cos(phi);
    let p1 = r * cos_phi;
    let mut p2 = r * sin_phi;
    let s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    Vec3::new(alpha_x * nh.x, alpha_y * nh.y, nh.z.max(1e-7)).normalize()
}

/// Beckmann normal distribution, anisotropic:
/// `exp(-(hx²/αx² + hy²/αy²) / hz²) / (π αx αy hz⁴)`.
// Out of line and cold: GGX lobes, the common case, keep their code as it was.
#[cold]
#[inline(never)]
pub fn beckmann_d(h: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let c2 = h.z * h.z;
    let (x, y) = (h.x / alpha_x, h.y / alpha_y);
    let e = (x * x + y * y) / c2;
    (-e).exp() / (PI * alpha_x * alpha_y * c2 * c2)
}

/// Smith's `Λ(w)` for Beckmann, exactly: with `a = |wz| / √(αx² wx² + αy² wy²)`
/// (`1 / (α tan θ)` along `w`'s azimuth), `Λ = (e^{-a²} / (a √π) - erfc(a)) / 2`. Either
/// side of the surface (refraction masks the transmitted direction too).
#[cold]
#[inline(never)]
pub fn beckmann_lambda(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if w.z == 0.0 {
        return f32::INFINITY;
    }
    let (x, y) = (alpha_x * w.x, alpha_y * w.y);
    let s = ((x * x + y * y) as f64).sqrt();
    if s <= 0.0 {
        return 0.0;
    }
    let a = w.z.abs() as f64 / s;
    if a > 6.0 {
        // Below f32's resolution.
        return 0.0;
    }
    (0.5 * ((-a * a).exp() / (a * std::f64::consts::PI.sqrt()) - libm::erfc(a))).max(0.0) as f32
}

/// Visible-normal sampling for anisotropic Beckmann (Heitz and d'Eon 2014): stretch `wi` to
/// the unit-roughness configuration, draw the slopes of the normals it sees, rotate them to
/// its azimuth and unstretch. Density `G1(wi) max(0, wi·h) D(h) / wi.z` with the exact
/// [`beckmann_lambda`].
#[cold]
#[inline(never)]
pub fn beckmann_sample_visible_normal(wi: Vec3, alpha_x: f32, alpha_y: f32, u: Vec2) -> Vec3 {
    let v = Vec3::new(alpha_x * wi.x, alpha_y * wi.y, wi.z).normalize();
    let sin_t = (v.x * v.x + v.y * v.y).sqrt();
    let (cos_p, sin_p) = if sin_t > 1e-7 {
        (v.x / sin_t, v.y / sin_t)
    } else {
        (1.0, 0.0)
    };
    let (sx, sy) = beckmann_visible_slopes(v.z as f64, sin_t as f64, u);
    let (rx, ry) = (cos_p * sx - sin_p * sy, sin_p * sx + cos_p * sy);
    Vec3::new(-rx * alpha_x, -ry * alpha_y, 1.0).normalize()
}

/// The slopes `(x, y)` of a unit-roughness Beckmann normal seen from `(sin θ, 0, cos θ)`: `y`
/// is Gaussian (`e^{-y²}/√π`), `x` has density `∝ (cot θ - x) e^{-x²}` below `cot θ`, whose
/// CDF `cot θ (1 + erf x) / 2 + e^{-x²} / (2√π)` is inverted numerically.
fn beckmann_visible_slopes(cos_t: f64, sin_t: f64, u: Vec2) -> (f32, f32) {
    let sqrt_pi = std::f64::consts::PI.sqrt();
    let (ux, uy) = (
        (u.x as f64).clamp(1e-9, 1.0 - 1e-9),
        (u.y as f64).clamp(1e-9, 1.0 - 1e-9),
    );
    let y = solve_increasing(
        |t| 0.5 * (1.0 + libm::erf(t)),
        |t| (-t * t).exp() / sqrt_pi,
        uy,
        -6.0,
        6.0,
    );
    if sin_t < 1e-7 {
        // Normal incidence: both slopes Gaussian.
        let x = solve_increasing(
            |t| 0.5 * (1.0 + libm::erf(t)),
            |t| (-t * t).exp() / sqrt_pi,
            ux,
            -6.0,
            6.0,
        );
        return (x as f32, y as f32);
    }
    let cot = cos_t / sin_t;
    let cdf = |t: f64| cot * 0.5 * (1.0 + libm::erf(t)) + (-t * t).exp() / (2.0 * sqrt_pi);
    let x = solve_increasing(
        cdf,
        |t| (cot - t).max(0.0) * (-t * t).exp() / sqrt_pi,
        ux * cdf(cot),
        -6.0,
        cot.min(6.0),
    );
    (x as f32, y as f32)
}

/// The `t` in `[lo, hi]` where the increasing `f` reaches `target`: Newton steps with the
/// derivative `df`, kept inside a shrinking bracket (bisection where a step leaves it).
fn solve_increasing(
    f: impl Fn(f64) -> f64,
    df: impl Fn(f64) -> f64,
    target: f64,
    mut lo: f64,
    mut hi: f64,
) -> f64 {
    let mut t = 0.0f64.clamp(lo, hi);
    for _ in 0..60 {
        let e = f(t) - target;
        if e.abs() < 1e-12 {
            break;
        }
        if e > 0.0 {
            hi = t;
        } else {
            lo = t;
        }
        let d = df(t);
        let next = if d > 0.0 { t - e / d } else { f64::NAN };
        t = if next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo < 1e-12 {
            break;
        }
    }
    t
}

/// GGX roughness, isotropic or not, with the functions that dispatch on it. Isotropic lobes
/// call exactly the isotropic functions above (bit-identical to code that uses them directly).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roughness {
    /// Along local +X (the tangent).
    pub alpha_x: f32,
    /// Along local +Y.
    pub alpha_y: f32,
}

impl Roughness {
    /// Alphas are clamped to `[DELTA_ALPHA, 1]` (Cycles' `bsdf_microfacet_ggx_setup` saturates
    /// both, so e.g. the Glossy BSDF's `r² / (1 - a)` stops at 1); NaN becomes `DELTA_ALPHA`.
    pub fn new(alpha_x: f32, alpha_y: f32) -> Self {
        let fix = |a: f32| a.clamp(super::DELTA_ALPHA, 1.0);
        let fix = |a: f32| {
            if a.is_nan() {
                super::DELTA_ALPHA
            } else {
                fix(a)
            }
        };
        Roughness {
            alpha_x: fix(alpha_x),
            alpha_y: fix(alpha_y),
        }
    }

    pub fn isotropic(alpha: f32) -> Self {
        Roughness::new(alpha, alpha)
    }

    #[inline]
    pub fn is_isotropic(&self) -> bool {
        self.alpha_x == self.alpha_y
    }

    #[inline]
    pub fn d(&self, h: Vec3) -> f32 {
        if self.is_isotropic() {
            ggx_d(h, self.alpha_x)
        } else {
            ggx_d_aniso(h, self.alpha_x, self.alpha_y)
        }
    }

    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        if self.is_isotropic() {
            ggx_g1(w, self.alpha_x)
        } else {
            ggx_g1_aniso(w, self.alpha_x, self.alpha_y)
        }
    }

    #[inline]
    pub fn g2(&self, wi: Vec3, wo: Vec3) -> f32 {
        if self.is_isotropic() {
            ggx_g2(wi, wo, self.alpha_x)
        } else {
            ggx_g2_aniso(wi, wo, self.alpha_x, self.alpha_y)
        }
    }

    /// A visible normal for `wi` (`wi.z > 0`).
    #[inline]
    pub fn sample_visible_normal(&self, wi: Vec3, u: Vec2) -> Vec3 {
        if self.is_isotropic() {
            sample_visible_normal(wi, self.alpha_x, u)
        } else {
            sample_visible_normal_aniso(wi, self.alpha_x, self.alpha_y, u)
        }
    }

    /// Density of the visible normal `h`: `G1(wi) max(0, wi·h) D(h) / wi.z`.
    #[inline]
    pub fn visible_normal_pdf(&self, wi: Vec3, h: Vec3) -> f32 {
        if wi.z <= 0.0 {
            return 0.0;
        }
        self.g1(wi) * wi.dot(h).max(0.0) * self.d(h) / wi.z
    }

    /// Solid-angle density of the reflected `wo`: `G1(wi) D(h) / (4 wi.z)`.
    #[inline]
    pub fn reflection_pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        if self.is_isotropic() {
            return reflection_pdf(wi, wo, self.alpha_x);
        }
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let h = (wi + wo).normalize();
        self.g1(wi) * self.d(h) / (4.0 * wi.z)
    }

    /// A reflected direction `(wo, pdf)`, or `None` below the horizon.
    #[inline]
    pub fn sample_reflection(&self, wi: Vec3, u: Vec2) -> Option<(Vec3, f32)> {
        if self.is_isotropic() {
            return sample_reflection(wi, self.alpha_x, u);
        }
        let h = self.sample_visible_normal(wi, u);
        let wo = 2.0 * wi.dot(h) * h - wi;
        if wo.z <= 0.0 {
            return None;
        }
        let pdf = self.reflection_pdf(wi, wo);
        (pdf > 0.0 && pdf.is_finite()).then_some((wo, pdf))
    }
}

/// A roughness read with the GGX or the Beckmann distribution: the view the lobes query (the
/// lobes keep the flag beside their [`Roughness`], which stays the size GGX needs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Distribution {
    pub roughness: Roughness,
    /// Beckmann (Blender's Glossy, Glass and Refraction BSDFs offer it) instead of GGX.
    pub beckmann: bool,
}

impl Distribution {
    #[inline]
    pub fn d(&self, h: Vec3) -> f32 {
        let r = &self.roughness;
        if self.beckmann {
            return beckmann_d(h, r.alpha_x, r.alpha_y);
        }
        r.d(h)
    }

    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        let r = &self.roughness;
        if self.beckmann {
            return 1.0 / (1.0 + beckmann_lambda(w, r.alpha_x, r.alpha_y));
        }
        r.g1(w)
    }

    #[inline]
    pub fn g2(&self, wi: Vec3, wo: Vec3) -> f32 {
        let r = &self.roughness;
        if self.beckmann {
            let (ax, ay) = (r.alpha_x, r.alpha_y);
            return 1.0 / (1.0 + beckmann_lambda(wi, ax, ay) + beckmann_lambda(wo, ax, ay));
        }
        r.g2(wi, wo)
    }

    /// A visible normal for `wi` (`wi.z > 0`).
    #[inline]
    pub fn sample_visible_normal(&self, wi: Vec3, u: Vec2) -> Vec3 {
        let r = &self.roughness;
        if self.beckmann {
            return beckmann_sample_visible_normal(wi, r.alpha_x, r.alpha_y, u);
        }
        r.sample_visible_normal(wi, u)
    }

    /// Density of the visible normal `h`: `G1(wi) max(0, wi·h) D(h) / wi.z`.
    #[inline]
    pub fn visible_normal_pdf(&self, wi: Vec3, h: Vec3) -> f32 {
        if wi.z <= 0.0 {
            return 0.0;
        }
        self.g1(wi) * wi.dot(h).max(0.0) * self.d(h) / wi.z
    }

    /// Solid-angle density of the reflected `wo`: `G1(wi) D(h) / (4 wi.z)`.
    #[inline]
    pub fn reflection_pdf(&self, wi: Vec3, wo: Vec3) -> f32 {
        if !self.beckmann {
            return self.roughness.reflection_pdf(wi, wo);
        }
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let h = (wi + wo).normalize();
        self.g1(wi) * self.d(h) / (4.0 * wi.z)
    }

    /// A reflected direction `(wo, pdf)`, or `None` below the horizon.
    #[inline]
    pub fn sample_reflection(&self, wi: Vec3, u: Vec2) -> Option<(Vec3, f32)> {
        if !self.beckmann {
            return self.roughness.sample_reflection(wi, u);
        }
        let h = self.sample_visible_normal(wi, u);
        let wo = 2.0 * wi.dot(h) * h - wi;
        if wo.z <= 0.0 {
            return None;
        }
        let pdf = self.reflection_pdf(wi, wo);
        (pdf > 0.0 && pdf.is_finite()).then_some((wo, pdf))
    }
}

/// Cycles' anisotropy mappings from a roughness `r` (alpha = r²) and an anisotropy `a`
/// to `(alpha_x, alpha_y)`, alpha_x along the tangent.
pub mod anisotropy {
    /// Principled BSDF and the Metallic BSDF (`svm/closure.h`): `a` in `[0, 1]`,
    /// `aspect = sqrt(1 - 0.9 a)`, `alpha_x = r² / aspect`, `alpha_y = r² · aspect`.
    pub fn principled(roughness: f32, anisotropic: f32) -> (f32, f32) {
        let r = roughness.clamp(0.0, 1.0);
        let alpha = r * r;
        let a = anisotropic.clamp(0.0, 1.0);
        if a <= 0.0 {
            return (alpha, alpha);
        }
        let aspect = (1.0 - 0.9 * a).sqrt();
        (alpha / aspect, alpha * aspect)
    }

    /// Glossy BSDF (`svm/closure.h`): `a` clamped to `[-0.99, 0.99]`; for `a < 0`
    /// `(r²/(1+a), r²(1+a))`, else `(r²(1-a), r²/(1-a))`; isotropic for `|a| ≤ 1e-4`.
    pub fn glossy(roughness: f32, anisotropy: f32) -> (f32, f32) {
        let r = roughness.clamp(0.0, 1.0);
        let alpha = r * r;
        let a = anisotropy.clamp(-0.99, 0.99);
        if a.abs() <= 1e-4 {
            (alpha, alpha)
        } else if a < 0.0 {
            (alpha / (1.0 + a), alpha * (1.0 + a))
        } else {
            (alpha * (1.0 - a), alpha / (1.0 - a))
        }
    }
}

/// The reflectance model of a [`RoughConductor`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConductorFresnel {
    /// Schlick with `F0` (glTF metals).
    Schlick(Vec3),
    /// A constant colour, no Fresnel: Blender's Glossy BSDF (Cycles' GGX glossy closure has
    /// `fresnel_type = NONE` and the colour as the closure weight).
    Constant(Vec3),
    /// A reflectance of one, the colour `tint` being in the closure's weight (Blender's
    /// Glossy BSDF): only the energy compensation sees `tint`, as its `F_ss`.
    Weighted(Vec3),
    /// Cycles' F82-tint (Principled metallic and the Metallic BSDF's "F82" mode):
    /// `F = Schlick(F0) - b cos (1 - cos)^6`, clamped to `[0, 1]`.
    F82 { f0: Vec3, b: Vec3 },
}

impl ConductorFresnel {
    /// F82-tint from the base colour (`F0`) and the edge tint (Principled: Specular Tint;
    /// Metallic BSDF: Edge Tint), both clamped to `[0, 1]` as Cycles does. With a white tint
    /// this is exactly Schlick.
    pub fn f82_tint(f0: Vec3, tint: Vec3) -> Self {
        let f0 = f0.clamp(Vec3::ZERO, Vec3::ONE);
        let tint = tint.clamp(Vec3::ZERO, Vec3::ONE);
        let b = if tint == Vec3::ONE {
            Vec3::ZERO
        } else {
            // Solve F82Tint(1/7) = Schlick(1/7) · tint for b (Cycles' fresnel_f82tint_B).
            let f: f32 = 6.0 / 7.0;
            let f5 = f.powi(5);
            let schlick = f0 + (Vec3::ONE - f0) * f5;
            schlick * (7.0 / (f5 * f)) * (Vec3::ONE - tint)
        };
        ConductorFresnel::F82 { f0, b }
    }

    /// The average single-scattering reflectance `F_ss` Cycles uses for the multiple-bounce
    /// Fresnel: `mix(F0, 1, 1/21) - b/126` (exact for Schlick/F82), or the constant colour.
    pub fn fss(&self) -> Vec3 {
        match *self {
            ConductorFresnel::Schlick(f0) => f0 + (Vec3::ONE - f0) / 21.0,
            ConductorFresnel::Constant(c) | ConductorFresnel::Weighted(c) => c,
            ConductorFresnel::F82 { f0, b } => f0 + (Vec3::ONE - f0) / 21.0 - b / 126.0,
        }
    }

    /// The reflectance at `cos = wi·h`.
    #[inline]
    pub fn eval(&self, cos: f32) -> Vec3 {
        match *self {
            ConductorFresnel::Schlick(f0) => fresnel::schlick(f0, cos),
            ConductorFresnel::Constant(c) => c,
            ConductorFresnel::Weighted(_) => Vec3::ONE,
            ConductorFresnel::F82 { f0, b } => {
                let s = (1.0 - cos).clamp(0.0, 1.0);
                let s5 = s * s * s * s * s;
                let schlick = f0 + (Vec3::ONE - f0) * s5;
                (schlick - b * (cos * s5 * s)).clamp(Vec3::ZERO, Vec3::ONE)
            }
        }
    }
}

/// A rough conductor: `f = F(wi·h) D(h) G2 / (4 cos θi cos θo)` with GGX, isotropic or
/// anisotropic (alpha_x along local +X, the tangent), and the reflectance of
/// [`ConductorFresnel`]. Reflects on the +Z side only.
///
/// With `multiscatter` (Cycles' "Multiscatter GGX", the Principled default), `f` is scaled by
/// [`tables::multiscatter_factor`]`(E(μ), E_avg, F_ss)`, Cycles' energy compensation of the
/// single-scattering loss (the sampled directions and the pdf are unchanged).
#[derive(Clone, Copy, Debug)]
pub struct RoughConductor {
    pub roughness: Roughness,
    /// The roughness the lobe was set up with, where its energy compensation is looked up:
    /// `roughness` unless Filter Glossy raised it ([`RoughConductor::blurred`]).
    pub setup_roughness: Roughness,
    pub fresnel: ConductorFresnel,
    pub multiscatter: bool,
    /// The Beckmann distribution instead of GGX.
    pub beckmann: bool,
}

impl RoughConductor {
    /// Isotropic GGX with Schlick `F0` (glTF's metal).
    pub fn new(f0: Vec3, alpha: f32) -> Self {
        let roughness = Roughness::isotropic(alpha);
        RoughConductor {
            roughness,
            setup_roughness: roughness,
            fresnel: ConductorFresnel::Schlick(f0),
            multiscatter: false,
            beckmann: false,
        }
    }

    /// Any roughness and reflectance model; alphas below [`super::DELTA_ALPHA`] are raised to it.
    pub fn with(alpha_x: f32, alpha_y: f32, fresnel: ConductorFresnel) -> Self {
        let roughness = Roughness::new(alpha_x, alpha_y);
        RoughConductor {
            roughness,
            setup_roughness: roughness,
            fresnel,
            multiscatter: false,
            beckmann: false,
        }
    }

    /// The same lobe with Cycles' Multiscatter GGX energy compensation.
    pub fn multiscatter(self) -> Self {
        RoughConductor {
            multiscatter: true,
            ..self
        }
    }

    /// The same lobe with its alphas raised to at least `blur` (Cycles' Filter Glossy,
    /// `bsdf_microfacet_blur`; `blur <= 0` changes nothing). The energy compensation stays
    /// that of the roughness the lobe was set up with, as Cycles does not recompute it.
    #[inline]
    /// The same lobe with the Beckmann distribution (`on`) instead of GGX.
    pub fn with_beckmann(self, on: bool) -> Self {
        RoughConductor {
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

    pub fn blurred(self, blur: f32) -> Self {
        if blur <= 0.0 {
            return self;
        }
        let r = self.roughness;
        RoughConductor {
            roughness: Roughness::new(r.alpha_x.max(blur), r.alpha_y.max(blur)),
            ..self
        }
    }

    /// The energy-compensation factor for this `wi` (1 without `multiscatter`).
    #[inline]
    pub fn energy_factor(&self, wi: Vec3) -> Vec3 {
        if !self.multiscatter {
            return Vec3::ONE;
        }
        let r = &self.setup_roughness;
        let (e, e_avg) = tables::ggx_e(r.alpha_x, r.alpha_y, wi.z);
        tables::multiscatter_factor(e, e_avg, self.fresnel.fss())
    }

    /// Blender's Glossy BSDF (distribution GGX): `color` = Color input, `(alpha_x, alpha_y)`
    /// from [`anisotropy::glossy`]`(Roughness, Anisotropy)`.
    pub fn glossy(color: Vec3, alpha_x: f32, alpha_y: f32) -> Self {
        RoughConductor::with(alpha_x, alpha_y, ConductorFresnel::Constant(color))
    }

    /// Principled BSDF's metallic lobe (Cycles 4.x/5.x): F82-tint with `F0` = Base Color and
    /// the edge tint = Specular Tint; `(alpha_x, alpha_y)` from
    /// [`anisotropy::principled`]`(Roughness, Anisotropic)`.
    pub fn f82(base_color: Vec3, specular_tint: Vec3, alpha_x: f32, alpha_y: f32) -> Self {
        RoughConductor::with(
            alpha_x,
            alpha_y,
            ConductorFresnel::f82_tint(base_color, specular_tint),
        )
    }
}

impl Bsdf for RoughConductor {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, _u1: f32) -> Vec3 {
        if rec.wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let a = self.distribution();
        let Some((wo, pdf)) = a.sample_reflection(rec.wi, u) else {
            return Vec3::ZERO;
        };
        rec.wo = wo;
        rec.pdf = pdf;
        rec.eta = 1.0;
        rec.measure = Measure::SolidAngle;
        let h = (rec.wi + wo).normalize();
        // f cos / pdf = F G2 / G1(wi)
        let w = self.fresnel.eval(rec.wi.dot(h)) * a.g2(rec.wi, wo) / a.g1(rec.wi);
        if self.multiscatter {
            w * self.energy_factor(rec.wi)
        } else {
            w
        }
    }

    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        let (wi, wo) = (rec.wi, rec.wo);
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Vec3::ZERO;
        }
        let h = (wi + wo).normalize();
        let a = self.distribution();
        let f = self.fresnel.eval(wi.dot(h)) * a.d(h) * a.g2(wi, wo) / (4.0 * wi.z * wo.z);
        if self.multiscatter {
            f * self.energy_factor(wi)
        } else {
            f
        }
    }

    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        self.distribution().reflection_pdf(rec.wi, rec.wo)
    }

    fn is_delta(&self) -> bool {
        false
    }
}
