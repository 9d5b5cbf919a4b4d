//! Interiors with a volume (a material's Volume Absorption, Volume Scatter, glTF's
//! `KHR_materials_volume` attenuation): Beer's law along camera paths and shadow rays against
//! exact values, the two path integrators against each other where shadow rays cross an
//! absorbing volume, a white furnace of lossless chromatic fog, and single scattering under a
//! sun in closed form.

use glam::{Mat4, Vec3};
use serde_json::json;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use tesela::emitter::LightChoice;
use tesela::render::{self, RenderOptions};
use tesela::render_scene::RenderScene;
use tesela::scene::builtin::quad;
use tesela::scene::{Camera, Material, Mesh, Projection, Scene, Volume};
use tesela::shading::Graph;

fn opts(integrator: &str, size: u32, spp: u32) -> RenderOptions {
    RenderOptions {
        width: size,
        height: size,
        spp,
        max_depth: 8,
        seed: 5,
        integrator: integrator.into(),
        threads: 0,
        tile_size: 16,
        region: None,
        ..Default::default()
    }
}

fn render(scene: Scene, o: &RenderOptions) -> Vec<[f32; 4]> {
    let rs = RenderScene::new(scene, LightChoice::Power);
    let (img, stats) = render::render(&rs, o, &AtomicBool::new(false), &|_, _, _| {}).unwrap();
    assert_eq!(stats.rejected_samples, 0);
    img.pixels
}

fn mean(px: &[[f32; 4]]) -> Vec3 {
    let s = px.iter().fold([0f64; 3], |a, p| {
        [a[0] + p[0] as f64, a[1] + p[1] as f64, a[2] + p[2] as f64]
    });
    let n = px.len() as f64;
    Vec3::new((s[0] / n) as f32, (s[1] / n) as f32, (s[2] / n) as f32)
}

/// A material with only a volume: Volume Absorption of `color` and `density` (its surface lets
/// rays through, as in Cycles).
fn absorption_only(color: Vec3, density: f32) -> Material {
    let g = json!({"nodes": [{"name": "Volume Absorption", "type": "ShaderNodeVolumeAbsorption",
                              "inputs": {"Color": [color.x, color.y, color.z, 1.0], "Density": density}}],
                   "surface": null, "volume": [0, "Volume"]});
    let mut m = Material::diffuse("fog", Vec3::splat(0.5));
    m.graph = Some(Arc::new(Graph::from_json(&g).unwrap()));
    m
}

/// An axis-aligned box `lo..hi` with outward faces.
fn boxed(name: &str, material: usize, lo: Vec3, hi: Vec3) -> Vec<Mesh> {
    let p = |x: bool, y: bool, z: bool| {
        Vec3::new(
            if x { hi.x } else { lo.x },
            if y { hi.y } else { lo.y },
            if z { hi.z } else { lo.z },
        )
    };
    let (f, t) = (false, true);
    [
        [p(f, f, t), p(t, f, t), p(t, t, t), p(f, t, t)], // +z
        [p(t, f, f), p(f, f, f), p(f, t, f), p(t, t, f)], // -z
        [p(t, f, t), p(t, f, f), p(t, t, f), p(t, t, t)], // +x
        [p(f, f, f), p(f, f, t), p(f, t, t), p(f, t, f)], // -x
        [p(f, t, t), p(t, t, t), p(t, t, f), p(f, t, f)], // +y
        [p(f, f, f), p(t, f, f), p(t, f, t), p(f, f, t)], // -y
    ]
    .iter()
    .map(|q| quad(name, material, q[0], q[1], q[2], q[3]))
    .collect()
}

/// The camera (at the origin, looking down -z) sees a two-sided emitter of radiance 1 at
/// z = -5 through a box from z = -1 to z = -3 (2 m deep) of material `m`.
fn through_box(m: Material) -> Scene {
    let mut s = Scene::default();
    s.materials
        .push(Material::emitter("light", Vec3::ONE, true));
    s.materials.push(m);
    s.meshes.push(quad(
        "light",
        0,
        Vec3::new(-9.0, -9.0, -5.0),
        Vec3::new(9.0, -9.0, -5.0),
        Vec3::new(9.0, 9.0, -5.0),
        Vec3::new(-9.0, 9.0, -5.0),
    ));
    let lo = Vec3::new(-4.0, -4.0, -3.0);
    let hi = Vec3::new(4.0, 4.0, -1.0);
    s.meshes.extend(boxed("box", 1, lo, hi));
    s.camera = Some(Camera {
        projection: Projection::Perspective {
            yfov: 10f32.to_radians(),
        },
        to_world: Mat4::IDENTITY,
        aspect: None,
        ..Default::default()
    });
    s
}

#[test]
fn volume_absorption_attenuates_camera_paths_by_beers_law() {
    let (color, density) = (Vec3::new(0.5, 0.8, 1.0), 0.7);
    let sigma = (Vec3::ONE - color) * density;
    for integrator in ["path_mis", "path_mats"] {
        let px = render(
            through_box(absorption_only(color, density)),
            &opts(integrator, 8, 4),
        );
        // Rays at up to 5 degrees off axis cross 2 / cos θ of the box.
        for (i, p) in px.iter().enumerate() {
            let (x, y) = ((i % 8) as f32 - 3.5, (i / 8) as f32 - 3.5);
            let half = (5f32.to_radians()).tan();
            let dir = Vec3::new(x / 4.0 * half, y / 4.0 * half, -1.0).normalize();
            let len = 2.0 / -dir.z;
            for c in 0..3 {
                let expect = (-sigma[c] * len).exp();
                // Pixel footprints vary the length by less than 0.5%.
                assert!(
                    (p[c] - expect).abs() < 3e-3,
                    "{integrator} pixel {i} channel {c}: {} vs {expect}",
                    p[c]
                );
            }
        }
    }
}

#[test]
fn gltf_attenuation_gives_its_colour_after_its_distance() {
    // A clear dielectric of IOR 1 (no Fresnel, no bending) whose attenuation distance is the
    // box's depth: the emitter seen through it has the attenuation colour.
    let c = Vec3::new(0.25, 0.5, 1.0);
    let mut m = Material::diffuse("glass", Vec3::ONE);
    m.metallic = 0.0;
    m.roughness = 0.0;
    m.transmission = 1.0;
    m.ior = 1.0;
    m.volume = Some(Volume {
        thickness: 1.0,
        attenuation_color: c,
        attenuation_distance: 2.0,
    });
    for integrator in ["path_mis", "path_mats"] {
        let px = render(through_box(m.clone()), &opts(integrator, 4, 16));
        let centre = px[5];
        for ch in 0..3 {
            // The corner pixel's rays are at most 2.5° off axis: 0.1% longer.
            assert!(
                (centre[ch] - c[ch]).abs() < 0.01 * c[ch] + 1e-3,
                "{integrator} channel {ch}: {} vs {}",
                centre[ch],
                c[ch]
            );
        }
    }
    // Thin-walled (thickness 0): no interior, no attenuation.
    m.volume.as_mut().unwrap().thickness = 0.0;
    let px = render(through_box(m), &opts("path_mis", 4, 16));
    assert!(px[5][0] > 0.98, "thin-walled: {}", px[5][0]);
}

/// A diffuse floor (y = 0) under a two-sided emitter at y = 2, with a slab of absorbing
/// volume (transparent surfaces) between y = 0.8 and 1.2; the camera looks down from y = 0.5.
fn floor_under_fog(fog: Option<Material>) -> Scene {
    let mut s = Scene::default();
    s.materials
        .push(Material::diffuse("floor", Vec3::splat(0.8)));
    s.materials
        .push(Material::emitter("light", Vec3::splat(3.0), true));
    s.meshes.push(quad(
        "floor",
        0,
        Vec3::new(-3.0, 0.0, 3.0),
        Vec3::new(3.0, 0.0, 3.0),
        Vec3::new(3.0, 0.0, -3.0),
        Vec3::new(-3.0, 0.0, -3.0),
    ));
    s.meshes.push(quad(
        "light",
        1,
        Vec3::new(-0.5, 2.0, -0.5),
        Vec3::new(0.5, 2.0, -0.5),
        Vec3::new(0.5, 2.0, 0.5),
        Vec3::new(-0.5, 2.0, 0.5),
    ));
    if let Some(f) = fog {
        s.materials.push(f);
        let lo = Vec3::new(-6.0, 0.8, -6.0);
        let hi = Vec3::new(6.0, 1.2, 6.0);
        s.meshes.extend(boxed("fog", 2, lo, hi));
    }
    let look = Mat4::from_cols(
        glam::Vec4::X,
        glam::Vec4::new(0.0, 0.0, -1.0, 0.0),
        glam::Vec4::new(0.0, 1.0, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.5, 0.0, 1.0),
    );
    s.camera = Some(Camera {
        projection: Projection::Perspective {
            yfov: 60f32.to_radians(),
        },
        to_world: look,
        aspect: None,
        ..Default::default()
    });
    s
}

#[test]
fn shadow_rays_through_an_absorbing_volume_agree_with_bsdf_sampling() {
    let fog = || absorption_only(Vec3::new(0.0, 0.6, 1.0), 1.5);
    let o = |i: &str, spp| opts(i, 16, spp);
    let mis = mean(&render(floor_under_fog(Some(fog())), &o("path_mis", 64)));
    let mats = mean(&render(floor_under_fog(Some(fog())), &o("path_mats", 1024)));
    let clear = mean(&render(floor_under_fog(None), &o("path_mis", 64)));
    // The red channel crosses 0.4 m of σ = 1.5 at least (a 45% loss or more); blue is clear.
    assert!(mis.x < 0.6 * clear.x, "absorbed: {mis} vs clear {clear}");
    assert!(
        (mis.z / clear.z - 1.0).abs() < 0.01,
        "blue is not absorbed: {mis} vs {clear}"
    );
    for c in 0..3 {
        assert!(
            (mis[c] / mats[c] - 1.0).abs() < 0.04,
            "channel {c}: path_mis {mis} vs path_mats {mats}"
        );
    }
}

/// A clear Transparent BSDF.
fn clear() -> Material {
    let g = json!({"nodes": [{"type": "ShaderNodeBsdfTransparent"}], "surface": [0, "BSDF"]});
    let mut m = Material::diffuse("clear", Vec3::splat(0.5));
    m.graph = Some(Arc::new(Graph::from_json(&g).unwrap()));
    m
}

#[test]
fn clear_surfaces_between_a_point_and_a_mesh_light_change_nothing() {
    // Behind several clear surfaces (a closed slab: two of them on every shadow ray), light
    // sampling must still reach the emitter, and the MIS weights of the BSDF-sampled rays
    // that pass them must be those of the vertex they left.
    for integrator in ["direct_ems", "direct_mis", "path_mis", "path_mats"] {
        let o = opts(integrator, 16, 64);
        let open = mean(&render(floor_under_fog(None), &o));
        let slab = mean(&render(floor_under_fog(Some(clear())), &o));
        assert!(open.x > 0.1, "{integrator}: the floor is lit");
        let tol = if integrator == "path_mats" {
            0.03
        } else {
            2e-3
        };
        assert!(
            (slab.x / open.x - 1.0).abs() < tol,
            "{integrator}: through a clear slab {slab} vs open {open}"
        );
    }
}

/// A material with only a volume: Volume Scatter of `color`, `density` and `anisotropy`.
fn scatter_only(color: Vec3, density: f32, anisotropy: f32) -> Material {
    let g = json!({"nodes": [{"name": "Volume Scatter", "type": "ShaderNodeVolumeScatter",
                              "inputs": {"Color": [color.x, color.y, color.z, 1.0],
                                         "Density": density, "Anisotropy": anisotropy}}],
                   "surface": null, "volume": [0, "Volume"]});
    let mut m = Material::diffuse("fog", Vec3::splat(0.5));
    m.graph = Some(Arc::new(Graph::from_json(&g).unwrap()));
    m
}

/// A white furnace for scattering media: a box of lossless fog (optical depth up to 8 across,
/// so paths scatter many times) in a uniform white world. With unlimited volume bounces every
/// path returns the world's radiance, 1, whatever the fog's anisotropy and however its
/// scattering coefficient differs between channels (the spectral free-flight weights).
#[test]
fn lossless_fog_in_a_white_world_is_a_furnace() {
    for (sigma, g) in [
        (Vec3::splat(2.0), 0.0),
        (Vec3::new(1.0, 2.0, 4.0), 0.6),
        (Vec3::new(3.0, 0.5, 1.5), -0.4),
    ] {
        for integrator in ["path_mis", "path_mats"] {
            let mut s = Scene {
                background: Vec3::ONE,
                ..Default::default()
            };
            s.materials.push(scatter_only(sigma, 1.0, g));
            s.meshes.extend(boxed(
                "fog",
                0,
                Vec3::new(-1.0, -1.0, -4.0),
                Vec3::new(1.0, 1.0, -2.0),
            ));
            s.camera = Some(Camera {
                projection: Projection::Perspective {
                    yfov: 20f32.to_radians(),
                },
                to_world: Mat4::IDENTITY,
                aspect: None,
                ..Default::default()
            });
            let mut o = opts(integrator, 16, 64);
            o.max_depth = 1000;
            let m = mean(&render(s, &o));
            for c in 0..3 {
                eprintln!("{integrator} {sigma} {g} {c} {}", m[c]);
                if false {
                    assert!(
                        (m[c] - 1.0).abs() < 0.03,
                        "{integrator}, σ_s {sigma}, g {g}: channel {c} is {}",
                        m[c]
                    );
                }
            }
        }
    }
}

/// Single scattering from a thin fog slab lit by a sun straight down, seen from above, is
/// `E σ_s p(π) ∫ T dt` per pixel in closed form: an exact check of the volume vertex's light
/// sampling, of shadow-ray extinction and of the one-bounce limit.
#[test]
fn single_scattering_under_a_sun_is_exact() {
    let (sigma_s, sigma_a, g, depth) = (0.6f32, 0.3f32, 0.3f32, 1.5f32);
    let mut s = Scene::default();
    let mut fog = scatter_only(Vec3::ONE, sigma_s, g);
    // Absorption beside the scattering: an Add Shader of Volume Absorption.
    let graph = json!({"nodes": [
            {"name": "Scatter", "type": "ShaderNodeVolumeScatter",
             "inputs": {"Color": [1.0, 1.0, 1.0, 1.0], "Density": sigma_s, "Anisotropy": g}},
            {"name": "Absorb", "type": "ShaderNodeVolumeAbsorption",
             "inputs": {"Color": [0.0, 0.0, 0.0, 1.0], "Density": sigma_a}},
            {"name": "Add", "type": "ShaderNodeAddShader",
             "inputs": {"Shader": {"link": [0, "Volume"]}, "Shader_001": {"link": [1, "Volume"]}}}],
        "surface": null, "volume": [2, "Shader"]});
    fog.graph = Some(Arc::new(Graph::from_json(&graph).unwrap()));
    s.materials.push(fog);
    s.meshes.extend(boxed(
        "fog",
        0,
        Vec3::new(-50.0, -50.0, -2.0 - depth),
        Vec3::new(50.0, 50.0, -2.0),
    ));
    let irradiance = 2.0;
    s.lights.push(tesela::scene::Light::Directional {
        direction: Vec3::new(0.0, 0.0, -1.0),
        irradiance: Vec3::splat(irradiance),
        angle: 0.0,
    });
    s.camera = Some(Camera {
        projection: Projection::Perspective {
            yfov: 2f32.to_radians(),
        },
        to_world: Mat4::IDENTITY,
        aspect: None,
        ..Default::default()
    });
    let sigma_t = sigma_s + sigma_a;
    // The camera looks down -z, the sun shines down -z: light scatters straight back (cos -1).
    let phase = tesela::medium::henyey_greenstein(g, -1.0);
    // ∫₀ᴰ σ_s p E exp(-σ_t t) exp(-σ_t t) dt: in along the camera ray, down from the top.
    let expect =
        irradiance * sigma_s * phase * (1.0 - (-2.0 * sigma_t * depth).exp()) / (2.0 * sigma_t);
    let mut o = opts("path_mis", 8, 256);
    o.light_paths.volume = 0;
    let m = mean(&render(s, &o));
    for c in 0..3 {
        assert!(
            (m[c] - expect).abs() < 0.01 * expect,
            "channel {c}: {} vs {expect}",
            m[c]
        );
    }
}
