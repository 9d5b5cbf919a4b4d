//! Debug views: shading normals mapped to colours (`n · 0.5 + 0.5`) and surface albedo
//! (base colour after textures) at the first hit; black where the ray escapes.

use super::Integrator;
use crate::render_scene::{Ctx, RenderScene};
use glam::Vec3;

pub struct Normals;

pub struct Albedo;

impl Integrator for Normals {
    fn li(&self, scene: &RenderScene, ctx: &mut Ctx, o: Vec3, d: Vec3) -> Vec3 {
        match scene.trace(ctx, o, d, 1) {
            Some(its) => its.ns * 0.5 + Vec3::splat(0.5),
            None => Vec3::ZERO,
        }
    }
}

impl Integrator for Albedo {
    fn li(&self, scene: &RenderScene, ctx: &mut Ctx, o: Vec3, d: Vec3) -> Vec3 {
        match scene.trace(ctx, o, d, 1) {
            Some(its) => scene.albedo(ctx, &its, d),
            None => Vec3::ZERO,
        }
    }
}
