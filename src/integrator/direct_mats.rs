//! Direct illumination by BSDF sampling (the seed's `direct_mats`): one BSDF sample at the
//! first non-delta surface; its ray counts the radiance of whatever emitter it hits.

use super::{Integrator, ShadingPoint, spawn};
use crate::bsdf::Measure;
use crate::render_scene::{Ctx, RenderScene};
use glam::Vec3;

pub struct DirectMats {
    pub max_depth: u32,
}

impl Integrator for DirectMats {
    fn li(&self, scene: &RenderScene, ctx: &mut Ctx, mut o: Vec3, mut d: Vec3) -> Vec3 {
        let mut l = Vec3::ZERO;
        let mut throughput = Vec3::ONE;
        let mut depth = 1;
        loop {
            let Some(its) = scene.trace(ctx, o, d, depth) else {
                if let Some((_, le, _)) = scene.background_radiance(d, o) {
                    l += throughput * le;
                }
                return l;
            };
            if let Some((_, le, _)) = scene.emitted(&its, d, o) {
                l += throughput * le;
            }
            if depth >= self.max_depth {
                return l;
            }
            let sp = ShadingPoint::new(scene, ctx, &its, d);
            let Some((wo, w, rec)) = sp.sample(ctx, &its, d) else {
                return l;
            };
            throughput *= w;
            o = spawn(&its, wo);
            d = wo;
            depth += 1;
            if rec.measure != Measure::Discrete {
                // The one non-delta bounce: count what it sees, then stop.
                match scene.trace(ctx, o, d, depth) {
                    Some(next) => {
                        if let Some((_, le, _)) = scene.emitted(&next, d, o) {
                            l += throughput * le;
                        }
                    }
                    None => {
                        if let Some((_, le, _)) = scene.background_radiance(d, o) {
                            l += throughput * le;
                        }
                    }
                }
                return l;
            }
        }
    }
}
