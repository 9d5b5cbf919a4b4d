//! A deliberately biased integrator: another integrator's radiance times a constant. It
//! exists so that tests of bias checks (the study's) have something they must catch; it is
//! not listed among the selectable integrators.

use super::Integrator;
use crate::render_scene::{Ctx, RenderScene};
use glam::Vec3;

/// The hidden name of [`Scaled`] over `direct_mis` with [`BIASED_FACTOR`].
#[doc(hidden)]
pub const BIASED_NAME: &str = "test_biased_direct_mis";

/// How much too bright [`BIASED_NAME`] is: 5 %, inside the noise of a single low-spp image
/// (a 32 × 32 Cornell box at 16 spp has a relative RMS error of tens of percent) but several
/// standard errors of a study's pooled mean.
#[doc(hidden)]
pub const BIASED_FACTOR: f32 = 1.05;

#[doc(hidden)]
pub struct Scaled {
    pub inner: Box<dyn Integrator>,
    pub factor: f32,
}

impl Integrator for Scaled {
    fn li(&self, scene: &RenderScene, ctx: &mut Ctx, o: Vec3, d: Vec3) -> Vec3 {
        self.inner.li(scene, ctx, o, d) * self.factor
    }
}
