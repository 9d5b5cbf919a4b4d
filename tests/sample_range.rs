//! Sample ranges: parts of a render split by sample index, merged, equal the whole render up
//! to float summation order; what cannot be split is refused.

use std::sync::atomic::AtomicBool;
use tesela::emitter::LightChoice;
use tesela::film::accumulators::{self, Accumulators};
use tesela::film::{Adaptive, Pass, PassSet};
use tesela::render::{self, Image, RenderOptions};
use tesela::render_scene::RenderScene;
use tesela::scene::builtin;

fn opts(passes: PassSet) -> RenderOptions {
    RenderOptions {
        width: 24,
        height: 20,
        spp: 24,
        seed: 11,
        tile_size: 8,
        passes,
        ..Default::default()
    }
}

fn whole(rs: &RenderScene, o: &RenderOptions) -> Image {
    render::render(rs, o, &AtomicBool::new(false), &|_, _, _| {})
        .unwrap()
        .0
}

fn part(rs: &RenderScene, o: &RenderOptions, a: u32, b: u32) -> Accumulators {
    let (mut film, stats) =
        render::render_range(rs, o, a..b, &AtomicBool::new(false), &|_, _, _| {}).unwrap();
    assert_eq!(stats.samples, (b - a) as u64 * (o.width * o.height) as u64);
    film.key = "test".into();
    film
}

/// Largest per-pixel error of `got` against `want` relative to the pixel's magnitude, over
/// Combined and every pass (each pass's channels are one vector: a normal's components may
/// cancel, its length does not).
fn worst_relative_error(want: &Image, got: &Image) -> f64 {
    assert_eq!((want.width, want.height), (got.width, got.height));
    assert_eq!(want.passes, got.passes);
    let rel = |a: &[f32], b: &[f32]| {
        let err = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max);
        let scale = a.iter().chain(b).map(|x| x.abs()).fold(0.0f32, f32::max);
        if err == 0.0 {
            0.0
        } else {
            (err / scale) as f64
        }
    };
    let mut worst = 0.0f64;
    for (a, b) in want.pixels.iter().zip(&got.pixels) {
        worst = worst.max(rel(a, b));
    }
    let stride = want.passes.stride();
    for (a, b) in want
        .aovs
        .chunks_exact(stride.max(1))
        .zip(got.aovs.chunks_exact(stride.max(1)))
    {
        for (p, at) in want.passes.iter() {
            let k = at..at + p.channels();
            worst = worst.max(rel(&a[k.clone()], &b[k]));
        }
    }
    worst
}

fn three_parts_merge_to_the_whole_render(passes: PassSet, transparent: bool) {
    let mut scene = builtin::cornell_box();
    scene.settings.film_transparent = transparent;
    let rs = RenderScene::new(scene, LightChoice::Power);
    let o = opts(passes);
    let want = whole(&rs, &o);
    let parts = [(0, 5), (5, 13), (13, 24)].map(|(a, b)| part(&rs, &o, a, b));
    // The parts are renders of their own samples, not copies of one image.
    let (i0, i1) = (parts[0].resolve(), parts[1].resolve());
    assert!(worst_relative_error(&i0, &i1) > 0.05);
    // Given out of order: merge sorts them by range.
    let named: Vec<_> = [2, 0, 1]
        .map(|i| (format!("part{i}"), parts[i].clone()))
        .into();
    let merged = Accumulators::merge(named).unwrap();
    assert_eq!(merged.samples, 0..24);
    let got = merged.resolve();
    let e = worst_relative_error(&want, &got);
    assert!(e <= 1e-5, "merged differs from the whole render by {e:e}");
    // One part alone is far from the whole (the comparison can fail).
    assert!(worst_relative_error(&want, &parts[1].resolve()) > 0.05);
}

#[test]
fn cornell_box_default_integrator_merges_exactly() {
    three_parts_merge_to_the_whole_render(PassSet::default(), false);
}

#[test]
fn cornell_box_with_every_pass_merges_exactly() {
    three_parts_merge_to_the_whole_render(PassSet::new(Pass::ALL), true);
}

#[test]
fn accumulator_files_round_trip_and_merge() {
    let rs = RenderScene::new(builtin::cornell_box(), LightChoice::Power);
    let o = opts(PassSet::new([Pass::Depth, Pass::Normal, Pass::Mist]));
    let dir = std::env::temp_dir().join(format!("tesela-sample-range-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut named = Vec::new();
    for (a, b) in [(0, 10), (10, 24)] {
        let p = part(&rs, &o, a, b);
        let path = dir.join(format!("p{a}.exr"));
        accumulators::write(&p, &path).unwrap();
        let back = accumulators::read(&path).unwrap();
        assert_eq!(back.samples, p.samples);
        assert_eq!((back.spp, &back.key, &back.passes), (24, &p.key, &p.passes));
        assert!(
            back.aovs == p.aovs,
            "pass sums change on the way through the file"
        );
        for (x, y) in back.pixels.iter().zip(&p.pixels) {
            assert_eq!((x.sum, x.coverage), (y.sum, y.coverage));
            assert_eq!((x.accepted, x.empty), (y.accepted, y.empty));
        }
        named.push((path.display().to_string(), back));
    }
    let got = Accumulators::merge(named).unwrap().resolve();
    let e = worst_relative_error(&whole(&rs, &o), &got);
    assert!(
        e <= 1e-5,
        "merged files differ from the whole render by {e:e}"
    );
    // An image that is not an accumulator file is named in the error.
    let plain = dir.join("plain.exr");
    tesela::output::write(&got, &plain).unwrap();
    let err = accumulators::read(&plain).unwrap_err();
    assert!(
        err.contains("plain.exr") && err.contains("not a Tesela accumulator"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn parts_that_do_not_tile_the_samples_are_refused() {
    let rs = RenderScene::new(builtin::cornell_box(), LightChoice::Power);
    let o = opts(PassSet::default());
    let (a, b, c) = (
        part(&rs, &o, 0, 8),
        part(&rs, &o, 8, 16),
        part(&rs, &o, 16, 24),
    );
    let merge = |ps: Vec<(&str, &Accumulators)>| {
        Accumulators::merge(
            ps.into_iter()
                .map(|(n, p)| (n.to_string(), p.clone()))
                .collect(),
        )
    };
    let e = merge(vec![("a", &a), ("c", &c)]).unwrap_err();
    assert!(e.contains("samples 8:16"), "{e}");
    let e = merge(vec![("a", &a), ("b", &b)]).unwrap_err();
    assert!(e.contains("samples 16:24"), "{e}");
    let e = merge(vec![("a", &a), ("b", &b), ("b again", &b), ("c", &c)]).unwrap_err();
    assert!(e.contains("b again") && e.contains("overlap"), "{e}");
    let mut other = c.clone();
    other.key = "another render".into();
    let e = merge(vec![("a", &a), ("b", &b), ("other", &other)]).unwrap_err();
    assert!(e.contains("other") && e.contains("another render"), "{e}");
    assert!(merge(vec![("a", &a), ("b", &b), ("c", &c)]).is_ok());
}

#[test]
fn adaptive_sampling_and_time_limits_are_not_split() {
    let rs = RenderScene::new(builtin::cornell_box(), LightChoice::Power);
    let cancel = AtomicBool::new(false);
    let mut o = opts(PassSet::default());
    o.adaptive = Some(Adaptive {
        threshold: 0.01,
        min_samples: 0,
    });
    let e = render::render_range(&rs, &o, 0..8, &cancel, &|_, _, _| {}).unwrap_err();
    assert!(e.to_string().contains("adaptive sampling"), "{e}");
    o.adaptive = None;
    o.time_limit = Some(2.0);
    let e = render::render_range(&rs, &o, 0..8, &cancel, &|_, _, _| {}).unwrap_err();
    assert!(e.to_string().contains("time limit"), "{e}");
    o.time_limit = None;
    let e = render::render_range(&rs, &o, 8..30, &cancel, &|_, _, _| {}).unwrap_err();
    assert!(e.to_string().contains("8:30"), "{e}");
}

/// `tesela ARGS` run in `dir` → (exit status, stderr).
fn tesela_in(dir: &std::path::Path, args: &[&str]) -> (i32, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_tesela"))
        .args(args)
        .current_dir(dir)
        .stdin(std::process::Stdio::null())
        .output()
        .expect("run tesela");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn read_rgba(path: &std::path::Path) -> Vec<[f32; 4]> {
    let img = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |r, _| vec![[0.0f32; 4]; r.width() * r.height()],
        |px: &mut Vec<[f32; 4]>, p, (r, g, b, a): (f32, f32, f32, f32)| {
            let w = 16;
            px[p.y() * w + p.x()] = [r, g, b, a];
        },
    )
    .unwrap();
    img.layer_data.channel_data.pixels
}

#[test]
fn the_command_line_splits_merges_and_refuses() {
    let dir = std::env::temp_dir().join(format!("tesela-sample-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = |name: &str| dir.join(name).display().to_string();
    let tesela = |args: &[&str]| tesela_in(&dir, args);
    let base = [
        "render",
        "--builtin",
        "cornell-box",
        "--width",
        "16",
        "--height",
        "16",
    ];
    fn with<'a>(base: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
        [base, &["--spp", "12", "-q"], extra].concat()
    }
    assert_eq!(tesela(&with(&base, &["-o", &p("whole.exr")])).0, 0);
    for (range, name) in [("0:5", "a.exr"), ("5:12", "b.exr")] {
        let (code, err) = tesela(&with(
            &base,
            &["--sample-range", range, "--accumulators", &p(name)],
        ));
        assert_eq!(code, 0, "{err}");
    }
    // The sums are the result: no default tesela.png beside them.
    assert!(!dir.join("tesela.png").exists());
    let (code, err) = tesela(&["merge", &p("b.exr"), &p("a.exr"), "-o", &p("merged.exr")]);
    assert_eq!(code, 0, "{err}");
    let (want, got) = (
        read_rgba(&dir.join("whole.exr")),
        read_rgba(&dir.join("merged.exr")),
    );
    for (a, b) in want.iter().zip(&got) {
        for (x, y) in a.iter().zip(b) {
            assert!(
                (x - y).abs() <= 1e-5 * x.abs().max(y.abs()),
                "{a:?} vs {b:?}"
            );
        }
    }
    // A missing range, and what a part cannot have: usage errors (2) that say why.
    let (code, err) = tesela(&["merge", &p("a.exr"), "-o", &p("m.exr")]);
    assert!(code == 2 && err.contains("samples 5:12"), "{code} {err}");
    let x = p("x.exr");
    let part = |extra: &[&str]| {
        let args = [
            &["--sample-range", "0:4", "--accumulators", x.as_str()],
            extra,
        ]
        .concat();
        tesela(&with(&base, &args))
    };
    let (code, err) = part(&["--adaptive-threshold", "0.01"]);
    assert!(
        code == 2 && err.contains("adaptive sampling"),
        "{code} {err}"
    );
    let (code, err) = part(&["--time-limit", "5"]);
    assert!(code == 2 && err.contains("time limit"), "{code} {err}");
    let (code, err) = part(&["--denoise"]);
    assert!(
        code == 2 && err.contains("tesela merge --denoise"),
        "{code} {err}"
    );
    let (code, err) = tesela(&with(
        &base,
        &["--sample-range", "4:20", "--accumulators", &p("x.exr")],
    ));
    assert!(code == 2 && err.contains("4:20"), "{code} {err}");
    // A plain image is not a part: the file is named, exit 3 (could not be loaded).
    let (code, err) = tesela(&["merge", &p("whole.exr"), "-o", &p("m.exr")]);
    assert!(code == 3 && err.contains("whole.exr"), "{code} {err}");
    std::fs::remove_dir_all(&dir).ok();
}
