//! Consistency of every sampling routine with its own density and value: the pdf that `sample`
//! reports equals `pdf()` on the sampled direction (relative 1e-3), and the returned weight is
//! `eval · |cos| / pdf` for BSDFs and `eval / pdf` for emitters. Delta BSDFs and lights have
//! `pdf() = 0` and `eval() = 0`. Plus the fallbacks of mesh emitters: no vertex normals, and
//! one-sided emission.

use glam::{Vec2, Vec3};
use tesela::bsdf::microfacet::anisotropy;
use tesela::bsdf::thin_film::ThinFilm;
use tesela::bsdf::{
    BaseLobe, Bsdf, BsdfInstance, BsdfQueryRecord, ChiangHair, Coat, ConductorFresnel, Dielectric,
    Diffuse, Layered, Measure, Mirror, Plastic, RoughConductor, RoughDielectric, Sheen,
    SurfaceParams, Toon, TopLobe, Translucent, Transparent, choose,
};
use tesela::emitter::{
    AreaEmitter, Directional, Emitter, EmitterInstance, EmitterQueryRecord, LightChoice,
    PointLight, SpotLight,
};
use tesela::render_scene::RenderScene;
use tesela::sampler::Sampler;
use tesela::sampling::square_to_uniform_sphere;
use tesela::scene::builtin::{quad, sphere};
use tesela::scene::{Light, LightProfile, LightShape, Material, Mesh, Scene, SpotFalloff};

const REL: f32 = 1e-3;

fn close(a: f32, b: f32, rel: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + 1e-12
}

fn close3(a: Vec3, b: Vec3, rel: f32) -> bool {
    (a - b).abs().max_element() <= rel * a.abs().max(b.abs()).max_element() + 1e-12
}

/// Random incident directions over the whole sphere, with extra grazing and normal ones.
fn incident(rng: &mut Sampler, k: usize) -> Vec3 {
    match k % 8 {
        0 => {
            let w = square_to_uniform_sphere(rng.next_2d());
            Vec3::new(w.x, w.y, 0.002 * w.z.signum()).normalize()
        }
        1 => Vec3::new(1e-4, -2e-4, 1.0).normalize(),
        _ => square_to_uniform_sphere(rng.next_2d()),
    }
}

/// Samples `bsdf` many times and checks each sample against `pdf()` and `eval()`.
/// Returns the number of non-delta samples checked.
fn check_bsdf(name: &str, bsdf: &dyn Bsdf, seed: u64) -> usize {
    let mut rng = Sampler::new(seed, 0, 0);
    let mut checked = 0;
    for k in 0..20_000 {
        let wi = incident(&mut rng, k);
        let mut rec = BsdfQueryRecord::new(wi);
        let w = bsdf.sample(&mut rec, rng.next_2d(), rng.next_1d());
        assert!(
            w.is_finite() && w.min_element() >= 0.0,
            "{name}: weight {w}"
        );
        if w == Vec3::ZERO {
            continue;
        }
        // Every BSDF here reflects only on the +Z side; only a diffuse lobe is lit there
        // for a viewer below its normal too (Cycles' diffuse closure ignores wi).
        assert!(
            (wi.z > 0.0 || name.starts_with("Diffuse")) && rec.wo.z > 0.0,
            "{name}: wi {wi} wo {}",
            rec.wo
        );
        assert!(
            (rec.wo.length() - 1.0).abs() < 1e-4,
            "{name}: |wo| = {}",
            rec.wo.length()
        );
        let pair = BsdfQueryRecord::pair(wi, rec.wo);
        match rec.measure {
            Measure::SolidAngle => {
                let pdf = bsdf.pdf(&pair);
                assert!(
                    rec.pdf > 0.0 && rec.pdf.is_finite(),
                    "{name}: rec.pdf {}",
                    rec.pdf
                );
                assert!(
                    close(rec.pdf, pdf, REL),
                    "{name}: sample reports pdf {} but pdf() = {pdf} (wi {wi}, wo {})",
                    rec.pdf,
                    rec.wo
                );
                let want = bsdf.eval(&pair) * rec.wo.z.abs() / pdf;
                assert!(
                    close3(w, want, REL),
                    "{name}: weight {w} but eval·cos/pdf = {want} (wi {wi}, wo {})",
                    rec.wo
                );
                checked += 1;
            }
            Measure::Discrete => assert_eq!(rec.pdf, 0.0, "{name}: delta sample with a pdf"),
        }
    }
    println!("{name}: {checked} samples checked");
    checked
}

#[test]
fn bsdf_sample_pdf_and_weight_agree() {
    let c = Vec3::new(0.9, 0.5, 0.2);
    let mut seed = 1;
    let mut run = |name: String, b: &dyn Bsdf| {
        seed += 1;
        assert!(!b.is_delta(), "{name}");
        assert!(
            check_bsdf(&name, b, seed) > 1000,
            "{name}: too few samples checked"
        );
    };
    run("Diffuse".into(), &Diffuse::new(c));
    for sigma in [0.3f32, 1.0] {
        run(
            format!("Diffuse (Oren-Nayar) sigma={sigma}"),
            &Diffuse::oren_nayar(c, sigma, c),
        );
    }
    for alpha in [0.0f32, 0.002, 0.02, 0.1, 0.4, 1.0] {
        run(
            format!("RoughConductor alpha={alpha}"),
            &RoughConductor::new(c, alpha),
        );
    }
    for (alpha, ior, spec, color) in [
        (0.0f32, 1.5f32, 1.0f32, Vec3::ONE),
        (0.0, 2.0, 0.5, Vec3::new(1.0, 0.4, 0.2)),
        (0.01, 1.5, 1.0, Vec3::ONE),
        (0.2, 1.45, 1.0, Vec3::ONE),
        (0.6, 2.5, 0.3, Vec3::new(0.2, 0.9, 0.5)),
        (1.0, 1.5, 1.0, Vec3::ONE),
    ] {
        run(
            format!("Plastic alpha={alpha} ior={ior} specular={spec}"),
            &Plastic::new(c, alpha, ior, spec, color),
        );
    }
    for (alpha, eta, tint) in [
        (0.0f32, 1.5f32, Vec3::ZERO),
        (0.3, 1.45, Vec3::new(1.0, 0.4, 0.0)),
    ] {
        run(
            format!("Cycles Plastic alpha={alpha} eta={eta} tint={tint}"),
            &Plastic::cycles(c, alpha, eta, tint),
        );
    }
}

/// Like [`check_bsdf`] for lobes that may transmit and may be seen from either side: sampled
/// reflections stay on `wi`'s side and refractions cross; `eta` is 1 for reflections.
fn check_any_bsdf(name: &str, bsdf: &dyn Bsdf, seed: u64, wi_below: bool) -> usize {
    let mut rng = Sampler::new(seed, 0, 0);
    let mut checked = 0;
    for k in 0..20_000 {
        let mut wi = incident(&mut rng, k);
        if !wi_below {
            wi.z = wi.z.abs();
        }
        let mut rec = BsdfQueryRecord::new(wi);
        let w = bsdf.sample(&mut rec, rng.next_2d(), rng.next_1d());
        assert!(
            w.is_finite() && w.min_element() >= 0.0,
            "{name}: weight {w}"
        );
        if w == Vec3::ZERO {
            continue;
        }
        assert!(
            (rec.wo.length() - 1.0).abs() < 1e-4,
            "{name}: |wo| = {}",
            rec.wo.length()
        );
        if rec.wo.z * wi.z > 0.0 {
            assert_eq!(rec.eta, 1.0, "{name}: reflection with eta {}", rec.eta);
        }
        let pair = BsdfQueryRecord::pair(wi, rec.wo);
        match rec.measure {
            Measure::SolidAngle => {
                let pdf = bsdf.pdf(&pair);
                assert!(
                    rec.pdf > 0.0 && rec.pdf.is_finite(),
                    "{name}: rec.pdf {}",
                    rec.pdf
                );
                assert!(
                    close(rec.pdf, pdf, REL),
                    "{name}: sample reports pdf {} but pdf() = {pdf} (wi {wi}, wo {})",
                    rec.pdf,
                    rec.wo
                );
                let want = bsdf.eval(&pair) * rec.wo.z.abs() / pdf;
                assert!(
                    close3(w, want, REL),
                    "{name}: weight {w} but eval·cos/pdf = {want} (wi {wi}, wo {})",
                    rec.wo
                );
                checked += 1;
            }
            Measure::Discrete => assert_eq!(rec.pdf, 0.0, "{name}: delta sample with a pdf"),
        }
    }
    println!("{name}: {checked} samples checked");
    checked
}

#[test]
fn blender_lobes_sample_pdf_and_weight_agree() {
    let c = Vec3::new(0.9, 0.5, 0.2);
    let mut seed = 300;
    let mut run = |name: String, b: &dyn Bsdf, wi_below: bool| {
        seed += 1;
        assert!(!b.is_delta(), "{name}");
        // Index-matched glass (IOR 1.00005) refracts as a delta: almost nothing to check.
        let min = if name.contains("1.00005") { 0 } else { 1000 };
        assert!(
            check_any_bsdf(&name, b, seed, wi_below) >= min,
            "{name}: too few samples checked"
        );
    };
    for (r, a) in [(0.2f32, 0.5f32), (0.6, -0.7), (1.0, 0.99), (0.05, 0.3)] {
        let (ax, ay) = anisotropy::glossy(r, a);
        run(
            format!("Glossy r={r} a={a}"),
            &RoughConductor::glossy(c, ax, ay),
            false,
        );
        let (ax, ay) = anisotropy::principled(r, a.abs());
        run(
            format!("F82 r={r} a={a}"),
            &RoughConductor::f82(c, Vec3::new(0.2, 0.9, 1.0), ax, ay),
            false,
        );
    }
    for (ior, alpha) in [
        (1.5f32, 0.002f32),
        (1.5, 0.1),
        (1.33, 0.6),
        (2.4, 1.0),
        (0.75, 0.3),
        (1.00005, 0.3),
    ] {
        run(
            format!("Glass ior={ior} alpha={alpha}"),
            &RoughDielectric::glass(c, ior, alpha),
            true,
        );
        run(
            format!("Principled transmission ior={ior} alpha={alpha}"),
            &RoughDielectric::principled_transmission(c, Vec3::new(1.0, 0.2, 0.5), ior, alpha),
            true,
        );
        run(
            format!("Principled transmission under a film ior={ior} alpha={alpha}"),
            &RoughDielectric::principled_transmission(c, Vec3::new(1.0, 0.2, 0.5), ior, alpha)
                .with_thin_film(ThinFilm::new(450.0, 1.4)),
            true,
        );
        run(
            format!("specular over diffuse under a film ior={ior} alpha={alpha}"),
            &Layered::new(
                RoughDielectric::principled_specular(c, ior, alpha, alpha)
                    .with_thin_film(ThinFilm::new(250.0, 1.8))
                    .multiscatter(),
                Diffuse::new(c),
            ),
            false,
        );
        run(
            format!("Refraction ior={ior} alpha={alpha}"),
            &RoughDielectric::refraction(c, ior, alpha),
            true,
        );
        run(
            format!("dielectric reflection ior={ior} alpha={alpha}"),
            &RoughDielectric::reflection(c, ior, alpha, 0.5 * alpha),
            false,
        );
    }
    for alpha in [0.01f32, 0.2, 0.7, 1.0] {
        run(
            format!("multiscatter F82 alpha={alpha}"),
            &RoughConductor::f82(c, Vec3::new(0.5, 0.8, 1.0), alpha, 0.6 * alpha).multiscatter(),
            false,
        );
        run(
            format!("multiscatter Glossy alpha={alpha}"),
            &RoughConductor::glossy(c, alpha, alpha).multiscatter(),
            false,
        );
        for ior in [1.5f32, 0.7] {
            run(
                format!("multiscatter glass ior={ior} alpha={alpha}"),
                &RoughDielectric::glass(c, ior, alpha).multiscatter(),
                true,
            );
        }
        run(
            format!("multiscatter specular over diffuse alpha={alpha}"),
            &Layered::new(
                RoughDielectric::principled_specular(c, 1.5, alpha, alpha).multiscatter(),
                Diffuse::new(c),
            ),
            false,
        );
    }
    run("Translucent".into(), &Translucent::new(c), true);
    for glossy in [false, true] {
        run(
            format!("Toon glossy={glossy}"),
            &Toon::new(c, 0.3, 0.2, glossy),
            false,
        );
    }
    for r in [0.01f32, 0.2, 0.5, 1.0] {
        run(format!("Sheen r={r}"), &Sheen::new(c, r), false);
    }
    let base = Diffuse::new(c);
    let metal = RoughConductor::f82(c, Vec3::ONE, 0.3, 0.3);
    for (w, r, ior, tint) in [
        (1.0f32, 0.0f32, 1.5f32, Vec3::ONE),
        (1.0, 0.3, 1.5, Vec3::new(0.9, 0.6, 0.3)),
        (0.4, 0.9, 2.0, Vec3::ONE),
    ] {
        let coat = Coat::new(w, r, ior, tint);
        run(
            format!("coat {w} {r} over diffuse"),
            &Layered::new(coat, base),
            false,
        );
        run(
            format!("coat {w} {r} over metal"),
            &Layered::new(coat, metal),
            false,
        );
        run(
            format!("sheen over coat {w} {r} over diffuse"),
            &Layered::new(Sheen::new(c, 0.5), Layered::new(coat, base)),
            false,
        );
    }
    // Through the enum: a coat over rough glass, seen from both sides.
    let glass = RoughDielectric::principled_transmission(c, Vec3::ONE, 1.5, 0.2);
    let b = BsdfInstance::Layered(Layered::new(
        TopLobe::Coat(Coat::new(1.0, 0.2, 1.5, Vec3::ONE)),
        BaseLobe::RoughDielectric(glass),
    ));
    assert!(b.is_transmissive());
    run("Layered coat over glass".into(), &b, true);
}

/// Reciprocity where it holds: `f(wi, wo) = f(wo, wi)` for the conductors, dielectric
/// reflection and translucency; for refraction, in Tesela's convention (no `1/η²` radiance
/// scaling), `f(wi, wo) = (η_o/η_i)² f(wo, wi)`. (The sheen LTC is not reciprocal, in Cycles
/// either: its lobe is fitted per `wi`.)
#[test]
fn bsdf_reciprocity() {
    let mut rng = Sampler::new(400, 0, 0);
    let c = Vec3::new(0.9, 0.5, 0.2);
    let (ax, ay) = anisotropy::principled(0.5, 0.7);
    let reflective: Vec<(&str, Box<dyn Bsdf>)> = vec![
        ("Glossy aniso", Box::new(RoughConductor::glossy(c, ax, ay))),
        (
            "F82 aniso",
            Box::new(RoughConductor::f82(c, Vec3::new(0.3, 0.8, 1.0), ax, ay)),
        ),
        (
            "Schlick",
            Box::new(RoughConductor::with(0.3, 0.3, ConductorFresnel::Schlick(c))),
        ),
        (
            "dielectric reflection",
            Box::new(RoughDielectric::reflection(c, 1.5, ax, ay)),
        ),
        ("Translucent", Box::new(Translucent::new(c))),
    ];
    let glass: Vec<(&str, RoughDielectric)> = vec![
        ("Glass 1.5", RoughDielectric::glass(c, 1.5, 0.3)),
        ("Glass 0.8", RoughDielectric::glass(Vec3::ONE, 0.8, 0.7)),
        (
            "Principled 1.33",
            RoughDielectric::principled_transmission(c, c, 1.33, 0.2),
        ),
    ];
    let mut n_refr = 0;
    for _ in 0..20_000 {
        let wi = square_to_uniform_sphere(rng.next_2d());
        let wo = square_to_uniform_sphere(rng.next_2d());
        for (name, b) in &reflective {
            let (f1, f2) = (
                b.eval(&BsdfQueryRecord::pair(wi, wo)),
                b.eval(&BsdfQueryRecord::pair(wo, wi)),
            );
            assert!(
                close3(f1, f2, 1e-3),
                "{name}: f(wi,wo) {f1} vs f(wo,wi) {f2}"
            );
        }
        for (name, b) in &glass {
            let (f1, f2) = (
                b.eval(&BsdfQueryRecord::pair(wi, wo)),
                b.eval(&BsdfQueryRecord::pair(wo, wi)),
            );
            let scale = if wi.z * wo.z < 0.0 {
                n_refr += (f1 != Vec3::ZERO) as usize;
                // η_o / η_i, with wo on the side that wi.z's sign says.
                let eta = if wi.z > 0.0 { b.ior } else { 1.0 / b.ior };
                eta * eta
            } else {
                1.0
            };
            // Refraction recomputes the half vector from either end in f32: near the critical
            // angle 1 - F is sensitive to it.
            let tol = if scale == 1.0 { 1e-3 } else { 1e-2 };
            assert!(
                close3(f1, f2 * scale, tol) || (f1 - f2 * scale).abs().max_element() < 1e-5,
                "{name}: f(wi,wo) {f1} vs η²·f(wo,wi) {} (wi {wi}, wo {wo})",
                f2 * scale
            );
        }
    }
    assert!(n_refr > 1000, "too few refraction pairs: {n_refr}");
}

#[test]
fn transparent_is_delta_pass_through() {
    let b = Transparent::new(Vec3::new(0.2, 0.4, 0.6));
    assert!(b.is_delta());
    let mut rng = Sampler::new(500, 0, 0);
    for k in 0..1000 {
        let wi = incident(&mut rng, k);
        let mut rec = BsdfQueryRecord::new(wi);
        let w = b.sample(&mut rec, rng.next_2d(), rng.next_1d());
        assert_eq!(
            (w, rec.wo, rec.eta, rec.measure),
            (b.color, -wi, 1.0, Measure::Discrete)
        );
        assert_eq!(b.pdf(&BsdfQueryRecord::pair(wi, -wi)), 0.0);
        assert_eq!(b.eval(&BsdfQueryRecord::pair(wi, -wi)), Vec3::ZERO);
    }
}

#[test]
fn chosen_bsdf_instances_agree() {
    // The same checks through `choose` and the enum dispatch the integrators use.
    let mut seed = 100;
    for (metallic, roughness, transmission, specular) in [
        (0.0f32, 0.5f32, 0.0f32, 1.0f32),
        (0.0, 0.0, 0.0, 1.0),
        (0.0, 0.7, 0.0, 0.0),
        (1.0, 0.3, 0.0, 1.0),
        (1.0, 0.9, 0.0, 1.0),
        (0.0, 0.4, 1.0, 1.0),
    ] {
        let p = SurfaceParams {
            base_color: Vec3::new(0.8, 0.6, 0.4),
            metallic,
            roughness,
            transmission,
            ior: 1.5,
            specular,
            specular_color: Vec3::ONE,
        };
        let b = choose(&p, 0.5);
        seed += 1;
        if b.is_transmissive() {
            assert!(matches!(b, BsdfInstance::RoughDielectric(_)), "{b:?}");
            check_any_bsdf(&format!("{b:?}"), &b, seed, true);
        } else {
            check_bsdf(&format!("{b:?}"), &b, seed);
        }
    }
}

#[test]
fn delta_bsdfs_have_no_density_and_no_value() {
    let mut rng = Sampler::new(200, 0, 0);
    let bsdfs: Vec<(&str, Box<dyn Bsdf>)> = vec![
        ("Mirror", Box::new(Mirror::new(Vec3::new(0.9, 0.7, 0.5)))),
        ("Dielectric 1.5", Box::new(Dielectric::new(1.5, Vec3::ONE))),
        (
            "Dielectric 0.7",
            Box::new(Dielectric::new(0.7, Vec3::splat(0.5))),
        ),
    ];
    for (name, b) in &bsdfs {
        assert!(b.is_delta(), "{name}");
        for k in 0..5000 {
            let wi = incident(&mut rng, k);
            let mut rec = BsdfQueryRecord::new(wi);
            let w = b.sample(&mut rec, rng.next_2d(), rng.next_1d());
            if w != Vec3::ZERO {
                assert_eq!(rec.measure, Measure::Discrete, "{name}");
                assert_eq!(rec.pdf, 0.0, "{name}");
                let pair = BsdfQueryRecord::pair(wi, rec.wo);
                assert_eq!(b.pdf(&pair), 0.0, "{name}: pdf on the sampled direction");
                assert_eq!(
                    b.eval(&pair),
                    Vec3::ZERO,
                    "{name}: eval on the sampled direction"
                );
            }
            let other = BsdfQueryRecord::pair(wi, square_to_uniform_sphere(rng.next_2d()));
            assert_eq!(b.pdf(&other), 0.0, "{name}");
            assert_eq!(b.eval(&other), Vec3::ZERO, "{name}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Emitters.

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// Triangles without vertex normals.
fn bare_mesh(name: &str, material: usize, tris: &[[Vec3; 3]]) -> Mesh {
    let mut m = Mesh {
        name: name.into(),
        material,
        ..Default::default()
    };
    for t in tris {
        let b = m.positions.len() as u32;
        m.positions.extend(t);
        m.indices.push([b, b + 1, b + 2]);
    }
    m
}

fn emitter_scene() -> Scene {
    let mut s = Scene {
        materials: vec![
            Material::diffuse("floor", Vec3::splat(0.5)),
            Material::emitter("one-sided", v(4.0, 3.0, 2.0), false),
            Material::emitter("two-sided", v(1.0, 2.0, 3.0), true),
        ],
        background: v(0.1, 0.2, 0.3),
        ..Default::default()
    };
    s.meshes.push(quad(
        "floor",
        0,
        v(-3., 0., 3.),
        v(3., 0., 3.),
        v(3., 0., -3.),
        v(-3., 0., -3.),
    ));
    // One-sided quad facing down, flat normals.
    s.meshes.push(quad(
        "ceiling light",
        1,
        v(-0.5, 2., -0.5),
        v(0.5, 2., -0.5),
        v(0.5, 2., 0.5),
        v(-0.5, 2., 0.5),
    ));
    // Smooth-shaded sphere: shading normals differ from the facets' geometric normals.
    s.meshes
        .push(sphere("bulb", 2, v(1.5, 1.0, 0.0), 0.3, 6, 12));
    s.meshes
        .push(sphere("one-sided bulb", 1, v(-1.5, 1.0, 0.5), 0.25, 5, 10));
    // Triangles without normals, tilted and of unequal size.
    s.meshes.push(bare_mesh(
        "bare",
        1,
        &[
            [v(0., 0.5, -2.), v(1., 0.6, -2.), v(0.2, 1.5, -1.8)],
            [v(-1., 0.5, -2.), v(-0.5, 0.5, -1.9), v(-0.9, 0.7, -2.)],
        ],
    ));
    s.lights = vec![
        Light::Directional {
            direction: v(0.2, -1.0, 0.1),
            irradiance: v(2., 2., 2.),
            angle: 0.3,
        },
        Light::Directional {
            direction: v(-0.3, -1.0, 0.4),
            irradiance: v(1., 1., 1.),
            angle: 3.0,
        },
        Light::Point {
            position: v(0., 1.5, 0.),
            intensity: v(5., 5., 5.),
        },
        Light::Spot {
            position: v(1., 1.8, 1.),
            direction: v(0., -1., 0.),
            intensity: v(8., 6., 4.),
            falloff: SpotFalloff::Gltf {
                cos_inner: 0.95,
                cos_outer: 0.8,
            },
        },
        Light::Directional {
            direction: v(0., -1., 0.),
            irradiance: v(3., 3., 3.),
            angle: 0.0,
        },
    ];
    // A ball and a panel shaped by an asymmetric IES profile, tilted: light sampling and rays
    // that hit them must see the same profile.
    let ies = "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 3 3 1 2 0 0 0\n1 1 10\n0 60 180\n0 90 180\n\
               50 30 5\n80 20 10\n10 5 1\n";
    let profile = |rx: f32| {
        Some(LightProfile {
            profile: std::sync::Arc::new(tesela::emitter::ies::IesProfile::parse(ies).unwrap()),
            to_local: glam::Mat3::from_rotation_x(rx),
        })
    };
    s.lights.push(Light::Blender {
        shape: LightShape::Point {
            position: v(-1.0, 1.6, 1.0),
            intensity: v(0.2, 0.2, 0.2),
            radius: 0.2,
            soft_falloff: false,
            spot: None,
        },
        visibility: Default::default(),
        profile: profile(0.4),
    });
    s.lights.push(Light::Blender {
        shape: LightShape::Area {
            center: v(0.5, 3.6, -1.0),
            axis_u: v(1., 0., 0.),
            axis_v: v(0., 0., 1.),
            normal: v(0., -1., 0.),
            size_u: 0.5,
            size_v: 0.3,
            ellipse: false,
            radiance: v(0.1, 0.1, 0.1),
            spread: std::f32::consts::PI,
        },
        visibility: Default::default(),
        profile: profile(-1.2),
    });
    s
}

/// The record the integrators rebuild for MIS when a BSDF-sampled ray hits the emitter at the
/// sampled point (or leaves the scene in the sampled direction).
fn rebuilt(e: &EmitterInstance, rec: &EmitterQueryRecord) -> EmitterQueryRecord {
    match e.shape() {
        EmitterInstance::Area(_) => {
            let mut back = EmitterQueryRecord::between(rec.ref_p, rec.p, rec.n, rec.ng, rec.uv);
            (back.tri, back.bary) = (rec.tri, rec.bary);
            back
        }
        // As `RenderScene::lights_on_ray` records a hit on a light's shape.
        EmitterInstance::AreaLight(_) => EmitterQueryRecord {
            ref_p: rec.ref_p,
            p: rec.p,
            n: rec.n,
            ng: rec.ng,
            wi: rec.wi,
            dist: rec.dist,
            ..Default::default()
        },
        _ => EmitterQueryRecord::towards(rec.ref_p, rec.wi),
    }
}

#[test]
fn emitter_sample_pdf_and_weight_agree() {
    let rs = RenderScene::new(emitter_scene(), LightChoice::Power);
    let scene = &rs.scene;
    assert_eq!(rs.emitters.len(), 4 + 7 + 1, "4 area, 7 lights, background");
    let mut rng = Sampler::new(300, 0, 0);
    for (i, e) in rs.emitters.iter().enumerate() {
        let name = format!("emitter {i} ({})", kind(e));
        let (mut checked, mut dark, mut solid_angle) = (0, 0, 0);
        for _ in 0..20_000 {
            let ref_p = v(6.0, 5.0, 6.0) * (rng.next_2d().extend(rng.next_1d()) - 0.5) + Vec3::Y;
            let mut rec = EmitterQueryRecord::from_ref(ref_p);
            let w = e.sample(scene, &mut rec, rng.next_2d());
            assert!(
                w.is_finite() && w.min_element() >= 0.0,
                "{name}: weight {w}"
            );
            if e.is_delta() {
                assert_eq!(rec.pdf, 0.0, "{name}");
                assert_eq!(e.pdf(scene, &rec), 0.0, "{name}");
                assert_eq!(e.eval(scene, &rec), Vec3::ZERO, "{name}");
                continue;
            }
            assert!(
                (rec.wi.length() - 1.0).abs() < 1e-4,
                "{name}: |wi| {}",
                rec.wi.length()
            );
            if rec.pdf == 0.0 {
                assert_eq!(w, Vec3::ZERO, "{name}: weight without a density");
                continue;
            }
            let pdf = e.pdf(scene, &rec);
            assert!(
                close(rec.pdf, pdf, REL),
                "{name}: sample reports pdf {} but pdf() = {pdf}",
                rec.pdf
            );
            let again = rebuilt(e, &rec);
            let pdf2 = e.pdf(scene, &again);
            assert!(
                close(pdf2, pdf, REL),
                "{name}: rebuilt record's pdf {pdf2} vs {pdf}"
            );
            let le = e.eval(scene, &rec);
            assert!(
                close3(e.eval(scene, &again), le, REL),
                "{name}: rebuilt eval"
            );
            assert!(
                close3(w, le / pdf, REL),
                "{name}: weight {w} but eval/pdf = {}",
                le / pdf
            );
            if let EmitterInstance::Area(a) = e {
                assert!((rec.dist - (rec.p - ref_p).length()).abs() < 1e-4 * rec.dist);
                assert!(
                    (rec.n.length() - 1.0).abs() < 1e-4 && (rec.ng.length() - 1.0).abs() < 1e-4
                );
                assert!(
                    rec.n.dot(rec.ng) >= 0.0,
                    "{name}: ng on the other side of n"
                );
                // The density, independently: the triangle's share of the area over its solid
                // angle where its longest edge is longer than the distance to its plane (and
                // its directions are not too close to one plane), else the area density
                // converted to solid angle.
                let m = &scene.meshes[a.mesh];
                let v = m.indices[rec.tri as usize].map(|i| m.positions[i as usize].as_dvec3());
                let r = ref_p.as_dvec3();
                let (e0, e1, e2) = (v[1] - v[0], v[2] - v[0], v[2] - v[1]);
                let longest = e0.length().max(e1.length()).max(e2.length());
                let n = e0.cross(e1);
                let plane = (n.dot(v[0] - r) / n.length()).abs();
                let [da, db, dc] = v.map(|p| (p - r).normalize());
                let triple = da.dot(db.cross(dc)).abs();
                let omega = 2.0 * triple.atan2(1.0 + da.dot(db) + db.dot(dc) + dc.dot(da));
                let solid = longest > plane && triple > 1e-4;
                let want = if solid {
                    (0.5 * n.length() / a.area as f64 / omega) as f32
                } else {
                    let cos = rec.ng.dot(rec.wi).abs();
                    rec.dist * rec.dist / (cos * a.area)
                };
                let near_switch =
                    (longest / plane - 1.0).abs() < 1e-4 || (triple / 1e-4 - 1.0).abs() < 1e-2;
                assert!(
                    near_switch || close(pdf, want, REL),
                    "{name}: pdf {pdf} vs {want} ({})",
                    if solid {
                        "by solid angle"
                    } else {
                        "d²/(cos A)"
                    }
                );
                solid_angle += solid as usize;
            } else if !matches!(
                e.shape(),
                EmitterInstance::Sphere(_) | EmitterInstance::AreaLight(_)
            ) {
                assert!(rec.dist.is_infinite(), "{name}");
            }
            if le == Vec3::ZERO {
                dark += 1;
            }
            checked += 1;
        }
        println!(
            "{name}: {checked} samples checked, {dark} of them from behind a one-sided face, \
             {solid_angle} by solid angle"
        );
        if !e.is_delta() {
            assert!(checked > 10_000, "{name}");
        }
        if matches!(e, EmitterInstance::Area(_)) {
            assert!(
                solid_angle > 100,
                "{name}: both ways of sampling are checked"
            );
        }
    }
}

fn kind(e: &EmitterInstance) -> &'static str {
    match e {
        EmitterInstance::Area(_) => "area",
        EmitterInstance::Point(_) => "point",
        EmitterInstance::Spot(_) => "spot",
        EmitterInstance::Directional(_) => "directional",
        EmitterInstance::Background(_) => "background",
        EmitterInstance::Environment(_) => "environment",
        EmitterInstance::Sphere(_) => "sphere",
        EmitterInstance::AreaLight(_) => "area light",
        EmitterInstance::Ies(_) => "IES light",
    }
}

#[test]
fn light_choice_is_folded_into_the_reported_pdf() {
    for choice in [LightChoice::Power, LightChoice::Uniform] {
        let rs = RenderScene::new(emitter_scene(), choice);
        // Emitter sampling on its own, and combined with BSDF sampling by MIS (whose density
        // `light_pdf` reports).
        for mis in [false, true] {
            let lights = rs.light_choice(mis, 0);
            let mut rng = Sampler::new(400, 0, 0);
            for _ in 0..20_000 {
                let ref_p = v(4.0, 2.0, 4.0) * (rng.next_2d().extend(rng.next_1d()) - 0.5);
                let u = (rng.next_1d(), rng.next_2d());
                let (i, rec, w) = rs.sample_light(ref_p, u, (2, Default::default()), (mis, 0));
                let e = &rs.emitters[i as usize];
                let pmf = lights.pmf_at(ref_p, i as usize);
                assert!(pmf > 0.0);
                if rs.is_delta_light(i) {
                    assert_eq!(rec.pdf, 0.0);
                    assert_eq!(rs.light_pdf(i, &rec, 0), 0.0);
                    continue;
                }
                if w == Vec3::ZERO {
                    continue;
                }
                let single = e.pdf(&rs.scene, &rec);
                assert!(close(rec.pdf, pmf * single, REL), "pmf·pdf");
                if mis {
                    assert!(
                        close(rs.light_pdf(i, &rebuilt(e, &rec), 0), rec.pdf, REL),
                        "light_pdf of emitter {i} ({}): {} vs {}",
                        kind(e),
                        rs.light_pdf(i, &rebuilt(e, &rec), 0),
                        rec.pdf
                    );
                }
                let le = e.eval(&rs.scene, &rec);
                assert!(
                    close3(w, le / rec.pdf, REL),
                    "weight {w} vs Le/(pmf·pdf) {}",
                    le / rec.pdf
                );
            }
        }
    }
}

#[test]
fn a_constant_world_is_left_to_bsdf_sampling_under_mis() {
    // emitter_scene's background is a constant colour: emitter sampling alone chooses it,
    // emitter sampling under MIS never does (density zero, so BSDF samples that escape get
    // weight one), and the other lights share its probability.
    let rs = RenderScene::new(emitter_scene(), LightChoice::Power);
    let b = rs.background.expect("the scene has a background") as usize;
    assert!(rs.light_choice(false, 0).pmf(b) > 0.0);
    assert_eq!(rs.light_choice(true, 0).pmf(b), 0.0);
    let rec = EmitterQueryRecord::from_ref(Vec3::ZERO);
    let mut escaped = rec;
    escaped.wi = v(0.0, 0.0, 1.0);
    assert_eq!(rs.light_pdf(b as u32, &escaped, 0), 0.0);
    let total: f32 = (0..rs.emitters.len())
        .map(|i| rs.light_choice(true, 0).pmf(i))
        .sum();
    assert!(close(total, 1.0, 1e-5), "{total}");
    let mut rng = Sampler::new(401, 0, 0);
    let mut chosen = [0u32; 2];
    for _ in 0..4000 {
        for (k, mis) in [false, true].into_iter().enumerate() {
            let u = (rng.next_1d(), rng.next_2d());
            let (i, _, _) = rs.sample_light(Vec3::ZERO, u, (2, Default::default()), (mis, 0));
            chosen[k] += (i as usize == b) as u32;
        }
    }
    assert!(chosen[0] > 0, "emitter sampling alone finds the world");
    assert_eq!(
        chosen[1], 0,
        "emitter sampling under MIS leaves it to the BSDF"
    );
}

#[test]
fn delta_lights() {
    let scene = Scene::default();
    let point = PointLight {
        position: v(1., 2., 3.),
        intensity: v(4., 5., 6.),
    };
    let spot = SpotLight {
        position: v(0., 3., 0.),
        direction: v(0., -1., 0.),
        intensity: v(10., 10., 10.),
        falloff: SpotFalloff::Gltf {
            cos_inner: 0.9,
            cos_outer: 0.5,
        },
    };
    let sun = Directional::new(v(0.3, -1., 0.), v(2., 2., 2.), 0.0);
    let mut rng = Sampler::new(500, 0, 0);
    for _ in 0..1000 {
        let ref_p = v(2.0, 1.0, 2.0) * (rng.next_2d().extend(rng.next_1d()) - 0.5);
        for (name, e) in [
            ("point", &point as &dyn Emitter),
            ("spot", &spot),
            ("sun", &sun),
        ] {
            assert!(e.is_delta(), "{name}");
            let mut rec = EmitterQueryRecord::from_ref(ref_p);
            let w = e.sample(&scene, &mut rec, rng.next_2d());
            assert_eq!(rec.pdf, 0.0, "{name}");
            assert_eq!(e.pdf(&scene, &rec), 0.0, "{name}");
            assert_eq!(e.eval(&scene, &rec), Vec3::ZERO, "{name}");
            let d2 = (rec.p - ref_p).length_squared();
            match name {
                "point" => {
                    assert!(close3(w, point.intensity / d2, 1e-5), "point: {w}");
                    assert!(((point.position - ref_p).normalize() - rec.wi).length() < 1e-5);
                    assert!((rec.dist * rec.dist - d2).abs() < 1e-4 * d2);
                }
                "spot" => {
                    // Below the light and within the inner cone: full intensity.
                    let cos = (ref_p - spot.position).normalize().dot(spot.direction);
                    if cos >= 0.9 {
                        assert!(close3(w, spot.intensity / d2, 1e-5), "spot: {w}");
                    }
                    assert_eq!(w == Vec3::ZERO, cos <= 0.5, "spot cutoff at cos {cos}");
                }
                _ => {
                    assert_eq!(w, v(2., 2., 2.));
                    assert!((rec.wi + v(0.3, -1., 0.).normalize()).length() < 1e-6);
                    assert!(rec.dist.is_infinite());
                }
            }
        }
    }
}

#[test]
fn mesh_emitter_without_normals_uses_the_geometric_normal() {
    // Two triangles, counter-clockwise seen from +Y (front faces up), no normals or uvs.
    let tris = [
        [v(0., 0., 0.), v(0., 0., -1.), v(-1., 0., 0.)],
        [v(2., 0.5, 0.), v(2., 0.5, -2.), v(0.5, 0.5, 0.)],
    ];
    let scene = Scene {
        meshes: vec![bare_mesh("bare", 0, &tris)],
        materials: vec![Material::emitter("e", v(1., 1., 1.), false)],
        ..Default::default()
    };
    assert!(scene.meshes[0].normals.is_empty() && scene.meshes[0].uvs.is_empty());
    let e = AreaEmitter::new(&scene, 0).expect("an emitter");
    assert!(close(e.area, 0.5 + 1.5, 1e-6), "area {}", e.area);
    let mut rng = Sampler::new(600, 0, 0);
    let mut lit = [0usize; 2];
    for k in 0..4000 {
        // From above: lit; from below: dark (one-sided, front = +Y by the right-hand rule).
        let above = k % 2 == 0;
        let ref_p = v(0.5, if above { 3.0 } else { -3.0 }, -0.5);
        let mut rec = EmitterQueryRecord::from_ref(ref_p);
        let w = e.sample(&scene, &mut rec, rng.next_2d());
        assert!(
            (rec.n - Vec3::Y).length() < 1e-6,
            "shading normal {}",
            rec.n
        );
        assert!(
            (rec.ng - Vec3::Y).length() < 1e-6,
            "geometric normal {}",
            rec.ng
        );
        assert!(
            rec.p.y.abs() < 1e-6 || (rec.p.y - 0.5).abs() < 1e-6,
            "point {}",
            rec.p
        );
        assert!(rec.pdf > 0.0 && rec.pdf.is_finite());
        assert_eq!(rec.uv, Vec2::ZERO);
        if above {
            assert!(close3(w, Vec3::ONE / rec.pdf, REL), "weight {w}");
            lit[(rec.p.y > 0.25) as usize] += 1;
        } else {
            assert_eq!(w, Vec3::ZERO, "lit from behind");
        }
    }
    // Both triangles are sampled, roughly 1 : 3 by area.
    let frac = lit[1] as f64 / 2000.0;
    assert!(
        (frac - 0.75).abs() < 0.05,
        "share of the large triangle {frac}"
    );
}

#[test]
fn one_sided_emitter_is_dark_from_behind() {
    let rs = RenderScene::new(emitter_scene(), LightChoice::Power);
    let scene = &rs.scene;
    // Emitter 0 is the one-sided ceiling quad facing down (−Y), emitter 1 the two-sided bulb.
    let EmitterInstance::Area(ceiling) = &rs.emitters[0] else {
        panic!("emitter 0 is not the ceiling light")
    };
    let EmitterInstance::Area(bulb) = &rs.emitters[1] else {
        panic!("emitter 1 is not the bulb")
    };
    assert!(!ceiling.two_sided && bulb.two_sided);
    let mut rng = Sampler::new(700, 0, 0);
    for _ in 0..2000 {
        let (below, above) = (v(0.1, 1.0, 0.2), v(0.1, 3.0, 0.2));
        let mut rec = EmitterQueryRecord::from_ref(below);
        let w = ceiling.sample(scene, &mut rec, rng.next_2d());
        assert!(w.max_element() > 0.0, "lit from the front");
        let mut rec = EmitterQueryRecord::from_ref(above);
        let w = ceiling.sample(scene, &mut rec, rng.next_2d());
        assert!(rec.pdf > 0.0, "the point is still a valid sample");
        assert_eq!(w, Vec3::ZERO, "one-sided emitter lit from behind");
        assert_eq!(ceiling.eval(scene, &rec), Vec3::ZERO);
        let back = EmitterQueryRecord::between(above, rec.p, rec.n, rec.ng, rec.uv);
        assert_eq!(ceiling.eval(scene, &back), Vec3::ZERO);
        // The two-sided bulb shines from inside-out facets seen from behind as well.
        let mut rec = EmitterQueryRecord::from_ref(v(1.5, 1.0, 0.0) + v(0.0, 0.0, 2.0));
        let w = bulb.sample(scene, &mut rec, rng.next_2d());
        assert!(
            w.max_element() > 0.0,
            "two-sided emitter dark from one side"
        );
    }
}

/// Cycles' Chiang hair scatters all around its fibre (local +X): over viewers from the whole
/// sphere, the pdf a sample reports is `pdf()` of its direction, the weight is
/// `eval · |wo.z| / pdf`, `eval_and_pdf` agrees with `eval` and `pdf`, and the light-pass split
/// is all glossy or all transmission.
#[test]
fn chiang_hair_sample_pdf_and_weight_agree() {
    let mut rng = Sampler::new(4242, 0, 0);
    let lobes = [
        ChiangHair::new(Vec3::new(0.2, 0.6, 1.4), 0.3, 0.3, 0.0, 1.55, 0.035, 0.0),
        ChiangHair::new(Vec3::ZERO, 0.1, 0.15, 0.3, 1.55, -0.1, 0.7),
        ChiangHair::new(Vec3::splat(5.0), 1.0, 0.8, 1.0, 1.3, 0.3, -0.95),
        ChiangHair::new(Vec3::ZERO, 0.001, 0.001, 0.0, 2.0, 0.0, 0.5),
    ];
    for (k, b) in lobes.iter().enumerate() {
        assert!(!b.is_delta());
        let mut checked = 0;
        for _ in 0..20_000 {
            let wi = square_to_uniform_sphere(rng.next_2d());
            let mut rec = BsdfQueryRecord::new(wi);
            let w = b.sample(&mut rec, rng.next_2d(), rng.next_1d());
            assert!(
                w.is_finite() && w.min_element() >= 0.0,
                "lobe {k}: weight {w}"
            );
            if w == Vec3::ZERO {
                continue;
            }
            assert_eq!(rec.measure, Measure::SolidAngle);
            assert!((rec.wo.length() - 1.0).abs() < 1e-4);
            let pair = BsdfQueryRecord::pair(wi, rec.wo);
            let (f, pdf) = b.eval_and_pdf(&pair);
            assert_eq!((f, pdf), (b.eval(&pair), b.pdf(&pair)));
            assert!(
                close(rec.pdf, pdf, REL),
                "lobe {k}: sample reports pdf {} but pdf() = {pdf} (wi {wi}, wo {})",
                rec.pdf,
                rec.wo
            );
            if rec.wo.z.abs() < 1e-3 {
                // eval = F / |wo.z|: too ill-conditioned to compare at 1e-3.
                continue;
            }
            let want = f * rec.wo.z.abs() / pdf;
            assert!(
                close3(w, want, REL),
                "lobe {k}: weight {w} but eval·cos/pdf = {want} (wi {wi}, wo {})",
                rec.wo
            );
            let [d, g] = b.eval_split(&pair);
            assert!(d == Vec3::ZERO && (g == f || g == Vec3::ZERO));
            checked += 1;
        }
        assert!(checked > 15_000, "lobe {k}: {checked} samples checked");
    }
}
