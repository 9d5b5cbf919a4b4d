//! The auxiliary passes of one camera sample: what the camera ray meets first (Cycles' data
//! passes and denoising features), the emission and the world it sees directly.
//!
//! The camera ray is traced again, deterministically (no random numbers: the integrator's
//! streams are untouched, so Combined is the same with or without passes), through
//! transparent surfaces as Cycles' camera paths go: the data passes come from the first
//! surface whose alpha reaches 1/2 (Cycles' alpha threshold), the light passes add up along
//! the way, weighted by the transmittance in front.

use super::color::closure_colors;
use super::pass::{LightClass, Pass, PassSet};
use crate::accel::offset_origin;
use crate::camera::RayCamera;
use crate::integrator::light_split::LightSplit;
use crate::render_scene::{Ctx, RenderScene};
use crate::scene::Mist;
use crate::shading::globals::{ray, to_blender};
use crate::shading::{Closure, ClosureKind};
use glam::Vec3;

/// What a film needs to compute data passes.
pub struct DataContext<'a> {
    pub scene: &'a RenderScene,
    pub camera: &'a RayCamera,
    pub passes: &'a PassSet,
    pub mist: Mist,
}

/// A closure's albedo for the denoiser (its colour: what it reflects or transmits at most);
/// `None` for transparent closures, which the ray passes through.
fn closure_albedo(c: &Closure) -> Option<Vec3> {
    let color = match c.kind {
        ClosureKind::Principled(p) => p.base_color,
        ClosureKind::Diffuse { color, .. }
        | ClosureKind::Glossy { color, .. }
        | ClosureKind::Glass { color, .. }
        | ClosureKind::Refraction { color, .. }
        | ClosureKind::Translucent { color }
        | ClosureKind::Toon { color, .. } => color,
        ClosureKind::Subsurface { .. } => Vec3::ONE,
        ClosureKind::Hair(h) => h.hair_albedo(),
        ClosureKind::Transparent { .. } => return None,
    };
    Some(c.weight * color)
}

#[inline]
fn put(acc: &mut [f32], at: usize, v: &[f32], overwrite: bool) {
    for (a, x) in acc[at..at + v.len()].iter_mut().zip(v) {
        if overwrite {
            *a = *x;
        } else {
            *a += *x;
        }
    }
}

impl DataContext<'_> {
    /// Adds the passes of the camera ray `o + t d` (unit `d`, `t < tmax`) into the pixel's
    /// record `acc` (laid out by `self.passes`); `first` is the pixel's first sample, which
    /// alone writes [`Pass::first_sample_only`] passes.
    pub fn add_sample(&self, ctx: &mut Ctx, o: Vec3, d: Vec3, first: bool, acc: &mut [f32]) {
        let (scene, set) = (self.scene, self.passes);
        let saved = (ctx.depth, ctx.ray_flags);
        ctx.depth = 1;
        ctx.ray_flags = ray::CAMERA;
        let mut tr = Vec3::ONE;
        let mut p = o;
        let mut data_done = false;
        let mut emission = Vec3::ZERO;
        let mut mist = 0.0f32;
        let want_emission = set.contains(Pass::Emission);
        // Cycles writes the Color passes at every surface the camera ray passes through
        // until it first scatters, weighted by the transparency in front.
        let want_colors = LightClass::ALL
            .into_iter()
            .any(|c| set.contains(c.passes().2));
        // As many transparent surfaces as the camera path passes (the integrator's limit).
        for _ in 0..=ctx.transparent_max.max(1) {
            let hit = scene.trace(ctx, p, d, 1);
            if want_emission {
                let tmax = hit.as_ref().map_or(f32::INFINITY, |h| h.t);
                emission += tr * scene.lights_on_ray(ctx, p, d, tmax, 1, f32::INFINITY, false);
            }
            let Some(its) = hit else {
                let env = set.offset(Pass::Environment);
                // The denoiser's albedo is the world's radiance where the camera sees it
                // (Cycles adds emission and background to the feature before any surface
                // wrote it), so a sky is not a black hole in its guide.
                let albedo = set.offset(Pass::DenoisingAlbedo).filter(|_| !data_done);
                if env.is_some() || albedo.is_some() {
                    let le = tr * scene.world_radiance(d, o);
                    for at in env.into_iter().chain(albedo) {
                        put(acc, at, &le.to_array(), false);
                    }
                }
                break;
            };
            let want_albedo = !data_done && set.contains(Pass::DenoisingAlbedo);
            if (want_emission || want_albedo)
                && let Some((_, le, _)) = scene.emitted(
                    &its,
                    o,
                    crate::shading::globals::ray::CAMERA,
                    (1, Default::default()),
                    0,
                )
            {
                if want_emission {
                    emission += tr * le;
                }
                if let Some(at) = set.offset(Pass::DenoisingAlbedo).filter(|_| want_albedo) {
                    put(acc, at, &(tr * le).to_array(), false);
                }
            }
            let program = &scene.programs[its.material as usize];
            let backfacing = its.ng.dot(d) > 0.0;
            let default_n = if backfacing { -its.ns } else { its.ns };
            let closures = match program.constant_set() {
                Some(c) => c,
                None => {
                    let g = scene.globals(&its, d, 1, ray::CAMERA);
                    program.eval(&g, &scene.shade_env(), &mut ctx.shade)
                }
            };
            let mut transparent = Vec3::ZERO;
            let (mut n_avg, mut n_feature, mut albedo) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
            let mut colors = [Vec3::ZERO; 3];
            for c in closures.closures() {
                let n = if c.normal == Vec3::ZERO {
                    default_n
                } else {
                    c.normal
                };
                if want_colors {
                    let k = closure_colors(c, n.dot(-d), backfacing);
                    for (a, b) in colors.iter_mut().zip(k) {
                        *a += tr * b;
                    }
                }
                match closure_albedo(c) {
                    None => transparent += c.weight,
                    Some(a) => {
                        let w = (c.weight.x + c.weight.y + c.weight.z) / 3.0;
                        n_avg += n * w;
                        n_feature += n * ((a.x + a.y + a.z) / 3.0);
                        albedo += a;
                    }
                }
            }
            if want_colors {
                for (class, v) in LightClass::ALL.into_iter().zip(colors) {
                    if let Some(at) = set.offset(class.passes().2) {
                        put(acc, at, &v.to_array(), false);
                    }
                }
            }
            let alpha = 1.0 - ((transparent.x + transparent.y + transparent.z) / 3.0).min(1.0);
            if set.contains(Pass::Mist) {
                let m = self.mist.amount(self.camera.mist_distance(its.p));
                mist += (1.0 - m) * alpha * (tr.x + tr.y + tr.z) / 3.0;
            }
            if !data_done && alpha >= 0.5 {
                data_done = true;
                let n_avg = n_avg.try_normalize().unwrap_or(default_n);
                let n_feature = n_feature.try_normalize().unwrap_or(n_avg);
                self.write_surface(&its, n_avg, n_feature, albedo * tr, first, acc);
            }
            tr *= transparent;
            if tr.max_element() <= 0.0 {
                break;
            }
            p = offset_origin(its.p, its.ng, d);
        }
        if let Some(at) = set.offset(Pass::Emission) {
            put(acc, at, &emission.to_array(), false);
        }
        if let Some(at) = set.offset(Pass::Mist) {
            acc[at] += mist;
        }
        (ctx.depth, ctx.ray_flags) = saved;
    }

    /// Adds one sample's light passes (radiance, divided by colour only when resolved).
    pub fn add_light(&self, split: &LightSplit, acc: &mut [f32]) {
        for class in LightClass::ALL {
            let (direct, indirect, _) = class.passes();
            let i = class as usize;
            for (p, v) in [(direct, split.direct[i]), (indirect, split.indirect[i])] {
                if let Some(at) = self.passes.offset(p) {
                    put(acc, at, &v.to_array(), false);
                }
            }
        }
    }

    /// The data passes of the first (opaque enough) surface.
    fn write_surface(
        &self,
        its: &crate::render_scene::Intersection,
        n_avg: Vec3,
        n_feature: Vec3,
        albedo: Vec3,
        first: bool,
        acc: &mut [f32],
    ) {
        let scene = self.scene;
        let mesh = &scene.scene.meshes[its.mesh as usize];
        for (pass, at) in self.passes.iter() {
            if pass.first_sample_only() && !first {
                continue;
            }
            match pass {
                Pass::Depth => acc[at] = self.camera.z_depth(its.p),
                Pass::Position => put(acc, at, &to_blender(its.p).to_array(), true),
                Pass::ObjectIndex => acc[at] = mesh.attrs.object.pass_index,
                Pass::MaterialIndex => {
                    acc[at] = scene.scene.materials[its.material as usize].pass_index as f32
                }
                Pass::Normal => put(acc, at, &to_blender(n_avg).to_array(), false),
                Pass::Uv => {
                    let uv = if mesh.uvs.is_empty() {
                        [0.0; 3]
                    } else {
                        [its.uv.x, 1.0 - its.uv.y, 1.0]
                    };
                    put(acc, at, &uv, false)
                }
                Pass::DenoisingNormal => put(
                    acc,
                    at,
                    &self.camera.to_camera_direction(n_feature).to_array(),
                    false,
                ),
                Pass::DenoisingAlbedo => put(acc, at, &albedo.to_array(), false),
                _ => {}
            }
        }
    }
}

/// Cycles' `safe_divide_even_color`: `a / b` per channel, and where a channel of `b` is 0,
/// the mean of the other channels' quotients (grey rather than black).
pub fn divide_even_color(a: Vec3, b: Vec3) -> Vec3 {
    let q = |a: f32, b: f32| if b != 0.0 { a / b } else { 0.0 };
    let (mut x, mut y, mut z) = (q(a.x, b.x), q(a.y, b.y), q(a.z, b.z));
    match (b.x == 0.0, b.y == 0.0, b.z == 0.0) {
        (true, true, _) => (x, y) = (z, z),
        (true, false, true) => (x, z) = (y, y),
        (true, false, false) => x = 0.5 * (y + z),
        (false, true, true) => (y, z) = (x, x),
        (false, true, false) => y = 0.5 * (x + z),
        (false, false, true) => z = 0.5 * (x + y),
        (false, false, false) => {}
    }
    Vec3::new(x, y, z)
}

/// Turns a pixel's accumulated record `acc` (laid out by `acc_set`, which holds every pass of
/// `out_set` and the Color passes its light passes need: [`PassSet::with_dividers`]) into the
/// values of `out_set`'s passes in `out`: averages over `n` samples, light passes divided by
/// their colour, and Blender's conventions for what was never written (Depth 1e10 where the
/// camera saw no surface; Mist stored as `1 - value`). Noisy Image is left to the caller.
pub fn resolve(acc_set: &PassSet, acc: &[f32], n: u32, out_set: &PassSet, out: &mut [f32]) {
    let inv = if n > 0 { 1.0 / n as f32 } else { 0.0 };
    let rgb = |at: usize| Vec3::new(acc[at], acc[at + 1], acc[at + 2]);
    for (pass, to) in out_set.iter() {
        let Some(at) = acc_set.offset(pass) else {
            continue;
        };
        if matches!(pass, Pass::ShadowCatcher | Pass::CatcherSums) {
            // Formed with Combined ([`super::resolve_pixel`]).
            continue;
        }
        if let Some((class, _)) = pass.light() {
            // Σ radiance / Σ colour: the sample counts cancel.
            let col = acc_set.offset(class.passes().2).map_or(Vec3::ZERO, rgb);
            let v = divide_even_color(rgb(at), col);
            out[to..to + 3].copy_from_slice(&v.to_array());
            continue;
        }
        let k = pass.channels();
        for c in 0..k {
            let v = acc[at + c];
            out[to + c] = match pass {
                Pass::Depth => {
                    if v == 0.0 {
                        1e10
                    } else {
                        v
                    }
                }
                Pass::Mist => 1.0 - v * inv,
                p if p.first_sample_only() => v,
                _ => v * inv,
            };
        }
    }
}
