//! Cycles' light passes (diffuse/glossy/transmission direct, indirect, colour) through the
//! public render API, on the built-in scenes.

use std::sync::atomic::AtomicBool;
use tesela::emitter::LightChoice;
use tesela::film::{LightClass, Pass, PassSet};
use tesela::render::{self, Image, RenderOptions};
use tesela::render_scene::RenderScene;
use tesela::scene::builtin;

fn scene(name: &str) -> RenderScene {
    RenderScene::new(builtin::by_name(name).unwrap(), LightChoice::Power)
}

fn opts(size: u32, spp: u32, integrator: &str) -> RenderOptions {
    RenderOptions {
        width: size,
        height: size,
        spp,
        max_depth: 8,
        seed: 3,
        tile_size: 8,
        integrator: integrator.into(),
        passes: PassSet::new(Pass::ALL),
        ..Default::default()
    }
}

fn run(rs: &RenderScene, o: &RenderOptions) -> Image {
    render::render(rs, o, &AtomicBool::new(false), &|_, _, _| {})
        .unwrap()
        .0
}

/// Pass `p` as one RGB triple per pixel.
fn rgb(img: &Image, p: Pass) -> Vec<[f32; 3]> {
    img.pass(p)
        .unwrap()
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect()
}

/// Mean over pixels and channels.
fn mean(img: &Image, p: Pass) -> f64 {
    let v = rgb(img, p);
    v.iter().flatten().map(|&x| x as f64).sum::<f64>() / (3 * v.len()) as f64
}

#[test]
fn light_passes_add_up_to_combined_on_every_pixel() {
    // Diffuse walls, a mirror and a glass sphere, an area light.
    let rs = scene("cornell-spheres");
    for integrator in [
        "path_mis",
        "path_mats",
        "direct_mis",
        "direct_ems",
        "direct_mats",
    ] {
        let img = run(&rs, &opts(32, 16, integrator));
        let (emit, env) = (rgb(&img, Pass::Emission), rgb(&img, Pass::Environment));
        let classes: Vec<_> = LightClass::ALL
            .iter()
            .map(|c| {
                let (d, i, col) = c.passes();
                (rgb(&img, d), rgb(&img, i), rgb(&img, col))
            })
            .collect();
        let mut worst = 0.0f32;
        for (k, px) in img.pixels.iter().enumerate() {
            for c in 0..3 {
                let mut sum = emit[k][c] + env[k][c];
                for (d, i, col) in &classes {
                    sum += (d[k][c] + i[k][c]) * col[k][c];
                }
                let err = (sum - px[c]).abs() / (1e-3 + px[c].abs());
                worst = worst.max(err);
            }
        }
        assert!(worst < 1e-4, "{integrator}: worst relative error {worst}");
    }
}

#[test]
fn each_class_gets_its_light() {
    let rs = scene("cornell-spheres");
    let img = run(&rs, &opts(32, 16, "path_mis"));
    // Light straight from the lamp onto the walls, via the mirror, and through the glass
    // (which needs two refractions: indirect); every class has colour where it is seen.
    for p in [
        Pass::DiffuseDirect,
        Pass::DiffuseIndirect,
        Pass::DiffuseColor,
        Pass::GlossyDirect,
        Pass::GlossyIndirect,
        Pass::GlossyColor,
        Pass::TransmissionIndirect,
        Pass::TransmissionColor,
    ] {
        assert!(mean(&img, p) > 1e-3, "{}: {}", p.name(), mean(&img, p));
    }
}

#[test]
fn a_direct_integrator_has_no_indirect_light() {
    // The plain box: diffuse walls only (no delta chain leads to a later vertex).
    let rs = scene("cornell-box");
    for (integrator, depth) in [
        ("direct_mis", 2),
        ("direct_ems", 2),
        ("direct_mats", 2),
        ("path_mis", 2),
        ("path_mats", 2),
    ] {
        let mut o = opts(24, 8, integrator);
        o.max_depth = depth;
        let img = run(&rs, &o);
        assert!(mean(&img, Pass::DiffuseDirect) > 0.05, "{integrator}");
        for p in [
            Pass::DiffuseIndirect,
            Pass::GlossyIndirect,
            Pass::TransmissionIndirect,
        ] {
            assert_eq!(mean(&img, p), 0.0, "{integrator}: {}", p.name());
        }
    }
    // With more bounces the same box has indirect light.
    let img = run(&rs, &opts(24, 8, "path_mis"));
    assert!(mean(&img, Pass::DiffuseIndirect) > 0.01);
}

#[test]
fn a_diffuse_scene_has_no_glossy_or_transmission_light() {
    let rs = scene("cornell-box");
    let img = run(&rs, &opts(24, 8, "path_mis"));
    for p in [
        Pass::GlossyDirect,
        Pass::GlossyIndirect,
        Pass::GlossyColor,
        Pass::TransmissionDirect,
        Pass::TransmissionIndirect,
        Pass::TransmissionColor,
    ] {
        assert_eq!(mean(&img, p), 0.0, "{}", p.name());
    }
    for p in [
        Pass::DiffuseDirect,
        Pass::DiffuseIndirect,
        Pass::DiffuseColor,
    ] {
        assert!(mean(&img, p) > 0.01, "{}", p.name());
    }
}

#[test]
fn light_passes_leave_combined_alone_and_noisy_image_is_combined() {
    let rs = scene("cornell-spheres");
    let mut o = opts(16, 8, "path_mis");
    let with = run(&rs, &o);
    o.passes = PassSet::default();
    let plain = run(&rs, &o);
    assert!(with.pixels == plain.pixels);
    let noisy = with.pass(Pass::NoisyImage).unwrap();
    let combined: Vec<f32> = with.pixels.iter().flatten().copied().collect();
    assert!(noisy == combined);
}

#[test]
fn integrators_without_a_split_say_so() {
    let rs = scene("cornell-box");
    let mut o = opts(8, 1, "normals");
    o.passes = PassSet::parse(["diffuse_direct"]).unwrap();
    let e = render::render(&rs, &o, &AtomicBool::new(false), &|_, _, _| {})
        .err()
        .expect("an error")
        .to_string();
    assert!(e.contains("normals") && e.contains("path_mis"), "{e}");
    // Colour passes alone come from the film: any integrator.
    o.passes = PassSet::parse(["diffuse_color"]).unwrap();
    let img = run(&rs, &o);
    assert!(mean(&img, Pass::DiffuseColor) > 0.1);
}

#[test]
fn data_passes_reuse_the_camera_ray() {
    // The denoiser's guides and the other first-surface passes follow the camera ray the
    // integrator traced: on an opaque scene they cast no ray of their own, and Combined is
    // the same with and without them.
    let rs = scene("cornell-box");
    let mut o = opts(16, 4, "path_mis");
    let stats =
        |o: &RenderOptions| render::render(&rs, o, &AtomicBool::new(false), &|_, _, _| {}).unwrap();
    o.passes = PassSet::default();
    let (plain, plain_stats) = stats(&o);
    o.passes = PassSet::parse(["denoising_albedo", "denoising_normal", "depth", "normal"]).unwrap();
    let (with, with_stats) = stats(&o);
    assert!(with.pixels == plain.pixels);
    assert_eq!(
        with_stats.rays, plain_stats.rays,
        "rays with and without data passes"
    );
    // The passes are there: the box's walls have albedo and unit normals.
    assert!(mean(&with, Pass::DenoisingAlbedo) > 0.1);
}
