//! White-furnace tests: the directional albedo `E(wi) = ∫ f |cos θo| dωo` of every lobe under
//! uniform white illumination, estimated two independent ways — the mean sample weight (Monte
//! Carlo, what the integrators compute) and a deterministic cubature of `eval` over the sphere —
//! which must agree, and must not exceed 1 (energy conservation) for white parameters.
//!
//! Bounds: `E ≤ 1 + 4σ + 1e-3` for every lobe; the two estimates agree within `4σ + 3e-3`
//! (`σ` the Monte Carlo standard error; 3e-3 covers the cubature of peaked lobes). Exact
//! values: translucent `E = colour` (every weight equals it), sheen `E = albedo(μ) · colour`.
//! Single-scattering GGX loses energy: a rough dielectric's `E` (reflection + refraction, white)
//! is `1 - loss`, where `loss` is the share of microfacet paths masked or scattered to the wrong
//! side; it vanishes as `alpha → 0` (asserted `E > 0.99` at alpha 0.05 for `θi ≤ 30°`), and
//! is bounded above by the grazing-free perfect-mirror loss (`E_glass ≥ E_mirror(alpha) - 0.01`
//! for `η > 1`, entering, `θi ≤ 60°`, measured against [`RoughConductor::glossy`] with F = 1).
//! Cycles' Multiscatter GGX compensation makes white lobes (mirror, glass) lossless: their albedo
//! is `1` within the accuracy of the regenerated tables and their interpolation (`± 0.012`;
//! `± 0.015` at 89° for the mirror, `± 0.02` at 85° for glass, whose tables have only 16 μ
//! nodes, and at 89° only "more than single scattering, at most 1.02" for glass: `E`
//! changes fastest there, between the μ nodes Cycles' tables share;
//! anisotropic lobes, which Cycles compensates with the isotropic table at `(αx αy)^(1/4)`, only
//! gain energy and end below 1.06: at αx = 1, αy = 0.3 only 0.50 → 0.78).
//! Layering follows Cycles: the base is attenuated by a tabulated *estimate* of the top lobe's
//! albedo, not by its exact albedo, so a white stack may exceed 1 slightly: allowed `+ 0.01`,
//! `+ 0.035` at grazing incidence (θ ≥ 85°, where the tables are coarsest).

#[path = "common/chi2.rs"]
mod chi2_common;

use chi2_common::DirGrid;
use glam::Vec3;
use tesela::bsdf::microfacet::anisotropy;
use tesela::bsdf::{
    Bsdf, BsdfQueryRecord, ChiangHair, Coat, Diffuse, Layered, Measure, RoughConductor,
    RoughDielectric, Sheen, Translucent, principled_specular_ior,
};
use tesela::sampler::Sampler;

const M: usize = 200_000;

fn dir(theta_deg: f32, below: bool) -> Vec3 {
    let t = theta_deg.to_radians();
    let w = Vec3::new(t.sin() * 0.3f32.cos(), t.sin() * 0.3f32.sin(), t.cos()).normalize();
    if below { Vec3::new(w.x, w.y, -w.z) } else { w }
}

/// `(mean weight, standard error, discrete share)` of the first channel over `M` samples.
fn mc_albedo(b: &dyn Bsdf, wi: Vec3, seed: u64) -> (f64, f64, f64) {
    let mut rng = Sampler::new(seed, 0, 0);
    let (mut s, mut s2, mut disc) = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..M {
        let mut rec = BsdfQueryRecord::new(wi);
        let w = b.sample(&mut rec, rng.next_2d(), rng.next_1d()).x as f64;
        s += w;
        s2 += w * w;
        if w > 0.0 && rec.measure == Measure::Discrete {
            disc += w;
        }
    }
    let m = s / M as f64;
    let var = (s2 / M as f64 - m * m).max(0.0);
    (m, (var / M as f64).sqrt(), disc / M as f64)
}

/// `∫ f |cos| dωo` of the non-delta part by adaptive cubature over the sphere, on a grid whose
/// rows are packed around `axis` (the lobe's peak).
fn cubature_albedo(b: &dyn Bsdf, wi: Vec3, axis: Vec3) -> f64 {
    let grid = DirGrid::new(axis, std::f64::consts::PI, 2.0, 64, 64);
    let m = 1e6;
    grid.expected(
        &|wo| (b.eval(&BsdfQueryRecord::pair(wi, wo)).x * wo.z.abs()) as f64,
        m,
    )
    .iter()
    .sum::<f64>()
        / m
}

/// Checks the bounds of the module documentation; returns the Monte Carlo albedo.
fn furnace(name: &str, b: &dyn Bsdf, wi: Vec3, axis: Vec3, seed: u64) -> f64 {
    furnace_within(name, b, wi, axis, seed, 1e-3)
}

/// [`furnace`] allowing the albedo to exceed 1 by `excess` (for Cycles' estimate-based layering).
fn furnace_within(name: &str, b: &dyn Bsdf, wi: Vec3, axis: Vec3, seed: u64, excess: f64) -> f64 {
    let (e, se, disc) = mc_albedo(b, wi, seed);
    let c = cubature_albedo(b, wi, axis) + disc;
    println!("{name}: E = {e:.5} ± {se:.5} (cubature + discrete {c:.5})");
    assert!(e <= 1.0 + 4.0 * se + excess, "{name}: albedo {e} > 1");
    assert!(
        (e - c).abs() <= 4.0 * se + 3e-3,
        "{name}: Monte Carlo {e} ± {se} vs cubature {c}"
    );
    e
}

fn mirror(w: Vec3) -> Vec3 {
    Vec3::new(-w.x, -w.y, w.z)
}

fn refracted(wi: Vec3, ior: f32) -> Vec3 {
    let eta = if wi.z < 0.0 { 1.0 / ior } else { ior };
    let sin2 = (1.0 - wi.z * wi.z) / (eta * eta);
    if sin2 >= 1.0 {
        return mirror(wi);
    }
    Vec3::new(
        -wi.x / eta,
        -wi.y / eta,
        -wi.z.signum() * (1.0 - sin2).sqrt(),
    )
    .normalize()
}

/// The Monte Carlo albedo alone, `≤ 1 + 4σ + 1e-3` unless compensated (the lobes' eval is
/// checked against their weights by `tests/sample_pdf.rs`).
fn mc_only(name: &str, b: &dyn Bsdf, wi: Vec3, _axis: Vec3, seed: u64) -> f64 {
    let (e, se, _) = mc_albedo(b, wi, seed);
    println!("{name}: E = {e:.5} ± {se:.5}");
    e
}

fn layering_excess(theta: f32) -> f64 {
    if theta >= 85.0 { 0.035 } else { 0.01 }
}

const THETAS: [f32; 6] = [0.0, 30.0, 60.0, 75.0, 85.0, 89.0];

#[test]
fn furnace_conductors() {
    let mut seed = 10;
    for (r, a) in [(0.2f32, 0.0f32), (0.5, 0.8), (0.8, -0.5), (1.0, 0.0)] {
        let (gx, gy) = anisotropy::glossy(r, a);
        let (px, py) = anisotropy::principled(r, a.abs());
        let lobes = [
            ("Glossy", RoughConductor::glossy(Vec3::ONE, gx, gy)),
            (
                "F82 white",
                RoughConductor::f82(Vec3::ONE, Vec3::ONE, px, py),
            ),
            (
                "F82 tinted",
                RoughConductor::f82(Vec3::ONE, Vec3::splat(0.3), px, py),
            ),
        ];
        for (name, b) in &lobes {
            for &t in &THETAS {
                seed += 1;
                let wi = dir(t, false);
                furnace(
                    &format!("{name} r={r} a={a} θ={t}"),
                    b,
                    wi,
                    mirror(wi),
                    seed,
                );
            }
        }
    }
}

#[test]
fn furnace_rough_dielectric() {
    let mut seed = 1000;
    for ior in [1.5f32, 2.4, 0.8] {
        for alpha in [0.05f32, 0.3, 1.0] {
            let glass = RoughDielectric::glass(Vec3::ONE, ior, alpha);
            let refr = RoughDielectric::refraction(Vec3::ONE, ior, alpha);
            let refl = RoughDielectric::reflection(Vec3::ONE, ior, alpha, alpha);
            let mirror_lobe = RoughConductor::glossy(Vec3::ONE, alpha, alpha);
            for t in [0.0f32, 30.0, 60.0, 85.0, 89.0] {
                for below in [false, true] {
                    let wi = dir(t, below);
                    let axis = refracted(wi, ior);
                    seed += 1;
                    let name = format!("ior={ior} alpha={alpha} θ={t} below={below}");
                    let e = furnace(&format!("Glass {name}"), &glass, wi, axis, seed);
                    // The single-lobe modes: Monte Carlo only (their eval is checked against
                    // their weights in tests/sample_pdf.rs).
                    let er = mc_only(&format!("Refraction {name}"), &refr, wi, axis, seed);
                    let el = mc_only(&format!("Reflection {name}"), &refl, wi, mirror(wi), seed);
                    // The reflection-only lobe is the glass's reflection part alone.
                    assert!(el <= e + 2e-3, "{name}: R-only {el} vs glass {e}");
                    assert!(er <= 1.0 + 1e-3);
                    if alpha == 0.05 && t <= 30.0 {
                        assert!(e > 0.99, "{name}: smooth-limit albedo {e}");
                    }
                    let eff = if below { 1.0 / ior } else { ior };
                    if eff > 1.0 && t <= 60.0 {
                        let (em, _, _) = mc_albedo(&mirror_lobe, dir(t, false), seed);
                        assert!(e >= em - 0.01, "{name}: glass {e} below the mirror's {em}");
                    }
                }
            }
        }
    }
}

#[test]
fn furnace_white_oren_nayar_is_lossless() {
    // The multiple-scattering term returns what single scattering loses, up to the fit of
    // its mean albedo E_avg (Cycles' (2π − 5.6)/3 B): within 0.2% of 1 for every σ and angle
    // (single scattering alone keeps π A = 0.78 at normal incidence for σ = 1).
    for sigma in [0.2f32, 0.5, 1.0] {
        let b = Diffuse::oren_nayar(Vec3::ONE, sigma, Vec3::ONE);
        for &t in &THETAS[..5] {
            let e = furnace_within(
                &format!("Oren-Nayar sigma={sigma} theta={t}"),
                &b,
                dir(t, false),
                Vec3::Z,
                3000 + t as u64,
                0.002,
            );
            assert!(
                (e - 1.0).abs() < 0.002 + 3.0 * 0.002,
                "σ {sigma}, θ {t}: E = {e}"
            );
            let c = cubature_albedo(&b, dir(t, false), Vec3::Z);
            assert!(
                (c - 1.0).abs() < 0.002,
                "σ {sigma}, θ {t}: cubature E = {c}"
            );
        }
    }
}

#[test]
fn furnace_specular_over_a_black_base_keeps_the_specular_layer() {
    // Directions sampled from the black base still carry the specular layer's reflection:
    // the mean weight must match the cubature of the mixture's value.
    for alpha in [0.1f32, 0.25, 0.8] {
        let b = Layered::new(
            RoughDielectric::principled_specular(Vec3::ONE, 1.5, alpha, alpha).multiscatter(),
            Diffuse::new(Vec3::ZERO),
        );
        for &t in &THETAS[..4] {
            let wi = dir(t, false);
            let e = furnace(
                &format!("specular over black alpha={alpha} theta={t}"),
                &b,
                wi,
                mirror(wi),
                4000 + t as u64,
            );
            assert!(e > 0.01, "alpha {alpha}, θ {t}: E = {e}");
        }
    }
}

#[test]
fn oren_nayar_is_brighter_towards_the_light_and_lambert_without_roughness() {
    let wi = dir(60.0, false);
    let lambert = Diffuse::new(Vec3::splat(0.5));
    let rough = Diffuse::oren_nayar(Vec3::splat(0.5), 1.0, Vec3::splat(0.5));
    let f = |b: &Diffuse, wo: Vec3| b.eval(&BsdfQueryRecord::pair(wi, wo)).x;
    // Back towards the viewer (retro-reflection) against the mirror direction.
    let (back, forward) = (f(&rough, wi), f(&rough, mirror(wi)));
    assert!(
        back > 1.5 * f(&lambert, wi) && forward < 0.8 * back,
        "{back} {forward}"
    );
    let smooth = Diffuse::oren_nayar(Vec3::splat(0.5), 0.0, Vec3::splat(0.5));
    for wo in [wi, mirror(wi), Vec3::Z] {
        assert_eq!(f(&smooth, wo), f(&lambert, wo));
    }
}

#[test]
fn furnace_translucent_is_exactly_the_colour() {
    let c = Vec3::new(0.8, 0.5, 0.2);
    let b = Translucent::new(c);
    let mut rng = Sampler::new(2000, 0, 0);
    for &t in &THETAS {
        for below in [false, true] {
            let wi = dir(t, below);
            for _ in 0..10_000 {
                let mut rec = BsdfQueryRecord::new(wi);
                assert_eq!(b.sample(&mut rec, rng.next_2d(), rng.next_1d()), c);
                assert!(rec.wo.z * wi.z < 0.0);
            }
            let e = cubature_albedo(&Translucent::new(Vec3::ONE), wi, Vec3::Z);
            assert!((e - 1.0).abs() < 1e-4, "∫ f cos = {e}");
        }
    }
}

#[test]
fn furnace_sheen_is_its_albedo() {
    let mut seed = 3000;
    for r in [0.1f32, 0.3, 0.6, 1.0] {
        let b = Sheen::new(Vec3::ONE, r);
        for &t in &THETAS {
            let wi = dir(t, false);
            seed += 1;
            let want = b.albedo(wi).x as f64;
            let e = furnace(&format!("Sheen r={r} θ={t}"), &b, wi, Vec3::Z, seed);
            assert!((e - want).abs() < 1e-5, "weights {e} vs albedo {want}");
        }
    }
}

#[test]
fn furnace_layered() {
    let white = Diffuse::new(Vec3::ONE);
    let metal = RoughConductor::f82(Vec3::ONE, Vec3::ONE, 0.1, 0.1);
    let mut seed = 4000;
    for (w, r, ior) in [
        (1.0f32, 0.0f32, 1.5f32),
        (1.0, 0.3, 1.5),
        (0.5, 0.8, 2.0),
        (1.0, 1.0, 1.33),
    ] {
        let coat = Coat::new(w, r, ior, Vec3::ONE);
        for t in [0.0f32, 60.0, 85.0, 89.0] {
            let wi = dir(t, false);
            seed += 1;
            let name = format!("coat w={w} r={r} ior={ior} θ={t}");
            let x = layering_excess(t);
            let over_diffuse = Layered::new(coat, white);
            furnace_within(
                &format!("{name} over diffuse"),
                &over_diffuse,
                wi,
                Vec3::Z,
                seed,
                x,
            );
            let over_metal = Layered::new(coat, metal);
            furnace_within(
                &format!("{name} over metal"),
                &over_metal,
                wi,
                mirror(wi),
                seed,
                x,
            );
            let sheen = Layered::new(Sheen::new(Vec3::ONE, 0.5), over_diffuse);
            furnace_within(
                &format!("sheen over {name} over diffuse"),
                &sheen,
                wi,
                Vec3::Z,
                seed,
                x,
            );
        }
    }
}

#[test]
fn furnace_multiscatter_white_lobes_are_lossless() {
    let mut seed = 5000;
    for alpha in [0.05f32, 0.3, 1.0] {
        let lobes = [
            (
                "mirror",
                RoughConductor::glossy(Vec3::ONE, alpha, alpha).multiscatter(),
            ),
            (
                "aniso mirror",
                RoughConductor::glossy(Vec3::ONE, alpha, 0.3 * alpha).multiscatter(),
            ),
        ];
        for (name, b) in &lobes {
            for &t in &THETAS {
                seed += 1;
                let wi = dir(t, false);
                let e = mc_only(
                    &format!("multiscatter {name} a={alpha} θ={t}"),
                    b,
                    wi,
                    mirror(wi),
                    seed,
                );
                if name.starts_with("aniso") {
                    // Cycles compensates an anisotropic lobe with the isotropic table at
                    // (αx αy)^(1/4): approximate, it only adds energy (αx = 1, αy = 0.3 at normal
                    // incidence: 0.50 becomes 0.78; elsewhere up to 1.03).
                    let single = RoughConductor::glossy(Vec3::ONE, alpha, 0.3 * alpha);
                    let (e1, _, _) = mc_albedo(&single, wi, seed);
                    assert!(
                        e >= e1 && e <= 1.06,
                        "{name}: albedo {e} (single scattering {e1})"
                    );
                } else {
                    let tol = if t >= 89.0 { 0.015 } else { 0.012 };
                    assert!((e - 1.0).abs() < tol, "{name}: albedo {e}");
                }
            }
        }
        for ior in [1.5f32, 2.4, 0.8] {
            let b = RoughDielectric::glass(Vec3::ONE, ior, alpha).multiscatter();
            for t in [0.0f32, 30.0, 60.0, 85.0, 89.0] {
                for below in [false, true] {
                    seed += 1;
                    let wi = dir(t, below);
                    let e = mc_only(
                        &format!("multiscatter glass ior={ior} a={alpha} θ={t} below={below}"),
                        &b,
                        wi,
                        refracted(wi, ior),
                        seed,
                    );
                    // The glass tables have 16 μ nodes: at 85° (μ = 0.087, between the first
                    // nodes) the interpolated E is up to 2% off; at 89° only a lower and an upper
                    // bound hold (compensation adds energy; E ∈ [0.93, 1.02] here).
                    if t >= 89.0 {
                        let single = RoughDielectric::glass(Vec3::ONE, ior, alpha);
                        let (e1, _, _) = mc_albedo(&single, wi, seed);
                        assert!(e >= e1 && e <= 1.02, "glass: albedo {e} (single {e1})");
                    } else {
                        let tol = if t >= 85.0 { 0.02 } else { 0.012 };
                        assert!((e - 1.0).abs() < tol, "glass: albedo {e}");
                    }
                }
            }
        }
        // Coloured lobes stay below 1 (the multiple-bounce Fresnel darkens them).
        let metal = RoughConductor::f82(Vec3::new(0.9, 0.9, 0.9), Vec3::splat(0.5), alpha, alpha)
            .multiscatter();
        for &t in &THETAS {
            seed += 1;
            let wi = dir(t, false);
            let e = mc_only(
                &format!("multiscatter F82 a={alpha} θ={t}"),
                &metal,
                wi,
                mirror(wi),
                seed,
            );
            assert!(e < 0.95, "{e}");
        }
    }
}

#[test]
fn furnace_principled_specular_over_diffuse() {
    let white = Diffuse::new(Vec3::ONE);
    let mut seed = 6000;
    for (ior, level, r, ms) in [
        (1.5f32, 0.5f32, 0.5f32, true),
        (1.45, 1.0, 0.2, true),
        (2.0, 0.25, 0.9, false),
        (1.5, 0.5, 0.05, true),
    ] {
        let eta = principled_specular_ior(ior, level);
        let mut spec = RoughDielectric::principled_specular(Vec3::ONE, eta, r * r, r * r);
        if ms {
            spec = spec.multiscatter();
        }
        let b = Layered::new(spec, white);
        for &t in &THETAS {
            seed += 1;
            let wi = dir(t, false);
            furnace_within(
                &format!("specular ior={ior} level={level} r={r} ms={ms} over diffuse θ={t}"),
                &b,
                wi,
                mirror(wi),
                seed,
                layering_excess(t),
            );
        }
    }
}

/// `∫ F dω` of the hair lobe (eval · |wo.z|, the value with its cosine) by cubature over the
/// sphere on rows of constant longitude about the fibre (+X), where its lobes lie as rings.
fn hair_cubature(b: &ChiangHair, wi: Vec3) -> f64 {
    let grid = DirGrid::new(Vec3::X, std::f64::consts::PI, 1.0, 96, 96);
    let m = 1e5;
    grid.expected(
        &|wo| (b.eval(&BsdfQueryRecord::pair(wi, wo)) * wo.z.abs()).x as f64,
        m,
    )
    .iter()
    .sum::<f64>()
        / m
}

/// Cycles' Chiang hair. Without absorption and without the cuticle tilt its attenuations sum
/// to 1 (`f + (1-f)²(1+f) + (1-f) f² = 1`) and each lobe's `M` and `N` are normalised, so the
/// white fibre keeps all energy: `E = 1` (cubature within `3e-3`; the sampler then draws
/// exactly `F`, so every Monte Carlo weight is 1) for every offset `h`, roughness and viewer.
/// The tilt shifts `M` in longitude, which keeps `dθ` but not `cos θ`: the lobe then gains or
/// loses energy (Cycles' model as it is; measured over these cases: 0.82–1.04 at Blender's
/// default 2°, 0.72–1.29 at 6°, the extremes where the viewer runs nearly along the fibre),
/// and the two estimates still agree. Absorption only loses energy.
#[test]
fn furnace_chiang_hair() {
    let mut seed = 900;
    let views = [0.0f32, 45.0, 80.0];
    let mut tilt_range = [(f64::MAX, f64::MIN); 2];
    for (r, rr) in [(0.15f32, 0.2f32), (0.3, 0.3), (0.7, 0.9)] {
        for h in [0.0f32, -0.9] {
            for &t in &views {
                seed += 1;
                // A viewer at longitude t from the fibre's normal plane.
                let wi = {
                    let a = t.to_radians();
                    Vec3::new(a.sin(), 0.3 * a.cos(), 0.954 * a.cos()).normalize()
                };
                let white = ChiangHair::new(Vec3::ZERO, r, rr, 0.0, 1.55, 0.0, h);
                let (e, se, _) = mc_albedo(&white, wi, seed);
                let c = hair_cubature(&white, wi);
                println!("hair r={r} rr={rr} h={h} θ={t}: E = {e:.5} ± {se:.5}, cubature {c:.5}");
                assert!(
                    (e - 1.0).abs() <= 4.0 * se + 1e-3,
                    "white hair: E = {e} ± {se}"
                );
                assert!((c - 1.0).abs() <= 3e-3, "white hair: cubature {c}");
                for alpha in [2f32, 6.0] {
                    let tilted =
                        ChiangHair::new(Vec3::ZERO, r, rr, 0.0, 1.55, alpha.to_radians(), h);
                    let (e, se, _) = mc_albedo(&tilted, wi, seed + 1000);
                    let c = hair_cubature(&tilted, wi);
                    println!("  tilt {alpha}°: E = {e:.5} ± {se:.5}, cubature {c:.5}");
                    assert!(
                        (e - c).abs() <= 4.0 * se + 3e-3,
                        "tilted: {e} ± {se} vs {c}"
                    );
                    let i = (alpha > 2.0) as usize;
                    tilt_range[i] = (tilt_range[i].0.min(e), tilt_range[i].1.max(e));
                }
                let brown = ChiangHair::new(Vec3::new(0.25, 0.52, 1.37), r, rr, 0.0, 1.55, 0.0, h);
                let (e, se, _) = mc_albedo(&brown, wi, seed + 2000);
                let c = hair_cubature(&brown, wi);
                assert!(
                    e < 1.0 && (e - c).abs() <= 4.0 * se + 3e-3,
                    "absorbing: {e} vs {c}"
                );
            }
        }
    }
    println!(
        "tilted white hair, E over the cases: 2° {:?}, 6° {:?}",
        tilt_range[0], tilt_range[1]
    );
}
