//! Shared body of the fuzz targets.

use tesela::emitter::LightChoice;
use tesela::render_scene::RenderScene;
use tesela::scene::gltf::load_from_slice;

/// Loads `data` (a `.glb` when `glb`, else `.gltf` JSON). A load error is fine; a panic, an
/// abort, a hang or unbounded memory is a finding. A scene that loads is also prepared for
/// rendering (BVH, emitters) and one ray per pixel of an 8x8 image is traced, so the
/// loader's output is checked against what the renderer assumes.
pub fn check(data: &[u8], glb: bool) {
    let scene = if glb {
        // Keep the fuzzer's bytes but make the 12-byte header valid about half the time:
        // the low bit of the first byte chooses, so both paths stay reachable.
        let fix = data.first().is_some_and(|b| b & 1 == 1);
        if fix && data.len() >= 12 {
            let mut v = data.to_vec();
            v[..4].copy_from_slice(b"glTF");
            v[4..8].copy_from_slice(&2u32.to_le_bytes());
            let n = v.len() as u32;
            v[8..12].copy_from_slice(&n.to_le_bytes());
            load_from_slice(&v, None, "fuzz.glb")
        } else {
            load_from_slice(data, None, "fuzz.glb")
        }
    } else {
        load_from_slice(data, None, "fuzz.gltf")
    };
    let Ok(scene) = scene else { return };
    // Bound the render work: a huge (but legal) scene is the memory test's business.
    if scene.triangle_count() > 100_000 {
        return;
    }
    let rs = RenderScene::new(scene, LightChoice::Power);
    let opts = tesela::render::RenderOptions {
        width: 8,
        height: 8,
        spp: 1,
        max_depth: 4,
        threads: 1,
        ..Default::default()
    };
    let cancel = std::sync::atomic::AtomicBool::new(false);
    if let Ok((img, _)) = tesela::render::render(&rs, &opts, &cancel, &|_, _, _| {}) {
        for p in &img.pixels {
            assert!(p.iter().all(|c| c.is_finite()), "non-finite pixel {p:?}");
        }
    }
}
