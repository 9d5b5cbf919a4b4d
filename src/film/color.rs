//! The Color light passes: a closure's albedo (what it reflects or transmits of a uniform
//! white surround) split by light class, Cycles' `surface_shader_diffuse/glossy/transmission`
//! over its `bsdf_albedo` estimates.

use super::LightClass;
use crate::bsdf::closure::principled_has_specular;
use crate::bsdf::fresnel;
use crate::bsdf::layered::{Coat, Layer};
use crate::bsdf::rough_dielectric::principled_specular_ior;
use crate::bsdf::tables::reflection_fresnel_s;
use crate::bsdf::{Plastic, Sheen};
use crate::shading::{Closure, ClosureKind, Principled};
use glam::Vec3;

/// `[diffuse, glossy, transmission]` albedo of closure `c` seen at cosine `mu` between its
/// normal and the direction towards the viewer; `backfacing` when the ray meets the back of
/// the surface (a glass lobe then refracts out of the denser side).
pub fn closure_colors(c: &Closure, mu: f32, backfacing: bool) -> [Vec3; 3] {
    let mu = mu.clamp(1e-4, 1.0);
    let mut out = [Vec3::ZERO; 3];
    let mut put = |class: LightClass, v: Vec3| out[class as usize] += c.weight * v;
    match c.kind {
        ClosureKind::Diffuse { color, .. } | ClosureKind::Translucent { color } => {
            put(LightClass::Diffuse, color)
        }
        // Cycles counts hair among its glossy closures; its albedo estimate across the fibre.
        ClosureKind::Hair(h) => put(LightClass::Glossy, h.hair_albedo()),
        ClosureKind::Toon { color, glossy, .. } => {
            let class = if glossy {
                LightClass::Glossy
            } else {
                LightClass::Diffuse
            };
            put(class, color)
        }
        // Blender's Glossy BSDF has no Fresnel: its colour is its albedo estimate.
        ClosureKind::Glossy { color, .. } => put(LightClass::Glossy, color),
        ClosureKind::Glass {
            color,
            roughness,
            ior,
            ..
        } => {
            // Cycles: generalized Schlick with the real IOR's F0 and the table's `s` for the
            // index seen from this side, both lobes tinted by the colour.
            let eta = if backfacing { 1.0 / ior } else { ior };
            let f0 = fresnel::f0_from_ior(ior);
            let f = f0 + (1.0 - f0) * reflection_fresnel_s(roughness * roughness, mu, eta);
            put(LightClass::Glossy, color * f);
            put(LightClass::Transmission, color * (1.0 - f));
        }
        ClosureKind::Refraction { color, .. } => put(LightClass::Transmission, color),
        ClosureKind::Principled(ref p) => {
            let [d, g, t] = principled_colors(p, mu, backfacing);
            put(LightClass::Diffuse, d);
            put(LightClass::Glossy, g);
            put(LightClass::Transmission, t);
        }
        // Cycles counts subsurface in the diffuse passes; its colour is in the weight.
        ClosureKind::Subsurface { .. } => put(LightClass::Diffuse, Vec3::ONE),
        ClosureKind::Transparent { .. } => {}
    }
    out
}

/// The Principled BSDF's lobes as Tesela layers them (see `bsdf::closure::principled`):
/// sheen (diffuse) over coat (glossy) over one of transmission (glass), metal (glossy) and
/// the dielectric base (specular glossy over diffuse), each below the attenuation of the
/// layers above it.
fn principled_colors(p: &Principled, mu: f32, backfacing: bool) -> [Vec3; 3] {
    let wi = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let (mut diffuse, mut glossy, mut transmission) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    let mut att = Vec3::ONE;
    if p.cycles && p.sheen_weight > 0.0 && p.sheen_tint.max_element() > 0.0 {
        let s = Sheen::new(p.sheen_tint * p.sheen_weight, p.sheen_roughness);
        diffuse += Layer::albedo(&s, wi);
        att *= Layer::attenuation(&s, wi);
    }
    if p.cycles && p.coat_weight > 0.0 {
        let c = Coat::new(p.coat_weight, p.coat_roughness, p.coat_ior, p.coat_tint);
        glossy += att * Layer::albedo(&c, wi);
        att *= c.attenuation(wi);
    }
    let r = p.roughness.clamp(0.0, 1.0);
    let metallic = p.metallic.clamp(0.0, 1.0);
    let t = p.transmission.clamp(0.0, 1.0) * (1.0 - metallic);
    let (metal, base) = ((1.0 - t) * metallic, (1.0 - t) * (1.0 - metallic));
    if t > 0.0 {
        let eta = if backfacing { 1.0 / p.ior } else { p.ior };
        let f0 = fresnel::f0_from_ior(p.ior);
        let f = f0 + (1.0 - f0) * reflection_fresnel_s(r * r, mu, eta);
        glossy += att * t * f;
        transmission += att * t * (1.0 - f) * p.base_color;
    }
    // Metals' F82 colour: the base colour at normal incidence.
    glossy += att * metal * p.base_color;
    if base > 0.0 {
        let pl = if p.cycles {
            Plastic::cycles(
                p.base_color,
                r * r,
                principled_specular_ior(p.ior, p.specular_level),
                p.specular_tint,
            )
        } else {
            Plastic::new(
                p.base_color,
                r * r,
                p.ior,
                2.0 * p.specular_level,
                p.specular_tint,
            )
        };
        let (f, s) = if principled_has_specular(p) {
            (pl.coat_fresnel(mu), pl.coat_share(mu))
        } else {
            (Vec3::ZERO, 0.0)
        };
        glossy += att * base * f;
        diffuse += att * base * (1.0 - s) * p.base_color;
    }
    [diffuse, glossy, transmission]
}
