//! The film: auxiliary passes, adaptive sampling, time limits and denoising through the
//! public render API, on the built-in scenes.

use std::sync::atomic::AtomicBool;
use tesela::emitter::LightChoice;
use tesela::film::{Adaptive, Pass, PassSet, PixelAcc};
use tesela::render::{self, RenderOptions};
use tesela::render_scene::RenderScene;
use tesela::scene::builtin;

fn cornell() -> RenderScene {
    RenderScene::new(builtin::cornell_box(), LightChoice::Power)
}

fn opts(size: u32, spp: u32) -> RenderOptions {
    RenderOptions {
        width: size,
        height: size,
        spp,
        max_depth: 6,
        seed: 5,
        tile_size: 8,
        ..Default::default()
    }
}

fn run(rs: &RenderScene, o: &RenderOptions) -> (render::Image, render::RenderStats) {
    render::render(rs, o, &AtomicBool::new(false), &|_, _, _| {}).unwrap()
}

fn all_passes() -> PassSet {
    PassSet::new(Pass::ALL)
}

#[test]
fn passes_and_adaptive_do_not_depend_on_the_thread_count() {
    let rs = cornell();
    let mut o = opts(24, 96);
    o.passes = all_passes();
    o.adaptive = Some(Adaptive {
        threshold: 0.05,
        min_samples: 16,
    });
    let mut results = Vec::new();
    for threads in [1, 2, 3] {
        o.threads = threads;
        let (img, st) = run(&rs, &o);
        results.push((img.pixels, img.aovs, st.samples));
    }
    for r in &results[1..] {
        assert!(
            r.0 == results[0].0,
            "Combined differs between thread counts"
        );
        assert!(r.1 == results[0].1, "passes differ between thread counts");
        assert_eq!(r.2, results[0].2, "adaptive sample counts differ");
    }
}

#[test]
fn combined_is_bit_identical_with_and_without_passes_and_rounds() {
    let rs = cornell();
    let plain = run(&rs, &opts(20, 24)).0;
    let mut o = opts(20, 24);
    o.passes = all_passes();
    let with = run(&rs, &o).0;
    assert!(plain.pixels == with.pixels);
    // A time limit splits the samples into rounds (1, 2, 4, ...): the sums are the same.
    o.time_limit = Some(1e6);
    let rounds = run(&rs, &o);
    assert!(rounds.1.rounds > 1);
    assert!(plain.pixels == rounds.0.pixels);
}

#[test]
fn first_surface_passes_on_the_cornell_box() {
    // The built-in box: the back wall faces +Z in glTF space (Blender: -Y), the camera
    // looks at it along -Z from z = 6.8 (glTF); see scene::builtin.
    let rs = cornell();
    let mut o = opts(32, 4);
    o.passes = PassSet::new([
        Pass::Depth,
        Pass::Normal,
        Pass::Position,
        Pass::DenoisingAlbedo,
    ]);
    let (img, _) = run(&rs, &o);
    let depth = img.pass(Pass::Depth).unwrap();
    let normal = img.pass(Pass::Normal).unwrap();
    let position = img.pass(Pass::Position).unwrap();
    let cam = rs.scene.camera.expect("the box has a camera").to_world;
    let origin = cam.transform_point3(glam::Vec3::ZERO);
    let forward = cam.transform_vector3(-glam::Vec3::Z).normalize();
    let (mut checked, mut unit) = (0, 0);
    for i in 0..(32 * 32) {
        let d = depth[i];
        assert!(d.is_finite() && d > 0.0, "pixel {i}: depth {d}");
        if d > 1e9 {
            continue;
        }
        // Position is Blender space (x, -z, y of glTF); depth its view-axis distance.
        let p = glam::Vec3::new(position[3 * i], position[3 * i + 2], -position[3 * i + 1]);
        let z = (p - origin).dot(forward);
        assert!(
            (z - d).abs() <= 1e-3 * d,
            "pixel {i}: depth {d} vs position {z}"
        );
        // Normals average over the samples (misses count as zero): unit length where every
        // sample meets one face, shorter at edges.
        let n = glam::Vec3::from_slice(&normal[3 * i..3 * i + 3]);
        assert!(n.length() < 1.0 + 1e-3, "pixel {i}: normal {n}");
        unit += usize::from(n.length() > 0.999);
        checked += 1;
    }
    assert!(checked > 900, "only {checked} pixels see the box");
    assert!(unit > 650, "only {unit} pixels have a unit normal");
    // The back wall faces the camera (Blender -Y), the floor up (+Z), the side walls +-X.
    let count = |want: glam::Vec3| {
        (0..32 * 32)
            .filter(|&i| glam::Vec3::from_slice(&normal[3 * i..3 * i + 3]).dot(want) > 0.999)
            .count()
    };
    for (name, want) in [
        ("back wall", -glam::Vec3::Y),
        ("floor", glam::Vec3::Z),
        ("left wall", glam::Vec3::X),
        ("right wall", -glam::Vec3::X),
    ] {
        assert!(
            count(want) > 40,
            "{name}: {} pixels with normal {want}",
            count(want)
        );
    }
    // A back-wall pixel: the albedo guide is its white; on the light it adds the emission
    // (as Cycles' feature does for what the camera sees emit).
    let albedo = img.pass(Pass::DenoisingAlbedo).unwrap();
    let wall = (0..32 * 32)
        .find(|&i| glam::Vec3::from_slice(&normal[3 * i..3 * i + 3]).dot(-glam::Vec3::Y) > 0.999)
        .unwrap();
    assert!(
        (0.3..0.9).contains(&albedo[3 * wall]),
        "back wall albedo {}",
        albedo[3 * wall]
    );
    assert!(
        albedo.iter().any(|&a| a > 2.0),
        "the light's emission is missing from the albedo guide"
    );
}

#[test]
fn noise_estimate_matches_the_known_deviation_of_its_half_buffer() {
    // Samples ~ U(0, 1) per channel: σ² = 1/12. With n samples, I − A = (mean of the even
    // minus mean of the odd samples) / 2 has standard deviation σ/√n, so E|I − A| per
    // channel is σ·√(2/(π n)). The estimate's numerator must average to 3 times that.
    let n = 64u32;
    let pixels = 4000;
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut diffs = Vec::with_capacity(pixels);
    for _ in 0..pixels {
        let mut p = PixelAcc::default();
        for s in 0..n {
            let l = glam::Vec3::new(uniform(), uniform(), uniform());
            p.sum += l;
            if s & 1 == 1 {
                p.half += 2.0 * l;
            }
            p.accepted += 1;
        }
        let i = p.sum / n as f32;
        // The numerator of the estimate, recovered from `error()` and the normaliser.
        let intensity = i.x + i.y + i.z;
        let norm = if intensity < 1.0 {
            intensity.sqrt()
        } else {
            intensity
        };
        diffs.push(p.error() as f64 * (1e-4 + norm as f64));
    }
    let mean = diffs.iter().sum::<f64>() / pixels as f64;
    let var = diffs.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (pixels - 1) as f64;
    let se = (var / pixels as f64).sqrt();
    let sigma = (1.0f64 / 12.0).sqrt();
    let want = 3.0 * sigma * (2.0 / (std::f64::consts::PI * n as f64)).sqrt();
    assert!(
        (mean - want).abs() < 3.0 * se,
        "mean |I - A| summed {mean:.5} vs {want:.5} (se {se:.5})"
    );
}

#[test]
fn adaptive_sampling_spends_fewer_samples_and_stays_unbiased() {
    let rs = cornell();
    let reference = run(&rs, &opts(24, 2048)).0;
    let mut o = opts(24, 1024);
    o.adaptive = Some(Adaptive {
        threshold: 0.02,
        min_samples: 0,
    });
    let (img, st) = run(&rs, &o);
    assert!(st.spp_min < st.spp_max, "every pixel took the same samples");
    assert!(
        st.spp_mean < 0.8 * 1024.0,
        "adaptive sampling saved little: mean {} spp",
        st.spp_mean
    );
    let mean = |im: &render::Image, c: usize| {
        im.pixels.iter().map(|p| p[c] as f64).sum::<f64>() / im.pixels.len() as f64
    };
    for c in 0..3 {
        let (a, r) = (mean(&img, c), mean(&reference, c));
        assert!((a / r - 1.0).abs() < 0.02, "channel {c}: {a} vs {r}");
    }
    // Per-pixel error estimates at the end are near the threshold the user set.
    assert!(st.noise < 0.05, "noise level {}", st.noise);
}

#[test]
fn bad_film_settings_are_clear_errors() {
    let rs = cornell();
    for (t, word) in [(f64::NAN, "time limit"), (-1.0, "time limit")] {
        let mut o = opts(8, 4);
        o.time_limit = Some(t);
        let e = render::render(&rs, &o, &AtomicBool::new(false), &|_, _, _| {})
            .err()
            .expect("accepted");
        assert!(e.to_string().contains(word), "{e}");
    }
    let mut o = opts(8, 4);
    o.adaptive = Some(Adaptive {
        threshold: f32::NAN,
        min_samples: 0,
    });
    let e = render::render(&rs, &o, &AtomicBool::new(false), &|_, _, _| {})
        .err()
        .expect("accepted");
    assert!(e.to_string().contains("adaptive threshold"), "{e}");
    // A time limit of 0 means none.
    let mut o = opts(8, 4);
    o.time_limit = Some(0.0);
    assert_eq!(run(&rs, &o).1.rounds, 1);
}

#[test]
fn the_film_denoises_with_its_own_guides() {
    let d = match tesela::denoise::Denoiser::load(None, 0) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("SKIPPED (no Open Image Denoise): {e}");
            return;
        }
    };
    let rs = cornell();
    let reference = run(&rs, &opts(64, 1024)).0;
    let mut o = opts(64, 16);
    o.passes = PassSet::new([Pass::DenoisingAlbedo, Pass::DenoisingNormal]);
    let (mut img, _) = run(&rs, &o);
    let rel_mse = |im: &render::Image| {
        let mut s = 0.0f64;
        for (p, r) in im.pixels.iter().zip(&reference.pixels) {
            for c in 0..3 {
                let (a, b) = (p[c] as f64, r[c] as f64);
                s += (a - b).powi(2) / (b * b + 1e-2);
            }
        }
        s / (3 * im.pixels.len()) as f64
    };
    let noisy = rel_mse(&img);
    let mean = |im: &render::Image| {
        im.pixels
            .iter()
            .map(|p| (p[0] + p[1] + p[2]) as f64)
            .sum::<f64>()
    };
    let noisy_mean = mean(&img);
    img.denoise(&d, true).unwrap();
    let clean = rel_mse(&img);
    eprintln!("relMSE noisy {noisy:.5}, denoised {clean:.5}");
    assert!(clean <= noisy / 4.0, "denoised {clean} vs noisy {noisy}");
    assert!((mean(&img) / noisy_mean - 1.0).abs() < 0.01);
    assert!(img.pixels.iter().all(|p| p.iter().all(|v| v.is_finite())));
}

fn tesela(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_tesela"))
        .args(args)
        .stdin(std::process::Stdio::null())
        .output()
        .expect("run tesela")
}

/// Runs `tesela` with stdin held open until it exits (in pipe mode, EOF means cancel).
fn tesela_pipe(args: &[&str]) -> std::process::Output {
    use std::io::Read;
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_tesela"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run tesela");
    let stdin = child.stdin.take();
    let mut err_pipe = child.stderr.take().unwrap();
    let err = std::thread::spawn(move || {
        let mut v = Vec::new();
        err_pipe.read_to_end(&mut v).ok();
        v
    });
    let mut stdout = Vec::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_end(&mut stdout)
        .unwrap();
    let status = child.wait().unwrap();
    drop(stdin);
    std::process::Output {
        status,
        stdout,
        stderr: err.join().unwrap(),
    }
}

#[test]
fn cli_refuses_bad_film_options_clearly() {
    let dir = std::env::temp_dir().join(format!("tesela-film-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("x.exr");
    let out = out.to_str().unwrap();
    let base = [
        "render", "--width", "8", "--height", "8", "--spp", "2", "-o", out,
    ];
    for (extra, code, word) in [
        (vec!["--passes", "depth,shiny"], 2, "unknown pass `shiny`"),
        (vec!["--time-limit", "NaN"], 1, "time limit"),
        (vec!["--adaptive-threshold", "-1"], 1, "adaptive threshold"),
    ] {
        let o = tesela(&[&base[..], &extra[..]].concat());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{extra:?}: {err}");
        assert!(err.contains(word), "{extra:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn pipe_speaks_version_2_when_asked_and_refuses_unknown_versions() {
    use tesela::protocol::{self, Message};
    let o = tesela_pipe(&[
        "render",
        "--pipe",
        "--pipe-version",
        "2",
        "--width",
        "8",
        "--height",
        "4",
        "--spp",
        "1",
        "--passes",
        "depth,normal",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut r = &o.stdout[..];
    let Some(Message::Hello {
        version, passes, ..
    }) = protocol::read(&mut r).unwrap()
    else {
        panic!("no HELLO");
    };
    assert_eq!(version, 2);
    let names: Vec<_> = passes.iter().map(|(n, c)| format!("{n}:{c}")).collect();
    assert_eq!(names, ["Combined:RGBA", "Depth:Z", "Normal:XYZ"]);
    let mut floats = 0;
    while let Some(m) = protocol::read(&mut r).unwrap() {
        if let Message::Tile { w, h, data, .. } = m {
            assert_eq!(data.len() as u32, w * h * (4 + 1 + 3));
            floats += data.len();
        }
    }
    assert_eq!(floats, 8 * 4 * 8);
    // Version 1 is the default; an unknown version is an ERROR frame naming both.
    let o = tesela_pipe(&[
        "render",
        "--pipe",
        "--pipe-version",
        "3",
        "--width",
        "4",
        "--height",
        "4",
    ]);
    assert_eq!(o.status.code(), Some(2));
    match protocol::read(&mut &o.stdout[..]).unwrap() {
        Some(Message::Error(m)) => assert!(m.contains("version 3") && m.contains("1 and 2"), "{m}"),
        other => panic!("expected an ERROR frame, got {other:?}"),
    }
    let o = tesela_pipe(&[
        "render", "--pipe", "--width", "4", "--height", "4", "--passes", "depth",
    ]);
    assert_eq!(o.status.code(), Some(2));
}

/// DONE says where the time went: scene load, BVH build, render, tile stream (what the
/// add-on's render log prints).
#[test]
fn pipe_done_reports_load_bvh_render_and_stream_seconds() {
    use tesela::protocol::{self, Message};
    let o = tesela_pipe(&[
        "render",
        "--builtin",
        "cornell-box",
        "--pipe",
        "--width",
        "8",
        "--height",
        "8",
        "--spp",
        "1",
        "--tile-size",
        "4",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut r = &o.stdout[..];
    let mut done = None;
    while let Some(m) = protocol::read(&mut r).unwrap() {
        if let Message::Done(json) = m {
            done = Some(json);
        }
    }
    let done: serde_json::Value = serde_json::from_str(&done.expect("a DONE frame")).unwrap();
    for key in ["seconds", "load_seconds", "bvh_seconds", "stream_seconds"] {
        let v = done[key].as_f64().unwrap_or(f64::NAN);
        // Each phase took some time (four tiles were streamed) and less than the whole run.
        assert!(v > 0.0 && v < 60.0, "{key} = {v} in {done}");
    }
}

#[test]
fn multilayer_exr_has_blenders_channel_names() {
    let dir = std::env::temp_dir().join(format!("tesela-film-exr-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("passes.exr");
    let o = tesela_pipe(&[
        "render",
        "--width",
        "8",
        "--height",
        "6",
        "--spp",
        "2",
        "--passes",
        "depth,uv,object_index,denoising_albedo",
        "-o",
        path.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
    let mut names: Vec<String> = img
        .layer_data
        .iter()
        .flat_map(|l| l.channel_data.list.iter().map(|c| c.name.to_string()))
        .collect();
    names.sort();
    let want = [
        "ViewLayer.Combined.A",
        "ViewLayer.Combined.B",
        "ViewLayer.Combined.G",
        "ViewLayer.Combined.R",
        "ViewLayer.Denoising Albedo.B",
        "ViewLayer.Denoising Albedo.G",
        "ViewLayer.Denoising Albedo.R",
        "ViewLayer.Depth.Z",
        "ViewLayer.IndexOB.X",
        "ViewLayer.UV.A",
        "ViewLayer.UV.U",
        "ViewLayer.UV.V",
    ];
    assert_eq!(names, want);
    std::fs::remove_dir_all(&dir).ok();
}
