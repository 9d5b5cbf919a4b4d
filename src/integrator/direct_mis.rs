//! Direct illumination with multiple importance sampling (the seed's `direct_mis`): one emitter
//! sample and one BSDF sample at the first non-delta surface, combined with the power
//! heuristic. Delta BSDF samples and delta lights get weight 1 (the other strategy cannot
//! produce them). The light-choice probability is part of the emitter density on both sides.

use super::light_split::{ClassWeights, Sink, SplitsLight};
use super::path::report;
use super::{ShadingPoint, sample_emitter_towards, spawn, trace_lit};
use crate::bsdf::Measure;
use crate::render_scene::{Ctx, RenderScene};
use glam::Vec3;

pub struct DirectMis {
    pub max_depth: u32,
    /// Most transparent surfaces a path passes straight through (Cycles'
    /// `transparent_max_bounces`; shadow rays get what the path has left).
    pub transparent: u32,
}

impl SplitsLight for DirectMis {
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
            if !sp.bsdf_is_delta() {
                let (e, towards) = sample_emitter_towards(scene, ctx, &its, &sp, d, true);
                l += throughput * e;
                if S::ACTIVE && e != Vec3::ZERO {
                    if depth == 1 {
                        sink.bounced(throughput * e, &sp.class_weights_to(towards), true);
                    } else {
                        sink.bounced(throughput * e, &weights, false);
                    }
                }
            }
            let Some((wo, w, rec)) = sp.sample(ctx, &its, d) else {
                return l;
            };
            if S::ACTIVE && depth == 1 {
                weights = sp.class_weights_sampled(&rec);
            }
            throughput *= w;
            ctx.receiver = scene.receiver_at(&its);
            o = spawn(&its, wo);
            d = wo;
            depth += 1;
            if rec.measure != Measure::Discrete {
                // The BSDF half of MIS at this vertex, then stop.
                let (_, emitted, lights) = trace_lit(scene, ctx, o, d, depth, true, rec.pdf);
                if let Some((e, le, erec)) = emitted {
                    let c = throughput * le * scene.hit_weight(ctx, e, &erec, rec.pdf);
                    l += c;
                    report(sink, c, depth, &weights);
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
