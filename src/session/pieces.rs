//! Pieces of a scene loaded on their own: a camera, a light, a material or the world, each
//! written as a small glTF document (sharing the loaded file's buffers, images and textures
//! where it needs them) and read by the same loader as the whole file, so an edit means what
//! the same JSON means in a file. Then merged into the kept scene, image and texture indices
//! moved past the scene's own.

use std::sync::Arc;

use glam::{Mat4, Vec3};
use serde_json::{Map, Value, json};

use crate::scene::gltf::Document;
use crate::scene::{Camera, Image, Light, Material, Scene, TexRef, Texture, World};

/// The 3 vertices of the triangle that carries a material through the loader.
const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// UV sets the carrier triangle has (so a textured material finds the set it reads).
const CARRIER_UV_SETS: usize = 4;

/// Name of that triangle's mesh (its warnings are not the material's).
const CARRIER: &str = "tesela-session-carrier";

/// A document of the given members and one root node list.
fn document(members: Map<String, Value>) -> Value {
    let mut doc = Map::new();
    doc.insert("asset".into(), json!({"version": "2.0"}));
    doc.extend(members);
    Value::Object(doc)
}

fn matrix_json(m: &Mat4) -> Value {
    json!(m.to_cols_array().to_vec())
}

/// What the loader said, less what concerns the carrier triangle.
fn warnings_of(scene: &Scene) -> Vec<String> {
    (scene.warnings.iter())
        .filter(|w| !w.contains(CARRIER))
        .cloned()
        .collect()
}

/// The camera of a view: `TESELA_camera` object `ext` on a node of world matrix `m`.
pub fn camera(m: &Mat4, ext: &Value) -> Result<(Camera, Vec<String>), String> {
    let doc = document(
        json!({
            "extensionsUsed": ["TESELA_camera"],
            "cameras": [{"type": "perspective", "perspective": {"yfov": 0.6911, "znear": 0.1}}],
            "nodes": [{"camera": 0, "matrix": matrix_json(m), "extensions": {"TESELA_camera": ext}}],
            "scenes": [{"nodes": [0]}],
            "scene": 0,
        })
        .as_object()
        .cloned()
        .unwrap_or_default(),
    );
    let scene = load_alone(&doc, "view camera")?;
    let cam = scene
        .camera
        .ok_or("the camera's matrix cannot place a camera (degenerate axes)")?;
    Ok((cam, warnings_of(&scene)))
}

/// The lights a node of world matrix `m` with `TESELA_light` object `ext` carries.
pub fn lights(m: &Mat4, ext: &Value) -> Result<(Vec<Light>, Vec<String>), String> {
    let doc = document(
        json!({
            "extensionsUsed": ["TESELA_light"],
            "nodes": [{"matrix": matrix_json(m), "extensions": {"TESELA_light": ext}}],
            "scenes": [{"nodes": [0]}],
            "scene": 0,
        })
        .as_object()
        .cloned()
        .unwrap_or_default(),
    );
    let scene = load_alone(&doc, "light")?;
    let w = warnings_of(&scene);
    Ok((scene.lights, w))
}

fn load_alone(doc: &Value, what: &str) -> Result<Scene, String> {
    let bytes = serde_json::to_vec(doc).map_err(|e| e.to_string())?;
    crate::scene::gltf::load_from_slice(&bytes, None, what).map_err(|e| e.to_string())
}

/// The members of `doc` that images and textures need, with `extra` appended to the
/// buffers (returned: the index of the first extra buffer view and accessor).
fn shared_members(doc: &Document, extra_len: usize) -> (Map<String, Value>, usize, usize) {
    let mut m = Map::new();
    for key in [
        "extensionsUsed",
        "textures",
        "samplers",
        "images",
        "bufferViews",
        "buffers",
        "accessors",
    ] {
        if let Some(v) = doc.raw.get(key) {
            m.insert(key.into(), v.clone());
        }
    }
    if let Some(images) = doc
        .raw
        .get("extensions")
        .and_then(|e| e.get("TESELA_images"))
    {
        m.insert(
            "extensions".into(),
            json!({ "TESELA_images": images.clone() }),
        );
    }
    let push = |m: &mut Map<String, Value>, key: &str, v: Value| -> usize {
        let a = m.entry(key).or_insert_with(|| json!([]));
        match a.as_array_mut() {
            Some(a) => {
                a.push(v);
                a.len() - 1
            }
            None => 0,
        }
    };
    let buffer = push(&mut m, "buffers", json!({"byteLength": extra_len}));
    let view = push(
        &mut m,
        "bufferViews",
        json!({"buffer": buffer, "byteLength": extra_len}),
    );
    let accessor = push(
        &mut m,
        "accessors",
        json!({"bufferView": view, "componentType": 5126, "count": 3, "type": "VEC3",
               "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]}),
    );
    if extra_len >= 36 + CARRIER_UV_SETS * 24 {
        for k in 0..CARRIER_UV_SETS {
            push(
                &mut m,
                "accessors",
                json!({"bufferView": view, "byteOffset": 36 + 24 * k, "componentType": 5126,
                       "count": 3, "type": "VEC2"}),
            );
        }
    }
    (m, view, accessor)
}

/// Material JSON `material` (as in a file's `materials[]`) read against `doc`'s textures and
/// images: the material and the textures and images it uses, in a scene of its own.
pub fn material(doc: &Document, material: &Value) -> Result<(Scene, Vec<String>), String> {
    let carrier: Vec<u8> = TRIANGLE
        .iter()
        .flatten()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    let (mut m, _, accessor) = shared_members(doc, carrier.len());
    m.insert("materials".into(), json!([material]));
    m.insert(
        "meshes".into(),
        json!([{"name": CARRIER, "primitives": [{"attributes": {"POSITION": accessor}, "material": 0}]}]),
    );
    m.insert("nodes".into(), json!([{"mesh": 0}]));
    m.insert("scenes".into(), json!([{"nodes": [0]}]));
    m.insert("scene".into(), json!(0));
    let (scene, _) = doc
        .load_piece(&document(m), &[&carrier])
        .map_err(|e| e.to_string())?;
    if scene.materials.is_empty() {
        return Err("the material did not load".into());
    }
    let w = warnings_of(&scene);
    Ok((scene, w))
}

/// World JSON `world` (a `TESELA_world` object) read against `doc`'s images.
pub fn world(doc: &Document, world: &Value) -> Result<(Scene, Vec<String>), String> {
    let pad = [0u8; 36];
    let (mut m, _, _) = shared_members(doc, pad.len());
    let ext = m.entry("extensions").or_insert_with(|| json!({}));
    if let Some(e) = ext.as_object_mut() {
        e.insert("TESELA_world".into(), world.clone());
    }
    let (scene, _) = doc
        .load_piece(&document(m), &[&pad])
        .map_err(|e| e.to_string())?;
    let w = warnings_of(&scene);
    Ok((scene, w))
}

/// Adds `img` to `scene` (or finds the same image there) and returns its index.
fn add_image(scene: &mut Scene, img: Image) -> usize {
    let same = |a: &Image| {
        a.width == img.width && a.height == img.height && a.rgba8 == img.rgba8 && {
            // Bit equality: NaN texels compare equal to themselves.
            a.float.len() == img.float.len()
                && (a.float.iter().zip(&img.float))
                    .all(|(x, y)| x.map(f32::to_bits) == y.map(f32::to_bits))
        }
    };
    if let Some(i) = scene.images.iter().position(same) {
        return i;
    }
    scene.images.push(img);
    scene.images.len() - 1
}

/// Moves `piece`'s images and textures into `scene`; returns the maps of their indices.
fn merge_images(scene: &mut Scene, piece: &Scene) -> (Vec<usize>, Vec<usize>) {
    let images: Vec<usize> = (piece.images.iter())
        .map(|i| add_image(scene, i.clone()))
        .collect();
    let textures = (piece.textures.iter())
        .map(|t| {
            let t = Texture {
                image: images.get(t.image).copied().unwrap_or(t.image),
                ..t.clone()
            };
            let found = scene.textures.iter().position(|s| {
                s.image == t.image
                    && s.wrap_s == t.wrap_s
                    && s.wrap_t == t.wrap_t
                    && s.nearest == t.nearest
            });
            found.unwrap_or_else(|| {
                scene.textures.push(t);
                scene.textures.len() - 1
            })
        })
        .collect();
    (images, textures)
}

fn remap_graph(g: &mut crate::shading::Graph, images: &[usize]) {
    for n in &mut g.nodes {
        if let Some(i) = n.image.as_mut() {
            *i = images.get(*i).copied().unwrap_or(*i);
        }
    }
}

/// Every texture reference of `m`.
fn texture_refs(m: &mut Material) -> Vec<&mut TexRef> {
    let mut v: Vec<&mut TexRef> = Vec::new();
    for t in [
        &mut m.base_color_texture,
        &mut m.metallic_roughness_texture,
        &mut m.normal_texture,
        &mut m.emission_texture,
        &mut m.transmission_texture,
        &mut m.specular_texture,
        &mut m.specular_color_texture,
    ] {
        v.extend(t.as_mut());
    }
    if let Some(c) = &mut m.clearcoat {
        for t in [
            &mut c.texture,
            &mut c.roughness_texture,
            &mut c.normal_texture,
        ] {
            v.extend(t.as_mut());
        }
    }
    if let Some(s) = &mut m.sheen {
        for t in [&mut s.color_texture, &mut s.roughness_texture] {
            v.extend(t.as_mut());
        }
    }
    if let Some(a) = &mut m.anisotropy {
        v.extend(a.texture.as_mut());
    }
    v
}

/// Material `k` of `piece`, its textures and images moved into `scene`.
pub fn merge_material(scene: &mut Scene, piece: &Scene, k: usize) -> Material {
    let (images, textures) = merge_images(scene, piece);
    let mut m = piece.materials[k].clone();
    for t in texture_refs(&mut m) {
        t.texture = textures.get(t.texture).copied().unwrap_or(t.texture);
    }
    if let Some(g) = &mut m.graph {
        remap_graph(Arc::make_mut(g), &images);
    }
    m
}

/// `piece`'s world (graph images moved into `scene`) and constant background.
pub fn merge_world(scene: &mut Scene, piece: &Scene) -> (World, Vec3) {
    let (images, _) = merge_images(scene, piece);
    let mut w = piece.world.clone();
    if let Some(g) = &mut w.graph {
        remap_graph(g, &images);
    }
    (w, piece.background)
}
