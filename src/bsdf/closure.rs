//! From a shading closure to the BSDF that renders it.

use super::microfacet::{ConductorFresnel, anisotropy};
use super::sheen::Sheen;
use super::{
    BaseLobe, BsdfInstance, Coat, DELTA_ALPHA, Dielectric, Diffuse, Layered, Mirror, Plastic,
    RoughConductor, RoughDielectric, SurfaceParams, Toon, TopLobe, Translucent, Transparent,
    choose, principled_specular_ior,
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
    build(c, u, 0.0)
}

/// `alpha` raised to at least `blur`, as Cycles' `bsdf_microfacet_blur` raises each of a
/// microfacet closure's GGX alphas (`alpha = max(blur, alpha)`, in alpha = roughness², not
/// in Blender's roughness); `blur <= 0` leaves it untouched.
#[inline]
fn blurred(alpha: f32, blur: f32) -> f32 {
    if blur > 0.0 { alpha.max(blur) } else { alpha }
}

/// Blender's roughness `r` (alpha = r²) raised so that its alpha is at least `blur`.
#[inline]
fn blurred_roughness(r: f32, blur: f32) -> f32 {
    if blur > 0.0 { r.max(blur.sqrt()) } else { r }
}

/// [`from_closure`] with Cycles' Filter Glossy: every microfacet lobe (Glossy, Glass,
/// Refraction; Principled's metal, specular, transmission and coat) has its GGX alphas raised
/// to at least `blur` (0: none). A smooth lobe so raised becomes the rough one, as Cycles'
/// near-zero-alpha GGX closure does; diffuse, translucent, sheen and transparent closures
/// stay. Cycles finds a lobe's energy compensation (and a layer's albedo) when it sets the
/// closure up, before the blur: they keep the lobe's own roughness, and a lobe that was smooth
/// gets no compensation.
// Out of line: inlined, it would weigh on every shading point without the filter.
#[inline(never)]
pub fn from_closure_blurred(c: &Closure, u: f32, blur: f32) -> BsdfInstance {
    build(c, u, blur)
}

/// [`from_closure_blurred`], inlined into [`from_closure`] with no blur to fold away.
#[inline(always)]
fn build(c: &Closure, u: f32, blur: f32) -> BsdfInstance {
    match &c.kind {
        ClosureKind::Principled(p) if !p.cycles => choose(
            &SurfaceParams {
                base_color: p.base_color,
                metallic: p.metallic,
                roughness: blurred_roughness(p.roughness, blur),
                transmission: p.transmission,
                ior: p.ior,
                specular: 2.0 * p.specular_level,
                specular_color: p.specular_tint,
            },
            u,
        ),
        ClosureKind::Principled(p) => principled(p, u, blur),
        ClosureKind::Diffuse {
            color,
            roughness,
            albedo,
        } => BsdfInstance::Diffuse(Diffuse::oren_nayar(*color, *roughness, *albedo)),
        ClosureKind::Glossy {
            color,
            roughness,
            anisotropy: a,
            multiscatter,
            beckmann,
            tint,
            ..
        } => {
            let (ax, ay) = anisotropy::glossy(*roughness, *a);
            let (bx, by) = (blurred(ax, blur), blurred(ay, blur));
            // Blender's Glossy BSDF has no Fresnel; its colour is in the closure's weight.
            if bx.max(by) < DELTA_ALPHA {
                BsdfInstance::Mirror(Mirror::with_fresnel(ConductorFresnel::Constant(*color)))
            } else {
                let fresnel = if *color == Vec3::ONE {
                    ConductorFresnel::Weighted(*tint)
                } else {
                    ConductorFresnel::Constant(*color)
                };
                let l = RoughConductor::with(ax, ay, fresnel).with_beckmann(*beckmann);
                let ms = *multiscatter && ax.max(ay) >= DELTA_ALPHA;
                BsdfInstance::RoughConductor(if ms { l.multiscatter() } else { l }.blurred(blur))
            }
        }
        ClosureKind::Glass {
            color,
            roughness,
            ior,
            multiscatter,
            beckmann,
            tint,
        } => {
            let alpha = roughness * roughness;
            let b = blurred(alpha, blur);
            if b < DELTA_ALPHA {
                // The colour tints every path through the glass once (the closure weight).
                let _ = color;
                BsdfInstance::Dielectric(Dielectric::new(*ior, Vec3::ONE))
            } else {
                let l = RoughDielectric::glass(Vec3::ONE, *ior, alpha).with_beckmann(*beckmann);
                let ms = *multiscatter && alpha >= DELTA_ALPHA;
                let l = if ms {
                    l.multiscatter_with_fss(*tint)
                } else {
                    l
                };
                BsdfInstance::RoughDielectric(l.blurred(blur))
            }
        }
        ClosureKind::Refraction {
            color,
            roughness,
            ior,
            beckmann,
        } => {
            let _ = color;
            let alpha = (roughness * roughness).max(DELTA_ALPHA);
            BsdfInstance::RoughDielectric(
                RoughDielectric::refraction(Vec3::ONE, *ior, alpha)
                    .with_beckmann(*beckmann)
                    .blurred(blur),
            )
        }
        ClosureKind::Translucent { color } => BsdfInstance::Translucent(Translucent::new(*color)),
        // The offset across the fibre is set with the shading point's frame.
        ClosureKind::Hair(h) => {
            let lobe = h.lobe(0.0);
            BsdfInstance::ChiangHair(if blur > 0.0 { lobe.blurred(blur) } else { lobe })
        }
        ClosureKind::Toon {
            color,
            size,
            smooth,
            glossy,
        } => BsdfInstance::Toon(Toon::new(*color, *size, *smooth, *glossy)),
        ClosureKind::Transparent { color } => BsdfInstance::Transparent(Transparent::new(*color)),
        // Where it is not walked, subsurface scattering is diffuse (the colour is the weight).
        ClosureKind::Subsurface { .. } => BsdfInstance::Diffuse(Diffuse::new(Vec3::ONE)),
    }
}

/// [`from_closure_blurred`] for a ray that left a diffuse bounce with some caustics switched
/// off (`off`: [`crate::integrator::light_paths::caustics`] bits), as Cycles' closure setup
/// leaves them out: without reflective caustics no Glossy, no Principled metal, specular layer
/// or coat; without refractive ones no Refraction and no Principled transmission; a Glass
/// without either is left out (with one of them it stays whole: an approximation). `None`:
/// nothing of the closure is left.
pub fn from_closure_without_caustics(
    c: &Closure,
    u: f32,
    off: u8,
    blur: f32,
) -> Option<BsdfInstance> {
    use crate::integrator::light_paths::caustics::{NO_REFLECTIVE, NO_REFRACTIVE};
    let (refl, refr) = (off & NO_REFLECTIVE != 0, off & NO_REFRACTIVE != 0);
    match &c.kind {
        ClosureKind::Glossy { .. } if refl => None,
        ClosureKind::Refraction { .. } if refr => None,
        ClosureKind::Glass { .. } if refl && refr => None,
        // Cycles keeps the glass's reflection.
        ClosureKind::Glass {
            roughness,
            ior,
            beckmann,
            ..
        } if refr => {
            let alpha = roughness * roughness;
            Some(BsdfInstance::RoughDielectric(
                RoughDielectric::reflection(Vec3::ONE, *ior, alpha, alpha)
                    .with_beckmann(*beckmann)
                    .blurred(blur),
            ))
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
                            .with_thin_film(q.thin_film)
                            .multiscatter()
                            .blurred(blur),
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
            Some(principled(&q, u, blur))
        }
        _ => Some(from_closure_blurred(c, u, blur)),
    }
}

/// Blender's Principled BSDF (4.x/5.x): one of transmission, metal or the dielectric base is
/// chosen with probability equal to its mixture weight; coat and sheen are layered on top.
/// Microfacet alphas are raised to at least `blur` ([`from_closure_blurred`]).
// Always inlined: without the filter the blur folds away.
#[inline(always)]
fn principled(p: &Principled, u: f32, blur: f32) -> BsdfInstance {
    let diffuse = if p.subsurface_weight > 0.0 {
        p.base_color * (1.0 - p.subsurface_weight.min(1.0))
    } else {
        p.base_color
    };
    // Cycles' diffuse base: Oren–Nayar whose multiple scattering takes the base colour.
    let rough_diffuse =
        |albedo: Vec3| Diffuse::oren_nayar(albedo, p.diffuse_roughness, p.base_color);
    let r = p.roughness.clamp(0.0, 1.0);
    let alpha0 = r * r;
    let (ax0, ay0) = anisotropy::principled(r, p.anisotropic);
    let alpha = blurred(alpha0, blur);
    let (ax, ay) = (blurred(ax0, blur), blurred(ay0, blur));
    // Energy compensation as set up before the blur: none for a lobe that was smooth.
    let (ms, ms_aniso) = (
        p.multiscatter && alpha0 >= DELTA_ALPHA,
        p.multiscatter && ax0.max(ay0) >= DELTA_ALPHA,
    );
    let metallic = p.metallic.clamp(0.0, 1.0);
    let transmission = p.transmission.clamp(0.0, 1.0) * (1.0 - metallic);
    let base = if u < transmission {
        if alpha < DELTA_ALPHA {
            BaseLobe::Dielectric(
                Dielectric::new(p.ior, p.base_color).with_thin_film(p.thin_film, p.specular_tint),
            )
        } else {
            let l = RoughDielectric::principled_transmission(
                p.base_color,
                p.specular_tint,
                p.ior,
                alpha0,
            )
            .with_thin_film(p.thin_film);
            BaseLobe::RoughDielectric(if ms { l.multiscatter() } else { l }.blurred(blur))
        }
    } else {
        let u2 = if transmission > 0.0 {
            (u - transmission) / (1.0 - transmission)
        } else {
            u
        };
        if u2 < metallic {
            if ax.max(ay) < DELTA_ALPHA {
                BaseLobe::Mirror(Mirror::with_fresnel(ConductorFresnel::f82_tint(
                    p.base_color,
                    p.specular_tint,
                )))
            } else {
                let l = RoughConductor::f82(p.base_color, p.specular_tint, ax0, ay0);
                BaseLobe::RoughConductor(if ms_aniso { l.multiscatter() } else { l }.blurred(blur))
            }
        } else if !principled_has_specular(p) {
            BaseLobe::Diffuse(rough_diffuse(diffuse))
        } else if ax.max(ay) < DELTA_ALPHA {
            BaseLobe::Plastic(
                Plastic::cycles(
                    diffuse,
                    alpha,
                    principled_specular_ior(p.ior, p.specular_level),
                    p.specular_tint,
                )
                .with_thin_film(p.thin_film),
            )
        } else {
            // Cycles: a GGX reflection with the Fresnel of the level-adjusted IOR over the
            // diffuse base, which keeps what the specular layer's albedo leaves.
            let ior = principled_specular_ior(p.ior, p.specular_level);
            let specular = RoughDielectric::principled_specular(p.specular_tint, ior, ax0, ay0)
                .with_thin_film(p.thin_film);
            let specular = if ms_aniso {
                specular.multiscatter()
            } else {
                specular
            };
            BaseLobe::SpecularDiffuse(Layered::new(specular.blurred(blur), rough_diffuse(diffuse)))
        }
    };
    let coat = (p.coat_weight > 0.0)
        .then(|| Coat::new(p.coat_weight, p.coat_roughness, p.coat_ior, p.coat_tint).blurred(blur));
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

/// Whether the Principled BSDF's dielectric base has its specular layer: as in Cycles, unless
/// the level-adjusted IOR is 1 (Specular IOR Level 0, or IOR 1) and there is no thin film. A
/// black Specular Tint keeps the layer: it scales `F0` only, and grazing reflection stays white.
#[inline]
pub fn principled_has_specular(p: &Principled) -> bool {
    principled_specular_ior(p.ior, p.specular_level) != 1.0 || p.thin_film.is_some()
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
    if principled_has_specular(p) {
        let ior = principled_specular_ior(p.ior, p.specular_level);
        let (ax, ay) = (ax.max(DELTA_ALPHA), ay.max(DELTA_ALPHA));
        let specular = RoughDielectric::principled_specular(p.specular_tint, ior, ax, ay)
            .with_thin_film(p.thin_film);
        let specular = if p.multiscatter {
            specular.multiscatter()
        } else {
            specular
        };
        att *= Layer::attenuation(&specular, wi);
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
    use super::{from_closure, from_closure_blurred, valid_specular_normal};
    use crate::bsdf::{BaseLobe, BsdfInstance, DielectricMode, Roughness, TopLobe};
    use crate::sampler::Sampler;
    use crate::sampling::square_to_uniform_sphere;
    use crate::shading::{Closure, ClosureKind, Principled};
    use glam::Vec3;

    fn closure(kind: ClosureKind) -> Closure {
        Closure {
            weight: Vec3::ONE,
            normal: Vec3::ZERO,
            tangent: Vec3::ZERO,
            surface_normal: Vec3::ZERO,
            kind,
        }
    }

    fn glossy(roughness: f32, anisotropy: f32) -> Closure {
        closure(ClosureKind::Glossy {
            beckmann: false,
            color: Vec3::ONE,
            roughness,
            anisotropy,
            rotation: 0.0,
            multiscatter: true,
            tint: Vec3::ONE,
        })
    }

    fn principled(metallic: f32, roughness: f32, coat_roughness: f32) -> Closure {
        closure(ClosureKind::Principled(Principled {
            base_color: Vec3::splat(0.8),
            metallic,
            roughness,
            specular_level: 0.5,
            coat_weight: 1.0,
            coat_roughness,
            ..Principled::lobe_only()
        }))
    }

    fn conductor(b: BsdfInstance) -> (Roughness, bool) {
        match b {
            BsdfInstance::RoughConductor(l) => (l.roughness, l.multiscatter),
            other => panic!("not a rough conductor: {other:?}"),
        }
    }

    /// Cycles' `bsdf_microfacet_blur`: each GGX alpha becomes `max(blur, alpha)`; a smooth
    /// lobe turns into the rough one without energy compensation, a lobe already rougher than
    /// the blur is left as it was, and non-microfacet closures are untouched.
    #[test]
    fn filter_glossy_raises_each_alpha_to_the_blur() {
        let b = 0.3;
        assert_eq!(
            conductor(from_closure_blurred(&glossy(0.0, 0.0), 0.5, b)),
            (Roughness::new(b, b), false),
            "a sharp Glossy"
        );
        // Roughness 0.8: alpha 0.64 > 0.3.
        let rough = glossy(0.8, 0.0);
        assert_eq!(
            format!("{:?}", from_closure_blurred(&rough, 0.5, b)),
            format!("{:?}", from_closure(&rough, 0.5))
        );
        // Roughness 0.4, anisotropy 0.5: alphas (0.08, 0.32); only the first is raised.
        let (ax, ay) = super::anisotropy::glossy(0.4, 0.5);
        assert!(ax < b && ay > b, "{ax} {ay}");
        let (r, ms) = conductor(from_closure_blurred(&glossy(0.4, 0.5), 0.5, b));
        assert_eq!((r.alpha_x, r.alpha_y, ms), (b, ay, true));
        // A rough lobe keeps the energy compensation of its own roughness (alpha 0.16).
        match from_closure_blurred(&glossy(0.4, 0.0), 0.5, b) {
            BsdfInstance::RoughConductor(l) => {
                assert_eq!(l.roughness, Roughness::new(b, b));
                assert_eq!(l.setup_roughness, Roughness::new(0.4 * 0.4, 0.4 * 0.4));
                assert!(l.multiscatter);
                let unblurred = match from_closure(&glossy(0.4, 0.0), 0.5) {
                    BsdfInstance::RoughConductor(u) => u,
                    other => panic!("{other:?}"),
                };
                let wi = Vec3::new(0.6, 0.0, 0.8);
                assert_eq!(l.energy_factor(wi), unblurred.energy_factor(wi));
            }
            other => panic!("{other:?}"),
        }
        let glass = closure(ClosureKind::Glass {
            beckmann: false,
            color: Vec3::ONE,
            roughness: 0.0,
            ior: 1.5,
            multiscatter: true,
            tint: Vec3::ONE,
        });
        match from_closure_blurred(&glass, 0.5, b) {
            BsdfInstance::RoughDielectric(l) => {
                assert_eq!(l.roughness, Roughness::new(b, b));
                assert_eq!(l.mode, DielectricMode::Glass);
                assert!(l.multiscatter_fss.is_none());
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            from_closure(&glass, 0.5),
            BsdfInstance::Dielectric(_)
        ));
        let refraction = closure(ClosureKind::Refraction {
            beckmann: false,
            color: Vec3::ONE,
            roughness: 0.1,
            ior: 1.5,
        });
        match from_closure_blurred(&refraction, 0.5, b) {
            BsdfInstance::RoughDielectric(l) => assert_eq!(l.roughness, Roughness::new(b, b)),
            other => panic!("{other:?}"),
        }
        let diffuse = closure(ClosureKind::lambert(Vec3::ONE));
        assert_eq!(
            format!("{:?}", from_closure_blurred(&diffuse, 0.5, b)),
            format!("{:?}", from_closure(&diffuse, 0.5))
        );
    }

    /// The Principled BSDF's metal and its coat are raised alike; the blur 0 builds exactly
    /// what [`from_closure`] builds.
    #[test]
    fn filter_glossy_blurs_principled_lobes_and_zero_is_no_blur() {
        let b = 0.25;
        let p = principled(1.0, 0.0, 0.0);
        let BsdfInstance::Layered(l) = from_closure_blurred(&p, 0.5, b) else {
            panic!("a coated metal is layered");
        };
        let TopLobe::Coat(coat) = l.top else {
            panic!("{:?}", l.top)
        };
        assert_eq!(coat.alpha, b);
        assert_eq!(coat.lobe().roughness, Roughness::new(b, b));
        // Its albedo over the metal is that of the smooth coat it was set up as.
        assert_eq!(coat.lobe().setup_roughness, Roughness::new(0.0, 0.0));
        match l.base {
            BaseLobe::RoughConductor(m) => {
                assert_eq!(m.roughness, Roughness::new(b, b));
                assert!(!m.multiscatter, "the smooth metal had no compensation");
            }
            other => panic!("{other:?}"),
        }
        for c in [
            p,
            principled(0.0, 0.0, 0.7),
            glossy(0.0, 0.0),
            glossy(0.3, -0.4),
        ] {
            for u in [0.1, 0.6] {
                assert_eq!(
                    format!("{:?}", from_closure_blurred(&c, u, 0.0)),
                    format!("{:?}", from_closure(&c, u))
                );
            }
        }
        // The dielectric Principled's smooth specular layer becomes a rough one over the base.
        let BsdfInstance::Layered(l) = from_closure_blurred(&principled(0.0, 0.0, 0.7), 0.5, b)
        else {
            panic!("coated");
        };
        match l.base {
            BaseLobe::SpecularDiffuse(s) => assert_eq!(s.top.roughness, Roughness::new(b, b)),
            other => panic!("{other:?}"),
        }
    }

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
