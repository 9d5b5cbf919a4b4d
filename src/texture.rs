//! Texture lookup: bilinear (Cycles' "Linear", no mipmaps) or nearest, with glTF wrap modes.
//! Texture coordinates follow glTF: `(0, 0)` is the image's top-left corner.
//! Colour (sRGB) textures, 8-bit or float, are filtered on their encoded values and decoded to
//! linear after filtering, as Cycles does with every sRGB image it reads from a file (its
//! `compress_as_srgb`: the decode runs in the kernel, after interpolation).

use crate::scene::{Image, Texture, Wrap};
use glam::{Vec2, Vec4};

/// sRGB transfer function decode table for 8-bit values.
#[cfg(test)]
fn srgb_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
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

/// Texel index `i` wrapped into `0..n` by `mode`.
#[inline(always)]
pub fn wrap(i: i64, n: u32, mode: Wrap) -> usize {
    let n = n as i64;
    if (0..n).contains(&i) {
        // Every mode leaves an index inside the image alone; skip their divisions.
        return i as usize;
    }
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

/// A float texel as stored (sRGB-encoded when the image is tagged sRGB: decoded after
/// filtering).
#[inline]
fn texel_f(img: &Image, x: usize, y: usize) -> Vec4 {
    Vec4::from_array(img.float[y * img.width as usize + x])
}

/// sRGB decode of a filtered encoded value (values above 1 follow the same power law, as
/// Cycles' `color_srgb_to_linear` does).
#[inline]
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// sRGB decode of a filtered, encoded colour when `srgb` (alpha unchanged).
#[inline]
pub fn decode(v: Vec4, srgb: bool) -> Vec4 {
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

/// Closest or bilinear filtering at glTF `uv` of an image of `width × height` texels whose
/// texel `(x, y)` (integer coordinates before any wrapping) is `fetch(x, y)`. The one filter
/// every image lookup uses; `fetch` decides wrapping, clipping and the texel's encoding.
#[inline(always)]
pub fn filter(
    width: u32,
    height: u32,
    nearest: bool,
    uv: Vec2,
    fetch: impl Fn(i64, i64) -> Vec4,
) -> Vec4 {
    if nearest {
        // Clamped to a range where the i64 conversion is exact.
        let x = (uv.x as f64 * width as f64 - 0.5).clamp(-1e9, 1e9);
        let y = (uv.y as f64 * height as f64 - 0.5).clamp(-1e9, 1e9);
        return fetch((x + 0.5).floor() as i64, (y + 0.5).floor() as i64);
    }
    let (x0, y0, fx, fy) = bilinear_at(width, height, uv);
    let top = fetch(x0, y0).lerp(fetch(x0 + 1, y0), fx);
    let bottom = fetch(x0, y0 + 1).lerp(fetch(x0 + 1, y0 + 1), fx);
    top.lerp(bottom, fy)
}

/// The texel `(x0, y0)` at or before glTF `uv` and the fractions `(fx, fy)` towards the next
/// ones (texel centres at half-integers; clamped to a range where the i64 conversion is
/// exact): where bilinear and cubic filtering take their texels and weights.
#[inline(always)]
fn bilinear_at(width: u32, height: u32, uv: Vec2) -> (i64, i64, f32, f32) {
    let x = (uv.x as f64 * width as f64 - 0.5).clamp(-1e9, 1e9);
    let y = (uv.y as f64 * height as f64 - 0.5).clamp(-1e9, 1e9);
    let (x0, y0) = (x.floor(), y.floor());
    (x0 as i64, y0 as i64, (x - x0) as f32, (y - y0) as f32)
}

/// Cycles' cubic interpolation: a uniform cubic B-spline over the 4 × 4 texels around `uv`
/// (glTF convention, as [`filter`]), texel centres at half-integers; `fetch` wraps or clips.
/// Its weights are positive, so the result stays within the texels' range.
pub fn filter_cubic(width: u32, height: u32, uv: Vec2, fetch: impl Fn(i64, i64) -> Vec4) -> Vec4 {
    let (x0, y0, tx, ty) = bilinear_at(width, height, uv);
    let (u, v) = (bspline_weights(tx), bspline_weights(ty));
    let mut sum = Vec4::ZERO;
    for (j, wy) in v.iter().enumerate() {
        let mut row = Vec4::ZERO;
        for (i, wx) in u.iter().enumerate() {
            row += *wx * fetch(x0 + i as i64 - 1, y0 + j as i64 - 1);
        }
        sum += *wy * row;
    }
    sum
}

/// The uniform cubic B-spline's weights for the texels at offsets -1, 0, 1, 2 of a point a
/// fraction `t` past texel 0 (they sum to 1).
#[inline]
fn bspline_weights(t: f32) -> [f32; 4] {
    [
        (((-1.0 / 6.0) * t + 0.5) * t - 0.5) * t + 1.0 / 6.0,
        ((0.5 * t - 1.0) * t) * t + 2.0 / 3.0,
        ((-0.5 * t + 0.5) * t + 0.5) * t + 1.0 / 6.0,
        (1.0 / 6.0) * t * t * t,
    ]
}

/// Looks up `tex` (whose image is `img`) at `uv`. `srgb` decodes colour data to linear.
pub fn lookup(tex: &Texture, img: &Image, uv: Vec2, srgb: bool) -> Vec4 {
    if img.width == 0 || img.height == 0 || !uv.is_finite() {
        return Vec4::ONE;
    }
    let (w, h) = (img.width, img.height);
    if !img.float.is_empty() {
        if tex.nearest {
            return decode(filter(w, h, true, uv, |x, y| fetch_f(tex, img, x, y)), srgb);
        }
        // The bilinear filter written out: the four fetches inline (a closure passed to
        // `filter` stays a call per texel).
        let (x0, y0, fx, fy) = bilinear_at(w, h, uv);
        let top = fetch_f(tex, img, x0, y0).lerp(fetch_f(tex, img, x0 + 1, y0), fx);
        let bottom = fetch_f(tex, img, x0, y0 + 1).lerp(fetch_f(tex, img, x0 + 1, y0 + 1), fx);
        return decode(top.lerp(bottom, fy), srgb);
    }
    if img.rgba8.is_empty() {
        return Vec4::ONE;
    }
    let v = if tex.nearest {
        filter(w, h, true, uv, |x, y| fetch_8(tex, img, x, y))
    } else {
        let (x0, y0, fx, fy) = bilinear_at(w, h, uv);
        let top = fetch_8(tex, img, x0, y0).lerp(fetch_8(tex, img, x0 + 1, y0), fx);
        let bottom = fetch_8(tex, img, x0, y0 + 1).lerp(fetch_8(tex, img, x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    };
    decode(v, srgb)
}

/// The wrapped texel `(x, y)` of an 8-bit image, encoded (inlined into the filter: it runs
/// four times per bilinear lookup).
#[inline(always)]
fn fetch_8(tex: &Texture, img: &Image, x: i64, y: i64) -> Vec4 {
    texel(
        img,
        wrap(x, img.width, tex.wrap_s),
        wrap(y, img.height, tex.wrap_t),
    )
}

/// The wrapped texel `(x, y)` of a float image, as stored.
#[inline(always)]
fn fetch_f(tex: &Texture, img: &Image, x: i64, y: i64) -> Vec4 {
    texel_f(
        img,
        wrap(x, img.width, tex.wrap_s),
        wrap(y, img.height, tex.wrap_t),
    )
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
        // The same for float texels tagged sRGB (16-bit PNGs, sRGB EXRs), above 1 too: the
        // encoded values are interpolated, then decoded.
        let float = Image {
            width: 2,
            height: 1,
            rgba8: Vec::new(),
            float: vec![[0.0, 2.0, 0.5, 1.0], [1.0, 4.0, 0.5, 0.5]],
        };
        let f = lookup(&tex, &float, Vec2::new(0.5, 0.5), true);
        let want = [
            srgb_to_linear(0.5),
            srgb_to_linear(3.0),
            srgb_to_linear(0.5),
            0.75,
        ];
        assert!(
            (f - Vec4::from_array(want)).abs().max_element() < 1e-6,
            "{f} against {want:?}"
        );
        let closest = Texture {
            nearest: true,
            ..tex.clone()
        };
        let c = lookup(&closest, &float, Vec2::new(0.7, 0.5), true);
        assert!((c.y - srgb_to_linear(4.0)).abs() < 1e-5, "{c}");
        let linear = lookup(&tex, &float, Vec2::new(0.5, 0.5), false);
        assert!((linear - Vec4::new(0.5, 3.0, 0.5, 0.75)).length() < 1e-6);
    }

    #[test]
    fn cubic_is_the_uniform_bspline() {
        // A single bright texel in an 8 x 8 image (repeating): at its centre the B-spline gives
        // 2/3 of it, half a texel off 23/48, a texel off 1/6 (the linear filter: 1, 1/2, 0).
        let spike = |x: i64, y: i64| {
            let (x, y) = (x.rem_euclid(8), y.rem_euclid(8));
            if (x, y) == (3, 4) {
                Vec4::ONE
            } else {
                Vec4::ZERO
            }
        };
        let at = |tx: f32, ty: f32| filter_cubic(8, 8, Vec2::new(tx / 8.0, ty / 8.0), spike).x;
        assert!((at(3.5, 4.5) - 4.0 / 9.0).abs() < 1e-6, "{}", at(3.5, 4.5));
        assert!((at(4.0, 4.5) - 2.0 / 3.0 * 23.0 / 48.0).abs() < 1e-6);
        assert!((at(4.5, 4.5) - 2.0 / 3.0 / 6.0).abs() < 1e-6);
        // A linear ramp is reproduced exactly, and the weights sum to one.
        let ramp = |x: i64, _y: i64| Vec4::splat(x as f32);
        for x in [2.5f32, 3.1, 4.75, 5.5] {
            let v = filter_cubic(16, 16, Vec2::new(x / 16.0, 0.5), ramp).x;
            assert!((v - (x - 0.5)).abs() < 1e-4, "{x}: {v}");
        }
        let ones = filter_cubic(8, 8, Vec2::new(0.37, 0.61), |_, _| Vec4::ONE);
        assert!((ones - Vec4::ONE).length() < 1e-6);
    }
}
