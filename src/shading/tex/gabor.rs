//! Blender's Gabor Texture (`ShaderNodeTexGabor`, Blender 4.3+), as Cycles' `svm_node_tex_gabor`:
//! sparse-convolution Gabor noise (Tricard et al. 2019's phasor formulation).
//!
//! Space is cut into unit cells; each cell holds [`IMPULSES`] kernels at hashed centres, with
//! hashed signs and (for isotropic noise) hashed orientations. A kernel is a Gaussian windowed
//! by a Hann window to the unit disk/ball, times the complex sinusoid `e^{2πi f·x}`; the point's
//! phasor sums the kernels of its own and the neighbouring cells. `Value` is the imaginary part,
//! `Intensity` the modulus and `Phase` the argument, normalised as Blender normalises them.

use super::hash::{
    hash_float3_to_float, hash_float3_to_float2, hash_float4_to_float, hash_float4_to_float2,
    hash_float4_to_float3,
};
use glam::{Vec2, Vec3, Vec4};
use std::f32::consts::PI;

/// Kernels per cell.
const IMPULSES: usize = 8;

/// `(r cos φ, r sin φ)`.
#[inline]
fn polar(r: f32, phi: f32) -> Vec2 {
    Vec2::new(r * phi.cos(), r * phi.sin())
}

/// The windowed Gaussian envelope at squared distance `d2`, and the phasor of angle `angle`.
#[inline]
fn kernel(d2: f32, angle: f32) -> Vec2 {
    let hann = 0.5 + 0.5 * (PI * d2).cos();
    let gauss = (-PI * d2).exp();
    polar(gauss * hann, angle)
}

#[inline]
fn dot2(a: Vec2, b: Vec2) -> f32 {
    a.x * b.x + a.y * b.y
}

#[inline]
fn dot3(a: Vec3, b: Vec3) -> f32 {
    a.x * b.x + a.y * b.y + a.z * b.z
}

fn cell_2d(cell: Vec2, p: Vec2, frequency: f32, isotropy: f32, base: f32) -> Vec2 {
    let mut noise = Vec2::ZERO;
    for i in 0..IMPULSES {
        let k = (i * 3) as f32;
        let random = (hash_float3_to_float(cell.extend(k)) - 0.5) * PI;
        let orientation = base + random * isotropy;
        let centre = hash_float3_to_float2(cell.extend(k + 1.0));
        let q = p - centre;
        let d2 = dot2(q, q);
        if d2 >= 1.0 {
            continue;
        }
        let weight = if hash_float3_to_float(cell.extend(k + 2.0)) < 0.5 {
            -1.0
        } else {
            1.0
        };
        let angle = 2.0 * PI * dot2(q, polar(frequency, orientation));
        noise += weight * kernel(d2, angle);
    }
    noise
}

/// The orientation of a 3D kernel: the base direction turned by hashed spherical angles.
fn orientation_3d(base: Vec3, isotropy: f32, seed: Vec4) -> Vec3 {
    if isotropy == 0.0 {
        return base;
    }
    let mut inclination = base.z.acos();
    let sign = if base.y < 0.0 { -1.0 } else { 1.0 };
    let mut azimuth = sign * (base.x / (base.x * base.x + base.y * base.y).sqrt()).acos();
    let r = hash_float4_to_float2(seed) * PI;
    inclination += r.x * isotropy;
    azimuth += r.y * isotropy;
    Vec3::new(
        inclination.sin() * azimuth.cos(),
        inclination.sin() * azimuth.sin(),
        inclination.cos(),
    )
}

fn cell_3d(cell: Vec3, p: Vec3, frequency: f32, isotropy: f32, base: Vec3) -> Vec2 {
    let mut noise = Vec2::ZERO;
    for i in 0..IMPULSES {
        let k = (i * 3) as f32;
        let orientation = orientation_3d(base, isotropy, cell.extend(k));
        let centre = hash_float4_to_float3(cell.extend(k + 1.0));
        let q = p - centre;
        let d2 = dot3(q, q);
        if d2 >= 1.0 {
            continue;
        }
        let weight = if hash_float4_to_float(cell.extend(k + 2.0)) < 0.5 {
            -1.0
        } else {
            1.0
        };
        let angle = 2.0 * PI * dot3(q, frequency * orientation);
        noise += weight * kernel(d2, angle);
    }
    noise
}

/// The Gabor node's `(Value, Phase, Intensity)` at `p` (its Vector input): `three_d` selects
/// the 3D noise (orientation `orientation_3d`, normalised here) over the 2D one in the XY plane
/// (orientation angle `orientation_2d`).
pub fn gabor(
    p: Vec3,
    scale: f32,
    frequency: f32,
    anisotropy: f32,
    three_d: bool,
    orientation_2d: f32,
    orientation_3d: Vec3,
) -> (f32, f32, f32) {
    let p = p * scale;
    let isotropy = 1.0 - anisotropy.clamp(0.0, 1.0);
    let frequency = frequency.max(0.001);
    let (phasor, sd) = if three_d {
        let len = dot3(orientation_3d, orientation_3d).sqrt();
        let o = orientation_3d / len;
        let c = p.floor();
        let local = p - c;
        let mut sum = Vec2::ZERO;
        for k in -1..=1 {
            for j in -1..=1 {
                for i in -1..=1 {
                    let off = Vec3::new(i as f32, j as f32, k as f32);
                    sum += cell_3d(c + off, local - off, frequency, isotropy, o);
                }
            }
        }
        // √(impulses · second moment ½ · ∫ kernel² = 1 / (4√2)).
        (
            sum,
            (IMPULSES as f32 * 0.5 * (1.0 / (4.0 * std::f32::consts::SQRT_2))).sqrt(),
        )
    } else {
        let q = Vec2::new(p.x, p.y);
        let c = q.floor();
        let local = q - c;
        let mut sum = Vec2::ZERO;
        for j in -1..=1 {
            for i in -1..=1 {
                let off = Vec2::new(i as f32, j as f32);
                sum += cell_2d(c + off, local - off, frequency, isotropy, orientation_2d);
            }
        }
        (sum, (IMPULSES as f32 * 0.5 * 0.25).sqrt())
    };
    let norm = 6.0 * sd;
    let value = (phasor.y / norm) * 0.5 + 0.5;
    let phase = (phasor.y.atan2(phasor.x) + PI) / (2.0 * PI);
    let intensity = dot2(phasor, phasor).sqrt() / norm;
    (value, phase, intensity)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_are_finite_and_in_range_and_vary() {
        let mut values = Vec::new();
        for i in 0..400 {
            let p = Vec3::new(
                i as f32 * 0.137,
                (i * 7 % 13) as f32 * 0.29,
                i as f32 * -0.05,
            );
            for three_d in [false, true] {
                let (v, ph, it) = gabor(p, 5.0, 2.0, 0.3, three_d, 0.785, Vec3::new(1.0, 1.0, 0.0));
                assert!(v.is_finite() && ph.is_finite() && it.is_finite());
                assert!((0.0..=1.0).contains(&ph) && it >= 0.0, "{v} {ph} {it}");
                values.push(v);
            }
        }
        // A noise around ½ with a spread, not a constant.
        let mean = values.iter().sum::<f32>() / values.len() as f32;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f32>() / values.len() as f32;
        assert!(
            (mean - 0.5).abs() < 0.05 && var.sqrt() > 0.03,
            "mean {mean} sd {}",
            var.sqrt()
        );
    }

    #[test]
    fn two_d_noise_ignores_z_and_three_d_does_not() {
        let at =
            |z: f32, three_d| gabor(Vec3::new(0.3, 0.2, z), 1.0, 2.0, 0.5, three_d, 0.0, Vec3::X);
        assert_eq!(at(0.0, false), at(7.0, false));
        assert_ne!(at(0.0, true), at(0.4, true));
    }
}
