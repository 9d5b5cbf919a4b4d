//! Color Ramp node (`ShaderNodeValToRGB`).
//!
//! Cycles does not evaluate the colour band at render time: Blender's
//! `BKE_colorband_evaluate` is sampled into a table at `i / RAMP_TABLE_SIZE` for
//! `i = 0..=RAMP_TABLE_SIZE` (257 entries in Blender 5.0), and the kernel reads that table
//! with `rgb_ramp_lookup` (linear interpolation between entries unless the band's
//! interpolation is CONSTANT). [`ColorBand::evaluate`] reproduces the band exactly and
//! [`Ramp`] the baked table and its lookup.

use super::math::{cmin, float_to_int, saturate};
use glam::{Vec3, Vec4};

/// `RAMP_TABLE_SIZE` in Cycles; the baked table has `RAMP_TABLE_SIZE + 1` entries.
pub const RAMP_TABLE_SIZE: usize = 256;

/// `ColorRamp.interpolation`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RampInterpolation {
    Ease,
    Cardinal,
    Linear,
    BSpline,
    Constant,
}

impl RampInterpolation {
    /// Parses `"EASE"`, `"CARDINAL"`, `"LINEAR"`, `"B_SPLINE"` or `"CONSTANT"`.
    pub fn from_blender(s: &str) -> Option<Self> {
        Some(match s {
            "EASE" => Self::Ease,
            "CARDINAL" => Self::Cardinal,
            "LINEAR" => Self::Linear,
            "B_SPLINE" => Self::BSpline,
            "CONSTANT" => Self::Constant,
            _ => return None,
        })
    }
}

/// `ColorRamp.color_mode`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RampColorMode {
    Rgb,
    Hsv,
    Hsl,
}

impl RampColorMode {
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

/// `ColorRamp.hue_interpolation` (used by the HSV and HSL colour modes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum HueInterpolation {
    Near,
    Far,
    Cw,
    Ccw,
}

impl HueInterpolation {
    /// Parses `"NEAR"`, `"FAR"`, `"CW"` or `"CCW"`.
    pub fn from_blender(s: &str) -> Option<Self> {
        Some(match s {
            "NEAR" => Self::Near,
            "FAR" => Self::Far,
            "CW" => Self::Cw,
            "CCW" => Self::Ccw,
            _ => return None,
        })
    }
}

/// One colour stop: position and straight RGBA.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RampElement {
    pub position: f32,
    pub color: Vec4,
}

/// A colour band as Blender stores it, evaluated exactly like `BKE_colorband_evaluate`.
#[derive(Clone, Debug, PartialEq)]
pub struct ColorBand {
    /// Stops in Blender's storage order (`ColorRamp.elements`), normally ascending position.
    pub elements: Vec<RampElement>,
    pub interpolation: RampInterpolation,
    pub color_mode: RampColorMode,
    pub hue_interpolation: HueInterpolation,
}

// Blender's BLI colour conversions (they differ from Cycles' `util/color.h` ones).

fn bli_rgb_to_hsv(c: Vec3) -> Vec3 {
    let (mut r, mut g, mut b) = (c.x, c.y, c.z);
    let mut k = 0.0f32;
    if g < b {
        std::mem::swap(&mut g, &mut b);
        k = -1.0;
    }
    let mut min_gb = b;
    if r < g {
        std::mem::swap(&mut r, &mut g);
        k = -2.0 / 6.0 - k;
        min_gb = cmin(g, b);
    }
    let chroma = r - min_gb;
    Vec3::new(
        (k + (g - b) / (6.0 * chroma + 1e-20)).abs(),
        chroma / (r + 1e-20),
        r,
    )
}

fn hue_ramps(h: f32) -> (f32, f32, f32) {
    let c = |x: f32| x.clamp_nan(0.0, 1.0);
    (
        c((h * 6.0 - 3.0).abs() - 1.0),
        c(2.0 - (h * 6.0 - 2.0).abs()),
        c(2.0 - (h * 6.0 - 4.0).abs()),
    )
}

fn bli_hsv_to_rgb(hsv: Vec3) -> Vec3 {
    let (nr, ng, nb) = hue_ramps(hsv.x);
    let (s, v) = (hsv.y, hsv.z);
    Vec3::new(
        ((nr - 1.0) * s + 1.0) * v,
        ((ng - 1.0) * s + 1.0) * v,
        ((nb - 1.0) * s + 1.0) * v,
    )
}

fn bli_rgb_to_hsl(c: Vec3) -> Vec3 {
    let (r, g, b) = (c.x, c.y, c.z);
    // std::max({r, g, b}) / std::min({r, g, b}): keep the first of equal values.
    let cmax = if g > r { g } else { r };
    let cmax = if b > cmax { b } else { cmax };
    let cmin_ = if g < r { g } else { r };
    let cmin_ = if b < cmin_ { b } else { cmin_ };
    let l = cmin(1.0, (cmax + cmin_) / 2.0);
    let (mut h, s);
    if cmax == cmin_ {
        h = 0.0;
        s = 0.0;
    } else {
        let d = cmax - cmin_;
        s = if l > 0.5 {
            d / (2.0 - cmax - cmin_)
        } else {
            d / (cmax + cmin_)
        };
        h = if cmax == r {
            (g - b) / d + if g < b { 6.0 } else { 0.0 }
        } else if cmax == g {
            (b - r) / d + 2.0
        } else {
            (r - g) / d + 4.0
        };
    }
    h /= 6.0;
    Vec3::new(h, s, l)
}

fn bli_hsl_to_rgb(hsl: Vec3) -> Vec3 {
    let (nr, ng, nb) = hue_ramps(hsl.x);
    let (s, l) = (hsl.y, hsl.z);
    let chroma = (1.0 - (2.0 * l - 1.0).abs()) * s;
    Vec3::new(
        (nr - 0.5) * chroma + l,
        (ng - 0.5) * chroma + l,
        (nb - 0.5) * chroma + l,
    )
}

trait ClampNan {
    fn clamp_nan(self, lo: f32, hi: f32) -> f32;
}
impl ClampNan for f32 {
    /// Blender's `CLAMP` macro: `if (a < lo) a = lo; else if (a > hi) a = hi;` (NaN kept).
    #[inline]
    fn clamp_nan(self, lo: f32, hi: f32) -> f32 {
        if self < lo {
            lo
        } else if self > hi {
            hi
        } else {
            self
        }
    }
}

/// `colorband_hue_interp`: `mfac * h1 + fac * h2` going around the hue circle as the
/// hue interpolation mode asks.
fn hue_interp(mode: HueInterpolation, mfac: f32, fac: f32, h1: f32, h2: f32) -> f32 {
    let hue_mod = |h: f32| if h < 1.0 { h } else { h - 1.0 };
    let h1 = hue_mod(h1);
    let h2 = hue_mod(h2);
    let m = match mode {
        HueInterpolation::Near => {
            if h1 < h2 && (h2 - h1) > 0.5 {
                1
            } else if h1 > h2 && (h2 - h1) < -0.5 {
                2
            } else {
                0
            }
        }
        HueInterpolation::Far => {
            if h1 == h2 || (h1 < h2 && (h2 - h1) < 0.5) {
                1
            } else if h1 > h2 && (h2 - h1) > -0.5 {
                2
            } else {
                0
            }
        }
        HueInterpolation::Ccw => {
            if h1 > h2 {
                2
            } else {
                0
            }
        }
        HueInterpolation::Cw => {
            if h1 < h2 {
                1
            } else {
                0
            }
        }
    };
    match m {
        1 => hue_mod(mfac * (h1 + 1.0) + fac * h2),
        2 => hue_mod(mfac * h1 + fac * (h2 + 1.0)),
        _ => mfac * h1 + fac * h2,
    }
}

/// `key_curve_position_weights` for KEY_CARDINAL (`fc = 0.71`) and KEY_BSPLINE.
#[allow(clippy::excessive_precision)]
fn key_weights(t: f32, cardinal: bool) -> [f32; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    if cardinal {
        let fc = 0.71f32;
        [
            -fc * t3 + 2.0 * fc * t2 - fc * t,
            (2.0 - fc) * t3 + (fc - 3.0) * t2 + 1.0,
            (fc - 2.0) * t3 + (3.0 - 2.0 * fc) * t2 + fc * t,
            fc * t3 - fc * t2,
        ]
    } else {
        [
            -0.16666666 * t3 + 0.5 * t2 - 0.5 * t + 0.16666666,
            0.5 * t3 - t2 + 0.66666666,
            -0.5 * t3 + 0.5 * t2 + 0.5 * t + 0.16666666,
            0.16666666 * t3,
        ]
    }
}

impl ColorBand {
    /// Builds a band from `(position, RGBA)` stops in Blender's storage order.
    ///
    /// The order is kept as given: Blender sorts stops when they are edited in the UI, but
    /// not when a script assigns `element.position`, and both Blender and Cycles then
    /// evaluate the stops in storage order (measured: an out-of-order band renders exactly
    /// like this unsorted evaluation). Use [`ColorBand::sorted`] to get the UI's ordering.
    pub fn new(
        elements: &[(f32, Vec4)],
        interpolation: RampInterpolation,
        color_mode: RampColorMode,
        hue_interpolation: HueInterpolation,
    ) -> Self {
        let elements: Vec<RampElement> = elements
            .iter()
            .map(|&(position, color)| RampElement { position, color })
            .collect();
        ColorBand {
            elements,
            interpolation,
            color_mode,
            hue_interpolation,
        }
    }

    /// The band with its stops stably sorted by position (`BKE_colorband_update_sort`).
    pub fn sorted(mut self) -> Self {
        self.elements.sort_by(|a, b| {
            a.position
                .partial_cmp(&b.position)
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        self
    }

    /// `BKE_colorband_evaluate` at `t`. HSV/HSL modes always interpolate linearly in their
    /// space (the band's interpolation only matters for RGB); CARDINAL and B_SPLINE results
    /// are clamped to [0, 1]. An empty band evaluates to transparent black.
    pub fn evaluate(&self, t: f32) -> Vec4 {
        let data = &self.elements;
        let tot = data.len();
        if tot == 0 {
            return Vec4::ZERO;
        }
        let ipo = if self.color_mode == RampColorMode::Rgb {
            self.interpolation
        } else {
            RampInterpolation::Linear
        };
        let simple = matches!(
            ipo,
            RampInterpolation::Linear | RampInterpolation::Ease | RampInterpolation::Constant
        );
        if tot == 1 || (t <= data[0].position && simple) {
            return data[0].color;
        }
        // First stop with position > t.
        let a = data.iter().position(|e| e.position > t).unwrap_or(tot);
        // cbd1 = right stop (position > t), cbd2 = left stop; out-of-range ends are
        // copies of the end stops placed at 1 (right) or 0 (left).
        let (cbd1, cbd2) = if a == tot {
            let last = data[tot - 1];
            (
                RampElement {
                    position: 1.0,
                    ..last
                },
                last,
            )
        } else if a == 0 {
            (
                data[0],
                RampElement {
                    position: 0.0,
                    ..data[0]
                },
            )
        } else {
            (data[a], data[a - 1])
        };
        if (a == tot && simple) || ipo == RampInterpolation::Constant {
            return cbd2.color;
        }
        let mut fac = if cbd2.position != cbd1.position {
            (t - cbd1.position) / (cbd2.position - cbd1.position)
        } else if a != tot {
            0.0
        } else {
            1.0
        };
        if matches!(
            ipo,
            RampInterpolation::BSpline | RampInterpolation::Cardinal
        ) {
            // Interpolate from right to left: cbd3 cbd2 cbd1 cbd0.
            let cbd0 = if a + 1 >= tot { cbd1 } else { data[a + 1] };
            let cbd3 = if a < 2 { cbd2 } else { data[a - 2] };
            let fac = fac.clamp_nan(0.0, 1.0);
            let w = key_weights(fac, ipo == RampInterpolation::Cardinal);
            let out = cbd3.color * w[3] + cbd2.color * w[2] + cbd1.color * w[1] + cbd0.color * w[0];
            return Vec4::new(
                out.x.clamp_nan(0.0, 1.0),
                out.y.clamp_nan(0.0, 1.0),
                out.z.clamp_nan(0.0, 1.0),
                out.w.clamp_nan(0.0, 1.0),
            );
        }
        if ipo == RampInterpolation::Ease {
            let fac2 = fac * fac;
            fac = 3.0 * fac2 - 2.0 * fac2 * fac;
        }
        let mfac = 1.0 - fac;
        let (c1, c2) = (cbd1.color, cbd2.color);
        let alpha = mfac * c1.w + fac * c2.w;
        match self.color_mode {
            RampColorMode::Rgb => Vec4::new(
                mfac * c1.x + fac * c2.x,
                mfac * c1.y + fac * c2.y,
                mfac * c1.z + fac * c2.z,
                alpha,
            ),
            RampColorMode::Hsv | RampColorMode::Hsl => {
                let hsv = self.color_mode == RampColorMode::Hsv;
                let to = if hsv { bli_rgb_to_hsv } else { bli_rgb_to_hsl };
                let from = if hsv { bli_hsv_to_rgb } else { bli_hsl_to_rgb };
                let h1 = to(c1.truncate());
                let h2 = to(c2.truncate());
                let mixed = Vec3::new(
                    hue_interp(self.hue_interpolation, mfac, fac, h1.x, h2.x),
                    mfac * h1.y + fac * h2.y,
                    mfac * h1.z + fac * h2.z,
                );
                from(mixed).extend(alpha)
            }
        }
    }
}

/// A colour ramp as Cycles renders it: the band baked into `RAMP_TABLE_SIZE + 1` entries
/// and read with `rgb_ramp_lookup`.
#[derive(Clone, Debug, PartialEq)]
pub struct Ramp {
    /// Entry `i` is the band at `i / (len - 1)`.
    pub table: Vec<Vec4>,
    /// Linear interpolation between entries (false for CONSTANT bands).
    pub interpolate: bool,
}

impl Ramp {
    /// Bakes a band from `(position, RGBA)` stops (Blender's storage order, see
    /// [`ColorBand::new`]) like Cycles' Blender sync.
    pub fn from_elements(
        elements: &[(f32, Vec4)],
        interpolation: RampInterpolation,
        color_mode: RampColorMode,
        hue_interpolation: HueInterpolation,
    ) -> Self {
        Self::from_band(&ColorBand::new(
            elements,
            interpolation,
            color_mode,
            hue_interpolation,
        ))
    }

    /// Bakes `band` at `i / RAMP_TABLE_SIZE`, `i = 0..=RAMP_TABLE_SIZE`; lookups interpolate
    /// unless the band's interpolation is CONSTANT (even in HSV/HSL mode).
    pub fn from_band(band: &ColorBand) -> Self {
        Self::from_band_with_size(band, RAMP_TABLE_SIZE)
    }

    /// Like [`Ramp::from_band`] with `size + 1` entries (`size >= 1`).
    pub fn from_band_with_size(band: &ColorBand, size: usize) -> Self {
        let size = size.max(1);
        let table = (0..=size)
            .map(|i| band.evaluate(i as f32 / size as f32))
            .collect();
        Ramp {
            table,
            interpolate: band.interpolation != RampInterpolation::Constant,
        }
    }

    /// A ramp from an already baked table (at least one entry).
    pub fn from_table(table: Vec<Vec4>, interpolate: bool) -> Self {
        let table = if table.is_empty() {
            vec![Vec4::ZERO]
        } else {
            table
        };
        Ramp { table, interpolate }
    }

    /// `rgb_ramp_lookup` without extrapolation: `t` is clamped to [0, 1] (NaN to 0), scaled
    /// to the table, and entries `i`, `i + 1` are lerped by the fractional part when
    /// interpolating; otherwise entry `floor` is returned. Returns (RGB, alpha) as a Vec4.
    pub fn lookup(&self, t: f32) -> Vec4 {
        table_lookup(&self.table, t, self.interpolate, false)
    }
}

/// Cycles `rgb_ramp_lookup(table, f, interpolate, extrapolate)` over an arbitrary table
/// (shared with the curve nodes). With `extrapolate`, inputs outside [0, 1] continue the
/// slope of the two end entries; NaN reads entry 0. Never panics (an empty table gives 0).
pub fn table_lookup<T>(table: &[T], f: f32, interpolate: bool, extrapolate: bool) -> T
where
    T: Copy
        + Default
        + std::ops::Add<Output = T>
        + std::ops::Sub<Output = T>
        + std::ops::Mul<f32, Output = T>,
{
    let n = table.len();
    if n == 0 {
        return T::default();
    }
    if n >= 2 && extrapolate && !(0.0..=1.0).contains(&f) && !f.is_nan() {
        let (t0, dy, f) = if f < 0.0 {
            (table[0], table[0] - table[1], -f)
        } else {
            (table[n - 1], table[n - 1] - table[n - 2], f - 1.0)
        };
        return t0 + dy * f * ((n - 1) as f32);
    }
    let f = saturate(f) * (n - 1) as f32;
    let i = float_to_int(f).clamp(0, n as i32 - 1) as usize;
    let t = f - i as f32;
    let a = table[i];
    if interpolate && t > 0.0 && i + 1 < n {
        a * (1.0 - t) + table[i + 1] * t
    } else {
        a
    }
}

#[cfg(test)]
#[allow(
    clippy::approx_constant,
    clippy::excessive_precision,
    clippy::type_complexity
)]
mod tests {
    use super::*;

    fn band(stops: &[(f32, [f32; 4])], interp: &str, mode: &str, hue: &str) -> ColorBand {
        let els: Vec<(f32, Vec4)> = stops
            .iter()
            .map(|&(p, c)| (p, Vec4::from_array(c)))
            .collect();
        ColorBand::new(
            &els,
            RampInterpolation::from_blender(interp).unwrap(),
            RampColorMode::from_blender(mode).unwrap(),
            HueInterpolation::from_blender(hue).unwrap(),
        )
    }

    #[test]
    fn band_edge_cases() {
        let red = [1.0, 0.0, 0.0, 1.0];
        let blue = [0.0, 0.0, 1.0, 0.5];
        // One element: constant everywhere, for every interpolation.
        for interp in ["LINEAR", "EASE", "CONSTANT", "B_SPLINE", "CARDINAL"] {
            let b = band(&[(0.4, red)], interp, "RGB", "NEAR");
            for t in [-1.0, 0.0, 0.4, 0.9, 2.0, f32::NAN] {
                assert_eq!(b.evaluate(t), Vec4::from_array(red));
            }
        }
        // Empty band (impossible in Blender) gives transparent black, table lookups too.
        let empty = band(&[], "LINEAR", "RGB", "NEAR");
        assert_eq!(empty.evaluate(0.5), Vec4::ZERO);
        assert_eq!(Ramp::from_band(&empty).lookup(0.5), Vec4::ZERO);
        // Linear: constant outside the stops, lerp between.
        let b = band(&[(0.25, red), (0.75, blue)], "LINEAR", "RGB", "NEAR");
        assert_eq!(b.evaluate(0.0), Vec4::from_array(red));
        assert_eq!(b.evaluate(1.0), Vec4::from_array(blue));
        assert_eq!(b.evaluate(0.5), Vec4::new(0.5, 0.0, 0.5, 0.75));
        // Constant: the left stop's colour.
        let b = band(&[(0.25, red), (0.75, blue)], "CONSTANT", "RGB", "NEAR");
        assert_eq!(b.evaluate(0.74), Vec4::from_array(red));
        assert_eq!(b.evaluate(0.75), Vec4::from_array(blue));
        // Out-of-order stops are evaluated in storage order, like Blender; sorted() fixes it.
        let unsorted = band(&[(0.75, blue), (0.25, red)], "LINEAR", "RGB", "NEAR");
        assert_ne!(unsorted.evaluate(0.5), Vec4::new(0.5, 0.0, 0.5, 0.75));
        assert_eq!(
            unsorted.sorted().evaluate(0.5),
            Vec4::new(0.5, 0.0, 0.5, 0.75)
        );
    }

    #[test]
    fn table_lookup_semantics() {
        let table = vec![0.0f32, 1.0, 4.0];
        assert_eq!(table_lookup(&table, 0.25, true, false), 0.5);
        assert_eq!(table_lookup(&table, 0.25, false, false), 0.0);
        assert_eq!(table_lookup(&table, 0.75, true, false), 2.5);
        assert_eq!(table_lookup(&table, 1.0, true, false), 4.0);
        assert_eq!(table_lookup(&table, -3.0, true, false), 0.0);
        assert_eq!(table_lookup(&table, 7.0, true, false), 4.0);
        assert_eq!(table_lookup(&table, f32::NAN, true, false), 0.0);
        // Extrapolation continues the end slopes.
        assert_eq!(table_lookup(&table, -0.5, true, true), -1.0);
        assert_eq!(table_lookup(&table, 1.5, true, true), 7.0);
        assert_eq!(table_lookup::<f32>(&[], 0.5, true, true), 0.0);
        assert_eq!(table_lookup(&[2.0f32], 5.0, true, true), 2.0);
        let r = Ramp::from_table(vec![Vec4::ZERO, Vec4::ONE], true);
        assert_eq!(r.lookup(0.5), Vec4::splat(0.5));
        assert_eq!(Ramp::from_table(vec![], true).lookup(0.3), Vec4::ZERO);
        for t in [f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 1e30, -1e30] {
            let _ = r.lookup(t);
            let _ = table_lookup(&table, t, true, true);
        }
    }

    #[test]
    fn baked_table_has_257_entries() {
        let b = band(&[(0.0, [0.0; 4]), (1.0, [1.0; 4])], "LINEAR", "RGB", "NEAR");
        let r = Ramp::from_band(&b);
        assert_eq!(r.table.len(), RAMP_TABLE_SIZE + 1);
        assert_eq!(r.table[128], Vec4::splat(0.5));
        assert!(r.interpolate);
        assert!(
            !Ramp::from_band(&ColorBand {
                interpolation: RampInterpolation::Constant,
                ..b
            })
            .interpolate
        );
    }

    /// Color Ramp outputs (Color, Alpha) measured from Cycles 5.0 for the configurations in
    /// [`CONFIGS`] (stops in Blender storage order, as read back from `ColorRamp.elements`).
    #[test]
    fn measured_from_cycles() {
        for &(name, fac, want) in MEASURED {
            let &(_, interp, mode, hue, stops) = CONFIGS.iter().find(|c| c.0 == name).unwrap();
            let ramp = Ramp::from_band(&band(stops, interp, mode, hue));
            let got = ramp.lookup(fac);
            let want = Vec4::from_array(want);
            assert!(
                (got - want).abs().max_element() <= 1e-6,
                "{name}({fac}): {got} vs Cycles {want}"
            );
        }
    }

    /// (name, interpolation, color_mode, hue_interpolation, stops)
    #[rustfmt::skip]
    #[allow(clippy::type_complexity)]
    const CONFIGS: &[(&str, &str, &str, &str, &[(f32, [f32; 4])])] = &[
        ("B_SPLINE", "B_SPLINE", "RGB", "NEAR", &[(0.1, [0.9, 0.1, 0.2, 1.0]), (0.35, [0.2, 0.8, 0.3, 0.5]), (0.6, [0.1, 0.3, 0.95, 0.0]), (0.85, [1.0, 0.9, 0.1, 0.8])]),
        ("CARDINAL", "CARDINAL", "RGB", "NEAR", &[(0.1, [0.9, 0.1, 0.2, 1.0]), (0.35, [0.2, 0.8, 0.3, 0.5]), (0.6, [0.1, 0.3, 0.95, 0.0]), (0.85, [1.0, 0.9, 0.1, 0.8])]),
        ("CONSTANT", "CONSTANT", "RGB", "NEAR", &[(0.1, [0.9, 0.1, 0.2, 1.0]), (0.35, [0.2, 0.8, 0.3, 0.5]), (0.6, [0.1, 0.3, 0.95, 0.0]), (0.85, [1.0, 0.9, 0.1, 0.8])]),
        ("EASE", "EASE", "RGB", "NEAR", &[(0.1, [0.9, 0.1, 0.2, 1.0]), (0.35, [0.2, 0.8, 0.3, 0.5]), (0.6, [0.1, 0.3, 0.95, 0.0]), (0.85, [1.0, 0.9, 0.1, 0.8])]),
        ("HSL_CCW", "LINEAR", "HSL", "CCW", &[(0.05, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 0.2, 1.0, 0.3]), (0.9, [0.1, 1.0, 0.4, 0.7])]),
        ("HSL_CONSTANT", "CONSTANT", "HSL", "NEAR", &[(0.05, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 0.2, 1.0, 0.3]), (0.9, [0.1, 1.0, 0.4, 0.7])]),
        ("HSL_CW", "LINEAR", "HSL", "CW", &[(0.05, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 0.2, 1.0, 0.3]), (0.9, [0.1, 1.0, 0.4, 0.7])]),
        ("HSL_EASE", "EASE", "HSL", "FAR", &[(0.05, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 0.2, 1.0, 0.3]), (0.9, [0.1, 1.0, 0.4, 0.7])]),
        ("HSL_FAR", "LINEAR", "HSL", "FAR", &[(0.05, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 0.2, 1.0, 0.3]), (0.9, [0.1, 1.0, 0.4, 0.7])]),
        ("HSL_NEAR", "LINEAR", "HSL", "NEAR", &[(0.05, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 0.2, 1.0, 0.3]), (0.9, [0.1, 1.0, 0.4, 0.7])]),
        ("HSV_CCW", "LINEAR", "HSV", "CCW", &[(0.05, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 0.2, 1.0, 0.3]), (0.9, [0.1, 1.0, 0.4, 0.7])]),
        ("HSV_CONSTANT", "CONSTANT", "HSV", "NEAR", &[(0.05, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 0.2, 1.0, 0.3]), (0.9, [0.1, 1.0, 0.4, 0.7])]),
        ("HSV_CW", "LINEAR", "HSV", "CW", &[(0.05, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 0.2, 1.0, 0.3]), (0.9, [0.1, 1.0, 0.4, 0.7])]),
        ("HSV_EASE", "EASE", "HSV", "FAR", &[(0.05, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 0.2, 1.0, 0.3]), (0.9, [0.1, 1.0, 0.4, 0.7])]),
        ("HSV_FAR", "LINEAR", "HSV", "FAR", &[(0.05, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 0.2, 1.0, 0.3]), (0.9, [0.1, 1.0, 0.4, 0.7])]),
        ("HSV_NEAR", "LINEAR", "HSV", "NEAR", &[(0.05, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 0.2, 1.0, 0.3]), (0.9, [0.1, 1.0, 0.4, 0.7])]),
        ("LINEAR", "LINEAR", "RGB", "NEAR", &[(0.1, [0.9, 0.1, 0.2, 1.0]), (0.35, [0.2, 0.8, 0.3, 0.5]), (0.6, [0.1, 0.3, 0.95, 0.0]), (0.85, [1.0, 0.9, 0.1, 0.8])]),
        ("bright_bs", "B_SPLINE", "RGB", "NEAR", &[(0.2, [2.0, 0.0, 0.5, 1.0]), (0.7, [0.0, 3.0, 1.0, 0.2])]),
        ("bright", "LINEAR", "RGB", "NEAR", &[(0.2, [2.0, 0.0, 0.5, 1.0]), (0.7, [0.0, 3.0, 1.0, 0.2])]),
        ("default", "LINEAR", "RGB", "NEAR", &[(0.0, [0.0, 0.0, 0.0, 1.0]), (1.0, [1.0, 1.0, 1.0, 1.0])]),
        ("one_bspline", "B_SPLINE", "RGB", "NEAR", &[(0.4, [0.3, 0.6, 0.9, 0.5])]),
        ("one", "LINEAR", "RGB", "NEAR", &[(0.4, [0.3, 0.6, 0.9, 0.5])]),
        ("same_pos_bs", "B_SPLINE", "RGB", "NEAR", &[(0.5, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 1.0, 0.0, 1.0]), (0.8, [0.0, 0.0, 1.0, 1.0])]),
        ("same_pos", "LINEAR", "RGB", "NEAR", &[(0.5, [1.0, 0.0, 0.0, 1.0]), (0.5, [0.0, 1.0, 0.0, 1.0]), (0.8, [0.0, 0.0, 1.0, 1.0])]),
        ("unordered", "LINEAR", "RGB", "NEAR", &[(0.9, [0.9, 0.1, 0.2, 1.0]), (0.2, [0.2, 0.8, 0.3, 0.5]), (0.55, [0.1, 0.3, 0.95, 0.0]), (0.05, [1.0, 0.9, 0.1, 0.8])]),
        ("unordered_card", "CARDINAL", "RGB", "NEAR", &[(0.9, [0.9, 0.1, 0.2, 1.0]), (0.2, [0.2, 0.8, 0.3, 0.5]), (0.55, [0.1, 0.3, 0.95, 0.0]), (0.05, [1.0, 0.9, 0.1, 0.8])]),
    ];

    /// (configuration, fac, RGBA): measured from Cycles 5.0.
    #[rustfmt::skip]
    const MEASURED: &[(&str, f32, [f32; 4])] = &[
        ("B_SPLINE", -0.16889429, [0.9, 0.099999994, 0.19999999, 0.99999994]),
        ("B_SPLINE", 0.29212165, [0.40600243, 0.5486034, 0.3186673, 0.6147202]),
        ("B_SPLINE", 0.0471673, [0.88773966, 0.11226034, 0.20175147, 0.9912426]),
        ("CARDINAL", -0.16889429, [0.9, 0.1, 0.2, 1.0]),
        ("CARDINAL", 0.29212165, [0.35238272, 0.70583934, 0.2165434, 0.650432]),
        ("CARDINAL", 0.0471673, [0.9583937, 0.041606262, 0.19165803, 1.0]),
        ("CONSTANT", -0.16889429, [0.9, 0.1, 0.2, 1.0]),
        ("CONSTANT", 0.29212165, [0.9, 0.1, 0.2, 1.0]),
        ("CONSTANT", 0.0471673, [0.9, 0.1, 0.2, 1.0]),
        ("EASE", 1.2364852, [1.0, 0.9, 0.1, 0.8]),
        ("EASE", -0.05162096, [0.9, 0.1, 0.2, 1.0]),
        ("EASE", -0.10861826, [0.9, 0.1, 0.2, 1.0]),
        ("HSL_CCW", 1.1538153, [0.1, 1.0, 0.4, 0.7]),
        ("HSL_CCW", 0.4060812, [0.25915846, 0.0, 1.0, 0.4460959]),
        ("HSL_CCW", 0.1920209, [1.0, 0.0, 0.6943244, 0.7790786]),
        ("HSL_CONSTANT", 0.21010971, [1.0, 0.0, 0.7677083, 0.7557292]),
        ("HSL_CONSTANT", -0.22021013, [1.0, 0.0, 0.0, 1.0]),
        ("HSL_CONSTANT", 0.7709353, [0.06738281, 1.0, 0.82440543, 0.56953126]),
        ("HSL_CW", 0.11371791, [1.0, 0.53806233, 0.0, 0.90088326]),
        ("HSL_CW", -0.17299914, [1.0, 0.0, 0.0, 1.0]),
        ("HSL_CW", 0.30407405, [0.0, 1.0, 0.14551412, 0.60477376]),
        ("HSL_EASE", -0.16889429, [1.0, 0.0, 0.0, 1.0]),
        ("HSL_EASE", 0.29212165, [0.0, 1.0, 0.044582807, 0.62336636]),
        ("HSL_EASE", 0.0471673, [1.0, 0.00049365964, 0.0, 0.99990904]),
        ("HSL_FAR", 1.1538153, [0.1, 1.0, 0.4, 0.7]),
        ("HSL_FAR", 0.4060812, [0.0, 0.9920269, 0.9989347, 0.4460959]),
        ("HSL_FAR", 0.1920209, [0.8007125, 1.0, 0.0, 0.7790786]),
        ("HSL_NEAR", -0.16889429, [1.0, 0.0, 0.0, 1.0]),
        ("HSL_NEAR", 0.29212165, [0.81629425, 0.0, 1.0, 0.62336636]),
        ("HSL_NEAR", 0.0471673, [1.0, 0.0, 0.00028580718, 0.99990904]),
        ("HSV_CCW", 1.1538153, [0.1, 1.0, 0.4, 0.7]),
        ("HSV_CCW", 0.4060812, [0.25915846, 0.0, 1.0, 0.4460959]),
        ("HSV_CCW", 0.1920209, [1.0, 0.0, 0.6943244, 0.7790786]),
        ("HSV_CONSTANT", 0.21010971, [1.0, 0.0, 0.7677083, 0.7557292]),
        ("HSV_CONSTANT", -0.22021013, [1.0, 0.0, 0.0, 1.0]),
        ("HSV_CONSTANT", 0.7709353, [0.06738281, 1.0, 0.82440543, 0.56953126]),
        ("HSV_CW", 0.11371791, [1.0, 0.53806233, 0.0, 0.90088326]),
        ("HSV_CW", -0.17299914, [1.0, 0.0, 0.0, 1.0]),
        ("HSV_CW", 0.30407405, [0.0, 1.0, 0.14551407, 0.60477376]),
        ("HSV_EASE", -0.16889429, [1.0, 0.0, 0.0, 1.0]),
        ("HSV_EASE", 0.29212165, [0.0, 1.0, 0.044582568, 0.62336636]),
        ("HSV_EASE", 0.0471673, [1.0, 0.00049365964, 0.0, 0.99990904]),
        ("HSV_FAR", 1.1538153, [0.1, 1.0, 0.4, 0.7]),
        ("HSV_FAR", 0.4060812, [0.0, 0.99202734, 0.9989347, 0.4460959]),
        ("HSV_FAR", 0.1920209, [0.80071265, 1.0, 0.0, 0.7790786]),
        ("HSV_NEAR", -0.16889429, [1.0, 0.0, 0.0, 1.0]),
        ("HSV_NEAR", 0.29212165, [0.81629425, 0.0, 1.0, 0.62336636]),
        ("HSV_NEAR", 0.0471673, [1.0, 0.0, 0.00028580718, 0.99990904]),
        ("LINEAR", 0.11371791, [0.8615898, 0.13841017, 0.20548718, 0.97256416]),
        ("LINEAR", -0.17299914, [0.9, 0.1, 0.2, 1.0]),
        ("LINEAR", 0.30407405, [0.32859263, 0.67140734, 0.28162962, 0.5918519]),
        ("bright_bs", 0.17810059, [1.0, 0.35320508, 0.55886745, 0.90581197]),
        ("bright_bs", 0.21139002, [1.0, 0.53494567, 0.5891576, 0.85734785]),
        ("bright_bs", 0.8892615, [0.016779557, 1.0, 0.9958051, 0.20671183]),
        ("bright", 0.11371791, [2.0, 0.0, 0.5, 1.0]),
        ("bright", -0.17299914, [2.0, 0.0, 0.5, 1.0]),
        ("bright", 0.30407405, [1.5837038, 0.62444437, 0.60407406, 0.8334815]),
        ("default", 1.1538153, [1.0, 1.0, 1.0, 1.0]),
        ("default", 0.4060812, [0.4060812, 0.4060812, 0.4060812, 1.0]),
        ("default", 0.1920209, [0.1920209, 0.1920209, 0.1920209, 1.0]),
        ("one_bspline", 0.006031513, [0.3, 0.6, 0.9, 0.5]),
        ("one_bspline", 0.7927018, [0.3, 0.6, 0.9, 0.5]),
        ("one_bspline", 0.7187352, [0.3, 0.6, 0.9, 0.5]),
        ("one", 1.0957365, [0.3, 0.6, 0.9, 0.5]),
        ("one", 0.9699931, [0.3, 0.6, 0.9, 0.5]),
        ("one", 1.1814284, [0.3, 0.6, 0.9, 0.5]),
        ("same_pos_bs", 0.006031513, [0.9999996, 3.8126745e-07, 0.0, 1.0]),
        ("same_pos_bs", 0.7927018, [2.55113e-06, 0.17912403, 0.8208734, 1.0]),
        ("same_pos_bs", 0.7187352, [0.0033128653, 0.32885838, 0.66782874, 1.0]),
        ("same_pos", -0.16889429, [1.0, 0.0, 0.0, 1.0]),
        ("same_pos", 0.29212165, [1.0, 0.0, 0.0, 1.0]),
        ("same_pos", 0.0471673, [1.0, 0.0, 0.0, 1.0]),
        ("unordered", 0.17810059, [0.9, 0.1, 0.2, 1.0]),
        ("unordered", 0.21139002, [0.9, 0.1, 0.2, 1.0]),
        ("unordered", 0.8892615, [0.9, 0.1, 0.2, 1.0]),
        ("unordered_card", 0.023201942, [0.9003224, 0.09967773, 0.19995399, 1.0]),
        ("unordered_card", 0.563607, [0.9728481, 0.027151834, 0.1895931, 1.0]),
        ("unordered_card", 1.19712, [1.0, 0.9, 0.1, 0.8]),
    ];
}
