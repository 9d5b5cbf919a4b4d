//! Image files carried whole in a `TESELA_images` entry (`"encoded"`): the add-on embeds the
//! bytes of files it cannot read pixels from itself (the tiles of a UDIM image after the
//! first), and the renderer decodes them as Cycles' image loader would: 8-bit PNG and JPEG as
//! bytes in their own encoding, 16-bit PNG and Radiance HDR as floats in their own encoding,
//! OpenEXR as scene-linear floats with its associated alpha.

use crate::scene::Image;
use std::io::Cursor;

/// Largest side of a decoded image (glTF images and embedded files alike).
pub(crate) const MAX_SIDE: u32 = 16384;
/// Largest decoder allocation for one image.
const MAX_ALLOC: u64 = 512 << 20;

/// Decodes `bytes` with the `image` crate, accepting only `formats` (`supported`: their names
/// for the messages, as "PNG and JPEG"; `either`: as "a PNG or JPEG"), within the size limits.
pub(crate) fn read(
    bytes: &[u8],
    formats: &[image::ImageFormat],
    (supported, either): (&str, &str),
) -> Result<image::DynamicImage, String> {
    let mut reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?;
    match reader.format() {
        Some(f) if formats.contains(&f) => {}
        Some(f) => {
            return Err(format!(
                "unsupported image format {f:?} ({supported} are supported)"
            ));
        }
        None => return Err(format!("not {either} image")),
    }
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_SIDE);
    limits.max_image_height = Some(MAX_SIDE);
    limits.max_alloc = Some(MAX_ALLOC);
    reader.limits(limits);
    reader.decode().map_err(|e| e.to_string())
}

/// `img` as RGBA8 texels, rows top to bottom.
pub(crate) fn bytes_image(img: &image::DynamicImage) -> Image {
    let rgba = img.to_rgba8();
    let (width, height) = rgba.dimensions();
    Image {
        width,
        height,
        rgba8: rgba
            .into_raw()
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect(),
        float: Vec::new(),
    }
}

/// Decodes `bytes` (PNG, JPEG, Radiance HDR or OpenEXR, told apart by their signatures) into
/// rows top to bottom. Float texels are decoded from sRGB to linear first with `linearize` (a
/// packed image, which Cycles takes from Blender's linear buffers); with `associate`,
/// straight-alpha float texels (16-bit PNG) then get their colour multiplied by alpha, as
/// Cycles associates alpha on load. Byte texels stay as they are (associated at lookup), and
/// EXR's alpha is associated already.
pub(crate) fn decode(bytes: &[u8], associate: bool, linearize: bool) -> Result<Image, String> {
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        let mut img = decode_exr(bytes)?;
        if linearize {
            img.float.iter_mut().for_each(|t| *t = srgb_to_linear(*t));
        }
        return Ok(img);
    }
    use image::ImageFormat::{Hdr, Jpeg, Png};
    let names = (
        "PNG, JPEG, Radiance HDR and OpenEXR",
        "a PNG, JPEG, Radiance HDR or OpenEXR",
    );
    let img = read(bytes, &[Png, Jpeg, Hdr], names)?;
    let bits = img.color().bits_per_pixel() / u16::from(img.color().channel_count());
    if bits <= 8 {
        return Ok(bytes_image(&img));
    }
    let (width, height) = (img.width(), img.height());
    let float = img
        .to_rgba32f()
        .into_raw()
        .chunks_exact(4)
        .map(|c| {
            let mut v = [c[0], c[1], c[2], c[3]].map(|x| if x.is_finite() { x } else { 0.0 });
            if linearize {
                v = srgb_to_linear(v);
            }
            if associate {
                [v[0] * v[3], v[1] * v[3], v[2] * v[3], v[3]]
            } else {
                v
            }
        })
        .collect();
    Ok(Image {
        width,
        height,
        rgba8: Vec::new(),
        float,
    })
}

/// The colour of an RGBA texel decoded from sRGB (alpha kept).
fn srgb_to_linear(t: [f32; 4]) -> [f32; 4] {
    let c = crate::texture::decode(glam::Vec4::from_array(t), true);
    c.to_array()
}

fn decode_exr(bytes: &[u8]) -> Result<crate::scene::Image, String> {
    use exr::prelude::*;
    struct Pixels {
        width: usize,
        texels: Vec<[f32; 4]>,
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |resolution, _| {
                let (w, h) = (resolution.width(), resolution.height());
                let fits = w > 0 && h > 0 && w <= MAX_SIDE as usize && h <= MAX_SIDE as usize;
                Pixels {
                    width: w,
                    texels: if fits {
                        vec![[0.0; 4]; w * h]
                    } else {
                        Vec::new()
                    },
                }
            },
            |p: &mut Pixels, pos, (r, g, b, a): (f32, f32, f32, f32)| {
                if let Some(t) = p.texels.get_mut(pos.y() * p.width + pos.x()) {
                    *t = [r, g, b, a].map(|x| if x.is_finite() { x } else { 0.0 });
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| e.to_string())?;
    let size = image.layer_data.size;
    let pixels = image.layer_data.channel_data.pixels;
    if pixels.texels.is_empty() {
        return Err(format!(
            "the image is {}x{}; at most {MAX_SIDE} on a side is supported",
            size.width(),
            size.height()
        ));
    }
    Ok(crate::scene::Image {
        width: size.width() as u32,
        height: size.height() as u32,
        rgba8: Vec::new(),
        float: pixels.texels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png(bits16: bool) -> Vec<u8> {
        let mut out = Vec::new();
        let enc = image::codecs::png::PngEncoder::new(&mut out);
        use image::ImageEncoder;
        if bits16 {
            // 2 x 1: half-transparent orange, opaque blue.
            let px: Vec<u8> = [65535u16, 26214, 0, 32768, 0, 0, 52428, 65535]
                .iter()
                .flat_map(|v| v.to_ne_bytes())
                .collect();
            enc.write_image(&px, 2, 1, image::ExtendedColorType::Rgba16)
                .unwrap();
        } else {
            enc.write_image(
                &[255, 102, 0, 128, 0, 0, 204, 255],
                2,
                1,
                image::ExtendedColorType::Rgba8,
            )
            .unwrap();
        }
        out
    }

    #[test]
    fn eight_bit_png_stays_bytes_and_straight() {
        let img = decode(&png(false), true, false).unwrap();
        assert_eq!((img.width, img.height), (2, 1));
        assert!(img.float.is_empty());
        assert_eq!(img.rgba8, vec![[255, 102, 0, 128], [0, 0, 204, 255]]);
    }

    #[test]
    fn sixteen_bit_png_is_float_and_associated_on_request() {
        let straight = decode(&png(true), false, false).unwrap();
        assert!(straight.rgba8.is_empty());
        let a = 32768.0 / 65535.0;
        assert!((straight.float[0][0] - 1.0).abs() < 1e-6);
        assert!((straight.float[0][3] - a).abs() < 1e-6);
        let assoc = decode(&png(true), true, false).unwrap();
        assert!((assoc.float[0][0] - a).abs() < 1e-6);
        assert!((assoc.float[0][1] - 0.4 * a).abs() < 1e-4);
        assert_eq!(assoc.float[1], straight.float[1]);
        // Packed: linear first, then associated; alpha untouched.
        let lin = decode(&png(true), true, true).unwrap();
        let g = crate::texture::decode(glam::Vec4::new(0.4, 0.0, 0.0, 1.0), true).x;
        assert!((lin.float[0][1] - g * a).abs() < 1e-4, "{:?}", lin.float[0]);
        assert!((lin.float[0][3] - a).abs() < 1e-6);
    }

    #[test]
    fn exr_reads_linear_floats_with_default_alpha() {
        use exr::prelude::*;
        let path = std::env::temp_dir().join(format!("tesela-tile-{}.exr", std::process::id()));
        write_rgb_file(&path, 3, 2, |x, y| (x as f32, y as f32 * 2.0, 7.5f32)).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::remove_file(&path).ok();
        let img = decode(&bytes, true, false).unwrap();
        assert_eq!((img.width, img.height), (3, 2));
        assert_eq!(img.float[3 + 2], [2.0, 2.0, 7.5, 1.0]);
    }

    #[test]
    fn other_bytes_are_a_clear_error() {
        let e = decode(b"GIF89a....", false, false).unwrap_err();
        assert!(e.contains("PNG"), "{e}");
        assert!(decode(&[0x76, 0x2f, 0x31, 0x01, 0, 0], false, false).is_err());
    }
}
