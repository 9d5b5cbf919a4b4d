//! Integrators: estimate the radiance arriving along a camera ray.
//!
//! Path depth counts **vertices** as Mitsuba does: the camera ray's first hit is vertex 1, so
//! `max_depth = 1` shows only emitters seen directly, `2` is direct illumination, and Cycles'
//! `max_bounces = b` corresponds to `b + 2`. Chains of delta (mirror/glass) bounces are followed
//! by every integrator — emitter sampling cannot see through them, BSDF sampling can.

pub mod debug;
pub mod direct_ems;
pub mod direct_mats;
pub mod direct_mis;
pub mod filter_glossy;
pub mod light_paths;
pub mod light_split;
pub mod path;
pub mod scaled;
pub mod subsurface;

use crate::accel::offset_origin;
use crate::bsdf::layered::{BaseLobe, TopLobe};
use crate::bsdf::{self, Bsdf, BsdfInstance, BsdfQueryRecord};
use crate::frame::Frame;
use crate::render_scene::{Ctx, Emitted, Intersection, RenderScene};
use crate::sampling::pick;
use glam::Vec3;

/// One integrator: radiance along the unit-direction ray `o + t d`.
pub trait Integrator: Send + Sync {
    fn li(&self, scene: &RenderScene, ctx: &mut Ctx, o: Vec3, d: Vec3) -> Vec3;

    /// True for integrators that can split their radiance into Cycles' light passes.
    fn splits_light(&self) -> bool {
        false
    }

    /// [`Integrator::li`] (the same value, the same random numbers) with its parts added to
    /// `split`; integrators that do not split put everything in `split.camera`.
    fn li_split(
        &self,
        scene: &RenderScene,
        ctx: &mut Ctx,
        o: Vec3,
        d: Vec3,
        split: &mut light_split::LightSplit,
    ) -> Vec3 {
        let l = self.li(scene, ctx, o, d);
        split.camera += l;
        l
    }
}

/// The integrators selectable by name. `direct_ems_first_hit` is emitter sampling at the
/// first hit only, without following delta chains (see [`direct_ems`]).
pub const NAMES: [&str; 8] = [
    "direct_ems",
    "direct_ems_first_hit",
    "direct_mats",
    "direct_mis",
    "path_mats",
    "path_mis",
    "normals",
    "albedo",
];

/// Builds the integrator called `name` with the given maximum path depth.
pub fn by_name(name: &str, max_depth: u32) -> Option<Box<dyn Integrator>> {
    by_name_with(name, max_depth, light_paths::LightPaths::default())
}

/// [`by_name`] with Cycles' light-path limits and clamps (used by the path integrators).
pub fn by_name_with(
    name: &str,
    max_depth: u32,
    paths: light_paths::LightPaths,
) -> Option<Box<dyn Integrator>> {
    Some(match name {
        "direct_ems" => Box::new(direct_ems::DirectEms {
            max_depth,
            follow_delta: true,
            transparent: paths.transparent,
        }),
        "direct_ems_first_hit" => Box::new(direct_ems::DirectEms {
            max_depth,
            follow_delta: false,
            transparent: paths.transparent,
        }),
        // Deliberately wrong (not listed in NAMES): for tests that must catch a bias.
        scaled::BIASED_NAME => Box::new(scaled::Scaled {
            inner: by_name("direct_mis", max_depth)?,
            factor: scaled::BIASED_FACTOR,
        }),
        "direct_mats" => Box::new(direct_mats::DirectMats {
            max_depth,
            transparent: paths.transparent,
        }),
        "direct_mis" => Box::new(direct_mis::DirectMis {
            max_depth,
            transparent: paths.transparent,
        }),
        "path_mats" => Box::new(path::PathMats { max_depth, paths }),
        "path_mis" => Box::new(path::PathMis { max_depth, paths }),
        "normals" => Box::new(debug::Normals),
        "albedo" => Box::new(debug::Albedo),
        _ => return None,
    })
}

/// What a render with integrator `name` leaves out of `scene`: the direct-only integrators
/// render subsurface materials as diffuse and leave volumes out (path_mis and path_mats render
/// both).
pub fn limitations(name: &str, scene: &RenderScene) -> Vec<String> {
    let mut out = Vec::new();
    if matches!(name, "path_mis" | "path_mats") {
        return out;
    }
    if scene.programs.iter().any(|p| p.may_scatter_below()) {
        out.push(format!("subsurface scattering renders as diffuse with the {name} integrator (path_mis and path_mats walk it)"));
    }
    if scene.absorbs {
        out.push(format!(
            "volumes are not rendered by the {name} integrator (path_mis and path_mats render them)"
        ));
    }
    out
}

/// Cycles' default `transparent_max_bounces`: the most transparent surfaces a path goes
/// straight through ([`crate::render_scene::Ctx::start_transparent`]).
pub const MAX_TRANSPARENT: u32 = 8;

/// The BSDF at a hit in its shading frame, with the local direction towards the ray's origin.
pub struct ShadingPoint {
    /// The chosen closure is transparent: the ray goes on straight, with `weight`.
    pub passes: bool,
    pub bsdf: BsdfInstance,
    pub frame: Frame,
    /// Local direction towards the previous vertex.
    pub wi: Vec3,
    /// The chosen closure's weight divided by the probability of choosing it.
    pub weight: Vec3,
    /// The path enters the surface here for a subsurface walk (the BSDF is then unused):
    /// `frame.n` is the BSSRDF's normal and `weight` the walk's.
    pub subsurface: Option<subsurface::Bssrdf>,
    /// The interpolated normal on the viewer's side when the closure's own normal differs
    /// from it (normal or bump map), for Cycles' bump shadowing; `None` otherwise.
    smooth: Option<Vec3>,
    /// The frame of the glossy layer of a specular-over-diffuse BSDF when a normal or bump
    /// map makes its normal differ from the diffuse one (Cycles raises a specular closure's
    /// normal so that it reflects above the surface; the diffuse keeps the mapped one).
    glossy_frame: Option<Frame>,
    /// Under a coat (in `glossy_frame`) over Principled's dielectric base, the frame of that
    /// base's specular layer when its raised normal differs from the diffuse one's.
    inner_frame: Option<Frame>,
}

impl ShadingPoint {
    /// A shading point to [`Self::shade`] into: one per path, reused at every vertex, so
    /// that the BSDF (hundreds of bytes for layered ones) is written in place rather than
    /// built aside and copied at each vertex.
    pub fn unshaded() -> Self {
        let frame = Frame::from_normal(Vec3::Z);
        ShadingPoint {
            passes: false,
            bsdf: BsdfInstance::Diffuse(bsdf::Diffuse::new(Vec3::ZERO)),
            frame,
            wi: Vec3::Z,
            weight: Vec3::ZERO,
            subsurface: None,
            smooth: None,
            glossy_frame: None,
            inner_frame: None,
        }
    }

    /// Evaluates the material at the hit (path vertex `depth`), chooses one closure and its
    /// BSDF (one random number for both) and sets up the frame, in place of what `self`
    /// held. Opaque surfaces shade both faces (the frame is flipped towards the viewer);
    /// transmissive ones keep the normal's outward side to tell entering from leaving.
    /// Microfacet lobes have their alphas raised to at least `ctx.blur` (Filter Glossy).
    /// False (and `self` left unusable) when nothing scatters there.
    pub fn shade(
        &mut self,
        scene: &RenderScene,
        ctx: &mut Ctx,
        its: &Intersection,
        d: Vec3,
        depth: u32,
    ) -> bool {
        let u = ctx.sampler.next_1d();
        let caustics_off =
            if depth > 1 && ctx.ray_flags & crate::shading::globals::ray::DIFFUSE != 0 {
                ctx.no_caustics
            } else {
                0
            };
        let blur = ctx.blur;
        let walks = ctx.walks_subsurface;
        let Some((closure, inv_p, u)) = scene.choose_closure(ctx, its, d, depth, u) else {
            return false;
        };
        let rest;
        let (closure, u, share) = match subsurface::split(closure, walks) {
            None => (closure, u, 1.0),
            Some(s) => match crate::sampling::pick(s.p, u) {
                (true, _) => {
                    *self = Self::subsurface_entry(its, d, closure, inv_p, &s);
                    return true;
                }
                (false, u) => {
                    rest = s.rest;
                    (&rest, u, 1.0 / (1.0 - s.p))
                }
            },
        };
        // Written in place (see `unshaded`).
        if caustics_off == 0 && blur == 0.0 {
            self.bsdf = bsdf::from_closure(closure, u);
        } else if caustics_off == 0 {
            self.bsdf = bsdf::closure::from_closure_blurred(closure, u, blur);
        } else {
            // Cycles leaves the closures of the caustics switched off out.
            match bsdf::closure::from_closure_without_caustics(closure, u, caustics_off, blur) {
                Some(b) => self.bsdf = b,
                None => return false,
            }
        }
        if let BsdfInstance::ChiangHair(hair) = &mut self.bsdf {
            // A strand: local +X along it, the offset across it from the outward normal.
            let n = its.ns;
            let t = Some(closure.tangent)
                .filter(|t| *t != Vec3::ZERO)
                .unwrap_or_else(|| crate::frame::Frame::from_normal(n).s);
            hair.h = bsdf::hair::offset_h(t, -d, n);
            let across = (-d - t * t.dot(-d))
                .try_normalize()
                .unwrap_or_else(|| crate::frame::Frame::from_normal(t).s);
            let frame = Frame {
                s: t,
                t: across.cross(t),
                n: across,
            };
            self.smooth = None;
            self.glossy_frame = None;
            self.inner_frame = None;
            self.passes = false;
            self.wi = frame.to_local(-d);
            self.frame = frame;
            self.weight = closure.weight * (inv_p * share);
            self.subsurface = None;
            return true;
        }
        let bsdf = &self.bsdf;
        // The closure's normal faces the viewer (Cycles' N); zero means the shading normal.
        let mut n = if closure.normal == Vec3::ZERO {
            its.ns
        } else {
            closure.normal
        };
        if bsdf.is_transmissive() {
            // Outward side: the side of the interpolated normal.
            if n.dot(its.ns) < 0.0 {
                n = -n;
            }
        } else if closure.normal == Vec3::ZERO
            && n.dot(-d) < 0.0
            && (its.face_normal().dot(-d) < 0.0 || !keeps_turned_normal(bsdf))
        {
            // The interpolated normal turned away from the viewer is flipped with the face
            // when the face is seen from behind, as Cycles' N; like a closure's own normal it
            // stays as it is on a face seen from the front (a diffuse lobe still lights it),
            // for the lobes that shade such a normal as Cycles does.
            n = -n;
        }
        // Specular lobes reflect above the geometric surface (Cycles' valid specular
        // reflection) under a closure normal, and under an interpolated one turned away from
        // the viewer, which is then their bump-shadowing reference as a closure normal's
        // surface is.
        let turned_away =
            !bsdf.is_transmissive() && closure.normal == Vec3::ZERO && n.dot(-d) < 0.0;
        let raise = closure.normal != Vec3::ZERO || turned_away;
        // The geometric normal on the viewer's side, what raised normals stay above.
        let ng_seen = if its.ng.dot(-d) < 0.0 {
            -its.ng
        } else {
            its.ng
        };
        if raise && raises_specular_normal(bsdf) {
            // Specular lobes (Glossy, Glass, Refraction, metallic or transmissive Principled)
            // under a normal or bump map reflect above the geometric surface, as Cycles makes
            // them; a transmissive lobe's normal is raised on the viewer's side.
            // (A transmissive lobe's normal points outwards; a reflective one's is Cycles' N.)
            let flip = bsdf.is_transmissive() && n.dot(-d) < 0.0;
            let m = bsdf::closure::valid_specular_normal(ng_seen, -d, if flip { -n } else { n });
            n = if flip { -m } else { m };
        }
        let rotation = anisotropic_rotation(&closure.kind);
        let tangent = match rotation {
            Some(_) if closure.tangent == Vec3::ZERO => scene
                .globals(its, d, depth, 0)
                .tangent()
                .map_or(Vec3::ZERO, |(t, _)| {
                    crate::shading::globals::from_blender(t)
                }),
            _ => closure.tangent,
        };
        let frame_of = |n: Vec3| match rotation {
            Some(rotation) => tangent_frame(n, tangent, rotation),
            None => Frame::from_normal(n),
        };
        // A coat has its own normal, as in Cycles: the Coat Normal input, else the surface's
        // (not the bumped one), raised to reflect above the surface; and a specular base below
        // it is raised as a specular lobe of its own is.
        // The surface's own normal (Cycles' `sd->N`) on the viewer's side.
        let surface_n = || {
            let ns = if closure.surface_normal == Vec3::ZERO {
                its.ns
            } else {
                closure.surface_normal
            };
            if ns.dot(-d) < 0.0 { -ns } else { ns }
        };
        let coat = coat_normal(bsdf, &closure.kind).map(|c| {
            let c = if c == Vec3::ZERO { surface_n() } else { c };
            bsdf::closure::valid_specular_normal(ng_seen, -d, c)
        });
        // A sheen keeps the bumped normal itself (Cycles does not raise it) over a raised base.
        let sheen = (raise && sheen_on_top(bsdf) && specular_base(bsdf)).then_some(n);
        let coat = coat.or(sheen);
        if coat.is_some() && raise && specular_base(bsdf) {
            n = bsdf::closure::valid_specular_normal(ng_seen, -d, n);
        }
        // Under a coat, Principled's dielectric base keeps its two normals: the specular
        // layer's raised, the diffuse's as mapped.
        let inner_frame = (coat.is_some() && raise && specular_diffuse_base(bsdf))
            .then(|| {
                let m = bsdf::closure::valid_specular_normal(ng_seen, -d, n);
                (m != n).then(|| Frame::from_normal(m))
            })
            .flatten();
        let frame = frame_of(n);
        let glossy_frame = match coat {
            Some(c) => (c != n).then(|| Frame::from_normal(c)),
            None => (raise && specular_over_diffuse(bsdf))
                .then(|| {
                    let m = bsdf::closure::valid_specular_normal(ng_seen, -d, n);
                    (m != n).then(|| frame_of(m))
                })
                .flatten(),
        };
        let smooth = raise.then(|| if turned_away { n } else { surface_n() });
        let wi = frame.to_local(-d);
        if let BsdfInstance::Layered(l) = &mut self.bsdf {
            // The layering for the direction its top lobe is queried with.
            l.prepare(glossy_frame.as_ref().map_or(wi, |g| g.to_local(-d)));
        }
        self.smooth = smooth;
        self.glossy_frame = glossy_frame;
        self.inner_frame = inner_frame.filter(|_| glossy_frame.is_some());
        self.passes = matches!(
            closure.kind,
            crate::shading::ClosureKind::Transparent { .. }
        );
        self.wi = wi;
        self.frame = frame;
        self.weight = closure.weight * (inv_p * share);
        self.subsurface = None;
        true
    }

    /// The shading point of a path entering the surface at `its` (seen along the unit `d`)
    /// for the walk of split `s` of `closure` (chosen with probability `1 / inv_p`): the
    /// BSSRDF's normal is the closure's (raised as a specular one's, as Cycles does) or the
    /// interpolated one on the viewer's side; the weight includes what the layers above the
    /// walk let through from `d`.
    fn subsurface_entry(
        its: &Intersection,
        d: Vec3,
        closure: &crate::shading::Closure,
        inv_p: f32,
        s: &subsurface::Split,
    ) -> ShadingPoint {
        let ng = if its.ng.dot(-d) < 0.0 {
            -its.ng
        } else {
            its.ng
        };
        let n = if closure.normal == Vec3::ZERO {
            if its.ns.dot(-d) < 0.0 {
                -its.ns
            } else {
                its.ns
            }
        } else {
            bsdf::closure::valid_specular_normal(ng, -d, closure.normal)
        };
        let frame = Frame::from_normal(n);
        let wi = frame.to_local(-d);
        let att = s.layers.as_ref().map_or(Vec3::ONE, |p| {
            bsdf::closure::principled_base_attenuation(p, wi)
        });
        ShadingPoint {
            passes: false,
            bsdf: BsdfInstance::Diffuse(bsdf::Diffuse::new(Vec3::ZERO)),
            frame,
            wi,
            weight: s.weight * att * inv_p,
            subsurface: Some(s.bssrdf),
            smooth: None,
            glossy_frame: None,
            inner_frame: None,
        }
    }

    /// The shading point where a walk leaves the surface at `its`, seen along the unit `d`
    /// (pointing into the surface): a white Lambertian BSDF about the interpolated normal on
    /// the side the walk left to (Cycles' exit closure; bump maps are not applied there).
    pub fn subsurface_exit(its: &Intersection, d: Vec3) -> ShadingPoint {
        let n = if its.ns.dot(-d) < 0.0 {
            -its.ns
        } else {
            its.ns
        };
        let frame = Frame::from_normal(n);
        ShadingPoint {
            passes: false,
            bsdf: BsdfInstance::Diffuse(bsdf::Diffuse::new(Vec3::ONE)),
            frame,
            wi: frame.to_local(-d),
            weight: Vec3::ONE,
            subsurface: None,
            smooth: None,
            glossy_frame: None,
            inner_frame: None,
        }
    }

    /// The kinds of scattering of the chosen BSDF (Light Path bits `DIFFUSE`, `GLOSSY`,
    /// `TRANSMISSION`), for lights that exclude some of them. The glossy coat over a diffuse
    /// base counts as both (one BSDF here; the light is excluded when it excludes both).
    #[inline]
    pub fn light_class(&self) -> u32 {
        use crate::shading::globals::ray;
        match self.bsdf {
            BsdfInstance::Diffuse(_) => ray::DIFFUSE,
            BsdfInstance::Mirror(_) | BsdfInstance::RoughConductor(_) => ray::GLOSSY,
            BsdfInstance::Plastic(_) => ray::DIFFUSE | ray::GLOSSY,
            BsdfInstance::Dielectric(_) | BsdfInstance::RoughDielectric(_) => {
                ray::GLOSSY | ray::TRANSMISSION
            }
            // Cycles counts translucent among the diffuse closures (CLOSURE_IS_BSDF_DIFFUSE).
            BsdfInstance::Translucent(_) => ray::DIFFUSE,
            BsdfInstance::Toon(t) if t.glossy => ray::GLOSSY,
            BsdfInstance::Toon(_) => ray::DIFFUSE,
            BsdfInstance::Transparent(_) => ray::TRANSMISSION,
            BsdfInstance::Sheen(_) => ray::DIFFUSE,
            BsdfInstance::ChiangHair(_) => ray::GLOSSY | ray::TRANSMISSION,
            BsdfInstance::Layered(_) => ray::DIFFUSE | ray::GLOSSY | ray::TRANSMISSION,
        }
    }

    /// Light-pass weights of light arriving from world direction `wo` (emitter sampling).
    #[inline]
    pub fn class_weights_to(&self, wo: Vec3) -> light_split::ClassWeights {
        light_split::ClassWeights::of(
            &self.bsdf,
            &BsdfQueryRecord::pair(self.wi, self.frame.to_local(wo)),
        )
    }

    /// Light-pass weights of the direction `sample` returned with `rec`.
    #[inline]
    pub fn class_weights_sampled(&self, rec: &BsdfQueryRecord) -> light_split::ClassWeights {
        light_split::ClassWeights::of(&self.bsdf, rec)
    }

    /// True when the chosen BSDF is purely specular.
    #[inline]
    pub fn bsdf_is_delta(&self) -> bool {
        self.bsdf.is_delta()
    }

    /// Whether the ray this point sampled (record `rec`, its Light Path bits `flags`) keeps a
    /// camera path's transparent background (Cycles' `LABEL_TRANSMIT_TRANSPARENT`): a
    /// transmission by a lobe that is not diffuse, whose `alpha_x · alpha_y` is at most
    /// `threshold` ([`RenderScene::transparent_glass`]).
    #[inline]
    pub fn keeps_clear(&self, rec: &BsdfQueryRecord, flags: u32, threshold: f32) -> bool {
        use crate::shading::globals::ray;
        if flags & ray::TRANSMISSION == 0 || flags & ray::DIFFUSE != 0 {
            return false;
        }
        rec.measure == bsdf::Measure::Discrete || self.bsdf.transmission_alpha2() <= threshold
    }

    /// `f · |cos θo|` for a world direction `wo`, zero if `wo` would cross the geometric surface
    /// on the wrong side for a reflection (avoids light leaks through shading normals).
    #[inline]
    pub fn eval_cos(&self, its: &Intersection, d: Vec3, wo: Vec3) -> Vec3 {
        let lo = self.frame.to_local(wo);
        if !self.bsdf.is_transmissive() && its.ng.dot(wo) * its.ng.dot(-d) <= 0.0 {
            return Vec3::ZERO;
        }
        if let Some(g) = &self.glossy_frame {
            return self.two_frame_eval_cos_pdf(g, d, wo, true).0 * self.weight;
        }
        let rec = BsdfQueryRecord::pair(self.wi, lo);
        match self.smooth {
            Some(ns) => self.bumped_eval(&rec, ns, wo, true) * lo.z.abs() * self.weight,
            None => self.bsdf.eval(&rec) * lo.z.abs() * self.weight,
        }
    }

    /// `(eval_cos(wo), pdf(wo))` with the work they share done once (the same values; the
    /// pdf is left zero where the value is).
    #[inline]
    pub fn eval_cos_pdf(&self, its: &Intersection, d: Vec3, wo: Vec3) -> (Vec3, f32) {
        if !self.bsdf.is_transmissive() && its.ng.dot(wo) * its.ng.dot(-d) <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        match (&self.glossy_frame, self.smooth) {
            (Some(g), _) => {
                let (f, pdf) = self.two_frame_eval_cos_pdf(g, d, wo, true);
                (f * self.weight, pdf)
            }
            (None, None) => {
                let lo = self.frame.to_local(wo);
                let (f, pdf) = self.bsdf.eval_and_pdf(&BsdfQueryRecord::pair(self.wi, lo));
                (f * lo.z.abs() * self.weight, pdf)
            }
            (None, Some(_)) => (self.eval_cos(its, d, wo), self.pdf(wo)),
        }
    }

    /// `f · |cos|` (without the closure weight) of a specular layer in frame `g` over the
    /// diffuse base in `self.frame`, each with its own normal's cosine and bump correction (as
    /// for evaluation when `is_eval`, else for a sample), as Cycles' two closures:
    /// `A(wi_g) f_d(wi, wo) |n·wo| + f_s(wi_g, wo_g) |m·wo|`; and with it the density
    /// [`Self::two_frame_pdf`] (one microfacet evaluation gives both).
    #[inline]
    fn two_frame_eval_cos_pdf(&self, g: &Frame, d: Vec3, wo: Vec3, is_eval: bool) -> (Vec3, f32) {
        let BsdfInstance::Layered(l) = &self.bsdf else {
            return (Vec3::ZERO, 0.0);
        };
        let ns = self.smooth.unwrap_or(self.frame.n);
        let (wi_g, wo_g, lo) = (g.to_local(-d), g.to_local(wo), self.frame.to_local(wo));
        let att = l.attenuation_at(wi_g);
        let (ft, pt) = l.top.eval_and_pdf(&BsdfQueryRecord::pair(wi_g, wo_g));
        let (fb, pb) = match (&self.inner_frame, &l.base) {
            (Some(m), BaseLobe::SpecularDiffuse(inner)) => {
                // The base's specular layer in its own frame over its diffuse in `self.frame`.
                let (wi_m, wo_m) = (m.to_local(-d), m.to_local(wo));
                let (fs, ps) = inner.top.eval_and_pdf(&BsdfQueryRecord::pair(wi_m, wo_m));
                let (fd, pd) = inner.base.eval_and_pdf(&BsdfQueryRecord::pair(self.wi, lo));
                let q = inner.top_probability(wi_m);
                let f = fs * wo_m.z.abs() * Self::bump_term(m.n, ns, wo, is_eval, false)
                    + inner.attenuation_at(wi_m)
                        * fd
                        * lo.z.abs()
                        * Self::bump_term(self.frame.n, ns, wo, is_eval, true);
                (f, q * ps + (1.0 - q) * pd)
            }
            _ => {
                let (fb, pb) = l.base.eval_and_pdf(&BsdfQueryRecord::pair(self.wi, lo));
                let diffuse = !specular_base(&self.bsdf);
                let bump = Self::bump_term(self.frame.n, ns, wo, is_eval, diffuse);
                (fb * lo.z.abs() * bump, pb)
            }
        };
        let base = att * fb;
        // A sheen on top is one of Cycles' diffuse closures, corrected as one.
        let top_diffuse = matches!(l.top, bsdf::layered::TopLobe::Sheen(_));
        let top = ft * wo_g.z.abs() * Self::bump_term(g.n, ns, wo, is_eval, top_diffuse);
        let p = l.top_probability(wi_g);
        (base + top, p * pt + (1.0 - p) * pb)
    }

    /// The BSDF at `rec` (per steradian) with the bump corrections for a closure normal off
    /// the interpolated one `ns`; a diffuse base under a glossy coat is corrected as the
    /// diffuse closure it is in Cycles, the coat as a glossy one.
    #[inline]
    fn bumped_eval(&self, rec: &BsdfQueryRecord, ns: Vec3, wo: Vec3, is_eval: bool) -> Vec3 {
        match self.bsdf.diffuse_parts(rec) {
            Some((base, coat)) => {
                base * self.bump_shadowing(ns, wo, is_eval, true)
                    + coat * self.bump_shadowing(ns, wo, is_eval, false)
            }
            None => self.bsdf.eval(rec) * self.bump_shadowing(ns, wo, is_eval, self.diffuse_lobe()),
        }
    }

    /// The density (per steradian) of [`Self::two_frame_eval_cos_pdf`]'s sampling: the glossy
    /// layer with Layered's probability `p(wi_g)`, else the base.
    #[inline]
    fn two_frame_pdf(&self, g: &Frame, d: Vec3, wo: Vec3) -> f32 {
        let BsdfInstance::Layered(l) = &self.bsdf else {
            return 0.0;
        };
        let wi_g = g.to_local(-d);
        let p = l.top_probability(wi_g);
        let lo = self.frame.to_local(wo);
        let base = match (&self.inner_frame, &l.base) {
            (Some(m), BaseLobe::SpecularDiffuse(inner)) => {
                let wi_m = m.to_local(-d);
                let q = inner.top_probability(wi_m);
                q * inner.top.pdf(&BsdfQueryRecord::pair(wi_m, m.to_local(wo)))
                    + (1.0 - q) * inner.base.pdf(&BsdfQueryRecord::pair(self.wi, lo))
            }
            _ => l.base.pdf(&BsdfQueryRecord::pair(self.wi, lo)),
        };
        p * l.top.pdf(&BsdfQueryRecord::pair(wi_g, g.to_local(wo))) + (1.0 - p) * base
    }

    /// Samples the two-frame pair: the world direction and its record, local to `self.frame`
    /// (its density comes with the value, from [`Self::two_frame_eval_cos_pdf`]); and for a
    /// delta lobe (a smooth coat or mirror metal), which has no value to evaluate, its
    /// weight, divided by the probability of choosing it.
    #[inline]
    fn two_frame_sample(
        &self,
        g: &Frame,
        d: Vec3,
        u: glam::Vec2,
        u1: f32,
    ) -> Option<(Vec3, BsdfQueryRecord, Option<Vec3>, bool)> {
        let BsdfInstance::Layered(l) = &self.bsdf else {
            return None;
        };
        let wi_g = g.to_local(-d);
        let (top, u1) = l.pick(wi_g, u1);
        // Under the top: the base's specular layer in its own frame, or the base as a whole.
        let inner = match (&self.inner_frame, &l.base) {
            (Some(m), BaseLobe::SpecularDiffuse(inner)) if !top => Some((m, inner)),
            _ => None,
        };
        let (frame, mut rec, w, diffuse) = if top {
            let mut rec = BsdfQueryRecord::new(wi_g);
            let w = l.top.sample(&mut rec, u, u1);
            (g, rec, w, matches!(l.top, TopLobe::Sheen(_)))
        } else if let Some((m, inner)) = inner {
            let wi_m = m.to_local(-d);
            let q = inner.top_probability(wi_m);
            let (spec, u1) = pick(q, u1);
            if spec {
                let mut rec = BsdfQueryRecord::new(wi_m);
                let w = inner.top.sample(&mut rec, u, u1) / q;
                (m, rec, w, false)
            } else {
                let mut rec = BsdfQueryRecord::new(self.wi);
                let w = inner.attenuation_at(wi_m) * inner.base.sample(&mut rec, u, u1) / (1.0 - q);
                (&self.frame, rec, w, true)
            }
        } else {
            let mut rec = BsdfQueryRecord::new(self.wi);
            let w = l.base.sample(&mut rec, u, u1);
            (
                &self.frame,
                rec,
                w,
                base_samples_diffuse(&l.base, self.wi, u1),
            )
        };
        // The pair's weight comes from its value; a black lobe's direction still counts.
        if w == Vec3::ZERO && !bsdf::layered::sampled_direction(&rec) {
            return None;
        }
        let discrete = (rec.measure == bsdf::Measure::Discrete).then(|| {
            let p = l.top_probability(wi_g);
            if top {
                w / p
            } else {
                l.attenuation_at(wi_g) * w / (1.0 - p)
            }
        });
        let wo = frame.to_world(rec.wo);
        rec.wo = self.frame.to_local(wo);
        rec.wi = self.wi;
        Some((wo, rec, discrete, diffuse))
    }

    /// The chosen BSDF is one of Cycles' diffuse closures (`CLOSURE_IS_BSDF_DIFFUSE`).
    #[inline]
    fn diffuse_lobe(&self) -> bool {
        match self.bsdf {
            BsdfInstance::Diffuse(_) | BsdfInstance::Translucent(_) | BsdfInstance::Sheen(_) => {
                true
            }
            BsdfInstance::Toon(t) => !t.glossy,
            _ => false,
        }
    }

    /// Cycles' correction for a closure normal that differs from the interpolated one `ns`
    /// (normal and bump maps), for light leaving along world direction `wo`: zero where `wo`
    /// lies on the wrong side of the interpolated surface for the closure's normal (for
    /// evaluation, and for diffuse lobes always), and for diffuse lobes a GGX shadowing term
    /// (Chiang et al. 2019) with `α² = tan²(N, Ns) / 8` that darkens the terminator smoothly.
    fn bump_shadowing(&self, ns: Vec3, wo: Vec3, is_eval: bool, diffuse: bool) -> f32 {
        Self::bump_term(self.frame.n, ns, wo, is_eval, diffuse)
    }

    /// [`Self::bump_shadowing`] for a closure with unit normal `n`.
    #[inline]
    fn bump_term(n: Vec3, ns: Vec3, wo: Vec3, is_eval: bool, diffuse: bool) -> f32 {
        let (cos_nsi, cos_nsn, cos_ni) = (ns.dot(wo), ns.dot(n), n.dot(wo));
        if cos_nsi * cos_nsn * cos_ni < 0.0 && (is_eval || diffuse) {
            return 0.0;
        }
        if !diffuse {
            return 1.0;
        }
        let (cos_i, cos_d) = (cos_nsi.abs(), cos_nsn.abs());
        if cos_d >= 1.0 || cos_i >= 1.0 {
            return 1.0;
        }
        if cos_i < 1e-6 {
            return 0.0;
        }
        let tan2_d = 1.0 / (cos_d * cos_d) - 1.0;
        let alpha2 = (0.125 * tan2_d).clamp(0.0, 1.0);
        let tan2_i = 1.0 / (cos_i * cos_i) - 1.0;
        let lambda = ((1.0 + alpha2 * tan2_i).sqrt() - 1.0) * 0.5;
        1.0 / (1.0 + lambda)
    }

    /// Light Path bits of a ray sampled from this point.
    #[inline]
    fn ray_flags(&self, rec: &BsdfQueryRecord, reflect: bool, diffuse: bool) -> u32 {
        use crate::shading::globals::ray;
        let kind = if rec.measure == bsdf::Measure::Discrete {
            ray::GLOSSY | ray::SINGULAR
        } else if diffuse {
            ray::DIFFUSE
        } else {
            ray::GLOSSY
        };
        kind | if reflect {
            ray::REFLECTION
        } else {
            ray::TRANSMISSION
        }
    }

    /// Whether the lobe `sample` picks with the random number `u1` for the incident local
    /// direction `wi` (of the lobe that makes the choice) is one of Cycles' diffuse closures:
    /// a Lambertian, translucent or sheen lobe, or the diffuse base of a layered or plastic
    /// BSDF when the choice falls below its top.
    #[inline]
    fn sampled_diffuse(&self, wi: Vec3, u1: f32) -> bool {
        match &self.bsdf {
            BsdfInstance::Diffuse(_) | BsdfInstance::Translucent(_) | BsdfInstance::Sheen(_) => {
                true
            }
            BsdfInstance::Toon(t) => !t.glossy,
            BsdfInstance::Plastic(p) => wi.z > 0.0 && u1 >= p.coat_share(wi.z),
            BsdfInstance::Layered(l) => {
                let (top, u2) = l.pick(wi, u1);
                if top {
                    return matches!(l.top, TopLobe::Sheen(_));
                }
                // The base's own choice, with the number Layered passes it.
                base_samples_diffuse(&l.base, wi, u2)
            }
            _ => false,
        }
    }

    /// BSDF density of world direction `wo` (per steradian).
    #[inline]
    pub fn pdf(&self, wo: Vec3) -> f32 {
        if let Some(g) = &self.glossy_frame {
            return self.two_frame_pdf(g, self.frame.to_world(-self.wi), wo);
        }
        self.bsdf
            .pdf(&BsdfQueryRecord::pair(self.wi, self.frame.to_local(wo)))
    }

    /// Samples the BSDF: `(world direction, weight, record)`, or `None` if it failed.
    #[inline]
    pub fn sample(
        &self,
        ctx: &mut Ctx,
        its: &Intersection,
        d: Vec3,
    ) -> Option<(Vec3, Vec3, BsdfQueryRecord)> {
        let mut rec = BsdfQueryRecord::new(self.wi);
        // The direction's pair and the lobe's number drawn jointly; the path's first BSDF
        // sample jointly with the pixel filter's offset too.
        let (u, u1) = ctx.sampler.reserved_3d();
        if let Some(g) = &self.glossy_frame {
            let (wo, mut rec, discrete, diffuse) = self.two_frame_sample(g, d, u, u1)?;
            if let Some(w) = discrete {
                ctx.ray_flags = self.ray_flags(&rec, true, diffuse);
                if its.ng.dot(wo) * its.ng.dot(-d) <= 0.0 {
                    return None;
                }
                let w = w * self.weight;
                return (w != Vec3::ZERO && w.is_finite()).then_some((wo, w, rec));
            }
            let (f, pdf) = self.two_frame_eval_cos_pdf(g, d, wo, false);
            if !(pdf > 0.0 && pdf.is_finite()) {
                return None;
            }
            rec.pdf = pdf;
            ctx.ray_flags = self.ray_flags(&rec, true, diffuse);
            if its.ng.dot(wo) * its.ng.dot(-d) <= 0.0 {
                return None;
            }
            let w = f / rec.pdf * self.weight;
            return (w != Vec3::ZERO && w.is_finite()).then_some((wo, w, rec));
        }
        let w = self.bsdf.sample(&mut rec, u, u1) * self.weight;
        if w == Vec3::ZERO || !w.is_finite() {
            return None;
        }
        let wo = self.frame.to_world(rec.wo);
        // A reflection must leave on the viewer's side of the true surface.
        let reflect = !self.bsdf.is_transmissive() || rec.wo.z * self.wi.z > 0.0;
        ctx.ray_flags = self.ray_flags(&rec, reflect, self.sampled_diffuse(self.wi, u1));
        if reflect && its.ng.dot(wo) * its.ng.dot(-d) <= 0.0 {
            return None;
        }
        let w = match (self.smooth, &self.bsdf) {
            // The mixture's weight re-evaluated with each part corrected on its own.
            (Some(ns), BsdfInstance::Plastic(_) | BsdfInstance::Layered(_))
                if rec.measure == bsdf::Measure::SolidAngle
                    && self.bsdf.diffuse_parts(&rec).is_some() =>
            {
                self.bumped_eval(&rec, ns, wo, false) * rec.wo.z.abs() / rec.pdf * self.weight
            }
            (Some(ns), _) => w * self.bump_shadowing(ns, wo, false, self.diffuse_lobe()),
            (None, _) => w,
        };
        if w == Vec3::ZERO {
            return None;
        }
        Some((wo, w, rec))
    }
}

/// Whether `bsdf` shades an interpolated normal that turns away from the viewer as Cycles
/// does (diffuse lobes light it as it is; the specular lobes that [`ShadingPoint::new`] raises
/// above the surface reflect about the raised normal). Other lobes see it flipped towards
/// the viewer.
#[inline]
fn keeps_turned_normal(bsdf: &BsdfInstance) -> bool {
    matches!(bsdf, BsdfInstance::Diffuse(_))
        || raises_specular_normal(bsdf)
        || specular_over_diffuse(bsdf)
}

/// The specular lobes whose normal [`ShadingPoint::new`] raises above the geometric surface
/// (Glossy, Glass, Refraction, metallic or transmissive Principled).
#[inline]
fn raises_specular_normal(bsdf: &BsdfInstance) -> bool {
    matches!(
        bsdf,
        BsdfInstance::Mirror(_)
            | BsdfInstance::RoughConductor(_)
            | BsdfInstance::Dielectric(_)
            | BsdfInstance::RoughDielectric(_)
    )
}

/// The normal of a coat on top of `bsdf`, made from closure `kind`: its Coat Normal (zero
/// when unlinked: the surface normal); `None` without a coat on top.
#[inline]
fn coat_normal(bsdf: &BsdfInstance, kind: &crate::shading::ClosureKind) -> Option<Vec3> {
    match (bsdf, kind) {
        (BsdfInstance::Layered(l), crate::shading::ClosureKind::Principled(p))
            if matches!(l.top, bsdf::layered::TopLobe::Coat(_)) =>
        {
            Some(p.coat_normal)
        }
        _ => None,
    }
}

/// Whether `base`, sampled for `wi` with the lobe-choice number `u1`, samples a diffuse lobe
/// (its own diffuse, or the diffuse below its inner layer when the choice falls there).
#[inline]
fn base_samples_diffuse(base: &BaseLobe, wi: Vec3, u1: f32) -> bool {
    match base {
        BaseLobe::Diffuse(_) | BaseLobe::Translucent(_) => true,
        BaseLobe::CoatedDiffuse(inner) => !inner.pick(wi, u1).0,
        BaseLobe::SpecularDiffuse(inner) => !inner.pick(wi, u1).0,
        _ => false,
    }
}

/// A coat or sheen over Principled's dielectric base (a specular layer over diffuse).
#[inline]
fn specular_diffuse_base(bsdf: &BsdfInstance) -> bool {
    matches!(bsdf, BsdfInstance::Layered(l) if matches!(l.base, bsdf::layered::BaseLobe::SpecularDiffuse(_)))
}

/// A sheen on top of a layered BSDF.
#[inline]
fn sheen_on_top(bsdf: &BsdfInstance) -> bool {
    matches!(bsdf, BsdfInstance::Layered(l) if matches!(l.top, bsdf::layered::TopLobe::Sheen(_)))
}

/// A layered BSDF whose base is a specular lobe (metal, glass): Cycles raises its normal and
/// corrects it for bumps as a glossy closure, not a diffuse one.
#[inline]
fn specular_base(bsdf: &BsdfInstance) -> bool {
    use bsdf::layered::BaseLobe;
    matches!(
        bsdf,
        BsdfInstance::Layered(l) if matches!(
            l.base,
            BaseLobe::Mirror(_)
                | BaseLobe::RoughConductor(_)
                | BaseLobe::Dielectric(_)
                | BaseLobe::RoughDielectric(_)
                | BaseLobe::CoatedConductor(_)
        )
    )
}

/// Principled's dielectric: a specular layer over diffuse, shaded in two frames.
#[inline]
fn specular_over_diffuse(bsdf: &BsdfInstance) -> bool {
    matches!(
        bsdf,
        BsdfInstance::Layered(l) if matches!(
            (&l.top, &l.base),
            (bsdf::layered::TopLobe::Specular(_), bsdf::layered::BaseLobe::Diffuse(_))
        )
    )
}

/// The rotation (in turns) of an anisotropic closure's tangent, `None` for isotropic ones.
#[inline]
fn anisotropic_rotation(k: &crate::shading::ClosureKind) -> Option<f32> {
    use crate::shading::ClosureKind;
    match k {
        ClosureKind::Glossy {
            anisotropy,
            rotation,
            ..
        } if *anisotropy != 0.0 => Some(*rotation),
        ClosureKind::Principled(p) if p.cycles && p.anisotropic != 0.0 => {
            Some(p.anisotropic_rotation)
        }
        _ => None,
    }
}

/// A frame around unit normal `n` whose local +X is the tangent `t` (projected into the
/// tangent plane) turned by `rotation` turns about `n`, as Blender's anisotropic lobes want.
fn tangent_frame(n: Vec3, t: Vec3, rotation: f32) -> Frame {
    let t = t - n * n.dot(t);
    if t.length_squared() < 1e-20 || !t.is_finite() {
        return Frame::from_normal(n);
    }
    let t = t.normalize();
    let b = n.cross(t);
    let (sin, cos) = (rotation * std::f32::consts::TAU).sin_cos();
    let s = t * cos + b * sin;
    Frame {
        s,
        t: n.cross(s),
        n,
    }
}

/// Power heuristic (β = 2) weight of a strategy with density `a` against one with density `b`.
#[inline]
pub fn mis_weight(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 && (a2 + b2).is_finite() {
        a2 / (a2 + b2)
    } else if a.is_infinite() {
        1.0
    } else {
        0.0
    }
}

/// Emitter sampling at a shading point: `Σ f cos Le / pdf` for one light sample, weighted
/// against BSDF sampling when `mis` (delta lights always get weight 1).
#[inline]
pub fn sample_emitter(
    scene: &RenderScene,
    ctx: &mut Ctx,
    its: &Intersection,
    sp: &ShadingPoint,
    d: Vec3,
    mis: bool,
) -> Vec3 {
    sample_emitter_towards(scene, ctx, its, sp, d, mis).0
}

/// [`sample_emitter`] and the world direction towards the light sample (zero when none).
#[inline]
pub fn sample_emitter_towards(
    scene: &RenderScene,
    ctx: &mut Ctx,
    its: &Intersection,
    sp: &ShadingPoint,
    d: Vec3,
    mis: bool,
) -> (Vec3, Vec3) {
    let none = (Vec3::ZERO, Vec3::ZERO);
    // The light's choice and its point drawn jointly.
    let (u, uc) = ctx.sampler.next_3d();
    let receiver = scene.receiver_at(its);
    let (light, rec, weight) =
        scene.sample_light(its.p, (uc, u), ctx.light_sample_at(), (mis, receiver));
    if weight == Vec3::ZERO || !scene.light_reaches(light, sp.light_class()) {
        return none;
    }
    let mis = mis && scene.light_uses_mis(light);
    let (f, bsdf_pdf) = if mis {
        sp.eval_cos_pdf(its, d, rec.wi)
    } else {
        (sp.eval_cos(its, d, rec.wi), 0.0)
    };
    if f == Vec3::ZERO {
        return none;
    }
    let tr = if scene.casts_shadow(light) {
        scene.transmittance(ctx, its.p, its.ng, (light, &rec))
    } else {
        Vec3::ONE
    };
    if tr == Vec3::ZERO {
        return none;
    }
    let w = if mis {
        mis_weight(rec.pdf, bsdf_pdf)
    } else {
        1.0
    };
    (f * weight * w * tr, rec.wi)
}

/// Traces the ray leaving path vertex `depth - 1` and returns the surface it hits (if any) with
/// the radiance arriving along it from that surface's emission, or from the background when
/// the ray escapes. When `last` (the path ends at the hit: only the emission matters) the
/// surface is not returned and the emission is found the cheap way
/// ([`RenderScene::emission_along`]).
#[inline]
pub fn trace_emitted(
    scene: &RenderScene,
    ctx: &mut Ctx,
    o: Vec3,
    d: Vec3,
    depth: u32,
    last: bool,
) -> (Option<Intersection>, Emitted) {
    ctx.depth = depth;
    if depth <= 1 {
        // Camera rays see every light.
        ctx.receiver = 0;
    }
    if last && depth > 1 {
        return (None, scene.emission_along(ctx, o, d));
    }
    let hit = scene.trace(ctx, o, d, depth);
    let flags = if depth <= 1 {
        crate::shading::globals::ray::CAMERA
    } else {
        ctx.ray_flags
    };
    let emitted = match &hit {
        Some(its) => scene.emitted(its, o, flags, ctx.path_at(), ctx.receiver),
        // A transparent-background path (Film > Transparent Glass) sees no world: it adds
        // to the film's transparency instead (the path integrators count it).
        None if ctx.clear_path => None,
        None => scene.background_radiance(d, o, depth, flags),
    };
    (hit, emitted)
}

/// [`trace_emitted`], plus the radiance of the Blender lights' shapes the ray passes through
/// before that surface (lights are not surfaces: they never stop a ray), weighted against
/// emitter sampling with the density `bsdf_pdf` of the BSDF sample that made the ray
/// (infinite: weight 1, for camera rays, delta bounces and integrators without emitter
/// sampling). Zero in scenes without such lights.
#[inline]
pub fn trace_lit(
    scene: &RenderScene,
    ctx: &mut Ctx,
    o: Vec3,
    d: Vec3,
    depth: u32,
    last: bool,
    bsdf_pdf: f32,
) -> (Option<Intersection>, Emitted, Vec3) {
    let (hit, emitted) = trace_emitted(scene, ctx, o, d, depth, last);
    if !scene.has_light_shapes() {
        return (hit, emitted, Vec3::ZERO);
    }
    let lights = if last && depth > 1 {
        scene.lights_on_ray(ctx, o, d, f32::INFINITY, depth, bsdf_pdf, true)
    } else {
        let end = if depth == 1 {
            ctx.camera_tmax(o, d)
        } else {
            f32::INFINITY
        };
        let tmax = hit.as_ref().map_or(end, |its| (its.p - o).length());
        let mut l = scene.lights_on_ray(ctx, o, d, tmax, depth, bsdf_pdf, false);
        if hit.is_none() && tmax.is_finite() {
            // A camera ray that escapes past the far clip still sees the suns, as the world.
            l += scene.suns_on_ray(ctx, o, d, depth, bsdf_pdf, false);
        }
        l
    };
    (hit, emitted, lights)
}

/// Origin for a ray leaving `its` along `wo`.
#[inline]
pub fn spawn(its: &Intersection, wo: Vec3) -> Vec3 {
    offset_origin(its.p, its.ng, wo)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::{Closure, ClosureKind, Principled};

    /// A shading point of a coated Principled BSDF (dielectric or metal base) under a tilted
    /// mapped normal seen at a grazing angle, with the frames `shade` gives it: the coat on the
    /// surface normal, the base's specular layer on the raised normal, the diffuse on the
    /// mapped one.
    fn coated(metallic: f32, coat_roughness: f32) -> (ShadingPoint, Intersection, Vec3) {
        let closure = Closure {
            weight: Vec3::ONE,
            normal: Vec3::ZERO,
            tangent: Vec3::ZERO,
            surface_normal: Vec3::ZERO,
            kind: ClosureKind::Principled(Principled {
                base_color: Vec3::new(0.8, 0.5, 0.3),
                metallic,
                roughness: 0.4,
                specular_level: 0.5,
                coat_weight: 1.0,
                coat_roughness,
                coat_ior: 1.5,
                coat_tint: Vec3::ONE,
                ..Principled::lobe_only()
            }),
        };
        let mut bsdf = bsdf::from_closure(&closure, 0.5);
        let ng = Vec3::Z;
        let d = -Vec3::new(0.9, 0.0, 0.25).normalize();
        let n = Vec3::new(-0.6, 0.1, 1.0).normalize();
        let m = bsdf::closure::valid_specular_normal(ng, -d, n);
        assert!(
            m.dot(n) < 0.999,
            "the raised normal differs from the mapped one"
        );
        let specular_base = specular_base(&bsdf);
        let base_n = if specular_base { m } else { n };
        let frame = Frame::from_normal(base_n);
        let g = Frame::from_normal(bsdf::closure::valid_specular_normal(ng, -d, ng));
        if let BsdfInstance::Layered(l) = &mut bsdf {
            l.prepare(g.to_local(-d));
        }
        let sp = ShadingPoint {
            passes: false,
            bsdf,
            frame,
            wi: frame.to_local(-d),
            weight: Vec3::ONE,
            subsurface: None,
            smooth: Some(ng),
            glossy_frame: Some(g),
            inner_frame: (!specular_base).then(|| Frame::from_normal(m)),
        };
        let its = Intersection {
            t: 1.0,
            p: Vec3::ZERO,
            ng,
            ng_flipped: false,
            ns: ng,
            uv: glam::Vec2::ZERO,
            mesh: 0,
            instance: 0,
            tri: 0,
            b1: 0.0,
            b2: 0.0,
            material: 0,
            emitter: None,
            time: 0.5,
        };
        (sp, its, d)
    }

    /// The sampled directions' weights are `eval_cos / pdf` with the density `pdf` gives, and
    /// their mean is the BSDF's integral over the sphere (estimated independently with
    /// uniform directions): the multi-frame sampling is unbiased and consistent with its
    /// density, as MIS needs.
    #[test]
    fn multi_frame_sampling_matches_its_density_and_integral() {
        for metallic in [0.0, 1.0] {
            let (sp, its, d) = coated(metallic, 0.2);
            let n = 200_000u32;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for i in 0..n {
                let mut ctx = Ctx::new(crate::sampler::SobolSampler::new(7, 3, i as u64));
                let Some((wo, w, rec)) = sp.sample(&mut ctx, &its, d) else {
                    continue;
                };
                let pdf = sp.pdf(wo);
                assert!(
                    (rec.pdf - pdf).abs() <= 1e-3 * pdf.max(1e-3),
                    "sampled density {} against pdf {pdf}",
                    rec.pdf
                );
                let f = sp.eval_cos(&its, d, wo);
                let expect = f / pdf;
                assert!(
                    (w - expect).abs().max_element() <= 1e-3 * expect.max_element().max(1e-3),
                    "weight {w} against eval/pdf {expect}"
                );
                let y = w.element_sum() as f64;
                sum += y;
                sum2 += y * y;
            }
            let mean = sum / n as f64;
            let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
            // The integral with uniform directions on the sphere.
            let (mut isum, mut isum2) = (0.0f64, 0.0f64);
            let m = 400_000u32;
            for i in 0..m {
                let mut s = crate::sampler::Sampler::new(11, 5, i as u64);
                let u = s.next_2d();
                let z = 1.0 - 2.0 * u.x;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * std::f32::consts::PI * u.y;
                let wo = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                let y = sp.eval_cos(&its, d, wo).element_sum() as f64 * 4.0 * std::f64::consts::PI;
                isum += y;
                isum2 += y * y;
            }
            let imean = isum / m as f64;
            let ise = ((isum2 / m as f64 - imean * imean) / m as f64).sqrt();
            let t = (mean - imean) / (se * se + ise * ise).sqrt();
            assert!(
                t.abs() < 4.0,
                "metallic {metallic}: sampled mean {mean} against integral {imean} (t = {t})"
            );
        }
    }

    /// A smooth coat is a delta lobe: sampling returns its reflection with a finite weight
    /// through the discrete branch, and the rough base still samples by its density.
    #[test]
    fn a_smooth_coat_over_a_raised_base_is_sampled_discretely() {
        let (sp, its, d) = coated(0.0, 0.0);
        let (mut discrete, mut rough) = (0, 0);
        for i in 0..2000u64 {
            let mut ctx = Ctx::new(crate::sampler::SobolSampler::new(3, 1, i));
            if let Some((wo, w, rec)) = sp.sample(&mut ctx, &its, d) {
                assert!(w.is_finite() && w.min_element() >= 0.0, "{w}");
                if rec.measure == bsdf::Measure::Discrete {
                    discrete += 1;
                    let r = 2.0 * Vec3::Z.dot(-d) * Vec3::Z - -d;
                    assert!(
                        wo.dot(r) > 0.9999,
                        "the coat reflects about the surface normal"
                    );
                } else {
                    rough += 1;
                }
            }
        }
        assert!(discrete > 50 && rough > 500, "{discrete} {rough}");
    }
}
