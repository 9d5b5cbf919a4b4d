//! Writes a large test scene for the memory benchmark (`bench/memory.sh`): the built-in
//! Cornell box with a finely tessellated displaced sphere, as one `.glb`.
//!
//! ```sh
//! cargo run --release --example big_scene -- OUT.glb [TRIANGLES] [INSTANCES]
//! ```
//!
//! TRIANGLES defaults to 10,000,000. With INSTANCES > 1 the sphere (of TRIANGLES triangles)
//! is placed INSTANCES times by `EXT_mesh_gpu_instancing` on a grid over the floor of the
//! box, each with its own size (a scatter).
//!
//! The sphere is a UV grid of `2 n × n` quads (`4 n²` triangles, the first `n` large enough
//! to reach TRIANGLES; the pole rows hold zero-area triangles, as real UV spheres do) with
//! per-vertex normals, u32 indices and its radius modulated by `sin(12θ) sin(12φ)`.
//! Buffer 0 is the GLB BIN chunk (the sphere); the box keeps its data-URI buffer as buffer 1.

use std::f32::consts::PI;
use std::io::{BufWriter, Write};

use serde_json::{Value, json};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = args.next().ok_or("usage: big_scene OUT.glb [TRIANGLES]")?;
    let want: u64 = match args.next() {
        Some(t) => t.parse()?,
        None => 10_000_000,
    };
    let instances: usize = match args.next() {
        Some(t) => t.parse()?,
        None => 1,
    };
    let n = ((want as f64 / 4.0).sqrt().ceil() as u32).max(2);
    let (nu, nv) = (2 * n, n);
    let verts = (nu + 1) as usize * (nv + 1) as usize;
    let tris = 2 * nu as usize * nv as usize;

    // The Cornell box through the exporter, then re-based on buffer 1.
    let tmp = std::env::temp_dir().join(format!("tesela-big-scene-{}.gltf", std::process::id()));
    let cornell = tesela::scene::builtin::cornell_box();
    tesela::scene::gltf_write::write(&cornell, &tmp)?;
    let mut doc: Value = serde_json::from_slice(&std::fs::read(&tmp)?)?;
    std::fs::remove_file(&tmp)?;
    for v in doc["bufferViews"].as_array_mut().ok_or("no bufferViews")? {
        v["buffer"] = json!(1);
    }

    // The sphere's binary data: positions, normals, indices.
    let (center, radius) = if instances > 1 {
        ([0.0f32; 3], 1.0f32)
    } else {
        ([0.0f32, 0.35, 0.05], 0.22f32)
    };
    let mut bin: Vec<u8> = Vec::with_capacity(verts * 24 + tris * 12);
    let mut normals: Vec<u8> = Vec::with_capacity(verts * 12);
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for j in 0..=nv {
        let theta = PI * j as f32 / nv as f32;
        for i in 0..=nu {
            let phi = 2.0 * PI * i as f32 / nu as f32;
            let n = [
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            ];
            let r = radius * (1.0 + 0.08 * (12.0 * theta).sin() * (12.0 * phi).sin());
            for k in 0..3 {
                let p = center[k] + r * n[k];
                lo[k] = lo[k].min(p);
                hi[k] = hi[k].max(p);
                bin.extend_from_slice(&p.to_le_bytes());
                normals.extend_from_slice(&n[k].to_le_bytes());
            }
        }
    }
    bin.extend_from_slice(&normals);
    drop(normals);
    let row = nu + 1;
    for j in 0..nv {
        for i in 0..nu {
            let a = j * row + i;
            let (b, c, d) = (a + 1, a + row + 1, a + row);
            for idx in [a, d, c, a, c, b] {
                bin.extend_from_slice(&idx.to_le_bytes());
            }
        }
    }

    // Placements: a `side × side` grid over the floor (x, z in [-0.45, 0.45]), sizes varying.
    let inst_at = bin.len();
    let side = (instances as f64).sqrt().ceil() as usize;
    let cell = 0.9 / side as f32;
    if instances > 1 {
        let mut scales = Vec::with_capacity(instances * 12);
        for k in 0..instances {
            let (i, j) = (k % side, k / side);
            let r = cell * (0.25 + 0.2 * ((k as f32 * 0.618_034).fract()));
            let t = [
                -0.45 + cell * (i as f32 + 0.5),
                r,
                -0.45 + cell * (j as f32 + 0.5),
            ];
            for v in t {
                bin.extend_from_slice(&v.to_le_bytes());
            }
            for v in [r, r * 0.8, r] {
                scales.extend_from_slice(&v.to_le_bytes());
            }
        }
        bin.extend_from_slice(&scales);
    }

    let views = doc["bufferViews"].as_array_mut().unwrap();
    let v0 = views.len();
    views.push(json!({"buffer": 0, "byteOffset": 0, "byteLength": verts * 12, "target": 34962}));
    views.push(
        json!({"buffer": 0, "byteOffset": verts * 12, "byteLength": verts * 12, "target": 34962}),
    );
    views.push(
        json!({"buffer": 0, "byteOffset": verts * 24, "byteLength": tris * 12, "target": 34963}),
    );
    let accessors = doc["accessors"].as_array_mut().ok_or("no accessors")?;
    let a0 = accessors.len();
    accessors.push(
        json!({"bufferView": v0, "componentType": 5126, "count": verts,
        "type": "VEC3", "min": lo, "max": hi}),
    );
    accessors
        .push(json!({"bufferView": v0 + 1, "componentType": 5126, "count": verts, "type": "VEC3"}));
    accessors.push(
        json!({"bufferView": v0 + 2, "componentType": 5125, "count": tris * 3, "type": "SCALAR"}),
    );
    let materials = doc["materials"].as_array_mut().ok_or("no materials")?;
    materials.push(json!({"name": "sphere", "pbrMetallicRoughness": {
        "baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.5}}));
    let mat = materials.len() - 1;
    let meshes = doc["meshes"].as_array_mut().ok_or("no meshes")?;
    meshes.push(json!({"name": "sphere", "primitives": [{"attributes":
        {"POSITION": a0, "NORMAL": a0 + 1}, "indices": a0 + 2, "material": mat}]}));
    let mesh = meshes.len() - 1;
    let mut node = json!({"name": "sphere", "mesh": mesh});
    if instances > 1 {
        let views = doc["bufferViews"].as_array_mut().unwrap();
        let v = views.len();
        for k in 0..2 {
            views.push(
                json!({"buffer": 0, "byteOffset": inst_at + k * instances * 12,
                "byteLength": instances * 12}),
            );
        }
        let accessors = doc["accessors"].as_array_mut().unwrap();
        let a = accessors.len();
        for k in 0..2 {
            accessors.push(json!({"bufferView": v + k, "componentType": 5126,
                "count": instances, "type": "VEC3"}));
        }
        node["extensions"] = json!({"EXT_mesh_gpu_instancing":
            {"attributes": {"TRANSLATION": a, "SCALE": a + 1}}});
        match doc["extensionsUsed"].as_array_mut() {
            Some(used) => used.push(json!("EXT_mesh_gpu_instancing")),
            None => doc["extensionsUsed"] = json!(["EXT_mesh_gpu_instancing"]),
        }
    }
    let nodes = doc["nodes"].as_array_mut().ok_or("no nodes")?;
    nodes.push(node);
    let node = nodes.len() - 1;
    doc["scenes"][0]["nodes"]
        .as_array_mut()
        .ok_or("no scene")?
        .push(json!(node));
    let box_buffer = doc["buffers"][0].clone();
    doc["buffers"] = json!([{"byteLength": bin.len()}, box_buffer]);

    let mut json = serde_json::to_vec(&doc)?;
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let total = u32::try_from(total).map_err(|_| "scene too large for one GLB (4 GiB)")?;
    let mut f = BufWriter::new(std::fs::File::create(&out)?);
    f.write_all(b"glTF")?;
    f.write_all(&2u32.to_le_bytes())?;
    f.write_all(&total.to_le_bytes())?;
    f.write_all(&(json.len() as u32).to_le_bytes())?;
    f.write_all(b"JSON")?;
    f.write_all(&json)?;
    f.write_all(&(bin.len() as u32).to_le_bytes())?;
    f.write_all(b"BIN\0")?;
    f.write_all(&bin)?;
    f.flush()?;
    println!(
        "{out}: {} triangles ({tris} in the sphere, {verts} vertices, placed {instances} times), {:.1} MB",
        tris * instances + cornell.triangle_count(),
        total as f64 / 1e6
    );
    Ok(())
}
