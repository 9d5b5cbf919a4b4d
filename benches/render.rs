//! `cargo bench`: renders the shipped scenes with each integrator and prints samples/s and rays/s
//! (no assertions: speed is measured, never asserted). Set TESELA_BENCH_THREADS to pin the
//! thread count (default: all cores).

use std::sync::atomic::AtomicBool;
use tesela::emitter::LightChoice;
use tesela::render::{self, RenderOptions};
use tesela::render_scene::RenderScene;
use tesela::scene::builtin;

fn main() {
    // `cargo test --benches` runs bench binaries with `--bench` absent: stay quick there.
    let quick = !std::env::args().any(|a| a == "--bench");
    let threads = std::env::var("TESELA_BENCH_THREADS")
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(0);
    let (size, spp) = if quick { (32, 1) } else { (256, 32) };
    println!(
        "{:<16} {:<12} {:>9} {:>12} {:>12} {:>10}",
        "scene", "integrator", "seconds", "Msamples/s", "Mrays/s", "BVH s"
    );
    for name in builtin::NAMES {
        let t = std::time::Instant::now();
        let scene = RenderScene::new(builtin::by_name(name).unwrap(), LightChoice::Power);
        let build = t.elapsed().as_secs_f64();
        for integrator in ["direct_mis", "path_mis"] {
            let opts = RenderOptions {
                width: size,
                height: size,
                spp,
                max_depth: if integrator == "direct_mis" { 2 } else { 7 },
                integrator: integrator.into(),
                threads,
                ..Default::default()
            };
            let (_, s) = render::render(&scene, &opts, &AtomicBool::new(false), &|_, _, _| {})
                .expect("render");
            println!(
                "{:<16} {:<12} {:>9.3} {:>12.3} {:>12.3} {:>10.3}",
                name,
                integrator,
                s.seconds,
                s.samples_per_second / 1e6,
                s.rays_per_second / 1e6,
                build
            );
        }
    }
}
