//! Loader tests of what shading reads beyond positions and normals: TEXCOORD_n, COLOR_n,
//! TANGENT and MikkTSpace, object data, and the material features of foreign glTF files
//! (normal maps, texture transforms, texture coordinate sets, vertex colours, alpha modes,
//! clearcoat, sheen, anisotropy, volume), checked through the compiled preset program where
//! the meaning is in the shading.

use base64::Engine;
use glam::{Mat4, Quat, Vec2, Vec3, Vec4};
use serde_json::{Value, json};

use super::load_from_slice;
use super::tests_load::{Bin, load};
use crate::scene::{AlphaMode, Scene};
use crate::shading::{ClosureKind, ClosureSet, Scratch, ShadeEnv, ShaderGlobals};

fn png_uri(w: u32, h: u32, px: &[[u8; 4]]) -> String {
    let img = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(px[(y * w + x) as usize]));
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&png)
    )
}

/// A unit quad in the XY plane facing +Z with +Z normals and glTF UVs (v down: the image's top
/// row at +Y). Returns (bin, attributes, indices accessor).
fn quad(b: &mut Bin) -> (Value, usize) {
    let p = b.vec3(&[[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]]);
    let n = b.vec3(&[[0., 0., 1.]; 4]);
    let uv = b.floats(&[0., 1., 1., 1., 1., 0., 0., 0.], "VEC2");
    let i = b.indices(&[0, 1, 2, 0, 2, 3]);
    (json!({ "POSITION": p, "NORMAL": n, "TEXCOORD_0": uv }), i)
}

/// A document with one quad primitive (extra attributes merged in), `material` as material 0
/// and the images (PNG data URIs) as textures 0, 1, ...
fn quad_doc(extra: Value, material: Value, images: &[String], node: Value) -> Vec<u8> {
    let mut b = Bin::default();
    let (mut attrs, i) = quad(&mut b);
    doc_with(&mut b, &mut attrs, extra);
    let textures: Vec<Value> = (0..images.len()).map(|k| json!({ "source": k })).collect();
    let imgs: Vec<Value> = images.iter().map(|u| json!({ "uri": u })).collect();
    let mut node = node;
    node["mesh"] = json!(0);
    b.finish(json!({
        "nodes": [node],
        "images": imgs,
        "textures": textures,
        "materials": [material],
        "meshes": [{ "primitives": [{ "attributes": attrs, "indices": i, "material": 0 }] }]
    }))
}

/// Adds accessors described by `extra` (`{"COLOR_0": ["VEC4", [..]]}` for floats) to `attrs`.
fn doc_with(b: &mut Bin, attrs: &mut Value, extra: Value) {
    for (k, v) in extra.as_object().unwrap() {
        let ty = v[0].as_str().unwrap();
        let data: Vec<f32> = v[1]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap() as f32)
            .collect();
        attrs[k] = json!(b.floats(&data, ty));
    }
}

/// Runs the material program of mesh `mi` at triangle 0, barycentrics (1/3, 1/3).
fn shade(s: &Scene, mi: usize) -> ClosureSet {
    let m = &s.meshes[mi];
    let (b1, b2) = (1.0 / 3.0, 1.0 / 3.0);
    let c = crate::shading::material_program(&s.materials[m.material], &s.textures);
    let p = m.interpolate(&m.positions, 0, b1, b2).unwrap();
    let n = m.shading_normal(0, b1, b2).unwrap_or(Vec3::Z);
    let uv = m.interpolate(&m.uvs, 0, b1, b2).unwrap_or_default();
    let mut g = ShaderGlobals::at(p, n, uv);
    g.mesh = Some(m);
    g.tri = 0;
    g.b1 = b1;
    g.b2 = b2;
    let env = ShadeEnv {
        images: &s.images,
        textures: &s.textures,
        camera_to_world: Mat4::IDENTITY,
        window: &crate::camera::NO_WINDOW,
        tracer: None,
    };
    let mut scratch = Scratch::default();
    c.program.eval(&g, &env, &mut scratch).clone()
}

fn principled(set: &ClosureSet) -> (crate::shading::Principled, Vec3, Vec3) {
    set.closures()
        .iter()
        .find_map(|c| match c.kind {
            ClosureKind::Principled(p) => Some((p, c.normal, c.tangent)),
            _ => None,
        })
        .expect("a Principled closure")
}

/// A normal-map texel (8 bits) for the unit tangent-space normal `n`.
fn encode(n: Vec3) -> [u8; 4] {
    let c = (n * 0.5 + Vec3::splat(0.5)) * 255.0;
    [c.x.round() as u8, c.y.round() as u8, c.z.round() as u8, 255]
}

/// The normal `n` as an 8-bit texel decodes to.
fn decoded(n: Vec3) -> Vec3 {
    let [r, g, b, _] = encode(n);
    (Vec3::new(r as f32, g as f32, b as f32) / 255.0 * 2.0 - Vec3::ONE).normalize()
}

fn normal_mapped(texel: Vec3, extra: Value, scale: f32, node: Value) -> Scene {
    let mat = json!({ "normalTexture": { "index": 0, "scale": scale },
                      "pbrMetallicRoughness": { "metallicFactor": 0 } });
    load(&quad_doc(
        extra,
        mat,
        &[png_uri(1, 1, &[encode(texel)])],
        node,
    ))
}

#[test]
fn normal_map_green_is_up_in_the_image_and_red_is_right() {
    let (s30, c30) = 30f32.to_radians().sin_cos();
    // Green: the tilt goes towards the image's top row, which the UVs put at +Y.
    let up = Vec3::new(0.0, s30, c30);
    let s = normal_mapped(up, json!({}), 1.0, json!({}));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.meshes[0].attrs.tangents.len(), 4, "MikkTSpace tangents");
    let (_, n, _) = principled(&shade(&s, 0));
    assert!(n.abs_diff_eq(decoded(up), 1e-4), "{n} (green inverted?)");
    // Red: towards +u, the image's right, at +X.
    let right = Vec3::new(s30, 0.0, c30);
    let s = normal_mapped(right, json!({}), 1.0, json!({}));
    let (_, n, _) = principled(&shade(&s, 0));
    assert!(n.abs_diff_eq(decoded(right), 1e-4), "{n}");
}

#[test]
fn normal_map_scale_multiplies_x_and_y() {
    let t = Vec3::new(0.3, 0.2, 0.9).normalize();
    let s = normal_mapped(t, json!({}), 2.0, json!({}));
    let (_, n, _) = principled(&shade(&s, 0));
    let d = decoded(t);
    let want = Vec3::new(2.0 * d.x, 2.0 * d.y, d.z).normalize();
    assert!(n.abs_diff_eq(want, 1e-3), "{n} vs {want}");
}

#[test]
fn file_tangents_and_their_sign_are_used() {
    let (s30, c30) = 30f32.to_radians().sin_cos();
    let up = Vec3::new(0.0, s30, c30);
    // TANGENT along +X with w = -1: the bitangent is -Y, so "up" in the map points to -Y.
    let t = json!({ "TANGENT": ["VEC4", [1, 0, 0, -1, 1, 0, 0, -1, 1, 0, 0, -1, 1, 0, 0, -1]] });
    let s = normal_mapped(up, t, 1.0, json!({}));
    assert_eq!(
        s.meshes[0].attrs.tangents[0],
        Vec4::new(1.0, 0.0, 0.0, -1.0)
    );
    let (_, n, _) = principled(&shade(&s, 0));
    let d = decoded(up);
    assert!(n.abs_diff_eq(Vec3::new(d.x, -d.y, d.z), 1e-4), "{n}");
    // TANGENT along +Y (w = 1, bitangent n × t = -X): red now tilts towards +Y.
    let right = Vec3::new(s30, 0.0, c30);
    let t = json!({ "TANGENT": ["VEC4", [0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1]] });
    let s = normal_mapped(right, t, 1.0, json!({}));
    let (_, n, _) = principled(&shade(&s, 0));
    let d = decoded(right);
    assert!(n.abs_diff_eq(Vec3::new(-d.y, d.x, d.z), 1e-4), "{n}");
}

#[test]
fn mirrored_and_rotated_nodes_keep_the_normal_map_on_the_image() {
    let (s30, c30) = 30f32.to_radians().sin_cos();
    let right = Vec3::new(s30, 0.0, c30);
    let up = Vec3::new(0.0, s30, c30);
    // Mirrored in X: the image's right now lies at -X, its top still at +Y.
    let mirror = |d: Vec3| Vec3::new(-d.x, d.y, d.z);
    for (texel, want) in [(right, mirror(decoded(right))), (up, mirror(decoded(up)))] {
        let s = normal_mapped(texel, json!({}), 1.0, json!({ "scale": [-1, 1, 1] }));
        let (_, n, _) = principled(&shade(&s, 0));
        assert!(n.abs_diff_eq(want, 1e-4), "{texel}: {n} vs {want}");
        // The same with the file's tangents.
        let t = json!({ "TANGENT": ["VEC4", [1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1]] });
        let s = normal_mapped(texel, t, 1.0, json!({ "scale": [-1, 1, 1] }));
        assert_eq!(
            s.meshes[0].attrs.tangents[0],
            Vec4::new(-1.0, 0.0, 0.0, -1.0)
        );
        let (_, n, _) = principled(&shade(&s, 0));
        assert!(n.abs_diff_eq(want, 1e-4), "TANGENT {texel}: {n} vs {want}");
    }
    // Rotated 90° about Z: the image's top is at -X.
    let q = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let s = normal_mapped(up, json!({}), 1.0, json!({ "rotation": q.to_array() }));
    let (_, n, _) = principled(&shade(&s, 0));
    let d = decoded(up);
    assert!(n.abs_diff_eq(Vec3::new(-d.y, d.x, d.z), 1e-4), "{n}");
}

#[test]
fn tangents_are_stored_only_when_the_material_needs_them() {
    let t = json!({ "TANGENT": ["VEC4", [1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1]] });
    let plain = json!({ "pbrMetallicRoughness": { "metallicFactor": 0 } });
    let s = load(&quad_doc(t.clone(), plain.clone(), &[], json!({})));
    assert!(
        s.meshes[0].attrs.tangents.is_empty(),
        "no normal map: not kept"
    );
    let s = load(&quad_doc(json!({}), plain, &[], json!({})));
    assert!(s.meshes[0].attrs.tangents.is_empty(), "nor generated");
    // A node graph may read them: kept.
    let graph = json!({ "extensions": { "TESELA_material_graph": { "version": 1, "nodes": [] } } });
    let s = load(&quad_doc(t, graph, &[], json!({})));
    assert_eq!(s.meshes[0].attrs.tangents.len(), 4);
}

#[test]
fn bad_tangents_are_errors_naming_the_accessor_or_warned() {
    let mat = json!({ "normalTexture": { "index": 0 } });
    let img = [png_uri(1, 1, &[[128, 128, 255, 255]])];
    let err = |extra: Value| {
        let bytes = quad_doc(extra, mat.clone(), &img, json!({}));
        load_from_slice(&bytes, None, "t.gltf")
            .unwrap_err()
            .to_string()
    };
    let e = err(json!({ "TANGENT": ["VEC3", [1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0]] }));
    assert!(
        e.contains("TANGENT of mesh 0 primitive 0") && e.contains("VEC3 where VEC4"),
        "{e}"
    );
    let e = err(json!({ "TANGENT": ["VEC4", [1, 0, 0, 1, 1, 0, 0, 1]] }));
    assert!(
        e.contains("TANGENT") && e.contains("count 2 differs"),
        "{e}"
    );
    // Non-finite tangents: a warning, those vertices fall back.
    let mut b = Bin::default();
    let (mut attrs, i) = quad(&mut b);
    let mut t: Vec<u8> = [1f32, 0., 0., 1.]
        .repeat(4)
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    t[0..4].copy_from_slice(&f32::NAN.to_le_bytes());
    attrs["TANGENT"] = json!(b.add(&t, 5126, 4, "VEC4", false));
    let bytes = b.finish(json!({
        "nodes": [{ "mesh": 0 }], "images": [{ "uri": img[0] }], "textures": [{ "source": 0 }],
        "materials": [mat],
        "meshes": [{ "primitives": [{ "attributes": attrs, "indices": i, "material": 0 }] }]
    }));
    let s = load(&bytes);
    assert!(
        s.warnings.iter().any(|w| w.contains("not finite")),
        "{:?}",
        s.warnings
    );
    assert_eq!(s.meshes[0].attrs.tangents[0].truncate(), Vec3::ZERO);
}

#[test]
fn uv_sets_colours_and_their_names() {
    let mut b = Bin::default();
    let (mut attrs, i) = quad(&mut b);
    attrs["TEXCOORD_1"] = json!(b.floats(&[0.5; 8], "VEC2"));
    attrs["TEXCOORD_2"] = json!(b.floats(&[0.25; 8], "VEC2"));
    // COLOR_0: normalized UNSIGNED_BYTE VEC3; COLOR_1: normalized UNSIGNED_SHORT VEC4.
    attrs["COLOR_0"] = json!(b.add(
        &[255, 128, 0, 0, 0, 255, 51, 102, 153, 255, 255, 255],
        5121,
        4,
        "VEC3",
        true
    ));
    let c1: Vec<u8> = [65535u16, 0, 32768, 65535]
        .repeat(4)
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    attrs["COLOR_1"] = json!(b.add(&c1, 5123, 4, "VEC4", true));
    let tex = json!({ "index": 0, "texCoord": 2 });
    let graph = json!({ "extensions": { "TESELA_material_graph": { "version": 1, "nodes": [] } } });
    let s = load(&b.finish(json!({
        "nodes": [{ "mesh": 0 }],
        "images": [{ "uri": png_uri(1, 1, &[[255; 4]]) }],
        "textures": [{ "source": 0 }],
        "materials": [{ "pbrMetallicRoughness": { "baseColorTexture": tex } }, graph.clone()],
        "meshes": [{ "primitives": [
            { "attributes": attrs.clone(), "indices": i, "material": 0 },
            { "attributes": attrs, "indices": i, "material": 1 }
        ] }]
    })));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    // The preset reads TEXCOORD_2 and COLOR_0 only.
    let a = &s.meshes[0].attrs;
    assert_eq!(a.uv_names, ["UVMap", "UVMap.001", "UVMap.002"]);
    assert_eq!(a.extra_uvs.len(), 2);
    assert!(a.extra_uvs[0].is_empty(), "TEXCOORD_1 is not read");
    assert_eq!(a.extra_uvs[1], vec![Vec2::splat(0.25); 4]);
    assert_eq!(a.colors.len(), 1);
    assert_eq!(a.colors[0].0, "Col");
    let c = &a.colors[0].1;
    assert!(
        c[0].abs_diff_eq(Vec4::new(1.0, 128.0 / 255.0, 0.0, 1.0), 1e-6),
        "{}",
        c[0]
    );
    assert!(
        c[2].abs_diff_eq(Vec4::new(0.2, 0.4, 0.6, 1.0), 1e-6),
        "{}",
        c[2]
    );
    assert!(s.materials[s.meshes[0].material].vertex_color);
    assert_eq!(s.meshes[0].uv(2, 0, 0.2, 0.2), Vec2::splat(0.25));
    // A set the mesh lacks reads set 0.
    assert_eq!(s.meshes[0].uv(1, 0, 0.0, 0.0), s.meshes[0].uvs[0]);
    // The graph material reads everything.
    let a = &s.meshes[1].attrs;
    assert_eq!(a.extra_uvs.len(), 2);
    assert_eq!(a.extra_uvs[0], vec![Vec2::splat(0.5); 4]);
    assert_eq!(a.colors.len(), 2);
    assert_eq!(a.colors[1].0, "Col.001");
    assert!(a.colors[1].1[0].abs_diff_eq(Vec4::new(1.0, 0.0, 32768.0 / 65535.0, 1.0), 1e-6));
    assert!(
        !s.materials[s.meshes[1].material].vertex_color,
        "graphs read colours by name"
    );

    // Names from the add-on's extras.
    let mut b = Bin::default();
    let (mut attrs, i) = quad(&mut b);
    attrs["COLOR_0"] = json!(b.floats(&[0.5; 16], "VEC4"));
    let s = load(&b.finish(json!({
        "nodes": [{ "mesh": 0 }],
        "materials": [graph],
        "meshes": [{ "primitives": [{ "attributes": attrs, "indices": i, "material": 0,
            "extras": { "tesela_uv_names": ["Main"], "tesela_color_names": ["Paint"] } }] }]
    })));
    let a = &s.meshes[0].attrs;
    assert_eq!(a.uv_names, ["Main"]);
    assert_eq!(a.colors[0].0, "Paint");
    assert_eq!(a.colors[0].1[0], Vec4::splat(0.5));
    assert_eq!(s.meshes[0].uv_set("Main"), Some(0));
}

#[test]
fn bad_colours_are_errors_naming_the_accessor_or_warned() {
    let mat = json!({});
    let err = |ty: &str, comp: u32, count: usize, data: &[u8], normalized: bool| {
        let mut b = Bin::default();
        let (mut attrs, i) = quad(&mut b);
        attrs["COLOR_0"] = json!(b.add(data, comp, count, ty, normalized));
        let bytes = b.finish(json!({
            "nodes": [{ "mesh": 0 }], "materials": [mat.clone()],
            "meshes": [{ "primitives": [{ "attributes": attrs, "indices": i, "material": 0 }] }]
        }));
        load_from_slice(&bytes, None, "t.gltf")
    };
    let e = err("VEC4", 5126, 3, &[0; 48], false)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("COLOR_0 of mesh 0 primitive 0") && e.contains("count 3 differs"),
        "{e}"
    );
    let e = err("SCALAR", 5126, 4, &[0; 16], false)
        .unwrap_err()
        .to_string();
    assert!(e.contains("COLOR_0") && e.contains("VEC3 or VEC4"), "{e}");
    let e = err("VEC4", 5120, 4, &[0; 16], true)
        .unwrap_err()
        .to_string();
    assert!(e.contains("COLOR_0") && e.contains("UNSIGNED_BYTE"), "{e}");
    // Unnormalized bytes: read as normalized, with a warning.
    let s = err("VEC4", 5121, 4, &[255; 16], false).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("normalized")),
        "{:?}",
        s.warnings
    );
    assert_eq!(s.meshes[0].attrs.colors[0].1[0], Vec4::ONE);
    // NaN components read as 0.
    let mut d: Vec<u8> = [0.5f32; 16].iter().flat_map(|x| x.to_le_bytes()).collect();
    d[0..4].copy_from_slice(&f32::NAN.to_le_bytes());
    let s = err("VEC4", 5126, 4, &d, false).unwrap();
    assert_eq!(
        s.meshes[0].attrs.colors[0].1[0],
        Vec4::new(0.0, 0.5, 0.5, 0.5)
    );
    assert!(
        s.warnings.iter().any(|w| w.contains("not finite")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn vertex_colours_multiply_base_colour_and_alpha() {
    // Base colour factor (0.5, 1, 1, 0.8) × COLOR_0 (0.2, 0.4, 0.6, 0.5): BLEND alpha 0.4.
    let col = json!({ "COLOR_0": ["VEC4", [0.2, 0.4, 0.6, 0.5, 0.2, 0.4, 0.6, 0.5, 0.2, 0.4, 0.6, 0.5, 0.2, 0.4, 0.6, 0.5]] });
    let mat = json!({ "alphaMode": "BLEND", "pbrMetallicRoughness": { "baseColorFactor": [0.5, 1, 1, 0.8], "metallicFactor": 0 } });
    let s = load(&quad_doc(col.clone(), mat.clone(), &[], json!({})));
    let set = shade(&s, 0);
    let (p, _, _) = principled(&set);
    assert!(
        p.base_color.abs_diff_eq(Vec3::new(0.1, 0.4, 0.6), 1e-6),
        "{}",
        p.base_color
    );
    let transparent: f32 = set
        .closures()
        .iter()
        .filter(|c| matches!(c.kind, ClosureKind::Transparent { .. }))
        .map(|c| c.weight.x)
        .sum();
    assert!((transparent - 0.6).abs() < 1e-6, "{transparent}");
    // Without COLOR_0 the same material is constant.
    let s = load(&quad_doc(json!({}), mat, &[], json!({})));
    let (p, _, _) = principled(&shade(&s, 0));
    assert_eq!(p.base_color, Vec3::new(0.5, 1.0, 1.0));
    // The default material is multiplied too.
    let mut b = Bin::default();
    let (mut attrs, i) = quad(&mut b);
    doc_with(&mut b, &mut attrs, col);
    let s = load(&b.finish(json!({
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{ "attributes": attrs, "indices": i }] }]
    })));
    let (p, _, _) = principled(&shade(&s, 0));
    assert!(p.base_color.abs_diff_eq(Vec3::new(0.2, 0.4, 0.6), 1e-6));
}

#[test]
fn alpha_mask_is_exactly_zero_or_one_and_opaque_ignores_alpha() {
    // A 2x1 texture: alpha 100 (0.39) on the left, 200 (0.78) on the right; the quad's UVs
    // span it; the probe point of triangle 0 (u = 2/3) reads alpha ≈ 0.72.
    let img = [png_uri(2, 1, &[[255, 255, 255, 100], [255, 255, 255, 200]])];
    let alpha_of = |mode: Value, cutoff: Value| {
        let mut mat = json!({ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 }, "metallicFactor": 0 } });
        if !mode.is_null() {
            mat["alphaMode"] = mode;
        }
        if !cutoff.is_null() {
            mat["alphaCutoff"] = cutoff;
        }
        let s = load(&quad_doc(json!({}), mat, &img, json!({})));
        let set = shade(&s, 0);
        let t: f32 = set
            .closures()
            .iter()
            .filter(|c| matches!(c.kind, ClosureKind::Transparent { .. }))
            .map(|c| c.weight.x)
            .sum();
        (s.materials[0].alpha_mode, 1.0 - t)
    };
    let (u, _) = {
        let s = load(&quad_doc(json!({}), json!({}), &[], json!({})));
        let m = &s.meshes[0];
        let uv = m.interpolate(&m.uvs, 0, 1.0 / 3.0, 1.0 / 3.0).unwrap();
        (uv.x, uv.y)
    };
    assert!(u > 0.5, "the probe lies on the right texel ({u})");
    assert_eq!(alpha_of(Value::Null, Value::Null), (AlphaMode::Opaque, 1.0));
    // Bilinear between 100 and 200 at u; MASK at 0.5: opaque; at 0.9: transparent.
    assert_eq!(
        alpha_of(json!("MASK"), Value::Null),
        (AlphaMode::Mask { cutoff: 0.5 }, 1.0)
    );
    assert_eq!(
        alpha_of(json!("MASK"), json!(0.9)),
        (AlphaMode::Mask { cutoff: 0.9 }, 0.0)
    );
    let (mode, a) = alpha_of(json!("BLEND"), Value::Null);
    assert_eq!(mode, AlphaMode::Blend);
    assert!(a > 100.0 / 255.0 && a < 200.0 / 255.0, "{a}");
    // A bad cutoff is warned about.
    let mat = json!({ "alphaMode": "MASK", "alphaCutoff": -1 });
    let s = load(&quad_doc(json!({}), mat, &[], json!({})));
    assert_eq!(s.materials[0].alpha_mode, AlphaMode::Mask { cutoff: 0.5 });
    assert!(
        s.warnings.iter().any(|w| w.contains("alphaCutoff")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn texture_transform_and_texcoord_select_the_texel() {
    // A 2x2 texture: red, green / blue, white (top row first).
    let img = [png_uri(
        2,
        2,
        &[
            [255, 0, 0, 255],
            [0, 255, 0, 255],
            [0, 0, 255, 255],
            [255, 255, 255, 255],
        ],
    )];
    let color_at = |tex: Value, extra: Value| -> (Vec3, Scene) {
        let mat =
            json!({ "pbrMetallicRoughness": { "baseColorTexture": tex, "metallicFactor": 0 } });
        let s = load(&quad_doc(extra, mat, &img, json!({})));
        let (p, _, _) = principled(&shade(&s, 0));
        (p.base_color, s)
    };
    let near = |c: Vec3, want: Vec3| c.abs_diff_eq(want, 1e-3);
    // A constant UV set 1 at (0.25, 0.25): the top-left texel, red.
    let uv1 = json!({ "TEXCOORD_1": ["VEC2", [0.25, 0.25, 0.25, 0.25, 0.25, 0.25, 0.25, 0.25]] });
    let sampler_free = json!({ "index": 0, "texCoord": 1 });
    let (c, s) = color_at(sampler_free, uv1.clone());
    assert!(near(c, Vec3::X), "{c}");
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    // Offset by (0.5, 0): green; by (0, 0.5): blue; (0.5, 0.5): white.
    for (off, want) in [
        ([0.5, 0.0], Vec3::Y),
        ([0.0, 0.5], Vec3::Z),
        ([0.5, 0.5], Vec3::ONE),
    ] {
        let tex = json!({ "index": 0, "texCoord": 1,
                          "extensions": { "KHR_texture_transform": { "offset": off } } });
        let (c, _) = color_at(tex, uv1.clone());
        assert!(near(c, want), "{off:?}: {c}");
    }
    // The extension's texCoord overrides: set 1 instead of set 0.
    let tex = json!({ "index": 0, "extensions": { "KHR_texture_transform": { "texCoord": 1, "offset": [0.5, 0.0] } } });
    let (c, s) = color_at(tex, uv1.clone());
    assert!(near(c, Vec3::Y), "{c}");
    assert_eq!(s.materials[0].base_color_texture.unwrap().texcoord, 1);
    // Rotation by 90° about the origin: (0.25, 0.25) -> (0.25, -0.25) -> wrapped (0.25, 0.75):
    // blue. Scale (3, 1): (0.75, 0.25): green.
    let tex = json!({ "index": 0, "texCoord": 1,
                      "extensions": { "KHR_texture_transform": { "rotation": std::f32::consts::FRAC_PI_2 } } });
    let (c, _) = color_at(tex, uv1.clone());
    assert!(near(c, Vec3::Z), "rotation: {c}");
    let tex = json!({ "index": 0, "texCoord": 1,
                      "extensions": { "KHR_texture_transform": { "scale": [3, 1] } } });
    let (c, _) = color_at(tex, uv1.clone());
    assert!(near(c, Vec3::Y), "scale: {c}");
    // texCoord 7, which the mesh lacks: warned, set 0 used.
    let (_, s) = color_at(json!({ "index": 0, "texCoord": 7 }), json!({}));
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("TEXCOORD_7") && w.contains("TEXCOORD_0 is used")),
        "{:?}",
        s.warnings
    );
    // Overflowing or malformed transforms are warned about and ignored.
    for bad in [
        json!({ "scale": [1e39, 1] }),
        json!({ "offset": "x" }),
        json!({ "rotation": [1] }),
    ] {
        let tex = json!({ "index": 0, "extensions": { "KHR_texture_transform": bad } });
        let (_, s) = color_at(tex, json!({}));
        assert!(
            s.materials[0]
                .base_color_texture
                .unwrap()
                .transform
                .is_none()
        );
        assert!(
            s.warnings
                .iter()
                .any(|w| w.contains("KHR_texture_transform")),
            "{bad}: {:?}",
            s.warnings
        );
    }
    // A malformed index is an error naming the material and slot.
    let mat = json!({ "extensions": { "KHR_materials_clearcoat": { "clearcoatTexture": { "index": -1 } } } });
    let e = load_from_slice(&quad_doc(json!({}), mat, &img, json!({})), None, "t.gltf")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("material 0") && e.contains("clearcoatTexture"),
        "{e}"
    );
}

#[test]
fn object_space_texture_space_and_object_info() {
    let node = json!({ "translation": [1, 2, 3], "scale": [2, 2, 2] });
    let s = load(&quad_doc(json!({}), json!({}), &[], node));
    let a = &s.meshes[0].attrs;
    let p = s.meshes[0].positions[2];
    assert!(
        a.to_object
            .transform_point3(p)
            .abs_diff_eq(Vec3::new(1.0, 1.0, 0.0), 1e-6)
    );
    // The quad's local bounds (0,0,0)..(1,1,0): centre (0.5, 0.5, 0), half extents 0.5 (z: 1).
    assert_eq!(
        a.texspace,
        Some((Vec3::new(0.5, 0.5, 0.0), Vec3::new(0.5, 0.5, 1.0)))
    );
    assert_eq!(a.object.location, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(a.object.random, 0.0);
    assert_eq!(a.object.color, Vec4::ONE);
    // The add-on's extras: Blender world coordinates for the location.
    let node = json!({ "extras": {
        "tesela_object": { "random": 0.25, "pass_index": 3, "color": [1, 0, 0, 0.5], "location": [1, 2, 3] },
        "tesela_texspace": { "location": [0, 0, 1], "size": [2, 2, 2] } } });
    let s = load(&quad_doc(json!({}), json!({}), &[], node));
    let o = &s.meshes[0].attrs.object;
    assert_eq!((o.random, o.pass_index), (0.25, 3.0));
    assert_eq!(o.color, Vec4::new(1.0, 0.0, 0.0, 0.5));
    assert_eq!(
        o.location,
        Vec3::new(1.0, 3.0, -2.0),
        "Blender (x, y, z) = glTF (x, z, -y)"
    );
    assert_eq!(
        s.meshes[0].attrs.texspace,
        Some((Vec3::new(0.0, 0.0, 1.0), Vec3::splat(2.0)))
    );
    // Malformed extras: warned, defaults used.
    let node = json!({ "extras": { "tesela_object": { "random": "x", "location": [1] },
                                   "tesela_texspace": { "location": 1 } } });
    let s = load(&quad_doc(json!({}), json!({}), &[], node));
    assert_eq!(s.meshes[0].attrs.object.random, 0.0);
    assert_eq!(s.warnings.len(), 2, "{:?}", s.warnings);
}

#[test]
fn object_ray_visibility_from_the_extras() {
    use crate::scene::ObjectInfo;
    use crate::shading::globals::ray;
    let s = load(&quad_doc(json!({}), json!({}), &[], json!({})));
    assert_eq!(
        s.meshes[0].attrs.object.visibility,
        ObjectInfo::VISIBLE_TO_ALL
    );
    let node = json!({ "extras": { "tesela_object": {
        "visibility": { "camera": false, "shadow": false, "glossy": true } } } });
    let s = load(&quad_doc(json!({}), json!({}), &[], node));
    assert_eq!(
        s.meshes[0].attrs.object.visibility,
        ray::DIFFUSE | ray::GLOSSY | ray::TRANSMISSION
    );
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    for bad in [json!({ "camera": 0 }), json!([false]), json!("none")] {
        let node = json!({ "extras": { "tesela_object": { "visibility": bad } } });
        let s = load(&quad_doc(json!({}), json!({}), &[], node));
        assert_eq!(
            s.meshes[0].attrs.object.visibility,
            ObjectInfo::VISIBLE_TO_ALL
        );
        assert!(
            s.warnings.iter().any(|w| w.contains("invalid visibility")),
            "{:?}",
            s.warnings
        );
    }
}

#[test]
fn object_holdout_from_the_extras() {
    let s = load(&quad_doc(json!({}), json!({}), &[], json!({})));
    assert!(!s.meshes[0].attrs.object.holdout);
    let node = json!({ "extras": { "tesela_object": { "holdout": true } } });
    let s = load(&quad_doc(json!({}), json!({}), &[], node));
    assert!(s.meshes[0].attrs.object.holdout);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let node = json!({ "extras": { "tesela_object": { "holdout": "yes" } } });
    let s = load(&quad_doc(json!({}), json!({}), &[], node));
    assert!(!s.meshes[0].attrs.object.holdout);
    assert!(
        s.warnings.iter().any(|w| w.contains("invalid holdout")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn blender_auto_texture_space_rules() {
    use super::mesh::auto_texspace;
    let (l, s) = auto_texspace(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 0.0, 2.000001));
    assert_eq!(l, Vec3::new(1.0, 0.0, 2.0000005));
    assert_eq!(s.x, 2.0);
    assert_eq!(s.y, 1.0, "a flat extent becomes 1");
    assert_eq!(s.z, 1e-5, "a tiny one becomes 1e-5");
}

#[test]
fn clearcoat_sheen_anisotropy_and_volume_reach_the_principled_inputs() {
    let img = [png_uri(1, 1, &[[255, 128, 64, 255]])];
    let mat = json!({
        "pbrMetallicRoughness": { "metallicFactor": 0 },
        "extensions": {
            "KHR_materials_clearcoat": { "clearcoatFactor": 0.8, "clearcoatRoughnessFactor": 0.4,
                "clearcoatTexture": { "index": 0 }, "clearcoatNormalTexture": { "index": 0, "scale": 0.5 } },
            "KHR_materials_sheen": { "sheenColorFactor": [1, 0.5, 0.25], "sheenRoughnessFactor": 0.3 },
            "KHR_materials_anisotropy": { "anisotropyStrength": 0.6, "anisotropyRotation": std::f32::consts::FRAC_PI_2 },
            "KHR_materials_transmission": { "transmissionFactor": 0.5, "transmissionTexture": { "index": 0 } },
            "KHR_materials_volume": { "thicknessFactor": 0, "attenuationDistance": 2, "attenuationColor": [1, 0.5, 0.5] }
        }
    });
    let bytes = quad_doc(json!({}), mat, &img, json!({}));
    let s = load(&bytes);
    let m = &s.materials[0];
    let cc = m.clearcoat.unwrap();
    assert_eq!((cc.factor, cc.roughness, cc.normal_scale), (0.8, 0.4, 0.5));
    assert!(cc.texture.is_some() && cc.normal_texture.is_some());
    assert_eq!(m.sheen.unwrap().color, Vec3::new(1.0, 0.5, 0.25));
    assert_eq!(m.anisotropy.unwrap().strength, 0.6);
    let v = m.volume.unwrap();
    assert_eq!((v.thickness, v.attenuation_distance), (0.0, 2.0));
    for needle in ["thin-walled", "attenuation"] {
        assert!(
            s.warnings
                .iter()
                .any(|w| w.contains("KHR_materials_volume") && w.contains(needle)),
            "{needle}: {:?}",
            s.warnings
        );
    }
    assert_eq!(
        s.meshes[0].attrs.tangents.len(),
        4,
        "tangents for the coat normal map"
    );
    // A sheen over a coat is a closure of its own, as Cycles sets it up: one Principled
    // closure carries the coat and the rest, another the sheen.
    let set = shade(&s, 0);
    let layers: Vec<_> = set
        .closures()
        .iter()
        .filter_map(|c| match c.kind {
            ClosureKind::Principled(p) => Some((p, c.tangent)),
            _ => None,
        })
        .collect();
    let (p, tangent) = *layers
        .iter()
        .find(|(p, _)| p.coat_weight > 0.0)
        .expect("a coated closure");
    // Coat weight = 0.8 × R (1.0); roughness 0.4; IOR 1.5.
    assert!((p.coat_weight - 0.8).abs() < 1e-6, "{}", p.coat_weight);
    assert!((p.coat_roughness - 0.4).abs() < 1e-6);
    assert_eq!(p.coat_ior, 1.5);
    assert!(p.coat_normal.length() > 0.99, "coat normal map linked");
    let (sheen, _) = layers
        .iter()
        .find(|(p, _)| p.sheen_weight > 0.0)
        .expect("a sheen closure");
    // Its weight is the glTF sheen's (1) over the sheen's albedo for the view direction.
    assert!(sheen.sheen_weight >= 1.0 && sheen.sheen_weight.is_finite());
    assert_eq!(sheen.sheen_tint, Vec3::new(1.0, 0.5, 0.25));
    assert!((sheen.sheen_roughness - 0.3).abs() < 1e-6);
    assert!((p.anisotropic - 0.6).abs() < 1e-6);
    // Rotated 90° counter-clockwise from the tangent (+X): the bitangent, +Y.
    assert!(tangent.abs_diff_eq(Vec3::Y, 1e-5), "{tangent}");
    // Transmission 0.5 × R.
    assert!((p.transmission - 0.5).abs() < 1e-6, "{}", p.transmission);
    // Every node of the preset compiles (none renders as muted or reads as zero).
    let c = crate::shading::material_program(m, &s.textures);
    assert!(
        !c.warnings
            .iter()
            .any(|w| w.contains("muted") || w.contains("reads as zero")),
        "{:?}",
        c.warnings
    );
    // Nothing is left "not supported".
    assert!(
        !s.warnings.iter().any(|w| w.contains("not supported")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn anisotropy_texture_turns_the_direction() {
    // RG = (0.5, 1) -> direction (0, 1): the bitangent; B = 0.5 × strength.
    let img = [png_uri(1, 1, &[[128, 255, 128, 255]])];
    let mat = json!({ "extensions": { "KHR_materials_anisotropy": {
        "anisotropyStrength": 1.0, "anisotropyTexture": { "index": 0 } } } });
    let s = load(&quad_doc(json!({}), mat, &img, json!({})));
    let (p, _, t) = principled(&shade(&s, 0));
    assert!(
        (p.anisotropic - 128.0 / 255.0).abs() < 1e-6,
        "{}",
        p.anisotropic
    );
    assert!(
        t.abs_diff_eq(Vec3::new(0.0039, 1.0, 0.0).normalize(), 1e-3),
        "{t}"
    );
}

#[test]
fn specular_textures_and_occlusion() {
    let img = [png_uri(1, 1, &[[255, 255, 255, 128]])];
    let mat = json!({
        "occlusionTexture": { "index": 0, "strength": 0.5 },
        "extensions": { "KHR_materials_specular": {
            "specularFactor": 1.0, "specularTexture": { "index": 0 },
            "specularColorFactor": [0.5, 0.5, 0.5], "specularColorTexture": { "index": 0 } } } });
    let s = load(&quad_doc(json!({}), mat, &img, json!({})));
    assert!(
        s.warnings.is_empty(),
        "occlusion is read silently: {:?}",
        s.warnings
    );
    let (p, _, _) = principled(&shade(&s, 0));
    assert!(
        (p.specular_level - 0.5 * 128.0 / 255.0).abs() < 1e-6,
        "{}",
        p.specular_level
    );
    assert!(p.specular_tint.abs_diff_eq(Vec3::splat(0.5), 1e-6));
    // A broken occlusion reference is only warned about.
    let mat = json!({ "occlusionTexture": { "index": 9 } });
    let s = load(&quad_doc(json!({}), mat, &img, json!({})));
    assert!(
        s.warnings.iter().any(|w| w.contains("occlusionTexture")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn colour_variants_only_for_preset_materials() {
    let count = |material: Value| {
        let mut b = Bin::default();
        let (plain, i) = quad(&mut b);
        let mut coloured = plain.clone();
        coloured["COLOR_0"] = json!(b.floats(&[1.0; 16], "VEC4"));
        let s = load(&b.finish(json!({
            "nodes": [{ "mesh": 0 }],
            "materials": [material],
            "meshes": [{ "primitives": [
                { "attributes": coloured, "indices": i, "material": 0 },
                { "attributes": plain, "indices": i, "material": 0 }
            ] }]
        })));
        let v: Vec<bool> = s
            .meshes
            .iter()
            .map(|m| s.materials[m.material].vertex_color)
            .collect();
        (s.materials.len(), v)
    };
    assert_eq!(count(json!({})), (2, vec![true, false]));
    let graph = json!({ "extensions": { "TESELA_material_graph": { "version": 1, "nodes": [] } } });
    assert_eq!(count(graph), (1, vec![false, false]));
}

#[test]
fn object_shadow_catcher_from_the_extras() {
    let s = load(&quad_doc(json!({}), json!({}), &[], json!({})));
    assert!(!s.meshes[0].attrs.object.shadow_catcher);
    let node = json!({ "extras": { "tesela_object": { "shadow_catcher": true } } });
    let s = load(&quad_doc(json!({}), json!({}), &[], node));
    assert!(s.meshes[0].attrs.object.shadow_catcher);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let node = json!({ "extras": { "tesela_object": { "shadow_catcher": 1 } } });
    let s = load(&quad_doc(json!({}), json!({}), &[], node));
    assert!(!s.meshes[0].attrs.object.shadow_catcher);
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("invalid shadow_catcher")),
        "{:?}",
        s.warnings
    );
}
