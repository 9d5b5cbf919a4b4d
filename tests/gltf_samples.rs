//! Loads every variant of the Khronos sample corpus in `../shared/gltf-samples` and checks
//! it against values read from the files themselves (triangle counts and world bounds
//! computed independently from the JSON and buffers; material, light, camera and sampler
//! values copied from the JSON).

use std::path::{Path, PathBuf};

use glam::Vec3;
use tesela::scene::gltf::{load, load_from_slice};
use tesela::scene::{Light, LoadErrorKind, Projection, Scene, Wrap};

fn samples_dir() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/gltf-samples");
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("note: {} is absent; sample tests skipped", dir.display());
        None
    }
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            walk(&p, out);
        } else if matches!(
            p.extension().and_then(|e| e.to_str()),
            Some("gltf") | Some("glb")
        ) {
            out.push(p);
        }
    }
}

/// (variant path, triangles, world bounds min, max), computed from the files by a separate
/// script (accessors, sparse data, default morph weights and node transforms evaluated
/// independently of the loader).
const EXPECTED: &[(&str, usize, [f32; 3], [f32; 3])] = &[
    (
        "AnimatedMorphCube/glTF/AnimatedMorphCube.gltf",
        12,
        [-1.0000, -1.0000, -1.0000],
        [1.0000, 1.0000, 1.0000],
    ),
    (
        "AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb",
        12,
        [-1.0000, -1.0000, -1.0000],
        [1.0000, 1.0000, 1.0000],
    ),
    (
        "AnimatedMorphCube/glTF-Quantized/AnimatedMorphCube.gltf",
        12,
        [-1.0000, -1.0000, -1.0000],
        [1.0000, 1.0000, 1.0000],
    ),
    (
        "Box With Spaces/glTF/Box With Spaces.gltf",
        12,
        [-1.0000, -1.0000, -1.0000],
        [1.0000, 1.0000, 1.0000],
    ),
    (
        "Box/glTF/Box.gltf",
        12,
        [-0.5000, -0.5000, -0.5000],
        [0.5000, 0.5000, 0.5000],
    ),
    (
        "Box/glTF-Draco/Box.gltf",
        12,
        [-0.5000, -0.5000, -0.5000],
        [0.5000, 0.5000, 0.5000],
    ),
    (
        "Box/glTF-Binary/Box.glb",
        12,
        [-0.5000, -0.5000, -0.5000],
        [0.5000, 0.5000, 0.5000],
    ),
    (
        "Box/glTF-Embedded/Box.gltf",
        12,
        [-0.5000, -0.5000, -0.5000],
        [0.5000, 0.5000, 0.5000],
    ),
    (
        "BoxInterleaved/glTF/BoxInterleaved.gltf",
        12,
        [-0.5000, -0.5000, -0.5000],
        [0.5000, 0.5000, 0.5000],
    ),
    (
        "BoxInterleaved/glTF-Binary/BoxInterleaved.glb",
        12,
        [-0.5000, -0.5000, -0.5000],
        [0.5000, 0.5000, 0.5000],
    ),
    (
        "BoxInterleaved/glTF-Embedded/BoxInterleaved.gltf",
        12,
        [-0.5000, -0.5000, -0.5000],
        [0.5000, 0.5000, 0.5000],
    ),
    (
        "BoxTextured/glTF/BoxTextured.gltf",
        12,
        [-0.5000, -0.5000, -0.5000],
        [0.5000, 0.5000, 0.5000],
    ),
    (
        "BoxTextured/glTF-Binary/BoxTextured.glb",
        12,
        [-0.5000, -0.5000, -0.5000],
        [0.5000, 0.5000, 0.5000],
    ),
    (
        "BoxTextured/glTF-Embedded/BoxTextured.gltf",
        12,
        [-0.5000, -0.5000, -0.5000],
        [0.5000, 0.5000, 0.5000],
    ),
    (
        "BoxVertexColors/glTF/BoxVertexColors.gltf",
        12,
        [0.0000, 0.0000, 0.0000],
        [1.0000, 1.0000, 1.0000],
    ),
    (
        "BoxVertexColors/glTF-Binary/BoxVertexColors.glb",
        12,
        [0.0000, 0.0000, 0.0000],
        [1.0000, 1.0000, 1.0000],
    ),
    (
        "BoxVertexColors/glTF-Embedded/BoxVertexColors.gltf",
        12,
        [0.0000, 0.0000, 0.0000],
        [1.0000, 1.0000, 1.0000],
    ),
    (
        "Cameras/glTF/Cameras.gltf",
        2,
        [0.0000, 0.0000, -0.7076],
        [1.0000, 0.7066, 0.0000],
    ),
    (
        "Cameras/glTF-Embedded/Cameras.gltf",
        2,
        [0.0000, 0.0000, -0.7076],
        [1.0000, 0.7066, 0.0000],
    ),
    (
        "EmissiveStrengthTest/glTF/EmissiveStrengthTest.gltf",
        90,
        [-8.0026, -6.0011, -2.0000],
        [8.0011, 4.0094, 1.9989],
    ),
    (
        "EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb",
        90,
        [-8.0026, -6.0011, -2.0000],
        [8.0011, 4.0094, 1.9989],
    ),
    (
        "IridescenceSuzanne/glTF/IridescenceSuzanne.gltf",
        11808,
        [-4.3259, -0.9705, -0.7783],
        [4.3259, 0.9392, 0.8223],
    ),
    (
        "MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf",
        16,
        [-2.8660, -4.0000, 0.0000],
        [2.8660, -2.0000, 0.0000],
    ),
    (
        "MeshPrimitiveModes/glTF-Embedded/MeshPrimitiveModes.gltf",
        16,
        [-2.8660, -4.0000, 0.0000],
        [2.8660, -2.0000, 0.0000],
    ),
    (
        "MorphPrimitivesTest/glTF/MorphPrimitivesTest.gltf",
        32,
        [-0.5000, 0.0000, -0.5000],
        [0.5000, 0.1000, 0.5000],
    ),
    (
        "MorphPrimitivesTest/glTF-Binary/MorphPrimitivesTest.glb",
        32,
        [-0.5000, 0.0000, -0.5000],
        [0.5000, 0.1000, 0.5000],
    ),
    (
        "MorphPrimitivesTest/glTF-Draco/MorphPrimitivesTest.gltf",
        32,
        [-0.5000, 0.0000, -0.5000],
        [0.5000, 0.1000, 0.5000],
    ),
    (
        "MultipleScenes/glTF/MultipleScenes.gltf",
        2,
        [0.0000, 0.0000, 0.0000],
        [1.0000, 1.0000, 0.0000],
    ),
    (
        "MultipleScenes/glTF-Embedded/MultipleScenes.gltf",
        2,
        [0.0000, 0.0000, 0.0000],
        [1.0000, 1.0000, 0.0000],
    ),
    (
        "NegativeScaleTest/glTF/NegativeScaleTest.gltf",
        7724,
        [-5.1617, -4.4535, -0.5000],
        [5.1617, 4.4535, 0.5000],
    ),
    (
        "NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb",
        7724,
        [-5.1617, -4.4535, -0.5000],
        [5.1617, 4.4535, 0.5000],
    ),
    (
        "OrientationTest/glTF/OrientationTest.gltf",
        524,
        [-5.3307, -5.3307, -5.3307],
        [5.3307, 5.3307, 5.3307],
    ),
    (
        "OrientationTest/glTF-Binary/OrientationTest.glb",
        524,
        [-5.3307, -5.3307, -5.3307],
        [5.3307, 5.3307, 5.3307],
    ),
    (
        "OrientationTest/glTF-Embedded/OrientationTest.gltf",
        524,
        [-5.3307, -5.3307, -5.3307],
        [5.3307, 5.3307, 5.3307],
    ),
    (
        "SimpleMeshes/glTF/SimpleMeshes.gltf",
        2,
        [0.0000, 0.0000, 0.0000],
        [2.0000, 1.0000, 0.0000],
    ),
    (
        "SimpleMeshes/glTF-Embedded/SimpleMeshes.gltf",
        2,
        [0.0000, 0.0000, 0.0000],
        [2.0000, 1.0000, 0.0000],
    ),
    (
        "SimpleSparseAccessor/glTF/SimpleSparseAccessor.gltf",
        12,
        [0.0000, 0.0000, 0.0000],
        [6.0000, 4.0000, 0.0000],
    ),
    (
        "SimpleSparseAccessor/glTF-Embedded/SimpleSparseAccessor.gltf",
        12,
        [0.0000, 0.0000, 0.0000],
        [6.0000, 4.0000, 0.0000],
    ),
    (
        "SpecularTest/glTF/SpecularTest.gltf",
        44828,
        [-0.7508, -0.3800, -0.0500],
        [0.3750, 0.3800, 0.0500],
    ),
    (
        "TextureCoordinateTest/glTF/TextureCoordinateTest.gltf",
        10,
        [-1.2000, -1.2000, -0.0526],
        [1.2000, 1.2000, 0.0000],
    ),
    (
        "TextureCoordinateTest/glTF-Binary/TextureCoordinateTest.glb",
        10,
        [-1.2000, -1.2000, -0.0526],
        [1.2000, 1.2000, 0.0000],
    ),
    (
        "TextureCoordinateTest/glTF-Embedded/TextureCoordinateTest.gltf",
        10,
        [-1.2000, -1.2000, -0.0526],
        [1.2000, 1.2000, 0.0000],
    ),
    (
        "TextureSettingsTest/glTF/TextureSettingsTest.gltf",
        72,
        [-5.1617, -5.6186, -0.1500],
        [5.1617, 4.4535, 0.1000],
    ),
    (
        "TextureSettingsTest/glTF-Binary/TextureSettingsTest.glb",
        72,
        [-5.1617, -5.6186, -0.1500],
        [5.1617, 4.4535, 0.1000],
    ),
    (
        "TextureSettingsTest/glTF-Embedded/TextureSettingsTest.gltf",
        72,
        [-5.1617, -5.6186, -0.1500],
        [5.1617, 4.4535, 0.1000],
    ),
    (
        "TextureTransformTest/glTF/TextureTransformTest.gltf",
        24,
        [-1.6000, -1.1413, 0.0000],
        [1.6000, 1.0500, 0.0100],
    ),
    (
        "TransmissionRoughnessTest/glTF/TransmissionRoughnessTest.gltf",
        77792,
        [-1.0000, -0.4500, -0.1500],
        [1.0000, 0.4500, 0.3500],
    ),
    (
        "Triangle/glTF/Triangle.gltf",
        1,
        [0.0000, 0.0000, 0.0000],
        [1.0000, 1.0000, 0.0000],
    ),
    (
        "Triangle/glTF-Embedded/Triangle.gltf",
        1,
        [0.0000, 0.0000, 0.0000],
        [1.0000, 1.0000, 0.0000],
    ),
    (
        "TriangleWithoutIndices/glTF/TriangleWithoutIndices.gltf",
        1,
        [0.0000, 0.0000, 0.0000],
        [1.0000, 1.0000, 0.0000],
    ),
    (
        "TriangleWithoutIndices/glTF-Embedded/TriangleWithoutIndices.gltf",
        1,
        [0.0000, 0.0000, 0.0000],
        [1.0000, 1.0000, 0.0000],
    ),
    (
        "Unicode❤♻Test/glTF/Unicode❤♻Test.gltf",
        2,
        [0.0000, 0.0000, 0.0000],
        [1.0000, 1.0000, 0.0000],
    ),
    (
        "Unicode❤♻Test/glTF-Binary/Unicode❤♻Test.glb",
        2,
        [0.0000, 0.0000, 0.0000],
        [1.0000, 1.0000, 0.0000],
    ),
];

fn sample(dir: &Path, rel: &str) -> Scene {
    let p = dir.join(rel);
    load(&p).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// Properties every loaded scene must have.
fn check_invariants(rel: &str, s: &Scene) {
    for m in &s.meshes {
        assert!(
            !m.indices.is_empty(),
            "{rel}: mesh {} has no triangles",
            m.name
        );
        let n = m.positions.len();
        assert!(
            m.positions.iter().all(|p| p.is_finite()),
            "{rel}: {}",
            m.name
        );
        for t in &m.indices {
            assert!(
                t.iter().all(|&i| (i as usize) < n),
                "{rel}: {} index out of range",
                m.name
            );
        }
        assert!(
            m.normals.is_empty() || m.normals.len() == n,
            "{rel}: {}",
            m.name
        );
        for nrm in &m.normals {
            assert!(
                (nrm.length() - 1.0).abs() < 1e-4,
                "{rel}: {} normal {nrm}",
                m.name
            );
        }
        assert!(m.uvs.is_empty() || m.uvs.len() == n, "{rel}: {}", m.name);
        assert!(m.material < s.materials.len(), "{rel}: {}", m.name);
    }
    for mat in &s.materials {
        for t in [
            mat.base_color_texture,
            mat.metallic_roughness_texture,
            mat.emission_texture,
        ]
        .into_iter()
        .flatten()
        {
            let tex = &s.textures[t.texture];
            let img = &s.images[tex.image];
            assert_eq!(img.rgba8.len(), (img.width * img.height) as usize, "{rel}");
        }
    }
}

#[test]
fn every_variant_loads_with_the_expected_geometry() {
    let Some(dir) = samples_dir() else { return };
    let mut files = Vec::new();
    walk(&dir, &mut files);
    assert!(files.len() >= 53, "only {} sample files found", files.len());
    let mut matched = vec![false; EXPECTED.len()];
    for p in &files {
        let rel = p
            .strip_prefix(&dir)
            .unwrap()
            .to_str()
            .unwrap()
            .replace('\\', "/");
        let s = load(p).unwrap_or_else(|e| panic!("{rel}: {e}"));
        check_invariants(&rel, &s);
        let k = EXPECTED
            .iter()
            .position(|(r, ..)| *r == rel)
            .unwrap_or_else(|| panic!("{rel}: no expected values for this variant"));
        matched[k] = true;
        let (_, tris, lo, hi) = EXPECTED[k];
        assert_eq!(
            s.instanced_triangle_count() as usize,
            tris,
            "{rel}: triangle count"
        );
        let (blo, bhi) = s.bounds().unwrap();
        assert!(
            blo.abs_diff_eq(Vec3::from(lo), 2e-3) && bhi.abs_diff_eq(Vec3::from(hi), 2e-3),
            "{rel}: bounds {blo}..{bhi}, expected {lo:?}..{hi:?}"
        );
    }
    for (k, m) in matched.iter().enumerate() {
        assert!(m, "{} was not found in the corpus", EXPECTED[k].0);
    }
}

/// Triangle centroids (compared as sets: an encoder reorders vertices and triangles).
fn centroids(s: &Scene) -> Vec<Vec3> {
    s.meshes
        .iter()
        .flat_map(|m| {
            m.indices
                .iter()
                .map(|t| t.iter().map(|&i| m.positions[i as usize]).sum::<Vec3>() / 3.0)
        })
        .collect()
}

#[test]
fn draco_variants_decode_to_the_uncompressed_geometry() {
    let Some(dir) = samples_dir() else { return };
    for (plain, draco, tol) in [
        ("Box/glTF/Box.gltf", "Box/glTF-Draco/Box.gltf", 1e-6),
        // Positions quantized (the encoder's default is 11 bits) over a unit box.
        (
            "MorphPrimitivesTest/glTF/MorphPrimitivesTest.gltf",
            "MorphPrimitivesTest/glTF-Draco/MorphPrimitivesTest.gltf",
            1e-3,
        ),
    ] {
        let (a, b) = (sample(&dir, plain), sample(&dir, draco));
        let (ca, cb) = (centroids(&a), centroids(&b));
        assert_eq!(ca.len(), cb.len(), "{draco}");
        for p in &ca {
            let near = cb
                .iter()
                .map(|q| (*q - *p).abs().max_element())
                .fold(f32::MAX, f32::min);
            assert!(near <= tol, "{draco}: no triangle within {near} of {p}");
        }
        // Normals (the shading of the normals view) agree pixel by pixel away from edges.
        let (ia, ib) = (
            render_scene(a, "normals", 48, 48, 4),
            render_scene(b, "normals", 48, 48, 4),
        );
        let off = ia
            .pixels
            .iter()
            .zip(&ib.pixels)
            .filter(|(p, q)| (0..3).any(|k| (p[k] - q[k]).abs() > 0.01))
            .count();
        assert!(
            off * 50 <= ia.pixels.len(),
            "{draco}: {off} of {} pixels differ",
            ia.pixels.len()
        );
    }
}

fn material<'a>(s: &'a Scene, name: &str) -> &'a tesela::scene::Material {
    s.materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name}"))
}

#[test]
fn emissive_strength_multiplies_the_emissive_factor() {
    let Some(dir) = samples_dir() else { return };
    for rel in [
        "EmissiveStrengthTest/glTF/EmissiveStrengthTest.gltf",
        "EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb",
    ] {
        let s = sample(&dir, rel);
        for (name, k) in [
            ("Emit1", 1.0),
            ("Emit2", 2.0),
            ("Emit4", 4.0),
            ("Emit8", 8.0),
            ("Emit16", 16.0),
        ] {
            let m = material(&s, name);
            let want = Vec3::new(0.1, 0.5, 0.9) * k;
            assert!(
                m.emission.abs_diff_eq(want, 1e-5),
                "{rel} {name}: {}",
                m.emission
            );
            // Not double-sided, no TESELA_emission: front only.
            assert!(!m.emission_two_sided);
        }
        assert!(!material(&s, "FlatBackdrop").is_emissive());
    }
}

#[test]
fn transmission_and_ior() {
    let Some(dir) = samples_dir() else { return };
    let s = sample(
        &dir,
        "TransmissionRoughnessTest/glTF/TransmissionRoughnessTest.gltf",
    );
    for (name, ior) in [
        ("Mat_IOR_1.0", 1.0),
        ("Mat_IOR_1.33", 1.33),
        ("Mat_IOR_1.50", 1.5),
        ("Mat_IOR_1.76", 1.76),
        ("Mat_IOR_2.42", 2.42),
    ] {
        let m = material(&s, name);
        assert_eq!(m.transmission, 1.0, "{name}");
        assert!((m.ior - ior).abs() < 1e-6, "{name}: {}", m.ior);
    }
    let opaque = material(&s, "Mat_Opaque");
    assert_eq!(opaque.transmission, 0.0);
    assert!((material(&s, "LabelMat").roughness - 0.8).abs() < 1e-6);
    // KHR_materials_volume: 5 mm thick, clear (no attenuation): what a solid dielectric
    // renders, so nothing to report.
    let v = material(&s, "Mat_IOR_1.50").volume.expect("volume");
    assert!((v.thickness - 0.005).abs() < 1e-9);
    assert!(v.attenuation_distance.is_infinite());
    assert!(
        !s.warnings
            .iter()
            .any(|w| w.contains("KHR_materials_volume")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn specular_extension() {
    let Some(dir) = samples_dir() else { return };
    let s = sample(&dir, "SpecularTest/glTF/SpecularTest.gltf");
    let mut factors: Vec<f32> = s.materials.iter().map(|m| m.specular).collect();
    factors.sort_by(f32::total_cmp);
    factors.dedup();
    // specularFactor values in the file: 0, 0.051269, 0.212231, 0.520996, 1 (default 1).
    for want in [0.0, 0.051269, 0.212231, 0.520996, 1.0] {
        assert!(
            factors.iter().any(|f| (f - want).abs() < 1e-6),
            "{want} not in {factors:?}"
        );
    }
    assert!(s.materials.iter().any(|m| {
        m.specular_color
            .abs_diff_eq(Vec3::new(0.212231, 0.212231, 0.0), 1e-6)
    }));
}

#[test]
fn directional_light_and_ior_in_iridescence_suzanne() {
    let Some(dir) = samples_dir() else { return };
    let s = sample(&dir, "IridescenceSuzanne/glTF/IridescenceSuzanne.gltf");
    assert_eq!(s.lights.len(), 1);
    match &s.lights[0] {
        Light::Directional {
            direction,
            irradiance,
            angle,
        } => {
            // intensity 2 lux, white; the node has only a translation: light along -Z.
            assert!(
                irradiance.abs_diff_eq(Vec3::splat(2.0 / 683.0), 1e-7),
                "{irradiance}"
            );
            assert!(direction.abs_diff_eq(-Vec3::Z, 1e-6), "{direction}");
            assert_eq!(*angle, 0.0);
        }
        other => panic!("expected a directional light, got {other:?}"),
    }
    let mut iors: Vec<f32> = s.materials.iter().map(|m| m.ior).collect();
    iors.sort_by(f32::total_cmp);
    assert_eq!(iors, vec![1.5, 1.5, 2.0]);
}

#[test]
fn cameras_use_the_first_camera_node() {
    let Some(dir) = samples_dir() else { return };
    for rel in [
        "Cameras/glTF/Cameras.gltf",
        "Cameras/glTF-Embedded/Cameras.gltf",
    ] {
        let s = sample(&dir, rel);
        let c = s.camera.expect("camera");
        assert_eq!(c.projection, Projection::Perspective { yfov: 0.7 });
        assert_eq!(c.aspect, Some(1.0));
        let t = c.to_world.w_axis.truncate();
        assert!(t.abs_diff_eq(Vec3::new(0.5, 0.5, 3.0), 1e-6), "{t}");
        assert!(c.to_world.z_axis.truncate().abs_diff_eq(Vec3::Z, 1e-6));
    }
}

#[test]
fn samplers_textures_and_double_sided() {
    let Some(dir) = samples_dir() else { return };
    for rel in [
        "TextureSettingsTest/glTF/TextureSettingsTest.gltf",
        "TextureSettingsTest/glTF-Embedded/TextureSettingsTest.gltf",
        "TextureSettingsTest/glTF-Binary/TextureSettingsTest.glb",
    ] {
        let s = sample(&dir, rel);
        let tex = |name: &str| {
            let t = material(&s, name).base_color_texture.expect(name);
            &s.textures[t.texture]
        };
        let t = tex("TextureClampMaterialT");
        assert_eq!(
            (t.wrap_s, t.wrap_t),
            (Wrap::Repeat, Wrap::ClampToEdge),
            "{rel}"
        );
        let t = tex("TextureClampMaterialS");
        assert_eq!(
            (t.wrap_s, t.wrap_t),
            (Wrap::ClampToEdge, Wrap::Repeat),
            "{rel}"
        );
        let t = tex("TextureMirrorMaterialT");
        assert_eq!(
            (t.wrap_s, t.wrap_t),
            (Wrap::Repeat, Wrap::MirroredRepeat),
            "{rel}"
        );
        let t = tex("TextureMirrorMaterialS");
        assert_eq!(
            (t.wrap_s, t.wrap_t),
            (Wrap::MirroredRepeat, Wrap::Repeat),
            "{rel}"
        );
        assert!(!t.nearest);
        assert!(material(&s, "DoubleSidedMaterial").double_sided);
        assert!(material(&s, "DoubleSidedMaterial").emission_two_sided);
        assert!(!material(&s, "SingleSidedMaterial").double_sided);
        // Three PNGs, 512x512 checkers and a 256x256 label sheet.
        assert_eq!(s.images.len(), 3, "{rel}");
        let mut dims: Vec<(u32, u32)> = s.images.iter().map(|i| (i.width, i.height)).collect();
        dims.sort();
        assert_eq!(dims, vec![(256, 256), (512, 512), (512, 512)], "{rel}");
    }
}

#[test]
fn png_and_jpeg_images_from_files_data_uris_and_buffer_views() {
    let Some(dir) = samples_dir() else { return };
    let mut first: Option<Vec<[u8; 4]>> = None;
    for rel in [
        "BoxTextured/glTF/BoxTextured.gltf",
        "BoxTextured/glTF-Embedded/BoxTextured.gltf",
        "BoxTextured/glTF-Binary/BoxTextured.glb",
    ] {
        let s = sample(&dir, rel);
        let m = &s.materials[0];
        assert_eq!(m.metallic, 0.0, "{rel}");
        assert_eq!(m.roughness, 1.0, "{rel}");
        let t = &s.textures[m.base_color_texture.expect("texture").texture];
        assert_eq!(
            (t.wrap_s, t.wrap_t, t.nearest),
            (Wrap::Repeat, Wrap::Repeat, false)
        );
        let img = &s.images[t.image];
        assert_eq!((img.width, img.height), (256, 256));
        // Same pixels whatever the storage.
        match &first {
            None => first = Some(img.rgba8.clone()),
            Some(f) => assert!(f == &img.rgba8, "{rel}: pixels differ"),
        }
        assert!(!s.meshes[0].uvs.is_empty());
    }
    for rel in [
        "MorphPrimitivesTest/glTF/MorphPrimitivesTest.gltf",
        "MorphPrimitivesTest/glTF-Binary/MorphPrimitivesTest.glb",
    ] {
        let s = sample(&dir, rel);
        assert_eq!(s.images.len(), 1, "{rel}");
        assert_eq!(
            (s.images[0].width, s.images[0].height),
            (512, 512),
            "{rel}: JPEG"
        );
    }
    for rel in [
        "Unicode❤♻Test/glTF/Unicode❤♻Test.gltf",
        "Box With Spaces/glTF/Box With Spaces.gltf",
    ] {
        let s = sample(&dir, rel);
        assert!(!s.images.is_empty(), "{rel}");
    }
}

#[test]
fn default_material_when_a_primitive_has_none() {
    let Some(dir) = samples_dir() else { return };
    let s = sample(&dir, "Triangle/glTF/Triangle.gltf");
    assert_eq!(s.materials.len(), 1);
    let m = &s.materials[0];
    assert_eq!(
        (m.base_color, m.metallic, m.roughness),
        (Vec3::ONE, 1.0, 1.0)
    );
    assert!(s.meshes[0].normals.is_empty(), "no NORMAL attribute");
}

#[test]
fn negative_scale_keeps_front_faces_front() {
    let Some(dir) = samples_dir() else { return };
    for rel in [
        "NegativeScaleTest/glTF/NegativeScaleTest.gltf",
        "NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb",
        "Box/glTF/Box.gltf",
        "OrientationTest/glTF/OrientationTest.gltf",
    ] {
        let s = sample(&dir, rel);
        let (mut agree, mut total) = (0usize, 0usize);
        for m in s.meshes.iter().filter(|m| !m.normals.is_empty()) {
            for t in &m.indices {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                let g = (b - a).cross(c - a);
                if g.length() < 1e-9 {
                    continue;
                }
                let n: Vec3 = t.iter().map(|&i| m.normals[i as usize]).sum();
                total += 1;
                if g.dot(n) > 0.0 {
                    agree += 1;
                }
            }
        }
        assert!(total > 0, "{rel}");
        assert!(
            agree as f64 >= 0.99 * total as f64,
            "{rel}: only {agree} of {total} triangles face along their normals"
        );
    }
}

#[test]
fn multiple_scenes_use_the_default_scene() {
    let Some(dir) = samples_dir() else { return };
    // `scene: 1` holds the square (2 triangles); scene 0 has the single triangle.
    let s = sample(&dir, "MultipleScenes/glTF/MultipleScenes.gltf");
    assert_eq!(s.triangle_count(), 2);
    assert_eq!(s.meshes[0].positions.len(), 4);
}

#[test]
fn primitive_modes_are_triangulated_or_skipped_with_a_warning() {
    let Some(dir) = samples_dir() else { return };
    let s = sample(&dir, "MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf");
    // TRIANGLES: 18 indices -> 6; STRIP: 6 -> 4; FAN: 8 -> 6.
    let mut counts: Vec<usize> = s.meshes.iter().map(|m| m.indices.len()).collect();
    counts.sort();
    assert_eq!(counts, vec![4, 6, 6]);
    for mode in ["POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"] {
        assert!(
            s.warnings.iter().any(|w| w.contains(mode)),
            "{mode}: {:?}",
            s.warnings
        );
    }
}

#[test]
fn morph_targets_use_the_default_weights() {
    let Some(dir) = samples_dir() else { return };
    // Base positions have y = 0; the target moves them by up to 0.2, at weight 0.5.
    let s = sample(&dir, "MorphPrimitivesTest/glTF/MorphPrimitivesTest.gltf");
    let (_, hi) = s.bounds().unwrap();
    assert!((hi.y - 0.1).abs() < 1e-6, "{hi}");
}

#[test]
fn quantized_cube_matches_the_float_cube() {
    let Some(dir) = samples_dir() else { return };
    let f = sample(&dir, "AnimatedMorphCube/glTF/AnimatedMorphCube.gltf");
    let q = sample(
        &dir,
        "AnimatedMorphCube/glTF-Quantized/AnimatedMorphCube.gltf",
    );
    assert_eq!(f.triangle_count(), q.triangle_count());
    let (fl, fh) = f.bounds().unwrap();
    let (ql, qh) = q.bounds().unwrap();
    assert!(fl.abs_diff_eq(ql, 1e-3) && fh.abs_diff_eq(qh, 1e-3));
    assert!(
        !q.meshes[0].normals.is_empty(),
        "normalized BYTE normals are read"
    );
}

#[test]
fn load_from_slice_refuses_external_files_without_a_base_dir() {
    let Some(dir) = samples_dir() else { return };
    let bytes = std::fs::read(dir.join("Box/glTF/Box.gltf")).unwrap();
    let e = load_from_slice(&bytes, None, "Box.gltf").unwrap_err();
    assert_eq!(e.kind, LoadErrorKind::Refused);
    assert!(
        e.to_string().starts_with("Box.gltf: buffer 0 (`Box0.bin`)"),
        "{e}"
    );
    // Self-contained variants load from memory.
    let bytes = std::fs::read(dir.join("Box/glTF-Embedded/Box.gltf")).unwrap();
    assert_eq!(
        load_from_slice(&bytes, None, "Box.gltf")
            .unwrap()
            .triangle_count(),
        12
    );
    let bytes = std::fs::read(dir.join("BoxTextured/glTF-Binary/BoxTextured.glb")).unwrap();
    assert_eq!(
        load_from_slice(&bytes, None, "x.glb").unwrap().images.len(),
        1
    );
}

// --- Renders of the samples whose materials use texture transforms, texture coordinate sets,
// vertex colours and normal maps, checked at pixels whose expected look was verified by eye
// against each sample's README (the view: an orthographic or perspective camera added to the
// file, the lights as stated).

/// Loads sample `rel` with its JSON changed by `edit` (resources still from its folder).
fn edited_sample(dir: &Path, rel: &str, edit: impl FnOnce(&mut serde_json::Value)) -> Scene {
    let p = dir.join(rel);
    let mut doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    edit(&mut doc);
    let bytes = serde_json::to_vec(&doc).unwrap();
    load_from_slice(&bytes, p.parent(), rel).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// Adds a camera node (`camera` is the glTF camera object) at `at`, looking down -Z.
fn add_camera(doc: &mut serde_json::Value, camera: serde_json::Value, at: [f32; 3]) {
    doc["cameras"] = serde_json::json!([camera]);
    let nodes = doc["nodes"].as_array_mut().unwrap();
    nodes.push(serde_json::json!({ "camera": 0, "translation": at }));
    let ni = nodes.len() - 1;
    let scene = doc["scene"].as_u64().unwrap_or(0) as usize;
    doc["scenes"][scene]["nodes"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!(ni));
}

fn render_scene(s: Scene, integrator: &str, w: u32, h: u32, spp: u32) -> tesela::render::Image {
    use tesela::render::{RenderOptions, render};
    let rs = tesela::render_scene::RenderScene::new(s, Default::default());
    let opts = RenderOptions {
        width: w,
        height: h,
        spp,
        max_depth: 2,
        integrator: integrator.into(),
        ..Default::default()
    };
    let (img, _) = render(
        &rs,
        &opts,
        &std::sync::atomic::AtomicBool::new(false),
        &|_, _, _| {},
    )
    .unwrap();
    img
}

fn px(img: &tesela::render::Image, x: u32, y: u32) -> Vec3 {
    let p = img.pixels[(y * img.width + x) as usize];
    Vec3::new(p[0], p[1], p[2])
}

#[test]
fn texture_transform_test_shows_every_arrow_on_its_green_marker() {
    let Some(dir) = samples_dir() else { return };
    let rel = "TextureTransformTest/glTF/TextureTransformTest.gltf";
    // The six quads span x in [-1.6, 1.6], y in [-1.05, 1.05]: an orthographic view of
    // [-1.7, 1.7] x [-1.275, 1.275] at 400x300, so world (x, y) is pixel
    // ((x + 1.7) / 3.4 * 400, (1.275 - y) / 2.55 * 300).
    let s = edited_sample(&dir, rel, |d| {
        add_camera(
            d,
            serde_json::json!({ "type": "orthographic",
                "orthographic": { "xmag": 1.7, "ymag": 1.275, "znear": 0.1, "zfar": 100 } }),
            [0.0, 0.0, 5.0],
        )
    });
    assert!(
        !s.warnings
            .iter()
            .any(|w| w.contains("KHR_texture_transform")),
        "{:?}",
        s.warnings
    );
    let img = render_scene(s, "albedo", 400, 300, 4);
    let at = |x: f32, y: f32| {
        px(
            &img,
            ((x + 1.7) / 3.4 * 400.0) as u32,
            ((1.275 - y) / 2.55 * 300.0) as u32,
        )
    };
    let near = |c: Vec3, want: Vec3, what: &str| {
        assert!(c.abs_diff_eq(want, 0.02), "{what}: {c}, expected {want}");
    };
    // Top row, the offsets: the UV texture's green (offset U), blue (V) and cyan (UV) quarters
    // with the check marks, not the yellow "not supported" quarter (sRGB 0.76 = linear 0.527).
    near(at(-1.5, 0.95), Vec3::new(0.0, 0.527, 0.0), "offset U");
    near(at(-0.4, 0.95), Vec3::new(0.0, 0.0, 0.527), "offset V");
    near(at(0.7, 0.95), Vec3::new(0.0, 0.527, 0.527), "offset UV");
    // Rotation (quad at (-1.1, -0.55)): the arrow runs from the top-left corner towards the green
    // marker at (-0.08, -0.52) of the quad; the unrotated arrow would lie on the diagonal
    // towards the yellow marker.
    near(at(-1.305, -0.761), Vec3::ZERO, "rotated arrow shaft");
    near(
        at(-0.95, -0.70),
        Vec3::ONE,
        "where the unrotated arrow would be",
    );
    // Scale (quad at (0, -0.55)): the arrow ends at the green marker near the quad's centre;
    // beyond it, where the unscaled arrow would go on, the texture is white.
    near(at(-0.1, -0.45), Vec3::ZERO, "scaled arrow shaft");
    near(at(0.15, -0.7), Vec3::ONE, "beyond the scaled arrow");
    // All three (quad at (1.1, -0.55)): the arrow crosses (0.85, -0.425) on its way to the
    // green marker; the clamped grey border shows at the bottom right.
    near(at(0.85, -0.425), Vec3::ZERO, "combined transform arrow");
    let border = at(1.3, -0.75);
    assert!(
        border.x > 0.6 && border.x < 0.9,
        "clamped grey border: {border}"
    );
}

#[test]
fn texture_coordinate_test_puts_each_corner_label_in_its_corner() {
    let Some(dir) = samples_dir() else { return };
    let rel = "TextureCoordinateTest/glTF/TextureCoordinateTest.gltf";
    // Orthographic view of [-1.3, 1.3]^2 at 260x260: world (x, y) is pixel
    // ((x + 1.3) * 100, (1.3 - y) * 100).
    let s = edited_sample(&dir, rel, |d| {
        add_camera(
            d,
            serde_json::json!({ "type": "orthographic",
                "orthographic": { "xmag": 1.3, "ymag": 1.3, "znear": 0.1, "zfar": 100 } }),
            [0.0, 0.0, 5.0],
        )
    });
    let img = render_scene(s, "albedo", 260, 260, 4);
    // The darkest pixel of a strip: the texture's corner checkers are black.
    let darkest = |xs: std::ops::Range<u32>, ys: std::ops::Range<u32>| {
        let mut m = f32::INFINITY;
        for y in ys {
            for x in xs.clone() {
                m = m.min(px(&img, x, y).max_element());
            }
        }
        m
    };
    // Top-left quad (x, y in [-1.2, -0.2] x [0.2, 1.2]): its checkers run along its outer top
    // edge (pixel rows 10..16), not along its bottom edge (rows 104..110).
    assert!(darkest(12..40, 10..16) < 0.1, "top-left checker");
    assert!(
        darkest(12..40, 104..110) > 0.5,
        "nothing at the top-left quad's bottom"
    );
    // Bottom-right quad (x, y in [0.2, 1.2] x [-1.2, -0.2]): checkers at its outer bottom edge.
    assert!(darkest(220..248, 244..250) < 0.1, "bottom-right checker");
    assert!(
        darkest(220..248, 150..156) > 0.5,
        "nothing at the bottom-right quad's top"
    );
}

#[test]
fn box_vertex_colors_multiply_the_default_material() {
    let Some(dir) = samples_dir() else { return };
    let rel = "BoxVertexColors/glTF/BoxVertexColors.gltf";
    // The unit cube [0, 1]^3 with COLOR_0 = position; seen from +Z (orthographic, [-0.1, 1.1]^2
    // at 120x120), the front face z = 1 shows albedo (x, y, 1).
    let s = edited_sample(&dir, rel, |d| {
        add_camera(
            d,
            serde_json::json!({ "type": "orthographic",
                "orthographic": { "xmag": 0.6, "ymag": 0.6, "znear": 0.1, "zfar": 100 } }),
            [0.5, 0.5, 5.0],
        )
    });
    assert!(s.materials[s.meshes[0].material].vertex_color);
    let img = render_scene(s, "albedo", 120, 120, 4);
    for (x, y) in [(0.1, 0.1), (0.9, 0.1), (0.5, 0.5), (0.2, 0.8), (0.9, 0.9)] {
        let (pxx, pxy) = (
            ((x + 0.1) / 1.2 * 120.0) as u32,
            ((1.1 - y) / 1.2 * 120.0) as u32,
        );
        // The pixel centre's world position.
        let cx = -0.1 + (pxx as f32 + 0.5) / 120.0 * 1.2;
        let cy = 1.1 - (pxy as f32 + 0.5) / 120.0 * 1.2;
        let c = px(&img, pxx, pxy);
        assert!(
            c.abs_diff_eq(Vec3::new(cx, cy, 1.0), 0.01),
            "({cx}, {cy}): {c}"
        );
    }
}

#[test]
fn box_with_spaces_normal_map_lights_the_faces_its_green_tilts_up() {
    let Some(dir) = samples_dir() else { return };
    let rel = "Box With Spaces/glTF/Box With Spaces.gltf";
    // A white Lambertian box with the sample's normal map, seen from +Z, lit by a sun from
    // above at a grazing 14 degrees to the front face. The logo is engraved: its grooves' lower
    // walls (green > 0.5 in the map, normals tilted towards the image's top) face the light and
    // are brighter than the flat face; the upper walls darker. An inverted green channel would
    // turn that around.
    let edit = |with_normals: bool| {
        move |d: &mut serde_json::Value| {
            let m = &mut d["materials"][0];
            m["pbrMetallicRoughness"] =
                serde_json::json!({ "metallicFactor": 0, "roughnessFactor": 1 });
            m["extensions"] =
                serde_json::json!({ "KHR_materials_specular": { "specularFactor": 0 } });
            if !with_normals {
                m.as_object_mut().unwrap().remove("normalTexture");
            }
            let th = (-76f32).to_radians();
            d["extensionsUsed"] =
                serde_json::json!(["KHR_lights_punctual", "KHR_materials_specular"]);
            d["extensions"] = serde_json::json!({ "KHR_lights_punctual": { "lights": [
                { "type": "directional", "intensity": 683.0 * 3.0 }] } });
            let nodes = d["nodes"].as_array_mut().unwrap();
            nodes.push(
                serde_json::json!({ "rotation": [(th / 2.0).sin(), 0, 0, (th / 2.0).cos()],
                "extensions": { "KHR_lights_punctual": { "light": 0 } } }),
            );
            let ni = nodes.len() - 1;
            d["scenes"][0]["nodes"]
                .as_array_mut()
                .unwrap()
                .push(serde_json::json!(ni));
            add_camera(
                d,
                serde_json::json!({ "type": "orthographic",
                    "orthographic": { "xmag": 1.0, "ymag": 1.0, "znear": 0.1, "zfar": 100 } }),
                [0.0, 0.0, 5.0],
            );
        }
    };
    let s = edited_sample(&dir, rel, edit(true));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert!(
        s.meshes
            .iter()
            .all(|m| m.attrs.tangents.len() == m.positions.len()),
        "MikkTSpace tangents"
    );
    // The normal map texel under each pixel of the front face (z = 1): found from the mesh.
    let mesh = s.meshes[0].clone();
    let nmap = {
        let t = s.materials[mesh.material].normal_texture.unwrap();
        s.images[s.textures[t.texture].image].clone()
    };
    let green_at = |x: f32, y: f32| -> Option<f32> {
        for (ti, t) in mesh.indices.iter().enumerate() {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            if (a.z - 1.0).abs() > 1e-4 || (b.z - 1.0).abs() > 1e-4 || (c.z - 1.0).abs() > 1e-4 {
                continue;
            }
            let (v0, v1, p) = (b - a, c - a, Vec3::new(x, y, 1.0) - a);
            let d = v0.x * v1.y - v1.x * v0.y;
            let b1 = (p.x * v1.y - v1.x * p.y) / d;
            let b2 = (v0.x * p.y - p.x * v0.y) / d;
            if b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 {
                continue;
            }
            let uv = mesh.uv(0, ti as u32, b1, b2);
            let tx = ((uv.x.rem_euclid(1.0)) * nmap.width as f32) as u32;
            let ty = ((uv.y.rem_euclid(1.0)) * nmap.height as f32) as u32;
            let texel = nmap.rgba8
                [(ty.min(nmap.height - 1) * nmap.width + tx.min(nmap.width - 1)) as usize];
            return Some(texel[1] as f32 / 255.0);
        }
        None
    };
    let n = 200;
    let lit = render_scene(s, "direct_ems", n, n, 4);
    let flat = render_scene(edited_sample(&dir, rel, edit(false)), "direct_ems", n, n, 4);
    // Over the front face: pixels whose texel tilts up (green > 0.6) against down (< 0.4).
    let (mut up, mut down) = (Vec::new(), Vec::new());
    for y in 0..n {
        for x in 0..n {
            let (wx, wy) = (
                -1.0 + (x as f32 + 0.5) / n as f32 * 2.0,
                1.0 - (y as f32 + 0.5) / n as f32 * 2.0,
            );
            let Some(g) = green_at(wx, wy) else { continue };
            let r = px(&lit, x, y).x / px(&flat, x, y).x.max(1e-6);
            if g > 0.6 {
                up.push(r);
            } else if g < 0.4 {
                down.push(r);
            }
        }
    }
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
    assert!(
        up.len() > 20 && down.len() > 20,
        "{} / {}",
        up.len(),
        down.len()
    );
    assert!(
        mean(&up) > 1.5,
        "upward-tilted texels are brighter: {}",
        mean(&up)
    );
    assert!(
        mean(&down) < 0.7,
        "downward-tilted texels are darker: {}",
        mean(&down)
    );
}
