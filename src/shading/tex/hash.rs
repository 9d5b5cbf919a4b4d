//! Blender's hashes (Bob Jenkins' lookup3, as in Cycles' `util/hash.h`): the random numbers behind
//! every procedural texture, bit for bit, so that a procedural looks the same as in Cycles.
//!
//! * `hash_uintN(k…)`: lookup3 with the initial value `0xdeadbeef + (N << 2) + 13`; for N = 4 one
//!   `mix` of the first three keys precedes the final round. The result is `c`.
//! * `hash_floatN_to_float(k)`: the hash of the IEEE bit patterns, mapped to `[0, 1]` by
//!   `n as f32 · 2⁻³²` (Cycles' `uint_to_float_incl`).
//! * `hash_floatN_to_floatM(k)`: `M` such hashes of the key and of the key with permuted or
//!   appended components (as Cycles' functions of the same names).
//!
//! Verified against Cycles 5.0 renders of the White Noise texture (1D–4D, Value and Color, all
//! bit-identical) and, through the random offsets and lattice hashes, the Noise texture.

use glam::{Vec2, Vec3, Vec4};

#[inline(always)]
const fn rot(x: u32, k: u32) -> u32 {
    x.rotate_left(k)
}

/// lookup3 `mix(a, b, c)`.
#[inline(always)]
const fn mix(mut a: u32, mut b: u32, mut c: u32) -> (u32, u32, u32) {
    a = a.wrapping_sub(c);
    a ^= rot(c, 4);
    c = c.wrapping_add(b);
    b = b.wrapping_sub(a);
    b ^= rot(a, 6);
    a = a.wrapping_add(c);
    c = c.wrapping_sub(b);
    c ^= rot(b, 8);
    b = b.wrapping_add(a);
    a = a.wrapping_sub(c);
    a ^= rot(c, 16);
    c = c.wrapping_add(b);
    b = b.wrapping_sub(a);
    b ^= rot(a, 19);
    a = a.wrapping_add(c);
    c = c.wrapping_sub(b);
    c ^= rot(b, 4);
    b = b.wrapping_add(a);
    (a, b, c)
}

/// lookup3 `final(a, b, c)`, returning the new `c` (the only word Cycles uses).
#[inline(always)]
const fn finalize(mut a: u32, mut b: u32, mut c: u32) -> u32 {
    c ^= b;
    c = c.wrapping_sub(rot(b, 14));
    a ^= c;
    a = a.wrapping_sub(rot(c, 11));
    b ^= a;
    b = b.wrapping_sub(rot(a, 25));
    c ^= b;
    c = c.wrapping_sub(rot(b, 16));
    a ^= c;
    a = a.wrapping_sub(rot(c, 4));
    b ^= a;
    b = b.wrapping_sub(rot(a, 14));
    c ^= b;
    c = c.wrapping_sub(rot(b, 24));
    c
}

/// lookup3's initial value for `n` 32-bit keys.
const fn init(n: u32) -> u32 {
    0xdead_beef_u32.wrapping_add(n << 2).wrapping_add(13)
}

/// Cycles' `hash_uint`.
#[inline]
pub const fn hash_uint(kx: u32) -> u32 {
    let i = init(1);
    finalize(i.wrapping_add(kx), i, i)
}

/// Cycles' `hash_uint2`.
#[inline]
pub const fn hash_uint2(kx: u32, ky: u32) -> u32 {
    let i = init(2);
    finalize(i.wrapping_add(kx), i.wrapping_add(ky), i)
}

/// Cycles' `hash_uint3`.
#[inline]
pub const fn hash_uint3(kx: u32, ky: u32, kz: u32) -> u32 {
    let i = init(3);
    finalize(i.wrapping_add(kx), i.wrapping_add(ky), i.wrapping_add(kz))
}

/// Cycles' `hash_uint4`: `mix` over `(kx, ky, kz)`, then `kw` added to `a` and `final`.
#[inline]
pub const fn hash_uint4(kx: u32, ky: u32, kz: u32, kw: u32) -> u32 {
    let i = init(4);
    let (a, b, c) = mix(i.wrapping_add(kx), i.wrapping_add(ky), i.wrapping_add(kz));
    finalize(a.wrapping_add(kw), b, c)
}

/// A hash mapped to `[0, 1]`: Cycles' `uint_to_float_incl`, `n as f32 * (1 / 0xFFFFFFFF as f32)`.
/// `0xFFFFFFFF as f32` rounds to 2^32, so this is an exact scaling by 2^-32 of the rounded `n`
/// (and `u32::MAX` maps to exactly 1.0).
#[inline]
pub const fn uint_to_float_incl(n: u32) -> f32 {
    n as f32 * (1.0 / u32::MAX as f32)
}

/// `hash_uint(k)` in `[0, 1]`.
#[inline]
pub const fn hash_uint_to_float(k: u32) -> f32 {
    uint_to_float_incl(hash_uint(k))
}

/// `hash_uint2(kx, ky)` in `[0, 1]`.
#[inline]
pub const fn hash_uint2_to_float(kx: u32, ky: u32) -> f32 {
    uint_to_float_incl(hash_uint2(kx, ky))
}

/// `hash_uint3(kx, ky, kz)` in `[0, 1]`.
#[inline]
pub const fn hash_uint3_to_float(kx: u32, ky: u32, kz: u32) -> f32 {
    uint_to_float_incl(hash_uint3(kx, ky, kz))
}

/// `hash_uint4(kx, ky, kz, kw)` in `[0, 1]`.
#[inline]
pub const fn hash_uint4_to_float(kx: u32, ky: u32, kz: u32, kw: u32) -> f32 {
    uint_to_float_incl(hash_uint4(kx, ky, kz, kw))
}

/// Hash of `k`'s bits in `[0, 1]`.
#[inline]
pub const fn hash_float_to_float(k: f32) -> f32 {
    hash_uint_to_float(k.to_bits())
}

/// Hash of the bits of `(k.x, k.y)` in `[0, 1]`.
#[inline]
pub const fn hash_float2_to_float(k: Vec2) -> f32 {
    hash_uint2_to_float(k.x.to_bits(), k.y.to_bits())
}

/// Hash of the bits of `(k.x, k.y, k.z)` in `[0, 1]`.
#[inline]
pub const fn hash_float3_to_float(k: Vec3) -> f32 {
    hash_uint3_to_float(k.x.to_bits(), k.y.to_bits(), k.z.to_bits())
}

/// Hash of the bits of `(k.x, k.y, k.z, k.w)` in `[0, 1]`.
#[inline]
pub fn hash_float4_to_float(k: Vec4) -> f32 {
    hash_uint4_to_float(k.x.to_bits(), k.y.to_bits(), k.z.to_bits(), k.w.to_bits())
}

/// `(h(k), h(k, 1))`.
#[inline]
pub fn hash_float_to_float2(k: f32) -> Vec2 {
    Vec2::new(
        hash_float_to_float(k),
        hash_float2_to_float(Vec2::new(k, 1.0)),
    )
}

/// `(h(k), h(k.x, k.y, 1))`.
#[inline]
pub fn hash_float2_to_float2(k: Vec2) -> Vec2 {
    Vec2::new(
        hash_float2_to_float(k),
        hash_float3_to_float(Vec3::new(k.x, k.y, 1.0)),
    )
}

/// `(h(x, y, z), h(z, x, y))`.
#[inline]
pub fn hash_float3_to_float2(k: Vec3) -> Vec2 {
    Vec2::new(
        hash_float3_to_float(k),
        hash_float3_to_float(Vec3::new(k.z, k.x, k.y)),
    )
}

/// `(h(x, y, z, w), h(z, x, w, y))`.
#[inline]
pub fn hash_float4_to_float2(k: Vec4) -> Vec2 {
    Vec2::new(
        hash_float4_to_float(k),
        hash_float4_to_float(Vec4::new(k.z, k.x, k.w, k.y)),
    )
}

/// `(h(k), h(k, 1), h(k, 2))`.
#[inline]
pub fn hash_float_to_float3(k: f32) -> Vec3 {
    Vec3::new(
        hash_float_to_float(k),
        hash_float2_to_float(Vec2::new(k, 1.0)),
        hash_float2_to_float(Vec2::new(k, 2.0)),
    )
}

/// `(h(x, y), h(x, y, 1), h(x, y, 2))`.
#[inline]
pub fn hash_float2_to_float3(k: Vec2) -> Vec3 {
    Vec3::new(
        hash_float2_to_float(k),
        hash_float3_to_float(Vec3::new(k.x, k.y, 1.0)),
        hash_float3_to_float(Vec3::new(k.x, k.y, 2.0)),
    )
}

/// `(h(x, y, z), h(x, y, z, 1), h(x, y, z, 2))`.
#[inline]
pub fn hash_float3_to_float3(k: Vec3) -> Vec3 {
    Vec3::new(
        hash_float3_to_float(k),
        hash_float4_to_float(Vec4::new(k.x, k.y, k.z, 1.0)),
        hash_float4_to_float(Vec4::new(k.x, k.y, k.z, 2.0)),
    )
}

/// `(h(x, y, z, w), h(z, x, w, y), h(w, z, y, x))`.
#[inline]
pub fn hash_float4_to_float3(k: Vec4) -> Vec3 {
    Vec3::new(
        hash_float4_to_float(k),
        hash_float4_to_float(Vec4::new(k.z, k.x, k.w, k.y)),
        hash_float4_to_float(Vec4::new(k.w, k.z, k.y, k.x)),
    )
}

/// `(h(x, y, z, w), h(w, x, y, z), h(z, w, x, y), h(y, z, w, x))`.
#[inline]
pub fn hash_float4_to_float4(k: Vec4) -> Vec4 {
    Vec4::new(
        hash_float4_to_float(k),
        hash_float4_to_float(Vec4::new(k.w, k.x, k.y, k.z)),
        hash_float4_to_float(Vec4::new(k.z, k.w, k.x, k.y)),
        hash_float4_to_float(Vec4::new(k.y, k.z, k.w, k.x)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference implementation of lookup3's `final`/`mix` straight from the C macros, to
    /// check the const rewrite.
    #[test]
    fn integer_hashes_are_lookup3() {
        fn reference(keys: &[u32]) -> u32 {
            let mut a = 0xdeadbeef_u32
                .wrapping_add((keys.len() as u32) << 2)
                .wrapping_add(13);
            let (mut b, mut c) = (a, a);
            let r = |x: u32, k: u32| x.rotate_left(k);
            let mut k = keys;
            while k.len() > 3 {
                a = a.wrapping_add(k[0]);
                b = b.wrapping_add(k[1]);
                c = c.wrapping_add(k[2]);
                a = a.wrapping_sub(c);
                a ^= r(c, 4);
                c = c.wrapping_add(b);
                b = b.wrapping_sub(a);
                b ^= r(a, 6);
                a = a.wrapping_add(c);
                c = c.wrapping_sub(b);
                c ^= r(b, 8);
                b = b.wrapping_add(a);
                a = a.wrapping_sub(c);
                a ^= r(c, 16);
                c = c.wrapping_add(b);
                b = b.wrapping_sub(a);
                b ^= r(a, 19);
                a = a.wrapping_add(c);
                c = c.wrapping_sub(b);
                c ^= r(b, 4);
                b = b.wrapping_add(a);
                k = &k[3..];
            }
            if k.len() > 2 {
                c = c.wrapping_add(k[2]);
            }
            if k.len() > 1 {
                b = b.wrapping_add(k[1]);
            }
            a = a.wrapping_add(k[0]);
            c ^= b;
            c = c.wrapping_sub(r(b, 14));
            a ^= c;
            a = a.wrapping_sub(r(c, 11));
            b ^= a;
            b = b.wrapping_sub(r(a, 25));
            c ^= b;
            c = c.wrapping_sub(r(b, 16));
            a ^= c;
            a = a.wrapping_sub(r(c, 4));
            b ^= a;
            b = b.wrapping_sub(r(a, 14));
            c ^= b;
            c = c.wrapping_sub(r(b, 24));
            c
        }
        for &(x, y, z, w) in &[
            (0u32, 0u32, 0u32, 0u32),
            (1, 2, 3, 4),
            (u32::MAX, 7, 0x8000_0000, 12345),
        ] {
            assert_eq!(hash_uint(x), reference(&[x]));
            assert_eq!(hash_uint2(x, y), reference(&[x, y]));
            assert_eq!(hash_uint3(x, y, z), reference(&[x, y, z]));
            assert_eq!(hash_uint4(x, y, z, w), reference(&[x, y, z, w]));
        }
    }

    /// Values measured from Cycles 5.0 (bpy 5.0.1) renders of the White Noise texture
    /// (Emission, 1 spp, 32-bit EXR), pixel values compared bit for bit.
    #[test]
    fn matches_cycles_white_noise() {
        // (key, Cycles Value, Cycles Color)
        for &(k, v, c) in MEASURED_1D {
            assert_eq!(hash_float_to_float(k), v, "1D {k}");
            assert_eq!(hash_float_to_float3(k), Vec3::from(c), "1D {k}");
        }
        for &(k, v, c) in MEASURED_2D {
            assert_eq!(hash_float2_to_float(Vec2::from(k)), v, "2D {k:?}");
            assert_eq!(
                hash_float2_to_float3(Vec2::from(k)),
                Vec3::from(c),
                "2D {k:?}"
            );
        }
        for &(k, v, c) in MEASURED_3D {
            assert_eq!(hash_float3_to_float(Vec3::from(k)), v, "3D {k:?}");
            assert_eq!(
                hash_float3_to_float3(Vec3::from(k)),
                Vec3::from(c),
                "3D {k:?}"
            );
        }
        for &(k, v, c) in MEASURED_4D {
            assert_eq!(hash_float4_to_float(Vec4::from(k)), v, "4D {k:?}");
            assert_eq!(
                hash_float4_to_float3(Vec4::from(k)),
                Vec3::from(c),
                "4D {k:?}"
            );
        }
    }

    #[test]
    fn unit_range() {
        assert_eq!(uint_to_float_incl(0), 0.0);
        assert_eq!(uint_to_float_incl(u32::MAX), 1.0);
        for k in [0.0f32, -0.0, 1.0, f32::NAN, f32::INFINITY, -1e30, 1e-40] {
            let v = hash_float4_to_float4(Vec4::splat(k));
            assert!(v.cmpge(Vec4::ZERO).all() && v.cmple(Vec4::ONE).all());
        }
    }

    // Keys and Cycles' pixel values (generated from the renders by a scratch script).
    #[rustfmt::skip]
    const MEASURED_1D: &[(f32, f32, [f32; 3])] = &[
        (0.0, 0.58242583, [0.58242583, 0.14955954, 0.544475]),
        (0.5, 0.98331493, [0.98331493, 0.25982833, 0.34820783]),
        (-2.0, 0.07574295, [0.07574295, 0.3071098, 0.034658656]),
        (1.9375, 0.026480563, [0.026480563, 0.3883663, 0.15941173]),
        (-1001.7, 0.44265962, [0.44265962, 0.69713026, 0.8506489]),
        (-1002.14, 0.89951307, [0.89951307, 0.13822927, 0.4807016]),
        (-1000.348, 0.15556684, [0.15556684, 0.26999974, 0.47537726]),
        (-1002.937, 0.1991312, [0.1991312, 0.75229114, 0.53226477]),
    ];
    #[rustfmt::skip]
    const MEASURED_2D: &[([f32; 2], f32, [f32; 3])] = &[
        ([0.0, 0.0], 0.86031276, [0.86031276, 0.62453455, 0.9908382]),
        ([0.5, -0.75], 0.25439468, [0.25439468, 0.73877394, 0.506049]),
        ([-2.0, 1.9375], 0.047260273, [0.047260273, 0.67367417, 0.23191227]),
        ([1.9375, -1.6875], 0.095924035, [0.095924035, 0.732638, 0.49824214]),
        ([1000.25, -999.5], 0.01369765, [0.01369765, 0.97345793, 0.46355644]),
        ([1000.482, -999.896], 0.40819424, [0.40819424, 0.4538051, 0.70735365]),
        ([999.322, -998.477], 0.894731, [0.894731, 0.17366731, 0.062199898]),
        ([1001.149, -1000.391], 0.19125609, [0.19125609, 0.3474574, 0.16813189]),
    ];
    #[rustfmt::skip]
    const MEASURED_3D: &[([f32; 3], f32, [f32; 3])] = &[
        ([0.0, 0.0, 0.0], 0.61106765, [0.61106765, 0.10291273, 0.8651527]),
        ([0.5, -0.75, 0.0], 0.09688488, [0.09688488, 0.095547125, 0.97904056]),
        ([-2.0, 1.9375, 0.0], 0.7652448, [0.7652448, 0.53360516, 0.17226547]),
        ([1.9375, -1.6875, 0.0], 0.9386821, [0.9386821, 0.49675754, 0.61702394]),
        ([1000.25, -999.5, 1003.1], 0.3528206, [0.3528206, 0.50254565, 0.40798992]),
        ([1000.482, -999.896, 1003.456], 0.65480155, [0.65480155, 0.41295218, 0.54935515]),
        ([999.322, -998.477, 1002.03296], 0.706901, [0.706901, 0.7460527, 0.24063317]),
        ([1001.149, -1000.391, 1004.06995], 0.41942424, [0.41942424, 0.7362089, 0.20977792]),
    ];
    #[rustfmt::skip]
    const MEASURED_4D: &[([f32; 4], f32, [f32; 3])] = &[
        ([0.0, 0.0, 0.0, 0.0], 0.111572966, [0.111572966, 0.111572966, 0.111572966]),
        ([0.5, -0.75, 0.0, 0.5], 0.17816027, [0.17816027, 0.49454194, 0.40474543]),
        ([-2.0, 1.9375, 0.0, -2.0], 0.38700494, [0.38700494, 0.70481414, 0.10431721]),
        ([1.9375, -1.6875, 0.0, 1.9375], 0.7254635, [0.7254635, 0.5213228, 0.82445765]),
        ([1000.25, -999.5, 1003.1, -1001.7], 0.5029108, [0.5029108, 0.011304746, 0.53936934]),
        ([1000.482, -999.896, 1003.456, -1002.14], 0.029186027, [0.029186027, 0.5847514, 0.9683121]),
        ([999.322, -998.477, 1002.03296, -1000.348], 0.6111739, [0.6111739, 0.27432355, 0.77226704]),
        ([1001.149, -1000.391, 1004.06995, -1002.937], 0.40116754, [0.40116754, 0.19577956, 0.22930926]),
    ];
}
