//! From a shading closure to the BSDF that renders it.

use super::microfacet::anisotropy;
use super::sheen::Sheen;
use super::{
    BaseLobe, BsdfInstance, Coat, DELTA_ALPHA, Dielectric, Diffuse, Layered, Mirror, Plastic,
    RoughConductor, RoughDielectric, SurfaceParams, TopLobe, Translucent, Transparent, choose,
    principled_specular_ior,
};
use crate::shading::{Closure, ClosureKind, Principled};
use glam::Vec3;

/// The shading normal a specular lobe uses in place of a normal- or bump-mapped `n` (unit,
/// viewer's side), as Cycles' `ensure_valid_specular_reflection`: `n` itself when the mirror
/// direction `r = 2 (n·wi) n - wi` of the unit direction `wi` towards the viewer stays at
/// least `t = min(0.9 (wi·ng), 0.01)` above the geometric surface (`r·ng ≥ t`, `ng` unit on the
/// viewer's side); else `n` turned towards `ng` in their common plane just enough that
/// `r·ng = t` (the root of `4a z⁴ - 2b z² + c = 0` for `z = n'·ng`, with `a = x² + wz²`,
/// `b = 2 (a + wz t)`, `c = (wz + t)²`, `x`, `wz` the components of `wi` along the tangent of
/// that plane and along `ng`).
pub fn valid_specular_normal(ng: Vec3, wi: Vec3, n: Vec3) -> Vec3 {
    let r = 2.0 * n.dot(wi) * n - wi;
    let wz = wi.dot(ng);
    let t = (0.9 * wz).min(0.01);
    if r.dot(ng) >= t {
        return n;
    }
    let x = (n - n.dot(ng) * ng).try_normalize().unwrap_or(n);
    let wx = wi.dot(x);
    let a = wx * wx + wz * wz;
    if a <= 0.0 {
        return n;
    }
    let b = 2.0 * (a + wz * t);
    let c = (t + wz) * (t + wz);
    let disc = (b * b - 4.0 * a * c).max(0.0).sqrt();
    // The root for which the unsquared equation holds (its two sides share wx's sign).
    let z2 = if wx < 0.0 { b + disc } else { b - disc } * 0.25 / a;
    let (nx, nz) = ((1.0 - z2).max(0.0).sqrt(), z2.max(0.0).sqrt());
    (nx * x + nz * ng).normalize()
}

/// The BSDF of closure `c` (its weight is applied by the caller); `u` in `[0, 1)` chooses
/// between the lobes of a layered closure such as the Principled BSDF. Anisotropic lobes
/// take local +X as their tangent: the caller builds the frame from [`Closure::tangent`].
#[inline]
pub fn from_closure(c: &Closure, u: f32) -> BsdfInstance {
    match &c.kind {
        ClosureKind::Principled(p) if !p.cycles => choose(
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
        ClosureKind::Principled(p) => principled(p, u),
        ClosureKind::Diffuse { color } => BsdfInstance::Diffuse(Diffuse::new(*color)),
        ClosureKind::Glossy {
            color,
            roughness,
            anisotropy: a,
            multiscatter,
            ..
        } => {
            let (ax, ay) = anisotropy::glossy(*roughness, *a);
            // Blender's Glossy BSDF has no Fresnel; its colour is in the closure's weight.
            if ax.max(ay) < DELTA_ALPHA {
                BsdfInstance::Mirror(Mirror::new(*color))
            } else {
                let l = RoughConductor::glossy(*color, ax, ay);
                BsdfInstance::RoughConductor(if *multiscatter { l.multiscatter() } else { l })
            }
        }
        ClosureKind::Glass {
            color,
            roughness,
            ior,
            multiscatter,
        } => {
            let alpha = roughness * roughness;
            if alpha < DELTA_ALPHA {
                // The colour tints every path through the glass once (the closure weight).
                let _ = color;
                BsdfInstance::Dielectric(Dielectric::new(*ior, Vec3::ONE))
            } else {
                let l = RoughDielectric::glass(Vec3::ONE, *ior, alpha);
                BsdfInstance::RoughDielectric(if *multiscatter { l.multiscatter() } else { l })
            }
        }
        ClosureKind::Refraction {
            color,
            roughness,
            ior,
        } => {
            let _ = color;
            let alpha = (roughness * roughness).max(DELTA_ALPHA);
            BsdfInstance::RoughDielectric(RoughDielectric::refraction(Vec3::ONE, *ior, alpha))
        }
        ClosureKind::Translucent { color } => BsdfInstance::Translucent(Translucent::new(*color)),
        ClosureKind::Transparent { color } => BsdfInstance::Transparent(Transparent::new(*color)),
        // Where it is not walked, subsurface scattering is diffuse (the colour is the weight).
        ClosureKind::Subsurface { .. } => BsdfInstance::Diffuse(Diffuse::new(Vec3::ONE)),
    }
}

/// [`from_closure`] for a ray that left a diffuse bounce with some caustics switched off
/// (`off`: [`crate::integrator::light_paths::caustics`] bits), as Cycles' closure setup leaves
/// them out: without reflective caustics no Glossy, no Principled metal, specular layer or
/// coat; without refractive ones no Refraction and no Principled transmission; a Glass without
/// either is left out (with one of them it stays whole: an approximation). `None`: nothing of
/// the closure is left.
pub fn from_closure_without_caustics(c: &Closure, u: f32, off: u8) -> Option<BsdfInstance> {
    use crate::integrator::light_paths::caustics::{NO_REFLECTIVE, NO_REFRACTIVE};
    let (refl, refr) = (off & NO_REFLECTIVE != 0, off & NO_REFRACTIVE != 0);
    match &c.kind {
        ClosureKind::Glossy { .. } if refl => None,
        ClosureKind::Refraction { .. } if refr => None,
        ClosureKind::Glass { .. } if refl && refr => None,
        // Cycles keeps the glass's reflection.
        ClosureKind::Glass { roughness, ior, .. } if refr => {
            let alpha = roughness * roughness;
            Some(BsdfInstance::RoughDielectric(RoughDielectric::reflection(
                Vec3::ONE,
                *ior,
                alpha,
                alpha,
            )))
        }
        ClosureKind::Principled(p) if p.cycles => {
            let mut q = *p;
            if refl {
                q.specular_level = 0.0;
                q.coat_weight = 0.0;
            }
            let black = Some(BsdfInstance::Diffuse(Diffuse::new(Vec3::ZERO)));
            // The lobe choice of `principled`, with the left-out lobes black.
            let metallic = q.metallic.clamp(0.0, 1.0);
            let transmission = q.transmission.clamp(0.0, 1.0) * (1.0 - metallic);
            if u < transmission {
                if refr {
                    // Cycles keeps the transmission lobe's reflection (a refraction-less glass).
                    let alpha = q.roughness.clamp(0.0, 1.0).powi(2);
                    return Some(BsdfInstance::RoughDielectric(
                        RoughDielectric::principled_specular(q.specular_tint, q.ior, alpha, alpha)
                            .multiscatter(),
                    ));
                }
            } else {
                let u2 = if transmission > 0.0 {
                    (u - transmission) / (1.0 - transmission)
                } else {
                    u
                };
                if refl && u2 < metallic {
                    return black;
                }
            }
            Some(principled(&q, u))
        }
        _ => Some(from_closure(c, u)),
    }
}

/// Blender's Principled BSDF (4.x/5.x): one of transmission, metal or the dielectric base is
/// chosen with probability equal to its mixture weight; coat and sheen are layered on top.
/// The dielectric base's diffuse keeps `1 - subsurface_weight` of the base colour: the rest
/// is the subsurface closure's, which the caller walks (or sets to zero to render as diffuse).
fn principled(p: &Principled, u: f32) -> BsdfInstance {
    let diffuse = if p.subsurface_weight > 0.0 {
        p.base_color * (1.0 - p.subsurface_weight.min(1.0))
    } else {
        p.base_color
    };
    let r = p.roughness.clamp(0.0, 1.0);
    let alpha = r * r;
    let (ax, ay) = anisotropy::principled(r, p.anisotropic);
    let metallic = p.metallic.clamp(0.0, 1.0);
    let transmission = p.transmission.clamp(0.0, 1.0) * (1.0 - metallic);
    let base = if u < transmission {
        if alpha < DELTA_ALPHA {
            BaseLobe::Dielectric(Dielectric::new(p.ior, p.base_color))
        } else {
            BaseLobe::RoughDielectric(
                RoughDielectric::principled_transmission(
                    p.base_color,
                    p.specular_tint,
                    p.ior,
                    alpha,
                )
                .multiscatter(),
            )
        }
    } else {
        let u2 = if transmission > 0.0 {
            (u - transmission) / (1.0 - transmission)
        } else {
            u
        };
        if u2 < metallic {
            if ax.max(ay) < DELTA_ALPHA {
                BaseLobe::Mirror(Mirror::new(p.base_color))
            } else {
                BaseLobe::RoughConductor(
                    RoughConductor::f82(p.base_color, p.specular_tint, ax, ay).multiscatter(),
                )
            }
        } else if p.specular_level * p.specular_tint.max_element() <= 0.0 {
            BaseLobe::Diffuse(Diffuse::new(diffuse))
        } else if ax.max(ay) < DELTA_ALPHA {
            BaseLobe::Plastic(Plastic::new(
                diffuse,
                alpha,
                p.ior,
                2.0 * p.specular_level,
                p.specular_tint,
            ))
        } else {
            // Cycles: a GGX reflection with the Fresnel of the level-adjusted IOR over the
            // diffuse base, which keeps what the specular layer's albedo leaves.
            let ior = principled_specular_ior(p.ior, p.specular_level);
            let specular = RoughDielectric::principled_specular(p.specular_tint, ior, ax, ay);
            BaseLobe::SpecularDiffuse(Layered::new(specular.multiscatter(), Diffuse::new(diffuse)))
        }
    };
    let coat = (p.coat_weight > 0.0)
        .then(|| Coat::new(p.coat_weight, p.coat_roughness, p.coat_ior, p.coat_tint));
    let sheen = (p.sheen_weight > 0.0 && p.sheen_tint.max_element() > 0.0)
        .then(|| Sheen::new(p.sheen_tint * p.sheen_weight, p.sheen_roughness));
    match (coat, sheen) {
        (None, None) => unlayered(base),
        (Some(c), None) => BsdfInstance::Layered(Layered::new(TopLobe::Coat(c), base)),
        (None, Some(s)) => BsdfInstance::Layered(Layered::new(TopLobe::Sheen(s), base)),
        (Some(c), Some(s)) => {
            // Sheen over coat over the base, where the enum can hold it; else the coat.
            let inner = match base {
                BaseLobe::Diffuse(d) => Some(BaseLobe::CoatedDiffuse(Layered::new(c, d))),
                BaseLobe::RoughConductor(m) => Some(BaseLobe::CoatedConductor(Layered::new(c, m))),
                _ => None,
            };
            match inner {
                Some(b) => BsdfInstance::Layered(Layered::new(TopLobe::Sheen(s), b)),
                None => BsdfInstance::Layered(Layered::new(TopLobe::Coat(c), base)),
            }
        }
    }
}

/// `A(wi)`: the share of light arriving from the local direction `wi` (above the closure's
/// normal) that the Principled BSDF's layers above its dielectric base — specular, coat and
/// sheen — pass down to it, per channel: the factor on the subsurface closure, as Cycles'
/// albedo scaling applies it to every closure below a layer. A smooth specular layer is
/// taken at the least roughness the rough one has.
pub fn principled_base_attenuation(p: &Principled, wi: Vec3) -> Vec3 {
    use super::layered::Layer;
    let r = p.roughness.clamp(0.0, 1.0);
    let (ax, ay) = anisotropy::principled(r, p.anisotropic);
    let mut att = Vec3::ONE;
    if p.specular_level * p.specular_tint.max_element() > 0.0 {
        let ior = principled_specular_ior(p.ior, p.specular_level);
        let (ax, ay) = (ax.max(DELTA_ALPHA), ay.max(DELTA_ALPHA));
        let specular = RoughDielectric::principled_specular(p.specular_tint, ior, ax, ay);
        att *= Layer::attenuation(&specular.multiscatter(), wi);
    }
    if p.coat_weight > 0.0 {
        let coat = Coat::new(p.coat_weight, p.coat_roughness, p.coat_ior, p.coat_tint);
        att *= coat.attenuation(wi);
    }
    if p.sheen_weight > 0.0 && p.sheen_tint.max_element() > 0.0 {
        att *= Sheen::new(p.sheen_tint * p.sheen_weight, p.sheen_roughness).attenuation(wi);
    }
    att
}

fn unlayered(b: BaseLobe) -> BsdfInstance {
    match b {
        BaseLobe::Diffuse(x) => BsdfInstance::Diffuse(x),
        BaseLobe::Mirror(x) => BsdfInstance::Mirror(x),
        BaseLobe::Dielectric(x) => BsdfInstance::Dielectric(x),
        BaseLobe::RoughConductor(x) => BsdfInstance::RoughConductor(x),
        BaseLobe::Plastic(x) => BsdfInstance::Plastic(x),
        BaseLobe::RoughDielectric(x) => BsdfInstance::RoughDielectric(x),
        BaseLobe::Translucent(x) => BsdfInstance::Translucent(x),
        BaseLobe::SpecularDiffuse(l) => BsdfInstance::Layered(Layered::new(
            TopLobe::Specular(l.top),
            BaseLobe::Diffuse(l.base),
        )),
        other => BsdfInstance::Layered(Layered::new(
            TopLobe::Sheen(Sheen::new(Vec3::ZERO, 0.5)),
            other,
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::valid_specular_normal;
    use crate::sampler::Sampler;
    use crate::sampling::square_to_uniform_sphere;

    /// Over random geometric normals, view directions above the surface and shading normals on
    /// the viewer's side: the result is a unit vector in the plane of `n` and `ng`, the mirror
    /// direction stays above the threshold, valid normals are kept, and corrected ones lift
    /// the mirror direction exactly to the threshold (the least turn).
    #[test]
    fn specular_normals_reflect_above_the_surface_with_the_least_turn() {
        let mut rng = Sampler::new(11, 0, 0);
        let (mut kept, mut turned) = (0, 0);
        for _ in 0..20_000 {
            let ng = square_to_uniform_sphere(rng.next_2d());
            let mut wi = square_to_uniform_sphere(rng.next_2d());
            if wi.dot(ng) < 0.0 {
                wi = -wi;
            }
            let mut n = square_to_uniform_sphere(rng.next_2d());
            if n.dot(ng) < 0.05 {
                n = (n + ng * (0.05 - n.dot(ng) + 0.2)).normalize();
            }
            let wz = wi.dot(ng);
            if wz < 1e-3 {
                continue;
            }
            let t = (0.9 * wz).min(0.01);
            let v = valid_specular_normal(ng, wi, n);
            assert!((v.length() - 1.0).abs() < 1e-4, "{v}");
            let rz = (2.0 * v.dot(wi) * v - wi).dot(ng);
            let before = (2.0 * n.dot(wi) * n - wi).dot(ng);
            if before >= t {
                assert_eq!(v, n);
                kept += 1;
            } else {
                assert!(
                    (rz - t).abs() < 2e-3,
                    "r.ng {rz} vs {t} (n {n}, wi {wi}, ng {ng})"
                );
                // In the plane of n and ng, turned towards ng.
                assert!(v.dot(n.cross(ng)).abs() < 1e-3, "{v} {n} {ng}");
                assert!(v.dot(ng) > n.dot(ng) - 1e-5);
                turned += 1;
            }
        }
        assert!(kept > 1000 && turned > 1000, "{kept} kept, {turned} turned");
    }
}
