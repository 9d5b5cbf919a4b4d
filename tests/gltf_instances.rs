//! glTF instancing: nodes sharing a mesh and `EXT_mesh_gpu_instancing` become one stored mesh
//! and its instances; bad placements are skipped with a warning or refused with a message
//! naming the file and the node or accessor, never a panic.

use base64::Engine;
use glam::{Mat4, Quat, Vec3};
use serde_json::{Value, json};
use tesela::scene::gltf::{LoadOptions, load_from_slice, load_from_slice_with};
use tesela::scene::{LoadErrorKind, Scene};

fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// A one-triangle mesh (accessor 0: indices, 1: positions) and `extra` float accessors
/// (VEC3 or VEC4 by their length per element), as accessors 2, 3, ...
fn doc(nodes: Value, indices: &[u16], extra: &[(&str, Vec<f32>)]) -> Value {
    let mut bin: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let pos_at = bin.len();
    bin.extend(f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0.]));
    let mut views = vec![
        json!({ "buffer": 0, "byteOffset": 0, "byteLength": indices.len() * 2 }),
        json!({ "buffer": 0, "byteOffset": pos_at, "byteLength": 36 }),
    ];
    let mut accessors = vec![
        json!({ "bufferView": 0, "componentType": 5123, "count": indices.len(), "type": "SCALAR" }),
        json!({ "bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3" }),
    ];
    for (ty, data) in extra {
        let width = if *ty == "VEC4" { 4 } else { 3 };
        views.push(json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": data.len() * 4 }));
        accessors.push(json!({
            "bufferView": views.len() - 1, "componentType": 5126,
            "count": data.len() / width, "type": ty
        }));
        bin.extend(f32s(data));
    }
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    json!({
        "asset": { "version": "2.0" },
        "extensionsUsed": ["EXT_mesh_gpu_instancing"],
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": nodes,
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 1 }, "indices": 0 }] }],
        "buffers": [{ "byteLength": bin.len(), "uri": uri }],
        "bufferViews": views,
        "accessors": accessors
    })
}

/// Loads with every mesh placed more than once instanced, however few triangles it has (by
/// default small ones are baked: see `small_placements_are_baked`).
fn load(d: &Value) -> Scene {
    let instanced = LoadOptions { bake_triangles: 0 };
    load_from_slice_with(&serde_json::to_vec(d).unwrap(), None, "t.gltf", &instanced).unwrap()
}

fn err(d: &Value) -> (LoadErrorKind, String) {
    match load_from_slice(&serde_json::to_vec(d).unwrap(), None, "t.gltf") {
        Ok(_) => panic!("loaded, expected an error"),
        Err(e) => {
            let s = e.to_string();
            assert!(s.starts_with("t.gltf: "), "message must name the file: {s}");
            (e.kind, s)
        }
    }
}

fn gpu(attributes: Value) -> Value {
    json!({ "EXT_mesh_gpu_instancing": { "attributes": attributes } })
}

#[test]
fn small_placements_are_baked() {
    // Three placements of a one-triangle mesh: baked by default (3 triangles in all),
    // instanced once the copies would exceed the limit.
    let d = doc(
        json!([
            { "mesh": 0, "translation": [1, 0, 0], "children": [1, 2] },
            { "mesh": 0, "scale": [-1, 2, 1] },
            { "mesh": 0, "translation": [0, 3, 0] }
        ]),
        &[0, 1, 2],
        &[],
    );
    let bytes = serde_json::to_vec(&d).unwrap();
    let baked = load_from_slice(&bytes, None, "t.gltf").unwrap();
    assert_eq!((baked.meshes.len(), baked.instances.len()), (3, 0));
    assert_eq!(baked.instanced_triangle_count(), 3);
    for (limit, instances) in [(3, 0), (2, 3)] {
        let o = LoadOptions {
            bake_triangles: limit,
        };
        let s = load_from_slice_with(&bytes, None, "t.gltf", &o).unwrap();
        assert_eq!(s.instances.len(), instances, "limit {limit}");
        assert_eq!(s.instanced_triangle_count(), 3);
    }
}

#[test]
fn nested_nodes_sharing_a_mesh_are_instances_of_one_mesh() {
    const H: f32 = std::f32::consts::FRAC_1_SQRT_2;
    // Node 0 holds the mesh and two children: one mirrored, one with a grandchild.
    let s = load(&doc(
        json!([
            { "mesh": 0, "translation": [1, 0, 0], "children": [1, 2] },
            { "mesh": 0, "scale": [-1, 2, 1] },
            { "mesh": 0, "rotation": [0, H, 0, H], "children": [3] },
            { "mesh": 0, "translation": [0, 0, 5] }
        ]),
        &[0, 1, 2],
        &[],
    ));
    assert_eq!(s.meshes.len(), 1);
    assert_eq!(s.instances.len(), 4);
    assert_eq!(s.instanced_triangle_count(), 4);
    let t0 = Mat4::from_translation(Vec3::X);
    let r = Mat4::from_quat(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2));
    let expect = [
        t0,
        t0 * Mat4::from_scale(Vec3::new(-1., 2., 1.)),
        t0 * r,
        t0 * r * Mat4::from_translation(Vec3::new(0., 0., 5.)),
    ];
    for (i, e) in s.instances.iter().zip(expect) {
        assert!(i.to_world.abs_diff_eq(e, 1e-5), "{:?} vs {e:?}", i.to_world);
        assert!(i.object.location.abs_diff_eq(e.w_axis.truncate(), 1e-5));
    }
    // The mesh is in object space: its positions are the file's.
    assert_eq!(s.meshes[0].positions[1], Vec3::X);
    let (lo, hi) = s.bounds().unwrap();
    assert!(lo.abs_diff_eq(Vec3::new(0., 0., -1.), 1e-5), "{lo}");
    assert!(hi.abs_diff_eq(Vec3::new(6., 2., 0.), 1e-5), "{hi}");
}

#[test]
fn gpu_instancing_places_the_mesh_under_the_node() {
    const H: f32 = std::f32::consts::FRAC_1_SQRT_2;
    let t = vec![0., 0., 0., 3., 0., 0., 0., 4., 0.];
    let r = vec![0., 0., 0., 1., 0., 0., H, H, 0., 0., 0., 1.];
    let sc = vec![1., 1., 1., 2., 2., 2., -1., 1., 1.];
    let d = doc(
        json!([{ "mesh": 0, "translation": [0, 0, -1],
                 "extensions": gpu(json!({ "TRANSLATION": 2, "ROTATION": 3, "SCALE": 4 })) }]),
        &[0, 1, 2],
        &[("VEC3", t), ("VEC4", r), ("VEC3", sc)],
    );
    let s = load(&d);
    assert_eq!((s.meshes.len(), s.instances.len()), (1, 3));
    let node = Mat4::from_translation(Vec3::new(0., 0., -1.));
    let second = node
        * Mat4::from_scale_rotation_translation(
            Vec3::splat(2.),
            Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
            Vec3::new(3., 0., 0.),
        );
    assert!(s.instances[1].to_world.abs_diff_eq(second, 1e-5));
    assert!(
        s.instances[2].to_world.x_axis.x < 0.0,
        "mirrored instance kept"
    );
    let randoms: Vec<f32> = s.instances.iter().map(|i| i.object.random).collect();
    assert!(
        randoms.iter().all(|r| (0.0..1.0).contains(r)) && randoms[0] != randoms[1],
        "each instance has its own Object Info random: {randoms:?}"
    );
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn non_finite_and_singular_instances_are_skipped_with_a_warning() {
    let t = vec![0., 0., 0., f32::NAN, 0., 0., 2., 0., 0.];
    let sc = vec![1., 1., 1., 1., 1., 1., 0., 1., 1.];
    let d = doc(
        json!([{ "mesh": 0,
                 "extensions": gpu(json!({ "TRANSLATION": 2, "SCALE": 3 })) }]),
        &[0, 1, 2],
        &[("VEC3", t), ("VEC3", sc)],
    );
    let s = load(&d);
    assert_eq!(s.instances.len(), 1, "only the first instance is valid");
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert!(
        s.warnings[0].contains("node 0: 2 of 3 placements of mesh 0 are skipped"),
        "{:?}",
        s.warnings
    );
    // A zero-length rotation quaternion is skipped the same way.
    let r = vec![0., 0., 0., 0., 0., 0., 0., 1.];
    let d = doc(
        json!([{ "mesh": 0, "extensions": gpu(json!({ "ROTATION": 2 })) }]),
        &[0, 1, 2],
        &[("VEC4", r)],
    );
    assert_eq!(load(&d).instances.len(), 1);
}

#[test]
fn a_billion_instances_are_refused_naming_the_accessor() {
    let mut d = doc(
        json!([{ "mesh": 0, "extensions": gpu(json!({ "TRANSLATION": 2 })) }]),
        &[0, 1, 2],
        &[("VEC3", vec![0.; 3])],
    );
    d["accessors"][2]["count"] = json!(1_000_000_000u64);
    let (kind, msg) = err(&d);
    assert_eq!(kind, LoadErrorKind::TooLarge, "{msg}");
    assert!(msg.contains("accessor 2"), "{msg}");
    assert!(
        msg.contains("1000000000 instances exceed the limit"),
        "{msg}"
    );
}

#[test]
fn mismatched_attribute_counts_and_bad_accessors_are_errors() {
    let d = doc(
        json!([{ "mesh": 0,
                 "extensions": gpu(json!({ "TRANSLATION": 2, "SCALE": 3 })) }]),
        &[0, 1, 2],
        &[("VEC3", vec![0.; 6]), ("VEC3", vec![1.; 9])],
    );
    let (_, msg) = err(&d);
    assert!(msg.contains("accessor 3 (node 0 EXT_mesh_gpu_instancing SCALE): 3 elements where the other attributes have 2"), "{msg}");
    let d = doc(
        json!([{ "mesh": 0, "extensions": gpu(json!({ "TRANSLATION": 9 })) }]),
        &[0, 1, 2],
        &[],
    );
    assert!(err(&d).1.contains("accessor 9 does not exist"));
    let d = doc(
        json!([{ "mesh": 0, "extensions": gpu(json!({ "TRANSLATION": 2 })) }]),
        &[0, 1, 2],
        &[("VEC4", vec![0.; 4])],
    );
    assert!(err(&d).1.contains("type VEC4 where VEC3 is expected"));
}

#[test]
fn instance_cycles_and_missing_meshes_are_errors() {
    let d = doc(
        json!([{ "mesh": 0, "children": [1] }, { "mesh": 0, "children": [0] }]),
        &[0, 1, 2],
        &[],
    );
    assert!(err(&d).1.contains("node 0 is reached twice (a cycle"));
    let d = doc(
        json!([{ "mesh": 0, "children": [1] }, { "mesh": 3 }]),
        &[0, 1, 2],
        &[],
    );
    assert!(
        err(&d)
            .1
            .contains("node 1: mesh 3 does not exist (the file has 1)")
    );
}

#[test]
fn trailing_indices_of_triangles_are_dropped_with_a_warning() {
    let s = load(&doc(json!([{ "mesh": 0 }]), &[0, 1, 2, 1, 2], &[]));
    assert_eq!(s.triangle_count(), 1);
    assert!(
        s.warnings.iter().any(|w| w.contains(
            "accessor 0 (indices of mesh 0 primitive 0): 5 indices are not a multiple of 3 for TRIANGLES; the last 2 are dropped"
        )),
        "{:?}",
        s.warnings
    );
}

#[test]
fn meshes_sharing_accessors_with_other_materials_are_one_geometry() {
    // Meshes 0 and 1 name the same accessors with different materials (Blender objects sharing
    // a mesh with object-linked materials); mesh 2 has its own positions.
    let mut d = doc(
        json!([
            { "mesh": 0, "translation": [0.0, 0.0, -1.0] },
            { "mesh": 1, "translation": [2.0, 0.0, -1.0] },
            { "mesh": 2, "translation": [4.0, 0.0, -1.0] }
        ]),
        &[0, 1, 2],
        &[("VEC3", vec![0., 0., 0., 2., 0., 0., 0., 2., 0.])],
    );
    d["scenes"][0]["nodes"] = json!([0, 1, 2]);
    let prim = |m: usize, pos: usize| json!({ "primitives": [{ "attributes": { "POSITION": pos }, "indices": 0, "material": m }] });
    d["meshes"] = json!([prim(0, 1), prim(1, 1), prim(0, 2)]);
    d["materials"] = json!([
        { "name": "red", "pbrMetallicRoughness": { "baseColorFactor": [1.0, 0.0, 0.0, 1.0] } },
        { "name": "blue", "pbrMetallicRoughness": { "baseColorFactor": [0.0, 0.0, 1.0, 1.0] } }
    ]);
    let s = load(&d);
    // Meshes 0 and 1: one stored geometry and two instances; mesh 2, placed once, is baked.
    assert_eq!(
        s.meshes.len(),
        2,
        "{:?}",
        s.meshes.iter().map(|m| &m.name).collect::<Vec<_>>()
    );
    assert_eq!(s.instances.len(), 2);
    assert_eq!(s.instances[0].mesh, s.instances[1].mesh);
    let stored = &s.meshes[s.instances[0].mesh];
    let material = |i: &tesela::scene::Instance| i.material.unwrap_or(stored.material);
    let names: Vec<&str> = s
        .instances
        .iter()
        .map(|i| s.materials[material(i)].name.as_str())
        .collect();
    assert_eq!(names, ["red", "blue"]);
    assert!((s.instances[1].to_world.w_axis.x - 2.0).abs() < 1e-6);
    let baked = s
        .meshes
        .iter()
        .find(|m| m.positions.len() == 3 && m.positions[1].x > 5.0);
    assert!(
        baked.is_some(),
        "mesh 2 baked at x = 4 with its own positions"
    );
}
