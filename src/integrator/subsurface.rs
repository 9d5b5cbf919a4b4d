//! Subsurface scattering as Cycles' random walk (Chiang, Kutz and Burley 2016): a path that
//! picks a BSSRDF enters the object through a rough refraction, walks through a homogeneous
//! medium made from the surface colour and radius until it crosses the object's own surface
//! again, and goes on from there as from a white Lambertian surface (Cycles'
//! `subsurface_shader_data_setup`). The entry is not a bounce: the exit vertex keeps the
//! entry's path depth.
//!
//! Not modelled: Dwivedi guiding (variance only; every step here uses classic distance and
//! phase sampling), bump mapping at the exit point, the Random Walk (Skin) entry and radius
//! fit, and Christensen–Burley's disk sampling (both render as Random Walk).

use super::ShadingPoint;
use crate::bsdf::microfacet::sample_visible_normal;
use crate::bsdf::principled_specular_ior;
use crate::frame::Frame;
use crate::render_scene::{Ctx, Intersection, RenderScene};
use crate::sampling::square_to_uniform_sphere;
use crate::shading::{Closure, ClosureKind, Principled};
use glam::{Vec2, Vec3};

/// Most scattering events of one walk (Cycles' `BSSRDF_MAX_BOUNCES`); a longer walk is lost.
pub const MAX_STEPS: u32 = 256;

/// Radius (metres) below which a channel cannot be walked (Cycles' `BSSRDF_MIN_RADIUS`).
pub const MIN_RADIUS: f32 = 1e-8;

/// Blender 5.0's Cycles scales the Random Walk (and Christensen–Burley) radius by `1 / 4π`,
/// to look like its older falloffs.
pub const RADIUS_SCALE: f32 = 0.25 * std::f32::consts::FRAC_1_PI;

/// Single-scattering albedo below which the walk raises it and scales the weight down
/// instead, avoiding a jump between low albedos and none.
const MIN_ALPHA: f32 = 0.2;

/// After this many steps the walk goes on isotropically with the similarity-reduced
/// coefficients `σs* = σs (1 - g)`, `σt* = σt - σs + σs*`.
const SIMILARITY_STEPS: u32 = 9;

/// Throughput under which a walk stops (Cycles' `VOLUME_THROUGHPUT_EPSILON`).
const MIN_THROUGHPUT: f32 = 1e-6;

/// A random-walk BSSRDF's parameters, per channel where a vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bssrdf {
    /// The multiple-scattering albedo the surface should show, each channel in `[0, 1]`.
    pub albedo: Vec3,
    /// Reduced mean free path per channel, world units: Subsurface Radius × Scale ×
    /// [`RADIUS_SCALE`].
    pub radius: Vec3,
    /// Henyey–Greenstein `g` of the medium, in `[0, 0.9]`.
    pub anisotropy: f32,
    /// Index of refraction of the entry, in `[1.01, 3.8]`.
    pub ior: f32,
    /// GGX `α` of the entry refraction.
    pub alpha: f32,
}

impl Bssrdf {
    /// A BSSRDF with Cycles' clamps on its parameters; `None` when a channel's radius is too
    /// small to walk (the caller renders the closure as diffuse instead).
    pub fn new(albedo: Vec3, radius: Vec3, anisotropy: f32, ior: f32, alpha: f32) -> Option<Self> {
        if !radius.is_finite() || radius.min_element() < MIN_RADIUS {
            return None;
        }
        Some(Bssrdf {
            albedo: albedo.clamp(Vec3::ZERO, Vec3::ONE),
            radius,
            anisotropy: if anisotropy.is_finite() {
                anisotropy.clamp(0.0, 0.9)
            } else {
                0.0
            },
            ior: if ior.is_finite() {
                ior.clamp(1.01, 3.8)
            } else {
                1.4
            },
            alpha: if alpha.is_finite() {
                alpha.clamp(1e-4, 1.0)
            } else {
                1.0
            },
        })
    }
}

/// How a closure with subsurface scattering shares its samples between the walk and the
/// rest of it: the walk is taken with probability `p`, with weight `weight / p` (before the
/// attenuation of the layers above it), else `rest` renders with weight `1 / (1 - p)`.
#[derive(Clone, Copy, Debug)]
pub struct Split {
    pub p: f32,
    pub bssrdf: Bssrdf,
    /// The walk's weight divided by `p`.
    pub weight: Vec3,
    /// The closure without its subsurface share (for the Subsurface Scattering node, itself:
    /// never used, `p` is 1).
    pub rest: Closure,
    /// The Principled BSDF whose layers cover the walk; `None` for the node.
    pub layers: Option<Principled>,
}

/// Share of the Principled base's samples that walk, for subsurface weight `ss` and mean
/// albedo `a`: close to the walk's share of the base's energy, keeping some for the
/// specular layer, which is sampled only beside the walk.
fn walk_share(ss: f32, a: f32) -> f32 {
    ss * a / (a + 0.2)
}

/// The split of closure `c` when it scatters below the surface; `None` when it does not.
/// Where the integrator does not walk (`walks` false) or the radius is too small to walk,
/// `p` is 0 and `rest` renders it all as diffuse.
#[inline(always)]
pub fn split(c: &Closure, walks: bool) -> Option<Split> {
    // The common case, without a call.
    match &c.kind {
        ClosureKind::Principled(p) if p.cycles && p.subsurface_weight > 0.0 => split_cold(c, walks),
        ClosureKind::Subsurface { .. } => split_cold(c, walks),
        _ => None,
    }
}

#[inline(never)]
fn split_cold(c: &Closure, walks: bool) -> Option<Split> {
    let none = |rest: Closure| Split {
        p: 0.0,
        bssrdf: Bssrdf {
            albedo: Vec3::ZERO,
            radius: Vec3::ONE,
            anisotropy: 0.0,
            ior: 1.4,
            alpha: 1.0,
        },
        weight: Vec3::ZERO,
        rest,
        layers: None,
    };
    match &c.kind {
        ClosureKind::Principled(pr) if pr.cycles && pr.subsurface_weight > 0.0 => {
            let ss = pr.subsurface_weight.clamp(0.0, 1.0);
            let albedo = pr.base_color.clamp(Vec3::ZERO, Vec3::ONE);
            let a = albedo.element_sum() / 3.0;
            let bssrdf = Bssrdf::new(
                albedo,
                (pr.subsurface_radius * (pr.subsurface_scale * RADIUS_SCALE)).max(Vec3::ZERO),
                pr.subsurface_anisotropy,
                principled_specular_ior(pr.ior, pr.specular_level),
                pr.roughness.clamp(0.0, 1.0).powi(2),
            );
            let metallic = pr.metallic.clamp(0.0, 1.0);
            let base = (1.0 - metallic) * (1.0 - pr.transmission.clamp(0.0, 1.0));
            let (Some(bssrdf), true, true) = (bssrdf, walks, a > 0.0 && base > 0.0) else {
                // All of the base colour to the diffuse (or nothing, for a black base).
                let mut rest = *c;
                if let ClosureKind::Principled(q) = &mut rest.kind {
                    q.subsurface_weight = if a > 0.0 { 0.0 } else { ss };
                }
                return Some(none(rest));
            };
            let q = walk_share(ss, a);
            Some(Split {
                p: base * q,
                bssrdf,
                weight: c.weight * albedo * (ss / q),
                rest: *c,
                layers: Some(*pr),
            })
        }
        ClosureKind::Subsurface {
            albedo,
            radius,
            ior,
            roughness,
            anisotropy,
        } => {
            let bssrdf = Bssrdf::new(
                *albedo,
                *radius * RADIUS_SCALE,
                *anisotropy,
                *ior,
                roughness.clamp(0.0, 1.0),
            );
            match (bssrdf, walks) {
                (Some(bssrdf), true) => Some(Split {
                    p: 1.0,
                    bssrdf,
                    weight: c.weight,
                    rest: *c,
                    layers: None,
                }),
                _ => Some(none(*c)),
            }
        }
        _ => None,
    }
}

/// The single-scattering albedo `α` of a medium with Henyey–Greenstein `g ≥ 0` that shows the
/// multiple-scattering albedo `color` at its surface: Wrenninge, Villemin and Hery's fit
/// (*Path Traced Subsurface Scattering using Anisotropic Phase Functions and Non-Exponential
/// Free Flights*, Pixar 2017), `α = (1 - b) A atan(B c)^C + b D atan(E c)^F` with `b = c^¼`
/// and `A..F` polynomials (two of them exponentials of polynomials) in `g`, as Blender 5.0's
/// Cycles uses it; kept below 1.
pub fn single_scatter_albedo(color: f32, g: f32) -> f32 {
    let c = color.clamp(0.0, 1.0);
    // Horner form of Σ k_i g^i.
    let poly = |k: [f32; 8]| k.iter().rev().fold(0.0, |acc, &ki| acc * g + ki);
    let a = poly([
        1.8260524, -1.2845106, -1.7990463, 9.193933, -22.821558, 32.023487, -23.62648, 7.21067,
    ]);
    let b = 4.985112
        + 0.12735596
            * poly([
                0.0, 31.149158, -201.84702, 841.576, -2018.0929, 2731.7156, -1935.4142, 559.00905,
            ])
            .exp();
    let cc = poly([
        1.096861,
        -0.39470406,
        1.0525812,
        -8.839637,
        28.864323,
        -46.88029,
        38.540283,
        -12.718104,
    ]);
    let d = poly([
        0.4963102, 0.36014658, -2.151393, 17.88969, -55.2984, 82.06598, -58.5106, 15.84783,
    ]);
    let e = 4.231903
        + 0.0031060395
            * poly([
                0.0, 76.73163, -594.3568, 2448.8834, -5576.685, 7116.6016, -4763.545, 1303.5318,
            ])
            .exp();
    let f = poly([
        2.40603, -2.5181484, 9.184949, -79.21917, 259.08287, -403.6138, 302.85712, -87.43705,
    ]);
    let blend = c.powf(0.25);
    let alpha = (1.0 - blend) * a * (b * c).atan().powf(cc) + blend * d * (e * c).atan().powf(f);
    if alpha.is_finite() {
        alpha.clamp(0.0, 0.999999)
    } else {
        0.0
    }
}

/// The medium a walk goes through: extinction `σt` (per world unit) and single-scattering
/// albedo `α` per channel, and the factor on the entering throughput (the surface albedo,
/// which the scattering itself brings, divided out; lowered where `α` was raised).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    pub sigma_t: Vec3,
    pub alpha: Vec3,
    pub weight: Vec3,
    pub g: f32,
}

impl Medium {
    /// Cycles' coefficients for `b`: `σt = 1 / (radius (1 - g))` (the radius is the reduced
    /// mean free path), `α` from [`single_scatter_albedo`].
    pub fn new(b: &Bssrdf) -> Medium {
        let g = b.anisotropy;
        let mut alpha = Vec3::new(
            single_scatter_albedo(b.albedo.x, g),
            single_scatter_albedo(b.albedo.y, g),
            single_scatter_albedo(b.albedo.z, g),
        );
        let mut weight = Vec3::ONE;
        for i in 0..3 {
            weight[i] = if b.albedo[i] > 0.0 {
                1.0 / b.albedo[i]
            } else {
                0.0
            };
            if alpha[i] < MIN_ALPHA {
                weight[i] *= alpha[i] / MIN_ALPHA;
                alpha[i] = MIN_ALPHA;
            }
        }
        Medium {
            sigma_t: Vec3::ONE / (b.radius.max(Vec3::splat(1e-16)) * (1.0 - g)),
            alpha,
            weight,
            g,
        }
    }
}

/// A direction from a Henyey–Greenstein phase function with `g` (positive: forward) about the
/// unit direction `d` of travel.
fn sample_phase(d: Vec3, g: f32, u: Vec2) -> Vec3 {
    if g.abs() < 1e-3 {
        return square_to_uniform_sphere(u);
    }
    let k = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
    let cos = ((1.0 + g * g - k * k) / (2.0 * g)).clamp(-1.0, 1.0);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u.y;
    let (sin_phi, cos_phi) = crate::trig::sin_cos(phi);
    Frame::from_normal(d).to_world(Vec3::new(sin * cos_phi, sin * sin_phi, cos))
}

/// Walks from `p` along the unit `d` through `m`, starting with throughput `throughput` (the
/// path's, times [`Medium::weight`]); `boundary(o, d, tmax)` returns the object's surface
/// nearest along a ray inside `(0, tmax)` as `(t, hit)`. Each step picks a channel with
/// probability proportional to `throughput ⊙ α` and samples a free flight in it; the
/// channels' densities are combined with the balance heuristic (one-sample MIS), so the
/// throughput changes by `T(t) σs / Σ_c P(c) σt,c T_c(t)` per scattering and by
/// `T(t) / Σ_c P(c) T_c(t)` on leaving (`T(t) = exp(-σt t)`). Returns the exit hit, the
/// direction the walk left along, and the throughput there; `None` when it is lost.
pub fn walk<H>(
    m: &Medium,
    mut p: Vec3,
    mut d: Vec3,
    mut throughput: Vec3,
    mut rand: impl FnMut() -> f32,
    mut boundary: impl FnMut(Vec3, Vec3, f32) -> Option<(f32, H)>,
) -> Option<(H, Vec3, Vec3)> {
    let sigma_s = m.sigma_t * m.alpha;
    let sigma_s_star = sigma_s * (1.0 - m.g);
    let sigma_t_star = m.sigma_t - sigma_s + sigma_s_star;
    for step in 0..MAX_STEPS {
        let (sigma_t, sigma_s, g) = if step <= SIMILARITY_STEPS {
            (m.sigma_t, sigma_s, m.g)
        } else {
            (sigma_t_star, sigma_s_star, 0.0)
        };
        let (u_channel, u_t) = (rand(), rand());
        if step > 0 {
            d = sample_phase(d, g, Vec2::new(rand(), rand()));
        }
        let weights = (throughput * m.alpha).abs();
        let sum = weights.element_sum();
        let channel_pdf = if sum > 0.0 && sum.is_finite() {
            weights / sum
        } else {
            Vec3::splat(1.0 / 3.0)
        };
        let channel = if u_channel < channel_pdf.x {
            0
        } else if u_channel < channel_pdf.x + channel_pdf.y {
            1
        } else {
            2
        };
        let mut t = -(1.0 - u_t).ln() / sigma_t[channel];
        let hit = boundary(p, d, t);
        let left = hit.is_some();
        if let Some((th, _)) = &hit {
            t = *th;
        }
        let tr = (-sigma_t * t).exp();
        let pdf = if left { tr } else { sigma_t * tr };
        let denom = channel_pdf.dot(pdf);
        if denom.is_nan() || denom <= 0.0 {
            return None;
        }
        throughput *= if left { tr } else { sigma_s * tr } / denom;
        if let Some((_, h)) = hit {
            return throughput.is_finite().then_some((h, d, throughput));
        }
        p += t * d;
        if throughput.max_element() < MIN_THROUGHPUT || !throughput.is_finite() {
            return None;
        }
    }
    None
}

/// The direction into the surface a walk starts along: the unit `wi` towards the viewer
/// refracted into the medium (relative IOR `1 / ior`) by a GGX microfacet normal sampled
/// visible from `wi` (`α` of `b`), about the unit normal `n` on the viewer's side. Like
/// Cycles, it only shapes the direction (no Fresnel, no shadowing weight). `None` when `wi`
/// lies below `n`.
pub fn entry_direction(b: &Bssrdf, n: Vec3, wi: Vec3, u: Vec2) -> Option<Vec3> {
    let frame = Frame::from_normal(n);
    let wl = frame.to_local(wi);
    if wl.z <= 0.0 {
        return None;
    }
    let h = frame.to_world(sample_visible_normal(wl, b.alpha, u));
    let eta = 1.0 / b.ior;
    let cos_hi = h.dot(wi);
    let k = 1.0 - eta * eta * (1.0 - cos_hi * cos_hi);
    let root = k.max(0.0).sqrt().max(1e-7);
    Some((-eta * wi + (eta * cos_hi - root) * h).normalize())
}

/// [`scatter`], then the vertex the path goes on from: the exit point, its white diffuse
/// shading point, and the direction it is seen along from outside.
pub fn exit_vertex(
    scene: &RenderScene,
    ctx: &mut Ctx,
    its: &Intersection,
    d: Vec3,
    sp: &ShadingPoint,
    b: &Bssrdf,
    throughput: &mut Vec3,
) -> Option<(Intersection, ShadingPoint, Vec3)> {
    let (exit, dv) = scatter(scene, ctx, its, d, sp, b, throughput)?;
    Some((exit, ShadingPoint::subsurface_exit(&exit, dv), dv))
}

/// Scatters a path that chose the subsurface closure at `its` (seen along the unit `d`,
/// shading point `sp` whose frame normal is the BSSRDF's): samples the entry, walks inside
/// the object that was hit (its mesh and instance only) and returns the exit point and a
/// direction towards it from outside (as if a ray came in there), with `throughput` updated
/// to the walk's weight (the exit's white diffuse BSDF follows). `None`: the walk was lost.
pub fn scatter(
    scene: &RenderScene,
    ctx: &mut Ctx,
    its: &Intersection,
    d: Vec3,
    sp: &ShadingPoint,
    b: &Bssrdf,
    throughput: &mut Vec3,
) -> Option<(Intersection, Vec3)> {
    let wo = entry_direction(b, sp.frame.n, -d, ctx.sampler.next_2d())?;
    // Cycles: the entry must cross the true surface.
    let ng = if its.ng.dot(d) > 0.0 { -its.ng } else { its.ng };
    if ng.dot(wo) >= 0.0 {
        return None;
    }
    let m = Medium::new(b);
    // The walk starts on the surface itself (an offset origin would be a sizeable part of a
    // small radius's free path); its first segment steps over the entry surface instead.
    let mut tmin = 1e-6 * (1.0 + its.p.abs().max_element());
    let (mesh, instance) = (its.mesh, its.instance);
    let start = *throughput * sp.weight * m.weight;
    let sampler = std::cell::RefCell::new(&mut *ctx);
    let (exit, dir, w) = walk(
        &m,
        its.p,
        wo,
        start,
        || sampler.borrow_mut().sampler.next_1d(),
        |o, d, tmax| {
            let t0 = std::mem::take(&mut tmin);
            scene
                .intersect_local(&mut sampler.borrow_mut(), o, d, t0, tmax, mesh, instance)
                .map(|h| (h.t, h))
        },
    )?;
    *throughput = w;
    Some((exit, -dir))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Sampler;

    /// van de Hulst's half-space albedo under diffuse light for single-scattering albedo `a`
    /// and `g`: `(1 - s)(1 - 0.139 s) / (1 + 1.17 s)` with `s² = (1 - a) / (1 - g a)`.
    fn van_de_hulst(a: f32, g: f32) -> f32 {
        let s = ((1.0 - a) / (1.0 - g * a)).sqrt();
        (1.0 - s) * (1.0 - 0.139 * s) / (1.0 + 1.17 * s)
    }

    /// The fit's defining property: a half-space with the single-scattering albedo it gives
    /// reflects the colour asked for (here by van de Hulst's independent formula, to the two
    /// approximations' agreement); and it grows with the colour.
    #[test]
    fn single_scatter_albedo_gives_the_colour_back() {
        for g in [0.0, 0.3] {
            let mut last = -1.0;
            for i in 1..86 {
                let c = i as f32 / 100.0;
                let a = single_scatter_albedo(c, g);
                assert!(a > last && (0.0..1.0).contains(&a), "c {c} g {g}: {a}");
                last = a;
                let back = van_de_hulst(a, g);
                assert!((back - c).abs() < 0.025, "c {c} g {g}: α {a} gives {back}");
            }
        }
        assert!(single_scatter_albedo(0.0, 0.0) < 1e-4);
        assert!(single_scatter_albedo(1.0, 0.0) > 0.9999);
    }

    /// The unit sphere at the origin as a walk's boundary.
    fn sphere(o: Vec3, d: Vec3, tmax: f32) -> Option<(f32, Vec3)> {
        // Inside: one root of |o + t d| = 1 ahead.
        let b = o.dot(d);
        let c = o.length_squared() - 1.0;
        let t = -b + (b * b - c).max(0.0).sqrt();
        (t > 0.0 && t < tmax).then(|| (t, o + t * d))
    }

    /// Walks `n` times from the sphere's north pole straight down: mean and standard error of
    /// each channel's exit weight, and the number of exits.
    fn walks(b: &Bssrdf, n: usize, seed: u64) -> (Vec3, Vec3, usize, Vec<Vec3>) {
        let m = Medium::new(b);
        let mut rng = Sampler::new(seed, 0, 0);
        let (mut sum, mut sum2, mut exits) = (Vec3::ZERO, Vec3::ZERO, 0);
        let mut points = Vec::new();
        for _ in 0..n {
            let p = Vec3::new(0.0, 0.0, 1.0 - 1e-6);
            let r = walk(&m, p, -Vec3::Z, m.weight, || rng.next_1d(), sphere);
            if let Some((exit, _, w)) = r {
                sum += w;
                sum2 += w * w;
                exits += 1;
                points.push(exit);
            }
        }
        let mean = sum / n as f32;
        let var = sum2 / n as f32 - mean * mean;
        (mean, (var / n as f32).max(Vec3::ZERO).sqrt(), exits, points)
    }

    /// A white medium barely absorbs: what enters a closed sphere leaves it (mean exit weight
    /// 1 within a few standard errors, here a fraction of a percent), whatever the channels'
    /// radii and the phase function.
    #[test]
    fn white_sphere_conserves_energy() {
        for (radius, g) in [
            (Vec3::new(0.5, 0.2, 0.1), 0.0),
            (Vec3::splat(0.3), 0.6),
            (Vec3::new(0.05, 0.3, 1.5), -0.4),
        ] {
            let b = Bssrdf::new(Vec3::ONE, radius, g, 1.4, 0.25).unwrap();
            let (mean, se, exits, _) = walks(&b, 20_000, 3);
            for c in 0..3 {
                assert!(
                    (mean[c] - 1.0).abs() < 4.0 * se[c] + 0.01,
                    "radius {radius} g {g}: mean {mean} ± {se}, {exits} exits"
                );
            }
        }
    }

    /// An absorbing medium returns less than a white one, ordered by albedo (more than the
    /// half-space albedo: paths through a convex body are shorter), finite and
    /// non-negative; every exit lies on the sphere.
    #[test]
    fn absorbing_sphere_returns_less_in_order() {
        let b = Bssrdf::new(Vec3::new(0.9, 0.5, 0.1), Vec3::splat(0.2), 0.0, 1.4, 0.25).unwrap();
        let (mean, _, _, points) = walks(&b, 20_000, 4);
        // The weights have the surface albedo divided out: what comes back is `mean ⊙ albedo`.
        let e = mean * b.albedo;
        assert!(
            e.x < 0.995 && e.x > e.y && e.y > e.z && e.z > 0.0,
            "returned {e} (weights {mean})"
        );
        assert!(points.iter().all(|p| (p.length() - 1.0).abs() < 1e-4));
    }

    /// A half-space lit by diffuse light (cosine-distributed entry directions) shows the
    /// multiple-scattering albedo the inversion targets, within the accuracy of van de
    /// Hulst's fit (a few percent); a walk without absorption, or with the surface albedo
    /// not divided out, would be off by far more.
    #[test]
    fn half_space_shows_the_albedo_asked_for() {
        let albedo = Vec3::new(0.8, 0.5, 0.2);
        let b = Bssrdf::new(albedo, Vec3::new(0.1, 0.3, 0.6), 0.0, 1.4, 0.25).unwrap();
        let m = Medium::new(&b);
        let mut rng = Sampler::new(9, 0, 0);
        let n = 40_000;
        let mut sum = Vec3::ZERO;
        for _ in 0..n {
            let dl = crate::sampling::square_to_cosine_hemisphere(rng.next_2d());
            let plane = |o: Vec3, d: Vec3, tmax: f32| {
                // The surface z = 0 above a medium filling z < 0.
                let t = -o.z / d.z;
                (d.z > 0.0 && t < tmax).then_some((t, ()))
            };
            let p = Vec3::new(0.0, 0.0, -1e-6);
            if let Some((_, _, w)) = walk(&m, p, -dl, m.weight, || rng.next_1d(), plane) {
                sum += w;
            }
        }
        let got = sum / n as f32 * albedo;
        for c in 0..3 {
            assert!(
                (got[c] - albedo[c]).abs() < 0.04 * albedo[c] + 0.005,
                "albedo {albedo}: got {got}"
            );
        }
    }

    /// The same random numbers give the same walk.
    #[test]
    fn walks_are_deterministic() {
        let b = Bssrdf::new(Vec3::new(0.7, 0.6, 0.3), Vec3::splat(0.4), 0.2, 1.4, 0.25).unwrap();
        let a = walks(&b, 500, 11);
        let c = walks(&b, 500, 11);
        assert_eq!(a.0, c.0);
        assert_eq!(a.3, c.3);
    }

    /// Entry directions point into the surface and, for a smooth interface at normal
    /// incidence, straight down.
    #[test]
    fn entry_refracts_into_the_surface() {
        let b = Bssrdf::new(Vec3::ONE, Vec3::ONE, 0.0, 1.4, 0.3).unwrap();
        let mut rng = Sampler::new(2, 0, 0);
        for _ in 0..1000 {
            let wi = crate::sampling::square_to_cosine_hemisphere(rng.next_2d());
            let wo = entry_direction(&b, Vec3::Z, wi, rng.next_2d()).unwrap();
            assert!(
                (wo.length() - 1.0).abs() < 1e-4 && wo.z < 0.0,
                "{wi} -> {wo}"
            );
        }
        let smooth = Bssrdf::new(Vec3::ONE, Vec3::ONE, 0.0, 1.4, 1e-4).unwrap();
        let wo = entry_direction(&smooth, Vec3::Z, Vec3::Z, Vec2::splat(0.5)).unwrap();
        assert!((wo + Vec3::Z).length() < 1e-3, "{wo}");
        assert!(entry_direction(&b, Vec3::Z, -Vec3::Z, Vec2::splat(0.5)).is_none());
    }
}
