//! Integrators against analytic solutions (furnaces, form factors), against each other
//! (Welch t-tests on independent renders), and for determinism and light leaks.
//! Thresholds are several standard errors wide with fixed seeds, so a real bias crosses them.

use glam::{Mat4, Vec3};
use std::f32::consts::PI;
use std::sync::atomic::AtomicBool;
use tesela::emitter::LightChoice;
use tesela::render::{self, RenderOptions};
use tesela::render_scene::RenderScene;
use tesela::scene::builtin::{quad, sphere};
use tesela::scene::{Camera, Material, Mesh, Projection, Scene};

const ALL: [&str; 5] = [
    "direct_ems",
    "direct_mats",
    "direct_mis",
    "path_mats",
    "path_mis",
];

fn render_with(scene: Scene, opts: &RenderOptions, choice: LightChoice) -> Vec<[f32; 4]> {
    let rs = RenderScene::new(scene, choice);
    let (img, stats) = render::render(&rs, opts, &AtomicBool::new(false), &|_, _, _| {}).unwrap();
    assert_eq!(stats.rejected_samples, 0, "non-finite samples");
    img.pixels
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

/// Mean and standard error of the mean of one channel over pixels whose true values are equal.
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

fn assert_close(name: &str, pixels: &[[f32; 4]], expected: f64) {
    let (mean, se) = mean_se(pixels, 0);
    let tol = 4.0 * se + 1e-4 * expected.abs();
    assert!(
        (mean - expected).abs() <= tol,
        "{name}: mean {mean:.5} expected {expected:.5} (4 se = {:.5})",
        4.0 * se
    );
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

/// Camera inside a closed sphere of albedo ρ that emits Le from both faces:
/// L = Le Σ_{k<D} ρ^k for depth D (Le(1+ρ) for direct light, Le/(1-ρ) in the limit).
#[test]
fn closed_emissive_furnace_matches_geometric_series() {
    let rho = 0.5f64;
    let le = 1.0f64;
    let make = || {
        let mut s = Scene::default();
        let mut m = Material::diffuse("shell", Vec3::splat(rho as f32));
        m.emission = Vec3::splat(le as f32);
        m.emission_two_sided = true;
        s.materials.push(m);
        let mut sph = sphere("shell", 0, Vec3::ZERO, 1.0, 24, 48);
        sph.normals.clear(); // flat facets: the furnace is exact for any closed surface
        s.meshes.push(sph);
        s.camera = camera(Mat4::IDENTITY, 60.0);
        s
    };
    for name in ALL {
        let px = render_with(make(), &opts(name, 16, 64, 2, 1), LightChoice::Power);
        assert_close(&format!("{name} depth 2"), &px, le * (1.0 + rho));
    }
    for name in ["path_mats", "path_mis"] {
        let px = render_with(make(), &opts(name, 16, 64, 5, 2), LightChoice::Power);
        assert_close(
            &format!("{name} depth 5"),
            &px,
            le * (1.0 - rho.powi(5)) / (1.0 - rho),
        );
        let px = render_with(make(), &opts(name, 16, 64, 64, 3), LightChoice::Power);
        assert_close(&format!("{name} depth 64"), &px, le / (1.0 - rho));
    }
    // Depth 1 shows the emitter only.
    let px = render_with(make(), &opts("path_mis", 8, 4, 1, 4), LightChoice::Power);
    assert_close("depth 1", &px, le);
}

/// A convex Lambertian object of albedo ρ under a constant background L_b reflects ρ L_b,
/// for every integrator (background emitter sampling, BSDF sampling and MIS).
#[test]
fn white_furnace_under_constant_background() {
    let rho = 0.8f64;
    let lb = 0.7f64;
    for name in ALL {
        let mut s = Scene::default();
        s.materials
            .push(Material::diffuse("ball", Vec3::splat(rho as f32)));
        let mut sph = sphere("ball", 0, Vec3::ZERO, 1.0, 24, 48);
        sph.normals.clear();
        s.meshes.push(sph);
        s.background = Vec3::splat(lb as f32);
        // A narrow view of the ball's centre: every camera ray hits it.
        s.camera = camera(Mat4::from_translation(Vec3::new(0.0, 0.0, 4.0)), 5.0);
        let px = render_with(s, &opts(name, 16, 64, 8, 5), LightChoice::Power);
        assert_close(name, &px, rho * lb);
    }
}

/// Form factor from a point to a parallel rectangle whose corner is straight above it at
/// height 1, with sides `x` and `y` (in units of the height).
fn corner_form_factor(x: f64, y: f64) -> f64 {
    let (ax, ay) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / ax * (y / ax).atan() + y / ay * (x / ay).atan()) / (2.0 * std::f64::consts::PI)
}

/// A floor patch under an emissive square (then a disk) at height h: the reflected radiance is
/// ρ · L · F with the closed-form form factor F.
#[test]
fn analytic_irradiance_under_square_and_disk() {
    let (rho, le, h, side) = (0.5f64, 3.0f64, 1.0f32, 1.2f32);
    let build = |light: Mesh| {
        let mut s = Scene::default();
        s.materials
            .push(Material::diffuse("floor", Vec3::splat(rho as f32)));
        s.materials
            .push(Material::emitter("light", Vec3::splat(le as f32), false));
        let v = Vec3::new;
        s.meshes.push(quad(
            "floor",
            0,
            v(-50., 0., 50.),
            v(50., 0., 50.),
            v(50., 0., -50.),
            v(-50., 0., -50.),
        ));
        s.meshes.push(light);
        // Looking straight down from below the light with a tiny field of view.
        let look_down = Mat4::from_translation(v(0.0, 0.5, 0.0)) * Mat4::from_rotation_x(-PI / 2.0);
        s.camera = camera(look_down, 0.5);
        s
    };
    let v = Vec3::new;
    let a = side / 2.0;
    // Counter-clockwise seen from below: the emitting side faces down.
    let square = quad(
        "light",
        1,
        v(-a, h, a),
        v(-a, h, -a),
        v(a, h, -a),
        v(a, h, a),
    );
    let f_square = 4.0 * corner_form_factor((a / h) as f64, (a / h) as f64);
    let r = 0.8f32;
    let mut disk = Mesh {
        name: "disk".into(),
        material: 1,
        ..Default::default()
    };
    disk.positions.push(v(0.0, h, 0.0));
    let n = 256;
    for i in 0..n {
        let phi = 2.0 * PI * i as f32 / n as f32;
        disk.positions.push(v(r * phi.cos(), h, r * phi.sin()));
    }
    for i in 0..n {
        // Winding so the normal points down (-Y).
        disk.indices.push([0, 1 + i, 1 + (i + 1) % n]);
    }
    // The polygon's inscribed area is slightly below the disk's; use its exact equivalent radius.
    let poly_area =
        0.5 * n as f64 * (r as f64).powi(2) * (2.0 * std::f64::consts::PI / n as f64).sin();
    let r_eq2 = poly_area / std::f64::consts::PI;
    let f_disk = r_eq2 / (r_eq2 + (h as f64).powi(2));
    for (light, f, label) in [(square, f_square, "square"), (disk, f_disk, "disk")] {
        for name in ALL {
            let px = render_with(
                build(light.clone()),
                &opts(name, 8, 256, 2, 7),
                LightChoice::Power,
            );
            assert_close(&format!("{label} {name}"), &px, rho * le * f);
        }
    }
}

/// Image means of `k` independent renders.
fn image_means(scene: &dyn Fn() -> Scene, name: &str, k: u64, choice: LightChoice) -> Vec<f64> {
    (0..k)
        .map(|seed| {
            let px = render_with(scene(), &opts(name, 24, 8, 2, 100 + seed), choice);
            px.iter().map(|p| (p[0] + p[1] + p[2]) as f64).sum::<f64>() / px.len() as f64
        })
        .collect()
}

/// Welch's t statistic of two samples.
fn welch_t(a: &[f64], b: &[f64]) -> f64 {
    let m = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    let v = |x: &[f64], mu: f64| {
        x.iter().map(|y| (y - mu).powi(2)).sum::<f64>() / (x.len() as f64 - 1.0)
    };
    let (ma, mb) = (m(a), m(b));
    (ma - mb) / (v(a, ma) / a.len() as f64 + v(b, mb) / b.len() as f64).sqrt()
}

/// direct_ems, direct_mats and direct_mis estimate the same direct illumination of the Cornell
/// box (and power-proportional and uniform light choice agree).
#[test]
fn direct_integrators_agree_on_cornell_box() {
    let scene = || tesela::scene::builtin::cornell_box();
    let ems = image_means(&scene, "direct_ems", 12, LightChoice::Power);
    let mats = image_means(&scene, "direct_mats", 12, LightChoice::Power);
    let mis = image_means(&scene, "direct_mis", 12, LightChoice::Power);
    let uni = image_means(&scene, "direct_mis", 12, LightChoice::Uniform);
    // |t| > 4.5 has probability < 0.1% for 22 degrees of freedom.
    for (label, a, b) in [
        ("ems/mats", &ems, &mats),
        ("ems/mis", &ems, &mis),
        ("mats/mis", &mats, &mis),
        ("power/uniform", &mis, &uni),
    ] {
        let t = welch_t(a, b);
        assert!(t.abs() < 4.5, "{label}: t = {t:.2} ({a:?} vs {b:?})");
    }
}

#[test]
fn identical_image_for_any_thread_count() {
    let scene = || tesela::scene::builtin::cornell_spheres();
    let mut o = opts("path_mis", 32, 4, 8, 9);
    o.threads = 1;
    let one = render_with(scene(), &o, LightChoice::Power);
    o.threads = 2;
    o.tile_size = 7;
    let two = render_with(scene(), &o, LightChoice::Power);
    assert!(
        one.iter()
            .zip(&two)
            .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits))
    );
    o.seed = 10;
    let other = render_with(scene(), &o, LightChoice::Power);
    assert!(one != other, "the seed changes the image");
}

/// A light whose edge touches a wall lights only its own side: the floor behind the wall stays
/// exactly black (no light leaks through the junction).
#[test]
fn light_touching_a_wall_does_not_leak() {
    let v = Vec3::new;
    let mut s = Scene::default();
    let mut wall_mat = Material::diffuse("wall", Vec3::splat(0.8));
    wall_mat.double_sided = true;
    s.materials.push(wall_mat);
    s.materials
        .push(Material::emitter("light", Vec3::splat(10.0), false));
    s.meshes.push(quad(
        "floor",
        0,
        v(-2., 0., 2.),
        v(2., 0., 2.),
        v(2., 0., -2.),
        v(-2., 0., -2.),
    ));
    s.meshes.push(quad(
        "wall",
        0,
        v(0., 0., 2.),
        v(0., 0., -2.),
        v(0., 1., -2.),
        v(0., 1., 2.),
    ));
    // Light from x = 0 (touching the wall) to x = 0.3, facing down.
    s.meshes.push(quad(
        "light",
        1,
        v(0., 0.5, 0.3),
        v(0., 0.5, -0.3),
        v(0.3, 0.5, -0.3),
        v(0.3, 0.5, 0.3),
    ));
    // Look down at the floor just behind the wall (x in [-0.21, -0.01]).
    s.camera = Some(Camera {
        projection: Projection::Orthographic { ymag: 0.1 },
        to_world: Mat4::from_translation(v(-0.11, 0.4, 0.0)) * Mat4::from_rotation_x(-PI / 2.0),
        aspect: None,
        ..Default::default()
    });
    for name in ALL {
        let px = render_with(s.clone(), &opts(name, 16, 16, 2, 11), LightChoice::Power);
        let max = px
            .iter()
            .map(|p| p[0].max(p[1]).max(p[2]))
            .fold(0.0f32, f32::max);
        assert_eq!(max, 0.0, "{name}: light leaked behind the wall");
    }
    // The lit side is lit (the test can see light at all).
    s.camera.as_mut().unwrap().to_world =
        Mat4::from_translation(v(0.15, 0.4, 0.0)) * Mat4::from_rotation_x(-PI / 2.0);
    let px = render_with(s, &opts("direct_ems", 8, 4, 2, 12), LightChoice::Power);
    let dark = px.iter().filter(|p| p[0] <= 0.0).count();
    assert_eq!(dark, 0, "lit side: {:?}", &px[..4]);
}

/// A mirror seen by the camera shows the light it reflects in every integrator that can
/// (BSDF sampling sees delta lobes; emitter sampling follows the delta chain).
#[test]
fn mirror_reflects_an_emitter_in_every_integrator() {
    let v = Vec3::new;
    let mut s = Scene::default();
    s.materials.push(Material::mirror("mirror", Vec3::ONE));
    s.materials
        .push(Material::emitter("light", Vec3::splat(2.0), true));
    // A mirror floor and a large two-sided emitter above it; the camera looks down at the mirror.
    s.meshes.push(quad(
        "mirror",
        0,
        v(-5., 0., 5.),
        v(5., 0., 5.),
        v(5., 0., -5.),
        v(-5., 0., -5.),
    ));
    s.meshes.push(quad(
        "light",
        1,
        v(-5., 2., -5.),
        v(5., 2., -5.),
        v(5., 2., 5.),
        v(-5., 2., 5.),
    ));
    s.camera = camera(
        Mat4::from_translation(v(0.0, 1.0, 0.0)) * Mat4::from_rotation_x(-PI / 2.0),
        20.0,
    );
    for name in ALL {
        let px = render_with(s.clone(), &opts(name, 8, 4, 3, 13), LightChoice::Power);
        assert_close(name, &px, 2.0);
    }
}

/// `o` with Cycles' Filter Glossy set to `blur_glossy`.
fn filter_glossy(mut o: RenderOptions, blur_glossy: f32) -> RenderOptions {
    o.light_paths.filter_glossy = tesela::integrator::filter_glossy::FilterGlossy::new(blur_glossy);
    o
}

/// Filter Glossy never blurs the camera ray's hit nor a lobe after delta bounces only: a
/// mirror floor seen from above shows an emitter over half of it and a mirror ceiling over
/// the other half (which would catch the emitter if it were blurred), and with depth 3 no
/// path shades anything after a non-delta bounce, so the image is the same bit for bit.
#[test]
fn filter_glossy_leaves_camera_hits_and_delta_chains_sharp() {
    let v = Vec3::new;
    let mut s = Scene::default();
    s.materials.push(Material::mirror("mirror", Vec3::ONE));
    s.materials
        .push(Material::emitter("light", Vec3::splat(2.0), true));
    s.meshes.push(quad(
        "floor",
        0,
        v(-5., 0., 5.),
        v(5., 0., 5.),
        v(5., 0., -5.),
        v(-5., 0., -5.),
    ));
    s.meshes.push(quad(
        "light",
        1,
        v(-5., 2., -5.),
        v(0., 2., -5.),
        v(0., 2., 5.),
        v(-5., 2., 5.),
    ));
    s.meshes.push(quad(
        "ceiling",
        0,
        v(0., 2., -5.),
        v(5., 2., -5.),
        v(5., 2., 5.),
        v(0., 2., 5.),
    ));
    s.camera = camera(
        Mat4::from_translation(v(0.0, 1.0, 0.0)) * Mat4::from_rotation_x(-PI / 2.0),
        40.0,
    );
    for name in ["path_mats", "path_mis"] {
        let o = opts(name, 16, 4, 3, 21);
        let sharp = render_with(s.clone(), &o, LightChoice::Power);
        let blurred = render_with(s.clone(), &filter_glossy(o, 1.0), LightChoice::Power);
        assert!(
            sharp.iter().any(|p| p[0] > 1.0),
            "{name}: the light is reflected"
        );
        assert_eq!(sharp, blurred, "{name}");
    }
}

/// A white floor lit only through a mirror ceiling: a light of half-size `l` at height 1,
/// centred over `x = cx`, shines up into a mirror of half-size `m` at height 2 (its image, at
/// height 3, lights the floor); the camera, at height 0.6, looks straight down at the floor.
fn caustic_scene(m: f32, l: f32, cx: f32) -> Scene {
    let v = Vec3::new;
    let mut s = Scene::default();
    s.materials.push(Material::diffuse("white", Vec3::ONE));
    s.materials.push(Material::mirror("mirror", Vec3::ONE));
    s.materials
        .push(Material::emitter("light", Vec3::splat(10.0), false));
    s.meshes.push(quad(
        "floor",
        0,
        v(-5., 0., 5.),
        v(5., 0., 5.),
        v(5., 0., -5.),
        v(-5., 0., -5.),
    ));
    s.meshes.push(quad(
        "mirror",
        1,
        v(-m, 2., -m),
        v(m, 2., -m),
        v(m, 2., m),
        v(-m, 2., m),
    ));
    // Emits upwards only (the normal is +y); its dark back shades the floor below.
    s.meshes.push(quad(
        "light",
        2,
        v(cx - l, 1., l),
        v(cx + l, 1., l),
        v(cx + l, 1., -l),
        v(cx - l, 1., -l),
    ));
    s.camera = camera(
        Mat4::from_translation(v(0.0, 0.6, 0.0)) * Mat4::from_rotation_x(-PI / 2.0),
        60.0,
    );
    s
}

/// Mean luminance sum of `k` independent renders of `scene` at depth 3 (camera, floor,
/// mirror: the caustic and nothing else).
fn caustic_means(scene: &Scene, name: &str, blur_glossy: f32, spp: u32, k: u64) -> Vec<f64> {
    (0..k)
        .map(|seed| {
            let o = filter_glossy(opts(name, 16, spp, 3, 300 + seed), blur_glossy);
            let px = render_with(scene.clone(), &o, LightChoice::Power);
            px.iter().map(|p| (p[0] + p[1] + p[2]) as f64).sum::<f64>() / px.len() as f64
        })
        .collect()
}

/// After the floor's diffuse bounce (density cos θ / π ≤ 1/π per steradian) the mirror is a
/// GGX lobe of alpha at least sqrt(1 - 1/π)/2 ≈ 0.41 under Filter Glossy 1: a small mirror
/// then sends most of a small light's reflection past the floor in view, so the caustic
/// there dims severalfold. With a larger mirror and light, BSDF sampling alone (path_mats)
/// and MIS with emitter sampling at the blurred mirror (path_mis) agree on the blurred
/// caustic (Welch t-test), as they do on the sharp one: both integrators blur the same lobe.
#[test]
fn filter_glossy_blurs_a_caustic_after_a_diffuse_bounce() {
    let small = caustic_scene(0.25, 0.1, 0.0);
    let sharp = caustic_means(&small, "path_mis", 0.0, 16, 4);
    let blurred = caustic_means(&small, "path_mis", 1.0, 16, 4);
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    assert!(
        mean(&blurred) < 0.5 * mean(&sharp) && mean(&blurred) > 0.0,
        "blurred {blurred:?} vs sharp {sharp:?}"
    );
    // The light off to the side, where it does not hide the mirror from the floor in view.
    // The same image for any thread count.
    let mut o = filter_glossy(opts("path_mis", 16, 4, 6, 5), 1.0);
    o.threads = 1;
    let one = render_with(small.clone(), &o, LightChoice::Power);
    o.threads = 2;
    assert_eq!(one, render_with(small.clone(), &o, LightChoice::Power));
    let large = caustic_scene(1.5, 0.3, 1.0);
    for b in [0.0, 1.0] {
        let mats = caustic_means(&large, "path_mats", b, 256, 10);
        let mis = caustic_means(&large, "path_mis", b, 64, 10);
        // |t| > 4.5 has probability < 0.1% for 14 degrees of freedom or more.
        let t = welch_t(&mats, &mis);
        assert!(t.abs() < 4.5, "blur {b}: t = {t:.2} ({mats:?} vs {mis:?})");
        if b > 0.0 {
            // The blur changes this caustic too, by more than the test's resolution.
            let sharp = caustic_means(&large, "path_mis", 0.0, 64, 10);
            let t = welch_t(&sharp, &mis);
            assert!(t.abs() > 9.0, "the large caustic changes: t = {t:.2}");
        }
    }
}
