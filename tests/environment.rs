//! Worlds that vary with direction: the environment emitter's importance sampling (chi-square,
//! sample/pdf agreement), Cycles' equirectangular orientation through the whole graph path,
//! furnaces and an analytic irradiance check for every integrator, Light Path and film
//! transparency, the TESELA_world loader, and the command line's `--env` on hostile images.

#[path = "common/chi2.rs"]
mod chi2_common;
#[path = "common/inputs.rs"]
mod inputs;

use chi2_common::*;
use glam::{DVec3, Mat4, Vec2, Vec3};
use serde_json::json;
use std::f64::consts::PI;
use std::process::Command;
use std::sync::atomic::AtomicBool;
use tesela::emitter::{Emitter, EmitterInstance, EmitterQueryRecord, Environment, LightChoice};
use tesela::render::{self, RenderOptions};
use tesela::render_scene::{Ctx, RenderScene};
use tesela::sampler::{Sampler, SobolSampler};
use tesela::scene::builtin::{quad, sphere};
use tesela::scene::world::environment_graph;
use tesela::scene::{Camera, Image, Material, Projection, Scene, WorldSampling};
use tesela::shading::globals::{from_blender, ray};
use tesela::shading::graph::{Graph, Node};

fn float_image(w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 3]) -> Image {
    let mut float = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let c = f(x, y);
            float.push([c[0], c[1], c[2], 1.0]);
        }
    }
    Image {
        width: w,
        height: h,
        rgba8: Vec::new(),
        float,
    }
}

/// A scene whose world is `img` as an equirectangular environment.
fn env_scene(img: Image, strength: f32, rotation_deg: f32) -> Scene {
    let mut s = Scene::default();
    s.images.push(img);
    s.world.graph = Some(environment_graph(0, strength, rotation_deg));
    s
}

fn world_of(scene: &Scene) -> Option<EmitterInstance> {
    let mut warnings = Vec::new();
    let e = tesela::emitter::environment::world_emitter(scene, Mat4::IDENTITY, &mut warnings);
    assert!(warnings.is_empty(), "{warnings:?}");
    e
}

fn environment(scene: &Scene) -> Environment {
    match world_of(scene) {
        Some(EmitterInstance::Environment(e)) => e,
        other => panic!("expected an environment emitter, got {other:?}"),
    }
}

/// A 64 x 32 sky: a gradient, darker below the horizon, with a bright 3 x 2 texel "sun".
fn sun_sky() -> Image {
    float_image(64, 32, |x, y| {
        if (20..23).contains(&x) && (9..11).contains(&y) {
            [80.0, 70.0, 60.0]
        } else if y < 16 {
            let t = y as f32 / 16.0;
            [0.2 + 0.3 * t, 0.3 + 0.3 * t, 0.8]
        } else {
            [0.1, 0.08, 0.05 + 0.002 * x as f32]
        }
    })
}

/// Cycles' `equirectangular_to_direction` in double precision (Blender's Z-up world).
fn cycles_direction(u: f64, v: f64) -> DVec3 {
    let phi = PI - 2.0 * PI * u;
    let theta = PI - PI * v;
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

#[test]
fn environment_sampling_matches_its_density_chi2() {
    let scene = env_scene(sun_sky(), 1.0, 30.0);
    let env = environment(&scene);
    assert!(env.distribution().is_some());
    let r = check_directions_with(
        "environment (sun patch)",
        &DirGrid::sphere(40, 80),
        1_000_000,
        11,
        &mut |s| {
            let mut rec = EmitterQueryRecord::from_ref(Vec3::ZERO);
            let w = env.sample(&scene, &mut rec, s.next_2d());
            (w != Vec3::ZERO).then_some(rec.wi)
        },
        &|w| env.pdf(&scene, &EmitterQueryRecord::towards(Vec3::ZERO, w)) as f64,
        SIGNIFICANCE,
        true,
    );
    assert!((r.integral - 1.0).abs() < 2e-3, "∫pdf = {}", r.integral);
    assert_eq!(r.rest_fraction, 0.0);
}

/// Every sample's stored density is what `pdf` says for its direction, and its weight is
/// `eval / pdf`; the weights' mean is `∫ L dω` by quadrature; the density integrates to 1.
#[test]
fn environment_sample_pdf_and_weight_agree() {
    let scene = env_scene(sun_sky(), 2.0, 0.0);
    let env = environment(&scene);
    // Quadrature over the sphere: equirectangular midpoints, 4 per texel each way.
    let (nu, nv) = (512usize, 256usize);
    let (mut int_l, mut int_p) = (0.0f64, 0.0f64);
    for j in 0..nv {
        for i in 0..nu {
            let (u, v) = ((i as f64 + 0.5) / nu as f64, (j as f64 + 0.5) / nv as f64);
            let d = cycles_direction(u, v);
            let dw = (2.0 * PI / nu as f64) * (PI / nv as f64) * (PI * v).sin();
            let wi = from_blender(d.as_vec3());
            let rec = EmitterQueryRecord::towards(Vec3::ZERO, wi);
            int_l += tesela::emitter::luminance(env.eval(&scene, &rec)) as f64 * dw;
            int_p += env.pdf(&scene, &rec) as f64 * dw;
        }
    }
    assert!((int_p - 1.0).abs() < 2e-3, "∫pdf = {int_p}");
    let mut rng = Sampler::new(5, 0, 0);
    let n = 200_000;
    let mut sum = 0.0f64;
    for _ in 0..n {
        let mut rec = EmitterQueryRecord::from_ref(Vec3::ZERO);
        let w = env.sample(&scene, &mut rec, rng.next_2d());
        assert!(rec.pdf > 0.0 && w.is_finite() && w.min_element() >= 0.0);
        assert!(rec.dist.is_infinite());
        let q = EmitterQueryRecord::towards(Vec3::ZERO, rec.wi);
        let p = env.pdf(&scene, &q);
        assert_eq!(p, rec.pdf, "direction {}", rec.wi);
        let le = env.eval(&scene, &q);
        assert!((w - le / p).abs().max_element() <= 1e-5 * (le / p).max_element().max(1.0));
        sum += tesela::emitter::luminance(w) as f64;
    }
    let mean = sum / n as f64;
    assert!(
        (mean - int_l).abs() < 0.02 * int_l,
        "E[L/pdf] = {mean}, ∫L dω = {int_l}"
    );
    // The light-selection power is π r² ∫ L dω / 4 (a facing surface's irradiance, for a sky
    // with no sun sampled apart).
    let power = env.power(&scene, 1.0) as f64;
    assert!(
        (power - std::f64::consts::PI * int_l / 4.0).abs() < 0.01 * power,
        "{power} vs {int_l}"
    );
}

/// A world graph whose environment texture reads texels without interpolation.
fn closest_graph(image: usize) -> Graph {
    let mut g = Graph::default();
    let mut env = Node::new("ShaderNodeTexEnvironment")
        .prop("interpolation", json!("Closest"))
        .prop("colorspace", json!("Non-Color"));
    env.image = Some(image);
    let env = g.add(env);
    let bg = g.add(Node::new("ShaderNodeBackground").link("Color", env, "Color"));
    g.surface = Some((bg, "Background".into()));
    g
}

/// Cycles' orientation: the direction at the centre of texel (column i, row j from the top)
/// reads that texel; Blender's +X is the centre column, +Y a quarter in, -Y three quarters,
/// +Z the top row.
#[test]
fn a_direction_reads_the_texel_cycles_reads() {
    let (w, h) = (5u32, 3u32);
    let value = |x: u32, y: u32| [x as f32 + 1.0, y as f32 + 1.0, (x * 10 + y) as f32];
    let mut scene = Scene::default();
    scene.images.push(float_image(w, h, value));
    scene.world.graph = Some(closest_graph(0));
    let env = environment(&scene);
    for y in 0..h {
        for x in 0..w {
            // Cycles' v runs up the image.
            let u = (x as f64 + 0.5) / w as f64;
            let v = 1.0 - (y as f64 + 0.5) / h as f64;
            let d = from_blender(cycles_direction(u, v).as_vec3());
            let got = env.radiance(&scene, d, 1, ray::CAMERA);
            assert_eq!(got, Vec3::from_array(value(x, y)), "texel ({x}, {y})");
        }
    }
    let at = |b: Vec3| env.radiance(&scene, from_blender(b), 1, 0);
    assert_eq!(at(Vec3::X), Vec3::from_array(value(2, 1)));
    assert_eq!(at(Vec3::Y), Vec3::from_array(value(1, 1)));
    assert_eq!(at(-Vec3::Y), Vec3::from_array(value(3, 1)));
    assert_eq!(at(Vec3::new(0.1, 0.0, 1.0).normalize()).y, 1.0);
    assert_eq!(at(Vec3::new(0.1, 0.0, -1.0).normalize()).y, 3.0);
    // A Mapping rotation of +90° about Z (Texture Coordinate > Mapping): the view towards
    // +X reads what +Y read before (the vector is rotated before the lookup).
    let mut rotated = env_scene(float_image(w, h, value), 1.0, 90.0);
    if let Some(g) = &mut rotated.world.graph {
        for n in &mut g.nodes {
            if n.kind == "ShaderNodeTexEnvironment" {
                n.props.insert("interpolation".into(), json!("Closest"));
            }
        }
    }
    let env = environment(&rotated);
    let got = env.radiance(&rotated, from_blender(-Vec3::Y), 1, 0);
    assert_eq!(got, Vec3::from_array(value(2, 1)));
}

fn camera(to_world: Mat4, yfov_deg: f32) -> Option<Camera> {
    Some(Camera {
        projection: Projection::Perspective {
            yfov: yfov_deg.to_radians(),
        },
        to_world,
        aspect: None,
        ..Default::default()
    })
}

fn opts(integrator: &str, size: u32, spp: u32, max_depth: u32, seed: u64) -> RenderOptions {
    RenderOptions {
        width: size,
        height: size,
        spp,
        max_depth,
        seed,
        integrator: integrator.into(),
        threads: 0,
        tile_size: 16,
        region: None,
        ..Default::default()
    }
}

fn render_with(scene: Scene, opts: &RenderOptions) -> Vec<[f32; 4]> {
    let rs = RenderScene::new(scene, LightChoice::Power);
    let (img, stats) = render::render(&rs, opts, &AtomicBool::new(false), &|_, _, _| {}).unwrap();
    assert_eq!(stats.rejected_samples, 0, "non-finite samples");
    img.pixels
}

fn mean_se(pixels: &[[f32; 4]], c: usize) -> (f64, f64) {
    let n = pixels.len() as f64;
    let mean = pixels.iter().map(|p| p[c] as f64).sum::<f64>() / n;
    let var = pixels
        .iter()
        .map(|p| (p[c] as f64 - mean).powi(2))
        .sum::<f64>()
        / (n - 1.0);
    (mean, (var / n).sqrt())
}

fn assert_close(name: &str, pixels: &[[f32; 4]], c: usize, expected: f64, rel: f64) {
    let (mean, se) = mean_se(pixels, c);
    let tol = 4.0 * se + rel * expected.abs();
    assert!(
        (mean - expected).abs() <= tol,
        "{name}: mean {mean:.5} expected {expected:.5} (tolerance {tol:.5})"
    );
}

const ALL: [&str; 5] = [
    "direct_ems",
    "direct_mats",
    "direct_mis",
    "path_mats",
    "path_mis",
];

/// A Lambertian ball of albedo ρ under a constant environment image L reflects ρ L, for every
/// integrator: through the uniform path (an exactly constant image) and the importance map
/// (an image varying by 0.1%).
#[test]
fn white_furnace_under_a_constant_environment_image() {
    let (rho, lb) = (0.8f64, 0.7f64);
    for (label, wiggle) in [("constant", 0.0f32), ("map", 1e-3)] {
        let img = float_image(16, 8, |x, y| {
            let k = 1.0 + wiggle * (((x + y) % 2) as f32 * 2.0 - 1.0);
            [lb as f32 * k; 3]
        });
        let make = || {
            let mut s = env_scene(img.clone(), 1.0, 0.0);
            s.materials
                .push(Material::diffuse("ball", Vec3::splat(rho as f32)));
            let mut sph = sphere("ball", 0, Vec3::ZERO, 1.0, 24, 48);
            sph.normals.clear();
            s.meshes.push(sph);
            s.camera = camera(Mat4::from_translation(Vec3::new(0.0, 0.0, 4.0)), 5.0);
            s
        };
        let env = environment(&make());
        assert_eq!(env.distribution().is_some(), wiggle > 0.0, "{label}");
        for name in ALL {
            let px = render_with(make(), &opts(name, 16, 64, 8, 5));
            assert_close(&format!("{label} {name}"), &px, 0, rho * lb, 2e-3);
        }
    }
}

/// A Lambertian floor under a sky with a bright sun patch: the reflected radiance is
/// `ρ/π ∫ L cos θ dω` over the upper hemisphere (quadrature of the world's own radiance), for
/// emitter sampling, BSDF sampling and both with MIS.
#[test]
fn floor_under_a_sun_patch_matches_quadrature() {
    let rho = 0.5f64;
    let make = || {
        let mut s = env_scene(sun_sky(), 1.0, 0.0);
        s.materials
            .push(Material::diffuse("floor", Vec3::splat(rho as f32)));
        let v = Vec3::new;
        s.meshes.push(quad(
            "floor",
            0,
            v(-500., 0., 500.),
            v(500., 0., 500.),
            v(500., 0., -500.),
            v(-500., 0., -500.),
        ));
        let look_down = Mat4::from_translation(v(0.0, 0.5, 0.0))
            * Mat4::from_rotation_x(-std::f32::consts::PI / 2.0);
        s.camera = camera(look_down, 0.5);
        s
    };
    let scene = make();
    let env = environment(&scene);
    let (nu, nv) = (1024usize, 256usize);
    let mut e = [0.0f64; 3];
    for j in 0..nv {
        for i in 0..nu {
            // The upper hemisphere: Cycles' v in (0.5, 1).
            let (u, v) = (
                (i as f64 + 0.5) / nu as f64,
                0.5 + 0.5 * (j as f64 + 0.5) / nv as f64,
            );
            let d = cycles_direction(u, v);
            let dw = (2.0 * PI / nu as f64) * (0.5 * PI / nv as f64) * d.z.max(0.0).acos().sin();
            let wi = from_blender(d.as_vec3());
            let l = env.eval(&scene, &EmitterQueryRecord::towards(Vec3::ZERO, wi));
            for c in 0..3 {
                e[c] += l[c] as f64 * d.z * dw;
            }
        }
    }
    for name in ["direct_ems", "direct_mats", "direct_mis", "path_mis"] {
        let px = render_with(make(), &opts(name, 16, 128, 2, 9));
        for (c, e) in e.iter().enumerate() {
            assert_close(&format!("{name} channel {c}"), &px, c, rho / PI * e, 3e-3);
        }
    }
}

/// A world graph: Mix Shader by Light Path "Is Camera Ray" between a dim constant (lighting)
/// and a bright one (what the camera sees).
fn backdrop_graph() -> Graph {
    let mut g = Graph::default();
    let lp = g.add(Node::new("ShaderNodeLightPath"));
    let lit = g.add(Node::new("ShaderNodeBackground").with("Color", &[0.5, 0.5, 0.5, 1.0]));
    let seen = g.add(Node::new("ShaderNodeBackground").with("Color", &[0.9, 0.2, 0.1, 1.0]));
    let mix = g.add(
        Node::new("ShaderNodeMixShader")
            .link("Fac", lp, "Is Camera Ray")
            .link("Shader", lit, "Background")
            .link("Shader_001", seen, "Background"),
    );
    g.surface = Some((mix, "Shader".into()));
    g
}

#[test]
fn light_path_backdrop_camera_sees_one_world_and_the_scene_is_lit_by_the_other() {
    let (rho, lit) = (0.8f64, 0.5f64);
    let make = || {
        let mut s = Scene::default();
        s.world.graph = Some(backdrop_graph());
        s.materials
            .push(Material::diffuse("ball", Vec3::splat(rho as f32)));
        let mut sph = sphere("ball", 0, Vec3::ZERO, 1.0, 24, 48);
        sph.normals.clear();
        s.meshes.push(sph);
        s
    };
    // The ball fills the narrow view: ρ · 0.5 for every integrator.
    for name in ALL {
        let mut s = make();
        s.camera = camera(Mat4::from_translation(Vec3::new(0.0, 0.0, 4.0)), 5.0);
        let px = render_with(s, &opts(name, 8, 32, 6, 3));
        assert_close(name, &px, 0, rho * lit, 2e-3);
    }
    // Looking away from the ball: the camera sees the bright backdrop.
    let mut s = make();
    s.camera = camera(
        Mat4::from_translation(Vec3::new(0.0, 0.0, 4.0)) * Mat4::from_rotation_y(3.1),
        5.0,
    );
    let px = render_with(s, &opts("path_mis", 4, 4, 6, 3));
    for p in &px {
        assert!(
            (Vec3::new(p[0], p[1], p[2]) - Vec3::new(0.9, 0.2, 0.1))
                .abs()
                .max_element()
                < 1e-6,
            "{p:?}"
        );
        assert_eq!(p[3], 1.0);
    }
    // Through a mirror the camera's ray is a reflection ray: it sees the lighting world.
    let mut s = make();
    s.materials[0] = Material::mirror("mirror", Vec3::ONE);
    s.camera = camera(Mat4::from_translation(Vec3::new(0.0, 0.0, 4.0)), 5.0);
    let px = render_with(s, &opts("path_mis", 4, 4, 6, 3));
    for p in &px {
        assert!(
            (p[0] - 0.5).abs() < 1e-5 && (p[1] - 0.5).abs() < 1e-5,
            "{p:?}"
        );
    }
}

#[test]
fn film_transparent_and_hidden_world_keep_the_lighting() {
    let mut s = env_scene(sun_sky(), 1.0, 0.0);
    s.materials
        .push(Material::diffuse("ball", Vec3::splat(0.8)));
    s.meshes.push(sphere("ball", 0, Vec3::ZERO, 1.0, 24, 48));
    s.camera = camera(Mat4::from_translation(Vec3::new(0.0, 0.0, 4.0)), 40.0);
    let visible = RenderScene::new(s.clone(), LightChoice::Power);
    let mut t = s.clone();
    t.settings.film_transparent = true;
    let transparent = RenderScene::new(t, LightChoice::Power);
    let mut h = s;
    h.world.visible_camera = false;
    let hidden = RenderScene::new(h, LightChoice::Power);
    let mut ctx = Ctx::new(SobolSampler::new(0, 0, 0));
    let (o, miss, hit) = (Vec3::new(0.0, 0.0, 4.0), Vec3::Y, -Vec3::Z);
    // Camera rays that escape see nothing; others (and lighting) see the world.
    assert!(
        visible
            .background_radiance(miss, o, 1, ray::CAMERA)
            .is_some()
    );
    for rs in [&transparent, &hidden] {
        assert!(rs.background_radiance(miss, o, 1, ray::CAMERA).is_none());
        let (_, le, _) = rs.background_radiance(miss, o, 2, ray::DIFFUSE).unwrap();
        assert!(le.max_element() > 0.0);
    }
    // Coverage: 1 on the ball, 0 on the sky, and always 1 without a transparent film.
    assert_eq!(transparent.camera_coverage(&mut ctx, o, hit), 1.0);
    assert_eq!(transparent.camera_coverage(&mut ctx, o, miss), 0.0);
    assert_eq!(visible.camera_coverage(&mut ctx, o, miss), 1.0);
    // The ball is lit the same: its pixels agree between the three.
    let o = opts("path_mis", 16, 16, 4, 2);
    let a = render::render(&visible, &o, &AtomicBool::new(false), &|_, _, _| {})
        .unwrap()
        .0;
    let b = render::render(&hidden, &o, &AtomicBool::new(false), &|_, _, _| {})
        .unwrap()
        .0;
    let centre = (8 * 16 + 8) as usize;
    assert_eq!(a.pixels[centre], b.pixels[centre]);
    assert_eq!(b.pixels[0][..3], [0.0, 0.0, 0.0], "the hidden sky is black");
    assert!(a.pixels[0][0] > 0.0);
}

#[test]
fn constant_worlds_stay_the_cheap_background() {
    // A Background of constant colour (what the add-on writes for a plain world) is the
    // constant emitter, with exactly the old radiance.
    let mut s = Scene::default();
    let mut g = Graph::default();
    let bg = g.add(
        Node::new("ShaderNodeBackground")
            .with("Color", &[0.6, 0.7, 0.9, 1.0])
            .with("Strength", &[1.5]),
    );
    g.surface = Some((bg, "Background".into()));
    s.world.graph = Some(g);
    match world_of(&s) {
        Some(EmitterInstance::Background(b)) => {
            assert_eq!(b.radiance, Vec3::new(0.6, 0.7, 0.9) * 1.5)
        }
        other => panic!("{other:?}"),
    }
    // Black worlds are no emitter at all; the sampling method NONE makes no light.
    let mut black = s.clone();
    if let Some(g) = &mut black.world.graph {
        g.nodes[0].set("Strength", tesela::shading::Input::Const(vec![0.0]));
    }
    assert!(world_of(&black).is_none());
    let mut none = env_scene(sun_sky(), 1.0, 0.0);
    none.world.sampling = WorldSampling::None;
    let env = environment(&none);
    assert_eq!(env.power(&none, 1.0), 0.0);
    assert!(env.radiance(&none, Vec3::Y, 1, ray::CAMERA).max_element() > 0.0);
}

// ---------------------------------------------------------------------------------------------
// The loader.

fn b64(bytes: &[u8]) -> String {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

#[test]
fn tesela_world_graph_images_sky_and_settings_load() {
    let texels: Vec<u8> = [0.25f32, 0.5, 1.0, 2.0, 4.0, 8.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["TESELA_world", "TESELA_images", "TESELA_render"],
        "buffers": [{"byteLength": texels.len(),
                     "uri": format!("data:application/octet-stream;base64,{}", b64(&texels))}],
        "bufferViews": [{"buffer": 0, "byteLength": texels.len()}],
        "extensions": {
            "TESELA_images": {"images": [{"name": "sky", "width": 2, "height": 1, "channels": 3,
                                          "component": "f32", "bufferView": 0,
                                          "colorspace": "Non-Color"}]},
            "TESELA_render": {"film_transparent": true, "film_transparent_glass": true,
                              "film_transparent_roughness": 0.25},
            "TESELA_world": {
                "name": "Sunset", "color": [0.1, 0.2, 0.3], "strength": 1.0,
                "visible_camera": false, "sampling": "MANUAL", "map_resolution": 256,
                "graph": {"version": 1, "nodes": [
                    {"name": "Env", "type": "ShaderNodeTexEnvironment",
                     "props": {"image": 0, "projection": "EQUIRECTANGULAR",
                               "interpolation": "Closest", "colorspace": "Non-Color"}},
                    {"name": "Sky Texture", "type": "ShaderNodeTexSky",
                     "props": {"sky_type": "HOSEK_WILKIE"}},
                    {"name": "Add", "type": "ShaderNodeMix",
                     "props": {"data_type": "RGBA", "blend_type": "ADD"},
                     "inputs": {"Factor_Float": 1.0, "A_Color": {"link": [0, "Color"]},
                                "B_Color": {"link": [1, "Color"]}}},
                    {"name": "Background", "type": "ShaderNodeBackground",
                     "inputs": {"Color": {"link": [2, "Result_Color"]}, "Strength": 1.0}}],
                    "surface": [3, "Background"]}
            }
        }
    });
    let s =
        tesela::scene::gltf::load_from_slice(&inputs::json_bytes(&doc), None, "w.gltf").unwrap();
    assert!(s.settings.film_transparent);
    assert_eq!(s.settings.film_transparent_glass, Some(0.25));
    assert!(!s.world.visible_camera);
    assert_eq!(s.world.sampling, WorldSampling::Manual(256));
    assert_eq!(s.world.name, "Sunset");
    let sky_warning = s
        .warnings
        .iter()
        .find(|w| w.contains("world 'Sunset'") && w.contains("'Sky Texture'"))
        .unwrap_or_else(|| panic!("no sky warning in {:?}", s.warnings));
    assert!(
        sky_warning.contains("colour") && sky_warning.contains("HOSEK_WILKIE"),
        "{sky_warning}"
    );
    // The sky reads as the world's colour, added to the image: +X is the image's left
    // texel's right edge... use the texels' centres: u = 0.25 (+Y) and 0.75 (-Y).
    let env = environment(&s);
    let at = |b: Vec3| env.radiance(&s, from_blender(b), 2, 0);
    let sky = Vec3::new(0.1, 0.2, 0.3);
    assert!((at(Vec3::Y) - (Vec3::new(0.25, 0.5, 1.0) + sky)).length() < 1e-6);
    assert!((at(-Vec3::Y) - (Vec3::new(2.0, 4.0, 8.0) + sky)).length() < 1e-6);

    // A graph that does not parse, or an image that cannot be read, is reported and falls back.
    let mut bad = doc.clone();
    bad["extensions"]["TESELA_world"]["graph"] = json!({"nodes": [{"inputs": {}}]});
    let s =
        tesela::scene::gltf::load_from_slice(&inputs::json_bytes(&bad), None, "w.gltf").unwrap();
    assert!(s.world.graph.is_none());
    assert!(
        s.warnings.iter().any(|w| w.contains("world 'Sunset'")),
        "{:?}",
        s.warnings
    );
    assert_eq!(s.background, Vec3::new(0.1, 0.2, 0.3));
    let mut bad = doc.clone();
    bad["extensions"]["TESELA_world"]["graph"]["nodes"][0]["props"]["image"] = json!(7);
    let s =
        tesela::scene::gltf::load_from_slice(&inputs::json_bytes(&bad), None, "w.gltf").unwrap();
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("'Env'") && w.contains("missing")),
        "{:?}",
        s.warnings
    );
    let mut warnings = Vec::new();
    let e = tesela::emitter::environment::world_emitter(&s, Mat4::IDENTITY, &mut warnings);
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("world 'Sunset'") && w.contains("magenta"))
    );
    // Magenta everywhere: the world no longer depends on the direction, so it is the
    // constant background.
    let Some(EmitterInstance::Background(bg)) = e else {
        panic!("a world of a missing image and a colour is constant")
    };
    let c = bg.radiance;
    assert!(
        (c - (Vec3::new(1.0, 0.0, 1.0) + sky)).length() < 1e-6,
        "{c}"
    );
}

// ---------------------------------------------------------------------------------------------
// The command line.

fn tesela(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_tesela"))
        .args(args)
        .output()
        .expect("cannot run tesela");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn write_exr(
    path: &std::path::Path,
    w: usize,
    h: usize,
    f: impl Fn(usize, usize) -> [f32; 3] + Sync,
) {
    exr::prelude::write_rgb_file(path, w, h, |x, y| {
        let c = f(x, y);
        (c[0], c[1], c[2])
    })
    .unwrap();
}

fn read_exr(path: &std::path::Path) -> (usize, usize, Vec<[f32; 4]>) {
    let img = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![[0.0f32; 4]; res.width() * res.height()]),
        |(w, px): &mut (usize, Vec<[f32; 4]>), pos, (r, g, b, a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = [r, g, b, a];
        },
    )
    .unwrap();
    let size = img.layer_data.size;
    (
        size.width(),
        size.height(),
        img.layer_data.channel_data.pixels.1,
    )
}

#[test]
fn cli_env_renders_hostile_images_or_says_why() {
    let dir = inputs::scratch("environment", "cli");
    let empty = inputs::write(
        &dir,
        "empty.gltf",
        &inputs::json_bytes(&json!({"asset": {"version": "2.0"}})),
    );
    let empty = empty.to_str().unwrap();
    let out = dir.join("out.exr");
    let out_s = out.to_str().unwrap();
    let render = |env: &str, extra: &[&str]| {
        let mut a = vec![
            "render", empty, "--env", env, "-o", out_s, "--width", "8", "--height", "4", "--spp",
            "2", "--quiet",
        ];
        a.extend_from_slice(extra);
        tesela(&a)
    };
    // 1x1: the whole world is that texel, times the strength.
    let one = dir.join("one.exr");
    write_exr(&one, 1, 1, |_, _| [0.25, 0.5, 1.0]);
    let (code, err) = render(
        one.to_str().unwrap(),
        &["--env-strength", "2", "--env-rotation", "-30"],
    );
    assert_eq!(code, 0, "{err}");
    let (_, _, px) = read_exr(&out);
    for p in &px {
        assert!(
            (Vec3::new(p[0], p[1], p[2]) - Vec3::new(0.5, 1.0, 2.0)).length() < 1e-5,
            "{p:?}"
        );
    }
    // 100000 x 2, and NaN/Inf/negative texels: finite images, the bad texels reported.
    let wide = dir.join("wide.exr");
    write_exr(&wide, 100_000, 2, |x, y| {
        [
            (x % 7) as f32 * 0.1,
            y as f32,
            match x % 5 {
                0 => f32::NAN,
                1 => f32::INFINITY,
                2 => -3.0,
                _ => 0.5,
            },
        ]
    });
    let (code, err) = render(wide.to_str().unwrap(), &[]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("not finite"), "{err}");
    let (w, h, px) = read_exr(&out);
    assert_eq!((w, h), (8, 4));
    assert!(
        px.iter().flatten().all(|v| v.is_finite() && *v >= 0.0),
        "{px:?}"
    );
    // Radiance HDR is read too.
    let hdr = dir.join("sky.hdr");
    let mut f = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n".to_vec();
    f.extend_from_slice(&[128, 64, 32, 129, 0, 0, 0, 0]); // (1, 0.5, 0.25), black
    std::fs::write(&hdr, f).unwrap();
    let (code, err) = render(hdr.to_str().unwrap(), &[]);
    assert_eq!(code, 0, "{err}");
    // Missing, corrupt and unknown files are load errors (3) naming the file.
    for (name, bytes) in [
        ("garbage.exr", &b"not an exr at all"[..]),
        ("garbage.hdr", &b"#?RADIANCE\nnonsense"[..]),
        ("image.png", &b"\x89PNG"[..]),
    ] {
        let p = inputs::write(&dir, name, bytes);
        let (code, err) = render(p.to_str().unwrap(), &[]);
        assert_eq!(code, 3, "{name}: {err}");
        assert!(err.contains(name), "{name}: {err}");
    }
    let (code, err) = render(dir.join("absent.exr").to_str().unwrap(), &[]);
    assert_eq!(code, 3, "{err}");
    assert!(err.contains("absent.exr"), "{err}");
    // Bad numbers are usage errors (2).
    for extra in [
        ["--env-strength", "-1"],
        ["--env-strength", "nan"],
        ["--env-rotation", "inf"],
    ] {
        let (code, err) = render(one.to_str().unwrap(), &extra);
        assert_eq!(code, 2, "{extra:?}: {err}");
    }
    let (code, err) = tesela(&[
        "render",
        empty,
        "--background",
        "0.1",
        "-2",
        "0.3",
        "-o",
        out_s,
    ]);
    assert_eq!(code, 2, "{err}");
    let (code, err) = tesela(&[
        "render",
        empty,
        "--background",
        "0.1",
        "0.2",
        "0.3",
        "-o",
        out_s,
        "--width",
        "4",
        "--height",
        "4",
        "--spp",
        "1",
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let (_, _, px) = read_exr(&out);
    assert!(
        px.iter()
            .all(|p| (p[0] - 0.1).abs() < 1e-6 && (p[2] - 0.3).abs() < 1e-6)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The sampler never produces a direction whose density is zero, and `pdf` is zero exactly
/// where the map is (cells of zero radiance), even with most of the sphere black.
#[test]
fn black_cells_are_never_sampled() {
    let img = float_image(64, 32, |x, y| {
        if x == 10 && y == 5 {
            [5.0; 3]
        } else {
            [0.0; 3]
        }
    });
    let scene = env_scene(img, 1.0, 0.0);
    let env = environment(&scene);
    let mut rng = Sampler::new(3, 0, 0);
    for _ in 0..100_000 {
        let mut rec = EmitterQueryRecord::from_ref(Vec3::ZERO);
        let w = env.sample(&scene, &mut rec, rng.next_2d());
        assert!(rec.pdf > 0.0, "{}", rec.wi);
        assert!(w.is_finite());
    }
    let _ = Vec2::ZERO;
}

/// Film > Transparent Glass: a glass ball in front of the sky on a transparent film. With it,
/// the sky seen through the ball is transparent (less alpha, less colour there); without it
/// the ball is opaque; the render is the same for any thread count.
#[test]
fn transparent_glass_clears_the_world_seen_through_glass() {
    let mut s = env_scene(sun_sky(), 1.0, 0.0);
    s.materials.push(Material::glass("ball", 1.45));
    s.meshes.push(sphere("ball", 0, Vec3::ZERO, 1.0, 24, 48));
    s.camera = camera(Mat4::from_translation(Vec3::new(0.0, 0.0, 4.0)), 40.0);
    s.settings.film_transparent = true;
    let mut g = s.clone();
    g.settings.film_transparent_glass = Some(0.1);
    let mut o = opts("path_mis", 16, 16, 8, 3);
    let off = render_with(s, &o);
    let on = render_with(g.clone(), &o);
    let centre = 8 * 16 + 8;
    assert_eq!(
        off[centre][3], 1.0,
        "without the setting the glass is opaque"
    );
    assert!(
        on[centre][3] < 0.5,
        "the sky through the glass: alpha {}",
        on[centre][3]
    );
    assert!(on[centre][0] < off[centre][0], "and no sky colour");
    assert_eq!(on[0], off[0], "the sky beside the ball is the same");
    o.threads = 1;
    assert_eq!(render_with(g, &o), on, "the same for any thread count");
}
