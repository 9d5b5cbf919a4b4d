//! Writing images: OpenEXR (linear float RGBA) or PNG (8-bit sRGB), chosen by extension.

use crate::render::Image;
use std::path::Path;

/// sRGB transfer function (encode) of a linear value, clamped to [0, 1].
#[inline]
pub fn srgb_encode(c: f32) -> f32 {
    let c = if c.is_finite() {
        c.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Writes `image` to `path` (`.exr` or `.png`).
pub fn write(image: &Image, path: &Path) -> Result<(), String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let shown = path.display();
    match ext.as_deref() {
        Some("exr") => {
            let w = image.width as usize;
            exr::prelude::write_rgba_file(path, w, image.height as usize, |x, y| {
                let p = image.pixels[y * w + x];
                (p[0], p[1], p[2], p[3])
            })
            .map_err(|e| format!("{shown}: cannot write EXR: {e}"))
        }
        Some("png") => {
            let mut buf = Vec::with_capacity(image.pixels.len() * 4);
            for p in &image.pixels {
                for c in &p[..3] {
                    buf.push((srgb_encode(*c) * 255.0 + 0.5) as u8);
                }
                buf.push((p[3].clamp(0.0, 1.0) * 255.0 + 0.5) as u8);
            }
            image::save_buffer(
                path,
                &buf,
                image.width,
                image.height,
                image::ExtendedColorType::Rgba8,
            )
            .map_err(|e| format!("{shown}: cannot write PNG: {e}"))
        }
        _ => Err(format!(
            "{shown}: unknown output format (use a .exr or .png file name)"
        )),
    }
}
