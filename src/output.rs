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

/// The view layer name of multi-layer EXR channels (`ViewLayer.Depth.Z`), Blender's default.
pub const VIEW_LAYER: &str = "ViewLayer";

/// Writes `image` with its passes as a multi-layer OpenEXR file, channels named as Blender
/// names them (`ViewLayer.Combined.R`, `ViewLayer.Depth.Z`, `ViewLayer.Denoising Normal.X`),
/// so Blender's image editor and compositor open it as render layers.
fn write_multilayer(image: &Image, path: &Path) -> Result<(), String> {
    use exr::prelude::*;
    let (w, h) = (image.width as usize, image.height as usize);
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = Default::default();
    for (c, id) in "RGBA".chars().enumerate() {
        let v: Vec<f32> = image.pixels.iter().map(|p| p[c]).collect();
        channels.push(AnyChannel::new(
            format!("{VIEW_LAYER}.Combined.{id}").as_str(),
            FlatSamples::F32(v),
        ));
    }
    let stride = image.passes.stride();
    for (pass, at) in image.passes.iter() {
        for (c, id) in pass.channel_ids().chars().enumerate() {
            let v: Vec<f32> = image.aovs.chunks_exact(stride).map(|r| r[at + c]).collect();
            channels.push(AnyChannel::new(
                format!("{VIEW_LAYER}.{}.{id}", pass.blender_name()).as_str(),
                FlatSamples::F32(v),
            ));
        }
    }
    let layer = Layer::new(
        (w, h),
        LayerAttributes::default(),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(channels),
    );
    exr::image::Image::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|e| format!("{}: cannot write EXR: {e}", path.display()))
}

/// Writes `image` to `path` (`.exr` or `.png`). With passes, an EXR is multi-layer; a PNG
/// holds Combined only.
pub fn write(image: &Image, path: &Path) -> Result<(), String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let shown = path.display();
    match ext.as_deref() {
        Some("exr") if !image.passes.is_empty() => write_multilayer(image, path),
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
