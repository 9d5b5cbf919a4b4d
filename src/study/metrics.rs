//! Error measures of a render against a reference, and the statistics the study draws from
//! them: per-pixel moments across independent seeds, pooled means with their standard errors,
//! and least-squares slopes in log-log space.

/// The ε of the relative squared error: it keeps black reference pixels from dominating (the
/// value PBRT's and Mitsuba's relMSE use for images of about unit brightness).
pub const REL_MSE_EPSILON: f64 = 1e-2;

/// Relative mean squared error of `image` against `reference` (linear RGBA, same size):
/// the mean over pixels and RGB channels of `(x − r)² / (r² + ε)`.
pub fn rel_mse(image: &[[f32; 4]], reference: &[[f32; 4]]) -> f64 {
    let mut sum = 0.0;
    for (x, r) in image.iter().zip(reference) {
        for c in 0..3 {
            let (x, r) = (x[c] as f64, r[c] as f64);
            sum += (x - r).powi(2) / (r * r + REL_MSE_EPSILON);
        }
    }
    sum / (3 * image.len().max(1)) as f64
}

/// The per-pixel relative squared error (mean over RGB), as an error image.
pub fn rel_se_image(image: &[[f32; 4]], reference: &[[f32; 4]]) -> Vec<f64> {
    image
        .iter()
        .zip(reference)
        .map(|(x, r)| {
            (0..3)
                .map(|c| {
                    let (x, r) = (x[c] as f64, r[c] as f64);
                    (x - r).powi(2) / (r * r + REL_MSE_EPSILON)
                })
                .sum::<f64>()
                / 3.0
        })
        .collect()
}

/// The value a pixel contributes to the means the study compares: the sum of its RGB.
#[inline]
pub fn pixel_value(p: &[f32; 4]) -> f64 {
    p[0] as f64 + p[1] as f64 + p[2] as f64
}

/// Mean of [`pixel_value`] over the pixels where `mask` is true (all pixels without a mask).
pub fn masked_mean(image: &[[f32; 4]], mask: Option<&[bool]>) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for (i, p) in image.iter().enumerate() {
        if mask.is_none_or(|m| m[i]) {
            sum += pixel_value(p);
            n += 1;
        }
    }
    if n == 0 { 0.0 } else { sum / n as f64 }
}

/// Per-pixel sums over independent renders of one configuration (different seeds): their
/// mean image, and the standard error of the image mean estimated from the per-pixel
/// variance across the renders (`P·(K−1)` degrees of freedom, so it is accurate even for
/// two renders).
#[derive(Clone, Debug)]
pub struct SeedMoments {
    sum: Vec<[f64; 4]>,
    /// Per-pixel sums of [`pixel_value`] and of its square.
    value: Vec<[f64; 2]>,
    pub count: u32,
}

impl SeedMoments {
    pub fn new(pixels: usize) -> Self {
        SeedMoments {
            sum: vec![[0.0; 4]; pixels],
            value: vec![[0.0; 2]; pixels],
            count: 0,
        }
    }

    /// Adds one render.
    pub fn add(&mut self, image: &[[f32; 4]]) {
        for ((s, v), p) in self.sum.iter_mut().zip(&mut self.value).zip(image) {
            for c in 0..4 {
                s[c] += p[c] as f64;
            }
            let x = pixel_value(p);
            v[0] += x;
            v[1] += x * x;
        }
        self.count += 1;
    }

    /// The mean image of the renders added.
    pub fn mean_image(&self) -> Vec<[f32; 4]> {
        let k = self.count.max(1) as f64;
        self.sum.iter().map(|s| s.map(|c| (c / k) as f32)).collect()
    }

    /// Mean over pixels and renders of [`pixel_value`].
    pub fn mean(&self) -> f64 {
        let k = self.count.max(1) as f64;
        self.value.iter().map(|v| v[0]).sum::<f64>() / (k * self.value.len().max(1) as f64)
    }

    /// Variance of [`Self::mean`]: `Σ_p s_p² / (K P²)` with `s_p²` the unbiased variance of
    /// pixel `p` across the K renders (pixels are independent: each has its own random
    /// streams). Infinite with fewer than two renders.
    pub fn mean_variance(&self) -> f64 {
        let k = self.count as f64;
        if self.count < 2 {
            return f64::INFINITY;
        }
        let p = self.value.len().max(1) as f64;
        let var_sum: f64 = self
            .value
            .iter()
            .map(|v| ((v[1] - v[0] * v[0] / k) / (k - 1.0)).max(0.0))
            .sum();
        var_sum / (k * p * p)
    }
}

/// An estimate with its standard error.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Estimate {
    pub value: f64,
    pub se: f64,
}

/// The inverse-variance weighted mean of independent estimates `(mean, variance)`.
pub fn pooled_mean(parts: &[(f64, f64)]) -> Estimate {
    let mut w_sum = 0.0;
    let mut wx = 0.0;
    for &(m, v) in parts {
        if v.is_finite() && v > 0.0 {
            w_sum += 1.0 / v;
            wx += m / v;
        }
    }
    if w_sum == 0.0 {
        // Without variances (single renders, or noise-free ones) a plain mean, of unknown error.
        let n = parts.len().max(1) as f64;
        let m = parts.iter().map(|p| p.0).sum::<f64>() / n;
        return Estimate {
            value: m,
            se: if parts.iter().all(|p| p.1 == 0.0) {
                0.0
            } else {
                f64::INFINITY
            },
        };
    }
    Estimate {
        value: wx / w_sum,
        se: (1.0 / w_sum).sqrt(),
    }
}

/// The ratio `a / b` of two independent estimates, its standard error to first order.
pub fn ratio(a: Estimate, b: Estimate) -> Estimate {
    let r = a.value / b.value;
    let rel = ((a.se / a.value).powi(2) + (b.se / b.value).powi(2)).sqrt();
    Estimate {
        value: r,
        se: (r * rel).abs(),
    }
}

/// Least-squares slope and intercept of `ln y` against `ln x` over the points with both
/// positive: `y ≈ exp(intercept) · x^slope`. `None` with fewer than two such points.
pub fn log_log_fit(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx == 0.0 {
        return None;
    }
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let slope = sxy / sxx;
    Some((slope, my - slope * mx))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_log_fit_recovers_a_power_law() {
        let pts: Vec<(f64, f64)> = (0..6)
            .map(|i| {
                let x = 2f64.powi(i);
                (x, 3.0 * x.powf(-0.8))
            })
            .collect();
        let (s, b) = log_log_fit(&pts).unwrap();
        assert!((s + 0.8).abs() < 1e-12 && (b - 3f64.ln()).abs() < 1e-12);
        assert!(log_log_fit(&pts[..1]).is_none());
    }

    #[test]
    fn seed_moments_match_direct_formulas() {
        // Two pixels, three renders: values (channel sums) 1,2,6 and 0,0,3.
        let imgs = [
            [[1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 1.0]],
            [[2.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 1.0]],
            [[2.0, 2.0, 2.0, 1.0], [1.0, 1.0, 1.0, 1.0]],
        ];
        let mut m = SeedMoments::new(2);
        for i in &imgs {
            m.add(i);
        }
        assert!((m.mean() - 2.0).abs() < 1e-12);
        // Pixel variances 7 and 3; Var(mean) = (7 + 3) / (3 · 4).
        assert!((m.mean_variance() - 10.0 / 12.0).abs() < 1e-12);
        assert_eq!(m.mean_image()[0], [5.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0, 1.0]);
    }

    #[test]
    fn pooled_mean_weights_by_inverse_variance() {
        let e = pooled_mean(&[(1.0, 1.0), (4.0, 4.0)]);
        assert!((e.value - 1.6).abs() < 1e-12 && (e.se - 0.8f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn rel_mse_of_a_known_error() {
        let r = [[1.0f32, 0.0, 2.0, 1.0]];
        let x = [[2.0f32, 0.0, 2.0, 1.0]];
        let expect = (1.0 / (1.0 + REL_MSE_EPSILON)) / 3.0;
        assert!((rel_mse(&x, &r) - expect).abs() < 1e-12);
    }
}
