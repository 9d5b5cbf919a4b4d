//! Node-graph materials in the renderer: transparency (camera rays, shadow rays, last path
//! segments), mixes, and the Bump node, against exact expectations.

use glam::{Mat4, Vec3};
use serde_json::json;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use tesela::emitter::LightChoice;
use tesela::render::{self, RenderOptions};
use tesela::render_scene::{Ctx, RenderScene};
use tesela::sampler::SobolSampler;
use tesela::scene::builtin::quad;
use tesela::scene::{Camera, Material, Projection, Scene};
use tesela::shading::Graph;

/// The integrators that render light (not the debug views).
const LIGHT_INTEGRATORS: [&str; 5] = [
    "direct_ems",
    "direct_mats",
    "direct_mis",
    "path_mats",
    "path_mis",
];

fn opts(integrator: &str, size: u32, spp: u32, max_depth: u32) -> RenderOptions {
    RenderOptions {
        width: size,
        height: size,
        spp,
        max_depth,
        seed: 3,
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

fn graph_material(name: &str, graph: serde_json::Value) -> Material {
    let mut m = Material::diffuse(name, Vec3::splat(0.5));
    m.graph = Some(Arc::new(Graph::from_json(&graph).unwrap()));
    m
}

/// A transparent panel of colour `t` (a Transparent BSDF node).
fn transparent(t: f32) -> Material {
    graph_material(
        "panel",
        json!({"nodes": [{"type": "ShaderNodeBsdfTransparent", "inputs": {"Color": [t, t, t, 1.0]}}],
               "surface": [0, "BSDF"]}),
    )
}

/// Looking down at a floor (y = 0) lit by an emitter at y = 2, with an optional panel at y = 1
/// between them; the camera sits under the panel.
fn shadow_scene(panel: Option<Material>) -> Scene {
    let mut s = Scene::default();
    s.materials
        .push(Material::diffuse("floor", Vec3::splat(0.8)));
    s.materials
        .push(Material::emitter("light", Vec3::splat(3.0), true));
    let (a, b) = (-2.0f32, 2.0f32);
    s.meshes.push(quad(
        "floor",
        0,
        Vec3::new(a, 0.0, b),
        Vec3::new(b, 0.0, b),
        Vec3::new(b, 0.0, a),
        Vec3::new(a, 0.0, a),
    ));
    s.meshes.push(quad(
        "light",
        1,
        Vec3::new(-0.5, 2.0, -0.5),
        Vec3::new(0.5, 2.0, -0.5),
        Vec3::new(0.5, 2.0, 0.5),
        Vec3::new(-0.5, 2.0, 0.5),
    ));
    if let Some(p) = panel {
        s.materials.push(p);
        s.meshes.push(quad(
            "panel",
            2,
            Vec3::new(-3.0, 1.0, 3.0),
            Vec3::new(3.0, 1.0, 3.0),
            Vec3::new(3.0, 1.0, -3.0),
            Vec3::new(-3.0, 1.0, -3.0),
        ));
    }
    // At y = 0.6 looking straight down.
    // Camera axes: x = world x, y = world -z, looking down its -z = world -y.
    let look = Mat4::from_cols(
        glam::Vec4::X,
        glam::Vec4::new(0.0, 0.0, -1.0, 0.0),
        glam::Vec4::new(0.0, 1.0, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.6, 0.0, 1.0),
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
fn a_transparent_panel_scales_direct_light_exactly() {
    for integrator in ["direct_ems", "direct_mis"] {
        let o = opts(integrator, 16, 16, 2);
        let open = render(shadow_scene(None), &o);
        let shaded = render(shadow_scene(Some(transparent(0.25))), &o);
        let (mut so, mut ss) = (0.0f64, 0.0f64);
        for (a, b) in open.iter().zip(&shaded) {
            // Same camera paths and deterministic shadow transmittance: pixel by pixel.
            assert!(
                (b[0] - 0.25 * a[0]).abs() <= 1e-5 * a[0].max(1.0),
                "{integrator}: {} vs 0.25 x {}",
                b[0],
                a[0]
            );
            so += a[0] as f64;
            ss += b[0] as f64;
        }
        assert!(so > 1.0, "{integrator}: the floor is lit");
        assert!((ss / so - 0.25).abs() < 1e-4);
    }
    // An opaque panel blocks everything.
    let opaque = render(
        shadow_scene(Some(Material::diffuse("p", Vec3::splat(0.5)))),
        &opts("direct_ems", 16, 4, 2),
    );
    assert!(opaque.iter().all(|p| p[0] == 0.0));
}

/// The camera looks at a two-sided emitter of radiance 1 through a panel.
fn through_panel(panel: Material) -> Scene {
    let mut s = Scene::default();
    s.materials
        .push(Material::emitter("light", Vec3::ONE, true));
    s.materials.push(panel);
    s.meshes.push(quad(
        "light",
        0,
        Vec3::new(-5.0, -5.0, -2.0),
        Vec3::new(5.0, -5.0, -2.0),
        Vec3::new(5.0, 5.0, -2.0),
        Vec3::new(-5.0, 5.0, -2.0),
    ));
    s.meshes.push(quad(
        "panel",
        1,
        Vec3::new(-5.0, -5.0, -1.0),
        Vec3::new(5.0, -5.0, -1.0),
        Vec3::new(5.0, 5.0, -1.0),
        Vec3::new(-5.0, 5.0, -1.0),
    ));
    s.camera = Some(Camera {
        projection: Projection::Perspective {
            yfov: 30f32.to_radians(),
        },
        to_world: Mat4::IDENTITY,
        aspect: None,
        ..Default::default()
    });
    s
}

#[test]
fn camera_rays_pass_through_transparent_closures() {
    for integrator in LIGHT_INTEGRATORS {
        let px = render(through_panel(transparent(0.4)), &opts(integrator, 8, 4, 3));
        for p in &px {
            assert!((p[0] - 0.4).abs() < 1e-5, "{integrator}: {}", p[0]);
        }
        // A mix of 30% clear and 70% black diffuse: 0.3 on average (a stochastic choice).
        let mix = graph_material(
            "mix",
            json!({"nodes": [
                {"type": "ShaderNodeBsdfTransparent"},
                {"type": "ShaderNodeBsdfDiffuse", "inputs": {"Color": [0.0, 0.0, 0.0, 1.0]}},
                {"type": "ShaderNodeMixShader", "inputs": {"Fac": 0.7,
                  "Shader": {"link": [0, "BSDF"]}, "Shader_001": {"link": [1, "BSDF"]}}}],
              "surface": [2, "Shader"]}),
        );
        let px = render(through_panel(mix), &opts(integrator, 16, 64, 3));
        let mean = px.iter().map(|p| p[0] as f64).sum::<f64>() / px.len() as f64;
        // 16384 Bernoulli(0.3) samples: standard error 0.0036.
        assert!((mean - 0.3).abs() < 0.015, "{integrator}: mean {mean}");
    }
}

#[test]
fn bump_tilts_the_normal_by_the_height_gradient() {
    // Height = 0.5 x (Blender object x), distance 1, strength 1: n = normalize(N - 0.5 x̂).
    let m = graph_material(
        "bumpy",
        json!({"nodes": [
            {"type": "ShaderNodeTexCoord"},
            {"type": "ShaderNodeSeparateXYZ", "inputs": {"Vector": {"link": [0, "Object"]}}},
            {"type": "ShaderNodeMath", "props": {"operation": "MULTIPLY"},
             "inputs": {"Value": {"link": [1, "X"]}, "Value_001": 0.5}},
            {"type": "ShaderNodeBump", "inputs": {"Strength": 1.0, "Distance": 1.0,
             "Height": {"link": [2, "Value"]}}},
            {"type": "ShaderNodeBsdfDiffuse", "inputs": {"Normal": {"link": [3, "Normal"]}}}],
          "surface": [4, "BSDF"]}),
    );
    let mut s = Scene::default();
    s.materials.push(m);
    // A floor facing glTF +Y (Blender +Z).
    s.meshes.push(quad(
        "floor",
        0,
        Vec3::new(-1.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, -1.0),
        Vec3::new(-1.0, 0.0, -1.0),
    ));
    let rs = RenderScene::new(s, LightChoice::Power);
    let mut ctx = Ctx::new(SobolSampler::new(0, 0, 0));
    for x in [-0.5f32, 0.0, 0.3] {
        let o = Vec3::new(x, 1.0, 0.2);
        let d = -Vec3::Y;
        let its = rs.intersect(&mut ctx, o, d).expect("hits the floor");
        let (c, _, _) = rs.choose_closure(&mut ctx, &its, d, 1, 0.5).unwrap();
        // Blender x is glTF x; Blender z is glTF y.
        let want = Vec3::new(-0.5, 1.0, 0.0).normalize();
        assert!(
            (c.normal - want).length() < 2e-3,
            "at x = {x}: {} vs {want}",
            c.normal
        );
    }
}

/// A Principled ball (subsurface weight 1, no specular layer, radius `radius` × scale 1) on
/// the floor under the light of [`shadow_scene`], seen from above.
fn subsurface_ball(radius: f32, weight: f32) -> Scene {
    let mut s = shadow_scene(None);
    s.camera.as_mut().unwrap().to_world =
        tesela::scene::builtin::look_at(Vec3::new(0.0, 1.2, 0.9), Vec3::new(0.0, 0.25, 0.0));
    s.materials.push(graph_material(
        "ball",
        json!({"nodes": [{"type": "ShaderNodeBsdfPrincipled", "inputs": {
                 "Base Color": [0.8, 0.8, 0.8, 1.0], "Specular IOR Level": 0.0,
                 "Subsurface Weight": weight, "Subsurface Radius": [radius, radius, radius],
                 "Subsurface Scale": 1.0}}],
               "surface": [0, "BSDF"]}),
    ));
    s.meshes.push(tesela::scene::builtin::sphere(
        "ball",
        2,
        Vec3::new(0.0, 0.25, 0.0),
        0.25,
        24,
        48,
    ));
    s
}

/// Mean over the whole 24×24 image and over its central 8×8 (the ball's lit top).
fn means(img: &[[f32; 4]]) -> (f32, f32) {
    let v = |p: &[f32; 4]| (p[0] + p[1] + p[2]) / 3.0;
    let all = img.iter().map(v).sum::<f32>() / img.len() as f32;
    let centre = (8..16)
        .flat_map(|y| (8..16).map(move |x| y * 24 + x))
        .map(|i| v(&img[i]))
        .sum::<f32>()
        / 64.0;
    (all, centre)
}

/// The walk runs in the path integrators: with a radius far below the ball's size a
/// subsurface ball looks like the diffuse one (the walk's albedo is the base colour), with a
/// radius like its size the lit top loses light to the rest of the ball; the image is the
/// same for any thread count.
#[test]
fn subsurface_walks_in_path_integrators() {
    let o = opts("path_mis", 24, 64, 6);
    let diffuse = means(&render(subsurface_ball(0.01, 0.0), &o));
    let narrow = means(&render(subsurface_ball(0.01, 1.0), &o));
    let wide = means(&render(subsurface_ball(3.0, 1.0), &o));
    assert!(
        (narrow.0 / diffuse.0 - 1.0).abs() < 0.05 && (narrow.1 / diffuse.1 - 1.0).abs() < 0.05,
        "narrow {narrow:?} vs diffuse {diffuse:?}"
    );
    assert!(
        wide.1 < 0.9 * narrow.1,
        "wide {wide:?} vs narrow {narrow:?}"
    );
    let one = render(
        subsurface_ball(0.3, 1.0),
        &RenderOptions {
            threads: 1,
            ..o.clone()
        },
    );
    let four = render(
        subsurface_ball(0.3, 1.0),
        &RenderOptions { threads: 4, ..o },
    );
    assert!(one == four, "thread count changed the image");
}

/// [`shadow_scene`] with `k` clear-ish panels (Transparent BSDF 0.5) stacked between the floor
/// and the light (y = 1.0, 1.1, ...), seen from a camera at height `camera_y`.
fn stacked_panels(k: usize, camera_y: f32) -> Scene {
    let mut s = shadow_scene(None);
    s.materials.push(transparent(0.5));
    let m = s.materials.len() - 1;
    for i in 0..k {
        let y = 1.0 + 0.1 * i as f32;
        s.meshes.push(quad(
            &format!("panel{i}"),
            m,
            Vec3::new(-3.0, y, 3.0),
            Vec3::new(3.0, y, 3.0),
            Vec3::new(3.0, y, -3.0),
            Vec3::new(-3.0, y, -3.0),
        ));
    }
    if let Some(c) = &mut s.camera {
        c.to_world.w_axis.y = camera_y;
    }
    s
}

/// Cycles' `transparent_max_bounces` = L: a shadow ray from a vertex the path reached after
/// passing j transparent surfaces passes at most L - j more; one more blocks the light as an
/// opaque surface does. Under k panels (Transparent 0.5) the floor is lit by 0.5^k of the open
/// light iff k <= L; seen through the same k panels from above (j = k), by 0.5^2k iff 2k <= L.
/// Emitter sampling alone is exact pixel by pixel; with BSDF sampling (which also passes
/// panels, at most L in all when L >= 1) the image's sum is compared.
#[test]
fn shadow_rays_pass_at_most_the_transparent_limit() {
    for integrator in ["direct_ems", "direct_mis", "path_mis"] {
        let depth = if integrator == "path_mis" { 3 } else { 2 };
        // A limit of 0 still lets a path ray through one surface (Cycles): emitter sampling only.
        let first = if integrator == "direct_ems" { 0 } else { 1 };
        for limit in first..5u32 {
            let mut o = opts(integrator, 8, 16, depth);
            o.light_paths.transparent = limit;
            for camera_y in [0.6, 1.8] {
                let open = render(stacked_panels(0, camera_y), &o);
                let lit: f64 = open.iter().map(|p| p[0] as f64).sum();
                assert!(lit > 1.0, "the floor is lit");
                for k in 0..6usize {
                    let passed = if camera_y > 1.0 { k } else { 0 };
                    let got = render(stacked_panels(k, camera_y), &o);
                    let n = (k + passed) as u32;
                    let at =
                        format!("{integrator}, limit {limit}, {k} panels, camera at {camera_y}");
                    if n > limit {
                        assert!(
                            got.iter().all(|p| p[0] == 0.0),
                            "{at}: the light is blocked"
                        );
                        continue;
                    }
                    let expect = 0.5f32.powi(n as i32);
                    if integrator == "direct_ems" && passed == 0 {
                        for (a, b) in open.iter().zip(&got) {
                            let want = expect * a[0];
                            assert!(
                                (b[0] - want).abs() <= 1e-5 * a[0].max(1.0),
                                "{at}: {} vs {want}",
                                b[0]
                            );
                        }
                    }
                    let sum: f64 = got.iter().map(|p| p[0] as f64).sum();
                    let want = expect as f64 * lit;
                    assert!((sum - want).abs() <= 0.03 * want, "{at}: {sum} vs {want}");
                }
            }
        }
    }
}

/// A camera path passes at most `transparent_max_bounces` = L transparent surfaces (one when
/// L = 0, as in Cycles); the surface after them ends it, its emission still counted: an
/// emitter behind k clear panels shows iff k <= max(L, 1), in every integrator.
#[test]
fn camera_paths_pass_at_most_the_transparent_limit() {
    for integrator in LIGHT_INTEGRATORS {
        for limit in 0..4u32 {
            for k in 0..5usize {
                let mut s = through_panel(transparent(1.0));
                let panel = s.meshes.pop().unwrap();
                for i in 0..k {
                    let mut p = panel.clone();
                    for v in &mut p.positions {
                        v.z += 0.1 * i as f32;
                    }
                    s.meshes.push(p);
                }
                let mut o = opts(integrator, 4, 2, 3);
                o.light_paths.transparent = limit;
                let want = if k as u32 <= limit.max(1) { 1.0 } else { 0.0 };
                for p in render(s, &o) {
                    assert!(
                        (p[0] - want).abs() < 1e-5,
                        "{integrator}, limit {limit}, {k} panels: {}",
                        p[0]
                    );
                }
            }
        }
    }
}
