//! From a shading closure to the BSDF that renders it.

use super::{
    BsdfInstance, DELTA_ALPHA, Dielectric, Diffuse, Mirror, RoughConductor, SurfaceParams, choose,
};
use crate::shading::{Closure, ClosureKind};
use glam::Vec3;

/// The BSDF of closure `c` (its weight is applied by the caller); `u` in `[0, 1)` chooses
/// between the lobes of a layered closure such as the Principled BSDF.
#[inline]
pub fn from_closure(c: &Closure, u: f32) -> BsdfInstance {
    match c.kind {
        ClosureKind::Principled(p) => choose(
            &SurfaceParams {
                base_color: p.base_color,
                metallic: p.metallic,
                roughness: p.roughness,
                transmission: p.transmission,
                ior: p.ior,
                specular: 2.0 * p.specular_level,
                specular_color: p.specular_tint,
            },
            u,
        ),
        ClosureKind::Diffuse { color } => BsdfInstance::Diffuse(Diffuse::new(color)),
        ClosureKind::Glossy {
            color, roughness, ..
        } => {
            let alpha = (roughness * roughness).clamp(0.0, 1.0);
            // Blender's Glossy BSDF has no Fresnel: a conductor whose F0 is white reflects
            // the same at every angle; the colour is in the closure's weight.
            if alpha < DELTA_ALPHA {
                BsdfInstance::Mirror(Mirror::new(color))
            } else {
                BsdfInstance::RoughConductor(RoughConductor::new(color, alpha))
            }
        }
        ClosureKind::Glass { color, ior, .. } | ClosureKind::Refraction { color, ior, .. } => {
            // Glass tints every path through it by its colour once (the weight); the
            // dielectric's own per-refraction tint stays white.
            let _ = color;
            BsdfInstance::Dielectric(Dielectric::new(ior, Vec3::ONE))
        }
        // Until dedicated lobes exist: Lambertian reflection for translucency, and an
        // index-matched dielectric (which refracts straight through) for transparency.
        ClosureKind::Translucent { color } => BsdfInstance::Diffuse(Diffuse::new(color)),
        ClosureKind::Transparent { color } => {
            BsdfInstance::Dielectric(Dielectric::new(1.0, color * color))
        }
    }
}
