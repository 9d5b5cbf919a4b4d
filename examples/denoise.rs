//! Denoises an EXR with Open Image Denoise, for trying the denoiser by hand.
//!
//! ```sh
//! cargo run --release --example denoise -- IN.exr OUT.exr [ALBEDO.exr [NORMAL.exr]] [--no-prefilter]
//! ```
//!
//! The library is found as the renderer finds it (`TESELA_OIDN_LIB`, next to the executable,
//! a `.venv` with PyPI's `pyoidn`). Normals are taken as stored (components in [-1, 1]).

use exr::prelude::*;
use tesela::denoise::{Denoiser, Input};

/// RGB interleaved pixels of the first RGBA layer of `path`, with its size.
fn read(path: &str) -> std::result::Result<(usize, usize, Vec<f32>), String> {
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![0.0f32; size.area() * 3]),
        |(w, px), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let i = 3 * (pos.y() * *w + pos.x());
            px[i..i + 3].copy_from_slice(&[r, g, b]);
        },
    )
    .map_err(|e| format!("{path}: {e}"))?;
    let size = image.layer_data.size;
    Ok((
        size.width(),
        size.height(),
        image.layer_data.channel_data.pixels.1,
    ))
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> std::result::Result<(), Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let prefilter = !args.iter().any(|a| a == "--no-prefilter");
    args.retain(|a| a != "--no-prefilter");
    let [input, output, aux @ ..] = args.as_slice() else {
        return Err(
            "usage: denoise IN.exr OUT.exr [ALBEDO.exr [NORMAL.exr]] [--no-prefilter]".into(),
        );
    };
    let denoiser = Denoiser::load(None, 0)?;
    eprintln!("{}", denoiser.describe());
    let (width, height, color) = read(input)?;
    let aux: Vec<Vec<f32>> = aux
        .iter()
        .map(|p| {
            let (w, h, px) = read(p)?;
            if (w, h) != (width, height) {
                return Err(format!("{p} is {w}x{h}, {input} is {width}x{height}"));
            }
            Ok(px)
        })
        .collect::<std::result::Result<_, String>>()?;
    let start = std::time::Instant::now();
    let out = denoiser.denoise(
        &Input {
            width,
            height,
            color: &color,
            albedo: aux.first().map(Vec::as_slice),
            normal: aux.get(1).map(Vec::as_slice),
        },
        prefilter,
    )?;
    eprintln!(
        "denoised {width}x{height} in {:.2} s",
        start.elapsed().as_secs_f64()
    );
    write_rgb_file(output, width, height, |x, y| {
        let i = 3 * (y * width + x);
        (out[i], out[i + 1], out[i + 2])
    })
    .map_err(|e| format!("{output}: {e}"))?;
    Ok(())
}
