//! Cycles' light passes from inside a path: each contribution to a camera path's radiance,
//! split by the class of the path's first bounce (diffuse, glossy, transmission) and by
//! whether it is direct (light sampled at the first bounce, or emission met by the ray that
//! leaves it) or indirect (everything after).
//!
//! The path integrators are generic over a [`Sink`]: [`NoSplit`] compiles to nothing, so a
//! render without light passes runs the same code as before.

use crate::bsdf::{Bsdf, BsdfQueryRecord, Measure};
use glam::Vec3;

/// The share of a path's radiance that goes to the diffuse and the glossy passes, per
/// channel (Cycles' `pass_diffuse_weight`, `pass_glossy_weight`); transmission takes
/// `1 - diffuse - glossy`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClassWeights {
    pub diffuse: Vec3,
    pub glossy: Vec3,
}

impl ClassWeights {
    /// The weights of light scattered from local direction `rec.wo` to `rec.wi` by `bsdf`:
    /// its [`Bsdf::eval_split`] over its value, per channel (0 where the value is 0). A
    /// direction sampled from a delta lobe is glossy when it reflects, transmission when it
    /// crosses the surface.
    #[inline]
    pub fn of<B: Bsdf>(bsdf: &B, rec: &BsdfQueryRecord) -> ClassWeights {
        if rec.measure == Measure::Discrete {
            let glossy = if rec.wo.z * rec.wi.z > 0.0 { 1.0 } else { 0.0 };
            return ClassWeights {
                diffuse: Vec3::ZERO,
                glossy: Vec3::splat(glossy),
            };
        }
        let f = bsdf.eval(rec);
        let [d, g] = bsdf.eval_split(rec);
        let div = |a: Vec3| {
            Vec3::new(
                if f.x != 0.0 { a.x / f.x } else { 0.0 },
                if f.y != 0.0 { a.y / f.y } else { 0.0 },
                if f.z != 0.0 { a.z / f.z } else { 0.0 },
            )
        };
        ClassWeights {
            diffuse: div(d),
            glossy: div(g),
        }
    }
}

/// One camera sample's light passes: radiance per class (`[diffuse, glossy, transmission]`),
/// not yet divided by colour, and what reached the camera before any bounce.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightSplit {
    pub direct: [Vec3; 3],
    pub indirect: [Vec3; 3],
    /// Emission and world seen straight or through transparent surfaces (Cycles' Emit and
    /// Env passes, which the film computes on its own).
    pub camera: Vec3,
}

impl LightSplit {
    /// Everything, for checks: equals the integrator's radiance up to rounding.
    pub fn total(&self) -> Vec3 {
        self.camera
            + self.direct.iter().copied().sum::<Vec3>()
            + self.indirect.iter().copied().sum::<Vec3>()
    }
}

/// Where an integrator reports the parts of its radiance.
pub trait Sink {
    /// False for [`NoSplit`]: callers skip the work of classifying.
    const ACTIVE: bool;
    /// Radiance `c` met before the path's first bounce.
    fn camera(&mut self, c: Vec3);
    /// Radiance `c` that came through the first bounce, with that bounce's weights.
    fn bounced(&mut self, c: Vec3, w: &ClassWeights, direct: bool);
}

/// No light passes.
pub struct NoSplit;

impl Sink for NoSplit {
    const ACTIVE: bool = false;
    #[inline(always)]
    fn camera(&mut self, _: Vec3) {}
    #[inline(always)]
    fn bounced(&mut self, _: Vec3, _: &ClassWeights, _: bool) {}
}

impl Sink for LightSplit {
    const ACTIVE: bool = true;
    #[inline]
    fn camera(&mut self, c: Vec3) {
        self.camera += c;
    }
    #[inline]
    fn bounced(&mut self, c: Vec3, w: &ClassWeights, direct: bool) {
        let to = if direct {
            &mut self.direct
        } else {
            &mut self.indirect
        };
        let (d, g) = (c * w.diffuse, c * w.glossy);
        to[0] += d;
        to[1] += g;
        to[2] += c - d - g;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Diffuse, Plastic};

    #[test]
    fn weights_split_a_mixed_lobe_and_sum_to_one() {
        let p = Plastic::new(Vec3::new(0.8, 0.4, 0.2), 0.09, 1.5, 1.0, Vec3::ONE);
        let wi = Vec3::new(0.3, 0.0, 0.954).normalize();
        let wo = Vec3::new(-0.3, 0.1, 0.95).normalize();
        let w = ClassWeights::of(&p, &BsdfQueryRecord::pair(wi, wo));
        // Near the mirror direction both lobes contribute.
        assert!(
            w.diffuse.min_element() > 0.01 && w.glossy.min_element() > 0.01,
            "{w:?}"
        );
        assert!(((w.diffuse + w.glossy) - Vec3::ONE).abs().max_element() < 1e-5);
        let d = ClassWeights::of(
            &Diffuse::new(Vec3::splat(0.5)),
            &BsdfQueryRecord::pair(wi, wo),
        );
        assert_eq!(d.diffuse, Vec3::ONE);
        assert_eq!(d.glossy, Vec3::ZERO);
        let mut s = LightSplit::default();
        s.bounced(Vec3::splat(2.0), &w, true);
        s.bounced(Vec3::ONE, &ClassWeights::default(), false);
        assert!((s.total() - Vec3::splat(3.0)).abs().max_element() < 1e-5);
        assert_eq!(s.indirect[2], Vec3::ONE);
    }
}
