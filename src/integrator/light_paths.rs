//! Cycles' Light Paths settings beyond the total depth: bounce limits per kind of scattering,
//! transparent pass-throughs, sample clamping, caustics and Filter Glossy.

use super::MAX_TRANSPARENT;
use super::filter_glossy::FilterGlossy;
use crate::shading::globals::ray;
use glam::Vec3;

/// Limits and clamps of the path integrators.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightPaths {
    /// Most bounces of each kind (Cycles' `diffuse_bounces`, `glossy_bounces`,
    /// `transmission_bounces`): once a path's count of a kind reaches its limit, the path
    /// ends at the next surface (whose emission still counts), as Cycles ends it.
    pub diffuse: u32,
    pub glossy: u32,
    pub transmission: u32,
    /// Most volume scatter bounces (Cycles' `volume_bounces`): as the kinds above.
    pub volume: u32,
    /// Transparent surfaces a path goes straight through (`transparent_max_bounces`).
    pub transparent: u32,
    /// Cycles' `sample_clamp_direct` / `sample_clamp_indirect`: a contribution whose
    /// `|R| + |G| + |B|` exceeds three times the value is scaled down to that; 0 = none. Direct is
    /// light sampled at the first hit and emission met by the camera ray or the first bounce.
    pub clamp_direct: f32,
    pub clamp_indirect: f32,
    /// Cycles' `caustics_reflective` / `caustics_refractive`: when off, a ray that left a
    /// diffuse bounce meets no glossy reflection (resp. refraction) lobes.
    pub caustics_reflective: bool,
    pub caustics_refractive: bool,
    /// Cycles' `blur_glossy` (off by default).
    pub filter_glossy: FilterGlossy,
}

/// Bits of [`LightPaths::no_caustics`].
pub mod caustics {
    pub const NO_REFLECTIVE: u8 = 1;
    pub const NO_REFRACTIVE: u8 = 2;
}

impl Default for LightPaths {
    /// No per-kind limit, Cycles' 8 transparent surfaces, no clamping, caustics on, no
    /// Filter Glossy.
    fn default() -> Self {
        LightPaths {
            diffuse: u32::MAX,
            glossy: u32::MAX,
            transmission: u32::MAX,
            volume: u32::MAX,
            transparent: MAX_TRANSPARENT,
            clamp_direct: 0.0,
            clamp_indirect: 0.0,
            caustics_reflective: true,
            caustics_refractive: true,
            filter_glossy: FilterGlossy::default(),
        }
    }
}

impl LightPaths {
    /// The caustics switched off, as [`caustics`] bits.
    #[inline]
    pub fn no_caustics(&self) -> u8 {
        let mut m = 0;
        if !self.caustics_reflective {
            m |= caustics::NO_REFLECTIVE;
        }
        if !self.caustics_refractive {
            m |= caustics::NO_REFRACTIVE;
        }
        m
    }

    /// The contribution `c` clamped as Cycles clamps it (`direct`: see the fields).
    #[inline]
    pub fn clamp(&self, c: Vec3, direct: bool) -> Vec3 {
        let limit = if direct {
            self.clamp_direct
        } else {
            self.clamp_indirect
        };
        if limit <= 0.0 {
            return c;
        }
        let limit = 3.0 * limit;
        let sum = c.x.abs() + c.y.abs() + c.z.abs();
        if sum > limit { c * (limit / sum) } else { c }
    }
}

/// One path's bounces of each kind.
#[derive(Clone, Copy, Debug, Default)]
pub struct BounceCount {
    diffuse: u32,
    glossy: u32,
    transmission: u32,
    volume: u32,
}

impl BounceCount {
    /// Counts a bounce whose new ray has Light Path bits `flags` (Cycles' rule: transmission
    /// if it crosses the surface, else diffuse or glossy); true when that kind's count has
    /// passed its limit in `paths` (a limit of 1 allows one bounce that still finds lights).
    #[inline]
    pub fn count(&mut self, flags: u32, paths: &LightPaths) -> bool {
        if flags & ray::VOLUME != 0 {
            self.volume += 1;
            self.volume > paths.volume
        } else if flags & ray::TRANSMISSION != 0 {
            self.transmission += 1;
            self.transmission > paths.transmission
        } else if flags & ray::DIFFUSE != 0 {
            self.diffuse += 1;
            self.diffuse > paths.diffuse
        } else {
            self.glossy += 1;
            self.glossy > paths.glossy
        }
    }
}

impl BounceCount {
    /// The counts as Light Path's depths, with `transparent` straight pass-throughs.
    #[inline]
    pub fn depths(&self, transparent: u32) -> crate::shading::globals::PathDepths {
        let d = |n: u32| n.min(u16::MAX as u32) as u16;
        crate::shading::globals::PathDepths {
            diffuse: d(self.diffuse),
            glossy: d(self.glossy),
            transmission: d(self.transmission),
            transparent: d(transparent),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clamping_scales_the_sum_of_components_to_the_limit() {
        let p = LightPaths {
            clamp_direct: 1.0,
            clamp_indirect: 1.0 / 3.0,
            ..Default::default()
        };
        let c = Vec3::new(2.0, 1.0, 1.0);
        assert_eq!(p.clamp(c, true), c * 0.75);
        assert_eq!(p.clamp(c, false), c * 0.25);
        assert_eq!(p.clamp(Vec3::splat(0.2), false), Vec3::splat(0.2));
        assert_eq!(LightPaths::default().clamp(c * 1e6, true), c * 1e6);
    }

    #[test]
    fn bounces_count_by_kind() {
        let p = LightPaths {
            diffuse: 2,
            glossy: 1,
            ..Default::default()
        };
        let mut b = BounceCount::default();
        let diffuse = ray::DIFFUSE | ray::REFLECTION;
        assert!(!b.count(diffuse, &p) && !b.count(diffuse, &p));
        assert!(
            b.count(diffuse, &p),
            "the third diffuse bounce passes a limit of 2"
        );
        let mut b = BounceCount::default();
        let refraction = ray::GLOSSY | ray::TRANSMISSION;
        assert!(!b.count(refraction, &p), "refraction is transmission");
        assert!(!b.count(ray::GLOSSY | ray::SINGULAR | ray::REFLECTION, &p));
        assert!(b.count(ray::GLOSSY | ray::REFLECTION, &p));
        let p = LightPaths {
            volume: 0,
            ..Default::default()
        };
        let mut b = BounceCount::default();
        assert!(b.count(ray::VOLUME, &p), "no volume bounce allowed");
        assert!(!b.count(ray::DIFFUSE | ray::REFLECTION, &p));
    }
}
