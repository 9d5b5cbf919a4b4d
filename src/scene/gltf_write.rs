//! Writes a [`Scene`] as a self-contained glTF 2.0 file (one buffer as a base64 data URI).
//! Used to turn the built-in scenes into `scenes/*.gltf`; textures are not written.

use super::{Light, Projection, Scene, SensorFit, SpotFalloff};
use base64::Engine;
use glam::{Vec2, Vec3};
use serde_json::{Value, json};
use std::path::Path;

/// Photometric scale: glTF stores candela and lux; Tesela works in W/sr and W/m².
const LUMENS_PER_WATT: f32 = 683.0;

struct Buffer {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Buffer {
    fn push(&mut self, data: &[u8], target: u32) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        self.views.push(json!({
            "buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len(), "target": target
        }));
        self.bytes.extend_from_slice(data);
        self.views.len() - 1
    }

    fn floats(&mut self, values: &[f32], kind: &str, count: usize, minmax: bool) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.push(&bytes, 34962);
        let mut acc =
            json!({"bufferView": view, "componentType": 5126, "count": count, "type": kind});
        if minmax && count > 0 {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for c in values.chunks_exact(3) {
                for k in 0..3 {
                    lo[k] = lo[k].min(c[k]);
                    hi[k] = hi[k].max(c[k]);
                }
            }
            acc["min"] = json!(lo);
            acc["max"] = json!(hi);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    fn indices(&mut self, values: &[u32]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.push(&bytes, 34963);
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5125, "count": values.len(), "type": "SCALAR"
        }));
        self.accessors.len() - 1
    }
}

/// Splits a radiance into a colour with components ≤ 1 and a strength.
fn color_strength(c: Vec3) -> ([f32; 3], f32) {
    let m = c.max_element();
    if m <= 0.0 {
        ([0.0; 3], 1.0)
    } else {
        ((c / m).to_array(), m)
    }
}

/// Quaternion `[x, y, z, w]` rotating -Z to `dir`.
fn rotation_to(dir: Vec3) -> [f32; 4] {
    glam::Quat::from_rotation_arc(-Vec3::Z, dir.normalize()).to_array()
}

pub fn write(scene: &Scene, path: &Path) -> Result<(), String> {
    let mut buf = Buffer {
        bytes: Vec::new(),
        views: Vec::new(),
        accessors: Vec::new(),
    };
    let mut meshes = Vec::new();
    let mut nodes = Vec::new();
    // Placed meshes get no node of their own: their instances are nodes referring to them
    // (another glTF mesh over the same accessors where an instance overrides the material).
    let placed = scene.placed_meshes();
    for (mi, m) in scene.meshes.iter().enumerate() {
        let pos: Vec<f32> = m.positions.iter().flat_map(|p| p.to_array()).collect();
        let mut attributes = json!({"POSITION": buf.floats(&pos, "VEC3", m.positions.len(), true)});
        if !m.normals.is_empty() {
            let n: Vec<f32> = m.normals.iter().flat_map(|p| p.to_array()).collect();
            attributes["NORMAL"] = json!(buf.floats(&n, "VEC3", m.normals.len(), false));
        }
        if !m.uvs.is_empty() {
            let t: Vec<f32> = m.uvs.iter().flat_map(|p| p.to_array()).collect();
            attributes["TEXCOORD_0"] = json!(buf.floats(&t, "VEC2", m.uvs.len(), false));
        }
        let idx: Vec<u32> = m.indices.iter().flatten().copied().collect();
        let indices = buf.indices(&idx);
        meshes.push(json!({"name": m.name, "primitives": [{
            "attributes": attributes, "indices": indices, "material": m.material
        }]}));
        let own = meshes.len() - 1;
        if !placed[mi] {
            nodes.push(json!({"name": m.name, "mesh": own}));
            continue;
        }
        let mut by_material = std::collections::HashMap::new();
        by_material.insert(m.material, own);
        for inst in scene.instances.iter().filter(|i| i.mesh == mi) {
            let mat = inst.material.unwrap_or(m.material);
            let mesh = *by_material.entry(mat).or_insert_with(|| {
                let mut copy = meshes[own].clone();
                copy["primitives"][0]["material"] = json!(mat);
                meshes.push(copy);
                meshes.len() - 1
            });
            nodes.push(json!({"name": m.name, "mesh": mesh,
                "matrix": inst.to_world.to_cols_array()}));
        }
    }
    let materials: Vec<Value> = scene
        .materials
        .iter()
        .map(|m| {
            let (emissive, strength) = color_strength(m.emission);
            let mut ext = serde_json::Map::new();
            if strength != 1.0 {
                ext.insert(
                    "KHR_materials_emissive_strength".into(),
                    json!({"emissiveStrength": strength}),
                );
            }
            if m.transmission > 0.0 {
                ext.insert(
                    "KHR_materials_transmission".into(),
                    json!({"transmissionFactor": m.transmission}),
                );
            }
            if m.ior != 1.5 {
                ext.insert("KHR_materials_ior".into(), json!({"ior": m.ior}));
            }
            if m.specular != 1.0 {
                ext.insert(
                    "KHR_materials_specular".into(),
                    json!({"specularFactor": m.specular}),
                );
            }
            if m.is_emissive() {
                ext.insert(
                    "TESELA_emission".into(),
                    json!({"two_sided": m.emission_two_sided}),
                );
            }
            json!({
                "name": m.name,
                "pbrMetallicRoughness": {
                    "baseColorFactor": [m.base_color.x, m.base_color.y, m.base_color.z, 1.0],
                    "metallicFactor": m.metallic,
                    "roughnessFactor": m.roughness,
                },
                "emissiveFactor": emissive,
                "doubleSided": m.double_sided,
                "extensions": ext,
            })
        })
        .collect();
    let mut lights = Vec::new();
    for l in &scene.lights {
        let (node, light) = match *l {
            Light::Point {
                position,
                intensity,
            } => {
                let (c, s) = color_strength(intensity);
                (
                    json!({"translation": position.to_array()}),
                    json!({"type": "point", "color": c, "intensity": s * LUMENS_PER_WATT}),
                )
            }
            Light::Spot {
                position,
                direction,
                intensity,
                falloff,
            } => {
                let (c, s) = color_strength(intensity);
                let (inner, outer) = match falloff {
                    SpotFalloff::Gltf {
                        cos_inner,
                        cos_outer,
                    } => (cos_inner.acos(), cos_outer.acos()),
                    SpotFalloff::Cycles { cos_half, .. }
                    | SpotFalloff::CyclesScaled { cos_half, .. } => (0.0, cos_half.acos()),
                };
                (
                    json!({"translation": position.to_array(), "rotation": rotation_to(direction)}),
                    json!({"type": "spot", "color": c, "intensity": s * LUMENS_PER_WATT,
                        "spot": {"innerConeAngle": inner, "outerConeAngle": outer}}),
                )
            }
            Light::Directional {
                direction,
                irradiance,
                ..
            } => {
                let (c, s) = color_strength(irradiance);
                (
                    json!({"rotation": rotation_to(direction)}),
                    json!({"type": "directional", "color": c, "intensity": s * LUMENS_PER_WATT}),
                )
            }
            // Blender lights come from the add-on's files; the built-in scenes have none.
            Light::Blender { .. } => continue,
        };
        lights.push(light);
        let mut node = node;
        node["extensions"] = json!({"KHR_lights_punctual": {"light": lights.len() - 1}});
        nodes.push(node);
    }
    let mut cameras = Vec::new();
    if let Some(c) = &scene.camera {
        // Only what a glTF camera can say (the built-in scenes need no more).
        let plain = c.fit == SensorFit::Vertical
            && c.shift == Vec2::ZERO
            && c.aperture.is_none()
            && c.clip_start == 0.0
            && c.clip_end == f32::INFINITY;
        if !plain {
            return Err(
                "the camera's sensor fit, lens shift, clipping or depth of field cannot \
                        be written as a glTF camera"
                    .into(),
            );
        }
        cameras.push(match c.projection {
            Projection::Perspective { yfov } => {
                let mut p = json!({"yfov": yfov, "znear": 0.01});
                if let Some(a) = c.aspect {
                    p["aspectRatio"] = json!(a);
                }
                json!({"type": "perspective", "perspective": p})
            }
            Projection::Orthographic { ymag } => json!({"type": "orthographic",
                "orthographic": {"xmag": ymag, "ymag": ymag, "znear": 0.01, "zfar": 1000.0}}),
            Projection::Panoramic(_) => {
                return Err("a panoramic camera cannot be written as a glTF camera".into());
            }
        });
        let m: Vec<f32> = c.to_world.to_cols_array().to_vec();
        nodes.push(json!({"name": "camera", "camera": 0, "matrix": m}));
    }
    let mut root_ext = serde_json::Map::new();
    let mut used = vec![
        "KHR_materials_emissive_strength",
        "KHR_materials_transmission",
        "KHR_materials_ior",
        "KHR_materials_specular",
        "TESELA_emission",
    ];
    if !lights.is_empty() {
        root_ext.insert("KHR_lights_punctual".into(), json!({"lights": lights}));
        used.push("KHR_lights_punctual");
    }
    if scene.background.max_element() > 0.0 {
        let (c, s) = color_strength(scene.background);
        root_ext.insert("TESELA_world".into(), json!({"color": c, "strength": s}));
        used.push("TESELA_world");
    }
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&buf.bytes)
    );
    let doc = json!({
        "asset": {"version": "2.0", "generator": "Tesela export-builtin"},
        "extensionsUsed": used,
        "extensions": root_ext,
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": cameras,
        "accessors": buf.accessors,
        "bufferViews": buf.views,
        "buffers": [{"byteLength": buf.bytes.len(), "uri": uri}],
    });
    let text = serde_json::to_string_pretty(&doc).map_err(|e| e.to_string())?;
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}
