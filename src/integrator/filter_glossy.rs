//! Cycles' Filter Glossy (Light Paths > Caustics, `blur_glossy`): glossy lobes met after
//! unlikely bounces are blurred, which trades accuracy for less noise in caustics.
//!
//! A path keeps `min_ray_pdf`, the least solid-angle density (per steradian) with which the
//! BSDF sampled any of its non-delta bounces so far (infinite for the camera ray: its first
//! hit is never blurred; delta bounces, whose Cycles density is `10⁶` times their choice, and
//! transparent pass-throughs leave it). At a hit, with `filter = 1 / blur_glossy`, Cycles
//! computes `blur_pdf = filter · min_ray_pdf`; when `blur_pdf < 1` every microfacet lobe there
//! has its GGX alphas raised to at least `sqrt(1 - blur_pdf) / 2`
//! (`surface_shader_prepare_closures`, `bsdf_microfacet_blur`).
//!
//! The density is that of the BSDF of the closure the hit chose (with the lobe mixture of a
//! layered one); Cycles' is the mixture over all the hit's closures, which is the same for a
//! single closure and differs for mixes of closures.

/// The setting, ready for the path loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterGlossy {
    /// `1 / blur_glossy`; 0 when the filter is off (Cycles marks that with `FLT_MAX`).
    filter: f32,
}

impl FilterGlossy {
    /// Cycles' `blur_glossy` (`>= 0`; 0 = off). Anything not a finite positive number is off.
    pub fn new(blur_glossy: f32) -> Self {
        let on = blur_glossy.is_finite() && blur_glossy > 0.0;
        FilterGlossy {
            filter: if on { 1.0 / blur_glossy } else { 0.0 },
        }
    }

    #[inline]
    pub fn is_on(&self) -> bool {
        self.filter > 0.0
    }

    /// The least GGX alpha of the lobes at a hit reached by a path whose least BSDF density
    /// so far is `min_ray_pdf` (per steradian): `sqrt(1 - filter · min_ray_pdf) / 2` when that
    /// product is below 1, else 0 (no blur).
    #[inline]
    pub fn roughness(&self, min_ray_pdf: f32) -> f32 {
        let blur_pdf = self.filter * min_ray_pdf;
        if self.is_on() && blur_pdf < 1.0 {
            (1.0 - blur_pdf).sqrt() * 0.5
        } else {
            0.0
        }
    }
}

impl Default for FilterGlossy {
    /// Off.
    fn default() -> Self {
        FilterGlossy::new(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blur_follows_cycles_formula() {
        let f = FilterGlossy::new(1.0);
        // After a diffuse bounce at normal incidence (pdf 1/π).
        let pdf = std::f32::consts::FRAC_1_PI;
        assert_eq!(f.roughness(pdf), (1.0 - pdf).sqrt() * 0.5);
        assert_eq!(
            f.roughness(0.0),
            0.5,
            "the blurriest bounce gives alpha 1/2"
        );
        assert_eq!(f.roughness(1.0), 0.0, "blur_pdf 1 is not below 1");
        assert_eq!(f.roughness(f32::INFINITY), 0.0, "the camera ray's hit");
        // blur_glossy scales the density: 2 halves it.
        let g = FilterGlossy::new(2.0);
        assert_eq!(g.roughness(1.0), 0.5f32.sqrt() * 0.5);
        assert_eq!(g.roughness(2.5), 0.0);
    }

    #[test]
    fn zero_and_invalid_settings_are_off() {
        for b in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let f = FilterGlossy::new(b);
            assert!(!f.is_on(), "{b}");
            assert_eq!(f.roughness(0.0), 0.0, "{b}");
            assert_eq!(f.roughness(f32::INFINITY), 0.0, "{b}");
        }
        assert_eq!(FilterGlossy::default(), FilterGlossy::new(0.0));
    }
}
