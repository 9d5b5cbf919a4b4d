//! Shader nodes: BSDFs, emission, and the Mix/Add Shader nodes that weight them.

use crate::bsdf::thin_film::ThinFilm;
use crate::shading::closure::{Closure, ClosureKind, ClosureSet, Principled};
use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::{ShaderGlobals, from_blender};
use crate::shading::program::{Op, Slot, Slots};
use glam::Vec3;

/// Node types whose outputs are closures.
pub fn is_shader_node(kind: &str) -> bool {
    kind.starts_with("ShaderNodeBsdf")
        || matches!(
            kind,
            "ShaderNodeEmission"
                | "ShaderNodeMixShader"
                | "ShaderNodeAddShader"
                | "ShaderNodeHoldout"
                | "ShaderNodeBackground"
                | "ShaderNodeSubsurfaceScattering"
                | "ShaderNodeEeveeSpecular"
                | "ShaderNodeVolumeAbsorption"
                | "ShaderNodeVolumeScatter"
                | "ShaderNodeVolumePrincipled"
                | "ShaderNodeVolumeCoefficients"
                | "ShaderNodeGroup"
        )
}

/// Principled BSDF inputs as slots.
#[derive(Clone, Copy, Debug)]
pub struct PrincipledSlots {
    base: Slot,
    metallic: Slot,
    roughness: Slot,
    ior: Slot,
    alpha: Slot,
    normal: Option<Slot>,
    specular_level: Slot,
    specular_tint: Slot,
    transmission: Slot,
    anisotropic: Slot,
    anisotropic_rotation: Slot,
    tangent: Option<Slot>,
    coat_weight: Slot,
    coat_roughness: Slot,
    coat_ior: Slot,
    coat_tint: Slot,
    coat_normal: Option<Slot>,
    sheen_weight: Slot,
    sheen_roughness: Slot,
    sheen_tint: Slot,
    subsurface_weight: Slot,
    subsurface_radius: Slot,
    subsurface_scale: Slot,
    subsurface_anisotropy: Slot,
    diffuse_roughness: Slot,
    thin_film_thickness: Slot,
    thin_film_ior: Slot,
    emission_color: Slot,
    emission_strength: Slot,
    cycles: bool,
    multiscatter: bool,
    /// The emission may be on under a coat or sheen, which attenuate it by the view direction.
    layered_emission: bool,
    /// A sheen may lie over a coat: the sheen becomes a closure of its own, above the rest
    /// weighted by what it lets through for the view direction.
    sheen_over_coat: bool,
}

/// How a Metallic BSDF gives its reflectance.
#[derive(Clone, Copy, Debug)]
pub enum MetalFresnel {
    /// F82-tint: Base Color and Edge Tint.
    F82 { base: Slot, tint: Slot },
    /// A physical conductor: complex IOR `eta + i k` per channel.
    Physical { ior: Slot, extinction: Slot },
}

/// A closure node's inputs.
/// The inputs of a Principled Hair BSDF's colour parametrization.
#[derive(Clone, Copy, Debug)]
pub enum HairColorSlots {
    Absorption(Slot),
    Melanin {
        melanin: Slot,
        redness: Slot,
        tint: Slot,
    },
    Reflectance(Slot),
}

#[derive(Clone, Debug)]
pub enum ClosureParams {
    Principled(Box<PrincipledSlots>),
    /// Blender's Metallic BSDF: Cycles' F82 or physical conductor closure, which is the
    /// Principled BSDF's metallic lobe.
    Metallic {
        fresnel: MetalFresnel,
        /// Multiscatter GGX (else plain GGX).
        multiscatter: bool,
        roughness: Slot,
        anisotropy: Slot,
        rotation: Slot,
        normal: Option<Slot>,
        tangent: Option<Slot>,
    },
    /// Blender's Sheen BSDF (microfiber): the Principled BSDF's sheen lobe on its own.
    Sheen {
        color: Slot,
        roughness: Slot,
        normal: Option<Slot>,
    },
    Diffuse {
        color: Slot,
        roughness: Slot,
        normal: Option<Slot>,
    },
    Glossy {
        color: Slot,
        roughness: Slot,
        anisotropy: Slot,
        rotation: Slot,
        normal: Option<Slot>,
        tangent: Option<Slot>,
        multiscatter: bool,
        /// The Beckmann distribution (else GGX).
        beckmann: bool,
    },
    Glass {
        color: Slot,
        roughness: Slot,
        ior: Slot,
        normal: Option<Slot>,
        refraction_only: bool,
        multiscatter: bool,
        /// The Beckmann distribution (else GGX).
        beckmann: bool,
    },
    Translucent {
        color: Slot,
        normal: Option<Slot>,
    },
    Toon {
        color: Slot,
        size: Slot,
        smooth: Slot,
        normal: Option<Slot>,
        glossy: bool,
    },
    /// Principled Hair BSDF (Chiang); `color` holds the parametrization's inputs.
    Hair {
        color: HairColorSlots,
        roughness: Slot,
        radial_roughness: Slot,
        coat: Slot,
        ior: Slot,
        offset: Slot,
        random_color: Slot,
        random_roughness: Slot,
        /// The Random input, and whether it is linked (else the strand's own random number
        /// is used where there is one, as in Cycles).
        random: Slot,
        random_linked: bool,
    },
    Transparent {
        color: Slot,
    },
    /// The Ray Portal BSDF with its Position and Direction unlinked: camera and indirect rays
    /// go on through it, tinted, as through a Transparent BSDF; shadow rays stop there (Cycles'
    /// portals are opaque to shadow rays).
    Portal {
        color: Slot,
    },
    /// The Subsurface Scattering node.
    Subsurface {
        color: Slot,
        scale: Slot,
        radius: Slot,
        ior: Slot,
        roughness: Slot,
        anisotropy: Slot,
        normal: Option<Slot>,
    },
    Emission {
        color: Slot,
        strength: Slot,
    },
    /// The Volume Absorption node: `σ_a = density · max(1 - color, 0)` (Cycles' absorption
    /// closure), 1/m.
    Absorption {
        color: Slot,
        density: Slot,
    },
    /// The Volume Scatter node: `σ_s = density · color`, Henyey–Greenstein `anisotropy`.
    Scatter {
        color: Slot,
        density: Slot,
        anisotropy: Slot,
    },
    /// The Volume Coefficients node: `σ_a`, `σ_s` (1/m, per channel) and emission
    /// (radiance per metre) given directly, Henyey–Greenstein `anisotropy`.
    Coefficients {
        absorption: Slot,
        scatter: Slot,
        anisotropy: Slot,
        emission: Slot,
    },
    /// The Principled Volume node as Cycles' `svm_node_principled_volume`: `σ_s = ρ c`,
    /// `σ_a = ρ max(1 - c, 0) max(1 - √a, 0)` (`ρ` density, `c` colour, `a` absorption
    /// colour), emission `strength · colour` plus `blackbody` of Stefan–Boltzmann intensity
    /// (`σ_SB 10⁻⁶ / π · mix(1, T⁴, blackbody)`) times its tint and colour.
    PrincipledVolume {
        color: Slot,
        density: Slot,
        anisotropy: Slot,
        absorption_color: Slot,
        emission_color: Slot,
        emission_strength: Slot,
        blackbody: Slot,
        blackbody_tint: Slot,
        temperature: Slot,
    },
    /// The Holdout node: its weight goes to [`crate::shading::ClosureSet::holdout`].
    Holdout,
    /// Mix Shader weights: `out1 = w (1 - clamp(fac)), out2 = w clamp(fac)`.
    MixWeights {
        fac: Slot,
        out1: Slot,
        out2: Slot,
    },
}

/// One closure (or weight) operation, with the weight slot of its place in the shader tree.
#[derive(Clone, Debug)]
pub struct ClosureOp {
    weight: Slot,
    params: ClosureParams,
}

impl ClosureOp {
    /// A constant-white Transparent BSDF of weight `weight`: the surface of a mesh whose
    /// material has only a volume (Cycles lets rays through it into the volume).
    pub fn transparent(weight: Slot, color: Slot) -> ClosureOp {
        ClosureOp {
            weight,
            params: ClosureParams::Transparent { color },
        }
    }

    pub fn emission(weight: Slot, color: Slot, strength: Slot) -> ClosureOp {
        ClosureOp {
            weight,
            params: ClosureParams::Emission { color, strength },
        }
    }

    /// `(weight, color, strength)` of an emission closure.
    pub fn as_emission(&self) -> Option<(Slot, Slot, Slot)> {
        match self.params {
            ClosureParams::Emission { color, strength } => Some((self.weight, color, strength)),
            _ => None,
        }
    }

    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals, out: &mut ClosureSet) {
        let w = s.f(self.weight);
        if let ClosureParams::MixWeights { fac, out1, out2 } = &self.params {
            let (fac, out1, out2) = (*fac, *out1, *out2);
            let f = s.f(fac).clamp(0.0, 1.0);
            s.set_f(out1, w * (1.0 - f));
            s.set_f(out2, w * f);
            return;
        }
        if w == 0.0 {
            return;
        }
        let normal =
            |n: Option<Slot>| -> Vec3 { n.map_or(Vec3::ZERO, |n| world_normal(s.v(n), g)) };
        let tangent = |t: Option<Slot>| -> Vec3 {
            t.map_or(Vec3::ZERO, |t| {
                let v = from_blender(s.v(t));
                let l = v.length();
                if l > 1e-12 && l.is_finite() {
                    v / l
                } else {
                    Vec3::ZERO
                }
            })
        };
        let col = |c: Slot| s.v(c).max(Vec3::ZERO);
        let surface_normal = if g.n_displaced {
            world_normal(g.n, g)
        } else {
            Vec3::ZERO
        };
        let push = |out: &mut ClosureSet, weight: Vec3, normal: Vec3, tangent: Vec3, kind| {
            out.push(Closure {
                weight,
                normal,
                tangent,
                surface_normal,
                kind,
            })
        };
        match &self.params {
            ClosureParams::Principled(p) => {
                let alpha = s.f(p.alpha).clamp(0.0, 1.0);
                let wb = w * alpha;
                if alpha < 1.0 {
                    push(
                        out,
                        Vec3::splat(w * (1.0 - alpha)),
                        Vec3::ZERO,
                        Vec3::ZERO,
                        ClosureKind::Transparent { color: Vec3::ONE },
                    );
                }
                let emission = col(p.emission_color) * s.f(p.emission_strength) * wb;
                if emission != Vec3::ZERO {
                    out.add_emission(emission * principled_emission_layers(s, p, g));
                }
                let pr = Principled {
                    base_color: col(p.base),
                    metallic: s.f(p.metallic).clamp(0.0, 1.0),
                    roughness: s.f(p.roughness).clamp(0.0, 1.0),
                    ior: {
                        let ior = s.f(p.ior);
                        if ior.is_finite() && ior > 0.0 {
                            ior
                        } else {
                            1.5
                        }
                    },
                    specular_level: s.f(p.specular_level).max(0.0),
                    specular_tint: col(p.specular_tint),
                    transmission: s.f(p.transmission).clamp(0.0, 1.0),
                    anisotropic: s.f(p.anisotropic).clamp(-1.0, 1.0),
                    anisotropic_rotation: s.f(p.anisotropic_rotation),
                    coat_weight: s.f(p.coat_weight).max(0.0),
                    coat_roughness: s.f(p.coat_roughness).clamp(0.0, 1.0),
                    coat_ior: s.f(p.coat_ior).max(1.0),
                    coat_tint: col(p.coat_tint),
                    coat_normal: normal(p.coat_normal),
                    sheen_weight: s.f(p.sheen_weight).max(0.0),
                    sheen_roughness: s.f(p.sheen_roughness).clamp(0.0, 1.0),
                    sheen_tint: col(p.sheen_tint),
                    subsurface_weight: s.f(p.subsurface_weight).clamp(0.0, 1.0),
                    subsurface_radius: col(p.subsurface_radius),
                    subsurface_scale: s.f(p.subsurface_scale).max(0.0),
                    subsurface_anisotropy: s.f(p.subsurface_anisotropy),
                    diffuse_roughness: s.f(p.diffuse_roughness),
                    thin_film: ThinFilm::new(s.f(p.thin_film_thickness), s.f(p.thin_film_ior)),
                    cycles: p.cycles,
                    multiscatter: p.multiscatter,
                };
                let n = normal(p.normal);
                let mut pr = pr;
                let mut wb = Vec3::splat(wb);
                if let Some((sheen, sheen_weight, below)) =
                    sheen_apart(&mut pr, n, g).filter(|_| p.sheen_over_coat)
                {
                    push(out, wb * sheen_weight, n, Vec3::ZERO, sheen);
                    wb *= below;
                }
                push(out, wb, n, tangent(p.tangent), ClosureKind::Principled(pr));
            }
            ClosureParams::Metallic {
                fresnel,
                multiscatter,
                roughness,
                anisotropy,
                rotation,
                normal: n,
                tangent: t,
            } => {
                let (base, tint) = match *fresnel {
                    MetalFresnel::F82 { base, tint } => (col(base), col(tint)),
                    MetalFresnel::Physical { ior, extinction } => {
                        physical_as_f82(col(ior).max(Vec3::ZERO), col(extinction).max(Vec3::ZERO))
                    }
                };
                let pr = Principled {
                    base_color: base,
                    metallic: 1.0,
                    roughness: s.f(*roughness).clamp(0.0, 1.0),
                    specular_tint: tint,
                    anisotropic: s.f(*anisotropy).clamp(0.0, 1.0),
                    anisotropic_rotation: s.f(*rotation),
                    multiscatter: *multiscatter,
                    ..Principled::lobe_only()
                };
                push(
                    out,
                    Vec3::splat(w),
                    normal(*n),
                    tangent(*t),
                    ClosureKind::Principled(pr),
                );
            }
            ClosureParams::Sheen {
                color,
                roughness,
                normal: n,
            } => {
                let pr = Principled {
                    sheen_weight: 1.0,
                    sheen_roughness: s.f(*roughness).clamp(0.0, 1.0),
                    sheen_tint: col(*color),
                    ..Principled::lobe_only()
                };
                push(
                    out,
                    Vec3::splat(w),
                    normal(*n),
                    Vec3::ZERO,
                    ClosureKind::Principled(pr),
                );
            }
            ClosureParams::Diffuse {
                color,
                roughness,
                normal: n,
            } => {
                let c = col(*color);
                push(
                    out,
                    c * w,
                    normal(*n),
                    Vec3::ZERO,
                    ClosureKind::Diffuse {
                        color: Vec3::ONE,
                        roughness: s.f(*roughness),
                        albedo: c.min(Vec3::ONE),
                    },
                );
            }
            ClosureParams::Glossy {
                color,
                roughness,
                anisotropy,
                rotation,
                normal: n,
                tangent: t,
                multiscatter,
                beckmann,
            } => push(
                out,
                col(*color) * w,
                normal(*n),
                tangent(*t),
                ClosureKind::Glossy {
                    color: Vec3::ONE,
                    roughness: s.f(*roughness).clamp(0.0, 1.0),
                    anisotropy: s.f(*anisotropy).clamp(-1.0, 1.0),
                    rotation: s.f(*rotation),
                    multiscatter: *multiscatter,
                    beckmann: *beckmann,
                    tint: col(*color).max(Vec3::ZERO),
                },
            ),
            ClosureParams::Glass {
                color,
                roughness,
                ior,
                normal: n,
                refraction_only,
                multiscatter,
                beckmann,
            } => {
                let (color, roughness, ior) = (
                    col(*color),
                    s.f(*roughness).clamp(0.0, 1.0),
                    s.f(*ior).clamp(1e-3, 1e3),
                );
                // Blender's Glass and Refraction tint every reflection and refraction by
                // their colour: it is the closure's weight, as for Glossy.
                let kind = if *refraction_only {
                    ClosureKind::Refraction {
                        color: Vec3::ONE,
                        roughness,
                        ior,
                        beckmann: *beckmann,
                    }
                } else {
                    ClosureKind::Glass {
                        color: Vec3::ONE,
                        roughness,
                        ior,
                        multiscatter: *multiscatter,
                        beckmann: *beckmann,
                        tint: color.max(Vec3::ZERO),
                    }
                };
                push(out, color * w, normal(*n), Vec3::ZERO, kind);
            }
            ClosureParams::Translucent { color, normal: n } => push(
                out,
                col(*color) * w,
                normal(*n),
                Vec3::ZERO,
                ClosureKind::Translucent { color: Vec3::ONE },
            ),
            ClosureParams::Toon {
                color,
                size,
                smooth,
                normal: n,
                glossy,
            } => push(
                out,
                col(*color) * w,
                normal(*n),
                Vec3::ZERO,
                ClosureKind::Toon {
                    color: Vec3::ONE,
                    size: s.f(*size),
                    smooth: s.f(*smooth),
                    glossy: *glossy,
                },
            ),
            ClosureParams::Hair {
                color,
                roughness,
                radial_roughness,
                coat,
                ior,
                offset,
                random_color,
                random_roughness,
                random,
                random_linked,
            } => {
                use crate::bsdf::hair::{HairColor, PrincipledHair};
                let strand = g.color_attribute(crate::scene::curves::CURVE_LAYER);
                let random = match strand {
                    Some(info) if !random_linked => info.z,
                    _ => s.f(*random),
                };
                let color = match color {
                    HairColorSlots::Absorption(a) => HairColor::Absorption(col(*a)),
                    HairColorSlots::Melanin {
                        melanin,
                        redness,
                        tint,
                    } => HairColor::Melanin {
                        melanin: s.f(*melanin).clamp(0.0, 1.0),
                        redness: s.f(*redness).clamp(0.0, 1.0),
                        tint: col(*tint),
                    },
                    HairColorSlots::Reflectance(c) => HairColor::Reflectance(col(*c)),
                };
                let hair = PrincipledHair {
                    color,
                    roughness: s.f(*roughness),
                    radial_roughness: s.f(*radial_roughness),
                    coat: s.f(*coat),
                    ior: s.f(*ior),
                    offset: s.f(*offset),
                    random_color: s.f(*random_color),
                    random_roughness: s.f(*random_roughness),
                    random,
                };
                // The strand's direction (the curve tangent its mesh carries).
                let t = g
                    .tangent()
                    .map_or(Vec3::ZERO, |(t, _)| from_blender(t).normalize_or_zero());
                push(out, Vec3::splat(w), Vec3::ZERO, t, ClosureKind::Hair(hair));
            }
            ClosureParams::Transparent { color } => push(
                out,
                col(*color) * w,
                Vec3::ZERO,
                Vec3::ZERO,
                ClosureKind::Transparent { color: Vec3::ONE },
            ),
            ClosureParams::Portal { color } => {
                if g.ray_flags & crate::shading::globals::ray::SHADOW == 0 {
                    push(
                        out,
                        col(*color) * w,
                        Vec3::ZERO,
                        Vec3::ZERO,
                        ClosureKind::Transparent { color: Vec3::ONE },
                    );
                }
            }
            ClosureParams::Subsurface {
                color,
                scale,
                radius,
                ior,
                roughness,
                anisotropy,
                normal: n,
            } => {
                let c = col(*color);
                push(
                    out,
                    c * w,
                    normal(*n),
                    Vec3::ZERO,
                    ClosureKind::Subsurface {
                        albedo: c.min(Vec3::ONE),
                        radius: (col(*radius) * s.f(*scale)).max(Vec3::ZERO),
                        ior: s.f(*ior),
                        roughness: s.f(*roughness),
                        anisotropy: s.f(*anisotropy),
                    },
                );
            }
            ClosureParams::Emission { color, strength } => {
                out.add_emission(col(*color) * s.f(*strength) * w);
            }
            ClosureParams::Absorption { color, density } => {
                let sigma = (Vec3::ONE - col(*color)).max(Vec3::ZERO) * s.f(*density).max(0.0);
                out.add_absorption(sigma * w);
            }
            ClosureParams::Scatter {
                color,
                density,
                anisotropy,
            } => {
                let sigma = col(*color).max(Vec3::ZERO) * s.f(*density).max(0.0);
                out.add_scatter(sigma * w, s.f(*anisotropy));
            }
            ClosureParams::Coefficients {
                absorption,
                scatter,
                anisotropy,
                emission,
            } => {
                out.add_absorption(col(*absorption).max(Vec3::ZERO) * w);
                out.add_scatter(col(*scatter).max(Vec3::ZERO) * w, s.f(*anisotropy));
                let e = col(*emission);
                if e.max_element() > 0.0 {
                    out.add_emission(e * w);
                }
            }
            ClosureParams::PrincipledVolume {
                color,
                density,
                anisotropy,
                absorption_color,
                emission_color,
                emission_strength,
                blackbody,
                blackbody_tint,
                temperature,
            } => {
                let rho = s.f(*density).max(0.0);
                if rho > 0.0 {
                    let c = col(*color);
                    let a = col(*absorption_color).max(Vec3::ZERO);
                    let sqrt_a = Vec3::new(a.x.sqrt(), a.y.sqrt(), a.z.sqrt());
                    out.add_scatter(c.max(Vec3::ZERO) * rho * w, s.f(*anisotropy));
                    let absorb =
                        (Vec3::ONE - c).max(Vec3::ZERO) * (Vec3::ONE - sqrt_a).max(Vec3::ZERO);
                    out.add_absorption(absorb * rho * w);
                }
                let strength = s.f(*emission_strength);
                if strength > 0.0 {
                    out.add_emission(col(*emission_color) * strength * w);
                }
                let bb = s.f(*blackbody);
                if bb > 0.0 {
                    let t = s.f(*temperature).max(0.0);
                    let t4 = (t * t) * (t * t);
                    let intensity =
                        5.670373e-8 * 1e-6 / std::f32::consts::PI * (1.0 + bb * (t4 - 1.0));
                    if intensity > 0.0 {
                        let c = super::color::blackbody(t);
                        out.add_emission(col(*blackbody_tint) * c * intensity * w);
                    }
                }
            }
            ClosureParams::Holdout => out.add_holdout(Vec3::splat(w)),
            ClosureParams::MixWeights { .. } => {}
        }
    }
}

/// Warns where a volume node's phase function is not Henyey-Greenstein, the one Tesela
/// renders (with the node's anisotropy).
fn warn_phase(cx: &mut NodeCx) {
    match cx.prop_str("phase").unwrap_or("HENYEY_GREENSTEIN") {
        "HENYEY_GREENSTEIN" => {}
        p => cx.warn(&format!(
            "the {p} phase function renders as Henyey-Greenstein of the node's anisotropy"
        )),
    }
}

/// A shader node reached from the material output's Volume: Volume Absorption, Volume Scatter
/// (Henyey–Greenstein), Principled Volume and Emission (radiance per metre) make the
/// homogeneous medium of the interior; surface shaders are reported and add nothing there, as
/// Cycles ignores surface closures in a volume.
fn compile_volume_closure(kind: &str, cx: &mut NodeCx, w: Slot) -> Result<bool, CompileError> {
    let params = match kind {
        "ShaderNodeVolumeAbsorption" => ClosureParams::Absorption {
            color: cx.color("Color", Vec3::splat(0.8))?,
            density: cx.float("Density", 1.0)?,
        },
        "ShaderNodeVolumeScatter" => {
            warn_phase(cx);
            ClosureParams::Scatter {
                color: cx.color("Color", Vec3::splat(0.8))?,
                density: cx.float("Density", 1.0)?,
                anisotropy: cx.float("Anisotropy", 0.0)?,
            }
        }
        "ShaderNodeVolumeCoefficients" => {
            warn_phase(cx);
            ClosureParams::Coefficients {
                absorption: cx.vector("Absorption Coefficients", Vec3::ONE)?,
                scatter: cx.vector("Scatter Coefficients", Vec3::ONE)?,
                anisotropy: cx.float("Anisotropy", 0.0)?,
                emission: cx.vector("Emission Coefficients", Vec3::ZERO)?,
            }
        }
        "ShaderNodeVolumePrincipled" => {
            // Its attribute inputs name volume grids; meshes have none, and Cycles then
            // renders the inputs as they are, as here.
            ClosureParams::PrincipledVolume {
                color: cx.color("Color", Vec3::splat(0.5))?,
                density: cx.float("Density", 1.0)?,
                anisotropy: cx.float("Anisotropy", 0.0)?,
                absorption_color: cx.color("Absorption Color", Vec3::ZERO)?,
                emission_color: cx.color("Emission Color", Vec3::ONE)?,
                emission_strength: cx.float("Emission Strength", 0.0)?,
                blackbody: cx.float("Blackbody Intensity", 0.0)?,
                blackbody_tint: cx.color("Blackbody Tint", Vec3::ONE)?,
                temperature: cx.float("Temperature", 1000.0)?,
            }
        }
        "ShaderNodeEmission" => ClosureParams::Emission {
            color: cx.color("Color", Vec3::ONE)?,
            strength: cx.float("Strength", 1.0)?,
        },
        _ if kind.starts_with("ShaderNodeBsdf") || kind == "ShaderNodeBsdfPrincipled" => {
            cx.warn("a surface shader in the Volume input renders nothing there, as in Cycles");
            return Ok(true);
        }
        _ => {
            cx.warn("this shader is not rendered in a volume; the volume renders clear");
            return Ok(true);
        }
    };
    cx.emit(Op::Closure(ClosureOp { weight: w, params }), false);
    Ok(true)
}

/// A physical conductor's complex IOR as the F82-tint model's base colour and edge tint that
/// reproduce its reflectance at normal incidence and at `cos θ = 1/7` (~82°) exactly, the fit
/// Cycles itself uses for the conductor's multiple-scattering term.
fn physical_as_f82(eta: Vec3, k: Vec3) -> (Vec3, Vec3) {
    use crate::bsdf::fresnel;
    let f0 = fresnel::conductor(1.0, eta, k);
    let f82 = fresnel::conductor(1.0 / 7.0, eta, k);
    let schlick = fresnel::schlick(f0, 1.0 / 7.0);
    let tint = Vec3::select(schlick.cmpgt(Vec3::ZERO), f82 / schlick, Vec3::ONE);
    (f0, tint)
}

/// A Blender Principled BSDF's sheen over its coat as a closure of its own, as Cycles sets it
/// up (the layered BSDF holds a sheen over a coat over a diffuse or metal base only): removes
/// the sheen from `pr` and returns the sheen closure, its weight factor and the factor
/// `1 - max(sheen albedo)` on the closures below, both for the view direction about the
/// closure normal `n` (renderer world space; zero for the shading normal). The sheen closure
/// carries its albedo in its weight and the sheen divided by it, so that the closure choice
/// picks it as often as it reflects. `None` without both layers, or for a view from below.
fn sheen_apart(pr: &mut Principled, n: Vec3, g: &ShaderGlobals) -> Option<(ClosureKind, f32, f32)> {
    use crate::bsdf::Sheen;
    if !(pr.coat_weight > 0.0 && pr.sheen_weight > 0.0) || pr.sheen_tint.max_element() <= 0.0 {
        return None;
    }
    let n = if n == Vec3::ZERO {
        from_blender(g.n)
    } else {
        n
    };
    let mu = n.dot(from_blender(g.i)).min(1.0);
    let tint = pr.sheen_tint * pr.sheen_weight;
    let wi = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let e = Sheen::new(Vec3::ONE, pr.sheen_roughness).albedo(wi).x;
    if !(e > 0.0 && e.is_finite()) {
        return None;
    }
    let below = (1.0 - tint.max_element() * e).clamp(0.0, 1.0);
    let sheen = Principled {
        sheen_weight: 1.0 / e,
        sheen_roughness: pr.sheen_roughness,
        sheen_tint: tint,
        multiscatter: pr.multiscatter,
        ..Principled::lobe_only()
    };
    pr.sheen_weight = 0.0;
    Some((ClosureKind::Principled(sheen), e, below))
}

/// The share of a Principled BSDF's emission that leaves through its sheen and coat, as Cycles
/// sets the emission closure up below those layers (`principled` in `svm/closure.h`): each
/// layer's `closure_layering_weight` for the view direction (Cycles' `wi`), the sheen about
/// the Normal turned towards the coat normal by the coat weight, the coat about its normal
/// (the Coat Normal, else the shading normal, made a valid specular one), and the coat's tint
/// along the view direction refracted into it. Cycles evaluates the emission of its light
/// samples without closures, so that the layers' albedos are not found there: a light sample
/// (no ray bits) takes the tint alone. Blender world space, as the slots.
fn principled_emission_layers(s: &Slots, p: &PrincipledSlots, g: &ShaderGlobals) -> Vec3 {
    use crate::bsdf::{Coat, Layer, Sheen};
    if !p.layered_emission {
        return Vec3::ONE;
    }
    let closures = g.ray_flags != 0;
    let unit = |slot: Option<Slot>| {
        slot.and_then(|n| s.v(n).try_normalize())
            .filter(|n| n.is_finite())
            .unwrap_or(g.n)
    };
    // The direction towards the viewer in a frame about a unit normal (the layers are
    // isotropic: only the cosine counts).
    let towards_viewer = |n: Vec3| {
        let mu = n.dot(g.i).clamp(-1.0, 1.0);
        Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu)
    };
    let n = unit(p.normal);
    let coat_n = unit(p.coat_normal);
    let coat_weight = s.f(p.coat_weight).max(0.0);
    let mut att = Vec3::ONE;
    let sheen_tint = s.v(p.sheen_tint).max(Vec3::ZERO);
    let sheen_weight = s.f(p.sheen_weight).max(0.0);
    if closures && sheen_weight > 0.0 && sheen_tint.max_element() > 0.0 {
        let sheen_n = n
            .lerp(coat_n, coat_weight.min(1.0))
            .try_normalize()
            .unwrap_or(n);
        let sheen = Sheen::new(
            sheen_tint * sheen_weight,
            s.f(p.sheen_roughness).clamp(0.0, 1.0),
        );
        att *= sheen.attenuation(towards_viewer(sheen_n));
    }
    if coat_weight > 0.0 {
        let coat_n = crate::bsdf::closure::valid_specular_normal(g.ng, g.i, coat_n);
        let tint = s.v(p.coat_tint).max(Vec3::ZERO);
        if closures {
            let coat = Coat::new(coat_weight, s.f(p.coat_roughness), s.f(p.coat_ior), tint);
            att *= coat.attenuation(towards_viewer(coat_n));
        } else if tint != Vec3::ONE {
            // Beer's law along the view direction refracted into a coat of unit thickness.
            let mu = coat_n.dot(g.i).clamp(-1.0, 1.0);
            let inv = 1.0 / s.f(p.coat_ior).max(1.0);
            let cos_t = (1.0 - inv * inv * (1.0 - mu * mu)).max(0.0).sqrt();
            let through = tint.powf(1.0 / cos_t);
            att *= Vec3::ONE + (through - Vec3::ONE) * coat_weight;
        }
    }
    att
}

/// A linked Normal input (Blender world space) as a unit world-space normal; zero (meaning
/// "the shading normal") when it is degenerate.
#[inline]
fn world_normal(n: Vec3, _g: &ShaderGlobals) -> Vec3 {
    let v = from_blender(n);
    let l = v.length();
    if l > 1e-12 && l.is_finite() {
        v / l
    } else {
        Vec3::ZERO
    }
}

/// Warns where a Glossy, Anisotropic, Glass or Refraction BSDF's distribution is one Tesela
/// renders as GGX (Beckmann, Ashikhmin-Shirley).
fn warn_microfacet_distribution(cx: &mut NodeCx) {
    match cx.prop_str("distribution").unwrap_or("MULTI_GGX") {
        "GGX" | "MULTI_GGX" | "SHARP" => {}
        "BECKMANN" => {}
        "ASHIKHMIN_SHIRLEY" => cx.warn("the Ashikhmin-Shirley distribution renders as GGX"),
        d => cx.warn(&format!("the {d} distribution renders as GGX")),
    }
}

/// Warns where the Principled BSDF's Diffuse Roughness (Oren-Nayar) cannot show: under a
/// mirror-smooth specular layer the diffuse base stays Lambertian.
fn warn_smooth_oren_nayar(cx: &mut NodeCx) {
    let rough = cx.is_linked("Diffuse Roughness")
        || cx.input_f32("Diffuse Roughness").is_some_and(|r| r > 0.0);
    let smooth = !cx.is_linked("Roughness")
        && cx
            .input_f32("Roughness")
            .is_some_and(|r| r * r < crate::bsdf::DELTA_ALPHA);
    if rough && smooth {
        cx.warn(
            "the Diffuse Roughness is not rendered under a mirror-smooth specular layer \
             (Roughness below 0.032): the diffuse base is Lambertian",
        );
    }
}

/// Warns where the subsurface method (enum property `prop`) is one Tesela renders as the
/// plain random walk.
fn warn_subsurface_method(cx: &mut NodeCx, prop: &str) {
    match cx.prop_str(prop).unwrap_or("RANDOM_WALK") {
        "RANDOM_WALK" => {}
        "RANDOM_WALK_SKIN" => cx.warn(
            "Random Walk (Skin) subsurface renders as Random Walk (no diffuse entry, no radius \
             fit to the albedo)",
        ),
        "BURLEY" => cx.warn(
            "Christensen-Burley subsurface renders as Random Walk (a volumetric walk, not \
             Cycles' disk sampling: softer, more translucent)",
        ),
        _ => cx.warn("unknown subsurface method renders as Random Walk"),
    }
}

/// Compiles closure node `kind` with weight slot `w`; `Ok(false)` when not implemented.
pub fn compile_closure(kind: &str, cx: &mut NodeCx, w: Slot) -> Result<bool, CompileError> {
    let normal = |cx: &mut NodeCx, id: &str| -> Result<Option<Slot>, CompileError> {
        if cx.is_linked(id) {
            cx.vector(id, Vec3::ZERO).map(Some)
        } else if cx.displaced() && id != "Tangent" {
            // Unlinked, the normal is N: after a displacement, the displaced one.
            let n = cx.alloc(3)?;
            cx.emit(
                Op::Input(super::input::InputOp {
                    src: super::input::Source::Normal,
                    out: n,
                }),
                true,
            );
            Ok(Some(n))
        } else {
            Ok(None)
        }
    };
    let params = match kind {
        "ShaderNodeMixShader" => {
            let fac = cx.float("Fac", 0.5)?;
            let out1 = cx.alloc(1)?;
            let out2 = cx.alloc(1)?;
            cx.emit(
                Op::Closure(ClosureOp {
                    weight: w,
                    params: ClosureParams::MixWeights { fac, out1, out2 },
                }),
                false,
            );
            cx.shader("Shader", out1)?;
            cx.shader("Shader_001", out2)?;
            return Ok(true);
        }
        "ShaderNodeAddShader" => {
            cx.shader("Shader", w)?;
            cx.shader("Shader_001", w)?;
            return Ok(true);
        }
        "ShaderNodeBackground" => return super::environment::compile_background(cx, w),
        _ if cx.in_volume() => return compile_volume_closure(kind, cx, w),
        "ShaderNodeBsdfPrincipled" => {
            warn_smooth_oren_nayar(cx);
            let f = |cx: &mut NodeCx, id: &str, d: f32| cx.float(id, d);
            let c = |cx: &mut NodeCx, id: &str, d: Vec3| cx.color(id, d);
            let mut p = PrincipledSlots {
                base: c(cx, "Base Color", Vec3::splat(0.8))?,
                metallic: f(cx, "Metallic", 0.0)?,
                roughness: f(cx, "Roughness", 0.5)?,
                ior: f(cx, "IOR", 1.5)?,
                alpha: f(cx, "Alpha", 1.0)?,
                normal: normal(cx, "Normal")?,
                specular_level: f(cx, "Specular IOR Level", 0.5)?,
                specular_tint: c(cx, "Specular Tint", Vec3::ONE)?,
                transmission: f(cx, "Transmission Weight", 0.0)?,
                anisotropic: f(cx, "Anisotropic", 0.0)?,
                anisotropic_rotation: f(cx, "Anisotropic Rotation", 0.0)?,
                tangent: normal(cx, "Tangent")?,
                coat_weight: f(cx, "Coat Weight", 0.0)?,
                coat_roughness: f(cx, "Coat Roughness", 0.03)?,
                coat_ior: f(cx, "Coat IOR", 1.5)?,
                coat_tint: c(cx, "Coat Tint", Vec3::ONE)?,
                coat_normal: normal(cx, "Coat Normal")?,
                sheen_weight: f(cx, "Sheen Weight", 0.0)?,
                sheen_roughness: f(cx, "Sheen Roughness", 0.5)?,
                sheen_tint: c(cx, "Sheen Tint", Vec3::ONE)?,
                subsurface_weight: f(cx, "Subsurface Weight", 0.0)?,
                subsurface_radius: cx.vector("Subsurface Radius", Vec3::new(1.0, 0.2, 0.1))?,
                subsurface_scale: f(cx, "Subsurface Scale", 0.05)?,
                subsurface_anisotropy: f(cx, "Subsurface Anisotropy", 0.0)?,
                diffuse_roughness: f(cx, "Diffuse Roughness", 0.0)?,
                thin_film_thickness: f(cx, "Thin Film Thickness", 0.0)?,
                thin_film_ior: f(cx, "Thin Film IOR", 1.33)?,
                emission_color: c(cx, "Emission Color", Vec3::ONE)?,
                emission_strength: f(cx, "Emission Strength", 0.0)?,
                cycles: !cx.prop_bool("gltf", false),
                // Blender 3.x and 4.x files keep GGX where it was chosen (3.x's default).
                multiscatter: cx.prop_str("distribution").unwrap_or("MULTI_GGX") != "GGX",
                layered_emission: false,
                sheen_over_coat: false,
            };
            if cx.is_linked("Alpha") || cx.const_value("Alpha").is_some_and(|v| v[0] < 1.0) {
                cx.passes();
            }
            // Cycles' has_surface_emission: an unlinked colour or strength at most its closure
            // weight cutoff switches the emission off (a negative strength typed in emits
            // nothing; one computed by a link takes light away).
            let on = |cx: &NodeCx, id: &str, default: f32| {
                cx.is_linked(id)
                    || cx.const_value(id).map_or(default, |v| {
                        v.iter().take(3).fold(f32::NEG_INFINITY, |m, &x| m.max(x))
                    }) > 1e-5
            };
            let layer = |cx: &NodeCx, id: &str| {
                p.cycles && (cx.is_linked(id) || cx.const_value(id).is_some_and(|v| v[0] > 0.0))
            };
            let (coat, sheen) = (layer(cx, "Coat Weight"), layer(cx, "Sheen Weight"));
            p.sheen_over_coat = coat && sheen;
            if on(cx, "Emission Color", 1.0) && on(cx, "Emission Strength", 0.0) {
                cx.emits();
                p.layered_emission = coat || sheen;
            } else {
                p.emission_strength = cx.constant(&[0.0])?;
            }
            let thin_film = "Thin Film Thickness";
            if (cx.is_linked(thin_film) || cx.const_value(thin_film).is_some_and(|v| v[0] > 0.1))
                && (cx.is_linked("Metallic") || cx.input_f32("Metallic").unwrap_or(0.0) > 0.0)
            {
                cx.warn("thin film on the metallic lobe is not rendered (only on the dielectric)");
            }
            let ss = "Subsurface Weight";
            if !p.cycles {
                // glTF materials have no subsurface.
            } else if cx.is_linked(ss) || cx.const_value(ss).is_some_and(|v| v[0] != 0.0) {
                cx.scatters_below();
                warn_subsurface_method(cx, "subsurface_method");
            }
            ClosureParams::Principled(Box::new(p))
        }
        "ShaderNodeBsdfMetallic" => {
            let fresnel = if cx.prop_str("fresnel_type") == Some("PHYSICAL_CONDUCTOR") {
                MetalFresnel::Physical {
                    ior: cx.vector("IOR", Vec3::new(0.18, 0.42, 1.37))?,
                    extinction: cx.vector("Extinction", Vec3::new(3.42, 2.35, 1.77))?,
                }
            } else {
                MetalFresnel::F82 {
                    base: cx.color("Base Color", Vec3::new(0.617, 0.577, 0.540))?,
                    tint: cx.color("Edge Tint", Vec3::new(0.695, 0.726, 0.770))?,
                }
            };
            let multiscatter = match cx.prop_str("distribution").unwrap_or("MULTI_GGX") {
                "MULTI_GGX" => true,
                "GGX" => false,
                d => {
                    cx.warn(&format!(
                        "distribution {d} renders as Multiscatter GGX (energy-conserving)"
                    ));
                    true
                }
            };
            if cx.is_linked("Thin Film Thickness")
                || cx
                    .const_value("Thin Film Thickness")
                    .is_some_and(|v| v[0] != 0.0)
            {
                cx.warn("thin film is not rendered");
            }
            ClosureParams::Metallic {
                fresnel,
                multiscatter,
                roughness: cx.float("Roughness", 0.5)?,
                anisotropy: cx.float("Anisotropy", 0.0)?,
                rotation: cx.float("Rotation", 0.0)?,
                normal: normal(cx, "Normal")?,
                tangent: normal(cx, "Tangent")?,
            }
        }
        "ShaderNodeBsdfSheen" => {
            if cx.prop_str("distribution").unwrap_or("MICROFIBER") != "MICROFIBER" {
                cx.warn("the Ashikhmin sheen renders as Microfiber");
            }
            ClosureParams::Sheen {
                color: cx.color("Color", Vec3::splat(0.8))?,
                roughness: cx.float("Roughness", 0.5)?,
                normal: normal(cx, "Normal")?,
            }
        }
        "ShaderNodeSubsurfaceScattering" => {
            cx.scatters_below();
            warn_subsurface_method(cx, "falloff");
            ClosureParams::Subsurface {
                color: cx.color("Color", Vec3::splat(0.8))?,
                scale: cx.float("Scale", 0.05)?,
                radius: cx.vector("Radius", Vec3::new(1.0, 0.2, 0.1))?,
                ior: cx.float("IOR", 1.4)?,
                roughness: cx.float("Roughness", 1.0)?,
                anisotropy: cx.float("Anisotropy", 0.0)?,
                normal: normal(cx, "Normal")?,
            }
        }
        "ShaderNodeBsdfDiffuse" => ClosureParams::Diffuse {
            color: cx.color("Color", Vec3::splat(0.8))?,
            roughness: cx.float("Roughness", 0.0)?,
            normal: normal(cx, "Normal")?,
        },
        "ShaderNodeBsdfAnisotropic" | "ShaderNodeBsdfGlossy" => {
            warn_microfacet_distribution(cx);
            ClosureParams::Glossy {
                color: cx.color("Color", Vec3::splat(0.8))?,
                roughness: cx.float("Roughness", 0.5)?,
                anisotropy: cx.float("Anisotropy", 0.0)?,
                rotation: cx.float("Rotation", 0.0)?,
                normal: normal(cx, "Normal")?,
                tangent: normal(cx, "Tangent")?,
                multiscatter: cx.prop_str("distribution").unwrap_or("MULTI_GGX") == "MULTI_GGX",
                beckmann: cx.prop_str("distribution") == Some("BECKMANN"),
            }
        }
        "ShaderNodeBsdfGlass" | "ShaderNodeBsdfRefraction" => {
            warn_microfacet_distribution(cx);
            ClosureParams::Glass {
                color: cx.color("Color", Vec3::ONE)?,
                roughness: cx.float("Roughness", 0.0)?,
                ior: cx.float("IOR", 1.5)?,
                normal: normal(cx, "Normal")?,
                refraction_only: kind == "ShaderNodeBsdfRefraction",
                multiscatter: cx.prop_str("distribution").unwrap_or("MULTI_GGX") == "MULTI_GGX",
                beckmann: cx.prop_str("distribution") == Some("BECKMANN"),
            }
        }
        "ShaderNodeBsdfToon" => ClosureParams::Toon {
            color: cx.color("Color", Vec3::splat(0.8))?,
            size: cx.float("Size", 0.5)?,
            smooth: cx.float("Smooth", 0.0)?,
            normal: normal(cx, "Normal")?,
            glossy: cx.prop_str("component") == Some("GLOSSY"),
        },
        "ShaderNodeBsdfHairPrincipled" => {
            if cx.prop_str("model") == Some("HUANG") {
                cx.warn("the Huang hair model is rendered with the Chiang model");
            }
            let color = match cx.prop_str("parametrization") {
                Some("ABSORPTION") => HairColorSlots::Absorption(
                    cx.color("Absorption Coefficient", Vec3::new(0.245531, 0.52, 1.365))?,
                ),
                Some("MELANIN") => HairColorSlots::Melanin {
                    melanin: cx.float("Melanin", 0.8)?,
                    redness: cx.float("Melanin Redness", 1.0)?,
                    tint: cx.color("Tint", Vec3::ONE)?,
                },
                _ => HairColorSlots::Reflectance(
                    cx.color("Color", Vec3::new(0.017513, 0.005763, 0.002059))?,
                ),
            };
            ClosureParams::Hair {
                color,
                roughness: cx.float("Roughness", 0.3)?,
                radial_roughness: cx.float("Radial Roughness", 0.3)?,
                coat: cx.float("Coat", 0.0)?,
                ior: cx.float("IOR", 1.55)?,
                offset: cx.float("Offset", 2f32.to_radians())?,
                random_color: cx.float("Random Color", 0.0)?,
                random_roughness: cx.float("Random Roughness", 0.0)?,
                random_linked: cx.is_linked("Random"),
                random: cx.float("Random", 0.0)?,
            }
        }
        "ShaderNodeBsdfTranslucent" => ClosureParams::Translucent {
            color: cx.color("Color", Vec3::splat(0.8))?,
            normal: normal(cx, "Normal")?,
        },
        "ShaderNodeBsdfTransparent" => {
            cx.passes();
            ClosureParams::Transparent {
                color: cx.color("Color", Vec3::ONE)?,
            }
        }
        "ShaderNodeBsdfRayPortal" => {
            // Unlinked, Position and Direction are the hit point and the ray's own direction:
            // the ray goes on through the surface, tinted, as through a Transparent BSDF.
            if cx.is_linked("Position") || cx.is_linked("Direction") {
                cx.warn(
                    "a Ray Portal BSDF with a linked Position or Direction renders as if \
                     unlinked (rays go on through the surface, not from the given position)",
                );
            }
            cx.passes();
            ClosureParams::Portal {
                color: cx.color("Color", Vec3::ONE)?,
            }
        }
        "ShaderNodeEmission" => {
            cx.emits();
            ClosureParams::Emission {
                color: cx.color("Color", Vec3::ONE)?,
                strength: cx.float("Strength", 1.0)?,
            }
        }
        "ShaderNodeHoldout" => {
            // Black, and with a transparent film a hole in the alpha where the camera sees it
            // (Cycles ignores holdouts on an opaque film).
            cx.passes();
            ClosureParams::Holdout
        }
        _ => return Ok(false),
    };
    // A Principled BSDF's emission under a coat or sheen, and a sheen over a coat, depend on
    // the view direction.
    let varying = matches!(&params,
        ClosureParams::Principled(p) if p.layered_emission || p.sheen_over_coat)
        || matches!(params, ClosureParams::Portal { .. });
    cx.emit(Op::Closure(ClosureOp { weight: w, params }), varying);
    let _ = SocketType::Shader;
    Ok(true)
}
