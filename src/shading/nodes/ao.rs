//! The Ambient Occlusion node (Cycles' `svm_node_ao`): the fraction of `samples` rays, cosine
//! distributed about the normal (its opposite with Inside), that travel `Distance` without
//! meeting a surface (of any object, or with Only Local of the point's own). `AO` is that
//! fraction, `Color` the input colour times it. Where nothing can be traced (a world or
//! light graph, a distance ≤ 0) it is 1, as in Cycles.

use crate::frame::Frame;
use crate::sampler::SobolSampler;
use crate::sampling::square_to_uniform_disk;
use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::{ShadeEnv, ShaderGlobals};
use crate::shading::program::{Op, Slot, Slots};
use glam::Vec3;

/// Most rays one node casts (Blender's limit of the Samples property).
pub const MAX_SAMPLES: u32 = 128;

#[derive(Clone, Copy, Debug)]
pub struct AoOp {
    color: Slot,
    distance: Slot,
    /// The Normal input when linked (else the shading normal).
    normal: Option<Slot>,
    samples: u32,
    inside: bool,
    only_local: bool,
    out_color: Slot,
    out_ao: Slot,
}

/// The unoccluded fraction at `g` about the unit normal `n` (Blender world space): `samples`
/// directions from a scrambled (0,2)-sequence seeded by the point, through the concentric
/// disk to the cosine-weighted hemisphere (Cycles' uniform disk lifted to the hemisphere).
pub fn ambient_occlusion(
    g: &ShaderGlobals,
    env: &ShadeEnv,
    n: Vec3,
    distance: f32,
    samples: u32,
    only_local: bool,
) -> f32 {
    let Some(tracer) = env.tracer else {
        return 1.0;
    };
    if distance.is_nan() || distance <= 0.0 || samples == 0 || g.object[0] == u32::MAX {
        return 1.0;
    }
    let frame = Frame::from_normal(n);
    let mut open = 0u32;
    for k in 0..samples {
        let mut rng = SobolSampler::new(g.seed as u64, 0x414f, k as u64);
        let d = square_to_uniform_disk(rng.next_2d());
        let z = (1.0 - d.length_squared()).max(0.0).sqrt();
        let w = frame.to_world(Vec3::new(d.x, d.y, z));
        if !tracer.blocked(g, w, distance, only_local) {
            open += 1;
        }
    }
    open as f32 / samples as f32
}

impl AoOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals, env: &ShadeEnv) {
        let n = match self.normal {
            Some(slot) => s.v(slot).try_normalize().unwrap_or(g.n),
            None => g.n,
        };
        let n = if self.inside { -n } else { n };
        let ao = ambient_occlusion(g, env, n, s.f(self.distance), self.samples, self.only_local);
        s.set_f(self.out_ao, ao);
        s.set_v(self.out_color, s.v(self.color) * ao);
    }
}

pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    if kind != "ShaderNodeAmbientOcclusion" {
        return Ok(false);
    }
    let color = cx.color("Color", Vec3::ONE)?;
    let distance = cx.float("Distance", 1.0)?;
    let normal = cx.linked_vector("Normal")?;
    let samples = cx.prop_f32("samples", 16.0).clamp(1.0, MAX_SAMPLES as f32) as u32;
    let out_color = cx.output("Color", SocketType::Color)?;
    let out_ao = cx.output("AO", SocketType::Float)?;
    cx.emit(
        Op::Ao(AoOp {
            color,
            distance,
            normal,
            samples,
            inside: cx.prop_bool("inside", false),
            only_local: cx.prop_bool("only_local", false),
            out_color,
            out_ao,
        }),
        true,
    );
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::globals::Tracer;
    use glam::Vec2;

    /// Blocks every ray closer than `cos_max` to the normal +Z (a cone of surfaces overhead),
    /// or with `local` only rays that ask for any object.
    struct Cone {
        cos_max: f32,
    }

    impl Tracer for Cone {
        fn blocked(&self, _g: &ShaderGlobals, d: Vec3, tmax: f32, only_local: bool) -> bool {
            !only_local && tmax > 0.5 && d.z > self.cos_max
        }

        fn local_hits(
            &self,
            _g: &ShaderGlobals,
            _o: Vec3,
            _d: Vec3,
            _tmax: f32,
            _hits: &mut [crate::shading::globals::LocalHit],
        ) -> usize {
            0
        }
    }

    fn env_with(tracer: &dyn Tracer) -> ShadeEnv<'_> {
        ShadeEnv {
            images: &[],
            textures: &[],
            camera_to_world: glam::Mat4::IDENTITY,
            window: &crate::camera::NO_WINDOW,
            tracer: Some(tracer),
        }
    }

    fn at_origin(seed: u32) -> ShaderGlobals<'static> {
        let mut g = ShaderGlobals::at(Vec3::ZERO, Vec3::Y, Vec2::ZERO); // Blender +Z
        g.object = [0, u32::MAX];
        g.seed = seed;
        g
    }

    #[test]
    fn open_fraction_is_the_cosine_weighted_measure_outside_the_cone() {
        // Cosine-weighted directions: P(cos θ > c) = 1 - c². Averaged over many points (seeds)
        // the fraction left open is c²; a uniform-hemisphere sampler would give c.
        let cone = Cone { cos_max: 0.6 };
        let env = env_with(&cone);
        let n = 4000;
        let mean: f32 = (0..n)
            .map(|i| ambient_occlusion(&at_origin(i), &env, Vec3::Z, 1.0, 16, false))
            .sum::<f32>()
            / n as f32;
        assert!(
            (mean - 0.36).abs() < 0.01,
            "open fraction {mean}, expected 0.36"
        );
        // Short rays, local-only queries, no scene, or no object: nothing blocks.
        assert_eq!(
            ambient_occlusion(&at_origin(1), &env, Vec3::Z, 0.4, 16, false),
            1.0
        );
        assert_eq!(
            ambient_occlusion(&at_origin(1), &env, Vec3::Z, 1.0, 16, true),
            1.0
        );
        let none = ShadeEnv {
            tracer: None,
            ..env
        };
        assert_eq!(
            ambient_occlusion(&at_origin(1), &none, Vec3::Z, 1.0, 16, false),
            1.0
        );
        let mut world = at_origin(1);
        world.object = [u32::MAX; 2];
        assert_eq!(
            ambient_occlusion(&world, &env, Vec3::Z, 1.0, 16, false),
            1.0
        );
    }

    #[test]
    fn samples_of_one_point_are_stratified() {
        // Sixteen scrambled (0,2) points: the open fraction of one point is within a couple
        // of samples of the expectation (independent samples: a standard deviation of 0.12).
        let cone = Cone { cos_max: 0.6 };
        let env = env_with(&cone);
        let worst = (0..500)
            .map(|i| (ambient_occlusion(&at_origin(i), &env, Vec3::Z, 1.0, 16, false) - 0.36).abs())
            .fold(0.0f32, f32::max);
        assert!(worst <= 0.2, "worst deviation {worst}");
    }
}
