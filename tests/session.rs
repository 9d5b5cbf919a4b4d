//! `tesela session` driven as the add-on drives it: a scripted client on the real binary's
//! pipes (docs/session.md). Every command, cancellation of a pass in flight, a flood of
//! views, malformed commands, end of input, and the pixels against `tesela render`.
//!
//! Each wait has a deadline that only a hang reaches (a test never asserts a speed).

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

const COMMAND: u32 = 32;
const HELLO: u32 = 1;
const LOG: u32 = 4;
const ERROR: u32 = 5;
const IMAGE: u32 = 16;

/// Long enough that only a hang reaches it.
const DEADLINE: Duration = Duration::from_secs(60);

/// An IMAGE frame.
#[derive(Clone, Debug)]
struct Image {
    generation: u64,
    pixel_size: u32,
    width: u32,
    height: u32,
    samples: u32,
    last: bool,
    denoised: bool,
    /// `[x, y, w, h]` of the view.
    window: [u32; 4],
    pixels: Vec<f32>,
}

impl Image {
    fn parse(p: &[u8]) -> Image {
        let u = |i: usize| u32::from_le_bytes(p[8 + 4 * i..12 + 4 * i].try_into().unwrap());
        let (w, h) = (u(7), u(8));
        let pixels: Vec<f32> = (p[52..].chunks_exact(4))
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(pixels.len(), (w * h * 4) as usize, "IMAGE size");
        Image {
            generation: u64::from_le_bytes(p[..8].try_into().unwrap()),
            pixel_size: u(6),
            width: w,
            height: h,
            samples: u(9),
            last: u(10) & 1 != 0,
            denoised: u(10) & 2 != 0,
            window: [u(2), u(3), u(4), u(5)],
            pixels,
        }
    }

    /// Mean of channel `c` over the image.
    fn mean(&self, c: usize) -> f64 {
        let v: Vec<f64> = self
            .pixels
            .iter()
            .skip(c)
            .step_by(4)
            .map(|&x| x as f64)
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    }
}

fn read_frame(r: &mut impl Read) -> Option<(u32, Vec<u8>)> {
    let mut h = [0u8; 8];
    r.read_exact(&mut h).ok()?;
    let kind = u32::from_le_bytes(h[..4].try_into().unwrap());
    let len = u32::from_le_bytes(h[4..].try_into().unwrap()) as usize;
    let mut p = vec![0u8; len];
    r.read_exact(&mut p).ok()?;
    Some((kind, p))
}

fn command(v: &Value) -> Vec<u8> {
    let j = v.to_string().into_bytes();
    let mut payload = (j.len() as u32).to_le_bytes().to_vec();
    payload.extend_from_slice(&j);
    frame(COMMAND, &payload)
}

fn frame(kind: u32, payload: &[u8]) -> Vec<u8> {
    let mut f = kind.to_le_bytes().to_vec();
    f.extend_from_slice(&(payload.len() as u32).to_le_bytes());
    f.extend_from_slice(payload);
    f
}

/// A running session with its frames arriving on a channel.
struct Session {
    child: Child,
    stdin: Option<ChildStdin>,
    frames: Receiver<(u32, Vec<u8>)>,
}

impl Session {
    fn start() -> Session {
        Self::start_with(&[])
    }

    fn start_with(extra: &[&str]) -> Session {
        let mut child = Command::new(env!("CARGO_BIN_EXE_tesela"))
            .args(["session", "--threads", "2"])
            .args(extra)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("cannot start tesela session");
        let mut out = child.stdout.take().unwrap();
        let (tx, rx) = channel();
        std::thread::spawn(move || {
            while let Some(f) = read_frame(&mut out) {
                if tx.send(f).is_err() {
                    break;
                }
            }
        });
        let stdin = child.stdin.take();
        let s = Session {
            child,
            stdin,
            frames: rx,
        };
        let (kind, p) = s.next().expect("no HELLO");
        assert_eq!(kind, HELLO);
        assert_eq!(&p[..4], b"TSLS");
        assert_eq!(u32::from_le_bytes(p[4..8].try_into().unwrap()), 1);
        s
    }

    fn send(&mut self, v: Value) {
        self.send_raw(&command(&v));
    }

    fn send_raw(&mut self, bytes: &[u8]) {
        let s = self.stdin.as_mut().unwrap();
        s.write_all(bytes).unwrap();
        s.flush().unwrap();
    }

    fn next(&self) -> Option<(u32, Vec<u8>)> {
        match self.frames.recv_timeout(DEADLINE) {
            Ok(f) => Some(f),
            Err(RecvTimeoutError::Timeout) => panic!("no frame within {DEADLINE:?}: a hang"),
            Err(RecvTimeoutError::Disconnected) => None,
        }
    }

    /// The frames up to the last IMAGE of generation `generation` (which is returned), with
    /// every IMAGE and ERROR before it.
    fn finish(&self, generation: u64) -> (Image, Vec<Image>, Vec<Value>) {
        let (mut images, mut errors) = (Vec::new(), Vec::new());
        loop {
            let (kind, p) = self.next().expect("the session ended");
            match kind {
                IMAGE => {
                    let im = Image::parse(&p);
                    images.push(im.clone());
                    if im.last && im.generation == generation {
                        return (im, images, errors);
                    }
                }
                ERROR => errors.push(serde_json::from_slice(&p).unwrap()),
                _ => {}
            }
        }
    }

    /// The next ERROR frame (skipping the others).
    fn error(&self) -> Value {
        loop {
            let (kind, p) = self.next().expect("the session ended");
            if kind == ERROR {
                return serde_json::from_slice(&p).unwrap();
            }
        }
    }

    /// Closes stdin and waits for the exit status.
    fn close(mut self) -> i32 {
        drop(self.stdin.take());
        let t = Instant::now();
        loop {
            if let Some(s) = self.child.try_wait().unwrap() {
                return s.code().unwrap_or(-1);
            }
            assert!(t.elapsed() < DEADLINE, "the session did not exit at EOF");
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A folder of its own for test `name`.
fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tesela-session-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The camera the test scene and the views use.
fn tesela_camera() -> Value {
    json!({"type": "PERSP", "lens": 35.0, "sensor_width": 36.0, "sensor_fit": "AUTO",
           "clip_start": 0.0})
}

fn camera_matrix(z: f32) -> Vec<f32> {
    vec![
        1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.5, z, 1.0,
    ]
}

/// The shipped Cornell box with a Blender camera, written into `dir`.
fn scene(dir: &Path) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box.gltf");
    let mut doc: Value = serde_json::from_slice(&std::fs::read(src).unwrap()).unwrap();
    for n in doc["nodes"].as_array_mut().unwrap() {
        if n.get("camera").is_some() {
            n["matrix"] = json!(camera_matrix(1.94));
            n["extensions"] = json!({"TESELA_camera": tesela_camera()});
        }
    }
    doc["extensionsUsed"]
        .as_array_mut()
        .unwrap()
        .push(json!("TESELA_camera"));
    let path = dir.join("scene.gltf");
    std::fs::write(&path, doc.to_string()).unwrap();
    path
}

/// A file with one mesh named `name`: a large quad across the box's floor.
fn mesh_file(dir: &Path, name: &str) -> PathBuf {
    let pos: [[f32; 3]; 4] = [
        [-0.5, 0.01, -0.5],
        [0.5, 0.01, -0.5],
        [0.5, 0.6, 0.5],
        [-0.5, 0.6, 0.5],
    ];
    let idx: [u32; 6] = [0, 2, 1, 0, 3, 2];
    let mut bin: Vec<u8> = pos.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
    bin.extend(idx.iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.join("mesh.bin"), &bin).unwrap();
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"uri": "mesh.bin", "byteLength": bin.len()}],
        "bufferViews": [{"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 24}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-0.5, 0.01, -0.5], "max": [0.5, 0.6, 0.5]},
            {"bufferView": 1, "componentType": 5125, "count": 6, "type": "SCALAR"}],
        "materials": [{"name": "green", "doubleSided": true}],
        "meshes": [{"name": name, "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "nodes": [{"name": name, "mesh": 0}],
        "scenes": [{"nodes": [0]}],
    });
    let path = dir.join("mesh.gltf");
    std::fs::write(&path, doc.to_string()).unwrap();
    path
}

fn view(width: u32, height: u32, z: f32) -> Value {
    json!({"cmd": "view", "width": width, "height": height,
           "camera": {"matrix": camera_matrix(z), "camera": tesela_camera()}})
}

/// Largest absolute difference between two images of the same size.
fn max_diff(a: &Image, b: &Image) -> f32 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    (a.pixels.iter().zip(&b.pixels))
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

/// Starts a session on the test scene with a small view and `samples`; the first image.
fn started(name: &str, samples: u32) -> (Session, PathBuf, Image) {
    let dir = folder(name);
    let path = scene(&dir);
    let mut s = Session::start();
    s.send(json!({"cmd": "settings", "samples": samples, "start_resolution": 16}));
    s.send(json!({"cmd": "load", "path": path}));
    s.send(view(48, 36, 1.94));
    let (im, images, errors) = s.finish(3);
    assert!(errors.is_empty(), "{errors:?}");
    // Reduced passes first, at pixel sizes halving down to 1.
    assert!(images[0].pixel_size > 1, "no reduced first pass");
    let sizes: Vec<u32> = images.iter().map(|i| i.pixel_size).collect();
    assert!(sizes.windows(2).all(|w| w[1] <= w[0]), "{sizes:?}");
    (s, dir, im)
}

#[test]
fn every_command_changes_what_it_should() {
    let (mut s, dir, base) = started("commands", 2);
    assert_eq!((base.width, base.height, base.samples), (48, 36, 2));
    let mut generation = 3;
    let mut step = |s: &mut Session, cmd: Value| -> Image {
        s.send(cmd.clone());
        generation += 1;
        let (im, _, errors) = s.finish(generation);
        assert!(errors.is_empty(), "{cmd}: {errors:?}");
        im
    };

    // A camera move: the image changes.
    let moved = step(&mut s, view(48, 36, 2.6));
    assert!(
        max_diff(&moved, &base) > 0.05,
        "view did not move the camera"
    );
    let back = step(&mut s, view(48, 36, 1.94));
    assert_eq!(
        max_diff(&back, &base),
        0.0,
        "the same view must give the same pixels"
    );

    // The red wall turns blue: blue rises, red falls.
    let blue = step(
        &mut s,
        json!({"cmd": "material", "name": "red", "material": {"name": "red",
            "pbrMetallicRoughness": {"baseColorFactor": [0.05, 0.05, 0.8, 1.0],
            "metallicFactor": 0.0, "roughnessFactor": 1.0}}}),
    );
    assert!(blue.mean(2) > base.mean(2) * 1.1 && blue.mean(0) < base.mean(0) * 0.95);

    // A new light brightens the box; moving it changes the image again.
    let lamp_at = |y: f32| {
        vec![
            1.0f32, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, y, 0.0, 1.0,
        ]
    };
    let lit = step(
        &mut s,
        json!({"cmd": "light", "node": "lamp", "matrix": lamp_at(0.6),
               "light": {"type": "POINT", "color": [1, 1, 1], "power": 20.0}}),
    );
    assert!(lit.mean(1) > blue.mean(1) * 1.2, "the light did not light");
    let lit_moved = step(
        &mut s,
        json!({"cmd": "transform", "node": "lamp", "matrix": lamp_at(0.2)}),
    );
    assert!(max_diff(&lit_moved, &lit) > 0.05, "the light did not move");
    let dimmer = step(
        &mut s,
        json!({"cmd": "light", "node": "lamp", "light": {"type": "POINT", "power": 5.0}}),
    );
    assert!(
        dimmer.mean(1) < lit_moved.mean(1),
        "the light's power did not change"
    );

    // Moving a block.
    let m = vec![
        1.0f32, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.3, 0.0, 0.0, 1.0,
    ];
    let block = step(
        &mut s,
        json!({"cmd": "transform", "node": "tall block", "matrix": m}),
    );
    assert!(max_diff(&block, &dimmer) > 0.05, "the block did not move");

    // The world: a bright sky seen through the open front brightens the image.
    let sky = step(
        &mut s,
        json!({"cmd": "world", "world": {"color": [1.0, 1.0, 1.0], "strength": 2.0}}),
    );
    assert!(
        sky.mean(1) > block.mean(1) * 1.05,
        "the world did not change"
    );

    // Hiding and showing an object: showing restores the image. Hiding made the baked block
    // an instance of itself at an identity placement (so a toggle rebuilds only the top
    // level): its hits are the same up to rounding in the last bit (measured 1.2e-7).
    let hidden = step(
        &mut s,
        json!({"cmd": "visibility", "node": "short block", "visible": false}),
    );
    assert!(max_diff(&hidden, &sky) > 0.05, "the block was not hidden");
    let shown = step(
        &mut s,
        json!({"cmd": "visibility", "node": "short block", "visible": true}),
    );
    let back = max_diff(&shown, &sky);
    assert!(back < 1e-5, "showing again must restore the image ({back})");

    // Replacing a mesh.
    let file = mesh_file(&dir, "short block");
    let replaced = step(
        &mut s,
        json!({"cmd": "mesh", "name": "short block", "path": file}),
    );
    assert!(
        max_diff(&replaced, &shown) > 0.05,
        "the mesh was not replaced"
    );

    // Settings: more samples refine the same generation's image further.
    let more = step(&mut s, json!({"cmd": "settings", "samples": 4}));
    assert_eq!(more.samples, 4);

    // Pause: no image while paused (samples 0 renders forever otherwise); resume goes on.
    s.send(json!({"cmd": "settings", "samples": 0}));
    generation += 1;
    loop {
        let (kind, p) = s.next().unwrap();
        if kind == IMAGE && Image::parse(&p).samples >= 8 {
            break;
        }
    }
    s.send(json!({"cmd": "pause"}));
    let mut last_before = 0;
    let paused_at = Instant::now();
    while paused_at.elapsed() < Duration::from_millis(400) {
        match s.frames.recv_timeout(Duration::from_millis(50)) {
            Ok((IMAGE, p)) => {
                let im = Image::parse(&p);
                assert!(
                    paused_at.elapsed() < Duration::from_millis(200),
                    "IMAGE {} spp while paused",
                    im.samples
                );
                last_before = im.samples;
            }
            _ => continue,
        }
    }
    s.send(json!({"cmd": "resume"}));
    loop {
        let (kind, p) = s.next().unwrap();
        if kind == IMAGE {
            let im = Image::parse(&p);
            assert_eq!(im.generation, generation);
            if im.samples > last_before + 16 {
                break;
            }
        }
    }
    s.send(json!({"cmd": "stop"}));
    assert_eq!(s.close(), 0);
}

#[test]
fn a_command_cancels_the_pass_in_flight() {
    let (mut s, _dir, _) = started("cancel", 2);
    // 256x256 with no sample target: the round from 16 to 32 samples is a million samples.
    s.send(json!({"cmd": "settings", "samples": 0}));
    s.send(view(256, 256, 1.94));
    loop {
        let (kind, p) = s.next().unwrap();
        if kind == IMAGE {
            let im = Image::parse(&p);
            if im.generation == 5 && im.samples == 16 {
                break;
            }
        }
    }
    // The round from 16 to 32 samples starts after the STATS that follows; it renders for
    // far longer than this pause.
    while s.next().is_some_and(|(k, _)| k != 17) {}
    std::thread::sleep(Duration::from_millis(50));
    {
        {}
    }
    let sent = Instant::now();
    s.send(view(256, 256, 2.2));
    let mut cancelled = false;
    loop {
        let (kind, p) = s.next().unwrap();
        if kind == LOG && String::from_utf8_lossy(&p[4..]).contains("generation 5: pass cancelled")
        {
            cancelled = true;
        }
        if kind == IMAGE {
            let im = Image::parse(&p);
            assert_eq!(
                im.generation, 6,
                "the pass of 16 to 32 samples was finished, not cancelled"
            );
            eprintln!(
                "first image after the command: {:.1} ms (pixel size {})",
                sent.elapsed().as_secs_f64() * 1e3,
                im.pixel_size
            );
            break;
        }
    }
    assert!(cancelled, "no pass was cancelled");
    assert_eq!(s.close(), 0);
}

#[test]
fn a_flood_of_views_renders_only_the_newest() {
    let (mut s, _dir, _) = started("flood", 1);
    let mut flood = Vec::new();
    for k in 0..200 {
        flood.extend(command(&view(48, 36, 1.94 + k as f32 * 0.005)));
    }
    s.send_raw(&flood);
    let (last, images, errors) = s.finish(3 + 200);
    assert!(errors.is_empty(), "{errors:?}");
    let mut generations: Vec<u64> = images.iter().map(|i| i.generation).collect();
    generations.dedup();
    eprintln!("generations rendered during the flood: {generations:?}");
    assert!(
        generations.len() <= 5,
        "{} of 200 views were rendered: {generations:?}",
        generations.len()
    );
    // The newest is the one rendered to the end: the same as that view alone.
    let mut alone = Session::start();
    alone.send(json!({"cmd": "settings", "samples": 1, "start_resolution": 16}));
    alone.send(json!({"cmd": "load", "path": scene(&folder("flood-alone"))}));
    alone.send(view(48, 36, 1.94 + 199.0 * 0.005));
    let (want, _, _) = alone.finish(3);
    assert_eq!(max_diff(&last, &want), 0.0);
    assert_eq!(s.close(), 0);
}

#[test]
fn malformed_commands_are_answered_and_the_session_survives() {
    let (mut s, dir, base) = started("malformed", 1);
    let cases: Vec<(Vec<u8>, Option<&str>, &str)> = vec![
        (frame(9, b"hello"), None, "not a command"),
        (frame(COMMAND, b"\x05\x00\x00\x00{oops"), None, "not JSON"),
        (frame(COMMAND, &[1, 2]), None, "JSON length"),
        (
            command(&json!({"cmd": "warp"})),
            Some("warp"),
            "unknown command",
        ),
        (
            command(&json!({"cmd": "view", "width": -3, "height": 2, "camera": {}})),
            Some("view"),
            "width",
        ),
        (
            command(&json!({"cmd": "transform", "node": "nobody", "matrix": camera_matrix(1.0)})),
            Some("transform"),
            "no node named `nobody`",
        ),
        (
            command(&json!({"cmd": "material", "name": "nothing", "material": {}})),
            Some("material"),
            "no material named",
        ),
        (
            command(&json!({"cmd": "load", "path": dir.join("missing.gltf")})),
            Some("load"),
            "missing.gltf",
        ),
        (
            command(&json!({"cmd": "settings", "pixel_size": 3})),
            Some("settings"),
            "pixel_size",
        ),
        (
            command(&json!({"cmd": "visibility", "node": "floor", "visible": "no"})),
            Some("visibility"),
            "true or false",
        ),
        (
            command(
                &json!({"cmd": "light", "node": "floor", "light": {"type": "POINT"}, "matrix": [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1]}),
            ),
            Some("light"),
            "singular",
        ),
    ];
    for (bytes, cmd, want) in cases {
        s.send_raw(&bytes);
        let e = s.error();
        assert_eq!(e["command"].as_str(), cmd, "{e}");
        assert_eq!(e["fatal"], json!(false));
        let m = e["message"].as_str().unwrap();
        assert!(m.contains(want), "`{want}` not in: {m}");
    }
    // Nothing changed: the next command works on the last good state.
    s.send(view(48, 36, 1.94));
    let (im, _, errors) = s.finish(4);
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(max_diff(&im, &base), 0.0);
    assert_eq!(s.close(), 0);
}

#[test]
fn end_of_input_exits_with_status_zero_even_mid_render() {
    let (mut s, _dir, _) = started("eof", 1);
    s.send(json!({"cmd": "settings", "samples": 0}));
    s.send(view(128, 128, 1.94));
    while s.next().is_some_and(|(k, _)| k != IMAGE) {}
    assert_eq!(s.close(), 0);
}

/// `tesela render --pipe` of `path`: its Combined RGBA pixels.
fn render_pixels(path: &Path, width: u32, height: u32, spp: u32) -> Vec<f32> {
    // The pipe mode stops when its stdin closes: keep it open until DONE.
    let mut child = Command::new(env!("CARGO_BIN_EXE_tesela"))
        .arg("render")
        .arg(path)
        .args(["--pipe", "--threads", "1", "--seed", "0"])
        .args([
            "--width",
            &width.to_string(),
            "--height",
            &height.to_string(),
        ])
        .args(["--spp", &spp.to_string(), "--max-depth", "16"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let stdin = child.stdin.take();
    let mut stdout = Vec::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_end(&mut stdout)
        .unwrap();
    drop(stdin);
    assert!(child.wait().unwrap().success(), "tesela render failed");
    let mut pixels = vec![0f32; (width * height * 4) as usize];
    let mut r = &stdout[..];
    while let Some((kind, p)) = read_frame(&mut r) {
        if kind == 2 {
            let u = |i: usize| u32::from_le_bytes(p[4 * i..4 * i + 4].try_into().unwrap());
            let (x, y, w, h) = (u(0), u(1), u(2), u(3));
            let data: Vec<f32> = (p[16..].chunks_exact(4))
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                .collect();
            for ty in 0..h {
                for tx in 0..w {
                    let at = (((y + ty) * width + x + tx) * 4) as usize;
                    let from = ((ty * w + tx) * 4) as usize;
                    pixels[at..at + 4].copy_from_slice(&data[from..from + 4]);
                }
            }
        }
    }
    pixels
}

#[test]
fn full_resolution_equals_tesela_render_bit_for_bit() {
    let (mut s, dir, _) = started("same-pixels", 8);
    // A 37x29 view: tiles and rows that do not divide evenly.
    s.send(view(37, 29, 1.94));
    let (im, images, _) = s.finish(4);
    // The session reached 8 samples in rounds of 1, 2, 4, 8 (on 2 threads).
    let rounds: Vec<u32> = (images.iter())
        .filter(|i| i.generation == 4 && i.pixel_size == 1)
        .map(|i| i.samples)
        .collect();
    assert_eq!(rounds, [1, 2, 4, 8]);
    let want = render_pixels(&dir.join("scene.gltf"), 37, 29, 8);
    let same = (im.pixels.iter().zip(&want)).all(|(a, b)| a.to_bits() == b.to_bits());
    let worst = (im.pixels.iter().zip(&want))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f32::max);
    assert!(
        same,
        "pixels differ from tesela render (largest difference {worst})"
    );
    assert_eq!(s.close(), 0);
}

#[test]
fn moving_an_object_twice_lands_where_one_move_does() {
    // The first move turns the baked block into an instance (the world's BVH is built once
    // more); the second only places the instance again.
    let at = |x: f32| {
        json!([
            1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, x, 0.0, 0.0, 1.0
        ])
    };
    let (mut twice, _d1, still) = started("move-twice", 2);
    twice.send(json!({"cmd": "transform", "node": "tall block", "matrix": at(0.2)}));
    twice.send(json!({"cmd": "transform", "node": "tall block", "matrix": at(-0.25)}));
    let (a, _, errors) = twice.finish(5);
    assert!(errors.is_empty(), "{errors:?}");
    let (mut once, _d2, _) = started("move-once", 2);
    once.send(json!({"cmd": "transform", "node": "tall block", "matrix": at(-0.25)}));
    let (b, _, _) = once.finish(4);
    let mean_diff = |x: &Image, y: &Image| {
        (x.pixels.iter().zip(&y.pixels))
            .map(|(p, q)| (p - q).abs() as f64)
            .sum::<f64>()
            / x.pixels.len() as f64
    };
    // A file with the block already there (baked at load): nothing may be left where the
    // block was, so only the rounding of instance against baked triangles differs.
    let dir = folder("move-file");
    let path = scene(&dir);
    let mut doc: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    for n in doc["nodes"].as_array_mut().unwrap() {
        if n["name"] == "tall block" {
            n["matrix"] = at(-0.25);
        }
    }
    std::fs::write(&path, doc.to_string()).unwrap();
    let mut filed = Session::start();
    filed.send(json!({"cmd": "settings", "samples": 2, "start_resolution": 16}));
    filed.send(json!({"cmd": "load", "path": path}));
    filed.send(view(48, 36, 1.94));
    let (c, _, _) = filed.finish(3);
    let moved = mean_diff(&a, &still);
    let apart = mean_diff(&a, &b);
    let from_file = mean_diff(&a, &c);
    eprintln!(
        "mean |twice - once| {apart:.2e}, |twice - file| {from_file:.2e}, |twice - unmoved| {moved:.2e}"
    );
    assert!(moved > 1e-2, "the block did not move");
    assert!(
        apart < moved * 0.01,
        "two moves differ from one: {apart} vs {moved}"
    );
    assert!(
        from_file < moved * 0.05,
        "the moved block differs from the file's: {from_file} vs {moved}"
    );
    assert_eq!(filed.close(), 0);
    assert_eq!(twice.close(), 0);
    assert_eq!(once.close(), 0);
}

/// pyoidn's library folder in the checkout's `.venv`, if installed there (as tests/denoise.rs).
fn checkout_wheel() -> Option<PathBuf> {
    let lib = Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/lib");
    std::fs::read_dir(lib)
        .ok()?
        .flatten()
        .map(|e| e.path().join("site-packages/pyoidn/oidn/lib"))
        .find(|d| d.is_dir())
}

#[test]
fn the_viewport_denoiser_denoises_what_is_sent() {
    let explicit = std::env::var_os(tesela::denoise::ENV_VAR)
        .is_none()
        .then(checkout_wheel)
        .flatten();
    if let Err(e) = tesela::denoise::Denoiser::load(explicit.as_deref(), 1) {
        eprintln!("SKIPPED (no Open Image Denoise): {e}");
        return;
    }
    let dir = folder("denoise");
    let path = scene(&dir);
    let lib = explicit.map(|p| p.display().to_string());
    let args: Vec<&str> = lib
        .iter()
        .flat_map(|l| ["--oidn-lib", l.as_str()])
        .collect();
    let run = |denoise: bool| {
        let mut s = Session::start_with(&args);
        s.send(json!({"cmd": "settings", "samples": 4, "denoise": denoise}));
        s.send(json!({"cmd": "load", "path": path}));
        s.send(view(64, 64, 1.94));
        let (im, _, errors) = s.finish(3);
        assert!(errors.is_empty(), "{errors:?}");
        assert_eq!(s.close(), 0);
        im
    };
    let (noisy, clean) = (run(false), run(true));
    assert!(
        !noisy.denoised && clean.denoised,
        "flag bit 1 must say denoised"
    );
    assert!(clean.pixels.iter().all(|v| v.is_finite()));
    // Denoising smooths the noise away but keeps the light: neighbours agree more, the
    // mean stays.
    let roughness = |im: &Image| {
        (im.pixels
            .chunks_exact(4)
            .zip(im.pixels.chunks_exact(4).skip(1)))
        .map(|(a, b)| (a[1] - b[1]).abs() as f64)
        .sum::<f64>()
    };
    eprintln!(
        "roughness {:.1} -> {:.1}",
        roughness(&noisy),
        roughness(&clean)
    );
    assert!(roughness(&clean) < 0.85 * roughness(&noisy));
    assert!((clean.mean(1) / noisy.mean(1) - 1.0).abs() < 0.05);
}

#[test]
fn sigterm_ends_the_session_at_once() {
    let (mut s, _dir, _) = started("sigterm", 1);
    s.send(json!({"cmd": "settings", "samples": 0}));
    s.send(view(128, 128, 1.94));
    while s.next().is_some_and(|(k, _)| k != IMAGE) {}
    // SAFETY: sends a signal to the child this test started.
    let r = unsafe { libc::kill(s.child.id() as libc::pid_t, libc::SIGTERM) };
    assert_eq!(r, 0);
    let t = Instant::now();
    let status = loop {
        if let Some(st) = s.child.try_wait().unwrap() {
            break st;
        }
        assert!(t.elapsed() < DEADLINE, "no exit after SIGTERM");
        std::thread::sleep(Duration::from_millis(5));
    };
    assert_eq!(status.code(), Some(130));
}

#[test]
fn a_border_renders_the_same_pixels_as_that_part_of_the_view() {
    let (mut s, _dir, full) = started("border", 2);
    let mut v = view(48, 36, 1.94);
    v["border"] = json!([10, 7, 21, 17]);
    s.send(v);
    let (im, images, errors) = s.finish(4);
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(im.window, [10, 7, 21, 17]);
    assert_eq!((im.width, im.height, im.pixel_size), (21, 17, 1));
    assert!(images.iter().all(|i| i.window == [10, 7, 21, 17]));
    for y in 0..17 {
        for x in 0..21 {
            let a = ((y * 21 + x) * 4) as usize;
            let b = (((y + 7) * 48 + x + 10) * 4) as usize;
            assert_eq!(im.pixels[a..a + 4], full.pixels[b..b + 4], "pixel {x} {y}");
        }
    }
    assert_eq!(s.close(), 0);
}

#[test]
fn a_textured_material_edit_keeps_its_texture() {
    // The Khronos samples beside the checkout, as tests/gltf_samples.rs finds them.
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/gltf-samples/BoxTextured/glTF/BoxTextured.gltf");
    if !file.exists() {
        eprintln!("SKIPPED: no glTF samples ({})", file.display());
        return;
    }
    let mut s = Session::start();
    s.send(json!({"cmd": "settings", "samples": 2, "start_resolution": 16}));
    s.send(json!({"cmd": "load", "path": file}));
    s.send(json!({"cmd": "world", "world": {"color": [1.0, 1.0, 1.0], "strength": 1.0}}));
    let m = vec![
        0.8f32, 0.0, -0.6, 0.0, -0.3, 0.87, -0.4, 0.0, 0.52, 0.5, 0.7, 0.0, 1.3, 1.2, 1.7, 1.0,
    ];
    s.send(json!({"cmd": "view", "width": 40, "height": 40,
                  "camera": {"matrix": m, "camera": tesela_camera()}}));
    let (a, _, errors) = s.finish(4);
    assert!(errors.is_empty(), "{errors:?}");
    // The box fills part of the view, lit by the world, with the logo's colours.
    let covered = a
        .pixels
        .chunks_exact(4)
        .filter(|p| (p[0] - 1.0).abs() > 0.05)
        .count();
    eprintln!(
        "pixels not the bare sky: {covered} of 1600; mean {:.3} {:.3} {:.3}",
        a.mean(0),
        a.mean(1),
        a.mean(2)
    );
    assert!(covered > 200, "the box is not in view");
    let textured = json!({"name": "Texture", "pbrMetallicRoughness":
        {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}});
    s.send(json!({"cmd": "material", "name": "Texture", "material": textured}));
    let (same, _, errors) = s.finish(5);
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(
        max_diff(&same, &a),
        0.0,
        "the same material JSON must render the same"
    );
    s.send(json!({"cmd": "material", "name": "Texture", "material":
        {"name": "Texture", "pbrMetallicRoughness": {"metallicFactor": 0.0}}}));
    let (plain, _, _) = s.finish(6);
    assert!(max_diff(&plain, &a) > 0.1, "the texture did not go away");
    s.send(json!({"cmd": "material", "name": "Texture", "material": textured}));
    let (back, _, _) = s.finish(7);
    assert_eq!(max_diff(&back, &a), 0.0, "the texture did not come back");
    assert_eq!(s.close(), 0);
}

#[test]
fn a_broken_framing_is_fatal_with_status_two() {
    let (mut s, _dir, _) = started("framing", 1);
    // A header announcing 4 GiB: no reader can find the next frame after it.
    s.send_raw(&[32, 0, 0, 0, 255, 255, 255, 255]);
    let e = s.error();
    assert_eq!(e["fatal"], json!(true), "{e}");
    assert!(e["message"].as_str().unwrap().contains("framing"), "{e}");
    assert_eq!(s.close(), 2);
}

/// The test scene with the short block's mesh placed a second time, by node `copy` at `x`.
fn scene_with_copy(dir: &Path, x: f32) -> PathBuf {
    let path = scene(dir);
    let mut doc: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let mesh = doc["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|n| n["name"] == "short block")
        .unwrap()["mesh"]
        .clone();
    let m = json!([
        1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, x, 0.0, 0.35, 1.0
    ]);
    doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"name": "copy", "mesh": mesh, "matrix": m}));
    let n = doc["nodes"].as_array().unwrap().len() - 1;
    doc["scenes"][0]["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!(n));
    std::fs::write(&path, doc.to_string()).unwrap();
    path
}

#[test]
fn moving_an_instance_equals_loading_it_moved() {
    // A mesh placed by two nodes is instanced at load: moving one node only places it again.
    let run = |name: &str, x_file: f32, x_moved: Option<f32>| {
        let path = scene_with_copy(&folder(name), x_file);
        let mut s = Session::start();
        s.send(json!({"cmd": "settings", "samples": 2, "start_resolution": 16}));
        s.send(json!({"cmd": "load", "path": path}));
        s.send(view(48, 36, 1.94));
        let mut generation = 3;
        if let Some(x) = x_moved {
            let m = json!([
                1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, x, 0.0, 0.35, 1.0
            ]);
            s.send(json!({"cmd": "transform", "node": "copy", "matrix": m}));
            generation += 1;
        }
        let (im, _, errors) = s.finish(generation);
        assert!(errors.is_empty(), "{errors:?}");
        assert_eq!(s.close(), 0);
        im
    };
    let (before, moved, file) = (
        run("inst-before", -0.6, None),
        run("inst-moved", -0.6, Some(0.55)),
        run("inst-file", 0.55, None),
    );
    assert!(
        max_diff(&moved, &before) > 0.05,
        "the instance did not move"
    );
    // Equal up to the last bits: the moved scene's acceleration structure is built from other
    // inputs than the file's, so a ray through an edge two triangles share may take the
    // other one (a difference of 7e-9 seen); a misplaced instance differs by > 0.05.
    let d = max_diff(&moved, &file);
    assert!(d < 1e-6, "moved instance differs from the file's by {d}");
}
