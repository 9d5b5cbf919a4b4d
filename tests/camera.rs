//! Cameras against their analytic definitions: the lens sampler's distribution (chi-square),
//! thin-lens rays and the circle of confusion of a rendered point, lens shift, sensor fit,
//! orthographic extents, panoramic mappings (Cycles' conventions), `TESELA_camera` loading
//! and its fallbacks for bad values.

#[path = "common/chi2.rs"]
mod chi2_common;

use chi2_common::*;
use glam::{Mat4, Vec2, Vec3};
use serde_json::{Value, json};
use std::f64::consts::PI;
use std::sync::atomic::AtomicBool;
use tesela::camera::{RayCamera, sample_aperture};
use tesela::emitter::LightChoice;
use tesela::render::{self, RenderOptions};
use tesela::render_scene::RenderScene;
use tesela::sampler::Sampler;
use tesela::scene::{
    Aperture, Camera, Material, Mesh, Panorama, Projection, Scene, SensorFit, gltf,
};

const N: usize = 1_000_000;

// ---------------------------------------------------------------------------------------------
// The lens sampler.

/// Whether `(x, y)` lies in the aperture shape `sample_aperture(_, blades, rotation, ratio)`
/// covers: the unit disk or the regular polygon inscribed in it, then squeezed in x by `ratio`.
fn in_aperture(x: f64, y: f64, blades: u32, rotation: f64, ratio: f64) -> bool {
    let x = x * ratio;
    if blades < 3 {
        return x * x + y * y <= 1.0;
    }
    let n = blades as f64;
    // Edge k's outward normal is at angle rotation + 2πk/n, at distance cos(π/n).
    (0..blades).all(|k| {
        let a = rotation + 2.0 * PI * k as f64 / n;
        x * a.cos() + y * a.sin() <= (PI / n).cos()
    })
}

fn aperture_area(blades: u32, ratio: f64) -> f64 {
    let a = if blades < 3 {
        PI
    } else {
        0.5 * blades as f64 * (2.0 * PI / blades as f64).sin()
    };
    a / ratio
}

/// The fraction of the aperture's area inside the cell `[x0, x1] × [y0, y1]`: exact for
/// polygons (the cell clipped by the polygon's edges, Sutherland–Hodgman), numerically
/// integrated for the disk.
fn aperture_fraction(
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    blades: u32,
    rotation: f64,
    ratio: f64,
) -> f64 {
    let area = aperture_area(blades, ratio);
    if blades < 3 {
        let density = |x: f64, y: f64| {
            if in_aperture(x, y, blades, rotation, ratio) {
                1.0 / area
            } else {
                0.0
            }
        };
        return integrate(&density, x0, x1, y0, y1, 1e-9);
    }
    // Clip in the unsqueezed frame (x · ratio), where the polygon is regular.
    let mut poly = vec![
        (x0 * ratio, y0),
        (x1 * ratio, y0),
        (x1 * ratio, y1),
        (x0 * ratio, y1),
    ];
    let apothem = (PI / blades as f64).cos();
    for k in 0..blades {
        let a = rotation + 2.0 * PI * k as f64 / blades as f64;
        let (nx, ny) = (a.cos(), a.sin());
        let side = |p: (f64, f64)| p.0 * nx + p.1 * ny - apothem;
        let mut out = Vec::new();
        for i in 0..poly.len() {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            let (sp, sq) = (side(p), side(q));
            if sp <= 0.0 {
                out.push(p);
            }
            if (sp < 0.0) != (sq < 0.0) && sp != sq {
                let t = sp / (sp - sq);
                out.push((p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1)));
            }
        }
        poly = out;
        if poly.is_empty() {
            return 0.0;
        }
    }
    let mut a2 = 0.0;
    for i in 0..poly.len() {
        let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
        a2 += p.0 * q.1 - q.0 * p.1;
    }
    (0.5 * a2.abs() / ratio) / area
}

#[test]
fn lens_sampler_is_uniform_over_the_aperture() {
    let cases = [
        (0, 0.0, 1.0),
        (3, 0.4, 1.0),
        (5, 0.0, 1.0),
        (6, 1.1, 1.0),
        (9, 0.2, 1.0),
        (6, 0.3, 2.0),
        (0, 0.0, 0.5),
    ];
    let alpha = sidak(SIGNIFICANCE, cases.len());
    for (blades, rotation, ratio) in cases {
        let name = format!("aperture blades {blades} rotation {rotation} ratio {ratio}");
        let g = 40usize;
        // The grid covers [-1/ratio, 1/ratio] x [-1, 1].
        let (wx, wy) = (1.0 / ratio, 1.0);
        let mut obs = vec![0.0; g * g];
        let mut rng = Sampler::new(11, blades as u64, (ratio * 10.0) as u64);
        for _ in 0..N {
            let p = sample_aperture(rng.next_2d(), blades, rotation as f32, ratio as f32);
            let (x, y) = (p.x as f64, p.y as f64);
            // Slightly inflated: f32 rounding on the boundary.
            assert!(
                in_aperture(x * (1.0 - 1e-5), y * (1.0 - 1e-5), blades, rotation, ratio),
                "{name}: {p} outside the aperture"
            );
            let i = (((x / wx + 1.0) * 0.5 * g as f64) as usize).min(g - 1);
            let j = (((y / wy + 1.0) * 0.5 * g as f64) as usize).min(g - 1);
            obs[i * g + j] += 1.0;
        }
        let (hx, hy) = (2.0 * wx / g as f64, 2.0 * wy / g as f64);
        let exp: Vec<f64> = (0..g * g)
            .map(|c| {
                let (x0, y0) = (-wx + (c / g) as f64 * hx, -wy + (c % g) as f64 * hy);
                N as f64 * aperture_fraction(x0, x0 + hx, y0, y0 + hy, blades, rotation, ratio)
            })
            .collect();
        let total = exp.iter().sum::<f64>() / N as f64;
        assert!((total - 1.0).abs() < 1e-3, "{name}: ∫pdf = {total}");
        assert_chi2(&name, &obs, &exp, alpha);
    }
}

#[test]
fn lens_sampler_chi_square_detects_a_wrong_shape() {
    // The test above can fail: a hexagon's samples against a pentagon's density do.
    let g = 30usize;
    let mut obs = vec![0.0; g * g];
    let mut rng = Sampler::new(3, 0, 0);
    let n = 200_000;
    for _ in 0..n {
        let p = sample_aperture(rng.next_2d(), 6, 0.0, 1.0);
        let i = (((p.x as f64 + 1.0) * 0.5 * g as f64) as usize).min(g - 1);
        let j = (((p.y as f64 + 1.0) * 0.5 * g as f64) as usize).min(g - 1);
        obs[i * g + j] += 1.0;
    }
    let h = 2.0 / g as f64;
    let exp: Vec<f64> = (0..g * g)
        .map(|c| {
            let (x0, y0) = (-1.0 + (c / g) as f64 * h, -1.0 + (c % g) as f64 * h);
            n as f64 * aperture_fraction(x0, x0 + h, y0, y0 + h, 5, 0.0, 1.0)
        })
        .collect();
    let bad = match pearson(&obs, &exp) {
        Ok(c) => c.p < 1e-6,
        Err(_) => true, // samples where the pentagon has no density
    };
    assert!(bad, "a hexagon passed as a pentagon");
}

// ---------------------------------------------------------------------------------------------
// Thin-lens rays.

fn scene_with(camera: Camera) -> Scene {
    Scene {
        camera: Some(camera),
        ..Default::default()
    }
}

fn thin_lens(yfov_deg: f32, radius: f32, focus: f32, blades: u32) -> Camera {
    Camera {
        projection: Projection::Perspective {
            yfov: yfov_deg.to_radians(),
        },
        aperture: Some(Aperture {
            radius,
            focus_distance: focus,
            blades,
            rotation: 0.3,
            ratio: 1.0,
        }),
        ..Default::default()
    }
}

#[test]
fn rays_through_a_pixel_converge_at_the_focus_distance_and_spread_over_the_aperture() {
    let (radius, focus) = (0.02f32, 3.0f32);
    for blades in [0, 6] {
        let cam = RayCamera::new(&scene_with(thin_lens(50.0, radius, focus, blades)), 64, 48);
        let pin = RayCamera::new(&scene_with(Camera::default_with_fov(50.0)), 64, 48);
        let film = Vec2::new(40.3, 11.7);
        let p = pin.ray(film, Vec2::ZERO).unwrap();
        // The pinhole ray's point on the plane z = -focus.
        let target = p.o + p.d * (focus / -p.d.z);
        let mut rng = Sampler::new(1, 2, 3);
        let mut max_r = 0.0f32;
        let mut mean = Vec3::ZERO;
        let n = 20_000;
        for _ in 0..n {
            let r = cam.ray(film, rng.next_2d()).unwrap();
            assert!((r.d.length() - 1.0).abs() < 1e-5);
            // Starts on the lens plane, within the aperture...
            assert!(
                r.o.z.abs() < 1e-7 && r.o.length() <= radius * 1.0001,
                "{r:?}"
            );
            max_r = max_r.max(r.o.length());
            mean += r.o;
            // ...and meets the pinhole ray at the plane in focus.
            let at = r.o + r.d * ((focus + r.o.z) / -r.d.z);
            assert!((at - target).length() < 1e-5 * focus, "{at} vs {target}");
        }
        assert!(
            max_r > radius * 0.98,
            "blades {blades}: lens radius {max_r} < {radius}"
        );
        assert!(
            (mean / n as f32).length() < radius * 0.02,
            "lens samples not centred"
        );
    }
}

/// A small emissive square of side `size` facing +Z, centred at `c`.
fn emissive_square(c: Vec3, size: f32) -> Mesh {
    let h = size * 0.5;
    Mesh {
        name: "dot".into(),
        positions: vec![
            c + Vec3::new(-h, -h, 0.0),
            c + Vec3::new(h, -h, 0.0),
            c + Vec3::new(h, h, 0.0),
            c + Vec3::new(-h, h, 0.0),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        material: 0,
        ..Default::default()
    }
}

fn render_scene(scene: Scene, w: u32, h: u32, spp: u32, threads: usize) -> Vec<[f32; 4]> {
    let rs = RenderScene::new(scene, LightChoice::Power);
    let opts = RenderOptions {
        width: w,
        height: h,
        spp,
        max_depth: 1,
        seed: 5,
        integrator: "path_mis".into(),
        threads,
        tile_size: 16,
        region: None,
        ..Default::default()
    };
    let (img, stats) = render::render(&rs, &opts, &AtomicBool::new(false), &|_, _, _| {}).unwrap();
    assert_eq!(stats.rejected_samples, 0, "non-finite samples");
    img.pixels
}

/// Intensity-weighted centroid (pixels) and mean squared distance from it of channel 0.
fn moments(px: &[[f32; 4]], w: u32) -> (f64, Vec2, f64) {
    let mut s = 0.0f64;
    let (mut sx, mut sy) = (0.0f64, 0.0f64);
    for (i, p) in px.iter().enumerate() {
        let (x, y) = ((i as u32 % w) as f64 + 0.5, (i as u32 / w) as f64 + 0.5);
        s += p[0] as f64;
        sx += p[0] as f64 * x;
        sy += p[0] as f64 * y;
    }
    let (cx, cy) = (sx / s, sy / s);
    let mut r2 = 0.0;
    for (i, p) in px.iter().enumerate() {
        let (x, y) = ((i as u32 % w) as f64 + 0.5, (i as u32 / w) as f64 + 0.5);
        r2 += p[0] as f64 * ((x - cx).powi(2) + (y - cy).powi(2));
    }
    (s, Vec2::new(cx as f32, cy as f32), r2 / s)
}

#[test]
fn circle_of_confusion_of_an_out_of_focus_point_matches_the_thin_lens() {
    // Cycles' thin lens (the image plane at distance 1, the lens at the pinhole): a point at
    // depth d seen with focus distance f and lens radius R is a disk of radius
    // R · |1/f - 1/d| on the image plane, i.e. R |d - f| / (d f) / tan(fov/2) · H/2 pixels.
    let (w, h) = (96u32, 96u32);
    let yfov = 40f32;
    let t = (yfov.to_radians() * 0.5).tan() as f64;
    let px_per_unit = h as f64 / 2.0 / t;
    let (radius, focus) = (0.2f32, 2.0f32);
    for d in [1.0f32, 4.0] {
        // A square of side `size` at depth d: its image is `s` pixels wide.
        let size = 0.02 * d;
        let s_px = size as f64 / d as f64 * px_per_unit;
        let dot = |focus| {
            let mut s = scene_with(thin_lens(yfov, radius, focus, 0));
            s.materials
                .push(Material::emitter("e", Vec3::splat(100.0), true));
            s.meshes
                .push(emissive_square(Vec3::new(0.0, 0.0, -d), size));
            s
        };
        let (_, c, r2) = moments(&render_scene(dot(focus), w, h, 2048, 0), w);
        // A uniform disk of radius ρ has E[r²] = ρ²/2; the square adds s²/6 and the box
        // pixel filter 1/6 px² (variances of convolved shapes add).
        let rho = (2.0 * (r2 - s_px * s_px / 6.0 - 1.0 / 6.0)).sqrt();
        let want = radius as f64 * ((1.0 / focus - 1.0 / d) as f64).abs() * px_per_unit;
        assert!(
            (rho - want).abs() < 0.03 * want,
            "depth {d}: blur radius {rho:.3} px, thin lens {want:.3} px"
        );
        assert!((c - Vec2::new(48.0, 48.0)).length() < 0.2, "centre {c}");
        // In focus the same square is sharp: its pixels are its box-filtered coverage, whose
        // second moment about the centre (48, 48) is, per axis, Σ w_i (x_i - 48)² / Σ w_i
        // with w_i the overlap of pixel i with [48 - s/2, 48 + s/2].
        let (_, _, r2) = moments(&render_scene(dot(d), w, h, 256, 0), w);
        let (lo, hi) = (48.0 - s_px / 2.0, 48.0 + s_px / 2.0);
        let (mut sw, mut sm) = (0.0, 0.0);
        for i in 40..56 {
            let o = (hi.min(i as f64 + 1.0) - lo.max(i as f64)).max(0.0);
            sw += o;
            sm += o * (i as f64 + 0.5 - 48.0).powi(2);
        }
        let sharp = 2.0 * sm / sw;
        assert!(
            (r2 - sharp).abs() < 0.03 * sharp,
            "depth {d} in focus: E[r²] = {r2} px², a sharp square {sharp}"
        );
    }
}

#[test]
fn depth_of_field_renders_are_identical_for_any_thread_count() {
    let mut s = scene_with(thin_lens(40.0, 0.05, 2.0, 6));
    s.materials
        .push(Material::emitter("e", Vec3::splat(10.0), true));
    s.meshes
        .push(emissive_square(Vec3::new(0.1, 0.0, -1.0), 0.05));
    let a = render_scene(s.clone(), 48, 32, 16, 1);
    let b = render_scene(s, 48, 32, 16, 2);
    assert!(a.iter().zip(&b).all(|(x, y)| x == y));
    assert!(a.iter().any(|p| p[0] > 0.0));
}

// ---------------------------------------------------------------------------------------------
// Shift, sensor fit, orthographic extents.

trait DefaultWithFov {
    fn default_with_fov(deg: f32) -> Camera;
}

impl DefaultWithFov for Camera {
    fn default_with_fov(deg: f32) -> Camera {
        Camera {
            projection: Projection::Perspective {
                yfov: deg.to_radians(),
            },
            ..Default::default()
        }
    }
}

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).length() <= tol
}

#[test]
fn lens_shift_moves_the_image_by_the_fitted_dimension() {
    // Shift is in units of the fitted dimension: on a 200x100 image with AUTO fit (the
    // width), shift (0.1, 0.05) moves the image window by (20, 10) pixels right and up, so
    // the shifted camera sees at pixel p what the unshifted one sees at p + (20, -10).
    for (fit, w, h, unit) in [
        (SensorFit::Auto, 200u32, 100u32, 200.0f32),
        (SensorFit::Vertical, 200, 100, 100.0),
        (SensorFit::Horizontal, 100, 200, 100.0),
        (SensorFit::Auto, 100, 200, 200.0),
    ] {
        for ortho in [false, true] {
            let base = Camera {
                projection: if ortho {
                    Projection::Orthographic { ymag: 1.5 }
                } else {
                    Projection::Perspective { yfov: 0.8 }
                },
                fit,
                ..Default::default()
            };
            let plain = RayCamera::new(&scene_with(base), w, h);
            let shifted = RayCamera::new(
                &scene_with(Camera {
                    shift: Vec2::new(0.1, 0.05),
                    ..base
                }),
                w,
                h,
            );
            for film in [Vec2::new(10.0, 20.0), Vec2::new(55.5, 70.25)] {
                let a = shifted.ray(film, Vec2::ZERO).unwrap();
                let b = plain
                    .ray(film + Vec2::new(0.1 * unit, -0.05 * unit), Vec2::ZERO)
                    .unwrap();
                assert!(
                    close(a.o, b.o, 1e-5) && close(a.d, b.d, 1e-5),
                    "{fit:?} {w}x{h} ortho {ortho}: {a:?} vs {b:?}"
                );
            }
        }
    }
}

#[test]
fn orthographic_extents_follow_the_sensor_fit() {
    // Blender ortho_scale 4 (ymag 2 across the fitted dimension).
    let cam = |fit| Camera {
        projection: Projection::Orthographic { ymag: 2.0 },
        fit,
        ..Default::default()
    };
    for (fit, w, h, hx, hy) in [
        (SensorFit::Auto, 200u32, 100u32, 2.0f32, 1.0f32),
        (SensorFit::Auto, 100, 200, 1.0, 2.0),
        (SensorFit::Vertical, 200, 100, 4.0, 2.0),
        (SensorFit::Horizontal, 100, 200, 2.0, 4.0),
    ] {
        let rc = RayCamera::new(&scene_with(cam(fit)), w, h);
        let tl = rc.ray(Vec2::ZERO, Vec2::ZERO).unwrap();
        let br = rc.ray(Vec2::new(w as f32, h as f32), Vec2::ZERO).unwrap();
        assert!(
            close(tl.o, Vec3::new(-hx, hy, 0.0), 1e-5),
            "{fit:?}: {tl:?}"
        );
        assert!(
            close(br.o, Vec3::new(hx, -hy, 0.0), 1e-5),
            "{fit:?}: {br:?}"
        );
        assert!(close(tl.d, -Vec3::Z, 1e-6));
    }
}

#[test]
fn perspective_fit_keeps_the_fitted_field_of_view() {
    let t = (0.4f32).tan();
    for (fit, w, h, hx, hy) in [
        (SensorFit::Auto, 300u32, 100u32, t, t / 3.0),
        (SensorFit::Auto, 100, 300, t / 3.0, t),
        (SensorFit::Vertical, 300, 100, 3.0 * t, t),
        (SensorFit::Horizontal, 100, 300, t, 3.0 * t),
    ] {
        let rc = RayCamera::new(
            &scene_with(Camera {
                projection: Projection::Perspective { yfov: 0.8 },
                fit,
                ..Default::default()
            }),
            w,
            h,
        );
        let d = rc.ray(Vec2::new(w as f32, 0.0), Vec2::ZERO).unwrap().d;
        assert!(
            close(d, Vec3::new(hx, hy, -1.0).normalize(), 1e-6),
            "{fit:?}: {d}"
        );
    }
}

#[test]
fn clip_start_moves_the_origin_along_the_ray_as_cycles() {
    let cam = Camera {
        projection: Projection::Perspective { yfov: 1.0 },
        clip_start: 0.5,
        clip_end: 10.0,
        ..Default::default()
    };
    let rc = RayCamera::new(&scene_with(cam), 64, 64);
    let r = rc.ray(Vec2::new(3.0, 60.0), Vec2::ZERO).unwrap();
    // The origin lies on the plane z = -clip_start, the end on z = -clip_end.
    assert!((r.o.z + 0.5).abs() < 1e-6, "{r:?}");
    assert!(((r.o + r.d * r.tmax).z + 10.0).abs() < 1e-4, "{r:?}");
    let ortho = RayCamera::new(
        &scene_with(Camera {
            projection: Projection::Orthographic { ymag: 1.0 },
            ..cam
        }),
        64,
        64,
    );
    let r = ortho.ray(Vec2::new(3.0, 60.0), Vec2::ZERO).unwrap();
    assert!(
        (r.o.z + 0.5).abs() < 1e-6 && (r.tmax - 9.5).abs() < 1e-5,
        "{r:?}"
    );
}

// ---------------------------------------------------------------------------------------------
// Panoramic cameras.

fn pano(p: Panorama, fit: SensorFit) -> Camera {
    Camera {
        projection: Projection::Panoramic(p),
        fit,
        ..Default::default()
    }
}

const FULL_SPHERE: Panorama = Panorama::Equirectangular {
    latitude_min: -std::f32::consts::FRAC_PI_2,
    latitude_max: std::f32::consts::FRAC_PI_2,
    longitude_min: -std::f32::consts::PI,
    longitude_max: std::f32::consts::PI,
};

#[test]
fn equirectangular_maps_known_directions_to_known_pixels() {
    let (w, h) = (200u32, 100u32);
    // A camera turned 90° about +Y (looking down world -X).
    let turn = Mat4::from_rotation_y(std::f32::consts::FRAC_PI_2);
    let rc = RayCamera::new(
        &scene_with(Camera {
            to_world: turn,
            ..pano(FULL_SPHERE, SensorFit::Auto)
        }),
        w,
        h,
    );
    let at = |x: f32, y: f32| rc.ray(Vec2::new(x, y), Vec2::ZERO).unwrap().d;
    // Camera space: centre = forward (-Z), u = 3/4 = right (+X), u = 1/4 = left, u = 0 = behind,
    // top row = up; rotated to world.
    let world = |v: Vec3| turn.transform_vector3(v);
    for (x, y, want) in [
        (100.0, 50.0, -Vec3::Z),
        (150.0, 50.0, Vec3::X),
        (50.0, 50.0, -Vec3::X),
        (0.0, 50.0, Vec3::Z),
        (100.0, 0.0, Vec3::Y),
        (100.0, 100.0, -Vec3::Y),
        // Latitude 45° up, longitude 45° right.
        (125.0, 25.0, Vec3::new(0.5, 0.5f32.sqrt(), -0.5)),
    ] {
        let d = at(x, y);
        assert!(
            close(d, world(want), 1e-5),
            "({x}, {y}): {d} want {}",
            world(want)
        );
    }
    // Restricted ranges: the image spans longitude [0, 90°], latitude [0, 45°].
    let rc = RayCamera::new(
        &scene_with(pano(
            Panorama::Equirectangular {
                latitude_min: 0.0,
                latitude_max: std::f32::consts::FRAC_PI_4,
                longitude_min: 0.0,
                longitude_max: std::f32::consts::FRAC_PI_2,
            },
            SensorFit::Auto,
        )),
        w,
        h,
    );
    let d = rc.ray(Vec2::new(0.0, 100.0), Vec2::ZERO).unwrap().d;
    assert!(close(d, -Vec3::Z, 1e-5), "{d}");
    let d = rc.ray(Vec2::new(200.0, 0.0), Vec2::ZERO).unwrap().d;
    let s = 0.5f32.sqrt();
    assert!(close(d, Vec3::new(s, s, 0.0), 1e-5), "{d}");
    // Shift moves (u, v) by the shift.
    let shifted = RayCamera::new(
        &scene_with(Camera {
            shift: Vec2::new(0.25, 0.0),
            ..pano(FULL_SPHERE, SensorFit::Auto)
        }),
        w,
        h,
    );
    let d = shifted.ray(Vec2::new(100.0, 50.0), Vec2::ZERO).unwrap().d;
    assert!(close(d, Vec3::X, 1e-5), "{d}");
}

#[test]
fn fisheyes_map_known_angles_to_known_radii() {
    let deg = |d: f32| d.to_radians();
    // Equidistant, 180°: θ = r · 90° with r in half image sizes.
    let rc = RayCamera::new(
        &scene_with(pano(
            Panorama::FisheyeEquidistant { fov: deg(180.0) },
            SensorFit::Auto,
        )),
        100,
        100,
    );
    let ray = |rc: &RayCamera, x: f32, y: f32| rc.ray(Vec2::new(x, y), Vec2::ZERO);
    let s = 0.5f32.sqrt();
    for (x, y, want) in [
        (50.0, 50.0, -Vec3::Z),
        (100.0, 50.0, Vec3::X),
        (75.0, 50.0, Vec3::new(s, 0.0, -s)),
        (50.0, 25.0, Vec3::new(0.0, s, -s)),
        (25.0, 50.0, Vec3::new(-s, 0.0, -s)),
    ] {
        let d = ray(&rc, x, y).unwrap().d;
        assert!(
            close(d, want, 1e-5),
            "equidistant ({x}, {y}): {d} want {want}"
        );
    }
    assert!(
        ray(&rc, 2.0, 2.0).is_none(),
        "the corner is outside the circle"
    );
    // Equisolid, lens 10.5 mm on a 36 mm sensor (fitted width of a 100x100 image), 180°:
    // r = 2 lens sin(θ/2); θ = 60° at r = 10.5 mm, the circle ends at r = 21 sin 45°.
    let rc = RayCamera::new(
        &scene_with(pano(
            Panorama::FisheyeEquisolid {
                fov: deg(180.0),
                lens: 10.5,
                sensor: 36.0,
            },
            SensorFit::Auto,
        )),
        100,
        100,
    );
    let x = 50.0 + 10.5 / 36.0 * 100.0;
    let d = ray(&rc, x, 50.0).unwrap().d;
    let want = Vec3::new(deg(60.0).sin(), 0.0, -deg(60.0).cos());
    assert!(close(d, want, 1e-5), "equisolid: {d} want {want}");
    let edge = 21.0 * deg(45.0).sin() / 36.0 * 100.0;
    assert!(ray(&rc, 50.0, 50.0 - edge + 0.2).is_some());
    assert!(ray(&rc, 50.0, 50.0 - edge - 0.2).is_none());
    // A wide image with VERTICAL fit: the sensor spans the height (100 px = 24 mm).
    let rc = RayCamera::new(
        &scene_with(pano(
            Panorama::FisheyeEquisolid {
                fov: deg(180.0),
                lens: 10.5,
                sensor: 24.0,
            },
            SensorFit::Vertical,
        )),
        200,
        100,
    );
    let d = ray(&rc, 100.0, 50.0 - 10.5 / 24.0 * 100.0).unwrap().d;
    let want = Vec3::new(0.0, deg(60.0).sin(), -deg(60.0).cos());
    assert!(close(d, want, 1e-5), "equisolid vertical: {d} want {want}");
}

#[test]
fn pixels_outside_a_fisheye_are_black() {
    let mut s = scene_with(pano(
        Panorama::FisheyeEquidistant { fov: 3.0 },
        SensorFit::Auto,
    ));
    s.background = Vec3::new(0.5, 0.25, 1.0);
    let (w, h) = (32u32, 32u32);
    let px = render_scene(s, w, h, 16, 0);
    let at = |x: u32, y: u32| px[(y * w + x) as usize];
    // An opaque film, as Cycles without "Transparent": black, alpha 1.
    assert_eq!(at(0, 0), [0.0, 0.0, 0.0, 1.0]);
    assert_eq!(at(31, 31), [0.0, 0.0, 0.0, 1.0]);
    assert_eq!(at(16, 16), [0.5, 0.25, 1.0, 1.0]);
    // On the rim: the covered fraction of the background.
    let rim = (0..w)
        .map(|x| at(x, 4))
        .find(|p| p[0] > 0.0 && p[0] < 0.5)
        .expect("a partly covered pixel");
    assert!((rim[1] - 0.5 * rim[0]).abs() < 1e-6, "{rim:?}");
}

// ---------------------------------------------------------------------------------------------
// TESELA_camera.

/// A glTF document with one camera node carrying `ext` as its TESELA_camera.
fn load_camera(ext: Value) -> Scene {
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["TESELA_camera"],
        "scenes": [{"nodes": [0]}],
        "nodes": [{"camera": 0, "translation": [0.0, 1.0, 2.0],
                   "extensions": {"TESELA_camera": ext}}],
        "cameras": [{"type": "perspective",
                     "perspective": {"yfov": 0.5, "aspectRatio": 1.5, "znear": 0.1}}],
    });
    gltf::load_from_slice(&serde_json::to_vec(&doc).unwrap(), None, "camera.gltf").unwrap()
}

#[test]
fn tesela_camera_carries_blender_camera_data() {
    let s = load_camera(json!({
        "type": "PERSP", "lens": 50.0, "sensor_width": 36.0, "sensor_height": 24.0,
        "sensor_fit": "AUTO", "shift_x": 0.1, "shift_y": -0.2,
        "clip_start": 0.25, "clip_end": 80.0,
        "dof": {"focus_distance": 3.0, "aperture_fstop": 2.0, "aperture_blades": 6,
                "aperture_rotation": 0.5, "aperture_ratio": 1.5}
    }));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let c = s.camera.unwrap();
    let yfov = 2.0 * (18.0f32 / 50.0).atan();
    assert_eq!(c.projection, Projection::Perspective { yfov });
    assert_eq!(c.fit, SensorFit::Auto);
    assert_eq!(c.shift, Vec2::new(0.1, -0.2));
    assert_eq!((c.clip_start, c.clip_end), (0.25, 80.0));
    assert_eq!(c.aspect, Some(1.5));
    assert_eq!(c.to_world.w_axis.truncate(), Vec3::new(0.0, 1.0, 2.0));
    // Aperture radius = focal length / (2 f-stop) = 50 mm / 4.
    let a = c.aperture.unwrap();
    assert!((a.radius - 0.0125).abs() < 1e-7, "{a:?}");
    assert_eq!(
        (a.focus_distance, a.blades, a.rotation, a.ratio),
        (3.0, 6, 0.5, 1.5)
    );

    let s = load_camera(
        json!({"type": "ORTHO", "ortho_scale": 5.0, "sensor_fit": "VERTICAL",
                               "dof": {"focus_distance": 2.0, "aperture_fstop": 4.0}}),
    );
    let c = s.camera.unwrap();
    assert_eq!(c.projection, Projection::Orthographic { ymag: 2.5 });
    assert_eq!(c.fit, SensorFit::Vertical);
    // Cycles: 1 m / (2 f-stop) for orthographic cameras.
    assert_eq!(c.aperture.unwrap().radius, 0.125);

    let s = load_camera(json!({"type": "PANO", "panorama_type": "FISHEYE_EQUISOLID",
                               "fisheye_fov": 3.0, "fisheye_lens": 8.0, "sensor_width": 30.0}));
    assert_eq!(
        s.camera.unwrap().projection,
        Projection::Panoramic(Panorama::FisheyeEquisolid {
            fov: 3.0,
            lens: 8.0,
            sensor: 30.0
        })
    );
    // Without dof, or with use_dof false: a pinhole.
    let s = load_camera(json!({"type": "PERSP", "dof": {"use_dof": false}}));
    assert!(s.camera.unwrap().aperture.is_none());
    // glTF cameras: vertical fov, no lens, znear/zfar as the clip distances (Blender's
    // importer: clip_start/clip_end); without zfar no far clip.
    for (cam, clip) in [
        (
            json!({"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1, "zfar": 9.0}}),
            (0.1, 9.0),
        ),
        (
            json!({"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.2}}),
            (0.2, f32::INFINITY),
        ),
        (
            json!({"type": "orthographic",
                "orthographic": {"xmag": 1.0, "ymag": 1.0, "znear": 0.0, "zfar": 50.0}}),
            (0.0, 50.0),
        ),
    ] {
        let doc = json!({"asset": {"version": "2.0"}, "nodes": [{"camera": 0}], "cameras": [cam]});
        let s = gltf::load_from_slice(&serde_json::to_vec(&doc).unwrap(), None, "g.gltf").unwrap();
        let c = s.camera.unwrap();
        assert_eq!(
            (c.fit, c.clip_start, c.clip_end, c.aperture),
            (SensorFit::Vertical, clip.0, clip.1, None)
        );
    }
}

#[test]
fn bad_tesela_camera_values_warn_and_fall_back() {
    let warned = |s: &Scene, what: &str| {
        assert!(
            s.warnings
                .iter()
                .any(|w| w.contains("TESELA_camera") && w.contains(what)),
            "no warning about {what}: {:?}",
            s.warnings
        );
    };
    for fstop in [json!(0.0), json!(-2.0), json!("f/2")] {
        let s = load_camera(json!({"type": "PERSP", "dof": {"aperture_fstop": fstop}}));
        warned(&s, "aperture_fstop");
        assert!(
            s.camera.unwrap().aperture.is_none(),
            "f-stop {fstop}: not a pinhole"
        );
    }
    for blades in [1, 2] {
        let s = load_camera(json!({"type": "PERSP", "dof": {"aperture_blades": blades}}));
        warned(&s, "aperture_blades");
        assert_eq!(s.camera.unwrap().aperture.unwrap().blades, 0);
    }
    let s = load_camera(json!({"type": "PERSP", "dof": {"focus_distance": -1.0}}));
    warned(&s, "focus_distance");
    assert!(s.camera.unwrap().aperture.is_none());
    let s = load_camera(json!({"type": "PERSP", "dof": {"aperture_ratio": 0.0}}));
    warned(&s, "aperture_ratio");
    assert_eq!(s.camera.unwrap().aperture.unwrap().ratio, 1.0);
    // An unusable lens or sensor: the glTF camera's field of view (vertical fit).
    for lens in [json!(0.0), json!(-5.0), json!(null)] {
        let s = load_camera(json!({"type": "PERSP", "lens": lens}));
        warned(&s, "lens");
        let c = s.camera.unwrap();
        assert_eq!(c.projection, Projection::Perspective { yfov: 0.5 });
        assert_eq!(c.fit, SensorFit::Vertical);
    }
    let s = load_camera(
        json!({"type": "PANO", "panorama_type": "FISHEYE_EQUIDISTANT",
                               "fisheye_fov": 0.0}),
    );
    warned(&s, "fisheye_fov");
    assert_eq!(
        s.camera.unwrap().projection,
        Projection::Panoramic(Panorama::FisheyeEquidistant {
            fov: std::f32::consts::PI
        })
    );
    let s = load_camera(json!({"type": "WIDE"}));
    warned(&s, "type");
    assert_eq!(
        s.camera.unwrap().projection,
        Projection::Perspective { yfov: 0.5 }
    );
    let s = load_camera(
        json!({"type": "PERSP", "shift_x": "left", "clip_start": -1.0,
                               "clip_end": 0.0}),
    );
    warned(&s, "shift_x");
    warned(&s, "clip_start");
    warned(&s, "clip_end");
    let c = s.camera.unwrap();
    assert_eq!(
        (c.shift, c.clip_start, c.clip_end),
        (Vec2::ZERO, 0.0, f32::INFINITY)
    );
}

#[test]
fn degenerate_cameras_render_finite_pixels() {
    // Extreme but accepted values: a huge aperture focused at Cycles' floor, a 360° fisheye,
    // a 10000-blade polygon, an equirectangular camera with an empty latitude range.
    let cams = [
        Camera {
            aperture: Some(Aperture {
                radius: 1e3,
                focus_distance: 1e-5,
                blades: 10_000,
                rotation: 1e6,
                ratio: 1e-3,
            }),
            ..Default::default()
        },
        pano(
            Panorama::FisheyeEquisolid {
                fov: 2.0 * std::f32::consts::PI,
                lens: 1e-3,
                sensor: 1e3,
            },
            SensorFit::Auto,
        ),
        pano(
            Panorama::Equirectangular {
                latitude_min: 0.3,
                latitude_max: 0.3,
                longitude_min: 0.0,
                longitude_max: 0.0,
            },
            SensorFit::Auto,
        ),
        pano(Panorama::Mirrorball, SensorFit::Auto),
        pano(Panorama::EquiangularCubemapFace, SensorFit::Auto),
    ];
    for cam in cams {
        let mut s = scene_with(cam);
        s.background = Vec3::ONE;
        s.materials.push(Material::diffuse("d", Vec3::splat(0.5)));
        s.meshes
            .push(emissive_square(Vec3::new(0.0, 0.0, -1.0), 1.0));
        // render_scene asserts that no sample was rejected as non-finite.
        let px = render_scene(s, 16, 16, 4, 0);
        assert!(px.iter().flatten().all(|v| v.is_finite()), "{cam:?}");
    }
}
