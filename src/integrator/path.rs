//! Unidirectional path tracing: `path_mats` (BSDF sampling only) and `path_mis` (emitter and
//! BSDF sampling at every vertex, power heuristic). Russian roulette from vertex 4 on, on the
//! throughput's **maximum** component, survival probability capped at 0.95. Both apply
//! Cycles' Filter Glossy ([`super::filter_glossy`]) when it is on. A vertex whose chosen
//! closure scatters below the surface walks ([`subsurface`]) and goes on from the exit point
//! at the same depth, lit and sampled there as a diffuse vertex. Segments inside interiors
//! with a volume ([`medium`]) are attenuated by Beer's law, or, where the medium scatters,
//! end where a sampled free flight ends: a volume vertex lit (path_mis) and scattered by its
//! phase function, counted as a volume bounce.

use super::light_paths::{BounceCount, LightPaths};
use super::light_split::{ClassWeights, Sink, SplitsLight};
use super::{ShadingPoint, mis_weight, sample_emitter_towards, spawn, subsurface, trace_lit};
use crate::bsdf::Measure;
use crate::medium::{self, FreeFlight};
use crate::render_scene::{Ctx, Emitted, Intersection, RenderScene};
use crate::shading::globals::ray;
use glam::Vec3;

/// Depth (vertex count) from which Russian roulette applies.
const RR_DEPTH: u32 = 4;

pub struct PathMats {
    pub max_depth: u32,
    pub paths: LightPaths,
}

pub struct PathMis {
    pub max_depth: u32,
    pub paths: LightPaths,
}

/// Reports contribution `c` met at path vertex `depth` (1: the camera ray's hit) to `sink`;
/// `w` are the first bounce's weights (unused before it).
#[inline(always)]
pub(super) fn report<S: Sink>(sink: &mut S, c: Vec3, depth: u32, w: &ClassWeights) {
    if S::ACTIVE {
        if depth <= 1 {
            sink.camera(c);
        } else {
            sink.bounced(c, w, depth == 2);
        }
    }
}

/// Applies the medium `ctx.medium` to the segment from `o` along `d` that ended at `hit`
/// (none: it left the scene), met with `emitted` and `lights` at and before its end, for a
/// path of `throughput` at vertex `depth`. A clear medium changes nothing; an absorbing one
/// attenuates by Beer's law. In a
/// scattering or emitting one ([`medium`]) the segment's emission is added to `l`, and a free
/// flight is sampled: when it ends before `hit`, what lay beyond is dropped, the light shapes
/// met before it are added, and the point where the light scattered is returned.
#[allow(clippy::too_many_arguments)]
#[inline]
fn through_medium<S: Sink>(
    paths: &LightPaths,
    scene: &RenderScene,
    ctx: &mut Ctx,
    (o, d, depth, bsdf_pdf): (Vec3, Vec3, u32, f32),
    hit: Option<&Intersection>,
    emitted: &mut Emitted,
    lights: &mut Vec3,
    throughput: &mut Vec3,
    (l, sink, weights): (&mut Vec3, &mut S, &ClassWeights),
) -> Option<Vec3> {
    let m = ctx.medium;
    if m.is_clear() {
        return None;
    }
    let t_hit = hit.map_or(f32::INFINITY, |h| h.t);
    if !m.scatters_or_emits() {
        *throughput *= medium::transmittance(m.sigma_t(), t_hit);
        return None;
    }
    let e = m.emitted_along(t_hit);
    if e != Vec3::ZERO {
        let c = paths.clamp(*throughput * e, depth <= 2);
        *l += c;
        report(sink, c, depth, weights);
    }
    match m.sample_free_flight(t_hit, *throughput, ctx.sampler.next_2d()) {
        FreeFlight::Pass { weight } => {
            *throughput *= weight;
            None
        }
        FreeFlight::Scatter { t, weight, passing } => {
            *emitted = None;
            *lights = Vec3::ZERO;
            if scene.has_light_shapes() {
                let seen = scene.lights_on_ray(ctx, o, d, t, depth, bsdf_pdf, false);
                if seen != Vec3::ZERO {
                    let c = paths.clamp(*throughput * seen * passing, depth <= 2);
                    *l += c;
                    report(sink, c, depth, weights);
                }
            }
            *throughput *= weight;
            Some(o + d * t)
        }
    }
}

/// Light sampled from the point `p` inside the current medium, which scatters light arriving
/// along `-wi` into `-d` with its Henyey–Greenstein phase function; weighted against phase
/// sampling by the power heuristic.
#[inline]
fn sample_emitter_in_medium(scene: &RenderScene, ctx: &mut Ctx, p: Vec3, d: Vec3) -> Vec3 {
    let (u, uc) = ctx.sampler.next_3d();
    // A point in a medium belongs to no object: every light reaches it.
    let (light, rec, weight) = scene.sample_light(p, (uc, u), ctx.light_sample_at(), (true, 0));
    if weight == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let f = medium::henyey_greenstein(ctx.medium.g, d.dot(rec.wi));
    if f <= 0.0 {
        return Vec3::ZERO;
    }
    let tr = if scene.casts_shadow(light) {
        scene.transmittance(ctx, p, Vec3::ZERO, (light, &rec))
    } else {
        Vec3::ONE
    };
    let w = if scene.light_uses_mis(light) {
        mis_weight(rec.pdf, f)
    } else {
        1.0
    };
    weight * f * w * tr
}

/// A direction scattered at a point of the current medium for a ray that travelled along
/// `d`, with its density per steradian; leaves the ray's Light Path bits in the context.
#[inline]
fn scatter_in_medium(ctx: &mut Ctx, d: Vec3) -> (Vec3, f32) {
    ctx.ray_flags = ray::VOLUME;
    medium::sample_henyey_greenstein(ctx.medium.g, d, ctx.sampler.next_2d())
}

/// Russian roulette: returns false to terminate, else rescales `throughput`.
#[inline]
fn roulette(ctx: &mut Ctx, depth: u32, throughput: &mut Vec3) -> bool {
    if depth < RR_DEPTH {
        return true;
    }
    let q = throughput.max_element().min(0.95);
    if q <= 0.0 || ctx.sampler.next_1d() >= q {
        return false;
    }
    *throughput /= q;
    true
}

impl SplitsLight for PathMats {
    #[inline(always)]
    fn run<S: Sink>(
        &self,
        scene: &RenderScene,
        ctx: &mut Ctx,
        o: Vec3,
        d: Vec3,
        sink: &mut S,
    ) -> Vec3 {
        if self.paths.filter_glossy.is_on() {
            self.path::<S, true>(scene, ctx, o, d, sink)
        } else {
            self.path::<S, false>(scene, ctx, o, d, sink)
        }
    }
}

impl PathMats {
    /// The path loop; `BLUR`: Filter Glossy is on (off, the loop is the one without it).
    #[inline(always)]
    fn path<S: Sink, const BLUR: bool>(
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
        let (mut counts, mut end) = (BounceCount::default(), self.max_depth);
        ctx.depths = Default::default();
        ctx.no_caustics = self.paths.no_caustics();
        // Least BSDF density of the path's non-delta bounces (Filter Glossy).
        let mut min_ray_pdf = f32::INFINITY;
        ctx.blur = 0.0;
        ctx.walks_subsurface = true;
        ctx.medium = scene.camera_medium;
        // Film > Transparent Glass: the path starts with a transparent background.
        let glass = scene.transparent_glass();
        (ctx.clear_path, ctx.see_through) = (glass.is_some(), 0.0);
        let glass = glass.unwrap_or(0.0);
        // Transparent surfaces passed (kept in the context too, for the shadow rays).
        let mut transparent = 0;
        ctx.start_transparent(self.paths.transparent);
        let mut sp = ShadingPoint::unshaded();
        loop {
            // Inside an interior the segment's length is needed: no shortcut; nor where the
            // path may escape to a transparent background (whether it does is counted).
            let last = depth >= end && ctx.medium.is_clear() && !ctx.clear_path;
            let (hit, mut emitted, mut lights) =
                trace_lit(scene, ctx, o, d, depth, last, f32::INFINITY);
            let scattered = through_medium(
                &self.paths,
                scene,
                ctx,
                (o, d, depth, f32::INFINITY),
                hit.as_ref(),
                &mut emitted,
                &mut lights,
                &mut throughput,
                (&mut l, sink, &weights),
            );
            let direct = depth <= 2;
            if let Some((_, le, _)) = emitted {
                let c = self.paths.clamp(throughput * le, direct);
                l += c;
                report(sink, c, depth, &weights);
            }
            if lights != Vec3::ZERO {
                let c = self.paths.clamp(throughput * lights, direct);
                l += c;
                report(sink, c, depth, &weights);
            }
            if let Some(p) = scattered {
                if depth >= end || !roulette(ctx, depth, &mut throughput) {
                    return l;
                }
                if S::ACTIVE && depth == 1 {
                    weights = ClassWeights::DIFFUSE;
                }
                let (wo, _) = scatter_in_medium(ctx, d);
                if counts.count(ctx.ray_flags, &self.paths) {
                    end = end.min(depth + 1);
                }
                ctx.depths = counts.depths(transparent);
                ctx.clear_path = false;
                (o, d) = (p, wo);
                depth += 1;
                continue;
            }
            let Some(its) = hit else {
                if ctx.clear_path && depth > 1 {
                    // Seen through transmission: the world is transparent (Cycles'
                    // `average(throughput)`); escapes of the camera ray itself are in the
                    // film's coverage already.
                    ctx.see_through += throughput.element_sum() / 3.0;
                }
                return l;
            };
            // At the path's last vertex a surface that lets the ray through (a volume's
            // boundary, a transparent closure) still passes the light behind it, as Cycles
            // goes on through transparent surfaces after its last bounce: a ray scattered in a
            // medium reaches the world beyond its boundary. (Outside media the last segment's
            // emission is found by `trace_lit` already.)
            let at_end = depth >= end;
            if at_end && !scene.has_passing_surfaces() {
                return l;
            }
            if !at_end && !roulette(ctx, depth, &mut throughput) {
                return l;
            }
            if BLUR {
                ctx.blur = self.paths.filter_glossy.roughness(min_ray_pdf);
            }
            if !sp.shade(scene, ctx, &its, d, depth) {
                return l;
            }
            if at_end && !sp.passes {
                return l;
            }
            if sp.passes {
                // Straight through a transparent closure: not a bounce (Cycles counts these
                // separately, up to `transparent_max_bounces`). Once the path has passed as
                // many as it may, it ends at the next surface (whose emission still counts),
                // as Cycles ends it; in a medium that surface is shaded, and ends it here.
                if ctx.path_transparent_left() == 0 {
                    return l;
                }
                transparent += 1;
                ctx.transparent = transparent;
                if ctx.path_transparent_left() == 0 {
                    end = depth;
                }
                ctx.depths = counts.depths(transparent);
                throughput *= sp.weight;
                if scene.absorbs {
                    ctx.medium = medium::after(scene, &its, d, d, ctx.medium);
                }
                o = spawn(&its, d);
                continue;
            }
            // `dv`: the direction the vertex is seen along (from outside, after a walk). By
            // reference: moving the shading point would copy it at every vertex.
            let walked;
            let (its, sp, dv) = match sp.subsurface {
                None => (&its, &sp, d),
                Some(b) => {
                    let Some(v) =
                        subsurface::exit_vertex(scene, ctx, &its, d, &sp, &b, &mut throughput)
                    else {
                        return l;
                    };
                    if S::ACTIVE && depth == 1 {
                        weights = ClassWeights::DIFFUSE;
                    }
                    walked = v;
                    (&walked.0, &walked.1, walked.2)
                }
            };
            let Some((wo, w, rec)) = sp.sample(ctx, its, dv) else {
                return l;
            };
            if S::ACTIVE && depth == 1 {
                weights = sp.class_weights_sampled(&rec);
            }
            if BLUR && rec.measure != Measure::Discrete {
                min_ray_pdf = min_ray_pdf.min(rec.pdf);
            }
            throughput *= w;
            if ctx.clear_path {
                ctx.clear_path = sp.keeps_clear(&rec, ctx.ray_flags, glass);
            }
            // `sample` left the new ray's Light Path bits in the context.
            if counts.count(ctx.ray_flags, &self.paths) {
                end = end.min(depth + 1);
            }
            ctx.depths = counts.depths(transparent);
            if scene.absorbs {
                ctx.medium = medium::after(scene, its, dv, wo, ctx.medium);
            }
            o = spawn(its, wo);
            d = wo;
            depth += 1;
        }
    }
}

impl SplitsLight for PathMis {
    #[inline(always)]
    fn run<S: Sink>(
        &self,
        scene: &RenderScene,
        ctx: &mut Ctx,
        o: Vec3,
        d: Vec3,
        sink: &mut S,
    ) -> Vec3 {
        if self.paths.filter_glossy.is_on() {
            self.path::<S, true>(scene, ctx, o, d, sink)
        } else {
            self.path::<S, false>(scene, ctx, o, d, sink)
        }
    }
}

impl PathMis {
    /// The path loop; `BLUR`: Filter Glossy is on (off, the loop is the one without it).
    #[inline(always)]
    fn path<S: Sink, const BLUR: bool>(
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
        // Density of the BSDF sample that produced the current ray; infinite for camera rays
        // and delta samples (emitter sampling could not have produced them: MIS weight 1).
        let mut bsdf_pdf = f32::INFINITY;
        ctx.mis_from = None;
        let (mut counts, mut end) = (BounceCount::default(), self.max_depth);
        ctx.depths = Default::default();
        ctx.no_caustics = self.paths.no_caustics();
        // Least BSDF density of the path's non-delta bounces (Filter Glossy).
        let mut min_ray_pdf = f32::INFINITY;
        ctx.blur = 0.0;
        ctx.walks_subsurface = true;
        ctx.medium = scene.camera_medium;
        // Film > Transparent Glass: the path starts with a transparent background.
        let glass = scene.transparent_glass();
        (ctx.clear_path, ctx.see_through) = (glass.is_some(), 0.0);
        let glass = glass.unwrap_or(0.0);
        // Transparent surfaces passed (kept in the context too, for the shadow rays).
        let mut transparent = 0;
        ctx.start_transparent(self.paths.transparent);
        let mut sp = ShadingPoint::unshaded();
        loop {
            // Inside an interior the segment's length is needed: no shortcut; nor where the
            // path may escape to a transparent background (whether it does is counted).
            let last = depth >= end && ctx.medium.is_clear() && !ctx.clear_path;
            let (hit, mut emitted, mut lights) = trace_lit(scene, ctx, o, d, depth, last, bsdf_pdf);
            let scattered = through_medium(
                &self.paths,
                scene,
                ctx,
                (o, d, depth, bsdf_pdf),
                hit.as_ref(),
                &mut emitted,
                &mut lights,
                &mut throughput,
                (&mut l, sink, &weights),
            );
            if let Some((e, le, erec)) = emitted {
                let w = scene.hit_weight(ctx, e, &erec, bsdf_pdf);
                let c = self.paths.clamp(throughput * le * w, depth <= 2);
                l += c;
                report(sink, c, depth, &weights);
            }
            if lights != Vec3::ZERO {
                let c = self.paths.clamp(throughput * lights, depth <= 2);
                l += c;
                report(sink, c, depth, &weights);
            }
            if let Some(p) = scattered {
                if depth >= end || !roulette(ctx, depth, &mut throughput) {
                    return l;
                }
                let ls = self.paths.clamp(
                    throughput * sample_emitter_in_medium(scene, ctx, p, d),
                    depth == 1,
                );
                l += ls;
                if S::ACTIVE && ls != Vec3::ZERO {
                    sink.bounced(ls, &ClassWeights::DIFFUSE, depth == 1);
                }
                if S::ACTIVE && depth == 1 {
                    weights = ClassWeights::DIFFUSE;
                }
                let (wo, pdf) = scatter_in_medium(ctx, d);
                ctx.mis_from = None;
                ctx.receiver = 0;
                bsdf_pdf = pdf;
                if counts.count(ctx.ray_flags, &self.paths) {
                    end = end.min(depth + 1);
                }
                ctx.depths = counts.depths(transparent);
                ctx.clear_path = false;
                (o, d) = (p, wo);
                depth += 1;
                continue;
            }
            let Some(its) = hit else {
                if ctx.clear_path && depth > 1 {
                    // Seen through transmission: the world is transparent (Cycles'
                    // `average(throughput)`); escapes of the camera ray itself are in the
                    // film's coverage already.
                    ctx.see_through += throughput.element_sum() / 3.0;
                }
                return l;
            };
            // At the path's last vertex a surface that lets the ray through (a volume's
            // boundary, a transparent closure) still passes the light behind it, as Cycles
            // goes on through transparent surfaces after its last bounce: a ray scattered in a
            // medium reaches the world beyond its boundary. (Outside media the last segment's
            // emission is found by `trace_lit` already.)
            let at_end = depth >= end;
            if at_end && !scene.has_passing_surfaces() {
                return l;
            }
            if !at_end && !roulette(ctx, depth, &mut throughput) {
                return l;
            }
            if BLUR {
                ctx.blur = self.paths.filter_glossy.roughness(min_ray_pdf);
            }
            if !sp.shade(scene, ctx, &its, d, depth) {
                return l;
            }
            if at_end && !sp.passes {
                return l;
            }
            if sp.passes {
                // Straight through a transparent closure: not a bounce (Cycles counts these
                // separately, up to `transparent_max_bounces`). Once the path has passed as
                // many as it may, it ends at the next surface (whose emission still counts),
                // as Cycles ends it; in a medium that surface is shaded, and ends it here.
                if ctx.path_transparent_left() == 0 {
                    return l;
                }
                transparent += 1;
                ctx.transparent = transparent;
                if ctx.path_transparent_left() == 0 {
                    end = depth;
                }
                ctx.depths = counts.depths(transparent);
                throughput *= sp.weight;
                if scene.absorbs {
                    ctx.medium = medium::after(scene, &its, d, d, ctx.medium);
                }
                // The ray goes on from here, but was sampled where it started.
                ctx.mis_from.get_or_insert(o);
                o = spawn(&its, d);
                continue;
            }
            // `dv`: the direction the vertex is seen along (from outside, after a walk). By
            // reference: moving the shading point would copy it at every vertex.
            let walked;
            let (its, sp, dv) = match sp.subsurface {
                None => (&its, &sp, d),
                Some(b) => {
                    let Some(v) =
                        subsurface::exit_vertex(scene, ctx, &its, d, &sp, &b, &mut throughput)
                    else {
                        return l;
                    };
                    if S::ACTIVE && depth == 1 {
                        weights = ClassWeights::DIFFUSE;
                    }
                    walked = v;
                    (&walked.0, &walked.1, walked.2)
                }
            };
            if !sp.bsdf_is_delta() {
                let (e, towards) = sample_emitter_towards(scene, ctx, its, sp, dv, true);
                let ls = self.paths.clamp(throughput * e, depth == 1);
                l += ls;
                if S::ACTIVE && ls != Vec3::ZERO {
                    if depth == 1 {
                        sink.bounced(ls, &sp.class_weights_to(towards), true);
                    } else {
                        sink.bounced(ls, &weights, false);
                    }
                }
            }
            let Some((wo, w, rec)) = sp.sample(ctx, its, dv) else {
                return l;
            };
            if S::ACTIVE && depth == 1 {
                weights = sp.class_weights_sampled(&rec);
            }
            ctx.mis_from = None;
            ctx.receiver = scene.receiver_at(its);
            bsdf_pdf = if rec.measure == Measure::Discrete {
                f32::INFINITY
            } else {
                rec.pdf
            };
            if BLUR && rec.measure != Measure::Discrete {
                min_ray_pdf = min_ray_pdf.min(rec.pdf);
            }
            throughput *= w;
            if ctx.clear_path {
                ctx.clear_path = sp.keeps_clear(&rec, ctx.ray_flags, glass);
            }
            // `sample` left the new ray's Light Path bits in the context.
            if counts.count(ctx.ray_flags, &self.paths) {
                end = end.min(depth + 1);
            }
            ctx.depths = counts.depths(transparent);
            if scene.absorbs {
                ctx.medium = medium::after(scene, its, dv, wo, ctx.medium);
            }
            o = spawn(its, wo);
            d = wo;
            depth += 1;
        }
    }
}
