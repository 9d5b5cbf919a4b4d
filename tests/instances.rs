//! Instances render as the same meshes baked into world space: rotated, non-uniformly scaled,
//! mirrored (negative determinant) and emissive instances, with the renderer's integrators.

use glam::{Mat4, Quat, Vec3};
use std::sync::atomic::AtomicBool;
use tesela::emitter::LightChoice;
use tesela::render::{self, RenderOptions};
use tesela::render_scene::RenderScene;
use tesela::scene::builtin::{self, sphere};
use tesela::scene::{Instance, Material, ObjectInfo, Scene};

fn render_scene(scene: Scene, integrator: &str) -> Vec<[f32; 4]> {
    let rs = RenderScene::new(scene, LightChoice::Power);
    let opts = RenderOptions {
        width: 48,
        height: 48,
        spp: 64,
        max_depth: 6,
        seed: 3,
        integrator: integrator.into(),
        threads: 0,
        tile_size: 16,
        region: None,
        ..Default::default()
    };
    let (img, stats) = render::render(&rs, &opts, &AtomicBool::new(false), &|_, _, _| {}).unwrap();
    assert_eq!(stats.rejected_samples, 0, "non-finite samples");
    img.pixels
}

/// The Cornell box with a unit sphere placed four times (one of them mirrored, one squashed)
/// and a small emissive sphere placed twice, under a material override.
fn instanced() -> Scene {
    let mut scene = builtin::cornell_box();
    let white = 0;
    scene
        .materials
        .push(Material::diffuse("orange", Vec3::new(0.8, 0.4, 0.1)));
    let orange = scene.materials.len() - 1;
    scene
        .materials
        .push(Material::emitter("glow", Vec3::new(6.0, 5.0, 2.0), false));
    let glow = scene.materials.len() - 1;
    let ball = scene.meshes.len();
    scene
        .meshes
        .push(sphere("ball", white, Vec3::ZERO, 1.0, 12, 24));
    let place = |s: Vec3, r: Quat, t: Vec3, material| Instance {
        motion: None,
        mesh: ball,
        to_world: Mat4::from_scale_rotation_translation(s, r, t),
        material,
        object: ObjectInfo::default(),
    };
    scene.instances = vec![
        place(
            Vec3::splat(0.15),
            Quat::IDENTITY,
            Vec3::new(-0.25, 0.15, -0.1),
            None,
        ),
        place(
            Vec3::new(-0.12, 0.2, 0.12),
            Quat::from_rotation_z(0.4),
            Vec3::new(0.2, 0.2, 0.1),
            Some(orange),
        ),
        place(
            Vec3::new(0.2, 0.06, 0.1),
            Quat::from_rotation_y(0.9),
            Vec3::new(0.0, 0.06, 0.3),
            None,
        ),
        place(
            Vec3::new(0.1, 0.1, -0.1),
            Quat::from_rotation_x(0.3),
            Vec3::new(0.25, 0.55, -0.25),
            Some(orange),
        ),
        place(
            Vec3::splat(0.05),
            Quat::IDENTITY,
            Vec3::new(-0.3, 0.6, 0.2),
            Some(glow),
        ),
        place(
            Vec3::new(-0.08, 0.04, 0.04),
            Quat::from_rotation_z(1.0),
            Vec3::new(0.3, 0.8, 0.25),
            Some(glow),
        ),
    ];
    scene
}

/// The same scene with every instance baked into a world-space mesh.
fn baked(mut scene: Scene) -> Scene {
    for inst in std::mem::take(&mut scene.instances) {
        let m = scene.meshes[inst.mesh].placed(&inst);
        scene.meshes.push(m);
    }
    // The object-space ball is no longer placed: leave it out.
    let ball = scene.meshes.iter().position(|m| m.name == "ball").unwrap();
    scene.meshes[ball].indices.clear();
    scene
}

fn channel_means(p: &[[f32; 4]]) -> [f64; 3] {
    let n = p.len() as f64;
    [0, 1, 2].map(|c| p.iter().map(|x| x[c] as f64).sum::<f64>() / n)
}

#[test]
fn instances_render_as_their_baked_meshes() {
    for integrator in ["path_mis", "direct_ems", "normals"] {
        let a = render_scene(instanced(), integrator);
        let b = render_scene(baked(instanced()), integrator);
        let (ma, mb) = (channel_means(&a), channel_means(&b));
        for c in 0..3 {
            let rel = (ma[c] - mb[c]).abs() / mb[c].abs().max(1e-3);
            assert!(
                rel < 0.01,
                "{integrator}: channel {c} means {ma:?} vs {mb:?}"
            );
        }
        // The same seeds on the same geometry: pixels differ only where rounding sends a
        // path elsewhere.
        let differ = (a.iter().zip(&b))
            .filter(|(x, y)| (0..3).any(|c| (x[c] - y[c]).abs() > 0.02 * (1.0 + y[c].abs())))
            .count();
        assert!(
            differ * 20 < a.len(),
            "{integrator}: {differ} of {} pixels differ",
            a.len()
        );
    }
}

/// Camera rays that end at a far clip still meet instances (the clipped query goes through
/// the top level too): with a far clip beyond the box, the image is the unclipped one.
#[test]
fn clipped_camera_rays_see_instances() {
    let mut clipped = instanced();
    let cam = clipped.camera.as_mut().expect("the box has a camera");
    cam.clip_end = 1000.0;
    let a = render_scene(instanced(), "normals");
    let b = render_scene(clipped, "normals");
    assert!(a == b, "a far clip beyond the scene changed the image");
}

#[test]
fn an_emissive_instance_lights_as_its_area_under_scale() {
    // Only the glowing spheres light the box: the light they give depends on their world area.
    let mut a = instanced();
    let mut b = baked(instanced());
    for s in [&mut a, &mut b] {
        let light = s.meshes.iter().position(|m| m.name == "light").unwrap();
        s.meshes[light].indices.clear();
    }
    let (ma, mb) = (
        channel_means(&render_scene(a, "direct_ems")),
        channel_means(&render_scene(b, "direct_ems")),
    );
    assert!(mb[0] > 1e-3, "the glowing spheres light the box: {mb:?}");
    for c in 0..3 {
        assert!(
            (ma[c] - mb[c]).abs() < 0.01 * mb[c],
            "channel {c}: {ma:?} vs {mb:?}"
        );
    }
}

#[test]
fn written_instances_load_back_as_instances() {
    let scene = instanced();
    let dir = std::env::temp_dir().join(format!("tesela-instances-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("instanced.gltf");
    tesela::scene::gltf_write::write(&scene, &path).unwrap();
    // Loaded as instances however few triangles they place (by default small ones are baked).
    let bytes = std::fs::read(&path).unwrap();
    let instanced = tesela::scene::gltf::LoadOptions { bake_triangles: 0 };
    let back =
        tesela::scene::gltf::load_from_slice_with(&bytes, Some(&dir), "instanced.gltf", &instanced)
            .unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(back.instances.len(), scene.instances.len());
    assert_eq!(
        back.instanced_triangle_count(),
        scene.instanced_triangle_count()
    );
    // The writer gives each material of the ball a glTF mesh on the same accessors: the ball
    // is stored once, its instances carrying their materials.
    let balls = back.meshes.iter().filter(|m| m.name == "ball").count();
    assert_eq!(balls, 1);
    for a in &scene.instances {
        assert!(
            back.instances
                .iter()
                .any(|i| i.to_world.abs_diff_eq(a.to_world, 1e-6)),
            "{:?} written and read back",
            a.to_world
        );
    }
    let names = |s: &Scene| {
        let mut v: Vec<String> = (s.instances.iter())
            .map(|i| {
                s.materials[i.material.unwrap_or(s.meshes[i.mesh].material)]
                    .name
                    .clone()
            })
            .collect();
        v.sort();
        v
    };
    assert_eq!(
        names(&back),
        names(&scene),
        "each instance keeps its material"
    );
}

/// What shading reads at a point of a mirrored, rotated, scaled instance equals what it reads
/// at the same point of the mesh baked into world space: object coordinates, Object Info,
/// tangent and bitangent sign (the file's tangents, and the fallback from the UVs).
#[test]
fn shading_reads_the_same_through_an_instance_as_baked() {
    use tesela::shading::globals::{ShaderGlobals, to_blender};
    let mesh = tesela::scene::Mesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        normals: vec![Vec3::Z; 3],
        uvs: vec![
            glam::Vec2::new(0.0, 1.0),
            glam::Vec2::new(1.0, 1.0),
            glam::Vec2::new(0.0, 0.0),
        ],
        indices: vec![[0, 1, 2]],
        ..Default::default()
    };
    let inst = Instance {
        motion: None,
        mesh: 0,
        to_world: Mat4::from_scale_rotation_translation(
            Vec3::new(-2.0, 0.5, 1.5),
            Quat::from_euler(glam::EulerRot::XYZ, 0.4, -0.8, 1.2),
            Vec3::new(3.0, -1.0, 2.0),
        ),
        material: None,
        object: ObjectInfo {
            random: 0.375,
            location: Vec3::new(3.0, -1.0, 2.0),
            ..Default::default()
        },
    };
    let baked = mesh.placed(&inst);
    let (b1, b2) = (0.2, 0.3);
    let p = inst.to_world.transform_point3(Vec3::new(b1, b2, 0.0));
    let at = |m: &'static tesela::scene::Mesh, i: Option<&'static Instance>, b1, b2| {
        let mut g = ShaderGlobals::at(p, Vec3::Z, glam::Vec2::ZERO);
        g.p = to_blender(p);
        g.mesh = Some(m);
        g.instance = i;
        g.b1 = b1;
        g.b2 = b2;
        g
    };
    for with_tangents in [false, true] {
        let mut mesh = mesh.clone();
        if with_tangents {
            mesh.attrs.tangents = vec![glam::Vec4::new(1.0, 0.0, 0.0, 1.0); 3];
        }
        let baked = if with_tangents {
            mesh.placed(&inst)
        } else {
            baked.clone()
        };
        let (mesh, baked, inst) = (
            Box::leak(Box::new(mesh)),
            Box::leak(Box::new(baked)),
            Box::leak(Box::new(inst.clone())),
        );
        // The mirrored bake reverses the winding: vertices 1 and 2 trade places.
        let (gi, gb) = (at(mesh, Some(inst), b1, b2), at(baked, None, b2, b1));
        assert!(
            gi.object_position()
                .abs_diff_eq(Vec3::new(b1, b2, 0.0), 1e-5)
        );
        assert!(gi.object_position().abs_diff_eq(gb.object_position(), 1e-5));
        assert_eq!(gi.object_info().unwrap().random, 0.375);
        assert_eq!(gb.object_info().unwrap().random, 0.375);
        let (ti, si) = gi.tangent().unwrap();
        let (tb, sb) = gb.tangent().unwrap();
        assert!(ti.abs_diff_eq(tb, 1e-5), "{with_tangents}: {ti} vs {tb}");
        assert_eq!(si, sb, "{with_tangents}: bitangent sign");
    }
}

#[test]
fn instances_that_cannot_be_drawn_are_left_out_without_a_panic() {
    let mut scene = instanced();
    let good = render_scene(instanced(), "albedo");
    let mut bad = scene.instances[0].clone();
    for to_world in [
        Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0)),
        Mat4::from_translation(Vec3::NAN),
    ] {
        scene.instances.push(Instance {
            motion: None,
            to_world,
            ..bad.clone()
        });
    }
    // In plain view at the centre of the box.
    bad.to_world = Mat4::from_scale_rotation_translation(
        Vec3::splat(0.2),
        Quat::IDENTITY,
        Vec3::new(0.0, 0.5, 0.2),
    );
    bad.material = Some(999);
    scene.instances.push(bad.clone());
    bad.material = None;
    bad.mesh = 999;
    scene.instances.push(bad);
    assert_eq!(render_scene(scene, "albedo"), good);
}
