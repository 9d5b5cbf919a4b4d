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
    let mut draco = 0;
    for p in &files {
        let rel = p
            .strip_prefix(&dir)
            .unwrap()
            .to_str()
            .unwrap()
            .replace('\\', "/");
        if rel.contains("glTF-Draco") {
            let e = load(p).expect_err(&rel);
            assert!(
                e.to_string().contains("KHR_draco_mesh_compression"),
                "{rel}: {e}"
            );
            draco += 1;
            continue;
        }
        let s = load(p).unwrap_or_else(|e| panic!("{rel}: {e}"));
        check_invariants(&rel, &s);
        let k = EXPECTED
            .iter()
            .position(|(r, ..)| *r == rel)
            .unwrap_or_else(|| panic!("{rel}: no expected values for this variant"));
        matched[k] = true;
        let (_, tris, lo, hi) = EXPECTED[k];
        assert_eq!(s.triangle_count(), tris, "{rel}: triangle count");
        let (blo, bhi) = s.bounds().unwrap();
        assert!(
            blo.abs_diff_eq(Vec3::from(lo), 2e-3) && bhi.abs_diff_eq(Vec3::from(hi), 2e-3),
            "{rel}: bounds {blo}..{bhi}, expected {lo:?}..{hi:?}"
        );
    }
    assert_eq!(draco, 2, "the two Draco variants");
    for (k, m) in matched.iter().enumerate() {
        assert!(m, "{} was not found in the corpus", EXPECTED[k].0);
    }
}

#[test]
fn draco_variants_fail_with_a_clear_error() {
    let Some(dir) = samples_dir() else { return };
    for rel in [
        "Box/glTF-Draco/Box.gltf",
        "MorphPrimitivesTest/glTF-Draco/MorphPrimitivesTest.gltf",
    ] {
        let e = load(&dir.join(rel)).expect_err(rel);
        assert_eq!(e.kind, LoadErrorKind::Unsupported);
        let msg = e.to_string();
        assert!(
            msg.contains("unsupported required extension `KHR_draco_mesh_compression`"),
            "{msg}"
        );
        assert!(
            msg.contains(rel.rsplit('/').next().unwrap()),
            "names the file: {msg}"
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
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("KHR_materials_volume"))
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
