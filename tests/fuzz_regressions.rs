//! Loads every file of `tests/fuzz_corpus/` (the minimized corpus of the `fuzz/` targets
//! and the inputs that once crashed them): no input may panic, errors are fine. Inputs that
//! load are also prepared for rendering and traced at 4x4 pixels, as the fuzz targets do.
//!
//! Layout: `tests/fuzz_corpus/gltf_json/*` are `.gltf` JSON inputs, `tests/fuzz_corpus/glb/*`
//! `.glb` inputs (loaded as they are and, as the glb target does, with a repaired 12-byte
//! header), and `tests/fuzz_corpus/crashes/*` inputs that once crashed a target (any kind).
//! Refresh with `fuzz/run.sh` and a `-merge=1` into these folders (see `fuzz/README.md`).

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use tesela::emitter::LightChoice;
use tesela::render::{self, RenderOptions};
use tesela::render_scene::RenderScene;
use tesela::scene::gltf::load_from_slice;

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_corpus")
}

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| rd.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    out.retain(|p| p.is_file());
    out.sort();
    out
}

/// Loads `bytes` without a base folder (external files are refused) and, if they load,
/// renders a few pixels with every integrator. Returns whether the input loaded.
fn check(path: &Path, bytes: &[u8]) -> bool {
    let name = path.display().to_string();
    let result = std::panic::catch_unwind(|| {
        let Ok(scene) = load_from_slice(bytes, None, &name) else {
            return false;
        };
        if scene.triangle_count() <= 100_000 {
            let rs = RenderScene::new(scene, LightChoice::Power);
            for integrator in tesela::integrator::NAMES {
                let opts = RenderOptions {
                    width: 4,
                    height: 4,
                    spp: 1,
                    max_depth: 4,
                    threads: 1,
                    integrator: integrator.into(),
                    ..Default::default()
                };
                let (img, _) =
                    render::render(&rs, &opts, &AtomicBool::new(false), &|_, _, _| {}).unwrap();
                assert!(img.pixels.iter().flatten().all(|c| c.is_finite()));
            }
        }
        true
    });
    match result {
        Ok(loaded) => loaded,
        Err(_) => panic!("{name}: panicked (a fuzzing regression)"),
    }
}

#[test]
fn every_corpus_input_loads_or_fails_cleanly() {
    let root = corpus();
    let mut total = 0;
    let mut loaded = 0;
    for sub in ["gltf_json", "glb", "crashes"] {
        for path in files(&root.join(sub)) {
            let bytes = std::fs::read(&path).unwrap();
            total += 1;
            loaded += check(&path, &bytes) as usize;
            if sub == "glb" && bytes.len() >= 12 {
                // The glb target's header repair (fuzz/fuzz_targets/common.rs).
                let mut v = bytes.clone();
                v[..4].copy_from_slice(b"glTF");
                v[4..8].copy_from_slice(&2u32.to_le_bytes());
                let n = v.len() as u32;
                v[8..12].copy_from_slice(&n.to_le_bytes());
                loaded += check(&path, &v) as usize;
            }
        }
    }
    // The corpus is committed with the tests: an empty one means it went missing.
    assert!(
        total >= 20,
        "only {total} corpus files under {}",
        root.display()
    );
    // A corpus of only broken files would not exercise the renderer side.
    assert!(loaded > 0, "no corpus input loads");
    eprintln!("{total} corpus inputs, {loaded} load");
}
