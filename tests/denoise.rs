//! The Open Image Denoise wrapper: a denoised 16 spp Cornell box against a converged render,
//! and bad input (missing, corrupt or foreign libraries, mismatched or non-finite images).
//!
//! Tests that need the library skip with a message when it is absent (`scripts/test.sh`
//! installs PyPI's pyoidn into .venv and exports TESELA_OIDN_LIB); the bad-input tests that do
//! not need it always run.

#[path = "common/inputs.rs"]
mod inputs;

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use tesela::denoise::{DenoiseError, Denoiser, ENV_VAR, Input};
use tesela::emitter::LightChoice;
use tesela::render::{self, RenderOptions};
use tesela::render_scene::RenderScene;

/// pyoidn's library folder in the checkout's `.venv`, if installed there.
fn checkout_wheel() -> Option<PathBuf> {
    let lib = Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/lib");
    std::fs::read_dir(lib)
        .ok()?
        .flatten()
        .map(|e| e.path().join("site-packages/pyoidn/oidn/lib"))
        .find(|d| d.is_dir())
}

/// The denoiser, or `None` (with a visible message) when the library is not installed.
fn denoiser(threads: usize) -> Option<Denoiser> {
    let explicit = match std::env::var_os(ENV_VAR) {
        Some(_) => None,
        None => checkout_wheel(),
    };
    match Denoiser::load(explicit.as_deref(), threads) {
        Ok(d) => {
            eprintln!("{}", d.describe());
            Some(d)
        }
        Err(e) => {
            eprintln!("SKIPPED (no Open Image Denoise): {e}");
            None
        }
    }
}

const SIZE: u32 = 64;

/// The built-in Cornell box with `integrator` at `spp`, RGB interleaved.
fn cornell(integrator: &str, spp: u32, seed: u64) -> Vec<f32> {
    let opts = RenderOptions {
        width: SIZE,
        height: SIZE,
        spp,
        max_depth: 6,
        seed,
        integrator: integrator.into(),
        threads: 0,
        tile_size: 16,
        region: None,
        ..Default::default()
    };
    let rs = RenderScene::new(tesela::scene::builtin::cornell_box(), LightChoice::Power);
    let (img, _) = render::render(&rs, &opts, &AtomicBool::new(false), &|_, _, _| {}).unwrap();
    img.pixels.iter().flat_map(|p| [p[0], p[1], p[2]]).collect()
}

/// Relative MSE against `reference`: mean of (x − r)² / (r² + 0.01) over pixels and channels.
fn rel_mse(x: &[f32], reference: &[f32]) -> f64 {
    let sum: f64 = x
        .iter()
        .zip(reference)
        .map(|(&x, &r)| (x as f64 - r as f64).powi(2) / ((r as f64).powi(2) + 0.01))
        .sum();
    sum / x.len() as f64
}

fn mean(x: &[f32]) -> f64 {
    x.iter().map(|&v| v as f64).sum::<f64>() / x.len() as f64
}

fn input<'a>(color: &'a [f32], albedo: Option<&'a [f32]>, normal: Option<&'a [f32]>) -> Input<'a> {
    Input {
        width: SIZE as usize,
        height: SIZE as usize,
        color,
        albedo,
        normal,
    }
}

/// A 16 spp render denoised with prefiltered albedo and normal has at most a quarter of the
/// noisy render's relMSE against a 1024 spp reference and keeps its mean within 1%. Without
/// the prefilter, and with the colour alone, the error must still halve at least and the mean
/// stay within 3% (measured: raw auxiliaries darken by 2%, nearly all of it the blurred edge of
/// the light, whose few bright pixels carry half of this small frame's mean).
#[test]
fn denoised_16_spp_cornell_box_has_a_quarter_of_the_error() {
    let Some(d) = denoiser(0) else { return };
    let reference = cornell("path_mis", 1024, 7);
    let noisy = cornell("path_mis", 16, 1);
    let albedo = cornell("albedo", 16, 2);
    // The debug view stores n·0.5 + 0.5; OIDN wants n (0 where nothing was hit).
    let normal: Vec<f32> = cornell("normals", 16, 3)
        .iter()
        .map(|&v| if v == 0.0 { 0.0 } else { 2.0 * v - 1.0 })
        .collect();
    let e_noisy = rel_mse(&noisy, &reference);
    eprintln!(
        "means: reference {:.5}, noisy {:.5}",
        mean(&reference),
        mean(&noisy)
    );
    let run = |label: &str, inp: Input, prefilter: bool| {
        let out = d.denoise(&inp, prefilter).unwrap();
        let e = rel_mse(&out, &reference);
        let m = mean(&out) / mean(&noisy) - 1.0;
        eprintln!(
            "{label}: relMSE {e:.5} (noisy {e_noisy:.5}, ratio {:.3}), mean {:+.3}%",
            e / e_noisy,
            100.0 * m
        );
        (e, m)
    };
    let (e, m) = run(
        "albedo+normal, prefiltered",
        input(&noisy, Some(&albedo), Some(&normal)),
        true,
    );
    assert!(e <= e_noisy / 4.0, "relMSE {e} vs noisy {e_noisy}");
    assert!(m.abs() < 0.01, "mean moved by {:.2}%", 100.0 * m);
    for (label, inp, prefilter) in [
        (
            "albedo+normal, raw",
            input(&noisy, Some(&albedo), Some(&normal)),
            false,
        ),
        (
            "albedo, prefiltered",
            input(&noisy, Some(&albedo), None),
            true,
        ),
        ("colour only", input(&noisy, None, None), false),
    ] {
        let (e, m) = run(label, inp, prefilter);
        assert!(e <= e_noisy / 2.0, "{label}: relMSE {e} vs noisy {e_noisy}");
        assert!(m.abs() < 0.03, "{label}: mean moved by {:.2}%", 100.0 * m);
    }
}

/// A non-finite value in any input is replaced before filtering: the result is finite and
/// the rest of the image is unchanged by the poisoned pixels' neighbourhood blowing up.
#[test]
fn nan_and_inf_inputs_give_a_finite_image() {
    let Some(d) = denoiser(0) else { return };
    let clean = vec![0.5f32; (3 * SIZE * SIZE) as usize];
    let mut color = clean.clone();
    let mut albedo = vec![0.8f32; color.len()];
    let mut normal = vec![0.0f32; color.len()];
    color[300] = f32::NAN;
    color[3001] = f32::INFINITY;
    color[6002] = f32::NEG_INFINITY;
    color[9000] = -4.0;
    albedo[400] = f32::NAN;
    normal[500] = f32::INFINITY;
    let out = d
        .denoise(&input(&color, Some(&albedo), Some(&normal)), true)
        .unwrap();
    assert!(out.iter().all(|v| v.is_finite()));
    let m = mean(&out);
    assert!((m - 0.5).abs() < 0.01, "mean {m}");
}

#[test]
fn mismatched_images_are_refused_before_filtering() {
    let px = (SIZE * SIZE) as usize;
    let color = vec![0.0f32; 3 * px];
    let short = vec![0.0f32; 3 * px - 1];
    let cases: [(Input, &str); 5] = [
        (input(&short, None, None), "color image has"),
        (input(&color, Some(&short), None), "albedo image has"),
        (
            input(&color, Some(&color), Some(&short)),
            "normal image has",
        ),
        (input(&color, None, Some(&color)), "needs an albedo"),
        (
            Input {
                width: 0,
                ..input(&color, None, None)
            },
            "empty",
        ),
    ];
    let d = denoiser(0);
    for (inp, expected) in cases {
        let e = inp.check().unwrap_err();
        assert!(e.to_string().contains(expected), "{e}");
        if let Some(d) = &d {
            assert_eq!(d.denoise(&inp, true).unwrap_err(), e);
        }
    }
    let huge = Input {
        width: usize::MAX,
        height: 2,
        ..input(&color, None, None)
    };
    assert!(huge.check().unwrap_err().to_string().contains("too large"));
}

fn unavailable(r: Result<Denoiser, DenoiseError>) -> String {
    match r {
        Err(DenoiseError::Unavailable(m)) => m,
        Err(e) => panic!("wrong error kind: {e}"),
        Ok(d) => panic!("loaded {}", d.describe()),
    }
}

#[test]
fn missing_library_names_the_paths_tried() {
    let m = unavailable(Denoiser::load(
        Some(Path::new("/nonexistent/libOpenImageDenoise.so.2")),
        0,
    ));
    assert!(
        m.contains("/nonexistent/libOpenImageDenoise.so.2 (absent)"),
        "{m}"
    );
    assert!(m.contains("pyoidn") && m.contains(ENV_VAR), "{m}");
    let dir = inputs::scratch("denoise", "empty");
    let m = unavailable(Denoiser::load(Some(&dir), 0));
    assert!(m.contains(&dir.display().to_string()), "{m}");
    assert!(m.contains("not found"), "{m}");
}

#[test]
fn corrupt_library_file_is_a_clear_error() {
    let dir = inputs::scratch("denoise", "corrupt");
    let garbage: Vec<u8> = (0..4096u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    let path = inputs::write(&dir, "libOpenImageDenoise.so.2", &garbage);
    let m = unavailable(Denoiser::load(Some(&dir), 0));
    assert!(
        m.contains(&path.display().to_string()) && m.contains("not a loadable library"),
        "{m}"
    );
    // The real library cut short (a broken download) is refused the same way.
    if let Some(real) = denoiser(0).map(|d| d.library_path().to_path_buf()) {
        let bytes = std::fs::read(&real).unwrap();
        let cut = inputs::write(&dir, "truncated.so", &bytes[..bytes.len() / 3]);
        let m = unavailable(Denoiser::load(Some(&cut), 0));
        assert!(
            m.contains("truncated.so") && m.contains("is truncated"),
            "{m}"
        );
        // So is a bundle whose TBB (loaded ahead of the library) was cut short.
        let bundle = inputs::scratch("denoise", "bundle");
        std::fs::copy(&real, bundle.join("libOpenImageDenoise.so.2")).unwrap();
        let tbb = std::fs::read(real.with_file_name("libtbb.so.12")).unwrap();
        inputs::write(&bundle, "libtbb.so.12", &tbb[..tbb.len() / 2]);
        let m = unavailable(Denoiser::load(Some(&bundle), 0));
        assert!(m.contains("libtbb.so.12: the file is truncated"), "{m}");
    }
}

#[cfg(target_os = "linux")]
#[test]
fn library_without_oidn_symbols_names_the_missing_symbol() {
    let m = unavailable(Denoiser::load(Some(Path::new("libm.so.6")), 0));
    assert!(
        m.contains("libm.so.6") && m.contains("no symbol oidnNewDevice"),
        "{m}"
    );
}

/// The CPU device gives the same result for any thread count, as renders do.
#[test]
fn denoising_is_deterministic_across_thread_counts() {
    let (Some(one), Some(all)) = (denoiser(1), denoiser(0)) else {
        return;
    };
    let noisy = cornell("path_mis", 4, 5);
    let albedo = cornell("albedo", 1, 6);
    let a = one
        .denoise(&input(&noisy, Some(&albedo), None), true)
        .unwrap();
    let b = all
        .denoise(&input(&noisy, Some(&albedo), None), true)
        .unwrap();
    assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
    assert!(
        one.describe().contains("CPU device, 1 thread)"),
        "{}",
        one.describe()
    );
}

#[test]
fn noisy_image_keeps_combined_from_before_denoising() {
    let Some(d) = denoiser(0) else { return };
    use tesela::film::{Pass, PassSet};
    let opts = RenderOptions {
        width: 32,
        height: 32,
        spp: 8,
        max_depth: 6,
        passes: PassSet::new([
            Pass::NoisyImage,
            Pass::DenoisingAlbedo,
            Pass::DenoisingNormal,
        ]),
        ..Default::default()
    };
    let rs = RenderScene::new(tesela::scene::builtin::cornell_box(), LightChoice::Power);
    let (mut img, _) = render::render(&rs, &opts, &AtomicBool::new(false), &|_, _, _| {}).unwrap();
    let before: Vec<f32> = img.pixels.iter().flatten().copied().collect();
    assert!(img.pass(Pass::NoisyImage).unwrap() == before);
    img.denoise(&d, true).unwrap();
    let after: Vec<f32> = img.pixels.iter().flatten().copied().collect();
    assert!(after != before, "the denoiser changed nothing");
    assert!(img.pass(Pass::NoisyImage).unwrap() == before);
}
