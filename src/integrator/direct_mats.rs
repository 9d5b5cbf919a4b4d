//! Direct illumination by BSDF sampling (the seed's `direct_mats`): one BSDF sample at the
//! first non-delta surface; its ray counts the radiance of whatever emitter it hits.

use super::light_split::{ClassWeights, Sink, SplitsLight};
use super::path::report;
use super::{ShadingPoint, spawn, trace_lit};
use crate::bsdf::Measure;
use crate::render_scene::{Ctx, RenderScene};
use glam::Vec3;

pub struct DirectMats {
    pub max_depth: u32,
    /// Most transparent surfaces a path passes straight through (Cycles'
    /// `transparent_max_bounces`; shadow rays get what the path has left).
    pub transparent: u32,
}

impl SplitsLight for DirectMats {
    #[inline(always)]
    fn run<S: Sink>(
        &self,
        scene: &RenderScene,
        ctx: &mut Ctx,
        mut o: Vec3,
        mut d: Vec3,
        sink: &mut S,
    ) -> Vec3 {
        let mut weights = ClassWeights::default();
        let mut l = Vec3::ZERO;
        let mut throughput = Vec3::ONE;
        let mut depth = 1;
        let mut sp = ShadingPoint::unshaded();
        ctx.start_transparent(self.transparent);
        // The vertex the path ends at.
        let mut end = self.max_depth;
        loop {
            let last = depth >= end;
            let (hit, emitted, lights) = trace_lit(scene, ctx, o, d, depth, last, f32::INFINITY);
            if let Some((_, le, _)) = emitted {
                l += throughput * le;
                report(sink, throughput * le, depth, &weights);
            }
            if lights != Vec3::ZERO {
                l += throughput * lights;
                report(sink, throughput * lights, depth, &weights);
            }
            let Some(its) = hit else {
                return l;
            };
            if last {
                return l;
            }
            if !sp.shade(scene, ctx, &its, d, depth) {
                return l;
            }
            if sp.passes {
                // Straight through a transparent closure: not a bounce (Cycles counts these
                // separately, up to `transparent_max_bounces`): once it has passed as many
                // as it may, it ends at the next surface (whose emission still counts).
                ctx.transparent += 1;
                if ctx.path_transparent_left() == 0 {
                    end = depth;
                }
                throughput *= sp.weight;
                o = spawn(&its, d);
                continue;
            }
            let Some((wo, w, rec)) = sp.sample(ctx, &its, d) else {
                return l;
            };
            if S::ACTIVE && depth == 1 {
                weights = sp.class_weights_sampled(&rec);
            }
            throughput *= w;
            o = spawn(&its, wo);
            d = wo;
            depth += 1;
            if rec.measure != Measure::Discrete {
                // The one non-delta bounce: count what it sees, then stop.
                let (_, emitted, lights) = trace_lit(scene, ctx, o, d, depth, true, f32::INFINITY);
                if let Some((_, le, _)) = emitted {
                    l += throughput * le;
                    report(sink, throughput * le, depth, &weights);
                }
                if lights != Vec3::ZERO {
                    l += throughput * lights;
                    report(sink, throughput * lights, depth, &weights);
                }
                return l;
            }
        }
    }
}
