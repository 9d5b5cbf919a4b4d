//! Pipe mode (the Blender add-on's renderer) ends when the add-on's process dies: every pipe
//! closes at once, so the renderer can no longer even write its last words to stderr, and
//! must still exit rather than render on for minutes (a farm killing Blender would leave it
//! behind).

use std::io::Read;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[test]
fn pipe_render_exits_when_its_reader_dies_mid_render() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tesela"))
        .args([
            "render",
            "--builtin",
            "cornell-box",
            "--pipe",
            "--pipe-version",
            "2",
        ])
        // One thread, a million samples per pixel: no row of the image finishes for minutes,
        // so only the cancel watchdog can end the process in time.
        .args([
            "--spp",
            "1048576",
            "--width",
            "16",
            "--height",
            "16",
            "--threads",
            "1",
        ])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start tesela");
    let mut out = child.stdout.take().expect("stdout");
    // The HELLO frame: the render is about to start.
    let mut hello = [0u8; 8];
    out.read_exact(&mut hello)
        .expect("the renderer's first frame");
    std::thread::sleep(Duration::from_millis(300));
    drop(child.stdin.take());
    drop(out);
    drop(child.stderr.take());
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if start.elapsed() > Duration::from_secs(20) {
            child.kill().ok();
            child.wait().ok();
            panic!("the renderer kept rendering after its reader died");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(status.code(), Some(130), "exit status {status:?}");
}
