//! Statistical tests of every sampling routine against its density (nori's warptest):
//! samples are histogrammed on a grid over the domain, expected counts come from numerically
//! integrating the density over each cell, sparse cells are pooled and Pearson's chi-square
//! test runs at significance 1% (Šidák-corrected within each family of cases). Delta lobes are
//! checked exactly or with binomial bounds on their discrete choices.

#[path = "common/chi2.rs"]
mod chi2_common;

use chi2_common::*;
use glam::{DVec3, Vec2, Vec3};
use std::f64::consts::PI;
use tesela::bsdf::microfacet::{
    anisotropy, ggx_d, ggx_d_aniso, ggx_g1, ggx_g1_aniso, sample_visible_normal,
    sample_visible_normal_aniso,
};
use tesela::bsdf::thin_film::ThinFilm;
use tesela::bsdf::{
    Bsdf, BsdfQueryRecord, ChiangHair, Coat, ConductorFresnel, Dielectric, Diffuse, Layered,
    Measure, Mirror, Plastic, RoughConductor, RoughDielectric, Sheen, Toon, Translucent,
    Transparent,
};
use tesela::emitter::{
    AreaEmitter, Background, Directional, Emitter, EmitterQueryRecord, LightChoice, LightSampler,
};
use tesela::render_scene::RenderScene;
use tesela::sampler::Sampler;
use tesela::sampling::*;
use tesela::scene::{Light, Material, Mesh, Scene, SpotFalloff};

const N: usize = 1_000_000;

/// Local direction at polar angle `theta_deg` in the XZ plane, tilted a little in azimuth so
/// no test direction is aligned with a grid seam.
fn dir_at(theta_deg: f64) -> Vec3 {
    let t = theta_deg.to_radians();
    let phi = 0.3f64;
    DVec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos())
        .normalize()
        .as_vec3()
}

// ---------------------------------------------------------------------------------------------
// The statistics helper itself.

#[test]
fn chi2_distribution_matches_tables() {
    // Upper quantiles from standard tables.
    for (x, k, p) in [
        (3.841_458_820_694_124, 1, 0.05),
        (6.634_896_601_021_214, 1, 0.01),
        (23.209_251_158_954_356, 10, 0.01),
        (124.342_113_404_9, 100, 0.05),
        (1_106.969_253_9, 1000, 0.01),
    ] {
        let got = chi2_sf(x, k);
        assert!(
            (got - p).abs() < 1e-6 * p.max(1e-3) * 100.0,
            "sf({x}, {k}) = {got}, want {p}"
        );
    }
    // k = 2: sf(x) = exp(-x/2) exactly.
    for x in [0.1, 1.0, 2.0, 10.0, 50.0] {
        assert!((chi2_sf(x, 2) - (-x / 2.0f64).exp()).abs() < 1e-12);
    }
    // A perfect fit passes; a gross misfit fails.
    let e = vec![100.0; 20];
    assert!(pearson(&e, &e).unwrap().p > 0.99);
    let mut o = e.clone();
    o[0] = 160.0;
    o[1] = 40.0;
    assert!(pearson(&o, &e).unwrap().p < 1e-6);
    // Samples where the density is zero are an error.
    assert!(pearson(&[1.0, 99.0, 100.0], &[0.0, 100.0, 100.0]).is_err());
}

// ---------------------------------------------------------------------------------------------
// Warps.

#[test]
fn warp_cosine_hemisphere() {
    let grid = DirGrid::sphere(40, 80);
    let r = check_directions(
        "cosine hemisphere",
        &grid,
        N,
        1,
        &mut |s| Some(square_to_cosine_hemisphere(s.next_2d())),
        &|w| square_to_cosine_hemisphere_pdf(w) as f64,
        SIGNIFICANCE,
    );
    assert!((r.integral - 1.0).abs() < 1e-4, "∫pdf = {}", r.integral);
}

#[test]
fn warp_uniform_sphere() {
    let grid = DirGrid::sphere(40, 80);
    let r = check_directions(
        "uniform sphere",
        &grid,
        N,
        2,
        &mut |s| Some(square_to_uniform_sphere(s.next_2d())),
        &|_| square_to_uniform_sphere_pdf() as f64,
        SIGNIFICANCE,
    );
    assert!((r.integral - 1.0).abs() < 1e-4, "∫pdf = {}", r.integral);
}

#[test]
fn warp_uniform_cone() {
    let cases = [0.98f32, 0.7, 0.0, -0.6];
    let alpha = sidak(SIGNIFICANCE, cases.len());
    for (k, &cos_max) in cases.iter().enumerate() {
        let theta_max = ((cos_max as f64).acos() * 1.1).min(PI);
        let grid = DirGrid::new(Vec3::Z, theta_max, 1.0, 40, 60);
        let r = check_directions(
            &format!("uniform cone cos_max={cos_max}"),
            &grid,
            N,
            10 + k as u64,
            &mut |s| Some(square_to_uniform_cone(s.next_2d(), cos_max)),
            &|w| square_to_uniform_cone_pdf(w, cos_max) as f64,
            alpha,
        );
        assert!((r.integral - 1.0).abs() < 1e-3, "∫pdf = {}", r.integral);
        assert_eq!(r.rest_fraction, 0.0);
    }
}

#[test]
fn warp_uniform_triangle() {
    // Grid over the barycentrics (b1, b2) ∈ [0,1]²; the density is 2 on b1 + b2 ≤ 1. With an
    // n×n grid the cells strictly below the anti-diagonal are inside, those on it half inside.
    let g = 40usize;
    let mut obs = vec![0.0; g * g];
    let mut rng = Sampler::new(3, 0, 0);
    for _ in 0..N {
        let b = square_to_uniform_triangle(rng.next_2d());
        assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-6, "{b}");
        let i = ((b.x * g as f32) as usize).min(g - 1);
        let j = ((b.y * g as f32) as usize).min(g - 1);
        obs[i * g + j] += 1.0;
    }
    let cell = 1.0 / (g * g) as f64;
    let exp: Vec<f64> = (0..g * g)
        .map(|c| {
            let (i, j) = (c / g, c % g);
            let inside = match (i + j).cmp(&(g - 1)) {
                std::cmp::Ordering::Less => 1.0,
                std::cmp::Ordering::Equal => 0.5,
                std::cmp::Ordering::Greater => 0.0,
            };
            N as f64 * 2.0 * cell * inside
        })
        .collect();
    assert!((exp.iter().sum::<f64>() - N as f64).abs() < 1e-6);
    assert_chi2("uniform triangle (b1, b2)", &obs, &exp, SIGNIFICANCE);
}

#[test]
fn warp_concentric_disk() {
    let g = 40usize;
    let mut obs = vec![0.0; g * g];
    let mut rng = Sampler::new(4, 0, 0);
    for _ in 0..N {
        let p = square_to_uniform_disk(rng.next_2d());
        assert!(p.length() <= 1.0 + 1e-6, "{p}");
        let i = (((p.x + 1.0) * 0.5 * g as f32) as usize).min(g - 1);
        let j = (((p.y + 1.0) * 0.5 * g as f32) as usize).min(g - 1);
        obs[i * g + j] += 1.0;
    }
    let density = |x: f64, y: f64| if x * x + y * y <= 1.0 { 1.0 / PI } else { 0.0 };
    let h = 2.0 / g as f64;
    let exp: Vec<f64> = (0..g * g)
        .map(|c| {
            let (x0, y0) = (-1.0 + (c / g) as f64 * h, -1.0 + (c % g) as f64 * h);
            N as f64 * integrate(&density, x0, x0 + h, y0, y0 + h, 0.01 / N as f64)
        })
        .collect();
    let total = exp.iter().sum::<f64>() / N as f64;
    assert!((total - 1.0).abs() < 1e-4, "∫pdf = {total}");
    assert_chi2("concentric disk", &obs, &exp, SIGNIFICANCE);
}

// ---------------------------------------------------------------------------------------------
// Discrete choices.

#[test]
fn discrete_cdf_counts_and_reuse() {
    // Items × 10 bins of the rescaled number `sample_reuse` returns: each item must be chosen
    // with its pmf, and the reused number must be uniform within the item.
    let weights = [1.0f32, 0.0, 3.0, 0.5, 10.0, 0.0, 2.5, 1e-3];
    let total: f64 = weights.iter().map(|&w| w as f64).sum();
    let d = DiscreteCdf::new(weights);
    let bins = 10usize;
    let mut obs = vec![0.0; weights.len() * bins];
    let mut rng = Sampler::new(5, 0, 0);
    for _ in 0..N {
        let u = rng.next_1d();
        let (i, r) = d.sample_reuse(u);
        let (j, p) = d.sample(u);
        assert_eq!(i, j);
        assert_eq!(p, d.pmf(i));
        assert!((0.0..1.0).contains(&r), "reused u = {r}");
        obs[i * bins + ((r * bins as f32) as usize).min(bins - 1)] += 1.0;
    }
    let exp: Vec<f64> = (0..obs.len())
        .map(|c| N as f64 * weights[c / bins] as f64 / total / bins as f64)
        .collect();
    for (i, &w) in weights.iter().enumerate() {
        assert!((d.pmf(i) as f64 - w as f64 / total).abs() < 1e-6);
    }
    assert_chi2("DiscreteCdf items × reused u", &obs, &exp, SIGNIFICANCE);
}

fn emitter_scene(meshes: Vec<Mesh>, two_sided: bool) -> Scene {
    Scene {
        meshes,
        materials: vec![Material::emitter(
            "light",
            Vec3::new(4.0, 3.0, 2.0),
            two_sided,
        )],
        ..Default::default()
    }
}

fn mesh_from_triangles(tris: &[[Vec3; 3]], normals: bool) -> Mesh {
    let mut m = Mesh {
        name: "emitter".into(),
        ..Default::default()
    };
    for t in tris {
        let b = m.positions.len() as u32;
        m.positions.extend(t);
        if normals {
            let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
            let n = if n == Vec3::ZERO { Vec3::Z } else { n };
            m.normals.extend([n; 3]);
        }
        m.indices.push([b, b + 1, b + 2]);
    }
    m
}

#[test]
fn area_emitter_picks_triangles_by_area_and_points_uniformly() {
    // Disjoint triangles of very different areas (and a degenerate one), 10 m apart in x, in
    // differently tilted planes. Each sampled point is located in its triangle and its
    // barycentrics (b1, b2) are histogrammed on an 8×8 grid: the triangle must be chosen with
    // probability area/total and the point must be uniform inside it.
    let tris: Vec<[Vec3; 3]> = vec![
        [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.2, 1.0, 0.0),
        ],
        [
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(12.0, 0.5, 0.3),
            Vec3::new(10.5, 2.0, 1.0),
        ],
        [
            Vec3::new(20.0, 0.0, 0.0),
            Vec3::new(20.3, 0.1, 0.0),
            Vec3::new(20.1, 0.25, 0.1),
        ],
        [
            Vec3::new(30.0, 0.0, 0.0),
            Vec3::new(30.0, 3.0, 0.0),
            Vec3::new(30.0, 0.0, 3.0),
        ],
        [
            Vec3::new(40.0, 0.0, 0.0),
            Vec3::new(41.0, 1.0, 1.0),
            Vec3::new(42.0, 2.0, 2.0),
        ],
        [
            Vec3::new(50.0, 0.0, 0.0),
            Vec3::new(51.5, 0.0, -0.5),
            Vec3::new(50.0, 0.7, 0.0),
        ],
    ];
    let areas: Vec<f64> = tris
        .iter()
        .map(|t| {
            let (a, b, c) = (t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3());
            0.5 * (b - a).cross(c - a).length()
        })
        .collect();
    assert!(areas[4] < 1e-9, "triangle 4 is degenerate");
    let total: f64 = areas.iter().sum();
    let scene = emitter_scene(vec![mesh_from_triangles(&tris, true)], true);
    let e = AreaEmitter::new(&scene, 0).unwrap();
    assert!((e.area as f64 - total).abs() < 1e-5 * total);

    let g = 8usize;
    let per = g * g;
    let mut obs = vec![0.0; tris.len() * per];
    let mut rng = Sampler::new(6, 0, 0);
    for _ in 0..N {
        let mut rec = EmitterQueryRecord::from_ref(Vec3::new(25.0, 1.0, 20.0));
        e.sample(&scene, &mut rec, rng.next_2d());
        let k = (rec.p.x / 10.0).round() as usize;
        assert!(
            k < tris.len() && areas[k] > 0.0,
            "point {} on triangle {k}",
            rec.p
        );
        let t = tris[k].map(|v| v.as_dvec3());
        let (e1, e2, d) = (t[1] - t[0], t[2] - t[0], rec.p.as_dvec3() - t[0]);
        let (a11, a12, a22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (r1, r2) = (d.dot(e1), d.dot(e2));
        let det = a11 * a22 - a12 * a12;
        let b1 = (a22 * r1 - a12 * r2) / det;
        let b2 = (a11 * r2 - a12 * r1) / det;
        let off_plane = (d - e1 * b1 - e2 * b2).length();
        assert!(
            off_plane < 1e-4,
            "point {} is off triangle {k} by {off_plane}",
            rec.p
        );
        assert!(
            b1 > -1e-4 && b2 > -1e-4 && b1 + b2 < 1.0 + 1e-4,
            "({b1}, {b2})"
        );
        let i = ((b1 * g as f64) as usize).min(g - 1);
        let j = ((b2 * g as f64) as usize).min(g - 1);
        obs[k * per + i * g + j] += 1.0;
    }
    let exp: Vec<f64> = (0..obs.len())
        .map(|c| {
            let (k, i, j) = (c / per, (c % per) / g, c % g);
            let inside = match (i + j).cmp(&(g - 1)) {
                std::cmp::Ordering::Less => 1.0,
                std::cmp::Ordering::Equal => 0.5,
                std::cmp::Ordering::Greater => 0.0,
            };
            N as f64 * areas[k] / total * 2.0 * inside / per as f64
        })
        .collect();
    assert_chi2(
        "AreaEmitter triangle × barycentric cell",
        &obs,
        &exp,
        SIGNIFICANCE,
    );
}

fn light_sampler_scene() -> Scene {
    let v = Vec3::new;
    let mut scene = Scene {
        materials: vec![
            Material::diffuse("floor", Vec3::splat(0.5)),
            Material::emitter("big", v(5.0, 5.0, 5.0), false),
            Material::emitter("small two-sided", v(1.0, 2.0, 3.0), true),
        ],
        background: v(0.2, 0.3, 0.4),
        ..Default::default()
    };
    use tesela::scene::builtin::quad;
    scene.meshes.push(quad(
        "floor",
        0,
        v(-2., 0., 2.),
        v(2., 0., 2.),
        v(2., 0., -2.),
        v(-2., 0., -2.),
    ));
    scene.meshes.push(quad(
        "big",
        1,
        v(-0.5, 2., -0.5),
        v(0.5, 2., -0.5),
        v(0.5, 2., 0.5),
        v(-0.5, 2., 0.5),
    ));
    scene.meshes.push(quad(
        "small",
        2,
        v(1., 1., 0.),
        v(1.2, 1., 0.),
        v(1.2, 1.3, 0.),
        v(1., 1.3, 0.),
    ));
    scene.lights = vec![
        Light::Point {
            position: v(0., 1., 0.),
            intensity: v(10., 10., 10.),
        },
        Light::Point {
            position: v(0., 1., 1.),
            intensity: Vec3::ZERO,
        },
        Light::Spot {
            position: v(1., 1., 1.),
            direction: v(0., -1., 0.),
            intensity: v(30., 20., 10.),
            falloff: SpotFalloff::Gltf {
                cos_inner: 0.9,
                cos_outer: 0.7,
            },
        },
        Light::Directional {
            direction: v(0.3, -1., 0.2),
            irradiance: v(3., 3., 3.),
            angle: 0.0,
        },
    ];
    scene
}

#[test]
fn light_sampler_power_and_uniform_choice() {
    let lum = |c: Vec3| 0.2126 * c.x as f64 + 0.7152 * c.y as f64 + 0.0722 * c.z as f64;
    for (case, choice) in [LightChoice::Power, LightChoice::Flat, LightChoice::Uniform]
        .into_iter()
        .enumerate()
    {
        let rs = RenderScene::new(light_sampler_scene(), choice);
        let r = rs.radius as f64;
        // Emitters: big quad, small quad, point, dark point, spot, sun, background.
        assert_eq!(rs.emitters.len(), 7);
        let expected_power = [
            lum(Vec3::splat(5.0)) * PI * 1.0,
            lum(Vec3::new(1.0, 2.0, 3.0)) * PI * 0.06 * 2.0,
            4.0 * PI * lum(Vec3::splat(10.0)),
            0.0,
            2.0 * PI * (1.0 - 0.7) * lum(Vec3::new(30.0, 20.0, 10.0)),
            lum(Vec3::splat(3.0)) * PI * r * r,
            // A world counts the irradiance π L of a facing surface, as a sun counts E.
            lum(Vec3::new(0.2, 0.3, 0.4)) * PI * PI * r * r,
        ];
        let powers: Vec<f64> = rs
            .emitters
            .iter()
            .map(|e| e.power(&rs.scene, rs.radius) as f64)
            .collect();
        for (i, (&p, &q)) in powers.iter().zip(&expected_power).enumerate() {
            assert!(
                (p - q).abs() <= 1e-4 * q.max(1e-6),
                "power of emitter {i}: {p} vs {q}"
            );
        }
        let weights: Vec<f64> = match choice {
            LightChoice::Power | LightChoice::Flat => expected_power.to_vec(),
            LightChoice::Uniform => expected_power
                .iter()
                .map(|&p| if p > 0.0 { 1.0 } else { 0.0 })
                .collect(),
        };
        let total: f64 = weights.iter().sum();
        let mut obs = vec![0.0; weights.len()];
        let mut rng = Sampler::new(7, case as u64, 0);
        for _ in 0..N {
            let (i, pmf) = rs.lights.sample(rng.next_1d());
            assert_eq!(pmf, rs.lights.pmf(i));
            obs[i] += 1.0;
        }
        for (i, w) in weights.iter().enumerate() {
            let pmf = rs.lights.pmf(i) as f64;
            assert!(
                (pmf - w / total).abs() < 1e-5,
                "pmf({i}) = {pmf}, want {}",
                w / total
            );
        }
        let exp: Vec<f64> = weights.iter().map(|w| N as f64 * w / total).collect();
        assert_chi2(
            &format!("LightSampler {choice:?}"),
            &obs,
            &exp,
            sidak(SIGNIFICANCE, 2),
        );
    }
    // An empty sampler chooses nothing.
    let empty = LightSampler::new(&[0.0, -1.0, f32::NAN], LightChoice::Power);
    assert!(empty.is_empty());
    assert_eq!(empty.pmf(0), 0.0);
}

// ---------------------------------------------------------------------------------------------
// GGX.

/// `D(h)` in the textbook form `1 / (π α² cos⁴θ (1 + tan²θ / α²)²)`.
fn ggx_d_reference(h: DVec3, alpha: f64) -> f64 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let c2 = h.z * h.z;
    let t2 = (1.0 - c2) / c2;
    let k = 1.0 + t2 / (alpha * alpha);
    1.0 / (PI * alpha * alpha * c2 * c2 * k * k)
}

/// Smith `G1(w) = 2 / (1 + sqrt(1 + α² tan²θ))`.
fn ggx_g1_reference(w: DVec3, alpha: f64) -> f64 {
    let c2 = w.z * w.z;
    let t2 = (1.0 - c2) / c2;
    2.0 / (1.0 + (1.0 + alpha * alpha * t2).sqrt())
}

fn visible_normal_pdf(wi: Vec3, h: Vec3, alpha: f32) -> f64 {
    ggx_g1(wi, alpha) as f64 * (wi.dot(h).max(0.0) as f64) * ggx_d(h, alpha) as f64 / wi.z as f64
}

#[test]
fn ggx_closed_forms_and_normalisation() {
    let mut rng = Sampler::new(8, 0, 0);
    for alpha in [0.05f32, 0.2, 0.5, 1.0] {
        for _ in 0..1000 {
            let w = square_to_uniform_sphere(rng.next_2d());
            if w.z.abs() < 1e-3 {
                continue;
            }
            let w = Vec3::new(w.x, w.y, w.z.abs());
            let (d, dr) = (
                ggx_d(w, alpha) as f64,
                ggx_d_reference(w.as_dvec3(), alpha as f64),
            );
            assert!(
                (d - dr).abs() <= 1e-4 * dr + 1e-9,
                "D({w}, {alpha}) = {d} vs {dr}"
            );
            let (g, gr) = (
                ggx_g1(w, alpha) as f64,
                ggx_g1_reference(w.as_dvec3(), alpha as f64),
            );
            assert!((g - gr).abs() <= 1e-5, "G1({w}, {alpha}) = {g} vs {gr}");
            assert_eq!(ggx_d(-w, alpha), 0.0);
        }
        // Projected-area normalisation ∫ D(h) cos θh dh = 1.
        let gamma = if alpha < 0.3 { 2.0 } else { 1.0 };
        let grid = DirGrid::new(Vec3::Z, PI / 2.0, gamma, 40, 8);
        let m = 1e6;
        let s: f64 = grid
            .expected(&|h| ggx_d(h, alpha) as f64 * h.z as f64, m)
            .iter()
            .sum::<f64>()
            / m;
        assert!((s - 1.0).abs() < 1e-4, "∫D cos = {s} for alpha {alpha}");
        // The visible-normal density is normalised for every incident direction (this pins G1).
        for theta in [0.0, 45.0, 80.0, 89.0] {
            let wi = dir_at(theta);
            let grid = DirGrid::new(Vec3::Z, PI / 2.0, gamma, 40, 40);
            let s: f64 = grid
                .expected(&|h| visible_normal_pdf(wi, h, alpha), m)
                .iter()
                .sum::<f64>()
                / m;
            assert!(
                (s - 1.0).abs() < 1e-4,
                "∫D_wi = {s} for alpha {alpha}, θi {theta}°"
            );
        }
    }
}

#[test]
fn ggx_visible_normals() {
    let alphas = [0.08f32, 0.3, 0.7, 1.0];
    let thetas = [0.0, 45.0, 75.0, 89.0];
    let alpha_case = sidak(SIGNIFICANCE, alphas.len() * thetas.len());
    let mut seed = 100;
    for &alpha in &alphas {
        for &theta in &thetas {
            let wi = dir_at(theta);
            let gamma = if alpha < 0.2 { 2.0 } else { 1.0 };
            let grid = DirGrid::new(Vec3::Z, PI / 2.0, gamma, 30, 60);
            seed += 1;
            let r = check_directions(
                &format!("visible normals alpha={alpha} θi={theta}°"),
                &grid,
                N / 2,
                seed,
                &mut |s| Some(sample_visible_normal(wi, alpha, s.next_2d())),
                &|h| visible_normal_pdf(wi, h, alpha),
                alpha_case,
            );
            assert!((r.integral - 1.0).abs() < 1e-3, "∫D_wi = {}", r.integral);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Non-delta BSDFs: directions of the sampled wo against `pdf()`.

fn check_bsdf(
    name: &str,
    bsdf: &dyn Bsdf,
    wi: Vec3,
    grid: &DirGrid,
    seed: u64,
    alpha: f64,
) -> DirCheck {
    check_directions(
        name,
        grid,
        N / 2,
        seed,
        &mut |s| {
            let mut rec = BsdfQueryRecord::new(wi);
            let w = bsdf.sample(&mut rec, s.next_2d(), s.next_1d());
            (w.max_element() > 0.0 && rec.measure == Measure::SolidAngle).then_some(rec.wo)
        },
        &|wo| bsdf.pdf(&BsdfQueryRecord::pair(wi, wo)) as f64,
        alpha,
    )
}

fn mirror_dir(wi: Vec3) -> Vec3 {
    Vec3::new(-wi.x, -wi.y, wi.z)
}

#[test]
fn diffuse_sampling() {
    let b = Diffuse::new(Vec3::new(0.8, 0.5, 0.2));
    let wi = dir_at(50.0);
    let r = check_bsdf(
        "Diffuse",
        &b,
        wi,
        &DirGrid::sphere(40, 80),
        200,
        SIGNIFICANCE,
    );
    assert!((r.integral - 1.0).abs() < 1e-4);
}

#[test]
fn oren_nayar_sampling() {
    let c = Vec3::new(0.8, 0.5, 0.2);
    for (theta, sigma) in [(20.0, 0.5f32), (75.0, 1.0)] {
        let b = Diffuse::oren_nayar(c, sigma, c);
        let r = check_bsdf(
            "Oren-Nayar",
            &b,
            dir_at(theta),
            &DirGrid::sphere(40, 80),
            210,
            sidak(SIGNIFICANCE, 2),
        );
        assert!((r.integral - 1.0).abs() < 1e-4);
    }
}

#[test]
fn rough_conductor_sampling() {
    let alphas = [0.1f32, 0.3, 0.7, 1.0];
    let thetas = [0.0, 40.0, 70.0, 88.0];
    let alpha_case = sidak(SIGNIFICANCE, alphas.len() * thetas.len());
    let mut seed = 300;
    for &alpha in &alphas {
        for &theta in &thetas {
            let wi = dir_at(theta);
            let b = RoughConductor::new(Vec3::new(0.9, 0.6, 0.3), alpha);
            // Grid centred on the mirror direction, rows packed near it for narrow lobes.
            let gamma = if alpha < 0.2 { 2.0 } else { 1.0 };
            let grid = DirGrid::new(mirror_dir(wi), PI, gamma, 40, 60);
            seed += 1;
            let r = check_bsdf(
                &format!("RoughConductor alpha={alpha} θi={theta}°"),
                &b,
                wi,
                &grid,
                seed,
                alpha_case,
            );
            // Samples below the horizon are the only failures: the density's missing mass.
            assert!(r.integral <= 1.0 + 1e-3, "∫pdf = {}", r.integral);
            assert!((r.integral + r.rest_fraction - 1.0).abs() < 0.01);
        }
    }
}

#[test]
fn plastic_rough_sampling() {
    let materials = [
        Plastic::new(Vec3::new(0.7, 0.2, 0.1), 0.15, 1.5, 1.0, Vec3::ONE),
        Plastic::new(
            Vec3::new(0.2, 0.6, 0.9),
            0.5,
            2.5,
            0.7,
            Vec3::new(1.0, 0.5, 0.2),
        ),
        Plastic::new(Vec3::splat(0.5), 0.9, 1.33, 1.0, Vec3::ONE),
    ];
    let thetas = [10.0, 60.0, 85.0];
    let alpha_case = sidak(SIGNIFICANCE, materials.len() * thetas.len());
    let mut seed = 400;
    for b in &materials {
        for &theta in &thetas {
            let wi = dir_at(theta);
            seed += 1;
            let r = check_bsdf(
                &format!("Plastic alpha={} θi={theta}°", b.alpha),
                b,
                wi,
                &DirGrid::sphere(40, 80),
                seed,
                alpha_case,
            );
            assert!(r.integral <= 1.0 + 1e-3, "∫pdf = {}", r.integral);
        }
    }
}

#[test]
fn plastic_smooth_sampling() {
    // Roughness 0: the continuous part is (1 - s) cos/π; the delta coat's share s is the mass
    // missing from the density, which the "rest" cell of the histogram receives.
    let b = Plastic::new(Vec3::new(0.7, 0.2, 0.1), 0.0, 1.5, 1.0, Vec3::ONE);
    let thetas = [0.0, 60.0, 85.0];
    let alpha_case = sidak(SIGNIFICANCE, thetas.len());
    for (k, &theta) in thetas.iter().enumerate() {
        let wi = dir_at(theta);
        let s = fresnel_schlick(0.04, wi.z as f64);
        let r = check_bsdf(
            &format!("smooth Plastic θi={theta}° (diffuse part)"),
            &b,
            wi,
            &DirGrid::sphere(40, 80),
            500 + k as u64,
            alpha_case,
        );
        assert!(
            (r.integral - (1.0 - s)).abs() < 1e-4,
            "∫pdf = {} vs {}",
            r.integral,
            1.0 - s
        );
    }
}

fn fresnel_schlick(f0: f64, cos: f64) -> f64 {
    f0 + (1.0 - f0) * (1.0 - cos.clamp(0.0, 1.0)).powi(5)
}

// ---------------------------------------------------------------------------------------------
// Emitters.

/// Ray–triangle intersection (Möller–Trumbore, f64): distance along the unit `d`, if any.
fn ray_triangle(o: DVec3, d: DVec3, t: [DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-14 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - t[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let dist = e2.dot(q) * inv;
    (dist > 0.0).then_some(dist)
}

/// Solid-angle density of area sampling from `ref_p` in direction `w`: the emitter's `pdf()`
/// summed over every point of the mesh along the ray (sampling ignores occlusion, so a
/// direction that crosses the mesh twice is reached through both points).
fn area_direction_pdf(scene: &Scene, e: &AreaEmitter, ref_p: Vec3, w: Vec3) -> f64 {
    let m = &scene.meshes[e.mesh];
    let (o, d) = (ref_p.as_dvec3(), w.as_dvec3().normalize());
    let mut sum = 0.0;
    for (k, tri) in m.indices.iter().enumerate() {
        let t = tri.map(|i| m.positions[i as usize].as_dvec3());
        if let Some(dist) = ray_triangle(o, d, t) {
            let ng = (t[1] - t[0]).cross(t[2] - t[0]).normalize().as_vec3();
            let p = (o + d * dist).as_vec3();
            let mut rec = EmitterQueryRecord::between(ref_p, p, ng, ng, Vec2::ZERO);
            rec.tri = k as u32;
            sum += e.pdf(scene, &rec) as f64;
        }
    }
    sum
}

#[test]
fn area_emitter_directions() {
    let v = Vec3::new;
    // A tilted quad with a triangle hovering in front of it (directions through both are
    // reached twice), and a folded "tent" whose two faces are both seen from the side.
    let quad_and_tri = vec![
        [v(-0.5, 1.0, -0.5), v(0.5, 1.2, -0.5), v(0.5, 1.4, 0.5)],
        [v(-0.5, 1.0, -0.5), v(0.5, 1.4, 0.5), v(-0.5, 1.2, 0.5)],
        [v(-0.2, 0.6, 0.0), v(0.4, 0.7, 0.1), v(0.0, 0.65, 0.4)],
    ];
    let tent = vec![
        [v(-1.0, 0.0, -0.5), v(1.0, 0.0, -0.5), v(1.0, 1.0, 0.0)],
        [v(-1.0, 0.0, -0.5), v(1.0, 1.0, 0.0), v(-1.0, 1.0, 0.0)],
        [v(-1.0, 1.0, 0.0), v(1.0, 1.0, 0.0), v(1.0, 0.0, 0.5)],
        [v(-1.0, 1.0, 0.0), v(1.0, 0.0, 0.5), v(-1.0, 0.0, 0.5)],
    ];
    let cases: Vec<(&str, Vec<[Vec3; 3]>, bool, Vec3)> = vec![
        (
            "quad + triangle, from below",
            quad_and_tri.clone(),
            true,
            v(0.1, 0.0, 0.2),
        ),
        (
            "quad + triangle, no normals",
            quad_and_tri,
            false,
            v(-0.3, 0.1, -0.4),
        ),
        ("tent from the side", tent.clone(), true, v(0.3, 0.4, 3.0)),
        ("tent at grazing angle", tent, true, v(3.0, 0.05, 0.1)),
        // Close to a large triangle: sampled by solid angle, nearly a hemisphere of directions.
        (
            "large triangle just below",
            vec![[v(-2.0, 1.0, -1.5), v(2.0, 1.0, -1.5), v(0.0, 1.0, 2.5)]],
            true,
            v(0.1, 0.7, 0.0),
        ),
    ];
    let alpha = sidak(SIGNIFICANCE, cases.len());
    for (k, (name, tris, normals, ref_p)) in cases.into_iter().enumerate() {
        let scene = emitter_scene(vec![mesh_from_triangles(&tris, normals)], true);
        let e = AreaEmitter::new(&scene, 0).unwrap();
        let centroid = tris.iter().flatten().copied().sum::<Vec3>() / (3 * tris.len()) as f32;
        let axis = (centroid - ref_p).normalize();
        let theta_max = tris
            .iter()
            .flatten()
            .map(|&p| {
                (axis.dot((p - ref_p).normalize()) as f64)
                    .clamp(-1.0, 1.0)
                    .acos()
            })
            .fold(0.0, f64::max)
            * 1.05;
        let grid = DirGrid::new(axis, theta_max, 1.0, 40, 60);
        let r = check_directions(
            &format!("AreaEmitter {name}"),
            &grid,
            N / 2,
            600 + k as u64,
            &mut |s| {
                let mut rec = EmitterQueryRecord::from_ref(ref_p);
                let w = e.sample(&scene, &mut rec, s.next_2d());
                (w.max_element() > 0.0).then_some(rec.wi)
            },
            &|w| area_direction_pdf(&scene, &e, ref_p, w),
            alpha,
        );
        assert!((r.integral - 1.0).abs() < 2e-3, "∫pdf = {}", r.integral);
        assert_eq!(r.rest_fraction, 0.0);
    }
}

#[test]
fn directional_cone_sampling() {
    let scene = Scene::default();
    let angles = [0.2f32, 1.0, 2.5, std::f32::consts::PI];
    let alpha = sidak(SIGNIFICANCE, angles.len());
    let dir = Vec3::new(0.3, -1.0, 0.2).normalize();
    for (k, &angle) in angles.iter().enumerate() {
        let light = Directional::new(dir, Vec3::splat(2.0), angle);
        assert!(!light.is_delta());
        let half = angle as f64 / 2.0;
        let cone_pdf = 1.0 / (2.0 * PI * (1.0 - half.cos()));
        let grid = DirGrid::new(-dir, (half * 1.1).min(PI), 1.0, 40, 60);
        let r = check_directions(
            &format!("Directional angle={angle}"),
            &grid,
            N / 2,
            700 + k as u64,
            &mut |s| {
                let mut rec = EmitterQueryRecord::from_ref(Vec3::ZERO);
                let w = light.sample(&scene, &mut rec, s.next_2d());
                assert!(rec.dist.is_infinite());
                (w.max_element() > 0.0).then_some(rec.wi)
            },
            &|w| {
                let p = light.pdf(&scene, &EmitterQueryRecord::towards(Vec3::ZERO, w)) as f64;
                if p > 0.0 {
                    assert!(
                        (p - cone_pdf).abs() < 1e-3 * cone_pdf,
                        "pdf {p} vs {cone_pdf}"
                    );
                }
                p
            },
            alpha,
        );
        assert!((r.integral - 1.0).abs() < 1e-3, "∫pdf = {}", r.integral);
        assert_eq!(r.rest_fraction, 0.0);
    }
}

#[test]
fn background_sampling() {
    let scene = Scene::default();
    let bg = Background {
        radiance: Vec3::new(0.3, 0.2, 0.1),
    };
    let r = check_directions(
        "Background",
        &DirGrid::sphere(40, 80),
        N,
        800,
        &mut |s| {
            let mut rec = EmitterQueryRecord::from_ref(Vec3::ONE);
            bg.sample(&scene, &mut rec, s.next_2d());
            Some(rec.wi)
        },
        &|w| bg.pdf(&scene, &EmitterQueryRecord::towards(Vec3::ONE, w)) as f64,
        SIGNIFICANCE,
    );
    assert!((r.integral - 1.0).abs() < 1e-4);
}

// ---------------------------------------------------------------------------------------------
// Delta lobes.

#[test]
fn mirror_reflects_with_schlick_weight() {
    let f0 = Vec3::new(0.95, 0.64, 0.54);
    let b = Mirror::new(f0);
    let mut rng = Sampler::new(900, 0, 0);
    for _ in 0..10_000 {
        let wi = square_to_uniform_sphere(rng.next_2d());
        let mut rec = BsdfQueryRecord::new(wi);
        let w = b.sample(&mut rec, rng.next_2d(), rng.next_1d());
        if wi.z <= 0.0 {
            assert_eq!(w, Vec3::ZERO, "no reflection from below");
            continue;
        }
        assert_eq!(rec.wo, Vec3::new(-wi.x, -wi.y, wi.z));
        assert_eq!(rec.measure, Measure::Discrete);
        assert_eq!(rec.eta, 1.0);
        for c in 0..3 {
            let want = fresnel_schlick(f0[c] as f64, wi.z as f64);
            assert!(
                (w[c] as f64 - want).abs() < 1e-5,
                "weight {w} at cos {}",
                wi.z
            );
        }
    }
}

/// Exact unpolarised Fresnel reflectance for light going from index `n1` into `n2` at
/// incidence cosine `cos_i ≥ 0`, with the transmitted cosine (`None` on total reflection).
fn fresnel_exact(n1: f64, n2: f64, cos_i: f64) -> (f64, Option<f64>) {
    let sin_t = n1 / n2 * (1.0 - cos_i * cos_i).max(0.0).sqrt();
    if sin_t >= 1.0 {
        return (1.0, None);
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    let rp = (n1 * cos_t - n2 * cos_i) / (n1 * cos_t + n2 * cos_i);
    (0.5 * (rs * rs + rp * rp), Some(cos_t))
}

#[test]
fn dielectric_fresnel_choice_and_snell() {
    let tint = Vec3::new(0.9, 0.8, 0.7);
    // (ior, incidence angle, entering?)
    let mut cases = vec![];
    for ior in [1.5f32, 1.33, 2.4, 0.8] {
        for theta in [0.0, 20.0, 40.0, 41.5, 42.5, 60.0, 80.0, 88.0] {
            cases.push((ior, theta, true));
            cases.push((ior, theta, false));
        }
    }
    let m = 40_000u64;
    let alpha = sidak(SIGNIFICANCE, cases.len());
    let mut min_p = 1.0f64;
    for (k, &(ior, theta, entering)) in cases.iter().enumerate() {
        let b = Dielectric::new(ior, tint);
        let mut wi = dir_at(theta);
        if !entering {
            wi.z = -wi.z;
        }
        let (n1, n2) = if entering {
            (1.0, ior as f64)
        } else {
            (ior as f64, 1.0)
        };
        let (r, cos_t) = fresnel_exact(n1, n2, wi.z.abs() as f64);
        let mut rng = Sampler::new(1000, k as u64, 0);
        let mut reflections = 0u64;
        for t in 0..m {
            // The last draw is the largest u1 the sampler can produce.
            let u1 = if t == m - 1 {
                1.0 - f32::EPSILON / 2.0
            } else {
                rng.next_1d()
            };
            let mut rec = BsdfQueryRecord::new(wi);
            let w = b.sample(&mut rec, rng.next_2d(), u1);
            assert_eq!(rec.measure, Measure::Discrete);
            assert_eq!(rec.pdf, 0.0);
            if rec.wo.z * wi.z > 0.0 {
                reflections += 1;
                assert_eq!(rec.wo, Vec3::new(-wi.x, -wi.y, wi.z));
                assert_eq!(w, Vec3::ONE);
                assert_eq!(rec.eta, 1.0);
            } else {
                let cos_t = cos_t.unwrap_or_else(|| {
                    panic!("refraction beyond the critical angle: ior {ior}, {theta}°, entering {entering}")
                });
                let wo = rec.wo.as_dvec3();
                let wi64 = wi.as_dvec3();
                assert!((wo.length() - 1.0).abs() < 1e-5);
                // Snell: n1 sin θi = n2 sin θt, on the far side, in the plane of incidence.
                let (sin_i, sin_t) = (wi64.truncate().length(), wo.truncate().length());
                assert!(
                    (n1 * sin_i - n2 * sin_t).abs() < 1e-5,
                    "Snell: {n1}·{sin_i} vs {n2}·{sin_t}"
                );
                assert!((wo.z.abs() - cos_t).abs() < 1e-5);
                if sin_i > 1e-6 {
                    let cross = wo.x * wi64.y - wo.y * wi64.x;
                    assert!(
                        cross.abs() < 1e-5 && wo.x * wi64.x + wo.y * wi64.y <= 0.0,
                        "plane of incidence"
                    );
                }
                let eta = (n2 / n1) as f32;
                assert!(
                    (rec.eta - eta).abs() < 1e-5 * eta,
                    "eta {} vs {eta}",
                    rec.eta
                );
                // Cycles' convention (docs/blender-units.md): sqrt(base colour) per refraction,
                // no 1/η² radiance scale.
                let want = tint.map(f32::sqrt);
                assert!(
                    (w - want).abs().max_element() < 1e-5 * want.max_element(),
                    "refraction weight {w} vs sqrt(tint) = {want} (ior {ior}, {theta}°, entering {entering})"
                );
            }
        }
        if cos_t.is_none() {
            assert_eq!(
                reflections, m,
                "total internal reflection must always reflect"
            );
            continue;
        }
        let p = binomial_p_value(reflections, m, r);
        min_p = min_p.min(p);
        println!(
            "Dielectric ior={ior} θ={theta}° {}: reflected {reflections}/{m}, Fresnel R = {r:.5}, p = {p:.4}",
            if entering { "entering" } else { "leaving" }
        );
        assert!(
            p >= alpha,
            "reflection fraction {} vs Fresnel {r}: p = {p:.3e}",
            reflections as f64 / m as f64
        );
    }
    println!("Dielectric: smallest p-value {min_p:.4} (per-case level {alpha:.2e})");
}

#[test]
fn smooth_plastic_coat_probability() {
    let cases = [
        (1.5f32, 1.0f32, Vec3::ONE),
        (1.5, 0.5, Vec3::new(1.0, 0.5, 0.25)),
        (2.2, 1.0, Vec3::new(0.5, 0.5, 0.5)),
    ];
    let thetas = [0.0, 60.0, 80.0, 89.0];
    let alpha = sidak(SIGNIFICANCE, cases.len() * thetas.len());
    let m = 100_000u64;
    let mut k = 0;
    for &(ior, specular, color) in &cases {
        let b = Plastic::new(Vec3::new(0.3, 0.5, 0.7), 0.0, ior, specular, color);
        let f0 = (((ior - 1.0) / (ior + 1.0)) as f64).powi(2) * color.max_element() as f64;
        for &theta in &thetas {
            let wi = dir_at(theta);
            let s = specular as f64 * fresnel_schlick(f0, wi.z as f64);
            let mut rng = Sampler::new(1100, k, 0);
            k += 1;
            let mut coat = 0u64;
            for _ in 0..m {
                let mut rec = BsdfQueryRecord::new(wi);
                let w = b.sample(&mut rec, rng.next_2d(), rng.next_1d());
                match rec.measure {
                    Measure::Discrete => {
                        coat += 1;
                        assert_eq!(rec.wo, Vec3::new(-wi.x, -wi.y, wi.z));
                        assert_eq!(rec.pdf, 0.0);
                        assert!((w - color / color.max_element()).abs().max_element() < 1e-6);
                    }
                    Measure::SolidAngle => {
                        assert!(rec.wo.z > 0.0 && rec.pdf > 0.0);
                    }
                }
            }
            let p = binomial_p_value(coat, m, s);
            println!(
                "smooth Plastic ior={ior} specular={specular} θ={theta}°: coat {coat}/{m}, s = {s:.5}, p = {p:.4}"
            );
            assert!(
                p >= alpha,
                "coat fraction {} vs specular·Schlick {s}: p = {p:.3e}",
                coat as f64 / m as f64
            );
        }
    }
}

/// Cycles' smooth Principled base (`Plastic::cycles`): the coat is picked with probability
/// `max F`, `F = mix(F0 · tint, 1, (F_exact - F0) / (1 - F0))` per channel, and weighs `F / max F`;
/// with a white tint `F` is the exact Fresnel reflectance, and a black tint keeps the grazing
/// reflection (Schlick's F0 scaling would remove it).
#[test]
fn smooth_plastic_cycles_coat_probability() {
    let cases = [
        (1.5f32, Vec3::ONE),
        (1.5, Vec3::ZERO),
        (1.8, Vec3::new(0.0, 0.5, 1.0)),
        (1.2, Vec3::splat(4.0)),
    ];
    let thetas = [0.0, 45.0, 75.0, 88.0];
    let alpha = sidak(SIGNIFICANCE, cases.len() * thetas.len());
    let m = 100_000u64;
    let mut k = 0;
    for &(eta, tint) in &cases {
        let b = Plastic::cycles(Vec3::new(0.3, 0.5, 0.7), 0.0, eta, tint);
        let f0 = ((eta as f64 - 1.0) / (eta as f64 + 1.0)).powi(2);
        for &theta in &thetas {
            let wi = dir_at(theta);
            let s = (fresnel_exact(1.0, eta as f64, wi.z as f64).0 - f0) / (1.0 - f0);
            let f = tint
                .as_dvec3()
                .map(|t| (t * f0).min(1.0))
                .map(|c| c + (1.0 - c) * s);
            let share = f.max_element();
            if tint == Vec3::ZERO && theta == 0.0 {
                assert!(
                    share < 1e-6,
                    "no reflection head-on with a black tint: {share}"
                );
            }
            if tint == Vec3::ONE {
                let exact = fresnel_exact(1.0, eta as f64, wi.z as f64).0;
                assert!(
                    (share - exact).abs() < 1e-5,
                    "white tint: {share} vs Fresnel {exact}"
                );
            }
            let mut rng = Sampler::new(1200, k, 0);
            k += 1;
            let mut coat = 0u64;
            for _ in 0..m {
                let mut rec = BsdfQueryRecord::new(wi);
                let w = b.sample(&mut rec, rng.next_2d(), rng.next_1d());
                if rec.measure == Measure::Discrete {
                    coat += 1;
                    assert_eq!(rec.wo, Vec3::new(-wi.x, -wi.y, wi.z));
                    let want = f / share;
                    assert!(
                        (w.as_dvec3() - want).abs().max_element() < 1e-4,
                        "coat weight {w} vs F / max F = {want}"
                    );
                }
            }
            let p = binomial_p_value(coat, m, share);
            println!(
                "Cycles smooth Plastic eta={eta} tint={tint} θ={theta}°: coat {coat}/{m}, max F = {share:.5}, p = {p:.4}"
            );
            assert!(
                p >= alpha,
                "coat fraction {} vs max F {share}: p = {p:.3e}",
                coat as f64 / m as f64
            );
        }
    }
}

/// Worst relative difference between an area emitter's triangle choice probability and the
/// triangle's share of the area, for a UV sphere of `rings × segments`.
fn worst_triangle_share_error(rings: u32, segments: u32) -> (usize, f64) {
    let mesh = tesela::scene::builtin::sphere("s", 0, Vec3::ZERO, 1.0, rings, segments);
    let scene = emitter_scene(vec![mesh], false);
    let e = AreaEmitter::new(&scene, 0).unwrap();
    let m = &scene.meshes[0];
    let areas: Vec<f64> = m
        .indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize].as_dvec3());
            0.5 * (b - a).cross(c - a).length()
        })
        .collect();
    let total: f64 = areas.iter().sum();
    let worst = areas
        .iter()
        .enumerate()
        .map(|(i, a)| (e.cdf.pmf(i) as f64 * total / a - 1.0).abs())
        .fold(0.0, f64::max);
    let min_pmf = (0..areas.len())
        .map(|i| e.cdf.pmf(i))
        .fold(f32::INFINITY, f32::min);
    println!(
        "{} triangles: worst relative error of pmf vs area share {worst:.2e}; the smallest \
         triangle is hit by {} of the 2^24 possible sample values",
        areas.len(),
        (min_pmf as f64 * (1u64 << 24) as f64).round()
    );
    (areas.len(), worst)
}

#[test]
fn area_emitter_triangle_probabilities_match_areas() {
    // The emitter reports the density 1/A at every point, which is right only if triangle i is
    // chosen with probability A_i / A. The choice (an f32 CDF driven by a 24-bit uniform number)
    // quantises probabilities to about 2^-24, fine for meshes of the built-in scenes' density.
    let (n, worst) = worst_triangle_share_error(48, 96);
    assert!(
        worst < 1e-2,
        "{n} triangles: choice probability off its area share by {worst:.2e}"
    );
}

/// On dense emissive meshes every triangle can be chosen and is chosen with its area share:
/// the choice probabilities match the (f32) areas to 1e-5 (a 24-bit f32 CDF was 9% to 62% off on 65k
/// to 261k triangles), and on a 1M-triangle sphere, whose smallest triangles have probabilities
/// below 2^-24, the uniform pair aimed at the middle of each triangle's CDF interval selects that
/// triangle (a choice made from `u.x` alone can never reach triangles between two 24-bit values).
#[test]
fn dense_mesh_emitter_triangle_probabilities_match_areas() {
    let mesh = tesela::scene::builtin::sphere("s", 0, Vec3::ZERO, 1.0, 512, 1024);
    let scene = emitter_scene(vec![mesh], false);
    let e = AreaEmitter::new(&scene, 0).unwrap();
    let m = &scene.meshes[0];
    let areas: Vec<f64> = m
        .indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize].as_dvec3());
            0.5 * (b - a).cross(c - a).length()
        })
        .collect();
    let total: f64 = areas.iter().sum();
    let mut below_2_24 = 0;
    let mut c = 0.0f64;
    for (i, a) in areas.iter().enumerate() {
        let p = e.cdf.pmf_fine(i);
        assert!(
            (p * total / a - 1.0).abs() < 1e-5,
            "triangle {i}: probability {p:e} vs area share {:e}",
            a / total
        );
        if p < 1.0 / 16_777_216.0 {
            below_2_24 += 1;
        }
        let mid = (c + 0.5 * p) * 16_777_216.0;
        let u = glam::Vec2::new((mid.floor() / 16_777_216.0) as f32, mid.fract() as f32);
        assert_eq!(
            e.choose_triangle(u).0,
            i,
            "triangle {i} (p = {p:e}) cannot be chosen"
        );
        c += p;
    }
    assert!(below_2_24 > 0, "the mesh must have triangles below 2^-24");
}

// ---------------------------------------------------------------------------------------------
// Lobes of Blender's shader nodes: anisotropic GGX, rough dielectric, translucent, transparent,
// sheen, and the coat/sheen layering.

/// Anisotropic visible-normal density `G1(wi) max(0, wi·h) D(h) / wi.z`, all from the closed
/// forms in f64 (D and Λ with the stretched tangent), independent of the library's.
fn visible_normal_pdf_aniso_reference(wi: Vec3, h: Vec3, ax: f64, ay: f64) -> f64 {
    let (wi, h) = (wi.as_dvec3(), h.as_dvec3());
    if h.z <= 0.0 {
        return 0.0;
    }
    let l = (h.x / ax).powi(2) + (h.y / ay).powi(2) + h.z * h.z;
    let d = 1.0 / (PI * ax * ay * l * l);
    let lambda =
        0.5 * (-1.0 + (1.0 + ((ax * wi.x).powi(2) + (ay * wi.y).powi(2)) / (wi.z * wi.z)).sqrt());
    wi.dot(h).max(0.0) * d / ((1.0 + lambda) * wi.z)
}

#[test]
fn ggx_anisotropic_closed_forms_and_visible_normals() {
    // Isotropic alphas reproduce the isotropic functions.
    let mut rng = Sampler::new(1200, 0, 0);
    for _ in 0..2000 {
        let w = square_to_uniform_sphere(rng.next_2d());
        let w = Vec3::new(w.x, w.y, w.z.abs().max(1e-3)).normalize();
        for a in [0.05f32, 0.4, 1.0] {
            let (d, di) = (ggx_d_aniso(w, a, a), ggx_d(w, a));
            assert!((d - di).abs() <= 1e-4 * di + 1e-9, "D {d} vs {di}");
            assert!((ggx_g1_aniso(w, a, a) - ggx_g1(w, a)).abs() < 1e-6);
        }
    }
    let cases = [(0.05f32, 0.3f32), (0.4, 0.1), (0.9, 0.3), (1.0, 0.5)];
    let thetas = [0.0, 45.0, 80.0, 89.0];
    let alpha_case = sidak(SIGNIFICANCE, cases.len() * thetas.len());
    let mut seed = 1210;
    for &(ax, ay) in &cases {
        for &theta in &thetas {
            // Rotated in azimuth, so wi is not aligned with an axis of the anisotropy.
            let wi = dir_at(theta);
            let gamma = if ax.min(ay) < 0.2 { 2.0 } else { 1.0 };
            let grid = DirGrid::new(Vec3::Z, PI / 2.0, gamma, 30, 60);
            seed += 1;
            let r = check_directions(
                &format!("aniso visible normals ax={ax} ay={ay} θi={theta}°"),
                &grid,
                N / 2,
                seed,
                &mut |s| Some(sample_visible_normal_aniso(wi, ax, ay, s.next_2d())),
                &|h| visible_normal_pdf_aniso_reference(wi, h, ax as f64, ay as f64),
                alpha_case,
            );
            assert!((r.integral - 1.0).abs() < 2e-3, "∫D_wi = {}", r.integral);
        }
    }
}

#[test]
fn anisotropic_conductor_sampling() {
    let f0 = Vec3::new(0.9, 0.6, 0.3);
    let (gx, gy) = anisotropy::glossy(0.5, 0.8);
    let (px, py) = anisotropy::principled(0.3, 1.0);
    let lobes = [
        ("Glossy r=0.5 aniso=0.8", RoughConductor::glossy(f0, gx, gy)),
        (
            "F82 r=0.3 aniso=1",
            RoughConductor::f82(f0, Vec3::new(1.0, 0.5, 0.2), px, py),
        ),
        (
            "Schlick ax=0.6 ay=0.15",
            RoughConductor::with(0.6, 0.15, ConductorFresnel::Schlick(f0)),
        ),
    ];
    let thetas = [0.0, 50.0, 85.0];
    let alpha_case = sidak(SIGNIFICANCE, lobes.len() * thetas.len());
    let mut seed = 1300;
    for (name, b) in &lobes {
        for &theta in &thetas {
            let wi = dir_at(theta);
            seed += 1;
            let r = check_bsdf(
                &format!("RoughConductor {name} θi={theta}°"),
                b,
                wi,
                &DirGrid::new(mirror_dir(wi), PI, 1.5, 40, 60),
                seed,
                alpha_case,
            );
            assert!(r.integral <= 1.0 + 1e-3, "∫pdf = {}", r.integral);
            assert!((r.integral + r.rest_fraction - 1.0).abs() < 0.01);
        }
    }
}

/// The direction refracted from `wi` through the smooth interface (`ior` = inside/outside,
/// `wi.z < 0` leaving), or the mirror direction on total internal reflection.
fn refracted_or_mirror(wi: Vec3, ior: f32) -> Vec3 {
    let eta = if wi.z < 0.0 { 1.0 / ior } else { ior };
    let sin2 = (1.0 - wi.z * wi.z) / (eta * eta);
    if sin2 >= 1.0 {
        return mirror_dir(wi);
    }
    Vec3::new(
        -wi.x / eta,
        -wi.y / eta,
        -wi.z.signum() * (1.0 - sin2).sqrt(),
    )
    .normalize()
}

#[test]
fn rough_dielectric_sampling() {
    // Glass from outside (entering) and inside (leaving), IOR above and below 1 (0.8 models a
    // bubble), grazing incidence, tinted reflection vs refraction (the choice probability
    // follows the tints as in Cycles) and Principled's F0 tint.
    let tint = Vec3::new(0.9, 0.5, 0.2);
    let lobes = [
        (
            "glass 1.5 a=0.1",
            RoughDielectric::glass(Vec3::ONE, 1.5, 0.1),
        ),
        ("glass 1.5 a=0.5", RoughDielectric::glass(tint, 1.5, 0.5)),
        (
            "glass 1.33 a=1",
            RoughDielectric::glass(Vec3::ONE, 1.33, 1.0),
        ),
        (
            "glass 0.8 a=0.3",
            RoughDielectric::glass(Vec3::ONE, 0.8, 0.3),
        ),
        (
            "principled 2.4 a=0.25",
            RoughDielectric::principled_transmission(tint, Vec3::new(1.0, 0.3, 0.6), 2.4, 0.25),
        ),
        (
            "aniso reflection-only 1.5 ax=0.4 ay=0.1",
            RoughDielectric::reflection(tint, 1.5, 0.4, 0.1),
        ),
        (
            // A coloured film makes the reflect/refract choice differ per channel.
            "principled 1.5 a=0.2 under a 380 nm film",
            RoughDielectric::principled_transmission(tint, Vec3::ONE, 1.5, 0.2)
                .with_thin_film(ThinFilm::new(380.0, 1.33)),
        ),
    ];
    let thetas = [0.0f64, 60.0, 87.0, -30.0, -70.0];
    let alpha_case = sidak(SIGNIFICANCE, lobes.len() * thetas.len());
    let mut seed = 1400;
    for (name, b) in &lobes {
        for &theta in &thetas {
            let mut wi = dir_at(theta.abs());
            if theta < 0.0 {
                wi.z = -wi.z;
            }
            seed += 1;
            let centre = refracted_or_mirror(wi, b.ior);
            let gamma = if b.roughness.alpha_x < 0.2 { 2.0 } else { 1.0 };
            let r = check_bsdf(
                &format!("RoughDielectric {name} θi={theta}°"),
                b,
                wi,
                &DirGrid::new(centre, PI, gamma, 40, 60),
                seed,
                alpha_case,
            );
            assert!(r.integral <= 1.0 + 1e-3, "∫pdf = {}", r.integral);
            assert!((r.integral + r.rest_fraction - 1.0).abs() < 0.01);
        }
    }
}

#[test]
fn refraction_bsdf_sampling() {
    let lobes = [
        (
            "1.45 a=0.2",
            RoughDielectric::refraction(Vec3::ONE, 1.45, 0.2),
        ),
        (
            "1.45 a=0.8",
            RoughDielectric::refraction(Vec3::splat(0.5), 1.45, 0.8),
        ),
        (
            "0.7 a=0.4",
            RoughDielectric::refraction(Vec3::ONE, 0.7, 0.4),
        ),
    ];
    let thetas = [10.0f64, 75.0, -40.0, -80.0];
    let alpha_case = sidak(SIGNIFICANCE, lobes.len() * thetas.len());
    let mut seed = 1500;
    for (name, b) in &lobes {
        for &theta in &thetas {
            let mut wi = dir_at(theta.abs());
            if theta < 0.0 {
                wi.z = -wi.z;
            }
            seed += 1;
            let r = check_bsdf(
                &format!("Refraction {name} θi={theta}°"),
                b,
                wi,
                &DirGrid::new(refracted_or_mirror(wi, b.ior), PI, 1.0, 40, 60),
                seed,
                alpha_case,
            );
            assert!(r.integral <= 1.0 + 1e-3, "∫pdf = {}", r.integral);
        }
    }
}

/// A rough dielectric whose `pdf()` misses one factor `η` in the refraction Jacobian
/// `η² |wo·h| / (wi·h + η wo·h)²` (the error the chi-square test must catch).
struct BrokenJacobian(RoughDielectric);

impl Bsdf for BrokenJacobian {
    fn sample(&self, rec: &mut BsdfQueryRecord, u: Vec2, u1: f32) -> Vec3 {
        self.0.sample(rec, u, u1)
    }
    fn eval(&self, rec: &BsdfQueryRecord) -> Vec3 {
        self.0.eval(rec)
    }
    fn pdf(&self, rec: &BsdfQueryRecord) -> f32 {
        let p = self.0.pdf(rec);
        if rec.wi.z * rec.wo.z < 0.0 {
            let eta = if rec.wi.z < 0.0 {
                1.0 / self.0.ior
            } else {
                self.0.ior
            };
            p / eta
        } else {
            p
        }
    }
    fn is_delta(&self) -> bool {
        false
    }
}

#[test]
fn chi2_rejects_a_wrong_refraction_jacobian() {
    let b = BrokenJacobian(RoughDielectric::glass(Vec3::ONE, 1.5, 0.3));
    let wi = dir_at(40.0);
    let grid = DirGrid::new(refracted_or_mirror(wi, 1.5), PI, 1.0, 40, 60);
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        check_bsdf("broken Jacobian", &b, wi, &grid, 1600, SIGNIFICANCE)
    }));
    assert!(r.is_err(), "a pdf off by η on refraction passed the test");
}

#[test]
fn translucent_sampling() {
    let b = Translucent::new(Vec3::new(0.8, 0.5, 0.2));
    let thetas = [30.0f64, 89.0, -60.0];
    let alpha_case = sidak(SIGNIFICANCE, thetas.len());
    for (k, &theta) in thetas.iter().enumerate() {
        let mut wi = dir_at(theta.abs());
        if theta < 0.0 {
            wi.z = -wi.z;
        }
        let r = check_bsdf(
            &format!("Translucent θi={theta}°"),
            &b,
            wi,
            &DirGrid::sphere(40, 80),
            1702 + k as u64,
            alpha_case,
        );
        assert!((r.integral - 1.0).abs() < 1e-4, "∫pdf = {}", r.integral);
        assert_eq!(r.rest_fraction, 0.0);
    }
}

#[test]
fn transparent_passes_straight_through() {
    let c = Vec3::new(0.3, 0.6, 0.9);
    let b = Transparent::new(c);
    assert!(b.is_delta());
    let mut rng = Sampler::new(1750, 0, 0);
    for _ in 0..10_000 {
        let wi = square_to_uniform_sphere(rng.next_2d());
        let mut rec = BsdfQueryRecord::new(wi);
        let w = b.sample(&mut rec, rng.next_2d(), rng.next_1d());
        assert_eq!(w, c);
        assert_eq!(rec.wo, -wi);
        assert_eq!(rec.measure, Measure::Discrete);
        assert_eq!((rec.eta, rec.pdf), (1.0, 0.0));
        let pair = BsdfQueryRecord::pair(wi, rec.wo);
        assert_eq!((b.eval(&pair), b.pdf(&pair)), (Vec3::ZERO, 0.0));
    }
}

#[test]
fn sheen_sampling() {
    let rough = [0.05f32, 0.3, 0.6, 1.0];
    let thetas = [0.0, 45.0, 80.0, 88.0];
    let alpha_case = sidak(SIGNIFICANCE, rough.len() * thetas.len());
    let mut seed = 1800;
    for &r in &rough {
        for &theta in &thetas {
            let wi = dir_at(theta);
            let b = Sheen::new(Vec3::new(1.0, 0.8, 0.6), r);
            seed += 1;
            if b.albedo(wi) == Vec3::ZERO {
                // Cycles drops the lobe here (invalid LTC): sampling always fails.
                let mut rng = Sampler::new(seed, 0, 0);
                for _ in 0..1000 {
                    let mut rec = BsdfQueryRecord::new(wi);
                    assert_eq!(b.sample(&mut rec, rng.next_2d(), 0.5), Vec3::ZERO);
                }
                println!("Sheen r={r} θi={theta}°: dropped (albedo 0)");
                continue;
            }
            let res = check_bsdf(
                &format!("Sheen r={r} θi={theta}°"),
                &b,
                wi,
                &DirGrid::sphere(40, 80),
                seed,
                alpha_case,
            );
            assert!((res.integral - 1.0).abs() < 2e-3, "∫pdf = {}", res.integral);
        }
    }
}

#[test]
fn layered_sampling() {
    let base = Diffuse::new(Vec3::new(0.7, 0.3, 0.1));
    let metal = RoughConductor::f82(Vec3::new(0.9, 0.6, 0.4), Vec3::ONE, 0.4, 0.4);
    let coat = Coat::new(1.0, 0.2, 1.5, Vec3::new(0.9, 0.7, 0.5));
    let rough_coat = Coat::new(0.6, 0.7, 1.8, Vec3::ONE);
    let sheen = Sheen::new(Vec3::splat(0.8), 0.5);
    let smooth_coat = Coat::new(1.0, 0.0, 1.5, Vec3::ONE);
    let lobes: Vec<(&str, Box<dyn Bsdf>)> = vec![
        ("coat over diffuse", Box::new(Layered::new(coat, base))),
        (
            "rough coat over metal",
            Box::new(Layered::new(rough_coat, metal)),
        ),
        (
            "sheen over coat over diffuse",
            Box::new(Layered::new(sheen, Layered::new(coat, base))),
        ),
        (
            "smooth coat over diffuse",
            Box::new(Layered::new(smooth_coat, base)),
        ),
    ];
    let thetas = [10.0, 60.0, 86.0];
    let alpha_case = sidak(SIGNIFICANCE, lobes.len() * thetas.len());
    let mut seed = 1900;
    for (name, b) in &lobes {
        for &theta in &thetas {
            let wi = dir_at(theta);
            seed += 1;
            let r = check_bsdf(
                &format!("Layered {name} θi={theta}°"),
                b.as_ref(),
                wi,
                &DirGrid::new(mirror_dir(wi), PI, 1.5, 40, 60),
                seed,
                alpha_case,
            );
            assert!(r.integral <= 1.0 + 1e-3, "∫pdf = {}", r.integral);
        }
    }
}

#[test]
fn toon_sampling() {
    // Diffuse Toon: a cone about the normal; Glossy Toon: about the mirror direction, clipped
    // by the horizon at grazing views (the clipped samples fall in the rest bin).
    let cases = [
        (false, 0.5, 0.0, 40.0),
        (false, 0.3, 0.4, 70.0),
        (false, 0.9, 0.5, 20.0),
        (true, 0.2, 0.1, 30.0),
        (true, 0.4, 0.3, 75.0),
        (true, 0.05, 0.0, 50.0),
    ];
    let alpha_case = sidak(SIGNIFICANCE, cases.len());
    for (k, &(glossy, size, smooth, theta)) in cases.iter().enumerate() {
        let b = Toon::new(Vec3::new(0.8, 0.5, 0.2), size, smooth, glossy);
        let r = check_bsdf(
            &format!("Toon glossy={glossy} size={size} smooth={smooth} θi={theta}°"),
            &b,
            dir_at(theta),
            &DirGrid::sphere(60, 120),
            2900 + k as u64,
            alpha_case,
        );
        if !glossy {
            assert!((r.integral - 1.0).abs() < 2e-3, "∫pdf = {}", r.integral);
            assert_eq!(r.rest_fraction, 0.0);
        }
    }
}

/// Cycles' Chiang hair: the sampled directions against `pdf()` over the whole sphere (the lobe
/// reflects and transmits around the fibre), for rough and fairly smooth fibres, centred and
/// grazing offsets `h`, with and without the cuticle tilt (whose folding over the poles the
/// density includes), a coat that sharpens R, and absorption that moves the lobe choice.
#[test]
fn chiang_hair_sampling() {
    // (sigma_a, roughness, radial roughness, coat, alpha, h, θi)
    let cases: [(Vec3, f32, f32, f32, f32, f32, f64); 7] = [
        (Vec3::ZERO, 0.6, 0.7, 0.0, 0.0, 0.0, 30.0),
        (Vec3::ZERO, 0.3, 0.3, 0.0, 0.035, 0.5, 60.0),
        (Vec3::new(0.3, 0.8, 2.0), 0.2, 0.25, 0.0, 0.1, -0.8, 20.0),
        (Vec3::splat(0.1), 0.15, 0.2, 0.5, 0.035, 0.2, 75.0),
        (Vec3::ZERO, 0.4, 0.5, 0.0, 0.3, 0.9, 85.0),
        (Vec3::splat(2.0), 1.0, 1.0, 0.0, -0.1, -0.3, 0.0),
        (Vec3::ZERO, 0.12, 0.15, 0.0, 0.0, 0.99, 45.0),
    ];
    let alpha_case = sidak(SIGNIFICANCE, cases.len());
    for (k, &(sigma, r, rr, coat, alpha, h, theta)) in cases.iter().enumerate() {
        let b = ChiangHair::new(sigma, r, rr, coat, 1.55, alpha, h);
        let wi = dir_at(theta);
        let name = format!("Chiang hair r={r} rr={rr} coat={coat} α={alpha} h={h} θi={theta}°");
        let res = check_bsdf(
            &name,
            &b,
            wi,
            &DirGrid::sphere(60, 120),
            1900 + k as u64,
            alpha_case,
        );
        assert!(
            (res.integral - 1.0).abs() < 3e-3,
            "{name}: ∫pdf = {}",
            res.integral
        );
    }
}

/// The test has the power to see a tilt of 2° (Blender's default Offset): samples of a tilted
/// fibre are rejected against the density of the same fibre untilted.
#[test]
fn chi2_rejects_hair_samples_of_another_tilt() {
    let tilted = ChiangHair::new(Vec3::ZERO, 0.3, 0.3, 0.0, 1.55, 2f32.to_radians(), 0.3);
    let flat = ChiangHair::new(Vec3::ZERO, 0.3, 0.3, 0.0, 1.55, 0.0, 0.3);
    let wi = dir_at(50.0);
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        check_directions(
            "hair tilted 2° against untilted",
            &DirGrid::sphere(60, 120),
            N / 2,
            1950,
            &mut |s| {
                let mut rec = BsdfQueryRecord::new(wi);
                let w = tilted.sample(&mut rec, s.next_2d(), s.next_1d());
                (w.max_element() > 0.0).then_some(rec.wo)
            },
            &|wo| flat.pdf(&BsdfQueryRecord::pair(wi, wo)) as f64,
            SIGNIFICANCE,
        )
    }));
    assert!(r.is_err(), "a 2° tilt passed unseen");
}

// ---------------------------------------------------------------------------------------------
// Beckmann (Blender's Glossy, Glass and Refraction BSDFs offer it): visible normals, and the
// lobes built on them.

#[test]
fn beckmann_visible_normals_and_masking() {
    use tesela::bsdf::microfacet::{Distribution, Roughness};
    // (alpha_x, alpha_y): isotropic and anisotropic, narrow to very rough.
    let rough = [(0.08f32, 0.08f32), (0.3, 0.3), (1.0, 1.0), (0.5, 0.1)];
    let thetas = [0.0, 45.0, 75.0, 89.0];
    let alpha_case = sidak(SIGNIFICANCE, rough.len() * thetas.len());
    let mut seed = 1700;
    for &(ax, ay) in &rough {
        let r = Distribution {
            roughness: Roughness::new(ax, ay),
            beckmann: true,
        };
        for &theta in &thetas {
            let wi = dir_at(theta);
            let gamma = if ax.min(ay) < 0.2 { 2.0 } else { 1.0 };
            let grid = DirGrid::new(Vec3::Z, PI / 2.0, gamma, 30, 60);
            seed += 1;
            let res = check_directions(
                &format!("Beckmann visible normals α=({ax}, {ay}) θi={theta}°"),
                &grid,
                N / 2,
                seed,
                &mut |s| Some(r.sample_visible_normal(wi, s.next_2d())),
                &|h| r.visible_normal_pdf(wi, h) as f64,
                alpha_case,
            );
            // ∫ G1(wi) (wi·h) D(h) / wi.z dh = 1 holds only with the exact Smith Λ.
            assert!(
                (res.integral - 1.0).abs() < 2e-3,
                "∫D_wi = {}",
                res.integral
            );
        }
    }
}

#[test]
fn beckmann_lobes_sampling() {
    let tint = Vec3::new(0.9, 0.6, 0.3);
    let conductors = [
        ("a=0.2", RoughConductor::new(tint, 0.2).with_beckmann(true)),
        (
            "ax=0.6 ay=0.15",
            RoughConductor::with(0.6, 0.15, ConductorFresnel::Constant(tint)).with_beckmann(true),
        ),
    ];
    let dielectrics = [
        (
            "glass 1.5 a=0.3",
            RoughDielectric::glass(Vec3::ONE, 1.5, 0.3).with_beckmann(true),
        ),
        (
            "refraction 1.45 a=0.5",
            RoughDielectric::refraction(Vec3::ONE, 1.45, 0.5).with_beckmann(true),
        ),
    ];
    let alpha_case = sidak(SIGNIFICANCE, 2 * 2 + 2 * 3);
    let mut seed = 1800;
    for (name, b) in &conductors {
        for theta in [10.0, 70.0] {
            let wi = dir_at(theta);
            seed += 1;
            let gamma = if b.roughness.alpha_y < 0.2 { 2.0 } else { 1.0 };
            let r = check_bsdf(
                &format!("Beckmann conductor {name} θi={theta}°"),
                b,
                wi,
                &DirGrid::new(mirror_dir(wi), PI, gamma, 40, 60),
                seed,
                alpha_case,
            );
            assert!(r.integral <= 1.0 + 1e-3, "∫pdf = {}", r.integral);
            assert!((r.integral + r.rest_fraction - 1.0).abs() < 0.01);
        }
    }
    for (name, b) in &dielectrics {
        for theta in [10.0f64, 70.0, -40.0] {
            let mut wi = dir_at(theta.abs());
            if theta < 0.0 {
                wi.z = -wi.z;
            }
            seed += 1;
            let r = check_bsdf(
                &format!("Beckmann {name} θi={theta}°"),
                b,
                wi,
                &DirGrid::new(refracted_or_mirror(wi, b.ior), PI, 1.0, 40, 60),
                seed,
                alpha_case,
            );
            assert!(r.integral <= 1.0 + 1e-3, "∫pdf = {}", r.integral);
            assert!((r.integral + r.rest_fraction - 1.0).abs() < 0.01);
        }
    }
}
