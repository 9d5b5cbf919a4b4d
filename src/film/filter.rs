//! Pixel filters by importance sampling, as Cycles filters: each camera sample's position in
//! the pixel is drawn from the filter's 1D profile on each axis (separable), and every sample
//! then counts with weight 1. Cycles' shapes and widths: a Gaussian of user width `w` spans
//! `±1.5 w` with `σ = w / 4`; Blackman–Harris spans `±w` (twice its nominal width).

/// Cycles' `pixel_filter_type`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilterType {
    Box,
    Gaussian,
    BlackmanHarris,
}

/// Bins of the piecewise-constant profile whose CDF is inverted exactly.
const BINS: usize = 4096;

/// A pixel filter ready to map uniform numbers to sample offsets.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelFilter {
    kind: FilterType,
    width: f32,
    /// The normalised CDF of the profile over `BINS` equal bins of its span (`BINS + 1`
    /// values from 0 to 1). Empty for box filters.
    cdf: Vec<f32>,
    span: f32,
}

impl Default for PixelFilter {
    /// A 1-pixel box: samples uniform over the pixel (the glTF CLI's default).
    fn default() -> Self {
        PixelFilter {
            kind: FilterType::Box,
            width: 1.0,
            cdf: Vec::new(),
            span: 1.0,
        }
    }
}

impl PixelFilter {
    /// The filter `kind` of user width `width` pixels (clamped to `[0.01, 10]`, as Blender).
    pub fn new(kind: FilterType, width: f32) -> PixelFilter {
        let width = if width.is_finite() {
            width.clamp(0.01, 10.0)
        } else {
            1.0
        };
        if kind == FilterType::Box {
            return PixelFilter {
                kind,
                width,
                cdf: Vec::new(),
                span: width,
            };
        }
        let span = Self::span(kind, width);
        // Each bin weighs the profile's integral over it (midpoint rule on 8 points).
        let mut acc = vec![0.0f64; BINS + 1];
        for i in 0..BINS {
            let mut w = 0.0;
            for k in 0..8 {
                let v = (-0.5 + (i as f64 + (k as f64 + 0.5) / 8.0) / BINS as f64) * span as f64;
                w += Self::profile(kind, width, v).max(0.0);
            }
            acc[i + 1] = acc[i] + w;
        }
        let total = acc[BINS];
        let cdf = acc.iter().map(|c| (c / total) as f32).collect();
        PixelFilter {
            kind,
            width,
            cdf,
            span,
        }
    }

    pub fn kind(&self) -> FilterType {
        self.kind
    }

    pub fn width(&self) -> f32 {
        self.width
    }

    /// The full support of the filter, pixels.
    pub fn span(kind: FilterType, width: f32) -> f32 {
        match kind {
            FilterType::Box => width,
            FilterType::Gaussian => 3.0 * width,
            FilterType::BlackmanHarris => 2.0 * width,
        }
    }

    /// The filter's unnormalised 1D profile at offset `v` (pixels) from the pixel centre.
    pub fn profile(kind: FilterType, width: f32, v: f64) -> f64 {
        match kind {
            FilterType::Box => 1.0,
            FilterType::Gaussian => {
                let v = v * 6.0 / (3.0 * width as f64);
                (-2.0 * v * v).exp()
            }
            FilterType::BlackmanHarris => {
                let x = std::f64::consts::TAU * (v / (2.0 * width as f64) + 0.5);
                0.35875 - 0.48829 * x.cos() + 0.14128 * (2.0 * x).cos() - 0.01168 * (3.0 * x).cos()
            }
        }
    }

    /// The sample's position in the pixel's frame (`0..1` is the pixel itself) for the
    /// uniform number `u ∈ [0, 1)`. A 1-pixel box returns `u` unchanged.
    #[inline]
    pub fn offset(&self, u: f32) -> f32 {
        if self.cdf.is_empty() {
            return if self.width == 1.0 {
                u
            } else {
                0.5 + (u - 0.5) * self.width
            };
        }
        // The bin whose CDF interval holds u, then linearly within it (the density is
        // constant there), so the samples follow the binned profile exactly.
        let i = self.cdf.partition_point(|&c| c <= u).clamp(1, BINS) - 1;
        let (a, b) = (self.cdf[i], self.cdf[i + 1]);
        let t = if b > a { (u - a) / (b - a) } else { 0.5 };
        let x = (i as f32 + t.clamp(0.0, 1.0)) / BINS as f32;
        0.5 + (x - 0.5) * self.span
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Chi-square of sampled offsets against the profile's integral over equal bins.
    fn chi2(f: &PixelFilter) -> (f64, usize) {
        let span = f.span as f64;
        let bins = 40;
        let n = 200_000;
        let mut counts = vec![0u64; bins];
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..n {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let u = (state >> 40) as f32 / (1u64 << 24) as f32;
            let v = f.offset(u) as f64 - 0.5;
            let b = ((v / span + 0.5) * bins as f64).floor();
            assert!(
                (0.0..bins as f64).contains(&b),
                "offset {v} outside the span"
            );
            counts[b as usize] += 1;
        }
        let mut expected = vec![0.0f64; bins];
        let fine = 200;
        for (b, e) in expected.iter_mut().enumerate() {
            for k in 0..fine {
                let v = ((b as f64 + (k as f64 + 0.5) / fine as f64) / bins as f64 - 0.5) * span;
                *e += PixelFilter::profile(f.kind, f.width, v);
            }
        }
        let total: f64 = expected.iter().sum();
        let mut stat = 0.0;
        let mut dof = 0;
        for (c, e) in counts.iter().zip(&expected) {
            let e = e / total * n as f64;
            if e < 5.0 {
                continue;
            }
            stat += (*c as f64 - e).powi(2) / e;
            dof += 1;
        }
        (stat, dof - 1)
    }

    #[test]
    fn gaussian_and_blackman_harris_samples_follow_their_profiles() {
        for f in [
            PixelFilter::new(FilterType::Gaussian, 1.5),
            PixelFilter::new(FilterType::BlackmanHarris, 1.5),
            PixelFilter::new(FilterType::BlackmanHarris, 0.7),
        ] {
            let (stat, dof) = chi2(&f);
            // 99.9th percentile of chi-square with ~39 degrees of freedom is ~73.
            let limit = dof as f64 + 4.5 * (2.0 * dof as f64).sqrt();
            assert!(
                stat < limit,
                "{f:?}: chi2 {stat:.1} > {limit:.1} ({dof} dof)"
            );
        }
    }

    #[test]
    fn a_wrong_profile_fails_the_test() {
        // Sampling a Gaussian and testing it against Blackman-Harris must not pass.
        let mut f = PixelFilter::new(FilterType::Gaussian, 1.5);
        f.kind = FilterType::BlackmanHarris;
        f.width = 1.5 * 3.0 / 2.0; // the same span: 4.5 px
        let (stat, dof) = chi2(&f);
        assert!(stat > 10.0 * dof as f64, "chi2 {stat} too small");
    }

    #[test]
    fn box_filters_are_uniform_and_the_unit_box_is_the_identity() {
        let f = PixelFilter::default();
        for u in [0.0, 0.25, 0.999] {
            assert_eq!(f.offset(u), u);
        }
        let f = PixelFilter::new(FilterType::Box, 2.0);
        assert_eq!(f.offset(0.0), -0.5);
        assert_eq!(f.offset(0.75), 1.0);
        // Symmetric about the pixel centre.
        let g = PixelFilter::new(FilterType::BlackmanHarris, 1.5);
        for u in [0.1f32, 0.3, 0.45] {
            assert!((g.offset(u) - 0.5 + g.offset(1.0 - u) - 0.5).abs() < 1e-3);
        }
    }
}
