//! Malformed glTF inputs, built in code: each must give an error (never a panic) whose
//! message names the file and the problem.

use std::path::{Path, PathBuf};

use base64::Engine;
use serde_json::{Value, json};
use tesela::scene::LoadErrorKind;
use tesela::scene::gltf::{load, load_from_slice};

#[path = "common/inputs.rs"]
mod inputs;
use inputs::{glb, json_bytes as bytes, write};

fn b64(bytes: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// A triangle: 3 u16 indices (6 bytes + 2 padding) then 3 float positions (36 bytes).
fn triangle_bin(positions: &[f32; 9], indices: [u16; 3]) -> Vec<u8> {
    let mut b: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    b.extend_from_slice(&[0, 0]);
    b.extend_from_slice(&f32s(positions));
    b
}

const TRI: [f32; 9] = [0., 0., 0., 1., 0., 0., 0., 1., 0.];

/// A valid one-triangle document whose buffer 0 is `uri` (of `len` bytes).
fn doc(uri: Option<&str>, len: usize) -> Value {
    let mut buffer = json!({ "byteLength": len });
    if let Some(u) = uri {
        buffer["uri"] = json!(u);
    }
    json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 1 }, "indices": 0 }] }],
        "buffers": [buffer],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": 6 },
            { "buffer": 0, "byteOffset": 8, "byteLength": 36 }
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5123, "count": 3, "type": "SCALAR" },
            { "bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3" }
        ]
    })
}

fn embedded(bin: &[u8]) -> Value {
    doc(
        Some(&format!(
            "data:application/octet-stream;base64,{}",
            b64(bin)
        )),
        bin.len(),
    )
}

/// Loads from memory and returns the error message (panics if it loads).
fn err(v: &[u8]) -> String {
    match load_from_slice(v, None, "t.gltf") {
        Ok(_) => panic!("loaded, expected an error"),
        Err(e) => {
            let s = e.to_string();
            assert!(s.starts_with("t.gltf: "), "message must name the file: {s}");
            s
        }
    }
}

fn assert_contains(msg: &str, what: &str) {
    assert!(msg.contains(what), "expected `{what}` in: {msg}");
}

/// A fresh folder for file-based cases.
fn scratch(name: &str) -> PathBuf {
    inputs::scratch("gltf-errors", name)
}

#[test]
fn the_valid_baseline_loads() {
    let bin = triangle_bin(&TRI, [0, 1, 2]);
    let s = load_from_slice(&bytes(&embedded(&bin)), None, "t.gltf").unwrap();
    assert_eq!(s.triangle_count(), 1);
    let mut d = doc(None, bin.len());
    d["buffers"][0].as_object_mut().unwrap().remove("uri");
    let s = load_from_slice(&glb(&bytes(&d), &bin), None, "t.glb").unwrap();
    assert_eq!(s.triangle_count(), 1);
}

#[test]
fn empty_and_garbage_files() {
    assert_contains(&err(b""), "empty file");
    assert_contains(&err(b"   \n"), "not a glTF file");
    assert_contains(&err(b"\x89PNG\r\n\x1a\n"), "not a glTF file");
    assert_contains(&err(b"[1, 2, 3]"), "not a glTF file");
    assert_contains(&err(br#"{"foo": 1}"#), "missing field `asset`");
    assert_contains(
        &err(br#"{"asset": {"version": "1.0"}}"#),
        "unsupported glTF version `1.0`",
    );
}

#[test]
fn truncated_json() {
    let full = bytes(&embedded(&triangle_bin(&TRI, [0, 1, 2])));
    let msg = err(&full[..full.len() / 2]);
    assert_contains(&msg, "invalid JSON");
    assert_contains(&msg, "EOF");
}

#[test]
fn bad_glb_magic_version_and_truncation() {
    let bin = triangle_bin(&TRI, [0, 1, 2]);
    let mut d = doc(None, bin.len());
    d["buffers"][0].as_object_mut().unwrap().remove("uri");
    let good = glb(&bytes(&d), &bin);
    let mut bad = good.clone();
    bad[..4].copy_from_slice(b"GLTF");
    assert_contains(&err(&bad), "bad GLB magic");
    let mut bad = good.clone();
    bad[..4].copy_from_slice(b"abcd");
    assert_contains(&err(&bad), "not a glTF file");
    let mut bad = good.clone();
    bad[4] = 1;
    assert_contains(&err(&bad), "unsupported GLB version 1");
    assert_contains(&err(&good[..good.len() - 8]), "truncated GLB");
    assert_contains(&err(&good[..10]), "truncated GLB");
    // A BIN chunk shorter than the buffer's byteLength.
    d["buffers"][0]["byteLength"] = json!(400);
    assert_contains(&err(&glb(&bytes(&d), &bin)), "shorter than byteLength 400");
}

#[test]
fn accessor_out_of_buffer_view_bounds() {
    let bin = triangle_bin(&TRI, [0, 1, 2]);
    let mut d = embedded(&bin);
    d["accessors"][1]["count"] = json!(4);
    assert_eq!(
        err(&bytes(&d)),
        "t.gltf: accessor 1 (POSITION of mesh 0 primitive 0): byteOffset+length 48 exceeds bufferView 1 of 36 bytes"
    );
    let mut d = embedded(&bin);
    d["accessors"][1]["byteOffset"] = json!(4);
    assert_contains(
        &err(&bytes(&d)),
        "byteOffset+length 40 exceeds bufferView 1",
    );
    let mut d = embedded(&bin);
    d["bufferViews"][1]["byteLength"] = json!(400);
    assert_contains(
        &err(&bytes(&d)),
        "bufferView 1: byteOffset 8 + byteLength 400 exceeds buffer 0 of 44 bytes",
    );
    let mut d = embedded(&bin);
    d["accessors"][1]["count"] = json!(u64::MAX);
    assert_contains(
        &err(&bytes(&d)),
        "accessor 1 (POSITION of mesh 0 primitive 0)",
    );
    let mut d = embedded(&bin);
    d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(7);
    assert_contains(
        &err(&bytes(&d)),
        "accessor 7 (POSITION of mesh 0 primitive 0) does not exist",
    );
}

#[test]
fn index_past_the_vertex_count() {
    let d = embedded(&triangle_bin(&TRI, [0, 1, 3]));
    let msg = err(&bytes(&d));
    assert_contains(&msg, "accessor 0 (indices of mesh 0 primitive 0)");
    assert_contains(&msg, "index 3 at position 2 is out of range for 3 vertices");
}

#[test]
fn nan_and_infinite_positions() {
    for bad in [f32::NAN, f32::INFINITY] {
        let mut p = TRI;
        p[4] = bad;
        let msg = err(&bytes(&embedded(&triangle_bin(&p, [0, 1, 2]))));
        assert_contains(&msg, "POSITION of mesh 0 primitive 0");
        assert_contains(&msg, "vertex 1 is not finite");
    }
}

#[test]
fn bin_file_of_the_wrong_length_and_missing_files() {
    let dir = scratch("bin");
    let bin = triangle_bin(&TRI, [0, 1, 2]);
    write(&dir, "short.bin", &bin[..20]);
    let p = write(
        &dir,
        "short.gltf",
        &bytes(&doc(Some("short.bin"), bin.len())),
    );
    let msg = load(&p).unwrap_err().to_string();
    assert!(msg.starts_with(&p.display().to_string()), "{msg}");
    assert_contains(&msg, "buffer 0 (`short.bin`)");
    assert_contains(&msg, "20 bytes, shorter than the buffer's byteLength 44");

    let p = write(
        &dir,
        "missing.gltf",
        &bytes(&doc(Some("nothere.bin"), bin.len())),
    );
    let e = load(&p).unwrap_err();
    assert_eq!(e.kind, LoadErrorKind::Io);
    assert_contains(
        &e.to_string(),
        "buffer 0 (`nothere.bin`): cannot read `nothere.bin`",
    );

    let e = load(&dir.join("no such scene.gltf")).unwrap_err();
    assert_contains(&e.to_string(), "no such scene.gltf: cannot read the file");

    // A data URI shorter than byteLength.
    let mut d = embedded(&bin);
    d["buffers"][0]["byteLength"] = json!(100);
    assert_contains(
        &err(&bytes(&d)),
        "data URI holds 44 bytes, fewer than byteLength 100",
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The triangle with a base-colour texture whose image has `image`.
fn textured(bin_uri: &str, len: usize, image: Value) -> Value {
    let mut d = doc(Some(bin_uri), len);
    d["meshes"][0]["primitives"][0]["material"] = json!(0);
    d["materials"] = json!([{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } }]);
    d["textures"] = json!([{ "source": 0 }]);
    d["images"] = json!([image]);
    d
}

#[test]
fn missing_and_undecodable_images() {
    let dir = scratch("img");
    let bin = triangle_bin(&TRI, [0, 1, 2]);
    write(&dir, "t.bin", &bin);
    let p = write(
        &dir,
        "a.gltf",
        &bytes(&textured(
            "t.bin",
            bin.len(),
            json!({ "uri": "missing%20tex.png" }),
        )),
    );
    let e = load(&p).unwrap_err();
    let msg = e.to_string();
    assert_contains(&msg, "image 0 (`missing%20tex.png`)");
    assert_contains(&msg, "cannot read `missing%20tex.png`");
    assert_contains(&msg, "missing tex.png");

    write(&dir, "bad.png", b"\x89PNG\r\n\x1a\nthis is not a png");
    let p = write(
        &dir,
        "b.gltf",
        &bytes(&textured("t.bin", bin.len(), json!({ "uri": "bad.png" }))),
    );
    let msg = load(&p).unwrap_err().to_string();
    assert_contains(&msg, "image 0 (`bad.png`): cannot decode the image");

    let data = format!("data:application/octet-stream;base64,{}", b64(&bin));
    let d = textured(
        &data,
        bin.len(),
        json!({ "uri": "data:image/png;base64,AAAA" }),
    );
    assert_contains(&err(&bytes(&d)), "cannot decode the image");
    let d = textured(
        &data,
        bin.len(),
        json!({ "bufferView": 9, "mimeType": "image/png" }),
    );
    assert_contains(&err(&bytes(&d)), "bufferView 9 does not exist");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn uris_outside_the_scene_folder_are_refused() {
    let dir = scratch("escape");
    let inner = dir.join("scene");
    std::fs::create_dir_all(&inner).unwrap();
    let bin = triangle_bin(&TRI, [0, 1, 2]);
    write(&dir, "outside.bin", &bin);
    let abs = dir.join("outside.bin").display().to_string();
    let cases = [
        ("../outside.bin", "leaves the scene's folder"),
        ("sub/../../outside.bin", "leaves the scene's folder"),
        ("%2E%2E/outside.bin", "leaves the scene's folder"),
        (abs.as_str(), "absolute path"),
        (
            "http://example.com/outside.bin",
            "scheme `http:` is not allowed",
        ),
        (
            "https://example.com/outside.bin",
            "scheme `https:` is not allowed",
        ),
        ("file:///etc/passwd", "scheme `file:` is not allowed"),
    ];
    for (uri, what) in cases {
        let p = write(&inner, "s.gltf", &bytes(&doc(Some(uri), bin.len())));
        let e = load(&p).unwrap_err();
        assert_eq!(e.kind, LoadErrorKind::Refused, "{uri}: {e}");
        assert_contains(&e.to_string(), what);
        // Images go through the same check.
        let data = format!("data:application/octet-stream;base64,{}", b64(&bin));
        let p = write(
            &inner,
            "i.gltf",
            &bytes(&textured(&data, bin.len(), json!({ "uri": uri }))),
        );
        let e = load(&p).unwrap_err();
        assert_eq!(e.kind, LoadErrorKind::Refused, "image {uri}: {e}");
    }
    // A symlink inside the folder that points outside it is refused too.
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(dir.join("outside.bin"), inner.join("link.bin")).unwrap();
        let p = write(&inner, "l.gltf", &bytes(&doc(Some("link.bin"), bin.len())));
        let e = load(&p).unwrap_err();
        assert_eq!(e.kind, LoadErrorKind::Refused, "{e}");
        assert_contains(&e.to_string(), "outside the scene's folder");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn unsupported_required_extensions() {
    let bin = triangle_bin(&TRI, [0, 1, 2]);
    for ext in [
        "KHR_texture_basisu",
        "EXT_lights_image_based",
        "KHR_materials_iridescence",
    ] {
        let mut d = embedded(&bin);
        d["extensionsUsed"] = json!([ext]);
        d["extensionsRequired"] = json!([ext]);
        let e = load_from_slice(&bytes(&d), None, "t.gltf").unwrap_err();
        assert_eq!(e.kind, LoadErrorKind::Unsupported);
        assert_contains(
            &e.to_string(),
            &format!("unsupported required extension `{ext}`"),
        );
    }
    // Supported ones load; unknown optional ones give one warning each.
    let mut d = embedded(&bin);
    d["extensionsUsed"] = json!(["KHR_mesh_quantization", "EXT_foo", "EXT_foo", "EXT_bar"]);
    d["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    let s = load_from_slice(&bytes(&d), None, "t.gltf").unwrap();
    assert_eq!(s.warnings.len(), 2, "{:?}", s.warnings);
    assert!(s.warnings[0].contains("EXT_foo"));
}

#[test]
fn invalid_camera_fields() {
    let bin = triangle_bin(&TRI, [0, 1, 2]);
    for yfov in [json!(0.0), json!(-0.5), json!(1e300), json!(4.0)] {
        let mut d = embedded(&bin);
        d["cameras"] =
            json!([{ "type": "perspective", "perspective": { "yfov": yfov, "znear": 0.1 } }]);
        d["nodes"][0]["camera"] = json!(0);
        let msg = err(&bytes(&d));
        assert_contains(&msg, "camera 0: perspective yfov");
    }
    let mut d = embedded(&bin);
    d["cameras"] = json!([{ "type": "orthographic", "orthographic": { "xmag": 1, "ymag": 0, "znear": 0.1, "zfar": 10 } }]);
    d["nodes"][0]["camera"] = json!(0);
    assert_contains(&err(&bytes(&d)), "orthographic ymag 0");
    let mut d = embedded(&bin);
    d["nodes"][0]["camera"] = json!(3);
    assert_contains(&err(&bytes(&d)), "node 0: camera 3 does not exist");
}

#[test]
fn broken_node_graphs() {
    let bin = triangle_bin(&TRI, [0, 1, 2]);
    let mut d = embedded(&bin);
    d["nodes"] = json!([{ "mesh": 0, "children": [1] }, { "children": [0] }]);
    assert_contains(&err(&bytes(&d)), "reached twice");
    let mut d = embedded(&bin);
    d["scenes"][0]["nodes"] = json!([0, 0]);
    assert_contains(&err(&bytes(&d)), "node 0 is reached twice");
    let mut d = embedded(&bin);
    d["scenes"][0]["nodes"] = json!([5]);
    assert_contains(&err(&bytes(&d)), "node 5 does not exist");
    let mut d = embedded(&bin);
    d["scene"] = json!(2);
    assert_contains(
        &err(&bytes(&d)),
        "scene 2 (the default `scene`) does not exist",
    );
    let mut d = embedded(&bin);
    d["nodes"][0]["rotation"] = json!([0, 0, 0, 0]);
    assert_contains(&err(&bytes(&d)), "node 0: rotation");
    // A long chain of nodes is walked without recursion.
    let mut d = embedded(&bin);
    let n = 20000;
    let nodes: Vec<Value> = (0..n)
        .map(|i| {
            if i + 1 < n {
                json!({ "children": [i + 1] })
            } else {
                json!({ "mesh": 0 })
            }
        })
        .collect();
    d["nodes"] = json!(nodes);
    let s = load_from_slice(&bytes(&d), None, "t.gltf").unwrap();
    assert_eq!(s.triangle_count(), 1);
}

#[test]
fn a_scene_without_triangles_is_not_an_error() {
    let d = json!({ "asset": { "version": "2.0" } });
    let s = load_from_slice(&bytes(&d), None, "t.gltf").unwrap();
    assert_eq!(s.triangle_count(), 0);
}

/// A tiny deterministic generator for the mutation test.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
}

#[test]
fn mutated_inputs_never_panic() {
    let bin = triangle_bin(&TRI, [0, 1, 2]);
    let mut d = doc(None, bin.len());
    d["buffers"][0].as_object_mut().unwrap().remove("uri");
    d["cameras"] = json!([{ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.1 } }]);
    d["nodes"] = json!([{ "mesh": 0, "children": [1] }, { "camera": 0, "translation": [0, 0, 3] }]);
    d["accessors"][1]["sparse"] = json!({ "count": 1,
        "indices": { "bufferView": 0, "componentType": 5123 },
        "values": { "bufferView": 1 } });
    let seeds = [glb(&bytes(&d), &bin), bytes(&embedded(&bin))];
    let mut rng = Lcg(12345);
    for seed in &seeds {
        // Every truncation.
        for n in 0..seed.len() {
            let _ = load_from_slice(&seed[..n], None, "t");
        }
        // Random byte mutations.
        for _ in 0..3000 {
            let mut m = seed.clone();
            for _ in 0..1 + rng.next() % 4 {
                let i = (rng.next() as usize) % m.len();
                m[i] = match rng.next() % 4 {
                    0 => rng.next() as u8,
                    1 => b'9',
                    2 => m[i] ^ 0x80,
                    _ => b'0',
                };
            }
            let _ = load_from_slice(&m, None, "t");
        }
    }
}

/// Every leaf (and object member) of a JSON document, as paths.
#[derive(Clone)]
enum Seg {
    Key(String),
    Idx(usize),
}

fn paths(v: &Value, here: &mut Vec<Seg>, out: &mut Vec<Vec<Seg>>) {
    out.push(here.clone());
    match v {
        Value::Object(o) => {
            for (k, c) in o {
                here.push(Seg::Key(k.clone()));
                paths(c, here, out);
                here.pop();
            }
        }
        Value::Array(a) => {
            for (i, c) in a.iter().enumerate() {
                here.push(Seg::Idx(i));
                paths(c, here, out);
                here.pop();
            }
        }
        _ => {}
    }
}

fn at<'a>(v: &'a mut Value, path: &[Seg]) -> Option<&'a mut Value> {
    path.iter().try_fold(v, |v, s| match s {
        Seg::Key(k) => v.get_mut(k.as_str()),
        Seg::Idx(i) => v.get_mut(*i),
    })
}

/// Structure-aware mutations: numbers, strings, removed members, duplicated elements.
fn mutate(doc: &Value, rng: &mut Lcg) -> Value {
    let mut d = doc.clone();
    let mut all = Vec::new();
    paths(&d, &mut Vec::new(), &mut all);
    for _ in 0..1 + rng.next() % 3 {
        let p = &all[(rng.next() as usize) % all.len()];
        let Some(v) = at(&mut d, p) else { continue };
        let numbers = [
            json!(0),
            json!(-1),
            json!(1),
            json!(2),
            json!(3),
            json!(7),
            json!(255),
            json!(65535),
            json!(4294967295u64),
            json!(4294967296u64),
            json!(u64::MAX),
            json!(1e300),
            json!(-1e300),
            json!(0.5),
            json!(5125),
            json!(5120),
            json!(5126),
        ];
        let strings = [
            "",
            "../x.bin",
            "/etc/passwd",
            "http://x/y",
            "data:,",
            "data:application/octet-stream;base64,AAAA",
            "data:image/png;base64,iVBORw0KGgo=",
            "%",
            "VEC3",
            "MAT4",
            "SCALAR",
            "spot",
            "AREA",
            "DISK",
            "SUN",
            "orthographic",
        ];
        match rng.next() % 5 {
            0 | 1 if v.is_number() || v.is_null() => {
                *v = numbers[(rng.next() as usize) % numbers.len()].clone()
            }
            0 | 1 if v.is_string() => *v = json!(strings[(rng.next() as usize) % strings.len()]),
            2 => {
                if let Value::Array(a) = v
                    && !a.is_empty()
                {
                    let i = (rng.next() as usize) % a.len();
                    let e = a[i].clone();
                    a.push(e);
                }
            }
            3 => {
                if let Value::Object(o) = v
                    && !o.is_empty()
                {
                    let k = o
                        .keys()
                        .nth((rng.next() as usize) % o.len())
                        .unwrap()
                        .clone();
                    o.remove(&k);
                }
            }
            _ => {
                if let Value::Array(a) = v {
                    a.reverse();
                }
            }
        }
    }
    d
}

/// A document that exercises most loader paths: sparse data, morph targets, strips,
/// cameras, every light kind, textures from a bufferView, Tesela extensions.
fn rich_doc() -> (Value, Vec<u8>) {
    let mut bin = triangle_bin(&TRI, [0, 1, 2]);
    let morph = f32s(&[0., 0., 1., 0., 0., 1., 0., 0., 1.]);
    bin.extend_from_slice(&morph);
    let mut png = Vec::new();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 255]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let png_off = bin.len();
    bin.extend_from_slice(&png);
    let mut d = doc(None, bin.len());
    d["buffers"][0].as_object_mut().unwrap().remove("uri");
    d["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "buffer": 0, "byteOffset": 44, "byteLength": 36 }));
    d["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "buffer": 0, "byteOffset": png_off, "byteLength": png.len() }));
    d["accessors"].as_array_mut().unwrap().push(json!({
        "bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC3",
        "sparse": { "count": 1, "indices": { "bufferView": 0, "componentType": 5123 },
                    "values": { "bufferView": 1 } } }));
    d["meshes"] = json!([{
        "weights": [0.5],
        "primitives": [
            { "attributes": { "POSITION": 1, "NORMAL": 2 }, "indices": 0, "material": 0,
              "targets": [{ "POSITION": 2, "NORMAL": 2 }] },
            { "attributes": { "POSITION": 1 }, "mode": 5 }
        ]
    }]);
    d["images"] = json!([{ "bufferView": 3, "mimeType": "image/png" }]);
    d["samplers"] = json!([{ "magFilter": 9728, "wrapS": 33648 }]);
    d["textures"] = json!([{ "source": 0, "sampler": 0 }]);
    d["materials"] = json!([{
        "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 }, "metallicRoughnessTexture": { "index": 0 } },
        "emissiveTexture": { "index": 0 }, "emissiveFactor": [1, 1, 1],
        "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": 3 },
                        "KHR_materials_ior": { "ior": 1.4 }, "KHR_materials_transmission": { "transmissionFactor": 1 },
                        "KHR_materials_specular": { "specularFactor": 0.5 }, "TESELA_emission": { "two_sided": true } } }]);
    d["cameras"] = json!([
        { "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.1, "aspectRatio": 1.5 } },
        { "type": "orthographic", "orthographic": { "xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 5 } }
    ]);
    d["extensions"] = json!({
        "KHR_lights_punctual": { "lights": [
            { "type": "point", "intensity": 10 },
            { "type": "spot", "spot": { "innerConeAngle": 0.1, "outerConeAngle": 0.4 } },
            { "type": "directional", "color": [1, 0.5, 0.5] }
        ] },
        "TESELA_world": { "color": [0.1, 0.1, 0.1], "strength": 1 },
        "TESELA_render": { "width": 64, "height": 48, "spp": 4 }
    });
    d["nodes"] = json!([
        { "mesh": 0, "children": [1, 2, 3], "rotation": [0, 0.7, 0, 0.7] },
        { "camera": 0, "translation": [0, 0, 3] },
        { "extensions": { "KHR_lights_punctual": { "light": 1 } }, "scale": [1, -1, 1] },
        { "children": [4, 5], "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 1,2,3,1] },
        { "extensions": { "TESELA_light": { "type": "AREA", "shape": "ELLIPSE", "size": 1, "size_y": 2, "power": 50 } } },
        { "extensions": { "TESELA_light": { "type": "SPOT", "power": 50, "spot_size": 1, "spot_blend": 0.5 },
                          "KHR_lights_punctual": { "light": 0 } } }
    ]);
    (d, bin)
}

fn fuzz_iterations(default: usize) -> usize {
    std::env::var("TESELA_FUZZ_ITERS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

#[test]
fn structured_mutations_never_panic() {
    let (d, bin) = rich_doc();
    let s = load_from_slice(&glb(&bytes(&d), &bin), None, "rich.glb").unwrap();
    assert!(
        s.camera.is_some() && s.lights.len() == 3 && s.meshes.len() == 2,
        "{s:?}"
    );
    let mut rng = Lcg(99);
    let (mut ok, mut failed) = (0, 0);
    for _ in 0..fuzz_iterations(1500) {
        let m = mutate(&d, &mut rng);
        match load_from_slice(&glb(&bytes(&m), &bin), None, "m.glb") {
            Ok(_) => ok += 1,
            Err(e) => {
                assert!(e.to_string().starts_with("m.glb: "), "{e}");
                failed += 1;
            }
        }
    }
    // Both outcomes must occur, or the mutations are not reaching the loader.
    assert!(ok > 0 && failed > 0, "{ok} loaded, {failed} failed");
}

#[test]
fn structured_mutations_of_the_samples_never_panic() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/gltf-samples");
    if !dir.is_dir() {
        eprintln!("note: {} is absent; skipped", dir.display());
        return;
    }
    let mut rng = Lcg(7);
    for model in [
        "Box",
        "SimpleSparseAccessor",
        "Cameras",
        "MeshPrimitiveModes",
        "AnimatedMorphCube",
    ] {
        for variant in ["glTF-Embedded", "glTF-Quantized", "glTF"] {
            let folder = dir.join(model).join(variant);
            let Some(file) = std::fs::read_dir(&folder).ok().and_then(|mut r| {
                r.find_map(|e| {
                    let p = e.ok()?.path();
                    (p.extension()? == "gltf").then_some(p)
                })
            }) else {
                continue;
            };
            let d: Value = serde_json::from_slice(&std::fs::read(&file).unwrap()).unwrap();
            for _ in 0..fuzz_iterations(150) {
                let m = mutate(&d, &mut rng);
                let _ = load_from_slice(&bytes(&m), Some(&folder), "m.gltf");
            }
        }
    }
}
