//! Hostile input and degenerate scenes (issue 4, renderer half).
//!
//! The CLI part runs the real `tesela` binary: every bad input must end with a clear message
//! and a non-zero exit status from the documented set (1 render error, 2 usage, 3 load
//! error) — never 101 (a panic), never a signal, never a hang (each run has a deadline and
//! a 4 GiB address-space limit, so an attempt to allocate an absurd image aborts the run and
//! fails the test).
//!
//! The library part renders degenerate geometry and edge-case materials with every
//! integrator and requires finite pixels *and* no rejected non-finite samples: the render
//! loop silently drops NaN/Inf samples, so counting them is what makes these tests able
//! to fail.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use base64::Engine;
use glam::{Mat4, Vec3};
use serde_json::{Value, json};
use tesela::emitter::LightChoice;
use tesela::render::{self, RenderOptions};
use tesela::render_scene::RenderScene;
use tesela::scene::builtin::{cornell_box, look_at, quad, sphere};
use tesela::scene::gltf::load_from_slice;
use tesela::scene::{Camera, Light, Material, Mesh, Projection, Scene, SpotFalloff};

#[path = "common/inputs.rs"]
mod inputs;
use inputs::{glb, json_bytes as to_bytes};

// ---------------------------------------------------------------------------------------
// Running the CLI
// ---------------------------------------------------------------------------------------

/// How a CLI run ended (stdout is drained but not kept).
struct Outcome {
    code: i32,
    stderr: String,
}

/// Runs `tesela args...` with a deadline and a 4 GiB address-space limit. Fails the test on
/// a hang, a signal or a panic (exit 101).
fn run(args: &[&str], deadline: Duration) -> Outcome {
    // `ulimit -v` in a shell that then execs the binary: an absurd allocation aborts
    // (a signal), which this function reports as a failure.
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg("ulimit -v 4194304 2>/dev/null; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_tesela"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = cmd.spawn().expect("cannot start tesela");
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let t_out = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = out.read_to_string(&mut s);
        s
    });
    let t_err = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err.read_to_string(&mut s);
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("tesela {args:?} did not finish within {deadline:?} (a hang)");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let _ = t_out.join();
    let stderr = t_err.join().unwrap();
    use std::os::unix::process::ExitStatusExt;
    if let Some(sig) = status.signal() {
        panic!("tesela {args:?} was killed by signal {sig}; stderr:\n{stderr}");
    }
    let code = status.code().unwrap();
    assert_ne!(code, 101, "tesela {args:?} panicked; stderr:\n{stderr}");
    Outcome { code, stderr }
}

const DEADLINE: Duration = Duration::from_secs(60);

/// Runs and checks the exit code and that stderr contains every one of `needles`.
fn expect_failure(args: &[&str], code: i32, needles: &[&str]) -> String {
    let o = run(args, DEADLINE);
    assert_eq!(
        o.code, code,
        "tesela {args:?}: exit {} (expected {code}); stderr:\n{}",
        o.code, o.stderr
    );
    for n in needles {
        assert!(
            o.stderr.contains(n),
            "tesela {args:?}: expected `{n}` in stderr:\n{}",
            o.stderr
        );
    }
    // A clear message: one `tesela: error:` line, no Rust backtrace or panic text.
    assert!(o.stderr.contains("error"), "no error message: {}", o.stderr);
    assert!(!o.stderr.contains("panicked"), "{}", o.stderr);
    o.stderr
}

/// A fresh folder for one test.
fn scratch(name: &str) -> PathBuf {
    inputs::scratch("robustness", name)
}

/// Writes `dir/name` and returns its path as a command-line argument.
fn write(dir: &Path, name: &str, data: &[u8]) -> String {
    s(&inputs::write(dir, name, data)).to_string()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

// ---------------------------------------------------------------------------------------
// Building glTF documents
// ---------------------------------------------------------------------------------------

fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// One triangle facing +Z at z = 0 seen by a camera on +Z: u16 indices (6 bytes + 2 padding)
/// then 3 float positions.
fn triangle_doc(positions: &[f32; 9]) -> Value {
    let mut bin: Vec<u8> = [0u16, 1, 2].iter().flat_map(|i| i.to_le_bytes()).collect();
    bin.extend_from_slice(&[0, 0]);
    bin.extend_from_slice(&f32s(positions));
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0, 1] }],
        "nodes": [{ "mesh": 0 }, { "camera": 0, "translation": [0.3, 0.3, 2.0] }],
        "cameras": [{ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.01 } }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 1 }, "indices": 0 }] }],
        "buffers": [{ "byteLength": bin.len(), "uri": uri }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": 6 },
            { "buffer": 0, "byteOffset": 8, "byteLength": 36 }
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5123, "count": 3, "type": "SCALAR" },
            { "bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3" }
        ],
        "extensionsUsed": ["TESELA_world"],
        "extensions": { "TESELA_world": { "color": [1, 1, 1], "strength": 1 } }
    })
}

const TRI: [f32; 9] = [0., 0., 0., 1., 0., 0., 0., 1., 0.];

/// The one-triangle document as a GLB (buffer 0 is the BIN chunk).
fn triangle_glb() -> Vec<u8> {
    let mut d = triangle_doc(&TRI);
    let mut bin: Vec<u8> = [0u16, 1, 2].iter().flat_map(|i| i.to_le_bytes()).collect();
    bin.extend_from_slice(&[0, 0]);
    bin.extend_from_slice(&f32s(&TRI));
    d["buffers"] = json!([{ "byteLength": bin.len() }]);
    glb(&to_bytes(&d), &bin)
}

// ---------------------------------------------------------------------------------------
// CLI: bad files
// ---------------------------------------------------------------------------------------

#[test]
fn the_valid_baselines_render() {
    // The documents the failure cases below are derived from do render, so each failure
    // is caused by the one thing that was broken.
    let dir = scratch("baseline");
    let gltf = write(&dir, "t.gltf", &to_bytes(&triangle_doc(&TRI)));
    let glb_path = write(&dir, "t.glb", &triangle_glb());
    for input in [&gltf, &glb_path] {
        let out = dir.join("out.png");
        let o = run(
            &[
                "render",
                input,
                "-o",
                s(&out),
                "--width",
                "8",
                "--height",
                "8",
                "--spp",
                "1",
                "--quiet",
            ],
            DEADLINE,
        );
        assert_eq!(o.code, 0, "{input}: {}", o.stderr);
        assert!(out.exists());
    }
}

#[test]
fn empty_and_blank_files() {
    let dir = scratch("empty");
    let e = write(&dir, "empty.gltf", b"");
    expect_failure(
        &["render", &e, "-o", "x.png"],
        3,
        &["empty.gltf", "empty file"],
    );
    let e = write(&dir, "empty.glb", b"");
    expect_failure(&["info", &e], 3, &["empty.glb", "empty file"]);
    let b = write(&dir, "blank.gltf", b" \n\t ");
    expect_failure(&["render", &b, "-o", "x.png"], 3, &["blank space"]);
}

#[test]
fn truncated_files() {
    let dir = scratch("truncated");
    // A .gltf cut in the middle of its JSON.
    let full = to_bytes(&triangle_doc(&TRI));
    let t = write(&dir, "cut.gltf", &full[..full.len() / 2]);
    expect_failure(
        &["render", &t, "-o", "x.png"],
        3,
        &["cut.gltf", "invalid JSON"],
    );
    // A .glb cut inside its header, inside the JSON chunk and inside the BIN chunk.
    let g = triangle_glb();
    for (n, what) in [
        (7, "shorter than the 12-byte header"),
        (40, "truncated GLB"),
        (g.len() - 3, "truncated GLB"),
    ] {
        let t = write(&dir, "cut.glb", &g[..n]);
        expect_failure(&["render", &t, "-o", "x.png"], 3, &["cut.glb", what]);
    }
}

#[test]
fn wrong_glb_magic() {
    let dir = scratch("magic");
    let mut g = triangle_glb();
    g[..4].copy_from_slice(b"GLTF");
    let p = write(&dir, "magic.glb", &g);
    expect_failure(
        &["render", &p, "-o", "x.png"],
        3,
        &["magic.glb", "bad GLB magic"],
    );
    // Something else entirely (a PNG header) named .glb.
    let p = write(&dir, "png.glb", b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR");
    expect_failure(&["render", &p, "-o", "x.png"], 3, &["not a glTF file"]);
    // Right magic, wrong version.
    let mut g = triangle_glb();
    g[4] = 1;
    let p = write(&dir, "v1.glb", &g);
    expect_failure(&["info", &p], 3, &["unsupported GLB version 1"]);
}

#[test]
fn nan_and_infinite_positions() {
    let dir = scratch("nan");
    for (name, bad) in [("nan", f32::NAN), ("inf", f32::INFINITY)] {
        let mut p = TRI;
        p[4] = bad;
        let f = write(&dir, &format!("{name}.gltf"), &to_bytes(&triangle_doc(&p)));
        expect_failure(
            &["render", &f, "-o", "x.png"],
            3,
            &["accessor 1", "vertex 1 is not finite"],
        );
    }
    // Finite in the file, infinite in world space after a node's scale.
    let mut p = TRI;
    p[3] = 3e38;
    let mut d = triangle_doc(&p);
    d["nodes"][0]["scale"] = json!([10.0, 1.0, 1.0]);
    let f = write(&dir, "overflow.gltf", &to_bytes(&d));
    expect_failure(
        &["render", &f, "-o", "x.png"],
        3,
        &["not finite in world space"],
    );
}

#[test]
fn coordinates_beyond_the_renderer_limit() {
    // Found by fuzzing: a triangle 1e20 m wide overflowed the BVH builder's surface-area
    // costs and made it panic. Such vertices are refused with the accessor's location.
    let dir = scratch("huge");
    for x in [1e13f32, 1e20, 3e38] {
        let mut p = TRI;
        p[3] = x;
        let f = write(&dir, "huge.gltf", &to_bytes(&triangle_doc(&p)));
        expect_failure(
            &["render", &f, "-o", "x.png"],
            3,
            &[
                "huge.gltf",
                "mesh 0 primitive 0 on node 0: vertex 1",
                "1e12 m",
            ],
        );
    }
    // Within the limit, a large but finite scene renders.
    let mut p = TRI;
    p[3] = 1e11;
    let f = write(&dir, "large.gltf", &to_bytes(&triangle_doc(&p)));
    let out = dir.join("large.png");
    let o = run(
        &[
            "render",
            &f,
            "-o",
            s(&out),
            "--width",
            "8",
            "--height",
            "8",
            "--spp",
            "1",
        ],
        DEADLINE,
    );
    assert_eq!(o.code, 0, "{}", o.stderr);
}

#[test]
fn camera_with_zero_negative_or_nan_fov() {
    let dir = scratch("fov");
    // JSON has no NaN literal: a NaN field of view arrives as a string, `null` or an
    // out-of-range number (1e39 overflows f32 to infinity).
    for (name, yfov, needle) in [
        ("zero", json!(0.0), "perspective yfov 0 is not in (0, pi)"),
        ("negative", json!(-0.5), "perspective yfov -0.5"),
        ("huge", json!(1e39), "perspective yfov inf"),
        ("pi", json!(std::f64::consts::PI), "is not in (0, pi)"),
        ("nan-string", json!("NaN"), "cameras[0]"),
        ("null", Value::Null, "cameras[0]"),
    ] {
        let mut d = triangle_doc(&TRI);
        d["cameras"][0]["perspective"]["yfov"] = yfov;
        let f = write(&dir, &format!("{name}.gltf"), &to_bytes(&d));
        expect_failure(&["render", &f, "-o", "x.png"], 3, &[needle]);
    }
    let mut d = triangle_doc(&TRI);
    d["cameras"][0] = json!({ "type": "orthographic",
        "orthographic": { "xmag": 1.0, "ymag": 0.0, "znear": 0.01, "zfar": 10.0 } });
    let f = write(&dir, "ortho.gltf", &to_bytes(&d));
    expect_failure(&["render", &f, "-o", "x.png"], 3, &["orthographic ymag 0"]);
    // A camera node whose transform collapses the view direction.
    let mut d = triangle_doc(&TRI);
    d["nodes"][1]["scale"] = json!([1.0, 1.0, 0.0]);
    let f = write(&dir, "flat.gltf", &to_bytes(&d));
    expect_failure(
        &["render", &f, "-o", "x.png"],
        3,
        &["camera transform is degenerate"],
    );
}

#[test]
fn other_broken_files_exit_with_the_load_error_status() {
    // The loader's messages for these are tested in tests/gltf_errors.rs; here: the CLI
    // turns each into exit status 3 with the file's name.
    let dir = scratch("broken");
    let mut cases: Vec<(&str, Value, &str)> = Vec::new();
    let mut d = triangle_doc(&TRI);
    d["accessors"][1]["count"] = json!(1000);
    cases.push(("oob", d, "accessor 1"));
    let mut d = triangle_doc(&TRI);
    d["accessors"][0]["count"] = json!(3);
    d["bufferViews"][0]["byteLength"] = json!(6);
    d["buffers"][0]["byteLength"] = json!(1000);
    cases.push(("short", d, "buffer 0"));
    let mut d = triangle_doc(&TRI);
    d["accessors"][1]["count"] = json!(2);
    cases.push(("index", d, "out of range for 2 vertices"));
    let mut d = triangle_doc(&TRI);
    d["extensionsRequired"] = json!(["KHR_texture_basisu"]);
    cases.push(("ext", d, "unsupported required extension"));
    let mut d = triangle_doc(&TRI);
    d["buffers"][0]["uri"] = json!("missing.bin");
    cases.push(("missing", d, "missing.bin"));
    let mut d = triangle_doc(&TRI);
    d["buffers"][0]["uri"] = json!("../outside.bin");
    cases.push(("escape", d, "outside.bin"));
    let mut d = triangle_doc(&TRI);
    d["buffers"][0]["uri"] = json!("/etc/passwd");
    cases.push(("absolute", d, "/etc/passwd"));
    let mut d = triangle_doc(&TRI);
    d["buffers"][0]["uri"] = json!("http://example.com/a.bin");
    cases.push(("http", d, "http:"));
    for (name, d, needle) in cases {
        let f = write(&dir, &format!("{name}.gltf"), &to_bytes(&d));
        let o = run(&["render", &f, "-o", "x.png", "--quiet"], DEADLINE);
        assert_eq!(o.code, 3, "{name}: {}", o.stderr);
        assert!(
            o.stderr.contains(&format!("{name}.gltf")),
            "{name}: {}",
            o.stderr
        );
        assert!(
            o.stderr.contains(needle),
            "{name}: `{needle}` in {}",
            o.stderr
        );
    }
    // A file that does not exist.
    let p = dir.join("nope.gltf");
    expect_failure(
        &["render", s(&p), "-o", "x.png"],
        3,
        &["nope.gltf", "cannot read"],
    );
}

// ---------------------------------------------------------------------------------------
// CLI: options
// ---------------------------------------------------------------------------------------

#[test]
fn absurd_resolution_is_refused_before_allocating() {
    let dir = scratch("resolution");
    let out = dir.join("big.png");
    let start = Instant::now();
    let err = expect_failure(
        &[
            "render",
            "--builtin",
            "cornell-box",
            "--width",
            "100000000",
            "--height",
            "100000000",
            "-o",
            s(&out),
        ],
        1,
        &["resolution 100000000x100000000 is too large"],
    );
    assert!(start.elapsed() < Duration::from_secs(20), "{err}");
    assert!(!out.exists());
    // The largest u32 in each direction, a product that overflows 32 bits, a zero side.
    expect_failure(
        &[
            "render",
            "--width",
            "4294967295",
            "--height",
            "4294967295",
            "-o",
            s(&out),
        ],
        1,
        &["is too large"],
    );
    expect_failure(
        &[
            "render",
            "--width",
            "65536",
            "--height",
            "65536",
            "-o",
            s(&out),
        ],
        1,
        &["is too large"],
    );
    expect_failure(
        &["render", "--width", "0", "-o", s(&out)],
        1,
        &["resolution must be at least 1x1"],
    );
    // The same limit applies to a resolution stored in the scene (TESELA_render).
    let mut d = triangle_doc(&TRI);
    d["extensionsUsed"] = json!(["TESELA_render"]);
    d["extensions"] =
        json!({ "TESELA_render": { "width": 4000000000u64, "height": 3000000000u64 } });
    let f = write(&dir, "big.gltf", &to_bytes(&d));
    expect_failure(&["render", &f, "-o", s(&out)], 1, &["is too large"]);
    // Absurd thread counts are refused instead of spending minutes starting threads.
    let start = Instant::now();
    expect_failure(
        &["render", "--threads", "100000", "-o", s(&out)],
        1,
        &["100000 worker threads is too many"],
    );
    assert!(start.elapsed() < Duration::from_secs(20));
    // Not a number at all: a usage error.
    let o = run(&["render", "--width", "1e9", "-o", s(&out)], DEADLINE);
    assert_eq!(o.code, 2, "{}", o.stderr);
    let o = run(&["render", "--width", "-5", "-o", s(&out)], DEADLINE);
    assert_eq!(o.code, 2, "{}", o.stderr);
}

#[test]
fn unknown_output_format_is_refused_before_rendering() {
    let dir = scratch("ext");
    for name in ["out.bmp", "out", "out.png.tmp", "out.jpg"] {
        let out = dir.join(name);
        expect_failure(
            &["render", "--spp", "100000", "-o", s(&out)],
            1,
            &["unknown output format", name],
        );
        assert!(!out.exists());
    }
    // An output folder that does not exist is refused before the render, not after it.
    let out = dir.join("no/such/folder/out.png");
    let start = Instant::now();
    expect_failure(
        &["render", "--spp", "100000", "-o", s(&out)],
        1,
        &["does not exist"],
    );
    assert!(start.elapsed() < Duration::from_secs(20));
}

#[test]
fn a_scene_without_triangles_renders_the_background_with_a_warning() {
    // Decision: not an error. The image shows only the background (black by default), as
    // Blender shows an empty scene, and a warning says there is nothing to see.
    let dir = scratch("empty-scene");
    for (name, doc) in [
        ("nothing.gltf", json!({ "asset": { "version": "2.0" } })),
        ("points.gltf", {
            let mut d = triangle_doc(&TRI);
            d["meshes"][0]["primitives"][0]["mode"] = json!(0);
            d["extensions"] =
                json!({ "TESELA_world": { "color": [0.5, 0.25, 1.0], "strength": 1 } });
            d
        }),
    ] {
        let f = write(&dir, name, &to_bytes(&doc));
        let out = dir.join("empty.exr");
        let _ = std::fs::remove_file(&out);
        let o = run(
            &[
                "render",
                &f,
                "-o",
                s(&out),
                "--width",
                "8",
                "--height",
                "6",
                "--spp",
                "2",
            ],
            DEADLINE,
        );
        assert_eq!(o.code, 0, "{name}: {}", o.stderr);
        assert!(
            o.stderr.contains("warning: the scene has no triangles"),
            "{name}: {}",
            o.stderr
        );
        let px = read_exr(&out);
        assert_eq!(px.len(), 48);
        let bg = if name == "points.gltf" {
            [0.5, 0.25, 1.0]
        } else {
            [0.0; 3]
        };
        for p in &px {
            for c in 0..3 {
                assert!(
                    (p[c] - bg[c]).abs() < 1e-6,
                    "{name}: pixel {p:?}, background {bg:?}"
                );
            }
        }
    }
}

#[test]
fn a_scene_without_light_says_so() {
    // Files made for real-time viewers often carry no light; the image is black, which is
    // right, but the user is told why and what gives the scene a world.
    let dir = scratch("unlit-scene");
    let mut dark = triangle_doc(&TRI);
    let o = dark.as_object_mut().unwrap();
    o.remove("extensions");
    o.remove("extensionsUsed");
    for (name, doc, args, warns) in [
        ("dark.gltf", dark.clone(), &[][..], true),
        (
            "dark.gltf",
            dark,
            &["--background", "1", "1", "1"][..],
            false,
        ),
        ("world.gltf", triangle_doc(&TRI), &[][..], false),
    ] {
        let f = write(&dir, name, &to_bytes(&doc));
        let out = dir.join("out.exr");
        let mut cmd = vec!["render", &f, "-o", s(&out), "--width", "4", "--height", "4"];
        cmd.extend_from_slice(&["--spp", "1"]);
        cmd.extend_from_slice(args);
        let o = run(&cmd, DEADLINE);
        assert_eq!(o.code, 0, "{name}: {}", o.stderr);
        assert_eq!(
            o.stderr.contains("warning: the scene has no light"),
            warns,
            "{name} {args:?}: {}",
            o.stderr
        );
    }
}

/// RGBA pixels of an EXR written by the renderer.
fn read_exr(path: &Path) -> Vec<[f32; 4]> {
    use exr::prelude::*;
    let img = read_first_rgba_layer_from_file(
        path,
        |res, _| {
            let w = res.width();
            (w, vec![[0f32; 4]; res.width() * res.height()])
        },
        |(w, px), pos, (r, g, b, a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = [r, g, b, a];
        },
    )
    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    img.layer_data.channel_data.pixels.1
}

#[test]
fn degenerate_file_renders_finite_pixels_through_the_cli() {
    // Zero-area, coincident and collinear triangles with zero-length normals, emission
    // strength 0 and an emissive triangle of zero area: loads, renders, every pixel finite.
    let dir = scratch("degenerate-cli");
    let pos: [f32; 27] = [
        0., 0., 0., 1., 0., 0., 0., 1., 0., // a real triangle
        0.5, 0.5, 0., 0.5, 0.5, 0., 0.5, 0.5, 0., // coincident vertices
        0., 0., 0., 0.5, 0.5, 0., 1., 1., 0., // collinear
    ];
    let normals = [0f32; 27];
    let idx: Vec<u16> = (0..9).collect();
    let mut bin: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
    bin.extend_from_slice(&[0, 0]);
    bin.extend_from_slice(&f32s(&pos));
    bin.extend_from_slice(&f32s(&normals));
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    let d = json!({
        "asset": { "version": "2.0" },
        "scenes": [{ "nodes": [0, 1, 2] }],
        "nodes": [
            { "mesh": 0 },
            { "mesh": 1 },
            { "camera": 0, "translation": [0.3, 0.3, 2.0] }
        ],
        "cameras": [{ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.01 } }],
        "materials": [
            { "emissiveFactor": [1, 1, 1],
              "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": 0.0 } } },
            { "emissiveFactor": [1, 1, 1] }
        ],
        "meshes": [
            { "primitives": [{ "attributes": { "POSITION": 1, "NORMAL": 2 }, "indices": 0, "material": 0 }] },
            { "primitives": [{ "attributes": { "POSITION": 1 }, "indices": 3, "material": 1 }] }
        ],
        "buffers": [{ "byteLength": bin.len(), "uri": uri }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": 18 },
            { "buffer": 0, "byteOffset": 20, "byteLength": 108 },
            { "buffer": 0, "byteOffset": 128, "byteLength": 108 },
            { "buffer": 0, "byteOffset": 6, "byteLength": 6 }
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5123, "count": 9, "type": "SCALAR" },
            { "bufferView": 1, "componentType": 5126, "count": 9, "type": "VEC3" },
            { "bufferView": 2, "componentType": 5126, "count": 9, "type": "VEC3" },
            { "bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR" }
        ],
        "extensionsUsed": ["KHR_materials_emissive_strength", "TESELA_world"],
        "extensions": { "TESELA_world": { "color": [1, 1, 1], "strength": 1 } }
    });
    let f = write(&dir, "degenerate.gltf", &to_bytes(&d));
    for integrator in tesela::integrator::NAMES {
        let out = dir.join(format!("{integrator}.exr"));
        let o = run(
            &[
                "render",
                &f,
                "-o",
                s(&out),
                "--width",
                "16",
                "--height",
                "16",
                "--spp",
                "4",
                "--integrator",
                integrator,
            ],
            DEADLINE,
        );
        assert_eq!(o.code, 0, "{integrator}: {}", o.stderr);
        assert!(
            o.stderr.contains("zero area"),
            "{integrator}: the zero-area emitter must be reported: {}",
            o.stderr
        );
        assert!(
            !o.stderr.contains("non-finite samples rejected"),
            "{integrator}: {}",
            o.stderr
        );
        let px = read_exr(&out);
        assert!(
            px.iter().flatten().all(|c| c.is_finite()),
            "{integrator}: non-finite pixel"
        );
        // The background is white and the real triangle is lit: not a black image.
        assert!(px.iter().any(|p| p[0] > 0.1), "{integrator}: black image");
    }
}

// ---------------------------------------------------------------------------------------
// Library: degenerate geometry and edge-case materials with every integrator
// ---------------------------------------------------------------------------------------

/// Renders `scene` with every integrator (8×8, 4 spp, depth 6) and checks every pixel is
/// finite and no sample was rejected as non-finite. Returns the mean of the path_mis image.
fn render_all(name: &str, scene: &Scene) -> f32 {
    let rs = RenderScene::new(scene.clone(), LightChoice::Power);
    let mut mean = 0.0;
    for integrator in tesela::integrator::NAMES {
        let opts = RenderOptions {
            width: 12,
            height: 12,
            spp: 4,
            max_depth: 6,
            seed: 7,
            integrator: integrator.into(),
            threads: 1,
            tile_size: 4,
            region: None,
            ..Default::default()
        };
        let (img, stats) = render::render(&rs, &opts, &AtomicBool::new(false), &|_, _, _| {})
            .unwrap_or_else(|e| panic!("{name}/{integrator}: {e}"));
        assert_eq!(
            stats.rejected_samples, 0,
            "{name}/{integrator}: non-finite or negative samples"
        );
        assert!(
            img.pixels.iter().flatten().all(|c| c.is_finite()),
            "{name}/{integrator}: non-finite pixel"
        );
        if integrator == "path_mis" {
            mean = img.pixels.iter().map(|p| p[0] + p[1] + p[2]).sum::<f32>()
                / img.pixels.len() as f32;
        }
    }
    mean
}

/// The Cornell box with `extra` meshes (materials appended; mesh material indices are
/// relative to `materials`).
fn box_with(materials: Vec<Material>, mut extra: Vec<Mesh>) -> Scene {
    let mut s = cornell_box();
    let base = s.materials.len();
    s.materials.extend(materials);
    for m in &mut extra {
        m.material += base;
    }
    s.meshes.extend(extra);
    s
}

fn mesh(name: &str, material: usize, positions: Vec<Vec3>, normals: Vec<Vec3>) -> Mesh {
    let n = positions.len() as u32;
    Mesh {
        name: name.into(),
        indices: (0..n / 3).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect(),
        positions,
        normals,
        uvs: Vec::new(),
        material,
        attrs: Default::default(),
    }
}

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

#[test]
fn zero_area_and_coincident_triangles() {
    let white = Material::diffuse("w", Vec3::splat(0.8));
    let tris = vec![
        // All three vertices in one point, on a lit spot of the floor and in mid-air.
        v(0.0, 0.0, 0.2),
        v(0.0, 0.0, 0.2),
        v(0.0, 0.0, 0.2),
        v(0.0, 0.5, 0.3),
        v(0.0, 0.5, 0.3),
        v(0.0, 0.5, 0.3),
        // Collinear (a needle) and two equal vertices.
        v(-0.4, 0.3, 0.3),
        v(0.0, 0.3, 0.3),
        v(0.4, 0.3, 0.3),
        v(-0.3, 0.7, 0.0),
        v(-0.3, 0.7, 0.0),
        v(0.3, 0.2, 0.0),
        // A sliver 1e-20 wide.
        v(-0.3, 0.4, 0.1),
        v(0.3, 0.4, 0.1),
        v(0.0, 0.4, 0.1 + 1e-20),
    ];
    let s = box_with(vec![white], vec![mesh("degenerate", 0, tris, vec![])]);
    assert!(render_all("zero-area", &s) > 0.01);
    // Two coincident copies of a quad (z-fighting) and a triangle with a coincident copy.
    let mirror = Material::mirror("m", Vec3::splat(0.9));
    let q = quad(
        "q",
        1,
        v(-0.2, 0.2, 0.0),
        v(0.2, 0.2, 0.0),
        v(0.2, 0.6, 0.0),
        v(-0.2, 0.6, 0.0),
    );
    let q2 = Mesh {
        material: 0,
        ..q.clone()
    };
    let s = box_with(vec![Material::diffuse("w", Vec3::ONE), mirror], vec![q, q2]);
    render_all("coincident", &s);
}

#[test]
fn emitters_of_zero_area_are_skipped_with_a_warning() {
    let light = Material::emitter("zero light", Vec3::splat(10.0), true);
    let point = vec![v(0.0, 0.5, 0.0); 6];
    let line = vec![v(-0.2, 0.5, 0.0), v(0.0, 0.5, 0.0), v(0.2, 0.5, 0.0)];
    let s = box_with(
        vec![light],
        vec![
            mesh("dot", 0, point, vec![]),
            mesh("needle", 0, line, vec![]),
        ],
    );
    let rs = RenderScene::new(s.clone(), LightChoice::Power);
    for name in ["dot", "needle"] {
        assert!(
            rs.scene
                .warnings
                .iter()
                .any(|w| w.contains(name) && w.contains("zero area")),
            "{name}: {:?}",
            rs.scene.warnings
        );
    }
    // Only the box's own light remains.
    assert_eq!(rs.emitters.len(), 1);
    render_all("zero-area emitters", &s);
    // An emitter with some zero-area triangles: only the others are sampled.
    let mixed = vec![
        v(0.0, 0.5, 0.0),
        v(0.0, 0.5, 0.0),
        v(0.0, 0.5, 0.0),
        v(-0.1, 0.5, -0.1),
        v(0.1, 0.5, -0.1),
        v(0.0, 0.5, 0.1),
    ];
    let s = box_with(
        vec![Material::emitter("mixed", Vec3::splat(5.0), true)],
        vec![mesh("mixed", 0, mixed, vec![])],
    );
    assert_eq!(
        RenderScene::new(s.clone(), LightChoice::Power)
            .emitters
            .len(),
        2
    );
    render_all("partly degenerate emitter", &s);
    // A scene whose only light has zero area: black, finite, no NaN from an empty light CDF.
    let mut s = Scene {
        camera: cornell_box().camera,
        ..Default::default()
    };
    s.materials.push(Material::diffuse("w", Vec3::ONE));
    s.materials.push(Material::emitter("l", Vec3::ONE, true));
    s.meshes.push(quad(
        "floor",
        0,
        v(-1., 0., 1.),
        v(1., 0., 1.),
        v(1., 0., -1.),
        v(-1., 0., -1.),
    ));
    s.meshes
        .push(mesh("l", 1, vec![v(0.0, 0.5, 0.0); 3], vec![]));
    assert_eq!(render_all("only a zero-area light", &s), 0.0);
}

#[test]
fn collapsed_zero_length_and_opposite_normals() {
    let mats = vec![
        Material::diffuse("w", Vec3::splat(0.8)),
        Material::mirror("m", Vec3::splat(0.9)),
        Material::glass("g", 1.5),
        Material {
            roughness: 0.3,
            ..Material::mirror("rough", Vec3::splat(0.9))
        },
    ];
    let tri = vec![v(-0.3, 0.1, 0.0), v(0.3, 0.1, 0.0), v(0.0, 0.7, 0.0)];
    let cases: Vec<(&str, Vec<Vec3>)> = vec![
        ("zero-length normals", vec![Vec3::ZERO; 3]),
        // Opposite normals: the interpolated normal vanishes inside the triangle.
        ("opposite normals", vec![Vec3::Z, -Vec3::Z, Vec3::Z]),
        ("cancelling normals", vec![Vec3::Z, -Vec3::Z, Vec3::ZERO]),
        // Normals lying in the surface (perpendicular to the geometric normal).
        ("tangent normals", vec![Vec3::X; 3]),
        // Shading normals pointing away from the face.
        ("backward normals", vec![-Vec3::Z; 3]),
        ("nan normals", vec![Vec3::NAN; 3]),
        ("tiny normals", vec![Vec3::splat(1e-30); 3]),
    ];
    for (name, normals) in cases {
        for mi in 0..mats.len() {
            let s = box_with(
                mats.clone(),
                vec![mesh(name, mi, tri.clone(), normals.clone())],
            );
            render_all(&format!("{name} / {}", mats[mi].name), &s);
        }
    }
    // An emitter with collapsed normals.
    let s = box_with(
        vec![Material::emitter("l", Vec3::splat(3.0), false)],
        vec![mesh("emitter", 0, tri, vec![Vec3::Z, -Vec3::Z, Vec3::ZERO])],
    );
    render_all("emitter with collapsed normals", &s);
    // The loader drops zero-length normals; with NaN ones it does the same.
    let doc = triangle_doc(&TRI);
    let s = load_from_slice(&to_bytes(&doc), None, "t.gltf").unwrap();
    render_all("loaded", &s);
}

#[test]
fn camera_inside_objects() {
    let mut s = box_with(
        vec![Material::diffuse("w", Vec3::splat(0.5))],
        vec![sphere("shell", 0, v(0.0, 0.5, 0.5), 0.3, 12, 24)],
    );
    let cam_at = |p: Vec3, t: Vec3| {
        Some(Camera {
            projection: Projection::Perspective { yfov: 1.2 },
            to_world: look_at(p, t),
            aspect: None,
            ..Default::default()
        })
    };
    s.camera = cam_at(v(0.0, 0.5, 0.5), v(0.0, 0.5, -1.0));
    // Closed sphere, no light inside: black but finite.
    assert_eq!(render_all("inside a diffuse sphere", &s), 0.0);
    // Inside glass, inside a mirror, inside a block, and exactly on a wall.
    s.materials.push(Material::glass("g", 1.5));
    s.meshes.last_mut().unwrap().material = s.materials.len() - 1;
    render_all("inside glass", &s);
    s.materials.push(Material::mirror("m", Vec3::ONE));
    s.meshes.last_mut().unwrap().material = s.materials.len() - 1;
    render_all("inside a mirror", &s);
    let mut s = cornell_box();
    s.camera = cam_at(v(-0.17, 0.3, -0.15), v(0.0, 0.3, 1.0));
    render_all("inside the tall block", &s);
    s.camera = cam_at(v(0.0, 0.5, -0.5), v(0.0, 0.5, 1.0));
    render_all("on the back wall", &s);
    s.camera = cam_at(v(0.0, 0.999, 0.0), v(0.0, 0.0, 0.0));
    render_all("on the light", &s);
    // An orthographic camera inside the box.
    s.camera = Some(Camera {
        projection: Projection::Orthographic { ymag: 0.3 },
        to_world: Mat4::from_translation(v(0.0, 0.5, 0.0)),
        aspect: None,
        ..Default::default()
    });
    render_all("orthographic inside", &s);
}

#[test]
fn edge_case_materials() {
    let sphere_with = |m: Material| {
        box_with(
            vec![m],
            vec![sphere("ball", 0, v(0.0, 0.3, 0.1), 0.25, 16, 32)],
        )
    };
    let d = Material::diffuse("d", Vec3::splat(0.7));
    let cases: Vec<(&str, Material)> = vec![
        (
            "emission strength 0",
            Material::emitter("e0", Vec3::ZERO, true),
        ),
        ("ior 1.0", Material::glass("ior1", 1.0)),
        (
            "ior 1.0 rough",
            Material {
                roughness: 0.5,
                ..Material::glass("ior1r", 1.0)
            },
        ),
        ("ior below 1", Material::glass("ior0.5", 0.5)),
        (
            "glass roughness 1",
            Material {
                roughness: 1.0,
                ..Material::glass("g1", 1.5)
            },
        ),
        (
            "metal roughness 0",
            Material {
                roughness: 0.0,
                ..Material::mirror("m0", Vec3::ONE)
            },
        ),
        (
            "metal roughness 1",
            Material {
                roughness: 1.0,
                ..Material::mirror("m1", Vec3::ONE)
            },
        ),
        (
            "dielectric roughness 0",
            Material {
                roughness: 0.0,
                specular: 1.0,
                ..d.clone()
            },
        ),
        (
            "dielectric roughness 1",
            Material {
                roughness: 1.0,
                specular: 1.0,
                ..d.clone()
            },
        ),
        (
            "metallic 0.5 roughness 0.001",
            Material {
                metallic: 0.5,
                roughness: 0.001,
                specular: 1.0,
                ..d.clone()
            },
        ),
        (
            "metallic 0.5 roughness 0",
            Material {
                metallic: 0.5,
                roughness: 0.0,
                specular: 1.0,
                ..d.clone()
            },
        ),
        (
            "roughness 1e-7",
            Material {
                roughness: 1e-7,
                ..Material::mirror("m", Vec3::ONE)
            },
        ),
        (
            "half transmissive",
            Material {
                transmission: 0.5,
                roughness: 0.001,
                ..Material::glass("t", 1.33)
            },
        ),
        ("black", Material::diffuse("black", Vec3::ZERO)),
        ("white furnace", Material::diffuse("white", Vec3::ONE)),
        (
            "specular 0 colour 0",
            Material {
                specular: 0.0,
                specular_color: Vec3::ZERO,
                ..d.clone()
            },
        ),
    ];
    for (name, m) in cases {
        render_all(name, &sphere_with(m));
    }
    // Emission strength 0 through the loader: the material is not an emitter.
    let mut doc = triangle_doc(&TRI);
    doc["materials"] = json!([{ "emissiveFactor": [1, 1, 1],
        "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": 0 } } }]);
    doc["meshes"][0]["primitives"][0]["material"] = json!(0);
    let s = load_from_slice(&to_bytes(&doc), None, "t.gltf").unwrap();
    assert!(!s.materials[0].is_emissive());
    let rs = RenderScene::new(s.clone(), LightChoice::Power);
    assert!(
        rs.emitters
            .iter()
            .all(|e| !matches!(e, tesela::emitter::EmitterInstance::Area(_)))
    );
    render_all("loaded emission strength 0", &s);
}

#[test]
fn lights_exactly_on_surfaces() {
    let floor_point = v(0.0, 0.0, 0.2);
    let lights = vec![
        Light::Point {
            position: floor_point,
            intensity: Vec3::splat(1.0),
        },
        // On the back wall, on an edge of the box, and on a corner.
        Light::Point {
            position: v(0.0, 0.5, -0.5),
            intensity: Vec3::splat(1.0),
        },
        Light::Point {
            position: v(0.5, 0.0, 0.0),
            intensity: Vec3::splat(1.0),
        },
        Light::Point {
            position: v(-0.5, 1.0, -0.5),
            intensity: Vec3::splat(1.0),
        },
        Light::Spot {
            position: v(0.0, 1.0, 0.0),
            direction: -Vec3::Y,
            intensity: Vec3::splat(2.0),
            falloff: SpotFalloff::Gltf {
                cos_inner: 0.9,
                cos_outer: 0.8,
            },
        },
        // A spot lying in the floor, aimed along it.
        Light::Spot {
            position: floor_point,
            direction: Vec3::Z,
            intensity: Vec3::splat(2.0),
            falloff: SpotFalloff::Cycles {
                cos_half: 0.5,
                smooth: 0.0,
            },
        },
    ];
    for (i, l) in lights.into_iter().enumerate() {
        let mut s = cornell_box();
        s.lights.push(l);
        render_all(&format!("light {i} on a surface"), &s);
    }
    // An area light coplanar with (inside) the floor, facing up and facing down.
    for (name, y) in [("up", 1.0f32), ("down", -1.0)] {
        let mut s = cornell_box();
        s.materials
            .push(Material::emitter("floor light", Vec3::splat(4.0), false));
        let m = s.materials.len() - 1;
        let (a, b, c, d) = (
            v(-0.2, 0.0, 0.1),
            v(0.2, 0.0, 0.1),
            v(0.2, 0.0, -0.1),
            v(-0.2, 0.0, -0.1),
        );
        s.meshes.push(if y > 0.0 {
            quad("floor light", m, a, b, c, d)
        } else {
            quad("floor light", m, d, c, b, a)
        });
        render_all(&format!("area light in the floor facing {name}"), &s);
    }
    // The box's own light moved exactly into the ceiling (no gap).
    let mut s = cornell_box();
    let light = s.meshes.iter_mut().find(|m| m.name == "light").unwrap();
    for p in &mut light.positions {
        p.y = 1.0;
    }
    render_all("light flush with the ceiling", &s);
    // A point light exactly on a vertex of a degenerate (zero-area) triangle.
    let mut s = box_with(
        vec![Material::diffuse("w", Vec3::ONE)],
        vec![mesh("dot", 0, vec![v(0.0, 0.5, 0.0); 3], vec![])],
    );
    s.lights.push(Light::Point {
        position: v(0.0, 0.5, 0.0),
        intensity: Vec3::ONE,
    });
    render_all("point light on a degenerate triangle", &s);
}
