//! Colour nodes evaluated like Cycles 5.0 SVM: RGB<->HSV/HSL (`util/color.h`), Separate /
//! Combine Color, Hue/Saturation/Value, Brightness/Contrast, Gamma, Invert, RGB to BW,
//! Blackbody and Wavelength. Every function is total: NaN and infinities never panic.

use super::math::{cmax, cmin, float_to_int, fract, saturate};
use glam::Vec3;

/// Cycles `rgb_to_hsv`: `v = max`, `s = (max - min) / max` (0 when `max == 0`), hue in
/// [0, 1) from the classic hexcone formula (0 when `s == 0`).
pub fn rgb_to_hsv(rgb: Vec3) -> Vec3 {
    let cmax_ = rgb.x.max(rgb.y.max(rgb.z));
    let cmin_ = cmin(rgb.x, cmin(rgb.y, rgb.z));
    let cdelta = cmax_ - cmin_;
    let v = cmax_;
    let s = if cmax_ != 0.0 { cdelta / cmax_ } else { 0.0 };
    let mut h = 0.0;
    if s != 0.0 {
        let c = (Vec3::splat(cmax_) - rgb) / cdelta;
        h = if rgb.x == cmax_ {
            c.z - c.y
        } else if rgb.y == cmax_ {
            2.0 + c.x - c.z
        } else {
            4.0 + c.y - c.x
        };
        h /= 6.0;
        if h < 0.0 {
            h += 1.0;
        }
    }
    Vec3::new(h, s, v)
}

/// Cycles `hsv_to_rgb` (sector-based; `h == 1` is treated as 0, hue is not wrapped, so
/// hues outside [0, 1] fall into the last sector).
pub fn hsv_to_rgb(hsv: Vec3) -> Vec3 {
    let (mut h, s, v) = (hsv.x, hsv.y, hsv.z);
    if s == 0.0 {
        return Vec3::splat(v);
    }
    if h == 1.0 {
        h = 0.0;
    }
    h *= 6.0;
    let i = h.floor();
    let f = h - i;
    let p = v * (1.0 - s);
    let q = v * (1.0 - (s * f));
    let t = v * (1.0 - (s * (1.0 - f)));
    if i == 0.0 {
        Vec3::new(v, t, p)
    } else if i == 1.0 {
        Vec3::new(q, v, p)
    } else if i == 2.0 {
        Vec3::new(p, v, t)
    } else if i == 3.0 {
        Vec3::new(p, q, v)
    } else if i == 4.0 {
        Vec3::new(t, p, v)
    } else {
        Vec3::new(v, p, q)
    }
}

/// Cycles `rgb_to_hsl`: `l = min(1, (max + min) / 2)`, the usual saturation and hue
/// (both 0 for greys).
pub fn rgb_to_hsl(rgb: Vec3) -> Vec3 {
    let cmax_ = rgb.x.max(rgb.y.max(rgb.z));
    let cmin_ = cmin(rgb.x, cmin(rgb.y, rgb.z));
    let l = cmin(1.0, (cmax_ + cmin_) / 2.0);
    let (mut h, s);
    if cmax_ == cmin_ {
        h = 0.0;
        s = 0.0;
    } else {
        let d = cmax_ - cmin_;
        s = if l > 0.5 {
            d / (2.0 - cmax_ - cmin_)
        } else {
            d / (cmax_ + cmin_)
        };
        h = if cmax_ == rgb.x {
            (rgb.y - rgb.z) / d + if rgb.y < rgb.z { 6.0 } else { 0.0 }
        } else if cmax_ == rgb.y {
            (rgb.z - rgb.x) / d + 2.0
        } else {
            (rgb.x - rgb.y) / d + 4.0
        };
    }
    h /= 6.0;
    Vec3::new(h, s, l)
}

/// Cycles / Blender `hsl_to_rgb`: `(n - 0.5) * chroma + l` per channel with
/// `chroma = (1 - |2l - 1|) s` and the piecewise-linear hue ramps `n` clamped to [0, 1].
pub fn hsl_to_rgb(hsl: Vec3) -> Vec3 {
    let (h, s, l) = (hsl.x, hsl.y, hsl.z);
    let nr = cmin(cmax((h * 6.0 - 3.0).abs() - 1.0, 0.0), 1.0);
    let ng = cmin(cmax(2.0 - (h * 6.0 - 2.0).abs(), 0.0), 1.0);
    let nb = cmin(cmax(2.0 - (h * 6.0 - 4.0).abs(), 0.0), 1.0);
    let chroma = (1.0 - (2.0 * l - 1.0).abs()) * s;
    Vec3::new(
        (nr - 0.5) * chroma + l,
        (ng - 0.5) * chroma + l,
        (nb - 0.5) * chroma + l,
    )
}

/// `ShaderNodeSeparateColor.mode` / `ShaderNodeCombineColor.mode`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColorMode {
    Rgb,
    Hsv,
    Hsl,
}

impl ColorMode {
    /// Parses `"RGB"`, `"HSV"` or `"HSL"`.
    pub fn from_blender(s: &str) -> Option<Self> {
        Some(match s {
            "RGB" => Self::Rgb,
            "HSV" => Self::Hsv,
            "HSL" => Self::Hsl,
            _ => return None,
        })
    }
}

/// Separate Color: the colour's (R, G, B), (H, S, V) or (H, S, L) components.
pub fn separate_color(mode: ColorMode, color: Vec3) -> Vec3 {
    match mode {
        ColorMode::Rgb => color,
        ColorMode::Hsv => rgb_to_hsv(color),
        ColorMode::Hsl => rgb_to_hsl(color),
    }
}

/// Combine Color: builds RGB from (R, G, B), (H, S, V) or (H, S, L).
pub fn combine_color(mode: ColorMode, c: Vec3) -> Vec3 {
    match mode {
        ColorMode::Rgb => c,
        ColorMode::Hsv => hsv_to_rgb(c),
        ColorMode::Hsl => hsl_to_rgb(c),
    }
}

/// Hue/Saturation/Value node: in HSV, `h = fract(h + hue + 0.5)`, `s = clamp(s * sat)`,
/// `v *= val`; back to RGB, mixed with the input by `fac`, negatives clamped to 0.
pub fn hue_saturation_value(hue: f32, saturation: f32, value: f32, fac: f32, color: Vec3) -> Vec3 {
    let mut hsv = rgb_to_hsv(color);
    hsv.x = fract(hsv.x + hue + 0.5);
    hsv.y = saturate(hsv.y * saturation);
    hsv.z *= value;
    let c = hsv_to_rgb(hsv);
    let mixc = |n: f32, o: f32| cmax(fac * n + (1.0 - fac) * o, 0.0);
    Vec3::new(mixc(c.x, color.x), mixc(c.y, color.y), mixc(c.z, color.z))
}

/// Brightness/Contrast node: `max((1 + contrast) c + brightness - contrast / 2, 0)`.
pub fn brightness_contrast(color: Vec3, brightness: f32, contrast: f32) -> Vec3 {
    let a = 1.0 + contrast;
    let b = brightness - contrast * 0.5;
    let f = |c: f32| cmax(a * c + b, 0.0);
    Vec3::new(f(color.x), f(color.y), f(color.z))
}

/// Gamma node: `c^gamma` for positive channels only (others unchanged); white when
/// `gamma == 0`.
pub fn gamma(color: Vec3, gamma: f32) -> Vec3 {
    if gamma == 0.0 {
        return Vec3::ONE;
    }
    let f = |c: f32| if c > 0.0 { c.powf(gamma) } else { c };
    Vec3::new(f(color.x), f(color.y), f(color.z))
}

/// Invert node: `fac (1 - c) + (1 - fac) c`.
pub fn invert(fac: f32, color: Vec3) -> Vec3 {
    let f = |c: f32| fac * (1.0 - c) + (1.0 - fac) * c;
    Vec3::new(f(color.x), f(color.y), f(color.z))
}

/// Luminance weights Cycles 5.0 uses for RGB to BW and colour-to-float conversion
/// (`kernel_data.film.rgb_to_y`): the Y row of the inverse of the OCIO XYZ->scene-linear
/// transform of Blender's default OCIO config (scene linear = Linear Rec.709, D65). The values
/// are the exact f32s measured from Cycles 5.0 renders of RGB to BW with unit colours; they
/// are *not* Cycles' hard-coded fallback (0.2126729, 0.7151522, 0.0721750), which is only used
/// without an OCIO config.
pub const RGB_TO_Y: Vec3 = Vec3::new(
    f32::from_bits(1046068754), // 0.21263912
    f32::from_bits(1060574547), // 0.71516913
    f32::from_bits(1033099724), // 0.07219276
);

/// RGB to BW node (and implicit colour->float conversion): `dot(color, RGB_TO_Y)`,
/// summed as `(r*wr + g*wg) + b*wb`.
pub fn rgb_to_bw(color: Vec3) -> f32 {
    (color.x * RGB_TO_Y.x + color.y * RGB_TO_Y.y) + color.z * RGB_TO_Y.z
}

#[allow(clippy::excessive_precision)]
const BLACKBODY_R: [[f32; 3]; 7] = [
    [1.61919106e+03, -2.05010916e-03, 5.02995757e+00],
    [2.48845471e+03, -1.11330907e-03, 3.22621544e+00],
    [3.34143193e+03, -4.86551192e-04, 1.76486769e+00],
    [4.09461742e+03, -1.27446582e-04, 7.25731635e-01],
    [4.67028036e+03, 2.91258199e-05, 1.26703442e-01],
    [4.59509185e+03, 2.87495649e-05, 1.50345020e-01],
    [3.78717450e+03, 9.35907826e-06, 3.99075871e-01],
];
#[allow(clippy::excessive_precision)]
const BLACKBODY_G: [[f32; 3]; 7] = [
    [-4.88999748e+02, 6.04330754e-04, -7.55807526e-02],
    [-7.55994277e+02, 3.16730098e-04, 4.78306139e-01],
    [-1.02363977e+03, 1.20223470e-04, 9.36662319e-01],
    [-1.26571316e+03, 4.87340896e-06, 1.27054498e+00],
    [-1.42529332e+03, -4.01150431e-05, 1.43972784e+00],
    [-1.17554822e+03, -2.16378048e-05, 1.30408023e+00],
    [-5.00799571e+02, -4.59832026e-06, 1.09098763e+00],
];
#[allow(clippy::excessive_precision)]
const BLACKBODY_B: [[f32; 4]; 7] = [
    [
        5.96945309e-11,
        -4.85742887e-08,
        -9.70622247e-05,
        -4.07936148e-03,
    ],
    [
        2.40430366e-11,
        5.55021075e-08,
        -1.98503712e-04,
        2.89312858e-02,
    ],
    [
        -1.40949732e-11,
        1.89878968e-07,
        -3.56632824e-04,
        9.10767778e-02,
    ],
    [
        -3.61460868e-11,
        2.84822009e-07,
        -4.93211319e-04,
        1.56723440e-01,
    ],
    [
        -1.97075738e-11,
        1.75359352e-07,
        -2.50542825e-04,
        -2.22783266e-02,
    ],
    [
        -1.61997957e-13,
        -1.64216008e-08,
        3.86216271e-04,
        -7.38077418e-01,
    ],
    [
        6.72650283e-13,
        -2.73078809e-08,
        4.24098264e-04,
        -7.52335691e-01,
    ],
];

/// Blackbody colour in linear Rec.709 for temperature `t` in kelvin, before clamping
/// (Cycles' piecewise fit: `a/t + b t + c` for R and G, a cubic for B, on 7 intervals;
/// constant below 800 K and from 12000 K).
#[allow(clippy::excessive_precision)]
pub fn blackbody_rec709(t: f32) -> Vec3 {
    if t >= 12000.0 {
        return Vec3::new(0.826_295_5, 0.994_508_05, 1.566_307_7);
    }
    if t.is_nan() {
        // Cycles' comparisons all fail for NaN, giving NaN and then black after the clamp.
        return Vec3::ZERO;
    }
    if t < 800.0 {
        // Arbitrary lower limit where light is very dim (matches OSL).
        return Vec3::new(5.413_294_5, -0.203_193_9, -0.082_253_52);
    }
    let i = if t >= 6365.0 {
        6
    } else if t >= 3315.0 {
        5
    } else if t >= 1902.0 {
        4
    } else if t >= 1449.0 {
        3
    } else if t >= 1167.0 {
        2
    } else if t >= 965.0 {
        1
    } else {
        0
    };
    let (r, g, b) = (BLACKBODY_R[i], BLACKBODY_G[i], BLACKBODY_B[i]);
    let t_inv = 1.0 / t;
    Vec3::new(
        r[0] * t_inv + r[1] * t + r[2],
        g[0] * t_inv + g[1] * t + g[2],
        ((b[0] * t + b[1]) * t + b[2]) * t + b[3],
    )
}

/// Blackbody node: [`blackbody_rec709`] with negative channels clamped to 0 (the scene
/// linear space is Rec.709, so no further conversion).
pub fn blackbody(t: f32) -> Vec3 {
    let c = blackbody_rec709(t);
    Vec3::new(cmax(c.x, 0.0), cmax(c.y, 0.0), cmax(c.z, 0.0))
}

const CIE_COLOR_MATCH: [[f32; 3]; 81] = [
    [0.0014, 0.0000, 0.0065],
    [0.0022, 0.0001, 0.0105],
    [0.0042, 0.0001, 0.0201],
    [0.0076, 0.0002, 0.0362],
    [0.0143, 0.0004, 0.0679],
    [0.0232, 0.0006, 0.1102],
    [0.0435, 0.0012, 0.2074],
    [0.0776, 0.0022, 0.3713],
    [0.1344, 0.0040, 0.6456],
    [0.2148, 0.0073, 1.0391],
    [0.2839, 0.0116, 1.3856],
    [0.3285, 0.0168, 1.6230],
    [0.3483, 0.0230, 1.7471],
    [0.3481, 0.0298, 1.7826],
    [0.3362, 0.0380, 1.7721],
    [0.3187, 0.0480, 1.7441],
    [0.2908, 0.0600, 1.6692],
    [0.2511, 0.0739, 1.5281],
    [0.1954, 0.0910, 1.2876],
    [0.1421, 0.1126, 1.0419],
    [0.0956, 0.1390, 0.8130],
    [0.0580, 0.1693, 0.6162],
    [0.0320, 0.2080, 0.4652],
    [0.0147, 0.2586, 0.3533],
    [0.0049, 0.3230, 0.2720],
    [0.0024, 0.4073, 0.2123],
    [0.0093, 0.5030, 0.1582],
    [0.0291, 0.6082, 0.1117],
    [0.0633, 0.7100, 0.0782],
    [0.1096, 0.7932, 0.0573],
    [0.1655, 0.8620, 0.0422],
    [0.2257, 0.9149, 0.0298],
    [0.2904, 0.9540, 0.0203],
    [0.3597, 0.9803, 0.0134],
    [0.4334, 0.9950, 0.0087],
    [0.5121, 1.0000, 0.0057],
    [0.5945, 0.9950, 0.0039],
    [0.6784, 0.9786, 0.0027],
    [0.7621, 0.9520, 0.0021],
    [0.8425, 0.9154, 0.0018],
    [0.9163, 0.8700, 0.0017],
    [0.9786, 0.8163, 0.0014],
    [1.0263, 0.7570, 0.0011],
    [1.0567, 0.6949, 0.0010],
    [1.0622, 0.6310, 0.0008],
    [1.0456, 0.5668, 0.0006],
    [1.0026, 0.5030, 0.0003],
    [0.9384, 0.4412, 0.0002],
    [0.8544, 0.3810, 0.0002],
    [0.7514, 0.3210, 0.0001],
    [0.6424, 0.2650, 0.0000],
    [0.5419, 0.2170, 0.0000],
    [0.4479, 0.1750, 0.0000],
    [0.3608, 0.1382, 0.0000],
    [0.2835, 0.1070, 0.0000],
    [0.2187, 0.0816, 0.0000],
    [0.1649, 0.0610, 0.0000],
    [0.1212, 0.0446, 0.0000],
    [0.0874, 0.0320, 0.0000],
    [0.0636, 0.0232, 0.0000],
    [0.0468, 0.0170, 0.0000],
    [0.0329, 0.0119, 0.0000],
    [0.0227, 0.0082, 0.0000],
    [0.0158, 0.0057, 0.0000],
    [0.0114, 0.0041, 0.0000],
    [0.0081, 0.0029, 0.0000],
    [0.0058, 0.0021, 0.0000],
    [0.0041, 0.0015, 0.0000],
    [0.0029, 0.0010, 0.0000],
    [0.0020, 0.0007, 0.0000],
    [0.0014, 0.0005, 0.0000],
    [0.0010, 0.0004, 0.0000],
    [0.0007, 0.0002, 0.0000],
    [0.0005, 0.0002, 0.0000],
    [0.0003, 0.0001, 0.0000],
    [0.0002, 0.0001, 0.0000],
    [0.0002, 0.0001, 0.0000],
    [0.0001, 0.0000, 0.0000],
    [0.0001, 0.0000, 0.0000],
    [0.0001, 0.0000, 0.0000],
    [0.0000, 0.0000, 0.0000],
];

/// Rows of the XYZ -> scene linear (Rec.709) matrix Cycles takes from the OCIO config
/// (`kernel_data.film.xyz_to_r/g/b`).
pub const XYZ_TO_RGB: [Vec3; 3] = [
    Vec3::new(3.240_97, -1.537_383_2, -0.498_610_8),
    Vec3::new(-0.969_243_6, 1.875_967_5, 0.041_555_1),
    Vec3::new(0.055_630_1, -0.203_977, 1.056_971_5),
];

/// CIE 1931 colour matching functions at `lambda_nm` (5 nm table from 380 nm, linearly
/// interpolated; zero outside [380, 780) nm).
pub fn wavelength_xyz(lambda_nm: f32) -> Vec3 {
    let mut ii = (lambda_nm - 380.0) * (1.0 / 5.0);
    let i = float_to_int(ii);
    if !(0..80).contains(&i) {
        return Vec3::ZERO;
    }
    ii -= i as f32;
    let c0 = CIE_COLOR_MATCH[i as usize];
    let c1 = CIE_COLOR_MATCH[i as usize + 1];
    let a = Vec3::from_array(c0);
    let b = Vec3::from_array(c1);
    a + (b - a) * ii
}

/// Wavelength node: `max(XYZ_TO_RGB * cie(lambda) / 2.52, 0)`.
pub fn wavelength(lambda_nm: f32) -> Vec3 {
    let xyz = wavelength_xyz(lambda_nm);
    let d = |r: Vec3| (r.x * xyz.x + r.y * xyz.y) + r.z * xyz.z;
    let c = Vec3::new(d(XYZ_TO_RGB[0]), d(XYZ_TO_RGB[1]), d(XYZ_TO_RGB[2])) * (1.0 / 2.52);
    Vec3::new(cmax(c.x, 0.0), cmax(c.y, 0.0), cmax(c.z, 0.0))
}

#[cfg(test)]
#[allow(
    clippy::approx_constant,
    clippy::excessive_precision,
    clippy::type_complexity
)]
mod tests {
    use super::*;

    fn v(a: [f32; 3]) -> Vec3 {
        Vec3::from_array(a)
    }

    fn close(got: Vec3, want: Vec3) -> bool {
        (got - want).abs().max_element() <= 1e-5 * want.abs().max_element().max(1.0)
    }

    #[test]
    fn conversions() {
        let c = Vec3::new(0.8, 0.4, 0.2);
        let hsv = rgb_to_hsv(c);
        assert!((hsv - Vec3::new(1.0 / 18.0, 0.75, 0.8)).abs().max_element() < 1e-6);
        assert!(close(hsv_to_rgb(hsv), c));
        assert!(close(hsl_to_rgb(rgb_to_hsl(c)), c));
        assert_eq!(rgb_to_hsv(Vec3::ZERO), Vec3::ZERO);
        assert_eq!(rgb_to_hsl(Vec3::splat(0.5)), Vec3::new(0.0, 0.0, 0.5));
        assert_eq!(
            hsv_to_rgb(Vec3::new(1.0, 1.0, 1.0)),
            Vec3::new(1.0, 0.0, 0.0)
        );
        assert_eq!(ColorMode::from_blender("HSL"), Some(ColorMode::Hsl));
        assert_eq!(
            gamma(Vec3::new(-1.0, 0.0, 4.0), 0.5),
            Vec3::new(-1.0, 0.0, 2.0)
        );
        assert_eq!(gamma(Vec3::new(-1.0, 0.0, 4.0), 0.0), Vec3::ONE);
        assert_eq!(
            invert(1.0, Vec3::new(0.25, 1.0, 2.0)),
            Vec3::new(0.75, 0.0, -1.0)
        );
        assert_eq!(
            brightness_contrast(Vec3::new(0.5, 0.0, 1.0), 0.0, 1.0),
            Vec3::new(0.5, 0.0, 1.5)
        );
        assert_eq!(wavelength(200.0), Vec3::ZERO);
        assert_eq!(wavelength(f32::NAN), Vec3::ZERO);
        assert_eq!(blackbody(f32::NAN), Vec3::ZERO);
        let vals = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, 1.0, -1.0];
        for &x in &vals {
            for &y in &vals {
                let c = Vec3::new(x, y, 0.5);
                let _ = (rgb_to_hsv(c), hsv_to_rgb(c), rgb_to_hsl(c), hsl_to_rgb(c));
                let _ = hue_saturation_value(x, y, x, y, c);
                let _ = (
                    brightness_contrast(c, x, y),
                    gamma(c, x),
                    invert(x, c),
                    rgb_to_bw(c),
                );
                let _ = (blackbody(x * 1e4), wavelength(x * 500.0));
            }
        }
    }

    /// RGB to BW of the unit colours, bit-exact as measured from Cycles 5.0.
    #[test]
    fn luminance_weights_measured() {
        assert_eq!(rgb_to_bw(Vec3::X).to_bits(), 1046068754); // 0.21263912
        assert_eq!(rgb_to_bw(Vec3::Y).to_bits(), 1060574547); // 0.7151691
        assert_eq!(rgb_to_bw(Vec3::Z).to_bits(), 1033099724); // 0.07219276
        assert_eq!(rgb_to_bw(Vec3::new(1.0, 1.0, 0.0)), 0.92780828);
    }

    enum Kind {
        Sep,
        Comb,
    }
    use Kind::*;

    /// Separate / Combine Color measured from Cycles 5.0: (kind, mode, input, output).
    #[test]
    fn measured_sep_comb() {
        for (kind, mode, input, want) in SEP_COMB {
            let mode = ColorMode::from_blender(mode).unwrap();
            let got = match kind {
                Sep => separate_color(mode, v(*input)),
                Comb => combine_color(mode, v(*input)),
            };
            assert!(close(got, v(*want)), "{mode:?}: {got} vs Cycles {want:?}");
        }
    }

    #[rustfmt::skip]
    const SEP_COMB: &[(Kind, &str, [f32; 3], [f32; 3])] = &[
        (Sep, "RGB", [0.6248188, 1.3038216, 0.4587593], [0.6248188, 1.3038216, 0.4587593]),
        (Sep, "RGB", [0.35924911, 1.3393059, -0.44594193], [0.35924911, 1.3393059, -0.44594193]),
        (Comb, "RGB", [1.4819803, -0.35760307, -0.24406147], [1.4819803, -0.35760307, -0.24406147]),
        (Comb, "RGB", [0.2146864, 0.9553127, -0.4571886], [0.2146864, 0.9553127, -0.4571886]),
        (Sep, "RGB", [0.5, 1.25, 0.5], [0.5, 1.25, 0.5]),
        (Sep, "RGB", [0.25, 1.25, -0.5], [0.25, 1.25, -0.5]),
        (Comb, "RGB", [1.5, -0.25, -0.25], [1.5, -0.25, -0.25]),
        (Comb, "RGB", [0.25, 1.0, -0.5], [0.25, 1.0, -0.5]),
        (Sep, "HSV", [0.6248188, 1.3038216, 0.4587593], [0.3005824, 0.6481426, 1.3038216]),
        (Sep, "HSV", [0.35924911, 1.3393059, -0.44594193], [0.25816256, 1.332965, 1.3393059]),
        (Comb, "HSV", [1.4819803, -0.35760307, -0.24406147], [-0.24406147, -0.3313386, -0.32190236]),
        (Comb, "HSV", [0.2146864, 0.9553127, -0.4571886], [-0.33135056, -0.4571886, -0.02043051]),
        (Sep, "HSV", [0.5, 1.25, 0.5], [0.33333334, 0.6, 1.25]),
        (Sep, "HSV", [0.25, 1.25, -0.5], [0.26190478, 1.4, 1.25]),
        (Comb, "HSV", [1.5, -0.25, -0.25], [-0.25, -0.3125, -0.25]),
        (Comb, "HSV", [0.25, 1.0, -0.5], [-0.25, -0.5, 0.0]),
        (Sep, "HSL", [0.6248188, 1.3038216, 0.4587593], [0.3005824, 3.5593688, 0.88129044]),
        (Sep, "HSL", [0.35924911, 1.3393059, -0.44594193], [0.25816256, 1.9983432, 0.44668198]),
        (Comb, "HSL", [1.4819803, -0.35760307, -0.24406147], [-0.15678434, -0.33133858, -0.33133858]),
        (Comb, "HSL", [0.2146864, 0.9553127, -0.4571886], [-0.6422706, -0.8939467, -0.020430505]),
        (Sep, "HSL", [0.5, 1.25, 0.5], [0.33333334, 3.0, 0.875]),
        (Sep, "HSL", [0.25, 1.25, -0.5], [0.26190478, 2.3333333, 0.375]),
        (Comb, "HSL", [1.5, -0.25, -0.25], [-0.1875, -0.3125, -0.3125]),
        (Comb, "HSL", [0.25, 1.0, -0.5], [-0.5, -1.0, 0.0]),
    ];

    /// Hue/Saturation/Value, Brightness/Contrast, Gamma, Invert, RGB to BW, Blackbody and
    /// Wavelength nodes measured from Cycles 5.0.
    #[test]
    fn measured_nodes() {
        for &(h, s, val, fac, c, want) in HSV {
            let got = hue_saturation_value(h, s, val, fac, v(c));
            assert!(close(got, v(want)), "hsv: {got} vs Cycles {want:?}");
        }
        for &(c, b, k, want) in BRIGHT {
            let got = brightness_contrast(v(c), b, k);
            assert!(close(got, v(want)), "bright: {got} vs Cycles {want:?}");
        }
        for &(c, g, want) in GAMMA {
            let got = gamma(v(c), g);
            assert!(close(got, v(want)), "gamma: {got} vs Cycles {want:?}");
        }
        for &(f, c, want) in INVERT {
            let got = invert(f, v(c));
            assert!(close(got, v(want)), "invert: {got} vs Cycles {want:?}");
        }
        for &(c, want) in BW {
            let got = rgb_to_bw(v(c));
            assert!(
                (got - want).abs() <= 1e-5 * want.abs().max(1.0),
                "bw: {got} vs Cycles {want}"
            );
        }
        for &(t, want) in BLACKBODY {
            let got = blackbody(t);
            assert!(
                close(got, v(want)),
                "blackbody({t}): {got} vs Cycles {want:?}"
            );
        }
        for &(l, want) in WAVELENGTH {
            let got = wavelength(l);
            assert!(
                close(got, v(want)),
                "wavelength({l}): {got} vs Cycles {want:?}"
            );
        }
    }

    /// (hue, saturation, value, fac, color, result)
    #[rustfmt::skip]
    const HSV: &[(f32, f32, f32, f32, [f32; 3], [f32; 3])] = &[
        (-0.27204895, 1.1179252, 1.7040367, 0.32961845, [0.9045906, 0.13879013, 0.43986893], [1.114513, 0.58889675, 0.32211202]),
        (-0.33994102, 1.3763208, 0.9627242, 0.011173248, [-0.49129486, -0.25624084, 0.5188217], [0.0, 0.0, 0.51860565]),
        (-0.31293297, -0.32178926, -0.028973103, -0.16767502, [-0.0887146, 0.6920929, 0.10103989], [0.0, 0.8115018, 0.121343985]),
        (-0.25, 1.0, 1.75, 0.25, [1.0, 0.25, 0.5], [1.1328125, 0.625, 0.484375]),
        (-0.25, 1.5, 1.0, 0.0, [-0.5, -0.25, 0.5], [0.0, 0.0, 0.5]),
        (-0.25, -0.25, 0.0, -0.25, [0.0, 0.75, 0.0], [0.0, 0.9375, 0.0]),
    ];
    /// (color, bright, contrast, result)
    #[rustfmt::skip]
    const BRIGHT: &[([f32; 3], f32, f32, [f32; 3])] = &[
        ([0.08861828, 0.9645114, 0.69571614], 0.4645114, 0.2935742, [0.4323586, 1.5653913, 1.2176847]),
        ([1.066122, 0.9247246, 0.4167633], 0.42472458, -0.12485504, [1.4201634, 1.2964201, 0.85188043]),
        ([0.07816768, 0.05849397, 1.4278822], -0.44150603, 1.3918233, [0.0, 0.0, 2.2778242]),
        ([0.0, 1.0, 0.75], 0.5, 0.25, [0.375, 1.625, 1.3125]),
        ([1.0, 1.0, 0.5], 0.5, 0.0, [1.5, 1.5, 1.0]),
        ([0.0, 0.0, 1.5], -0.5, 1.5, [0.0, 0.0, 2.5]),
    ];
    /// (color, gamma, result)
    #[rustfmt::skip]
    const GAMMA: &[([f32; 3], f32, [f32; 3])] = &[
        ([0.9690757, 1.8708797, 1.5668197], 2.7934074, [0.9159916, 5.7535367, 3.505642]),
        ([0.96166325, 1.9336481, 0.61462116], 2.893837, [0.89304096, 6.741082, 0.24449196]),
        ([0.8577628, 0.29407454, 1.2174935], 0.27051926, [0.9593444, 0.7181373, 1.0546792]),
        ([1.0, 1.75, 1.5], 2.75, [1.0, 4.659664, 3.0496569]),
        ([1.0, 2.0, 0.5], 3.0, [1.0, 8.0, 0.125]),
        ([0.75, 0.25, 1.25], 0.25, [0.9306049, 0.70710677, 1.0573713]),
        ([0.5, 0.25, -0.5], 0.0, [1.0, 1.0, 1.0]),
    ];
    /// (fac, color, result)
    #[rustfmt::skip]
    const INVERT: &[(f32, [f32; 3], [f32; 3])] = &[
        (0.14446354, [0.8210821, 0.14446354, 0.2781582], [0.7283128, 0.24718764, 0.34225428]),
        (0.054457664, [-0.19548416, 0.054457664, 0.7609625], [-0.11973527, 0.102984056, 0.73253965]),
        (0.25, [0.75, 0.25, 0.25], [0.625, 0.375, 0.375]),
        (0.0, [-0.25, 0.0, 0.75], [-0.25, 0.0, 0.75]),
    ];
    /// (color, value)
    #[rustfmt::skip]
    const BW: &[([f32; 3], f32)] = &[
        ([-0.2900982, 1.471014, 1.489315], 1.0978553),
        ([0.8561859, -0.25268936, 1.4293728], 0.104533345),
        ([1.0876732, 1.4995003, 1.2553902], 1.3943082),
    ];
    /// (temperature, color)
    #[rustfmt::skip]
    const BLACKBODY: &[(f32, [f32; 3])] = &[
        (3506.2385, [1.5616953, 0.8929396, 0.40722373]),
        (3006.7578, [1.7675388, 0.8450816, 0.274044]),
        (10225.237, [0.86514986, 0.99499196, 1.4481146]),
        (8357.261, [0.9304519, 0.9926344, 1.2773056]),
        (8119.478, [0.9414975, 0.9919729, 1.2508824]),
        (4129.814, [1.3817384, 0.93007094, 0.56543714]),
    ];
    /// (wavelength nm, color)
    #[rustfmt::skip]
    const WAVELENGTH: &[(f32, [f32; 3])] = &[
        (401.02048, [0.0053154263, 0.0, 0.032420658]),
        (662.40265, [0.15266414, 0.0, 0.0]),
        (667.6415, [0.10976179, 0.0, 0.0]),
        (644.16235, [0.39471796, 0.0, 0.0]),
        (435.10257, [0.09104595, 0.0, 0.6876981]),
        (735.02637, [0.0010406794, 0.0, 0.0]),
    ];
}
