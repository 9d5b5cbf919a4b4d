//! Whole-document tests of the loader: transforms, instancing, normals, cameras, lights and
//! Tesela's extensions, on small files built in code.

use std::f32::consts::{FRAC_PI_2, PI};

use base64::Engine;
use glam::{Mat4, Quat, Vec3};
use serde_json::{Value, json};

use super::load_from_slice;
use crate::scene::{Light, LightShape, LightVisibility, Projection, Scene, SpotFalloff};

/// Builds the binary part of a test document.
#[derive(Default)]
pub(super) struct Bin {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    pub(super) fn add(
        &mut self,
        data: &[u8],
        comp: u32,
        count: usize,
        ty: &str,
        normalized: bool,
    ) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        self.views.push(json!({
            "buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()
        }));
        self.bytes.extend_from_slice(data);
        self.accessors.push(json!({
            "bufferView": self.views.len() - 1, "componentType": comp, "count": count,
            "type": ty, "normalized": normalized
        }));
        self.accessors.len() - 1
    }

    pub(super) fn vec3(&mut self, v: &[[f32; 3]]) -> usize {
        let b: Vec<u8> = v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        self.add(&b, 5126, v.len(), "VEC3", false)
    }

    /// FLOAT components, `ty` naming the element type (`VEC2`, `VEC4`, ...).
    pub(super) fn floats(&mut self, v: &[f32], ty: &str) -> usize {
        let width = match ty {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "MAT4" => 16,
            _ => 4,
        };
        let b: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        self.add(&b, 5126, v.len() / width, ty, false)
    }

    pub(super) fn indices(&mut self, i: &[u16]) -> usize {
        let b: Vec<u8> = i.iter().flat_map(|x| x.to_le_bytes()).collect();
        self.add(&b, 5123, i.len(), "SCALAR", false)
    }

    /// Completes `doc` with the buffer, views and accessors.
    pub(super) fn finish(self, mut doc: Value) -> Vec<u8> {
        let b64 = base64::engine::general_purpose::STANDARD.encode(&self.bytes);
        doc["asset"] = json!({ "version": "2.0" });
        doc["buffers"] = json!([{
            "byteLength": self.bytes.len(),
            "uri": format!("data:application/gltf-buffer;base64,{b64}")
        }]);
        doc["bufferViews"] = json!(self.views);
        doc["accessors"] = json!(self.accessors);
        serde_json::to_vec(&doc).unwrap()
    }
}

pub(super) fn load(bytes: &[u8]) -> Scene {
    load_from_slice(bytes, None, "test.gltf").unwrap_or_else(|e| panic!("{e}"))
}

/// A unit right triangle in the XY plane facing +Z, with +Z normals, as mesh 0.
fn triangle_doc(nodes: Value) -> Vec<u8> {
    let mut b = Bin::default();
    let p = b.vec3(&[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]);
    let n = b.vec3(&[[0., 0., 1.]; 3]);
    let i = b.indices(&[0, 1, 2]);
    let roots: Vec<usize> = (0..nodes.as_array().unwrap().len()).collect();
    b.finish(json!({
        "scenes": [{ "nodes": roots }],
        "nodes": nodes,
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": p, "NORMAL": n }, "indices": i }] }]
    }))
}

fn face_normal(s: &Scene, mesh: usize) -> Vec3 {
    let m = &s.meshes[mesh];
    let [a, b, c] = m.indices[0].map(|i| m.positions[i as usize]);
    (b - a).cross(c - a).normalize()
}

#[test]
fn instancing_trs_and_nested_matrices() {
    // Node 0 and node 2 (child of node 1) share mesh 0.
    let m =
        Mat4::from_rotation_translation(Quat::from_rotation_x(-FRAC_PI_2), Vec3::new(0., 5., 0.));
    let s = load(&triangle_doc(
        json!([{ "mesh": 0, "translation": [10, 0, 0] }]),
    ));
    assert_eq!(s.meshes.len(), 1);
    assert_eq!(s.meshes[0].positions[1], Vec3::new(11., 0., 0.));

    let mut doc: Value = serde_json::from_slice(&triangle_doc(json!([
        { "mesh": 0, "translation": [10, 0, 0] },
        { "matrix": m.to_cols_array(), "children": [2] },
        { "mesh": 0, "scale": [2, 2, 2] }
    ])))
    .unwrap();
    doc["scenes"][0]["nodes"] = json!([0, 1]);
    let bytes = serde_json::to_vec(&doc).unwrap();
    // By default two copies of a triangle are baked (a flat BVH is faster); instanced:
    let baked = load(&bytes);
    assert_eq!((baked.meshes.len(), baked.instances.len()), (2, 0));
    let instanced = super::LoadOptions { bake_triangles: 0 };
    let s = super::load_from_slice_with(&bytes, None, "test.gltf", &instanced).unwrap();
    assert_eq!(s.meshes.len(), 1, "one mesh stored once");
    assert_eq!(s.instances.len(), 2, "and placed twice");
    assert!(
        s.instances
            .iter()
            .all(|i| i.mesh == 0 && i.material.is_none())
    );
    let first = s.meshes[0].placed(&s.instances[0]);
    assert_eq!(first.positions[1], Vec3::new(11., 0., 0.));
    // Second instance: scaled by 2, rotated -90° about X (+Y -> -Z), moved up 5.
    let second = Scene {
        meshes: vec![s.meshes[0].placed(&s.instances[1])],
        ..Default::default()
    };
    let p = &second.meshes[0].positions;
    assert!(p[2].abs_diff_eq(Vec3::new(0., 5., -2.), 1e-5), "{:?}", p);
    assert!(second.meshes[0].normals[0].abs_diff_eq(Vec3::Y, 1e-5));
    assert!(face_normal(&second, 0).abs_diff_eq(Vec3::Y, 1e-5));
    assert_eq!(s.materials.len(), 1);
}

#[test]
fn negative_scale_flips_winding_and_normals_follow() {
    let s = load(&triangle_doc(json!([{ "mesh": 0, "scale": [1, 1, -1] }])));
    assert!(face_normal(&s, 0).abs_diff_eq(-Vec3::Z, 1e-6));
    assert!(s.meshes[0].normals[0].abs_diff_eq(-Vec3::Z, 1e-6));
    let s = load(&triangle_doc(json!([{ "mesh": 0, "scale": [-1, 1, 1] }])));
    assert_eq!(s.meshes[0].indices[0], [0, 2, 1]);
    assert!(face_normal(&s, 0).abs_diff_eq(Vec3::Z, 1e-6));
}

#[test]
fn zero_normals_are_dropped_and_missing_ones_stay_empty() {
    let mut b = Bin::default();
    let p = b.vec3(&[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]);
    let n = b.vec3(&[[0., 0., 1.], [0., 0., 0.], [0., 0., 1.]]);
    let bytes = b.finish(json!({
        "nodes": [{ "mesh": 0 }, { "mesh": 1 }],
        "meshes": [
            { "primitives": [{ "attributes": { "POSITION": p, "NORMAL": n } }] },
            { "primitives": [{ "attributes": { "POSITION": p } }] }
        ]
    }));
    let s = load(&bytes);
    assert_eq!(s.meshes.len(), 2);
    assert!(s.meshes[0].normals.is_empty());
    assert!(s.meshes[1].normals.is_empty());
    assert_eq!(s.meshes[0].indices, vec![[0, 1, 2]], "non-indexed");
}

#[test]
fn strips_fans_and_empty_primitives() {
    let mut b = Bin::default();
    let p = b.vec3(&[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]]);
    let two = b.vec3(&[[0., 0., 0.], [1., 0., 0.]]);
    let bytes = b.finish(json!({
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [
            { "attributes": { "POSITION": p }, "mode": 5 },
            { "attributes": { "POSITION": p }, "mode": 6 },
            { "attributes": { "POSITION": two }, "mode": 4 },
            { "attributes": { "POSITION": p }, "mode": 1 }
        ] }]
    }));
    let s = load(&bytes);
    assert_eq!(
        s.meshes.len(),
        2,
        "the 2-vertex primitive has no triangle and is dropped"
    );
    assert_eq!(s.meshes[0].indices, vec![[0, 1, 2], [2, 1, 3]]);
    assert_eq!(s.meshes[1].indices, vec![[1, 2, 0], [2, 3, 0]]);
    assert_eq!(s.warnings.len(), 2, "{:?}", s.warnings);
    assert!(
        s.warnings[0].contains("primitive 2: 2 vertices without indices are not a multiple of 3")
    );
    assert!(s.warnings[1].contains("LINES"));
}

#[test]
fn quantized_attributes() {
    let mut b = Bin::default();
    // u16 positions (not normalized), i8 normalized normals, u8 normalized uvs.
    let pos: Vec<u8> = [0u16, 0, 0, 0, 100, 0, 0, 0, 0, 100, 0, 0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let p = b.add(&pos, 5123, 3, "VEC3", false);
    // Each VEC3 of i8 padded to 4 bytes needs byteStride 4.
    let n = b.add(
        &[0, 0, 127, 0, 0, 0, 127, 0, 0, 0, 127, 0],
        5120,
        3,
        "VEC3",
        true,
    );
    b.views[1]["byteStride"] = json!(4);
    // The 6-byte position elements are padded to 8 as well.
    b.views[0]["byteStride"] = json!(8);
    let t = b.add(&[0, 255, 255, 255, 0, 0], 5121, 3, "VEC2", true);
    let bytes = b.finish(json!({
        "extensionsUsed": ["KHR_mesh_quantization"],
        "extensionsRequired": ["KHR_mesh_quantization"],
        "nodes": [{ "mesh": 0, "scale": [0.01, 0.01, 0.01] }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": p, "NORMAL": n, "TEXCOORD_0": t } }] }]
    }));
    let s = load(&bytes);
    let m = &s.meshes[0];
    assert!(
        m.positions[1].abs_diff_eq(Vec3::X, 1e-6),
        "{:?}",
        m.positions
    );
    assert!(m.normals.iter().all(|n| n.abs_diff_eq(Vec3::Z, 1e-6)));
    assert_eq!(m.uvs[0], glam::Vec2::new(0.0, 1.0));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn camera_is_the_first_in_traversal_order_and_rigid() {
    let rot = Quat::from_rotation_y(0.5);
    let bytes = serde_json::to_vec(&json!({
        "asset": { "version": "2.0" },
        "scenes": [{ "nodes": [0, 2] }],
        "cameras": [
            { "type": "perspective", "perspective": { "yfov": 0.5, "znear": 0.1 } },
            { "type": "orthographic", "orthographic": { "xmag": 3, "ymag": 2, "znear": 0.1, "zfar": 9 } }
        ],
        "nodes": [
            { "children": [1], "scale": [3, 3, 3] },
            { "camera": 1, "rotation": rot.to_array(), "translation": [1, 2, 3] },
            { "camera": 0 }
        ]
    }))
    .unwrap();
    let s = load(&bytes);
    let c = s.camera.unwrap();
    assert_eq!(c.projection, Projection::Orthographic { ymag: 2.0 });
    assert_eq!(c.aspect, Some(1.5));
    let want = Mat4::from_rotation_translation(rot, Vec3::new(3., 6., 9.));
    assert!(c.to_world.abs_diff_eq(want, 1e-5), "{:?}", c.to_world);
}

fn lights_doc(generator: Option<&str>, nodes: Value, lights: Value) -> Vec<u8> {
    let mut asset = json!({ "version": "2.0" });
    if let Some(g) = generator {
        asset["generator"] = json!(g);
    }
    let roots: Vec<usize> = (0..nodes.as_array().unwrap().len()).collect();
    serde_json::to_vec(&json!({
        "asset": asset,
        "extensionsUsed": ["KHR_lights_punctual", "TESELA_light"],
        "extensionsRequired": ["KHR_lights_punctual"],
        "extensions": { "KHR_lights_punctual": { "lights": lights } },
        "scenes": [{ "nodes": roots }],
        "nodes": nodes
    }))
    .unwrap()
}

fn khr(i: usize) -> Value {
    json!({ "KHR_lights_punctual": { "light": i } })
}

#[test]
fn khr_punctual_lights_in_radiometric_units() {
    let rot = Quat::from_rotation_x(FRAC_PI_2);
    let bytes = lights_doc(
        None,
        json!([
            { "extensions": khr(0), "translation": [1, 2, 3] },
            { "extensions": khr(1), "rotation": rot.to_array() },
            { "extensions": khr(2) }
        ]),
        json!([
            { "type": "point", "intensity": 1366, "color": [1, 0.5, 0.25] },
            { "type": "spot", "intensity": 683, "spot": { "innerConeAngle": 0.2, "outerConeAngle": 0.5 } },
            { "type": "directional", "intensity": 2049 }
        ]),
    );
    let s = load(&bytes);
    assert_eq!(s.lights.len(), 3);
    match &s.lights[0] {
        Light::Point {
            position,
            intensity,
        } => {
            assert_eq!(*position, Vec3::new(1., 2., 3.));
            assert!(intensity.abs_diff_eq(Vec3::new(2., 1., 0.5), 1e-6));
        }
        l => panic!("{l:?}"),
    }
    match &s.lights[1] {
        Light::Spot {
            direction,
            intensity,
            falloff,
            ..
        } => {
            assert!(direction.abs_diff_eq(Vec3::Y, 1e-6), "{direction}");
            assert!(intensity.abs_diff_eq(Vec3::ONE, 1e-6));
            assert_eq!(
                *falloff,
                SpotFalloff::Gltf {
                    cos_inner: 0.2f32.cos(),
                    cos_outer: 0.5f32.cos()
                }
            );
        }
        l => panic!("{l:?}"),
    }
    match &s.lights[2] {
        Light::Directional {
            direction,
            irradiance,
            angle,
        } => {
            assert!(direction.abs_diff_eq(-Vec3::Z, 1e-6));
            assert!(irradiance.abs_diff_eq(Vec3::splat(3.0), 1e-6));
            assert_eq!(*angle, 0.0);
        }
        l => panic!("{l:?}"),
    }
}

#[test]
fn blender_exported_spots_get_cycles_falloff() {
    let outer = std::f32::consts::FRAC_PI_6;
    let inner = outer * (1.0 - 0.3);
    let bytes = lights_doc(
        Some("Khronos glTF Blender I/O v5.0.21"),
        json!([{ "extensions": khr(0) }, { "extensions": khr(1) }]),
        json!([
            { "type": "spot", "intensity": 683, "spot": { "innerConeAngle": inner, "outerConeAngle": outer } },
            { "type": "spot", "intensity": 683, "spot": { "innerConeAngle": outer, "outerConeAngle": outer } }
        ]),
    );
    let s = load(&bytes);
    let Light::Spot {
        falloff: SpotFalloff::Cycles { cos_half, smooth },
        ..
    } = s.lights[0]
    else {
        panic!("{:?}", s.lights[0]);
    };
    assert!((cos_half - outer.cos()).abs() < 1e-6);
    assert!(
        (smooth - (1.0 - outer.cos()) * 0.3).abs() < 1e-6,
        "{smooth}"
    );
    // blend 0: a hard edge.
    let Light::Spot {
        falloff: SpotFalloff::Cycles { smooth, .. },
        ..
    } = s.lights[1]
    else {
        panic!("{:?}", s.lights[1]);
    };
    assert_eq!(smooth, 0.0);
}

#[test]
fn tesela_light_overrides_the_khr_copy() {
    let mut both = khr(0);
    both["TESELA_light"] = json!({ "type": "POINT", "color": [1, 1, 1], "power": 100.0 });
    let bytes = lights_doc(
        None,
        json!([
            { "extensions": both, "translation": [0, 1, 0] },
            { "extensions": { "TESELA_light": { "type": "SPOT", "power": 40.0, "color": [1, 0, 0], "spot_size": 1.0, "spot_blend": 0.2, "radius": 0.1, "soft_falloff": false } } },
            { "extensions": { "TESELA_light": { "type": "SUN", "strength": 3.0, "color": [1, 1, 0.5], "angle": 0.01,
                                                "visible_camera": false, "visible_glossy": false, "cast_shadow": false } } }
        ]),
        json!([{ "type": "point", "intensity": 5435.14 }]),
    );
    let s = load(&bytes);
    assert_eq!(s.lights.len(), 3);
    let blender = |i: usize| match &s.lights[i] {
        Light::Blender {
            shape, visibility, ..
        } => (*shape, *visibility),
        l => panic!("{l:?}"),
    };
    let (shape, vis) = blender(0);
    assert_eq!(vis, LightVisibility::default());
    match shape {
        LightShape::Point {
            position,
            intensity,
            radius,
            soft_falloff,
            spot,
        } => {
            assert_eq!(position, Vec3::Y);
            assert!(intensity.abs_diff_eq(Vec3::splat(100.0 / (4.0 * PI)), 1e-5));
            assert_eq!((radius, soft_falloff, spot), (0.0, true, None));
        }
        l => panic!("{l:?}"),
    }
    match blender(1).0 {
        LightShape::Point {
            intensity,
            radius,
            soft_falloff,
            spot: Some((direction, falloff)),
            ..
        } => {
            assert!(intensity.abs_diff_eq(Vec3::new(40.0 / (4.0 * PI), 0., 0.), 1e-5));
            assert!(direction.abs_diff_eq(-Vec3::Z, 1e-6));
            assert_eq!((radius, soft_falloff), (0.1, false));
            let ch = 0.5f32.cos();
            assert_eq!(
                falloff,
                SpotFalloff::Cycles {
                    cos_half: ch,
                    smooth: (1.0 - ch) * 0.2
                }
            );
        }
        l => panic!("{l:?}"),
    }
    let (shape, vis) = blender(2);
    match shape {
        LightShape::Sun {
            irradiance, angle, ..
        } => {
            assert!(irradiance.abs_diff_eq(Vec3::new(3., 3., 1.5), 1e-6));
            assert_eq!(angle, 0.01);
        }
        l => panic!("{l:?}"),
    }
    assert_eq!(
        vis,
        LightVisibility {
            camera: false,
            glossy: false,
            cast_shadow: false,
            ..Default::default()
        }
    );
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn a_light_node_graph_is_evaluated_when_constant() {
    // The add-on's light graph: Blackbody (3200 K) into the Emission, strength 2 (constant:
    // the colour is base_color x its emission); a Noise Texture on the strength varies over
    // the light: the fallback `color` and the warnings.
    let graph = |strength: Value| {
        json!({"version": 1, "surface": [1, "Emission"], "nodes": [
            {"name": "Blackbody", "type": "ShaderNodeBlackbody", "props": {},
             "inputs": {"Temperature": 3200.0}, "internal_links": {}},
            {"name": "Emission", "type": "ShaderNodeEmission", "props": {},
             "inputs": {"Color": {"link": [0, "Color"]}, "Strength": strength},
             "internal_links": {}},
            {"name": "Noise Texture", "type": "ShaderNodeTexNoise", "props": {},
             "inputs": {}, "internal_links": {}}]})
    };
    let light = |strength: Value| {
        json!({ "TESELA_light": { "type": "POINT", "power": 100.0, "color": [0.5, 0.5, 0.5],
                                  "base_color": [1.0, 1.0, 0.5], "graph": graph(strength),
                                  "node_warnings": ["light 'Lamp': not rendered"] } })
    };
    let noise = json!({"link": [2, "Fac"]});
    // A node the renderer does not implement must not fold into a constant.
    let mut unknown = light(json!({"link": [2, "Fac"]}));
    unknown["TESELA_light"]["graph"]["nodes"][2]["type"] = json!("ShaderNodeTexIES");
    unknown["TESELA_light"]["node_warnings"] = json!(["light 'Spot': IES not rendered"]);
    let bytes = lights_doc(
        None,
        json!([{ "extensions": light(json!(2.0)) }, { "extensions": light(noise) },
               { "extensions": unknown }]),
        json!([]),
    );
    let s = load(&bytes);
    let warnings = &s.warnings;
    let intensity = |i: usize| match &s.lights[i] {
        Light::Blender {
            shape: LightShape::Point { intensity, .. },
            ..
        } => *intensity * (4.0 * std::f32::consts::PI) / 100.0,
        l => panic!("{l:?}"),
    };
    let warm = intensity(0);
    // Blackbody 3200 K is orange: red well above blue, and the strength 2 and the base colour
    // (blue halved) multiply it.
    assert!(warm.x > 2.0 * warm.z && warm.x > 1.0, "{warm}");
    assert!((intensity(1) - Vec3::splat(0.5)).abs().max_element() < 1e-5);
    assert!((intensity(2) - Vec3::splat(0.5)).abs().max_element() < 1e-5);
    assert!(
        warnings.iter().any(|w| w.contains("light 'Spot'")),
        "{warnings:?}"
    );
    assert!(
        warnings.iter().any(|w| w.contains("ShaderNodeTexIES")),
        "{warnings:?}"
    );
    assert_eq!(
        warnings
            .iter()
            .filter(|w| w.contains("light 'Lamp'"))
            .count(),
        1,
        "{warnings:?}"
    );
}

#[test]
fn tesela_area_lights_keep_their_shape() {
    // A 2 m square under a node scaled by 2 and turned to face down (-Z -> -Y).
    let rot = Quat::from_rotation_x(-FRAC_PI_2);
    let bytes = lights_doc(
        None,
        json!([
            { "name": "Key", "rotation": rot.to_array(), "scale": [2, 2, 2], "translation": [0, 3, 0],
              "extensions": { "TESELA_light": { "type": "AREA", "shape": "SQUARE", "size": 2.0, "power": 100.0, "color": [1, 0.5, 1], "spread": 1.0 } } },
            { "extensions": { "TESELA_light": { "type": "AREA", "shape": "DISK", "size": 1.0, "power": 10.0 } } },
            { "extensions": { "TESELA_light": { "type": "AREA", "shape": "RECTANGLE", "size": 2.0, "size_y": 0.5, "power": 10.0 } } },
            { "scale": [1, 1, -1],
              "extensions": { "TESELA_light": { "type": "AREA", "shape": "ELLIPSE", "size": 2.0, "size_y": 1.0, "power": 10.0 } } }
        ]),
        json!([]),
    );
    let s = load(&bytes);
    assert!(s.meshes.is_empty(), "lights are not geometry");
    assert_eq!(s.lights.len(), 4);
    let area = |i: usize| match s.lights[i] {
        Light::Blender {
            shape:
                LightShape::Area {
                    center,
                    normal,
                    size_u,
                    size_v,
                    ellipse,
                    radiance,
                    spread,
                    ..
                },
            ..
        } => (center, normal, size_u, size_v, ellipse, radiance, spread),
        ref l => panic!("{l:?}"),
    };
    let (center, normal, su, sv, ellipse, radiance, spread) = area(0);
    assert!(center.abs_diff_eq(Vec3::new(0., 3., 0.), 1e-6));
    assert!(normal.abs_diff_eq(-Vec3::Y, 1e-5), "faces the node's -Z");
    assert!(
        (su - 4.0).abs() < 1e-5 && (sv - 4.0).abs() < 1e-5,
        "{su} {sv}"
    );
    assert_eq!((ellipse, spread), (false, 1.0));
    assert!(radiance.abs_diff_eq(Vec3::new(1., 0.5, 1.) * 100.0 / (PI * 16.0), 1e-5));
    let (_, normal, _, _, ellipse, radiance, spread) = area(1);
    assert!(ellipse && spread == PI && normal.abs_diff_eq(-Vec3::Z, 1e-6));
    assert!(
        (radiance.x - 10.0 / (PI * PI / 4.0)).abs() < 1e-4,
        "exact disk area"
    );
    assert!((area(2).5.x - 10.0 / PI).abs() < 1e-4, "area 1 m²");
    // Mirrored in Z: the light now faces +Z.
    assert!(area(3).1.abs_diff_eq(Vec3::Z, 1e-6));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn tesela_light_bad_parameters_warn_and_fall_back() {
    let bytes = lights_doc(
        None,
        json!([
            { "extensions": { "TESELA_light": { "type": "POINT", "power": 10.0, "radius": -1.0 } } },
            { "extensions": { "TESELA_light": { "type": "AREA", "size": 1.0, "power": 10.0, "spread": 4.0 } } },
            { "extensions": { "TESELA_light": { "type": "AREA", "size": 1.0, "power": 10.0, "spread": -0.5 } } },
            { "extensions": { "TESELA_light": { "type": "SUN", "strength": 1.0, "angle": 7.0 } } },
            { "extensions": { "TESELA_light": { "type": "AREA", "size": 0.0, "power": 10.0 } } }
        ]),
        json!([]),
    );
    let s = load(&bytes);
    assert_eq!(s.lights.len(), 4, "the zero-size area light is skipped");
    assert!(matches!(
        s.lights[0],
        Light::Blender {
            shape: LightShape::Point { radius: 0.0, .. },
            ..
        }
    ));
    for i in [1, 2] {
        assert!(
            matches!(s.lights[i], Light::Blender { shape: LightShape::Area { spread, .. }, .. } if spread == PI),
            "{:?}",
            s.lights[i]
        );
    }
    assert!(matches!(
        s.lights[3],
        Light::Blender { shape: LightShape::Sun { angle, .. }, .. } if angle == PI
    ));
    let w = s.warnings.join("\n");
    for want in [
        "radius -1",
        "spread 4",
        "spread -0.5",
        "angle 7",
        "invalid size",
    ] {
        assert!(w.contains(want), "no warning about {want}: {w}");
    }
}

#[test]
fn tesela_world_render_and_emission() {
    let mut b = Bin::default();
    let p = b.vec3(&[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]);
    let bytes = b.finish(json!({
        "extensionsUsed": ["TESELA_world", "TESELA_render", "TESELA_emission", "KHR_materials_emissive_strength"],
        "extensions": {
            "TESELA_world": { "color": [0.1, 0.2, 0.3], "strength": 2.0 },
            "TESELA_render": { "width": 640, "height": 480, "spp": 64, "max_depth": 14, "seed": 7, "integrator": "path_mis" }
        },
        "nodes": [{ "mesh": 0 }],
        "materials": [
            { "emissiveFactor": [1, 0.5, 0.25], "doubleSided": true,
              "extensions": { "TESELA_emission": { "two_sided": false },
                              "KHR_materials_emissive_strength": { "emissiveStrength": 4 } } },
            { "emissiveFactor": [1, 1, 1],
              "extensions": { "TESELA_emission": { "two_sided": true } } },
            { "emissiveFactor": [1, 1, 1], "doubleSided": true }
        ],
        "meshes": [{ "primitives": [
            { "attributes": { "POSITION": p }, "material": 0 },
            { "attributes": { "POSITION": p }, "material": 1 },
            { "attributes": { "POSITION": p }, "material": 2 },
            { "attributes": { "POSITION": p }, "material": 0 }
        ] }]
    }));
    let s = load(&bytes);
    assert!(s.background.abs_diff_eq(Vec3::new(0.2, 0.4, 0.6), 1e-6));
    let r = &s.settings;
    assert_eq!(
        (r.width, r.height, r.spp, r.max_depth, r.seed),
        (Some(640), Some(480), Some(64), Some(14), Some(7))
    );
    assert_eq!(r.integrator.as_deref(), Some("path_mis"));
    assert_eq!(s.materials.len(), 3, "material 0 is shared, not duplicated");
    let m0 = &s.materials[s.meshes[0].material];
    assert!(m0.emission.abs_diff_eq(Vec3::new(4., 2., 1.), 1e-6));
    assert!(m0.double_sided && !m0.emission_two_sided);
    let m1 = &s.materials[s.meshes[1].material];
    assert!(!m1.double_sided && m1.emission_two_sided);
    let m2 = &s.materials[s.meshes[2].material];
    assert!(m2.double_sided && m2.emission_two_sided);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn texture_transform_is_read_and_samplers_shared() {
    let mut b = Bin::default();
    let p = b.vec3(&[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]);
    let uv = b.floats(&[0., 0., 1., 0., 0., 1.], "VEC2");
    let mut png = Vec::new();
    image::RgbaImage::from_pixel(2, 1, image::Rgba([10, 20, 30, 255]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let uri = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&png)
    );
    let tt = json!({ "index": 0, "extensions": { "KHR_texture_transform": { "scale": [2, 2] } } });
    let bytes = b.finish(json!({
        "extensionsUsed": ["KHR_texture_transform"],
        "extensionsRequired": ["KHR_texture_transform"],
        "nodes": [{ "mesh": 0 }],
        "images": [{ "uri": uri }],
        "samplers": [{ "magFilter": 9728, "wrapS": 33071, "wrapT": 33648 }],
        "textures": [{ "source": 0, "sampler": 0 }],
        "materials": [{ "pbrMetallicRoughness": { "baseColorTexture": tt.clone() }, "emissiveTexture": tt }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": p, "TEXCOORD_0": uv }, "material": 0 }] }]
    }));
    let s = load(&bytes);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let m = &s.materials[0];
    for t in [m.base_color_texture, m.emission_texture] {
        let tr = t.unwrap().transform.expect("the transform is kept");
        assert_eq!(tr.scale, glam::Vec2::splat(2.0));
    }
    assert_eq!(s.images.len(), 1);
    assert_eq!(s.textures.len(), 1, "one texture shared by two slots");
    let t = &s.textures[0];
    assert!(t.nearest);
    assert_eq!(
        (t.wrap_s, t.wrap_t),
        (
            crate::scene::Wrap::ClampToEdge,
            crate::scene::Wrap::MirroredRepeat
        )
    );
    assert_eq!(s.images[0].rgba8, vec![[10, 20, 30, 255]; 2]);
}

/// A data URI of a 2x1 image of one colour in `format`.
fn image_uri(rgba: [u8; 4], format: image::ImageFormat, mime: &str) -> String {
    let mut bytes = Vec::new();
    image::RgbaImage::from_pixel(2, 1, image::Rgba(rgba))
        .write_to(&mut std::io::Cursor::new(&mut bytes), format)
        .unwrap();
    format!(
        "data:{mime};base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bytes)
    )
}

#[test]
fn webp_textures_are_preferred_to_their_fallback_and_unlit_is_understood() {
    let mut b = Bin::default();
    let p = b.vec3(&[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]);
    let uv = b.floats(&[0., 0., 1., 0., 0., 1.], "VEC2");
    let png = image_uri([200, 0, 0, 255], image::ImageFormat::Png, "image/png");
    let webp = image_uri([0, 0, 200, 255], image::ImageFormat::WebP, "image/webp");
    let webp_only = image_uri([0, 150, 0, 255], image::ImageFormat::WebP, "image/webp");
    let bytes = b.finish(json!({
        "extensionsUsed": ["EXT_texture_webp", "KHR_materials_unlit"],
        "nodes": [{ "mesh": 0 }, { "mesh": 1 }],
        "images": [{ "uri": png }, { "uri": webp }, { "uri": webp_only }],
        "textures": [
            { "source": 0, "extensions": { "EXT_texture_webp": { "source": 1 } } },
            { "extensions": { "EXT_texture_webp": { "source": 2 } } }
        ],
        "materials": [
            { "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } },
            { "pbrMetallicRoughness": { "baseColorTexture": { "index": 1 } },
              "extensions": { "KHR_materials_unlit": {} } }
        ],
        "meshes": [
            { "primitives": [{ "attributes": { "POSITION": p, "TEXCOORD_0": uv }, "material": 0 }] },
            { "primitives": [{ "attributes": { "POSITION": p, "TEXCOORD_0": uv }, "material": 1 }] }
        ]
    }));
    let s = load(&bytes);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let texel = |m: usize| {
        let t = s.materials[m].base_color_texture.unwrap().texture;
        s.images[s.textures[t].image].rgba8[0]
    };
    assert_eq!(
        texel(0),
        [0, 0, 200, 255],
        "the WebP source, not the PNG fallback"
    );
    assert_eq!(texel(1), [0, 150, 0, 255], "a WebP-only texture");
    assert!(!s.materials[0].unlit && s.materials[1].unlit);
}

#[test]
fn scenes_without_nodes_and_empty_documents() {
    for doc in [
        json!({ "asset": { "version": "2.0" }, "scenes": [{}] }),
        json!({ "asset": { "version": "2.0" }, "scene": 0, "scenes": [{ "name": "x" }], "extensionsUsed": ["TESELA_world"],
                "extensions": { "TESELA_world": { "color": [0.5, 0.5, 0.5], "strength": 1.0 } } }),
        json!({ "asset": { "version": "2.0" }, "nodes": [{ "children": [1] }, {}] }),
    ] {
        let s = load(&serde_json::to_vec(&doc).unwrap());
        assert_eq!(s.triangle_count(), 0);
    }
}

#[test]
fn typed_errors_carry_a_json_path_and_unused_parts_are_not_checked() {
    let mut b = Bin::default();
    let p = b.vec3(&[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]);
    let doc = json!({
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": p }, "material": 0 }] }],
        "materials": [{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } }],
        "textures": [{ "extensions": { "KHR_texture_basisu": { "source": 0 } } }],
        "animations": [{ "channels": "garbage" }],
        "skins": [{ "joints": "garbage" }],
        "extras": { "anything": [1, 2, 3] }
    });
    let mut d: Value = serde_json::from_slice(&b.finish(doc)).unwrap();
    let s = load(&serde_json::to_vec(&d).unwrap());
    assert_eq!(s.triangle_count(), 1);
    assert!(s.materials[0].base_color_texture.is_none());
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert!(s.warnings[0].contains("texture 0 has no `source`"));

    d["accessors"][0].as_object_mut().unwrap().remove("count");
    let e = load_from_slice(&serde_json::to_vec(&d).unwrap(), None, "x.gltf").unwrap_err();
    assert_eq!(
        e.to_string(),
        "x.gltf: not a valid glTF 2.0 document: accessors[0]: missing field `count`"
    );
    d["accessors"][0]["count"] = json!(3);
    d["nodes"][0]["mesh"] = json!("zero");
    let e = load_from_slice(&serde_json::to_vec(&d).unwrap(), None, "x.gltf").unwrap_err();
    assert!(
        e.to_string().contains("nodes[0]: invalid type: string"),
        "{e}"
    );
}

/// A triangle skinned to two joints: vertex 0 on joint 0, vertex 1 on joint 1, vertex 2 half
/// and half; `joints` and `weights` replace the defaults to make bad files.
fn skinned_doc(joints: &[u8], weights: &[f32]) -> Vec<u8> {
    let mut b = Bin::default();
    let p = b.vec3(&[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]);
    let n = b.vec3(&[[0., 0., 1.]; 3]);
    let j = b.add(joints, 5121, joints.len() / 4, "VEC4", false);
    let w = b.floats(weights, "VEC4");
    // Joint 1 binds at x = 1: its inverse bind matrix moves it back to the origin.
    let mut ib = glam::Mat4::IDENTITY.to_cols_array().to_vec();
    ib.extend(glam::Mat4::from_translation(Vec3::new(-1., 0., 0.)).to_cols_array());
    let ib = b.floats(&ib, "MAT4");
    let h = std::f32::consts::FRAC_1_SQRT_2;
    b.finish(json!({
        "scenes": [{ "nodes": [0, 1] }],
        "nodes": [
            { "mesh": 0, "skin": 0, "translation": [100, 0, 0] },
            { "translation": [0, 0, 5], "children": [2] },
            { "translation": [1, 0, 0], "rotation": [0, 0, h, h] }
        ],
        "skins": [{ "joints": [1, 2], "inverseBindMatrices": ib }],
        "meshes": [{ "primitives": [{ "attributes": {
            "POSITION": p, "NORMAL": n, "JOINTS_0": j, "WEIGHTS_0": w } }] }]
    }))
}

#[test]
fn skinned_meshes_take_the_pose_of_their_joints() {
    let joints = [0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0];
    let weights = [1., 0., 0., 0., 1., 0., 0., 0., 0.5, 0.5, 0., 0.];
    let s = load(&skinned_doc(&joints, &weights));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let p = &s.meshes[0].positions;
    // Joint 0 moves by (0, 0, 5); joint 1 also turns 90 degrees about Z at x = 1; the mesh
    // node's own translation (100, 0, 0) is not applied.
    let expect = [
        Vec3::new(0., 0., 5.),
        Vec3::new(1., 0., 5.),
        // Half of (0, 1, 5) by joint 0, half of (0, -1, 5), the point turned about (1, 0, 5).
        (Vec3::new(0., 1., 5.) + Vec3::new(0., -1., 5.)) * 0.5,
    ];
    for (got, want) in p.iter().zip(expect) {
        assert!(got.abs_diff_eq(want, 1e-5), "{got} != {want}");
    }
    // Bad skins are clear errors naming the accessor.
    let bad_joint = [0, 0, 0, 0, 7, 0, 0, 0, 0, 1, 0, 0];
    let e = load_from_slice(&skinned_doc(&bad_joint, &weights), None, "t.gltf").unwrap_err();
    assert!(e.to_string().contains("names joint 7"), "{e}");
    let nan = [1., 0., 0., 0., f32::NAN, 0., 0., 0., 0.5, 0.5, 0., 0.];
    let e = load_from_slice(&skinned_doc(&joints, &nan), None, "t.gltf").unwrap_err();
    assert!(e.to_string().contains("WEIGHTS_0"), "{e}");
}
