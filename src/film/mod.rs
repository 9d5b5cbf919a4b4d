//! The film: per-pixel accumulators for Combined (RGB, coverage alpha) and the auxiliary
//! passes, the adaptive-sampling statistics, and the schedule of sample rounds.
//!
//! Every pixel keeps its own sums, added in sample order, so a render is the same for any
//! thread count and any split into rounds (Combined is bit-identical to one long round).

pub mod accumulators;
pub mod catcher;
pub mod color;
pub mod data;
pub mod filter;
pub mod pass;

pub use filter::{FilterType, PixelFilter};
pub use pass::{LightClass, Pass, PassSet};

use glam::Vec3;

/// Cycles' adaptive sampling: a pixel stops once its error estimate falls below the noise
/// threshold. The estimate compares the mean of all samples `I` with the mean of the half of
/// them in [`in_half_buffer`]'s class `A` (the half buffer): `Σ_rgb |I − A| / (1e-4 +
/// √(Σ_rgb I))` (or `Σ I` above 1), checked every 16 samples after the minimum, with
/// unconverged pixels spreading to their neighbours so that noise at an edge is never left
/// alone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// Blender's `adaptive_threshold` (noise threshold; 0 = automatic: `max(0.001, 1/spp)`).
    pub threshold: f32,
    /// Blender's `adaptive_min_samples` (0 = automatic: `max(4, ⌈16 / threshold^0.3⌉)`).
    pub min_samples: u32,
}

/// Samples between two convergence checks (Cycles' adaptive step).
pub const ADAPTIVE_STEP: u32 = 16;

impl Adaptive {
    /// `(threshold the estimate is compared with, minimum samples)` for `spp` samples, as
    /// Cycles derives them (its threshold is scaled by 5 internally).
    pub fn resolved(&self, spp: u32) -> (f32, u32) {
        let t = if self.threshold > 0.0 {
            self.threshold
        } else {
            (1.0 / spp.max(1) as f32).max(0.001)
        };
        let min = if self.min_samples == 0 {
            ((16.0 / t.powf(0.3)).ceil() as u32).max(4)
        } else {
            self.min_samples.max(4)
        };
        (t * 5.0, min)
    }

    /// After how many samples the pixels are checked: the first check comes after sample
    /// index `(min + 1) | 15` (0-based), then every 16 samples.
    pub fn first_check(&self, spp: u32) -> u32 {
        let (_, min) = self.resolved(spp);
        ((min + 1) | (ADAPTIVE_STEP - 1)) + 1
    }
}

/// Whether sample `index` of a pixel goes into the half buffer: the parity of its index's
/// odd-position bits (Christensen et al. 2018, section 10.2.1, as Cycles splits its samples).
/// Every aligned block of four indices gives the half two whose shuffled indices are
/// consecutive, a stratified pair of the (0,2)-sequence the sampler draws from, so the half is
/// itself well stratified and `|I − A|` measures the error of stratified sampling. Odd indices
/// (one of each consecutive pair) are stratified only pairwise and give twice the estimate on a
/// smooth integrand, so pixels sample on after they have converged.
#[inline]
pub fn in_half_buffer(index: u32) -> bool {
    (index & 0xaaaa_aaaa).count_ones() & 1 == 1
}

/// One pixel's sums.
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelAcc {
    /// Radiance summed over the accepted samples, in sample order.
    pub sum: Vec3,
    /// Twice the radiance of the samples [`in_half_buffer`] (adaptive sampling's half buffer).
    pub half: Vec3,
    /// Summed coverage (alpha) of the accepted samples, with a transparent film.
    pub coverage: f32,
    pub accepted: u32,
    /// Samples where the camera sees nothing (outside a fisheye's circle): black.
    pub empty: u32,
    /// The next sample index to render.
    pub next: u32,
    /// Adaptive sampling decided this pixel has converged.
    pub converged: bool,
}

impl PixelAcc {
    /// Samples that count for the mean.
    #[inline]
    pub fn n(&self) -> u32 {
        self.accepted + self.empty
    }

    /// Mean radiance and alpha. An opaque film has alpha 1 everywhere, a transparent one
    /// (`render.film_transparent`) the mean coverage.
    #[inline]
    pub fn rgba(&self, transparent: bool) -> [f32; 4] {
        let n = self.n();
        let c = if n > 0 {
            self.sum / n as f32
        } else {
            Vec3::ZERO
        };
        let alpha = if transparent && n > 0 {
            // Film > Transparent Glass's samples may leave [0, 1]; their mean stays in it
            // but for the noise (Cycles saturates it too).
            (self.coverage / n as f32).clamp(0.0, 1.0)
        } else {
            1.0
        };
        [c.x, c.y, c.z, alpha]
    }

    /// Cycles' per-pixel error estimate (see [`Adaptive`]), in the units of its threshold.
    pub fn error(&self) -> f32 {
        let n = self.n();
        if n == 0 {
            return f32::INFINITY;
        }
        let scale = 1.0 / n as f32;
        let (i, a) = (self.sum * scale, self.half * scale);
        let diff = (i - a).abs();
        let difference = diff.x + diff.y + diff.z;
        let intensity = i.x + i.y + i.z;
        let normalize = if intensity < 1.0 {
            intensity.max(0.0).sqrt()
        } else {
            intensity
        };
        difference / (1e-4 + normalize)
    }
}

/// Pixel `p`'s Combined RGBA, with the passes of `out_set` written to `out` from its record
/// `rec` (laid out by `acc_set`, which holds `out_set`'s passes and what they are computed
/// from). With shadow catchers (`acc_set` holds [`Pass::CatcherSums`]) Combined is the
/// catchers' matte with their shadows ([`catcher`]).
pub fn resolve_pixel(
    p: &PixelAcc,
    acc_set: &PassSet,
    rec: &[f32],
    out_set: &PassSet,
    transparent: bool,
    out: &mut [f32],
) -> [f32; 4] {
    if acc_set.is_empty() {
        return p.rgba(transparent);
    }
    if !out_set.is_empty() {
        data::resolve(acc_set, rec, p.accepted, out_set, out);
    }
    let (rgba, shadow) = match acc_set.offset(Pass::CatcherSums) {
        Some(at) => {
            let sums = &rec[at..at + Pass::CatcherSums.channels()];
            let with_shadow = !out_set.contains(Pass::ShadowCatcher);
            catcher::resolve(p, sums, transparent, with_shadow)
        }
        None => (p.rgba(transparent), Vec3::ONE),
    };
    if let Some(at) = out_set.offset(Pass::NoisyImage) {
        out[at..at + 4].copy_from_slice(&rgba);
    }
    if let Some(at) = out_set.offset(Pass::ShadowCatcher) {
        out[at..at + 3].copy_from_slice(&shadow.to_array());
    }
    rgba
}

/// Spreads "not converged" to the horizontal, then the vertical neighbours of every
/// unconverged pixel (Cycles' two box-filter passes), on a `w × h` mask of converged flags.
pub fn dilate_unconverged(converged: &mut [bool], w: usize, h: usize) {
    let src = converged.to_vec();
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if !src[i] {
                continue;
            }
            if (x > 0 && !src[i - 1]) || (x + 1 < w && !src[i + 1]) {
                converged[i] = false;
            }
        }
    }
    let src = converged.to_vec();
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if !src[i] {
                continue;
            }
            if (y > 0 && !src[i - w]) || (y + 1 < h && !src[i + w]) {
                converged[i] = false;
            }
        }
    }
}

/// The sample counts at which rounds end, for `spp` samples: one round without adaptive
/// sampling or a time limit; otherwise rounds ending at the adaptive checks, or (time limit
/// alone) at 1, 2, 4, ... samples and then every 32.
pub fn round_ends(spp: u32, adaptive: Option<&Adaptive>, timed: bool) -> Vec<u32> {
    let mut ends = Vec::new();
    match adaptive {
        Some(a) => {
            let mut e = a.first_check(spp);
            while e < spp {
                ends.push(e);
                e += ADAPTIVE_STEP;
            }
        }
        None if timed => {
            let mut e = 1;
            while e < spp {
                ends.push(e);
                e = if e < 32 { e * 2 } else { e + 32 };
            }
        }
        None => {}
    }
    ends.push(spp);
    ends
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cycles_defaults_resolve_as_cycles_does() {
        let a = Adaptive {
            threshold: 0.01,
            min_samples: 0,
        };
        let (t, min) = a.resolved(4096);
        assert!((t - 0.05).abs() < 1e-7);
        // ceil(16 / 0.01^0.3) = ceil(63.7) = 64.
        assert_eq!(min, 64);
        // Sample index (64 + 1) | 15 = 79 is the first checked: after 80 samples.
        assert_eq!(a.first_check(4096), 80);
        let ends = round_ends(128, Some(&a), false);
        assert_eq!(ends, vec![80, 96, 112, 128]);
        assert_eq!(round_ends(100, None, false), vec![100]);
        assert_eq!(
            round_ends(100, None, true),
            vec![1, 2, 4, 8, 16, 32, 64, 96, 100]
        );
    }

    #[test]
    fn dilation_spreads_one_pixel_each_way() {
        let (w, h) = (5, 5);
        let mut m = vec![true; w * h];
        m[2 * w + 2] = false;
        dilate_unconverged(&mut m, w, h);
        let unconverged: Vec<_> = (0..w * h).filter(|&i| !m[i]).collect();
        // The centre, its row neighbours, then the 3x3 block through the column pass.
        assert_eq!(unconverged, vec![6, 7, 8, 11, 12, 13, 16, 17, 18]);
    }

    #[test]
    fn error_estimate_is_zero_for_identical_halves_and_grows_with_disagreement() {
        let mut p = PixelAcc {
            sum: Vec3::splat(2.0),
            half: Vec3::splat(2.0),
            accepted: 4,
            ..Default::default()
        };
        assert_eq!(p.error(), 0.0);
        p.half = Vec3::splat(3.0);
        // I = 0.5, A = 0.75 per channel; R+G+B = 1.5 > 1 normalises linearly.
        let want = 0.75 / (1e-4 + 1.5);
        assert!((p.error() - want).abs() < 1e-6);
        // A dim pixel normalises by the square root: I = 0.05, A = 0.075 per channel.
        p.sum = Vec3::splat(0.2);
        p.half = Vec3::splat(0.3);
        let want = 0.075 / (1e-4 + 0.15f32.sqrt());
        assert!((p.error() - want).abs() < 1e-6);
    }

    /// `(mean of all, mean of the half buffer)` of `f` over the first `n` samples of `pixel`,
    /// `f` seeing the first `dims` 2D points of each sample.
    fn halves(pixel: u64, n: u32, dims: usize, f: impl Fn(&[glam::Vec2]) -> f32) -> (f32, f32) {
        let (mut all, mut half) = (0.0, 0.0);
        for s in 0..n {
            let mut sampler = crate::sampler::SobolSampler::new(3, pixel, s as u64);
            let pts: Vec<_> = (0..dims).map(|_| sampler.next_2d()).collect();
            let v = f(&pts);
            all += v;
            if in_half_buffer(s) {
                half += 2.0 * v;
            }
        }
        (all / n as f32, half / n as f32)
    }

    #[test]
    fn half_buffer_is_a_stratified_half_of_the_samples() {
        let n = 256;
        assert_eq!(
            (0..n).filter(|&s| in_half_buffer(s)).count(),
            n as usize / 2
        );
        let mut smooth_error = 0.0;
        for pixel in 0..64 {
            for dim in 0..4 {
                // A smooth integrand of the pair: the half's mean is about as close to the
                // full set's as stratification allows (0.012 here; odd indices, one of each
                // consecutive pair, give 0.025, a random half 0.054).
                let f = |p: &[glam::Vec2]| (3.0 * p[dim].x).sin() * p[dim].y + p[dim].x.powi(2);
                let (i, a) = halves(pixel, n, dim + 1, f);
                smooth_error += (i - a).abs() / 256.0;
                // A step across the middle of either coordinate: the samples integrate it
                // exactly, and so does the half.
                for axis in 0..2 {
                    let (i, a) = halves(pixel, n, dim + 1, |p| (p[dim][axis] < 0.5) as u32 as f32);
                    assert!(
                        (i - 0.5).abs() < 1e-6 && (a - 0.5).abs() < 1e-6,
                        "{pixel} {dim}: {a}"
                    );
                }
            }
        }
        assert!(smooth_error < 0.018, "mean |I - A| {smooth_error}");
    }
}
