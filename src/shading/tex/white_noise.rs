//! Blender's White Noise Texture (`ShaderNodeTexWhiteNoise`), as Cycles' `svm_node_tex_white_noise`.
//!
//! The output is a pure hash of the input's bit patterns (no scale, no interpolation): every
//! distinct float coordinate gives an independent uniform value in `[0, 1]`.

use glam::{Vec2, Vec3, Vec4};

use super::hash::{
    hash_float_to_float, hash_float_to_float3, hash_float2_to_float, hash_float2_to_float3,
    hash_float3_to_float, hash_float3_to_float3, hash_float4_to_float, hash_float4_to_float3,
};

/// White noise at `p` (and `w`) for `dimensions` 1–4, returning `(Value, Color)`.
///
/// * 1D hashes `w`; 2D hashes `(p.x, p.y)`; 3D hashes `p`; 4D hashes `(p, w)`.
/// * `Value = hash_floatN_to_float(k)`, `Color = hash_floatN_to_float3(k)` (Cycles' lookup3
///   hashes of the IEEE bit patterns, mapped to `[0, 1]` by `n * 2^-32`).
/// * `Value` and `Color.x` are the same number.
///
/// Any input (NaN, ±Inf, −0.0 …) is hashed by its bits, so the output is always in `[0, 1]`.
/// Note `0.0` and `-0.0` hash differently, as in Cycles. `dimensions` outside 1–4 is clamped.
#[inline]
pub fn white_noise(dimensions: u8, p: Vec3, w: f32) -> (f32, Vec3) {
    match dimensions {
        0 | 1 => (hash_float_to_float(w), hash_float_to_float3(w)),
        2 => {
            let k = Vec2::new(p.x, p.y);
            (hash_float2_to_float(k), hash_float2_to_float3(k))
        }
        3 => (hash_float3_to_float(p), hash_float3_to_float3(p)),
        _ => {
            let k = Vec4::new(p.x, p.y, p.z, w);
            (hash_float4_to_float(k), hash_float4_to_float3(k))
        }
    }
}

/// The `Value` output only (one hash instead of three).
#[inline]
pub fn white_noise_value(dimensions: u8, p: Vec3, w: f32) -> f32 {
    match dimensions {
        0 | 1 => hash_float_to_float(w),
        2 => hash_float2_to_float(Vec2::new(p.x, p.y)),
        3 => hash_float3_to_float(p),
        _ => hash_float4_to_float(Vec4::new(p.x, p.y, p.z, w)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_equals_color_x_and_in_range() {
        let pts = [
            (Vec3::new(0.0, 0.0, 0.0), 0.0),
            (Vec3::new(-1.5, 2.25, 1e30), -7.0),
            (
                Vec3::new(f32::NAN, f32::INFINITY, f32::NEG_INFINITY),
                f32::NAN,
            ),
        ];
        for d in 0..=6u8 {
            for &(p, w) in &pts {
                let (v, c) = white_noise(d, p, w);
                assert_eq!(v, c.x);
                assert_eq!(v, white_noise_value(d, p, w));
                for x in [v, c.y, c.z] {
                    assert!((0.0..=1.0).contains(&x), "{d} {p} {w} -> {x}");
                }
            }
        }
    }
}
