//! Blender's Brick Texture node (`ShaderNodeTexBrick`), as Cycles 5.0 evaluates it
//! (`kernel/svm/brick.h`).
//!
//! At `q = p * scale`: the row is `r = floor(q.y / row_height)`. Every `squash_frequency`-th
//! row (those with `r mod f == 0`, C's remainder) has its bricks `squash` times as wide, and
//! every `offset_frequency`-th row is shifted by `offset * width`. The brick is
//! `b = floor((q.x + shift) / width)`, and `(x, y)` the position within it. The tint
//! `t = clamp(noise((r << 16) + (b & 0xFFFF)) + bias, 0, 1)`, with Blender's integer noise, mixes
//! Color1 towards Color2; the mortar factor is 0 farther than Mortar Size from the brick's edges,
//! 1 closer (or, with Mortar Smooth > 0, `smoothstep((1 - d / size) / smooth)`).
//! Color = `mix(mix(color1, color2, t), mortar, Fac)` with Fac the mortar factor.
//!
//! The `mul_add`s reproduce the FMAs of Cycles' x86 AVX2 kernel, with which the results match
//! Cycles 5.0 renders bit for bit (without them the smooth mortar edge differs by up to 6e-5).

use glam::Vec3;

/// The node's settings and unlinked inputs (Blender's defaults in `Default`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrickParams {
    /// "Offset" (0 to 1): the shift of every `offset_frequency`-th row, in brick widths.
    pub offset: f32,
    pub offset_frequency: i32,
    /// "Squash": the width factor of every `squash_frequency`-th row.
    pub squash: f32,
    pub squash_frequency: i32,
    pub color1: Vec3,
    pub color2: Vec3,
    pub mortar: Vec3,
    pub scale: f32,
    pub mortar_size: f32,
    pub mortar_smooth: f32,
    pub bias: f32,
    pub brick_width: f32,
    pub row_height: f32,
}

impl Default for BrickParams {
    fn default() -> Self {
        Self {
            offset: 0.5,
            offset_frequency: 2,
            squash: 1.0,
            squash_frequency: 2,
            color1: Vec3::splat(0.8),
            color2: Vec3::splat(0.2),
            mortar: Vec3::ZERO,
            scale: 5.0,
            mortar_size: 0.02,
            mortar_smooth: 0.1,
            bias: 0.0,
            brick_width: 0.5,
            row_height: 0.25,
        }
    }
}

/// C's `(int)floorf(f)` as x86 computes it (`i32::MIN` for NaN and out of range).
#[inline]
fn floor_to_int(f: f32) -> i32 {
    let f = f.floor();
    if (-2_147_483_648.0..2_147_483_648.0).contains(&f) {
        f as i32
    } else {
        i32::MIN
    }
}

/// Blender's "fast integer noise": a value in `[0, 1)`.
#[inline]
fn brick_noise(n: u32) -> f32 {
    let n = n.wrapping_add(1013) & 0x7fff_ffff;
    let n = (n >> 13) ^ n;
    let nn = n
        .wrapping_mul(
            n.wrapping_mul(n)
                .wrapping_mul(60493)
                .wrapping_add(19_990_303),
        )
        .wrapping_add(1_376_312_589)
        & 0x7fff_ffff;
    0.5 * (nn as f32 / 1_073_741_824.0)
}

#[inline]
fn smoothstepf(f: f32) -> f32 {
    if f <= 0.0 {
        0.0
    } else if f >= 1.0 {
        1.0
    } else {
        let ff = f * f;
        3.0f32.mul_add(ff, -(2.0 * ff * f))
    }
}

/// Cycles' `saturatef`: NaN goes to 0 (`f32::clamp` would keep it).
#[inline]
#[allow(clippy::manual_clamp)]
fn saturate(x: f32) -> f32 {
    x.max(0.0).min(1.0)
}

#[inline]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// `svm_brick` at an already scaled point: `(tint, mortar factor)`.
fn brick_tint_mortar(p: Vec3, b: &BrickParams) -> (f32, f32) {
    let row_height = b.row_height;
    let mut brick_width = b.brick_width;
    let row = floor_to_int(p.y / row_height);
    // Cycles' x86 AVX2 kernel fuses `p.x + brick_width * offset` into one FMA; so do we, or the
    // mortar's smooth edge (which amplifies the rounding of x by 1 / (size * smooth)) would
    // differ by up to ~1e-4.
    let mut shifted = p.x;
    if b.offset_frequency != 0 && b.squash_frequency != 0 {
        if row.wrapping_rem(b.squash_frequency) == 0 {
            brick_width *= b.squash;
        }
        if row.wrapping_rem(b.offset_frequency) == 0 {
            shifted = brick_width.mul_add(b.offset, p.x);
        }
    }
    let brick = floor_to_int(shifted / brick_width);
    let x = shifted - brick_width * brick as f32;
    let y = p.y - row_height * row as f32;

    let key = (row.wrapping_shl(16)).wrapping_add(brick & 0xFFFF) as u32;
    let tint = saturate(brick_noise(key) + b.bias);
    let min_dist = min(min(x, y), min(brick_width - x, row_height - y));
    let mortar = if min_dist >= b.mortar_size {
        0.0
    } else if b.mortar_smooth == 0.0 {
        1.0
    } else {
        smoothstepf((1.0 - min_dist / b.mortar_size) / b.mortar_smooth)
    };
    (tint, mortar)
}

/// The Brick Texture node: returns `(Color, Fac)` at texture coordinate `p`.
pub fn brick(p: Vec3, params: &BrickParams) -> (Vec3, f32) {
    let (tint, f) = brick_tint_mortar(p * params.scale, params);
    let mut color1 = params.color1;
    if f != 1.0 {
        color1 = Vec3::splat(tint).mul_add(params.color2, (1.0 - tint) * color1);
    }
    (params.mortar.mul_add(Vec3::splat(f), color1 * (1.0 - f)), f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_measured_from_cycles() {
        // Measured from Cycles 5.0 renders with the parameters of `measured_params`.
        let b = measured_params();
        for &(p, c, fac) in MEASURED {
            let (got, f) = brick(Vec3::from_array(p), &b);
            assert!(
                (got - Vec3::from_array(c)).abs().max_element() < 1e-6,
                "{p:?}: {got} vs {c:?}"
            );
            assert!(fac.is_nan() || (f - fac).abs() < 1e-6);
        }
    }

    fn measured_params() -> BrickParams {
        BrickParams {
            offset: 0.7,
            offset_frequency: 2,
            squash: 1.7,
            squash_frequency: 3,
            color1: Vec3::new(0.8, 0.3, 0.1),
            color2: Vec3::new(0.1, 0.4, 0.9),
            mortar: Vec3::new(0.05, 0.05, 0.02),
            scale: 2.0,
            bias: 0.3,
            brick_width: 0.6,
            row_height: 0.3,
            ..Default::default()
        }
    }

    /// (p, Color, Fac); Fac from the Color (the mortar is (0.05, 0.05, 0.02)).
    const MEASURED: &[([f32; 3], [f32; 3], f32)] = &[
        // In the smooth mortar edge, where rounding is amplified ~750 times.
        (
            [-0.8574997, 0.024500264, -0.21290995],
            [0.15008293, 0.21447977, 0.37473118],
            f32::NAN,
        ),
        ([-0.6614996, -0.6124996, 0.0061200405], [0.1, 0.4, 0.9], 0.0),
        (
            [-1.2984997, 1.0045002, -0.60147995],
            [0.41605306, 0.35484958, 0.5387965],
            0.0,
        ),
    ];

    #[test]
    fn ranges_and_no_panic() {
        let weird = [
            0.0,
            -0.0,
            1.0,
            -3.5,
            1e-30,
            1e30,
            f32::NAN,
            f32::INFINITY,
            -f32::INFINITY,
        ];
        for &x in &weird {
            for freq in [i32::MIN, -1, 0, 1, 3] {
                let b = BrickParams {
                    offset_frequency: freq,
                    squash_frequency: freq.wrapping_neg(),
                    brick_width: x,
                    row_height: 0.3,
                    ..Default::default()
                };
                let _ = brick(Vec3::new(x, 0.7, 0.0), &b);
                let _ = brick(Vec3::new(0.2, x, 0.0), &BrickParams { row_height: x, ..b });
            }
        }
        let b = BrickParams::default();
        for i in 0..500 {
            let p = Vec3::new(i as f32 * 0.0371 - 9.0, i as f32 * -0.0173 + 2.0, 0.0);
            let (c, f) = brick(p, &b);
            assert!((0.0..=1.0).contains(&f));
            assert!(c.cmpge(Vec3::ZERO).all() && c.cmple(Vec3::splat(0.8 + 1e-6)).all());
        }
    }
}
