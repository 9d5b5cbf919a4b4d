//! Texture lookup: bilinear (Cycles' "Linear", no mipmaps) or nearest, with glTF wrap modes.
//! Texture coordinates follow glTF: `(0, 0)` is the image's top-left corner.
//! Colour (sRGB) textures are filtered on their encoded values and decoded to linear after
//! filtering, as Cycles does with 8-bit images.

use crate::scene::{Image, Texture, Wrap};
use glam::{Vec2, Vec4};
use std::sync::OnceLock;

/// sRGB transfer function decode table for 8-bit values.
fn srgb_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = [0.0; 256];
        for (i, v) in t.iter_mut().enumerate() {
            let c = i as f32 / 255.0;
            *v = if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            };
        }
        t
    })
}

#[inline]
fn wrap(i: i64, n: u32, mode: Wrap) -> usize {
    let n = n as i64;
    let r = match mode {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::ClampToEdge => i.clamp(0, n - 1),
        Wrap::MirroredRepeat => {
            let p = i.rem_euclid(2 * n);
            if p < n { p } else { 2 * n - 1 - p }
        }
    };
    r as usize
}

/// Encoded texel value in [0, 1].
#[inline]
fn texel(img: &Image, x: usize, y: usize) -> Vec4 {
    let p = img.rgba8[y * img.width as usize + x];
    Vec4::new(p[0] as f32, p[1] as f32, p[2] as f32, p[3] as f32) / 255.0
}

/// A float texel, linear (an sRGB-tagged float image is decoded per texel, before filtering,
/// as Cycles converts float images to linear when it loads them).
#[inline]
fn texel_f(img: &Image, x: usize, y: usize, srgb: bool) -> Vec4 {
    let v = Vec4::from_array(img.float[y * img.width as usize + x]);
    if srgb {
        Vec4::new(
            srgb_to_linear(v.x),
            srgb_to_linear(v.y),
            srgb_to_linear(v.z),
            v.w,
        )
    } else {
        v
    }
}

/// sRGB decode of a filtered encoded value in [0, 1].
#[inline]
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[inline]
fn decode(v: Vec4, srgb: bool) -> Vec4 {
    if srgb {
        Vec4::new(
            srgb_to_linear(v.x),
            srgb_to_linear(v.y),
            srgb_to_linear(v.z),
            v.w,
        )
    } else {
        v
    }
}

/// Looks up `tex` (whose image is `img`) at `uv`. `srgb` decodes colour data to linear.
pub fn lookup(tex: &Texture, img: &Image, uv: Vec2, srgb: bool) -> Vec4 {
    if img.width == 0 || img.height == 0 || !uv.is_finite() {
        return Vec4::ONE;
    }
    let x = uv.x as f64 * img.width as f64 - 0.5;
    let y = uv.y as f64 * img.height as f64 - 0.5;
    // Keep coordinates in a range where i64 conversion is exact.
    let x = x.clamp(-1e9, 1e9);
    let y = y.clamp(-1e9, 1e9);
    if !img.float.is_empty() {
        if tex.nearest {
            let xi = wrap((x + 0.5).floor() as i64, img.width, tex.wrap_s);
            let yi = wrap((y + 0.5).floor() as i64, img.height, tex.wrap_t);
            return texel_f(img, xi, yi, srgb);
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let xa = wrap(x0, img.width, tex.wrap_s);
        let xb = wrap(x0 + 1, img.width, tex.wrap_s);
        let ya = wrap(y0, img.height, tex.wrap_t);
        let yb = wrap(y0 + 1, img.height, tex.wrap_t);
        let top = texel_f(img, xa, ya, srgb).lerp(texel_f(img, xb, ya, srgb), fx);
        let bottom = texel_f(img, xa, yb, srgb).lerp(texel_f(img, xb, yb, srgb), fx);
        return top.lerp(bottom, fy);
    }
    if img.rgba8.is_empty() {
        return Vec4::ONE;
    }
    if tex.nearest {
        let xi = wrap((x + 0.5).floor() as i64, img.width, tex.wrap_s);
        let yi = wrap((y + 0.5).floor() as i64, img.height, tex.wrap_t);
        let p = img.rgba8[yi * img.width as usize + xi];
        if srgb {
            let t = srgb_table();
            return Vec4::new(
                t[p[0] as usize],
                t[p[1] as usize],
                t[p[2] as usize],
                p[3] as f32 / 255.0,
            );
        }
        return texel(img, xi, yi);
    }
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let xa = wrap(x0, img.width, tex.wrap_s);
    let xb = wrap(x0 + 1, img.width, tex.wrap_s);
    let ya = wrap(y0, img.height, tex.wrap_t);
    let yb = wrap(y0 + 1, img.height, tex.wrap_t);
    let top = texel(img, xa, ya).lerp(texel(img, xb, ya), fx);
    let bottom = texel(img, xa, yb).lerp(texel(img, xb, yb), fx);
    decode(top.lerp(bottom, fy), srgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker() -> Image {
        Image {
            width: 2,
            height: 2,
            float: Vec::new(),
            rgba8: vec![
                [255, 0, 0, 255],
                [0, 255, 0, 255],
                [0, 0, 255, 255],
                [255, 255, 255, 255],
            ],
        }
    }

    #[test]
    fn texel_centres_and_wrap() {
        let img = checker();
        let tex = Texture {
            image: 0,
            wrap_s: Wrap::Repeat,
            wrap_t: Wrap::Repeat,
            nearest: false,
        };
        let c = lookup(&tex, &img, Vec2::new(0.25, 0.25), false);
        assert!(
            (c - Vec4::new(1.0, 0.0, 0.0, 1.0)).length() < 1e-6,
            "top-left texel"
        );
        let c = lookup(&tex, &img, Vec2::new(1.25, 0.75), false);
        assert!(
            (c - Vec4::new(0.0, 0.0, 1.0, 1.0)).length() < 1e-6,
            "repeat"
        );
        let mid = lookup(&tex, &img, Vec2::new(0.5, 0.25), false);
        assert!(
            (mid - Vec4::new(0.5, 0.5, 0.0, 1.0)).length() < 1e-6,
            "bilinear"
        );
        let s = lookup(&tex, &img, Vec2::new(0.75, 0.75), true);
        assert!((s.x - 1.0).abs() < 1e-6);
        let half = srgb_table()[128];
        assert!((half - 0.2158605).abs() < 1e-5);
        // Filtering happens before decoding: halfway between red and green is sRGB 0.5.
        let mid = lookup(&tex, &img, Vec2::new(0.5, 0.25), true);
        assert!((mid.x - srgb_to_linear(0.5)).abs() < 1e-6, "{mid}");
    }
}
