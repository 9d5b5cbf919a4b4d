//! Blender's light shapes (`TESELA_light` → `Light::Blender`): every integrator against exact
//! irradiance (sphere and disk lights, a spot's cone, a sun cone, area lights with spread, a
//! parallel beam), the chi-square test of each new sampler against its density, each
//! sampler's reported density and weight against `pdf()`/`eval()` (also on the record a ray
//! hit rebuilds), and the rules that lights never occlude and obey their ray visibility.

#[path = "common/chi2.rs"]
mod chi2_common;

use chi2_common::*;
use glam::{DVec3, Mat4, Vec2, Vec3};
use std::f32::consts::PI;
use std::f64::consts::PI as PI64;
use std::sync::atomic::AtomicBool;
use tesela::emitter::{
    AreaLight, Emitter, EmitterInstance, EmitterQueryRecord, LightChoice, SphereLight,
};
use tesela::render::{self, RenderOptions};
use tesela::render_scene::RenderScene;
use tesela::sampler::Sampler;
use tesela::scene::builtin::quad;
use tesela::scene::{
    Camera, Light, LightShape, LightVisibility, Material, Projection, Scene, SpotFalloff,
};

const ALL: [&str; 5] = [
    "direct_ems",
    "direct_mats",
    "direct_mis",
    "path_mats",
    "path_mis",
];

const RHO: f32 = 0.5;

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// A Lambertian floor (albedo [`RHO`]) at y = 0, seen straight down by a camera at height
/// `cam_h` with a tiny field of view: every pixel sees (nearly) the origin.
fn floor_scene(cam_h: f32) -> Scene {
    let mut s = Scene::default();
    s.materials
        .push(Material::diffuse("floor", Vec3::splat(RHO)));
    s.meshes.push(quad(
        "floor",
        0,
        v(-50., 0., 50.),
        v(50., 0., 50.),
        v(50., 0., -50.),
        v(-50., 0., -50.),
    ));
    let look_down = Mat4::from_translation(v(0.0, cam_h, 0.0)) * Mat4::from_rotation_x(-PI / 2.0);
    s.camera = Some(Camera {
        projection: Projection::Perspective {
            yfov: 0.2f32.to_radians(),
        },
        to_world: look_down,
        ..Default::default()
    });
    s
}

fn blender(shape: LightShape) -> Light {
    Light::Blender {
        profile: None,
        shape,
        visibility: LightVisibility::default(),
    }
}

fn point(position: Vec3, power: f32, radius: f32, soft: bool) -> LightShape {
    LightShape::Point {
        position,
        intensity: Vec3::splat(power / (4.0 * PI)),
        radius,
        soft_falloff: soft,
        spot: None,
    }
}

/// An area light facing down (-Y) centred on `c`, `su` along X and `sv` along Z.
fn area_down(c: Vec3, su: f32, sv: f32, ellipse: bool, power: f32, spread: f32) -> LightShape {
    let a = su * sv * if ellipse { PI / 4.0 } else { 1.0 };
    LightShape::Area {
        center: c,
        axis_u: Vec3::X,
        axis_v: Vec3::Z,
        normal: -Vec3::Y,
        size_u: su,
        size_v: sv,
        ellipse,
        radiance: Vec3::splat(power / (PI * a)),
        spread,
    }
}

fn render_mean(scene: Scene, integrator: &str, spp: u32, max_depth: u32) -> (f64, f64) {
    let rs = RenderScene::new(scene, LightChoice::Power);
    let opts = RenderOptions {
        width: 8,
        height: 8,
        spp,
        max_depth,
        seed: 11,
        integrator: integrator.into(),
        threads: 0,
        tile_size: 16,
        region: None,
        ..Default::default()
    };
    let (img, stats) = render::render(&rs, &opts, &AtomicBool::new(false), &|_, _, _| {}).unwrap();
    assert_eq!(stats.rejected_samples, 0, "non-finite samples");
    let px = &img.pixels;
    let n = px.len() as f64;
    let mean = px.iter().map(|p| p[0] as f64).sum::<f64>() / n;
    let var = px.iter().map(|p| (p[0] as f64 - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Every integrator's image mean equals `expected_e · ρ/π` within 4 standard errors (+0.2%).
fn assert_irradiance(name: &str, scene: &dyn Fn() -> Scene, expected_e: f64, spp: u32) {
    let want = expected_e * RHO as f64 / PI64;
    for integrator in ALL {
        let (mean, se) = render_mean(scene(), integrator, spp, 2);
        let tol = 4.0 * se + 2e-3 * want.abs();
        println!("{name} {integrator}: {mean:.6} vs {want:.6} (se {se:.2e})");
        assert!(
            (mean - want).abs() <= tol,
            "{name} {integrator}: mean {mean:.6}, expected {want:.6} (tolerance {tol:.2e})"
        );
    }
}

/// `cos θ` to the floor's normal and distance of the light centre seen from the origin.
fn geometry(c: Vec3) -> (f64, f64) {
    let d = c.as_dvec3().length();
    (c.y as f64 / d, d)
}

#[test]
fn sphere_and_disk_lights_light_a_plane_exactly() {
    // Fully above the horizon: a sphere of radiance L subtends a cone of half-angle α
    // (sin α = r/d), E = π L sin²α cos θ = I cos θ / d²; the disk facing the point subtends
    // tan β = r/d, E = π L sin²β cos θ = I cos θ / (d² + r²).
    let (c, power, r) = (v(0.5, 1.0, -0.3), 60.0f32, 0.4f32);
    let (cos, d) = geometry(c);
    let intensity = power as f64 / (4.0 * PI64);
    for (soft, e) in [
        (false, intensity * cos / (d * d)),
        (true, intensity * cos / (d * d + (r * r) as f64)),
    ] {
        let scene = || {
            let mut s = floor_scene(0.05);
            s.lights.push(blender(point(c, power, r, soft)));
            s
        };
        let name = if soft { "disk light" } else { "sphere light" };
        assert_irradiance(name, &scene, e, 256);
    }
}

#[test]
fn negative_lights_take_their_irradiance_away() {
    // A light of negative power (Cycles renders them: artists darken corners so) adds its
    // negative irradiance: a 60 W sphere light and a -10 W area light above the point give
    // E(60 W) - E(10 W), for every integrator (the light choice weighs the area light by
    // the magnitude of its power, so it is still sampled).
    let (c, power, r) = (v(0.5, 1.0, -0.3), 60.0f32, 0.4f32);
    let (cos, d) = geometry(c);
    let sphere = power as f64 / (4.0 * PI64) * cos / (d * d);
    let (ca, su, sv, neg) = (v(-0.2, 1.2, 0.1), 0.6f32, 0.4f32, -10.0f32);
    let l0 = neg as f64 / (PI64 * (su * sv) as f64);
    let area = area_irradiance(ca, su, sv, false, l0, PI64);
    assert!(area < -0.2 * sphere, "{area} {sphere}");
    let scene = || {
        let mut s = floor_scene(0.05);
        s.lights.push(blender(point(c, power, r, false)));
        s.lights
            .push(blender(area_down(ca, su, sv, false, neg, PI)));
        s
    };
    assert_irradiance(
        "sphere light and negative area light",
        &scene,
        sphere + area,
        256,
    );
}

#[test]
fn spot_sphere_samples_its_beam_when_narrower_than_the_ball() {
    // The ball subtends ~20° from the origin; the spot's hard-edged cone (blend 0) is 8° wide
    // around the line to the origin, so only light leaving within 8° of the axis arrives: the
    // cone of directions of half-angle 8° around the line, E = π L sin²(8°) cos θ.
    let c = v(0.3, 1.0, 0.2);
    let (power, r) = (40.0f32, 0.35f32);
    let half = 8f32.to_radians();
    let axis = (-c).normalize();
    let (cos, _) = geometry(c);
    let l = power as f64 / (4.0 * PI64) / (PI64 * (r * r) as f64);
    let e = PI64 * l * (half as f64).sin().powi(2) * cos;
    let scene = || {
        let mut s = floor_scene(0.05);
        s.lights.push(blender(LightShape::Point {
            position: c,
            intensity: Vec3::splat(power / (4.0 * PI)),
            radius: r,
            soft_falloff: false,
            spot: Some((
                axis,
                SpotFalloff::Cycles {
                    cos_half: half.cos(),
                    smooth: 0.0,
                },
            )),
        }));
        s
    };
    assert_irradiance("spot sphere", &scene, e, 512);
}

#[test]
fn sun_cone_keeps_the_irradiance() {
    // A 40° sun 30° from the zenith: E = S cos 30°, whatever the angle.
    let strength = 3.0f32;
    let tilt = 30f32.to_radians();
    let scene = || {
        let mut s = floor_scene(0.05);
        s.lights.push(blender(LightShape::Sun {
            direction: v(tilt.sin(), -tilt.cos(), 0.0),
            irradiance: Vec3::splat(strength),
            angle: 40f32.to_radians(),
        }));
        s
    };
    assert_irradiance(
        "sun cone",
        &scene,
        strength as f64 * (tilt as f64).cos(),
        256,
    );
}

/// `E` at the origin of the floor from an area light facing down at height `h` over
/// `[u0,u1] × [v0,v1]` (x, z; an ellipse inscribed in it when `ellipse`), radiance `l0`, spread
/// `spread`: a 1500² midpoint rule in f64.
fn area_irradiance(c: Vec3, su: f32, sv: f32, ellipse: bool, l0: f64, spread: f64) -> f64 {
    let m = 1500;
    let (hu, hv) = (su as f64 / 2.0, sv as f64 / 2.0);
    let half = spread / 2.0;
    let (t, norm) = (half.tan(), 1.0 / (half.tan() - half));
    let mut e = 0.0;
    for i in 0..m {
        for j in 0..m {
            let a = -1.0 + 2.0 * (i as f64 + 0.5) / m as f64;
            let b = -1.0 + 2.0 * (j as f64 + 0.5) / m as f64;
            if ellipse && a * a + b * b > 1.0 {
                continue;
            }
            let p = c.as_dvec3() + DVec3::new(a * hu, 0.0, b * hv);
            let d2 = p.length_squared();
            let cos = p.y / d2.sqrt();
            let f = if spread >= PI64 {
                1.0
            } else {
                let tan = (1.0 - cos * cos).sqrt() / cos;
                ((t - tan) * norm).max(0.0)
            };
            e += l0 * f * cos * cos / d2;
        }
    }
    e * (2.0 * hu / m as f64) * (2.0 * hv / m as f64)
}

#[test]
fn area_lights_with_spread_light_a_plane_exactly() {
    let power = 50.0f32;
    for (label, c, su, sv, ellipse, spread_deg) in [
        (
            "square, no spread",
            v(0.2, 1.0, 0.1),
            1.0,
            1.0,
            false,
            180.0f32,
        ),
        (
            "square, spread 60°",
            v(0.2, 1.0, 0.1),
            1.0,
            1.0,
            false,
            60.0,
        ),
        (
            "rectangle, spread 20°",
            v(0.1, 0.8, -0.05),
            2.0,
            0.6,
            false,
            20.0,
        ),
        (
            "ellipse, spread 90°",
            v(0.3, 1.2, 0.0),
            1.5,
            1.0,
            true,
            90.0,
        ),
        ("disk, no spread", v(-0.2, 0.9, 0.3), 1.0, 1.0, true, 180.0),
    ] {
        let spread = spread_deg.to_radians();
        let a = su * sv * if ellipse { PI / 4.0 } else { 1.0 };
        let l0 = power as f64 / (PI64 * a as f64);
        let e = area_irradiance(c, su, sv, ellipse, l0, spread as f64);
        let scene = || {
            let mut s = floor_scene(0.05);
            s.lights
                .push(blender(area_down(c, su, sv, ellipse, power, spread)));
            s
        };
        assert_irradiance(label, &scene, e, 256);
    }
}

#[test]
fn zero_spread_is_a_parallel_beam() {
    // Cycles: spread 0 sends the light straight down; a point under the light receives P/A.
    let (power, a) = (20.0f32, 0.5f32 * 0.8);
    for (c, expected) in [
        (v(0.1, 1.0, 0.05), (power / a) as f64),
        (v(0.6, 1.0, 0.0), 0.0),
    ] {
        let scene = || {
            let mut s = floor_scene(0.05);
            s.lights
                .push(blender(area_down(c, 0.5, 0.8, false, power, 0.0)));
            s
        };
        for integrator in ["direct_ems", "direct_mis", "path_mis"] {
            let (mean, _) = render_mean(scene(), integrator, 4, 2);
            let want = expected * RHO as f64 / PI64;
            assert!(
                (mean - want).abs() <= 1e-4 * want.max(1.0),
                "{integrator}: {mean} vs {want}"
            );
        }
    }
}

#[test]
fn lights_do_not_occlude_and_follow_their_visibility() {
    let strength = 2.0f32;
    let sun = || {
        blender(LightShape::Sun {
            direction: -Vec3::Y,
            irradiance: Vec3::splat(strength),
            angle: 10f32.to_radians(),
        })
    };
    // An area light facing up and a sphere light hang between the sun and the floor, over
    // the point the camera sees: they block nothing. Facing up, the area light does not
    // light the floor; the sphere light sits off to the side and is excluded from diffuse
    // surfaces, so only the sun remains.
    let e_sun = strength as f64;
    let scene = || {
        let mut s = floor_scene(0.05);
        s.lights.push(sun());
        let mut up = area_down(v(0.0, 1.0, 0.0), 1.0, 1.0, false, 100.0, PI);
        if let LightShape::Area { normal, .. } = &mut up {
            *normal = Vec3::Y;
        }
        s.lights.push(blender(up));
        s.lights.push(Light::Blender {
            profile: None,
            shape: point(v(0.0, 2.0, 0.0), 100.0, 0.3, false),
            visibility: LightVisibility {
                diffuse: false,
                ..Default::default()
            },
        });
        s
    };
    assert_irradiance("lights under a sun", &scene, e_sun, 64);

    // A box above the origin shadows a sphere light unless the light does not cast shadows.
    let c = v(0.0, 2.0, 0.0);
    let (cos, d) = geometry(c);
    let e_light = 30.0 / (4.0 * PI64) * cos / (d * d);
    for (cast_shadow, e) in [(true, 0.0), (false, e_light)] {
        let scene = || {
            let mut s = floor_scene(0.05);
            s.materials.push(Material::diffuse("box", Vec3::splat(0.5)));
            s.meshes.push(quad(
                "blocker",
                1,
                v(-0.5, 1.0, 0.5),
                v(-0.5, 1.0, -0.5),
                v(0.5, 1.0, -0.5),
                v(0.5, 1.0, 0.5),
            ));
            s.lights.push(Light::Blender {
                profile: None,
                shape: point(c, 30.0, 0.1, false),
                visibility: LightVisibility {
                    cast_shadow,
                    mis: false,
                    ..Default::default()
                },
            });
            s
        };
        for integrator in ["direct_ems", "direct_mis", "path_mis"] {
            let (mean, se) = render_mean(scene(), integrator, 64, 2);
            let want = e * RHO as f64 / PI64;
            assert!(
                (mean - want).abs() <= 4.0 * se + 2e-3 * want,
                "cast_shadow {cast_shadow} {integrator}: {mean} vs {want}"
            );
        }
    }

    // The camera sees a light's shape only when it is visible to the camera: looking up at an
    // area light from below, radiance L, else the black background behind it.
    for camera in [true, false] {
        let mut s = Scene::default();
        let l0 = 100.0 / PI;
        s.lights.push(Light::Blender {
            profile: None,
            shape: area_down(v(0.0, 2.0, 0.0), 1.0, 1.0, false, 100.0, PI),
            visibility: LightVisibility {
                camera,
                ..Default::default()
            },
        });
        s.camera = Some(Camera {
            projection: Projection::Perspective {
                yfov: 1f32.to_radians(),
            },
            to_world: Mat4::from_rotation_x(PI / 2.0),
            ..Default::default()
        });
        for integrator in ALL {
            let (mean, _) = render_mean(s.clone(), integrator, 4, 2);
            let want = if camera { l0 as f64 } else { 0.0 };
            assert!(
                (mean - want).abs() < 1e-4 * want.max(1.0),
                "camera {camera} {integrator}: {mean} vs {want}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Samplers: chi-square against the density, and the density and weight they report.

/// Density of `e` sampling direction `w` from `ref_p`: the light's `pdf()` on the record a ray
/// hit builds (as the integrators do), zero where the ray misses the shape.
fn shape_pdf(e: &EmitterInstance, ref_p: Vec3, w: Vec3) -> f64 {
    let scene = Scene::default();
    let w = w.normalize();
    let hit = match e {
        EmitterInstance::Sphere(s) => s.intersect(ref_p, w, f32::INFINITY),
        EmitterInstance::AreaLight(a) => {
            a.intersect(ref_p, w, f32::INFINITY).map(|t| (t, a.normal))
        }
        _ => unreachable!(),
    };
    let Some((t, n)) = hit else { return 0.0 };
    let rec = EmitterQueryRecord {
        ref_p,
        p: ref_p + w * t,
        n,
        ng: n,
        wi: w,
        dist: t,
        ..Default::default()
    };
    e.pdf(&scene, &rec) as f64
}

fn sphere_light(radius: f32, sphere: bool, spot: Option<(Vec3, SpotFalloff)>) -> EmitterInstance {
    EmitterInstance::Sphere(SphereLight {
        position: v(0.2, 1.5, -0.3),
        radius,
        radiance: v(3.0, 2.0, 1.0),
        sphere,
        spot,
    })
}

fn area_light(ellipse: bool, spread_deg: f32) -> EmitterInstance {
    let n = v(0.2, -1.0, 0.3).normalize();
    let u = n.cross(Vec3::Z).normalize();
    let w = n.cross(u);
    EmitterInstance::AreaLight(AreaLight::new(
        v(0.1, 1.2, 0.0),
        u,
        w,
        n,
        1.4,
        0.6,
        ellipse,
        v(2.0, 2.0, 2.0),
        spread_deg.to_radians(),
    ))
}

fn chi2_cases() -> Vec<(String, EmitterInstance, Vec3)> {
    let spot = |deg: f32| {
        Some((
            v(-0.1, -1.0, 0.2).normalize(),
            SpotFalloff::Cycles {
                cos_half: (0.5 * deg.to_radians()).cos(),
                smooth: 0.0,
            },
        ))
    };
    vec![
        (
            "sphere, far".into(),
            sphere_light(0.1, true, None),
            v(1.0, -2.0, 3.0),
        ),
        (
            "sphere, near".into(),
            sphere_light(0.5, true, None),
            v(0.5, 1.0, 0.2),
        ),
        (
            "sphere, inside".into(),
            sphere_light(0.5, true, None),
            v(0.3, 1.6, -0.2),
        ),
        (
            "spot sphere, beam cone".into(),
            sphere_light(0.6, true, spot(20.0)),
            v(0.0, 0.3, 0.0),
        ),
        (
            "disk, near".into(),
            sphere_light(0.5, false, None),
            v(0.6, 0.8, 0.1),
        ),
        (
            "disk, far".into(),
            sphere_light(0.2, false, None),
            v(-1.0, -0.5, 1.0),
        ),
        (
            "rectangle, solid angle".into(),
            area_light(false, 180.0),
            v(0.3, 0.2, 0.4),
        ),
        (
            "rectangle, grazing".into(),
            area_light(false, 180.0),
            v(2.5, 0.9, 0.3),
        ),
        (
            "rectangle, spread 50°".into(),
            area_light(false, 50.0),
            v(0.5, 0.0, 0.1),
        ),
        (
            "ellipse, area".into(),
            area_light(true, 180.0),
            v(-0.2, 0.4, 0.1),
        ),
        (
            "ellipse, spread 30°".into(),
            area_light(true, 30.0),
            v(0.2, 0.3, 0.0),
        ),
        (
            "ellipse, spread 120°".into(),
            area_light(true, 120.0),
            v(0.2, 0.6, 0.0),
        ),
    ]
}

#[test]
fn light_shape_samplers_match_their_densities() {
    let scene = Scene::default();
    let cases = chi2_cases();
    let alpha = sidak(SIGNIFICANCE, cases.len());
    for (k, (name, e, ref_p)) in cases.into_iter().enumerate() {
        // A grid around the light's centre seen from ref_p, wide enough for its support.
        let (center, extent) = match &e {
            EmitterInstance::Sphere(s) => (s.position, s.radius),
            EmitterInstance::AreaLight(a) => (a.center, a.half_u.hypot(a.half_v)),
            _ => unreachable!(),
        };
        let to = center - ref_p;
        let inside = to.length() <= extent;
        let (axis, theta_max) = if inside {
            (Vec3::Z, PI64)
        } else {
            let ratio = (extent / to.length()).min(1.0) as f64;
            // Spheres and disks are round in direction space: their edge (asin / atan of
            // r/d) is put on the boundary of the grid's 29th row, where the cubature of the
            // expected counts is exact; area lights get a margin.
            let theta = match &e {
                EmitterInstance::Sphere(s) if s.sphere => ratio.asin() * 30.0 / 29.0,
                EmitterInstance::Sphere(_) => ratio.atan() * 30.0 / 29.0,
                _ => ratio.asin() * 1.15 + 0.01,
            };
            (to.normalize(), theta.min(PI64))
        };
        let grid = DirGrid::new(axis, theta_max, 1.0, 30, 40);
        let r = check_directions(
            &name,
            &grid,
            400_000,
            900 + k as u64,
            &mut |s| {
                let mut rec = EmitterQueryRecord::from_ref(ref_p);
                let w = e.sample(&scene, &mut rec, s.next_2d());
                (rec.pdf > 0.0 && w.is_finite()).then_some(rec.wi)
            },
            &|w| shape_pdf(&e, ref_p, w),
            alpha,
        );
        assert!(r.integral <= 1.0 + 3e-3, "{name}: ∫pdf = {}", r.integral);
    }
}

#[test]
fn light_shape_samples_agree_with_pdf_and_eval() {
    let scene = Scene::default();
    let mut rng = Sampler::new(77, 0, 0);
    for (name, e, _) in chi2_cases() {
        let mut checked = 0;
        for _ in 0..20_000 {
            let ref_p = v(4.0, 4.0, 4.0) * (rng.next_2d().extend(rng.next_1d()) - 0.5) + Vec3::Y;
            let mut rec = EmitterQueryRecord::from_ref(ref_p);
            let w = e.sample(&scene, &mut rec, rng.next_2d());
            assert!(
                w.is_finite() && w.min_element() >= 0.0,
                "{name}: weight {w}"
            );
            if rec.pdf == 0.0 {
                assert_eq!(w, Vec3::ZERO, "{name}: weight without a density");
                continue;
            }
            assert!((rec.wi.length() - 1.0).abs() < 1e-4, "{name}");
            assert!(
                (rec.dist - (rec.p - ref_p).length()).abs() <= 2e-4 * rec.dist.max(1e-3),
                "{name}: dist {} vs |p - ref| {}",
                rec.dist,
                (rec.p - ref_p).length()
            );
            let pdf = e.pdf(&scene, &rec);
            assert!(
                (pdf - rec.pdf).abs() <= 1e-3 * pdf.max(rec.pdf),
                "{name}: sample pdf {} vs pdf() {pdf}",
                rec.pdf
            );
            let le = e.eval(&scene, &rec);
            assert!(
                (w - le / pdf).abs().max_element() <= 1e-3 * (le / pdf).max_element() + 1e-9,
                "{name}: weight {w} vs eval/pdf {}",
                le / pdf
            );
            // The record a ray towards the sample rebuilds gives the same density.
            let again = shape_pdf(&e, ref_p, rec.wi) as f32;
            assert!(
                (again - pdf).abs() <= 2e-3 * pdf,
                "{name}: ray-hit pdf {again} vs {pdf} at {ref_p}"
            );
            checked += 1;
        }
        println!("{name}: {checked} samples checked");
        assert!(checked > 1_000, "{name}: only {checked} samples");
    }
    // The parallel beam is a delta light: no density, no value, irradiance P/A straight down.
    let beam = area_light(false, 0.0);
    assert!(beam.is_delta());
    let EmitterInstance::AreaLight(a) = &beam else {
        unreachable!()
    };
    let mut rec = EmitterQueryRecord::from_ref(a.center + a.normal * 0.7);
    let w = beam.sample(&scene, &mut rec, Vec2::splat(0.5));
    assert!((w - a.radiance * PI).abs().max_element() < 1e-5);
    assert!(rec.wi.abs_diff_eq(-a.normal, 1e-6) && (rec.dist - 0.7).abs() < 1e-5);
    assert_eq!(
        (beam.pdf(&scene, &rec), beam.eval(&scene, &rec)),
        (0.0, Vec3::ZERO)
    );
}

#[test]
fn zero_radius_point_lights_stay_delta_lights() {
    let mut s = floor_scene(0.05);
    s.lights
        .push(blender(point(v(0., 1., 0.), 10.0, 0.0, false)));
    s.lights.push(blender(LightShape::Point {
        position: v(0., 1., 0.),
        intensity: Vec3::ONE,
        radius: 1e-30,
        soft_falloff: true,
        spot: None,
    }));
    let rs = RenderScene::new(s, LightChoice::Power);
    assert!(matches!(rs.emitters[0], EmitterInstance::Point(_)));
    assert!(
        matches!(rs.emitters[1], EmitterInstance::Point(_)),
        "radiance overflows"
    );
    assert!(!rs.has_light_shapes());
}

/// A floor lit by two dozen lights of every kind (none very close to it: heavy-tailed
/// estimates would blur the comparison) and a sun.
fn many_lights_scene() -> Scene {
    let mut s = floor_scene(3.0);
    if let Some(c) = &mut s.camera {
        c.projection = Projection::Perspective {
            yfov: 60f32.to_radians(),
        };
    }
    let mut rng = Sampler::new(21, 0, 0);
    for k in 0..24 {
        let p = v(
            rng.next_1d() * 6.0 - 3.0,
            0.8 + rng.next_1d() * 1.5,
            rng.next_1d() * 6.0 - 3.0,
        );
        let power = 10f32.powf(rng.next_1d() * 2.0);
        let shape = match k % 4 {
            0 => point(p, power, 0.05 + 0.15 * rng.next_1d(), k % 8 == 0),
            1 => point(p, power, 0.0, false),
            2 => LightShape::Point {
                position: p,
                intensity: Vec3::splat(power / (4.0 * PI)),
                radius: 0.1,
                soft_falloff: false,
                spot: Some((
                    v(0.2, -1.0, 0.1).normalize(),
                    SpotFalloff::Cycles {
                        cos_half: 0.8,
                        smooth: 0.05,
                    },
                )),
            },
            _ => area_down(p, 0.5, 0.3, k % 8 == 3, power, 1.2),
        };
        s.lights.push(blender(shape));
    }
    s.lights.push(blender(LightShape::Sun {
        direction: v(0.3, -1.0, 0.2).normalize(),
        irradiance: Vec3::splat(0.5),
        angle: 0.1,
    }));
    s
}

/// Renders `scene` with the light tree and with the flat choice by power: both must agree
/// with a long flat reference (t-tests over 8 seeds), the tree with less squared error.
fn tree_against_flat(scene: fn() -> Scene) {
    let rs = RenderScene::new(scene(), LightChoice::Power);
    assert!(rs.lights.uses_tree());
    let flat = RenderScene::new(scene(), LightChoice::Flat);
    assert!(!flat.lights.uses_tree());
    let stats = |rs: &RenderScene, seed: u64, spp: u32| {
        let opts = RenderOptions {
            width: 24,
            height: 24,
            spp,
            max_depth: 2,
            seed,
            integrator: "direct_mis".into(),
            threads: 0,
            tile_size: 16,
            region: None,
            ..Default::default()
        };
        let (img, st) = render::render(rs, &opts, &AtomicBool::new(false), &|_, _, _| {}).unwrap();
        assert_eq!(st.rejected_samples, 0);
        img.pixels.iter().map(|p| p[0] as f64).collect::<Vec<_>>()
    };
    let reference = stats(&flat, 999, 2048);
    let mean = |a: &[f64]| a.iter().sum::<f64>() / a.len() as f64;
    let sq = |a: &[f64]| {
        a.iter()
            .zip(&reference)
            .map(|(x, r)| (x - r) * (x - r))
            .sum::<f64>()
    };
    let (mut mt, mut mf) = (Vec::new(), Vec::new());
    let (mut err_t, mut err_f) = (0.0, 0.0);
    for seed in 0..8 {
        let (t, f) = (stats(&rs, seed, 16), stats(&flat, 100 + seed, 16));
        mt.push(mean(&t));
        mf.push(mean(&f));
        err_t += sq(&t);
        err_f += sq(&f);
    }
    let var = |a: &[f64]| {
        let m = mean(a);
        a.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (a.len() - 1) as f64
    };
    let r = mean(&reference);
    let t_tree = (mean(&mt) - r) / (var(&mt) / mt.len() as f64).sqrt();
    let t_flat = (mean(&mf) - r) / (var(&mf) / mf.len() as f64).sqrt();
    println!(
        "reference {r:.5}; tree {:.5} (t = {t_tree:.2}), flat {:.5} (t = {t_flat:.2}); \
         squared error at 16 spp: tree {err_t:.1}, flat {err_f:.1}",
        mean(&mt),
        mean(&mf)
    );
    assert!(
        t_tree.abs() < 4.0,
        "the light tree is biased: t = {t_tree:.2}"
    );
    assert!(
        t_flat.abs() < 4.0,
        "the flat choice is biased: t = {t_flat:.2}"
    );
    assert!(
        err_t < err_f,
        "the tree is not less noisy: {err_t} vs {err_f}"
    );
}

#[test]
fn light_tree_is_unbiased_and_less_noisy() {
    tree_against_flat(many_lights_scene);
}

/// A floor under a sun and one lamp just above it: the lamp's power is a sliver of the sun's
/// over the whole scene, yet it outshines the sun where the camera looks.
fn lamp_and_sun_scene() -> Scene {
    let mut s = floor_scene(2.0);
    if let Some(c) = &mut s.camera {
        c.projection = Projection::Perspective {
            yfov: 60f32.to_radians(),
        };
    }
    s.lights
        .push(blender(point(v(0.5, 0.8, 0.3), 30.0, 0.1, false)));
    s.lights.push(blender(LightShape::Sun {
        direction: v(0.3, -1.0, 0.2).normalize(),
        irradiance: Vec3::splat(0.5),
        angle: 0.1,
    }));
    s
}

#[test]
fn a_lamp_beside_a_sun_is_chosen_by_what_it_gives_the_point() {
    tree_against_flat(lamp_and_sun_scene);
    let rs = RenderScene::new(lamp_and_sun_scene(), LightChoice::Power);
    let (lamp, sun) = (0usize, 1usize);
    assert!(matches!(rs.emitters[sun], EmitterInstance::Directional(_)));
    // By power over the scene the sun takes nearly every shadow ray; under the lamp the tree
    // gives the lamp most of them, and fewer the farther the point.
    assert!(rs.lights.pmf(lamp) < 0.05, "{}", rs.lights.pmf(lamp));
    let shares: Vec<f32> = [0.0, 2.0, 10.0, 40.0]
        .iter()
        .map(|&x| rs.lights.pmf_at(v(0.5 + x, 0.0, 0.3), lamp))
        .collect();
    println!("lamp's share at 0, 2, 10, 40 from it: {shares:?}");
    assert!(shares[0] > 0.9, "{shares:?}");
    assert!(shares.windows(2).all(|w| w[1] < w[0]), "{shares:?}");
    assert!(shares[3] < 0.5, "{shares:?}");
    // The point's probabilities sum to one and are what sampling does.
    let mut rng = Sampler::new(77, 0, 0);
    for &x in &[0.0f32, 3.0, 12.0] {
        let p = v(0.5 + x, 0.0, 0.3);
        let total = rs.lights.pmf_at(p, lamp) + rs.lights.pmf_at(p, sun);
        assert!((total - 1.0).abs() < 1e-5, "{total}");
        let n = 20_000;
        let mut lamp_count = 0u32;
        for _ in 0..n {
            let (i, pmf) = rs.lights.sample_at(p, rng.next_1d()).unwrap();
            assert!((pmf - rs.lights.pmf_at(p, i)).abs() <= 1e-5 * pmf.max(1.0));
            lamp_count += (i == lamp) as u32;
        }
        let q = rs.lights.pmf_at(p, lamp) as f64;
        let z = (lamp_count as f64 - n as f64 * q) / (n as f64 * q * (1.0 - q)).sqrt().max(1e-9);
        assert!(
            z.abs() < 4.0,
            "at {p}: lamp chosen {lamp_count} of {n}, pmf {q}"
        );
    }
}
