//! Scenes built in code: the default Cornell box and the seed's figures. `scenes/*.gltf` are
//! these scenes written out with `tesela export-builtin`.

use super::{Camera, Material, Mesh, Projection, Scene};
use glam::{Mat4, Quat, Vec2, Vec3};
use std::f32::consts::PI;

/// Names accepted by [`by_name`].
pub const NAMES: [&str; 3] = ["cornell-box", "cornell-spheres", "glass-pane"];

/// A built-in scene by name.
pub fn by_name(name: &str) -> Option<Scene> {
    match name {
        "cornell-box" => Some(cornell_box()),
        "cornell-spheres" => Some(cornell_spheres()),
        "glass-pane" => Some(glass_pane()),
        _ => None,
    }
}

fn add_material(scene: &mut Scene, m: Material) -> usize {
    scene.materials.push(m);
    scene.materials.len() - 1
}

/// A quad `a b c d` (counter-clockwise seen from the front) as two triangles, flat normals.
pub fn quad(name: &str, material: usize, a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> Mesh {
    let n = (b - a).cross(c - a).normalize();
    Mesh {
        name: name.into(),
        positions: vec![a, b, c, d],
        normals: vec![n; 4],
        uvs: vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        material,
        attrs: Default::default(),
    }
}

/// A UV sphere with smooth normals (outward) and `rings × segments` quads.
pub fn sphere(
    name: &str,
    material: usize,
    center: Vec3,
    radius: f32,
    rings: u32,
    segments: u32,
) -> Mesh {
    let mut m = Mesh {
        name: name.into(),
        material,
        ..Default::default()
    };
    for r in 0..=rings {
        let theta = PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = 2.0 * PI * s as f32 / segments as f32;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            m.positions.push(center + n * radius);
            m.normals.push(n);
            m.uvs.push(Vec2::new(
                s as f32 / segments as f32,
                r as f32 / rings as f32,
            ));
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let i0 = r * row + s;
            let (i1, i2, i3) = (i0 + 1, i0 + row, i0 + row + 1);
            if r != 0 {
                m.indices.push([i0, i2, i1]);
            }
            if r + 1 != rings {
                m.indices.push([i1, i2, i3]);
            }
        }
    }
    m
}

/// An axis-aligned box rotated by `angle` about +Y around its base centre, as one mesh.
fn block(name: &str, material: usize, base: Vec3, size: Vec3, angle: f32) -> Mesh {
    let t = Mat4::from_rotation_translation(Quat::from_rotation_y(angle), base);
    let h = Vec3::new(size.x * 0.5, 0.0, size.z * 0.5);
    let corner = |x: f32, y: f32, z: f32| {
        t.transform_point3(Vec3::new(-h.x + x * size.x, y * size.y, -h.z + z * size.z))
    };
    let faces = [
        [(0., 1., 1.), (1., 1., 1.), (1., 1., 0.), (0., 1., 0.)], // top
        [(0., 0., 1.), (1., 0., 1.), (1., 1., 1.), (0., 1., 1.)], // +z
        [(1., 0., 0.), (0., 0., 0.), (0., 1., 0.), (1., 1., 0.)], // -z
        [(1., 0., 1.), (1., 0., 0.), (1., 1., 0.), (1., 1., 1.)], // +x
        [(0., 0., 0.), (0., 0., 1.), (0., 1., 1.), (0., 1., 0.)], // -x
    ];
    let mut m = Mesh {
        name: name.into(),
        material,
        ..Default::default()
    };
    for f in faces {
        let q = f.map(|(x, y, z)| corner(x, y, z));
        let base_index = m.positions.len() as u32;
        let n = (q[1] - q[0]).cross(q[2] - q[0]).normalize();
        m.positions.extend(q);
        m.normals.extend([n; 4]);
        m.indices.push([base_index, base_index + 1, base_index + 2]);
        m.indices.push([base_index, base_index + 2, base_index + 3]);
    }
    m
}

/// Camera-to-world transform of a camera at `eye` looking at `target` with +Y up
/// (the camera looks down its local -Z).
pub fn look_at(eye: Vec3, target: Vec3) -> Mat4 {
    let back = (eye - target).normalize();
    let right = Vec3::Y.cross(back).normalize();
    let up = back.cross(right);
    Mat4::from_cols(
        right.extend(0.0),
        up.extend(0.0),
        back.extend(0.0),
        eye.extend(1.0),
    )
}

/// The empty Cornell box (walls, light), 1 m wide, open towards +Z, camera on +Z.
fn cornell_shell(scene: &mut Scene) {
    let white = add_material(
        scene,
        Material::diffuse("white", Vec3::new(0.725, 0.71, 0.68)),
    );
    let red = add_material(
        scene,
        Material::diffuse("red", Vec3::new(0.63, 0.065, 0.05)),
    );
    let green = add_material(
        scene,
        Material::diffuse("green", Vec3::new(0.14, 0.45, 0.091)),
    );
    let light = add_material(
        scene,
        Material::emitter("light", Vec3::new(17.0, 12.0, 4.0), false),
    );
    let (l, r, b, t, back, front) = (-0.5, 0.5, 0.0, 1.0, -0.5, 0.5);
    let v = Vec3::new;
    scene.meshes.push(quad(
        "floor",
        white,
        v(l, b, front),
        v(r, b, front),
        v(r, b, back),
        v(l, b, back),
    ));
    scene.meshes.push(quad(
        "ceiling",
        white,
        v(l, t, back),
        v(r, t, back),
        v(r, t, front),
        v(l, t, front),
    ));
    scene.meshes.push(quad(
        "back",
        white,
        v(l, b, back),
        v(r, b, back),
        v(r, t, back),
        v(l, t, back),
    ));
    scene.meshes.push(quad(
        "left",
        red,
        v(l, b, front),
        v(l, b, back),
        v(l, t, back),
        v(l, t, front),
    ));
    scene.meshes.push(quad(
        "right",
        green,
        v(r, b, back),
        v(r, b, front),
        v(r, t, front),
        v(r, t, back),
    ));
    let (s, y) = (0.12, t - 0.001);
    scene.meshes.push(quad(
        "light",
        light,
        v(-s, y, -s),
        v(s, y, -s),
        v(s, y, s),
        v(-s, y, s),
    ));
    scene.camera = Some(Camera {
        projection: Projection::Perspective {
            yfov: 39.3f32.to_radians(),
        },
        to_world: Mat4::from_translation(v(0.0, 0.5, 1.94)),
        aspect: Some(1.0),
        ..Default::default()
    });
}

/// The diffuse Cornell box with a tall and a short block, lit by a one-sided area light.
pub fn cornell_box() -> Scene {
    let mut scene = Scene::default();
    cornell_shell(&mut scene);
    let white = 0;
    scene.meshes.push(block(
        "tall block",
        white,
        Vec3::new(-0.17, 0.0, -0.15),
        Vec3::new(0.3, 0.6, 0.3),
        0.3,
    ));
    scene.meshes.push(block(
        "short block",
        white,
        Vec3::new(0.18, 0.0, 0.12),
        Vec3::new(0.3, 0.3, 0.3),
        -0.3,
    ));
    scene
}

/// The diffuse Cornell box with its light's area scaled by `area_scale` about the light's
/// centre and its radiance by `1 / area_scale`: the same emitted power (radiance × area × π
/// for a one-sided Lambertian emitter) through a smaller or larger emitter. `area_scale` must
/// keep the light inside the ceiling (at most 17: the ceiling is 1 m wide, the light 0.24 m).
pub fn cornell_box_light_area(area_scale: f32) -> Scene {
    let mut scene = cornell_box();
    let k = area_scale.sqrt();
    for m in &mut scene.meshes {
        if m.name == "light" {
            let c = m.positions.iter().copied().sum::<Vec3>() / m.positions.len() as f32;
            for p in &mut m.positions {
                *p = c + (*p - c) * Vec3::new(k, 1.0, k);
            }
        }
    }
    for m in &mut scene.materials {
        if m.name == "light" {
            m.emission /= area_scale;
        }
    }
    scene
}

/// The Cornell box with a mirror sphere and a glass sphere (the seed's delta-BSDF figure).
pub fn cornell_spheres() -> Scene {
    let mut scene = Scene::default();
    cornell_shell(&mut scene);
    let mirror = add_material(&mut scene, Material::mirror("mirror", Vec3::ONE));
    let glass = add_material(&mut scene, Material::glass("glass", 1.5));
    scene.meshes.push(sphere(
        "mirror sphere",
        mirror,
        Vec3::new(-0.2, 0.2, -0.15),
        0.2,
        48,
        96,
    ));
    scene.meshes.push(sphere(
        "glass sphere",
        glass,
        Vec3::new(0.2, 0.2, 0.15),
        0.2,
        48,
        96,
    ));
    scene
}

/// The seed's "interesting image": a tilted glass pane (a thin slab) in front of an emissive
/// wall with a pattern of strips, above a diffuse floor.
pub fn glass_pane() -> Scene {
    let mut scene = Scene::default();
    let floor = add_material(&mut scene, Material::diffuse("floor", Vec3::splat(0.6)));
    let dark = add_material(&mut scene, Material::diffuse("wall", Vec3::splat(0.1)));
    let warm = add_material(
        &mut scene,
        Material::emitter("warm", Vec3::new(2.4, 1.2, 0.4), false),
    );
    let cool = add_material(
        &mut scene,
        Material::emitter("cool", Vec3::new(0.4, 1.0, 2.4), false),
    );
    let glass = add_material(&mut scene, Material::glass("glass", 1.5));
    let v = Vec3::new;
    scene.meshes.push(quad(
        "floor",
        floor,
        v(-2.0, 0.0, 2.0),
        v(2.0, 0.0, 2.0),
        v(2.0, 0.0, -2.0),
        v(-2.0, 0.0, -2.0),
    ));
    scene.meshes.push(quad(
        "wall",
        dark,
        v(-2.0, 0.0, -1.0),
        v(2.0, 0.0, -1.0),
        v(2.0, 2.0, -1.0),
        v(-2.0, 2.0, -1.0),
    ));
    for i in 0..6 {
        let x0 = -1.5 + i as f32 * 0.5;
        let m = if i % 2 == 0 { warm } else { cool };
        scene.meshes.push(quad(
            &format!("strip {i}"),
            m,
            v(x0 + 0.05, 0.3, -0.99),
            v(x0 + 0.3, 0.3, -0.99),
            v(x0 + 0.3, 1.7, -0.99),
            v(x0 + 0.05, 1.7, -0.99),
        ));
    }
    // A 1.2 × 1.0 × 0.12 m slab, tilted 40° about X and 30° about Y.
    let mut pane = block("glass pane", glass, Vec3::ZERO, v(1.2, 1.0, 0.12), 0.0);
    // The block helper leaves out the bottom face; close the slab with it.
    let h = v(0.6, 0.0, 0.06);
    let bi = pane.positions.len() as u32;
    pane.positions.extend([
        v(-h.x, 0.0, -h.z),
        v(h.x, 0.0, -h.z),
        v(h.x, 0.0, h.z),
        v(-h.x, 0.0, h.z),
    ]);
    pane.normals.extend([-Vec3::Y; 4]);
    pane.indices.push([bi, bi + 1, bi + 2]);
    pane.indices.push([bi, bi + 2, bi + 3]);
    let t = Mat4::from_translation(v(0.0, 0.45, 0.1))
        * Mat4::from_rotation_y(30f32.to_radians())
        * Mat4::from_rotation_x(-40f32.to_radians());
    for p in &mut pane.positions {
        *p = t.transform_point3(*p);
    }
    for n in &mut pane.normals {
        *n = t.transform_vector3(*n).normalize();
    }
    scene.meshes.push(pane);
    scene.camera = Some(Camera {
        projection: Projection::Perspective {
            yfov: 45f32.to_radians(),
        },
        to_world: look_at(v(0.0, 1.3, 2.6), v(0.0, 0.7, -0.5)),
        aspect: None,
        ..Default::default()
    });
    scene
}
