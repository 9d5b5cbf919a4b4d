//! The auxiliary passes of one camera sample: what the camera ray meets first (Cycles' data
//! passes and denoising features), the emission and the world it sees directly.
//!
//! The camera ray is traced again, deterministically (no random numbers: the integrator's
//! streams are untouched, so Combined is the same with or without passes), through
//! transparent surfaces as Cycles' camera paths go: the data passes come from the first
//! surface whose alpha reaches 1/2 (Cycles' alpha threshold), the light passes add up along
//! the way, weighted by the transmittance in front.

use super::pass::{Pass, PassSet};
use crate::accel::offset_origin;
use crate::camera::RayCamera;
use crate::integrator::MAX_TRANSPARENT;
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
        ClosureKind::Diffuse { color }
        | ClosureKind::Glossy { color, .. }
        | ClosureKind::Glass { color, .. }
        | ClosureKind::Refraction { color, .. }
        | ClosureKind::Translucent { color } => color,
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
        for _ in 0..=MAX_TRANSPARENT {
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
                && let Some((_, le, _)) = scene.emitted(&its, o)
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
            for c in closures.closures() {
                let n = if c.normal == Vec3::ZERO {
                    default_n
                } else {
                    c.normal
                };
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
                Pass::Mist | Pass::Emission | Pass::Environment => {}
            }
        }
    }
}

/// Turns a pixel's accumulated record into pass values: averages over `n` samples, and
/// Blender's conventions for what was never written (Depth 1e10 where the camera saw no
/// surface; Mist stored as `1 - value`).
pub fn resolve(set: &PassSet, acc: &[f32], n: u32, out: &mut [f32]) {
    let inv = if n > 0 { 1.0 / n as f32 } else { 0.0 };
    for (pass, at) in set.iter() {
        let k = pass.channels();
        for c in 0..k {
            let v = acc[at + c];
            out[at + c] = match pass {
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
