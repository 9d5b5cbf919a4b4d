//! Cycles' light passes from inside a path: each contribution to a camera path's radiance,
//! split by the class of the path's first bounce (diffuse, glossy, transmission) and by
//! whether it is direct (light sampled at the first bounce, or emission met by the ray that
//! leaves it) or indirect (everything after).
//!
//! The path integrators are generic over a [`Sink`]: [`NoSplit`] compiles to nothing, so a
//! render without light passes runs the same code as before.

use super::Integrator;
use crate::bsdf::{Bsdf, BsdfQueryRecord, Measure};
use crate::render_scene::{Ctx, RenderScene};
use glam::Vec3;

/// The share of a path's radiance that goes to the diffuse and the glossy passes, per
/// channel (Cycles' `pass_diffuse_weight`, `pass_glossy_weight`); transmission takes
/// `1 - diffuse - glossy`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClassWeights {
    pub diffuse: Vec3,
    pub glossy: Vec3,
}

impl ClassWeights {
    /// All diffuse (Cycles counts light through a subsurface walk as diffuse).
    pub const DIFFUSE: ClassWeights = ClassWeights {
        diffuse: Vec3::ONE,
        glossy: Vec3::ZERO,
    };

    /// The weights of light scattered from local direction `rec.wo` to `rec.wi` by `bsdf`:
    /// its [`Bsdf::eval_split`] over its value, per channel (0 where the value is 0). A
    /// direction sampled from a delta lobe is glossy when it reflects, transmission when it
    /// crosses the surface.
    #[inline]
    pub fn of<B: Bsdf>(bsdf: &B, rec: &BsdfQueryRecord) -> ClassWeights {
        if rec.measure == Measure::Discrete {
            let glossy = if rec.wo.z * rec.wi.z > 0.0 { 1.0 } else { 0.0 };
            return ClassWeights {
                diffuse: Vec3::ZERO,
                glossy: Vec3::splat(glossy),
            };
        }
        let f = bsdf.eval(rec);
        let [d, g] = bsdf.eval_split(rec);
        let div = |a: Vec3| {
            Vec3::new(
                if f.x != 0.0 { a.x / f.x } else { 0.0 },
                if f.y != 0.0 { a.y / f.y } else { 0.0 },
                if f.z != 0.0 { a.z / f.z } else { 0.0 },
            )
        };
        ClassWeights {
            diffuse: div(d),
            glossy: div(g),
        }
    }
}

/// One camera sample's light passes: radiance per class (`[diffuse, glossy, transmission]`),
/// not yet divided by colour, and what reached the camera before any bounce.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightSplit {
    pub direct: [Vec3; 3],
    pub indirect: [Vec3; 3],
    /// Emission and world seen straight or through transparent surfaces (Cycles' Emit and
    /// Env passes, which the film computes on its own).
    pub camera: Vec3,
}

impl LightSplit {
    /// Everything, for checks: equals the integrator's radiance up to rounding.
    pub fn total(&self) -> Vec3 {
        self.camera
            + self.direct.iter().copied().sum::<Vec3>()
            + self.indirect.iter().copied().sum::<Vec3>()
    }
}

/// Where an integrator reports the parts of its radiance.
pub trait Sink {
    /// False for [`NoSplit`]: callers skip the work of classifying.
    const ACTIVE: bool;
    /// Radiance `c` met before the path's first bounce.
    fn camera(&mut self, c: Vec3);
    /// Radiance `c` that came through the first bounce, with that bounce's weights.
    fn bounced(&mut self, c: Vec3, w: &ClassWeights, direct: bool);
}

/// An integrator whose one path loop, generic over its [`Sink`], serves both
/// [`Integrator::li`] (with [`NoSplit`], compiling to the plain loop) and
/// [`Integrator::li_split`].
pub trait SplitsLight: Send + Sync {
    fn run<S: Sink>(
        &self,
        scene: &RenderScene,
        ctx: &mut Ctx,
        o: Vec3,
        d: Vec3,
        sink: &mut S,
    ) -> Vec3;
}

impl<T: SplitsLight> Integrator for T {
    fn li(&self, scene: &RenderScene, ctx: &mut Ctx, o: Vec3, d: Vec3) -> Vec3 {
        self.run(scene, ctx, o, d, &mut NoSplit)
    }

    fn splits_light(&self) -> bool {
        true
    }

    fn li_split(
        &self,
        scene: &RenderScene,
        ctx: &mut Ctx,
        o: Vec3,
        d: Vec3,
        split: &mut LightSplit,
    ) -> Vec3 {
        self.run(scene, ctx, o, d, split)
    }
}

/// No light passes.
pub struct NoSplit;

impl Sink for NoSplit {
    const ACTIVE: bool = false;
    #[inline(always)]
    fn camera(&mut self, _: Vec3) {}
    #[inline(always)]
    fn bounced(&mut self, _: Vec3, _: &ClassWeights, _: bool) {}
}

impl Sink for LightSplit {
    const ACTIVE: bool = true;
    #[inline]
    fn camera(&mut self, c: Vec3) {
        self.camera += c;
    }
    #[inline]
    fn bounced(&mut self, c: Vec3, w: &ClassWeights, direct: bool) {
        let to = if direct {
            &mut self.direct
        } else {
            &mut self.indirect
        };
        let (d, g) = (c * w.diffuse, c * w.glossy);
        to[0] += d;
        to[1] += g;
        to[2] += c - d - g;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Diffuse, Plastic, from_closure};
    use crate::sampler::Sampler;
    use crate::sampling::square_to_uniform_sphere;
    use crate::shading::{Closure, ClosureKind, Principled};

    #[test]
    fn weights_split_a_mixed_lobe_and_sum_to_one() {
        let p = Plastic::new(Vec3::new(0.8, 0.4, 0.2), 0.09, 1.5, 1.0, Vec3::ONE);
        let wi = Vec3::new(0.3, 0.0, 0.954).normalize();
        let wo = Vec3::new(-0.3, 0.1, 0.95).normalize();
        let w = ClassWeights::of(&p, &BsdfQueryRecord::pair(wi, wo));
        // Near the mirror direction both lobes contribute.
        assert!(
            w.diffuse.min_element() > 0.01 && w.glossy.min_element() > 0.01,
            "{w:?}"
        );
        assert!(((w.diffuse + w.glossy) - Vec3::ONE).abs().max_element() < 1e-5);
        let d = ClassWeights::of(
            &Diffuse::new(Vec3::splat(0.5)),
            &BsdfQueryRecord::pair(wi, wo),
        );
        assert_eq!(d.diffuse, Vec3::ONE);
        assert_eq!(d.glossy, Vec3::ZERO);
        let mut s = LightSplit::default();
        s.bounced(Vec3::splat(2.0), &w, true);
        s.bounced(Vec3::ONE, &ClassWeights::default(), false);
        assert!((s.total() - Vec3::splat(3.0)).abs().max_element() < 1e-5);
        assert_eq!(s.indirect[2], Vec3::ONE);
    }

    fn principled(metallic: f32, transmission: f32, coat: f32, sheen: f32) -> Principled {
        Principled {
            base_color: Vec3::new(0.7, 0.4, 0.2),
            metallic,
            roughness: 0.4,
            ior: 1.45,
            specular_level: 0.5,
            transmission,
            coat_weight: coat,
            coat_roughness: 0.2,
            sheen_weight: sheen,
            ..Principled::lobe_only()
        }
    }

    /// Over random direction pairs, every BSDF's diffuse and glossy parts are non-negative and
    /// at most its value; on the reflection side of an opaque BSDF they are all of it; a
    /// dielectric's refraction is neither (transmission).
    #[test]
    fn splits_are_parts_of_the_value() {
        let color = Vec3::new(0.8, 0.5, 0.3);
        let kinds = [
            (
                ClosureKind::Principled(principled(0.0, 0.0, 0.0, 0.0)),
                "plastic",
            ),
            (
                ClosureKind::Principled(principled(0.0, 0.0, 0.6, 0.8)),
                "sheen+coat",
            ),
            (
                ClosureKind::Principled(principled(1.0, 0.0, 0.5, 0.0)),
                "coated metal",
            ),
            (
                ClosureKind::Principled(principled(0.0, 1.0, 0.0, 0.0)),
                "glass",
            ),
            (
                ClosureKind::Glass {
                    beckmann: false,
                    color,
                    roughness: 0.3,
                    ior: 1.5,
                    multiscatter: true,
                    tint: Vec3::ONE,
                },
                "glass bsdf",
            ),
            (
                ClosureKind::Glossy {
                    beckmann: false,
                    color,
                    roughness: 0.3,
                    anisotropy: 0.0,
                    rotation: 0.0,
                    multiscatter: true,
                    tint: Vec3::ONE,
                },
                "glossy",
            ),
            (ClosureKind::Translucent { color }, "translucent"),
            (ClosureKind::lambert(color), "diffuse"),
        ];
        let mut rng = Sampler::new(5, 0, 0);
        for (kind, name) in kinds {
            let (mut reflected, mut refracted) = (0, 0);
            for i in 0..4000 {
                let c = Closure {
                    weight: Vec3::ONE,
                    normal: Vec3::ZERO,
                    tangent: Vec3::ZERO,
                    surface_normal: Vec3::ZERO,
                    kind,
                };
                let b = from_closure(&c, (i as f32 + 0.5) / 4000.0);
                let mut wi = square_to_uniform_sphere(rng.next_2d());
                wi.z = wi.z.abs().max(0.05);
                let wi = wi.normalize();
                let wo = square_to_uniform_sphere(rng.next_2d());
                let rec = BsdfQueryRecord::pair(wi, wo);
                let f = b.eval(&rec);
                let [d, g] = b.eval_split(&rec);
                let tol = 1e-4 * f.max_element() + 1e-7;
                assert!(d.min_element() >= 0.0 && g.min_element() >= 0.0, "{name}");
                assert!(
                    ((d + g) - f).max_element() <= tol,
                    "{name}: {d} + {g} > {f}"
                );
                if f.max_element() > 0.0 {
                    if wo.z > 0.0 {
                        reflected += 1;
                        assert!((f - (d + g)).abs().max_element() <= tol, "{name}");
                    } else {
                        refracted += 1;
                        if !name.contains("translucent") {
                            assert_eq!(d + g, Vec3::ZERO, "{name}: refraction is transmission");
                        } else {
                            assert_eq!(d, f, "{name}: translucent is diffuse");
                        }
                    }
                }
            }
            if !name.contains("translucent") {
                assert!(reflected > 100, "{name}: {reflected} reflections tested");
            }
            if name.contains("glass") || name.contains("translucent") {
                assert!(refracted > 100, "{name}: {refracted} refractions tested");
            }
        }
        // Sheen is diffuse, the coat glossy: a sheen over a plain diffuse base is all diffuse.
        let mut p = principled(0.0, 0.0, 0.0, 1.0);
        p.specular_level = 0.0;
        let c = Closure {
            weight: Vec3::ONE,
            normal: Vec3::ZERO,
            tangent: Vec3::ZERO,
            surface_normal: Vec3::ZERO,
            kind: ClosureKind::Principled(p),
        };
        let rec = BsdfQueryRecord::pair(Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.3, 0.2, 0.93));
        let b = from_closure(&c, 0.9);
        let [d, g] = b.eval_split(&rec);
        assert!(g == Vec3::ZERO && (d - b.eval(&rec)).abs().max_element() < 1e-6);
    }
}
