//! Blender's Perlin noise, fractal noises and the Noise Texture node (`ShaderNodeTexNoise`),
//! following Cycles 5.0 (`kernel/svm/noise.h`, `fractal_noise.h`, `noisetex.h`) operation for
//! operation: results are bit-identical to Cycles' CPU renders (see the tests).
//!
//! Perlin noise (improved Perlin, gradient noise on the integer lattice):
//! `n(p) = multilinear blend over the 2^D cell corners c of grad(hash(c)) · (p − c)` with the
//! quintic fade `f(t) = t³(t(6t − 15) + 10)` as blend weights, corners hashed with lookup3
//! (`hash_uintN`). The signed noise `snoise` is `perlin · s_D` with OSL's experimental scales
//! `s = 0.25, 0.6616, 0.982, 0.8344` (range about `[-1, 1]`); the unsigned `noise` is
//! `0.5 · snoise + 0.5`. Before evaluation each coordinate is wrapped with `fmod(p, 100000)` (and
//! offset by 0.5 where `|p| ≥ 10⁶`), as Blender 4.x/5.x do against float precision loss.
//!
//! Rounding: the reference is Cycles' x86-64 CPU kernel as shipped (the AVX2 kernel, built by
//! GCC, which contracts `a·b + c` into FMA). Every place where that binary fuses a multiply into
//! an add is reproduced with `mul_add`; this was established by comparing against renders, not
//! guessed. 1D is Cycles' scalar code; 2D–4D follow its SIMD code: `lerp(a, b, t) =
//! fma(t, b − a, a)`, FMA fade, AVX2 corner order for 4D (w first), `fmod` as
//! `p − trunc(p · 1e-5) · 1e5` for 3D/4D. Float → int conversion mimics x86 `cvttss2si`
//! (NaN → `i32::MIN`). `f32::mul_add` is one instruction when FMA is enabled at compile time
//! (e.g. `-C target-cpu=x86-64-v3`), otherwise a libm call (correct, slower).
//!
//! The fractal functions reproduce the rounding of the Noise Texture's calls; other Cycles
//! nodes calling them (Wave, …) may be compiled with slightly different fusion at the call site.

use std::ops::{Add, Mul};

use glam::{Vec2, Vec3, Vec4};

use super::hash::{
    hash_float_to_float, hash_float2_to_float, hash_uint, hash_uint2, hash_uint3, hash_uint4,
};

// ---------------------------------------------------------------------------------------------
// Helpers.

/// Float → int as C's `(int)f` compiles on x86 (`cvttss2si`): truncation, and `i32::MIN` for NaN
/// and values out of range.
#[inline(always)]
fn float_to_int(f: f32) -> i32 {
    if (-2147483648.0..2147483648.0).contains(&f) {
        f as i32
    } else {
        i32::MIN
    }
}

/// `(x − ⌊x⌋, ⌊x⌋ as int)` (Cycles' `floorfrac`).
#[inline(always)]
fn floorfrac(x: f32) -> (f32, u32) {
    let f = x.floor();
    (x - f, float_to_int(f) as u32)
}

/// Cycles' `mix(a, b, t) = a + t·(b − a)`, with the multiply fused into the add:
/// `fma(t, b − a, a)`.
#[inline(always)]
fn mix(a: f32, b: f32, t: f32) -> f32 {
    t.mul_add(b - a, a)
}

/// Scalar quintic fade `t·t·t·(t·(t·6 − 15) + 10)` (Cycles' scalar `fade`, used by 1D), the two
/// inner multiply-adds fused.
#[inline(always)]
fn fade(t: f32) -> f32 {
    t * t * t * t.mul_add(t.mul_add(6.0, -15.0), 10.0)
}

/// SIMD quintic fade (Cycles' `float4 fade` with the AVX2 kernel's FMA `madd`):
/// `a = fma(t, 6, −15)`, `b = fma(t, a, 10)`, `(t·t)·(t·b)`.
#[inline(always)]
fn fade_simd(t: f32) -> f32 {
    let a = t.mul_add(6.0, -15.0);
    let b = t.mul_add(a, 10.0);
    (t * t) * (t * b)
}

#[inline(always)]
fn negate_if(v: f32, cond: u32) -> f32 {
    if cond != 0 { -v } else { v }
}

/// 0.5 where `|p| ≥ 10⁶` (moves such points off the lattice, where the noise would be 0).
#[inline(always)]
fn precision_correction(p: f32) -> f32 {
    if p.abs() >= 1_000_000.0 { 0.5 } else { 0.0 }
}

/// 1D/2D wrap: exact `fmodf(p, 100000)` plus [`precision_correction`].
#[inline(always)]
fn wrap_exact(p: f32) -> f32 {
    p % 100_000.0 + precision_correction(p)
}

/// 3D/4D wrap: Cycles' SSE4.2 `fmod` for `float3`/`float4`, `p − trunc(p · (1/100000))·100000`
/// (reciprocal multiply, fused multiply-subtract; both measured from renders), plus
/// [`precision_correction`]. It differs from `fmodf` only where the quotient rounds up to an
/// integer, and then by one period.
#[inline(always)]
fn wrap_simd(p: f32) -> f32 {
    let quotient = (p * (1.0 / 100_000.0f32)).trunc();
    (-quotient).mul_add(100_000.0, p) + precision_correction(p)
}

/// Cycles' `clamp(a, lo, hi) = min(max(a, lo), hi)` with `max(a, b) = a > b ? a : b`:
/// NaN maps to `lo`.
#[inline(always)]
fn clamp_cycles(a: f32, lo: f32, hi: f32) -> f32 {
    let m = if a > lo { a } else { lo };
    if m < hi { m } else { hi }
}

/// Cycles' `saturatef`.
#[inline(always)]
fn saturate(a: f32) -> f32 {
    clamp_cycles(a, 0.0, 1.0)
}

/// Cycles' film `ensure_finite`: NaN and ±Inf become 0.
#[inline(always)]
fn ensure_finite(a: f32) -> f32 {
    if a.is_finite() { a } else { 0.0 }
}

// ---------------------------------------------------------------------------------------------
// Gradients.

/// The 1D gradient slope `±(1 + (h & 7))` (Cycles' `grad1(h, x)` is this times `x`).
#[inline(always)]
fn grad1_slope(hash: u32) -> f32 {
    let h = hash & 15;
    negate_if((1 + (h & 7)) as f32, h & 8)
}

/// 2D gradients `(±1, ±2)`, `(±2, ±1)` dotted with `(x, y)`.
#[inline(always)]
fn grad2(hash: u32, x: f32, y: f32) -> f32 {
    let h = hash & 7;
    let u = if h < 4 { x } else { y };
    let v = 2.0 * if h < 4 { y } else { x };
    negate_if(u, h & 1) + negate_if(v, h & 2)
}

/// Perlin's 12 cube-edge gradients (16 slots) dotted with `(x, y, z)`.
#[inline(always)]
fn grad3(hash: u32, x: f32, y: f32, z: f32) -> f32 {
    let h = hash & 15;
    let u = if h < 8 { x } else { y };
    let vt = if h == 12 || h == 14 { x } else { z };
    let v = if h < 4 { y } else { vt };
    negate_if(u, h & 1) + negate_if(v, h & 2)
}

/// 32 gradients with three components `±1` and one 0, dotted with `(x, y, z, w)`.
#[inline(always)]
fn grad4(hash: u32, x: f32, y: f32, z: f32, w: f32) -> f32 {
    let h = hash & 31;
    let u = if h < 24 { x } else { y };
    let v = if h < 16 { y } else { z };
    let s = if h < 8 { z } else { w };
    negate_if(u, h & 1) + negate_if(v, h & 2) + negate_if(s, h & 4)
}

// ---------------------------------------------------------------------------------------------
// Perlin noise, unscaled and unwrapped (textures use `snoise_*`). Zero at lattice points.

/// 1D Perlin noise: `lerp(g₀·fx, g₁·(fx − 1), fade(fx))`, slopes `g ∈ ±{1..8}`.
#[inline(always)]
pub fn perlin_1d(x: f32) -> f32 {
    let (fx, xi) = floorfrac(x);
    let u = fade(fx);
    let g0 = grad1_slope(hash_uint(xi));
    let b = grad1_slope(hash_uint(xi.wrapping_add(1))) * (fx - 1.0);
    // a + u·(b − a) with a = g0·fx: the compiled Cycles fuses the product `a` into both uses.
    let diff = (-g0).mul_add(fx, b);
    g0.mul_add(fx, u * diff)
}

/// 2D Perlin noise; blended along x, then y.
#[inline(always)]
pub fn perlin_2d(x: f32, y: f32) -> f32 {
    let (fx, xi) = floorfrac(x);
    let (fy, yi) = floorfrac(y);
    let (u, v) = (fade_simd(fx), fade_simd(fy));
    let (x1, y1) = (xi.wrapping_add(1), yi.wrapping_add(1));
    let (fx1, fy1) = (fx - 1.0, fy - 1.0);
    let v00 = grad2(hash_uint2(xi, yi), fx, fy);
    let v01 = grad2(hash_uint2(xi, y1), fx, fy1);
    let v10 = grad2(hash_uint2(x1, yi), fx1, fy);
    let v11 = grad2(hash_uint2(x1, y1), fx1, fy1);
    mix(mix(v00, v10, u), mix(v01, v11, u), v)
}

/// 3D Perlin noise; blended along x, then y, then z.
#[inline(always)]
pub fn perlin_3d(x: f32, y: f32, z: f32) -> f32 {
    let (fx, xi) = floorfrac(x);
    let (fy, yi) = floorfrac(y);
    let (fz, zi) = floorfrac(z);
    let (u, v, w) = (fade_simd(fx), fade_simd(fy), fade_simd(fz));
    let (x0, x1) = ((xi, fx), (xi.wrapping_add(1), fx - 1.0));
    let ys = [(yi, fy), (yi.wrapping_add(1), fy - 1.0)];
    let zs = [(zi, fz), (zi.wrapping_add(1), fz - 1.0)];
    // s[j][k]: the x edge at (y_j, z_k), blended along x.
    let mut s = [[0.0f32; 2]; 2];
    for (j, &(yh, yf)) in ys.iter().enumerate() {
        for (k, &(zh, zf)) in zs.iter().enumerate() {
            let g0 = grad3(hash_uint3(x0.0, yh, zh), x0.1, yf, zf);
            let g1 = grad3(hash_uint3(x1.0, yh, zh), x1.1, yf, zf);
            s[j][k] = mix(g0, g1, u);
        }
    }
    mix(mix(s[0][0], s[1][0], v), mix(s[0][1], s[1][1], v), w)
}

/// 4D Perlin noise; blended along w first, then x, y, z (the order of Cycles' AVX2 kernel).
#[inline(always)]
pub fn perlin_4d(x: f32, y: f32, z: f32, w: f32) -> f32 {
    let (fx, xi) = floorfrac(x);
    let (fy, yi) = floorfrac(y);
    let (fz, zi) = floorfrac(z);
    let (fw, wi) = floorfrac(w);
    let (u, v, t, s) = (fade_simd(fx), fade_simd(fy), fade_simd(fz), fade_simd(fw));
    let xs = [(xi, fx), (xi.wrapping_add(1), fx - 1.0)];
    let ys = [(yi, fy), (yi.wrapping_add(1), fy - 1.0)];
    let zs = [(zi, fz), (zi.wrapping_add(1), fz - 1.0)];
    let (w0, w1) = ((wi, fw), (wi.wrapping_add(1), fw - 1.0));
    // c[i][j][k]: the w edge at corner (x_i, y_j, z_k), blended along w.
    let mut c = [[[0.0f32; 2]; 2]; 2];
    for (i, &(xh, xf)) in xs.iter().enumerate() {
        for (j, &(yh, yf)) in ys.iter().enumerate() {
            for (k, &(zh, zf)) in zs.iter().enumerate() {
                let a = grad4(hash_uint4(xh, yh, zh, w0.0), xf, yf, zf, w0.1);
                let b = grad4(hash_uint4(xh, yh, zh, w1.0), xf, yf, zf, w1.1);
                c[i][j][k] = mix(a, b, s);
            }
        }
    }
    let ex = |j: usize, k: usize| mix(c[0][j][k], c[1][j][k], u);
    mix(mix(ex(0, 0), ex(1, 0), v), mix(ex(0, 1), ex(1, 1), v), t)
}

// ---------------------------------------------------------------------------------------------
// Signed / unsigned wrapped noise.

/// OSL's output scales of Perlin noise per dimension (to about `[-1, 1]`).
const SCALE_1D: f32 = 0.2500;
const SCALE_2D: f32 = 0.6616;
const SCALE_3D: f32 = 0.9820;
const SCALE_4D: f32 = 0.8344;

/// Signed 1D noise: `0.25 · perlin_1d(wrap(p))`, about `[-1, 1]`.
#[inline(always)]
pub fn snoise_1d(p: f32) -> f32 {
    SCALE_1D * perlin_1d(wrap_exact(p))
}

/// Signed 2D noise: `0.6616 · perlin_2d(wrap(p))`.
#[inline(always)]
pub fn snoise_2d(p: Vec2) -> f32 {
    SCALE_2D * perlin_2d(wrap_exact(p.x), wrap_exact(p.y))
}

/// Signed 3D noise: `0.982 · perlin_3d(wrap(p))`.
#[inline(always)]
pub fn snoise_3d(p: Vec3) -> f32 {
    SCALE_3D * perlin_3d(wrap_simd(p.x), wrap_simd(p.y), wrap_simd(p.z))
}

/// Signed 4D noise: `0.8344 · perlin_4d(wrap(p))`.
#[inline(always)]
pub fn snoise_4d(p: Vec4) -> f32 {
    SCALE_4D
        * perlin_4d(
            wrap_simd(p.x),
            wrap_simd(p.y),
            wrap_simd(p.z),
            wrap_simd(p.w),
        )
}

/// Unsigned 1D noise `0.5 · snoise + 0.5`, about `[0, 1]`.
#[inline(always)]
pub fn noise_1d(p: f32) -> f32 {
    0.5 * snoise_1d(p) + 0.5
}

/// Unsigned 2D noise `0.5 · snoise + 0.5`.
#[inline(always)]
pub fn noise_2d(p: Vec2) -> f32 {
    0.5 * snoise_2d(p) + 0.5
}

/// Unsigned 3D noise `0.5 · snoise + 0.5`.
#[inline(always)]
pub fn noise_3d(p: Vec3) -> f32 {
    0.5 * snoise_3d(p) + 0.5
}

/// Unsigned 4D noise `0.5 · snoise + 0.5`.
#[inline(always)]
pub fn noise_4d(p: Vec4) -> f32 {
    0.5 * snoise_4d(p) + 0.5
}

/// A point of 1–4 dimensions (`f32`, `Vec2`, `Vec3`, `Vec4`) that signed noise can be evaluated
/// at, so the fractal functions are written once.
pub trait NoisePoint: Copy + Add<Output = Self> + Mul<f32, Output = Self> {
    /// Signed noise `snoise_Nd(self)`.
    fn snoise(self) -> f32;
    /// `snoise(self) + c` with the scale factor fused into the add (`fma(s_D, perlin, c)`), as
    /// the compiled Cycles fractals compute it.
    fn snoise_plus(self, c: f32) -> f32;
}

impl NoisePoint for f32 {
    #[inline(always)]
    fn snoise(self) -> f32 {
        snoise_1d(self)
    }
    #[inline(always)]
    fn snoise_plus(self, c: f32) -> f32 {
        SCALE_1D.mul_add(perlin_1d(wrap_exact(self)), c)
    }
}

impl NoisePoint for Vec2 {
    #[inline(always)]
    fn snoise(self) -> f32 {
        snoise_2d(self)
    }
    #[inline(always)]
    fn snoise_plus(self, c: f32) -> f32 {
        SCALE_2D.mul_add(perlin_2d(wrap_exact(self.x), wrap_exact(self.y)), c)
    }
}

impl NoisePoint for Vec3 {
    #[inline(always)]
    fn snoise(self) -> f32 {
        snoise_3d(self)
    }
    #[inline(always)]
    fn snoise_plus(self, c: f32) -> f32 {
        let n = perlin_3d(wrap_simd(self.x), wrap_simd(self.y), wrap_simd(self.z));
        SCALE_3D.mul_add(n, c)
    }
}

impl NoisePoint for Vec4 {
    #[inline(always)]
    fn snoise(self) -> f32 {
        snoise_4d(self)
    }
    #[inline(always)]
    fn snoise_plus(self, c: f32) -> f32 {
        let n = perlin_4d(
            wrap_simd(self.x),
            wrap_simd(self.y),
            wrap_simd(self.z),
            wrap_simd(self.w),
        );
        SCALE_4D.mul_add(n, c)
    }
}

// ---------------------------------------------------------------------------------------------
// Fractals. Octave i samples `snoise(L^i · p)` with amplitude `r^i` (L = lacunarity,
// r = roughness) for i = 0..=⌊detail⌋; the fraction of `detail` blends in one more octave.
// Callers should pass `detail` in [0, 15] (the node clamps it); at most 64 whole octaves run.

const MAX_OCTAVES: i32 = 64;

#[inline(always)]
fn octaves(detail: f32) -> i32 {
    float_to_int(detail).min(MAX_OCTAVES)
}

/// Fractal Brownian motion: `sum = Σ r^i · snoise(L^i · p)`, plus the fractional octave
/// (`lerp(sum, sum + r^n·snoise(L^n·p), fract(detail))`). With `normalize`, each sum is mapped
/// by `0.5 · sum / Σ r^i + 0.5` (about `[0, 1]`) before that lerp.
#[inline(always)]
pub fn fbm<P: NoisePoint>(
    p: P,
    detail: f32,
    roughness: f32,
    lacunarity: f32,
    normalize: bool,
) -> f32 {
    let mut fscale = 1.0f32;
    let mut amp = 1.0f32;
    let mut maxamp = 0.0f32;
    let mut sum = 0.0f32;
    for _ in 0..=octaves(detail) {
        let t = (p * fscale).snoise();
        sum = t.mul_add(amp, sum);
        maxamp += amp;
        amp *= roughness;
        fscale *= lacunarity;
    }
    let rmd = detail - detail.floor();
    if rmd != 0.0 {
        let t = (p * fscale).snoise();
        let sum2 = t.mul_add(amp, sum);
        if normalize {
            mix(
                0.5 * sum / maxamp + 0.5,
                0.5 * sum2 / (maxamp + amp) + 0.5,
                rmd,
            )
        } else {
            mix(sum, sum2, rmd)
        }
    } else if normalize {
        0.5 * sum / maxamp + 0.5
    } else {
        sum
    }
}

/// Multifractal: `Π (r^i · snoise(L^i · p) + 1)`; the fractional octave multiplies by
/// `(fract(detail) · r^n · snoise + 1)`.
#[inline(always)]
pub fn multi_fractal<P: NoisePoint>(mut p: P, detail: f32, roughness: f32, lacunarity: f32) -> f32 {
    let mut value = 1.0f32;
    let mut pwr = 1.0f32;
    for _ in 0..=octaves(detail) {
        value *= pwr.mul_add(p.snoise(), 1.0);
        pwr *= roughness;
        p = p * lacunarity;
    }
    let rmd = detail - detail.floor();
    if rmd != 0.0 {
        value *= (rmd * pwr).mul_add(p.snoise(), 1.0);
    }
    value
}

/// Heterogeneous terrain: `v = offset + snoise(p)`, then for i ≥ 1
/// `v += (snoise(L^i p) + offset) · r^i · v` (the fractional octave scaled by `fract(detail)`).
#[inline(always)]
pub fn hetero_terrain<P: NoisePoint>(
    mut p: P,
    detail: f32,
    roughness: f32,
    lacunarity: f32,
    offset: f32,
) -> f32 {
    let mut pwr = roughness;
    let mut value = p.snoise_plus(offset);
    p = p * lacunarity;
    for _ in 1..=octaves(detail) {
        // value += (snoise + offset)·pwr·value, the last product fused into the add.
        value = (p.snoise_plus(offset) * pwr).mul_add(value, value);
        pwr *= roughness;
        p = p * lacunarity;
    }
    let rmd = detail - detail.floor();
    if rmd != 0.0 {
        let increment = p.snoise_plus(offset) * pwr * value;
        value = rmd.mul_add(increment, value);
    }
    value
}

/// Hybrid additive/multiplicative multifractal: `signal = (snoise(L^i p) + offset) · r^i`,
/// `value += w · signal`, `w ← min(w, 1) · gain · signal` (w starts at 1), stopping once
/// `w ≤ 0.001`; the fractional octave adds `fract(detail) · w · signal`.
#[inline(always)]
pub fn hybrid_multi_fractal<P: NoisePoint>(
    mut p: P,
    detail: f32,
    roughness: f32,
    lacunarity: f32,
    offset: f32,
    gain: f32,
) -> f32 {
    let mut pwr = 1.0f32;
    let mut value = 0.0f32;
    let mut weight = 1.0f32;
    let n = octaves(detail);
    let mut i = 0;
    while weight > 0.001 && i <= n {
        weight = weight.min(1.0);
        let signal = p.snoise_plus(offset) * pwr;
        pwr *= roughness;
        value = weight.mul_add(signal, value);
        weight *= gain * signal;
        p = p * lacunarity;
        i += 1;
    }
    let rmd = detail - detail.floor();
    if rmd != 0.0 && weight > 0.001 {
        weight = weight.min(1.0);
        let signal = p.snoise_plus(offset) * pwr;
        value = (rmd * weight).mul_add(signal, value);
    }
    value
}

/// Ridged multifractal: `signal_i = (offset − |snoise(L^i p)|)² · saturate(signal_{i−1} · gain)`
/// (no weight for i = 0), `value = Σ r^i · signal_i`. Only whole octaves count: Cycles ignores
/// the fraction of `detail` here.
#[inline(always)]
pub fn ridged_multi_fractal<P: NoisePoint>(
    mut p: P,
    detail: f32,
    roughness: f32,
    lacunarity: f32,
    offset: f32,
    gain: f32,
) -> f32 {
    let mut pwr = roughness;
    let mut signal = offset - p.snoise().abs();
    signal *= signal;
    let mut value = signal;
    for _ in 1..=octaves(detail) {
        p = p * lacunarity;
        let weight = saturate(signal * gain);
        signal = offset - p.snoise().abs();
        signal *= signal;
        signal *= weight;
        value = signal.mul_add(pwr, value);
        pwr *= roughness;
    }
    value
}

// ---------------------------------------------------------------------------------------------
// The node.

/// The Noise Texture's `noise_type` (discriminants as Cycles' `NodeNoiseType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum NoiseType {
    Multifractal = 0,
    #[default]
    Fbm = 1,
    HybridMultifractal = 2,
    RidgedMultifractal = 3,
    HeteroTerrain = 4,
}

/// The Noise Texture's settings and (unlinked or evaluated) scalar inputs.
/// Defaults are Blender's: 3D fBm, normalize on, scale 5, detail 2, roughness 0.5,
/// lacunarity 2, offset 0, gain 1, distortion 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseParams {
    /// 1–4 (0 is treated as 1, above 4 as 4).
    pub dimensions: u8,
    pub kind: NoiseType,
    /// Only affects fBm.
    pub normalize: bool,
    pub scale: f32,
    /// Clamped to `[0, 15]` (NaN → 0).
    pub detail: f32,
    /// Clamped to `≥ 0` (NaN → 0).
    pub roughness: f32,
    pub lacunarity: f32,
    /// Hybrid, ridged and hetero terrain only.
    pub offset: f32,
    /// Hybrid and ridged only.
    pub gain: f32,
    pub distortion: f32,
}

impl Default for NoiseParams {
    fn default() -> Self {
        Self {
            dimensions: 3,
            kind: NoiseType::Fbm,
            normalize: true,
            scale: 5.0,
            detail: 2.0,
            roughness: 0.5,
            lacunarity: 2.0,
            offset: 0.0,
            gain: 1.0,
            distortion: 0.0,
        }
    }
}

/// The fractal parameters after the node's clamping.
#[derive(Clone, Copy)]
struct Fractal {
    kind: NoiseType,
    normalize: bool,
    detail: f32,
    roughness: f32,
    lacunarity: f32,
    offset: f32,
    gain: f32,
}

impl Fractal {
    #[inline(always)]
    fn eval<P: NoisePoint>(&self, p: P) -> f32 {
        let (d, r, l) = (self.detail, self.roughness, self.lacunarity);
        match self.kind {
            NoiseType::Multifractal => multi_fractal(p, d, r, l),
            NoiseType::Fbm => fbm(p, d, r, l, self.normalize),
            NoiseType::HybridMultifractal => {
                hybrid_multi_fractal(p, d, r, l, self.offset, self.gain)
            }
            NoiseType::RidgedMultifractal => {
                ridged_multi_fractal(p, d, r, l, self.offset, self.gain)
            }
            NoiseType::HeteroTerrain => hetero_terrain(p, d, r, l, self.offset),
        }
    }

    /// `(value, color)` at an already distorted point; the colour's second and third channels
    /// are the fractal at `p + off_g` and `p + off_b`.
    #[inline(always)]
    fn value_color<P: NoisePoint>(
        &self,
        p: P,
        want_color: bool,
        off_g: P,
        off_b: P,
    ) -> (f32, Vec3) {
        let value = self.eval(p);
        if !want_color {
            return (ensure_finite(value), Vec3::ZERO);
        }
        let color = Vec3::new(value, self.eval(p + off_g), self.eval(p + off_b));
        (ensure_finite(value), color.map(ensure_finite))
    }
}

// Cycles' random seed offsets `100 + 100 · hash(seed[, i])` in [100, 200] (constant-folded, so
// not fused, in the compiled kernel).

const fn offset1(seed: f32) -> f32 {
    100.0 + hash_float_to_float(seed) * 100.0
}

const fn offset_n(seed: f32, i: f32) -> f32 {
    100.0 + hash_float2_to_float(Vec2::new(seed, i)) * 100.0
}

const fn offset2(seed: f32) -> Vec2 {
    Vec2::new(offset_n(seed, 0.0), offset_n(seed, 1.0))
}

const fn offset3(seed: f32) -> Vec3 {
    Vec3::new(
        offset_n(seed, 0.0),
        offset_n(seed, 1.0),
        offset_n(seed, 2.0),
    )
}

const fn offset4(seed: f32) -> Vec4 {
    Vec4::new(
        offset_n(seed, 0.0),
        offset_n(seed, 1.0),
        offset_n(seed, 2.0),
        offset_n(seed, 3.0),
    )
}

/// `random_float_offset(0..=2)`: distortion, then colour G and B (1D).
const OFFSETS_1D: [f32; 3] = [offset1(0.0), offset1(1.0), offset1(2.0)];
/// `random_float2_offset(0..=3)`: distortion x, y, then colour G, B (2D).
const OFFSETS_2D: [Vec2; 4] = [offset2(0.0), offset2(1.0), offset2(2.0), offset2(3.0)];
/// `random_float3_offset(0..=4)`: distortion x, y, z, then colour G, B (3D).
const OFFSETS_3D: [Vec3; 5] = [
    offset3(0.0),
    offset3(1.0),
    offset3(2.0),
    offset3(3.0),
    offset3(4.0),
];
/// `random_float4_offset(0..=5)`: distortion x, y, z, w, then colour G, B (4D).
const OFFSETS_4D: [Vec4; 6] = [
    offset4(0.0),
    offset4(1.0),
    offset4(2.0),
    offset4(3.0),
    offset4(4.0),
    offset4(5.0),
];

/// Blender's Noise Texture node at `p` (the Vector input) and `w` (the W input).
///
/// Returns `(Fac, Color)`; with `want_color == false` only `Fac` is computed and `Color` is zero.
///
/// Math (Cycles `svm_node_tex_noise`): `detail ← clamp(detail, 0, 15)`,
/// `roughness ← max(roughness, 0)`, `p ← p · scale`, `w ← w · scale`; the point `q` is `w` (1D),
/// `p.xy` (2D), `p` (3D) or `(p, w)` (4D). With distortion `d ≠ 0` each component `i` of `q` is
/// displaced by `d · snoise(q + offset_i)`. `Fac = fractal(q)` and
/// `Color = (Fac, fractal(q + offset_G), fractal(q + offset_B))`, the offsets being Cycles' fixed
/// pseudo-random vectors in `[100, 200]`.
///
/// Never panics, never allocates. Outputs are always finite: where Cycles computes NaN or ±Inf
/// (non-finite inputs or overflowing parameters) its film writes 0 (`ensure_finite`), and so
/// do we.
pub fn noise_texture(p: Vec3, w: f32, params: &NoiseParams, want_color: bool) -> (f32, Vec3) {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU has FMA, checked just above.
        return unsafe { noise_texture_fma(p, w, params, want_color) };
    }
    noise_texture_impl(p, w, params, want_color)
}

/// [`noise_texture`] compiled with FMA: its `mul_add`s (Cycles' fused operations) become
/// single instructions instead of calls; the results are the same, an FMA being exact.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
unsafe fn noise_texture_fma(
    p: Vec3,
    w: f32,
    params: &NoiseParams,
    want_color: bool,
) -> (f32, Vec3) {
    noise_texture_impl(p, w, params, want_color)
}

#[inline(always)]
fn noise_texture_impl(p: Vec3, w: f32, params: &NoiseParams, want_color: bool) -> (f32, Vec3) {
    let f = Fractal {
        kind: params.kind,
        normalize: params.normalize,
        detail: clamp_cycles(params.detail, 0.0, 15.0),
        roughness: params.roughness.max(0.0),
        lacunarity: params.lacunarity,
        offset: params.offset,
        gain: params.gain,
    };
    let p = p * params.scale;
    let w = w * params.scale;
    let d = params.distortion;
    match params.dimensions {
        0 | 1 => {
            let o = &OFFSETS_1D;
            let mut q = w;
            if d != 0.0 {
                q = snoise_1d(q + o[0]).mul_add(d, q);
            }
            f.value_color(q, want_color, o[1], o[2])
        }
        2 => {
            let o = &OFFSETS_2D;
            let mut q = Vec2::new(p.x, p.y);
            if d != 0.0 {
                // As compiled in Cycles (measured): the x product is fused into its add, the y
                // product is not.
                let dx = snoise_2d(q + o[0]);
                let dy = snoise_2d(q + o[1]);
                q = Vec2::new(dx.mul_add(d, q.x), q.y + dy * d);
            }
            f.value_color(q, want_color, o[2], o[3])
        }
        3 => {
            let o = &OFFSETS_3D;
            let mut q = p;
            if d != 0.0 {
                // SIMD `float3`: the products are packed into a vector first, so not fused.
                q += Vec3::new(
                    snoise_3d(q + o[0]) * d,
                    snoise_3d(q + o[1]) * d,
                    snoise_3d(q + o[2]) * d,
                );
            }
            f.value_color(q, want_color, o[3], o[4])
        }
        _ => {
            let o = &OFFSETS_4D;
            let mut q = Vec4::new(p.x, p.y, p.z, w);
            if d != 0.0 {
                q += Vec4::new(
                    snoise_4d(q + o[0]) * d,
                    snoise_4d(q + o[1]) * d,
                    snoise_4d(q + o[2]) * d,
                    snoise_4d(q + o[3]) * d,
                );
            }
            f.value_color(q, want_color, o[4], o[5])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One Noise Texture evaluation measured from a Cycles 5.0 (bpy 5.0.1, x86-64 CPU) render:
    /// Emission shader, 1 spp, 32-bit EXR, pixel RGB = the node's Color output (R = Fac).
    struct Measured {
        dims: u8,
        kind: NoiseType,
        normalize: bool,
        scale: f32,
        detail: f32,
        roughness: f32,
        lacunarity: f32,
        offset: f32,
        gain: f32,
        distortion: f32,
        p: [f32; 3],
        w: f32,
        color: [f32; 3],
    }

    #[test]
    fn matches_cycles_renders_bit_for_bit() {
        for (i, m) in MEASURED.iter().enumerate() {
            let params = NoiseParams {
                dimensions: m.dims,
                kind: m.kind,
                normalize: m.normalize,
                scale: m.scale,
                detail: m.detail,
                roughness: m.roughness,
                lacunarity: m.lacunarity,
                offset: m.offset,
                gain: m.gain,
                distortion: m.distortion,
            };
            let (fac, color) = noise_texture(Vec3::from(m.p), m.w, &params, true);
            assert_eq!(
                color.to_array(),
                m.color,
                "row {i}: {}D {:?}",
                m.dims,
                m.kind
            );
            assert_eq!(fac, m.color[0], "row {i}");
            assert_eq!(
                noise_texture(Vec3::from(m.p), m.w, &params, false).0,
                m.color[0],
                "row {i}"
            );
        }
    }

    /// Deterministic pseudo-random points in `[-r, r]^4`.
    fn points(n: usize, r: f32) -> impl Iterator<Item = Vec4> {
        (0..n as u32).map(move |i| {
            let h = |k: u32| super::super::hash::hash_uint2_to_float(i, k) * 2.0 - 1.0;
            Vec4::new(h(0), h(1), h(2), h(3)) * r
        })
    }

    #[test]
    fn signed_noise_range() {
        for q in points(20_000, 50.0) {
            for v in [
                snoise_1d(q.x),
                snoise_2d(q.truncate().truncate()),
                snoise_3d(q.truncate()),
                snoise_4d(q),
            ] {
                assert!(v.abs() <= 1.05, "{q} -> {v}");
            }
            let n = noise_3d(q.truncate());
            assert!((-0.03..=1.03).contains(&n));
        }
    }

    #[test]
    fn zero_on_the_lattice() {
        for k in [-3.0f32, 0.0, 1.0, 17.0, -12345.0] {
            assert_eq!(perlin_1d(k), 0.0);
            assert_eq!(perlin_2d(k, 2.0 - k), 0.0);
            assert_eq!(perlin_3d(k, 1.0, -k), 0.0);
            assert_eq!(perlin_4d(k, -1.0, 3.0, k), 0.0);
        }
    }

    #[test]
    fn continuous_across_cells() {
        let e = 1e-3f32;
        for q in points(2_000, 20.0) {
            // Step across the nearest lattice plane in every axis.
            let c = q.round() - Vec4::splat(e * 0.5);
            let d = Vec4::splat(e);
            assert!((snoise_1d(c.x) - snoise_1d(c.x + e)).abs() < 0.02);
            let (a2, b2) = (c.truncate().truncate(), (c + d).truncate().truncate());
            assert!((snoise_2d(a2) - snoise_2d(b2)).abs() < 0.02);
            assert!((snoise_3d(c.truncate()) - snoise_3d((c + d).truncate())).abs() < 0.02);
            assert!((snoise_4d(c) - snoise_4d(c + d)).abs() < 0.02);
            // Fractional detail is continuous in detail.
            let p = q.truncate();
            let f = |det: f32| fbm(p, det, 0.5, 2.0, true);
            assert!((f(3.0) - f(3.0 + 1e-4)).abs() < 1e-3);
            assert!((f(3.0) - f(3.0 - 1e-4)).abs() < 1e-3);
        }
    }

    #[test]
    fn normalized_fbm_in_unit_range() {
        let params = NoiseParams {
            detail: 6.5,
            roughness: 0.7,
            ..NoiseParams::default()
        };
        for q in points(5_000, 10.0) {
            for dims in 1..=4 {
                let params = NoiseParams {
                    dimensions: dims,
                    ..params
                };
                let (v, c) = noise_texture(q.truncate(), q.w, &params, true);
                assert!((-0.05..=1.05).contains(&v), "{dims}D {q} -> {v}");
                assert!(c.cmpge(Vec3::splat(-0.05)).all() && c.cmple(Vec3::splat(1.05)).all());
            }
        }
    }

    #[test]
    fn never_nan_never_panics() {
        let specials = [
            0.0,
            -0.0,
            1e-40,
            0.5,
            -7.25,
            1e3,
            99_999.99,
            1e5,
            1e6,
            -3e9,
            1e30,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        let kinds = [
            NoiseType::Fbm,
            NoiseType::Multifractal,
            NoiseType::HybridMultifractal,
            NoiseType::RidgedMultifractal,
            NoiseType::HeteroTerrain,
        ];
        for (i, &x) in specials.iter().enumerate() {
            let y = specials[(i * 7 + 3) % specials.len()];
            let par = specials[(i * 5 + 1) % specials.len()];
            for dims in 0..=5u8 {
                for &kind in &kinds {
                    for normalize in [false, true] {
                        let p = Vec3::new(x, y, 0.3);
                        let base = NoiseParams {
                            dimensions: dims,
                            kind,
                            normalize,
                            detail: 15.0,
                            distortion: 1.0,
                            ..NoiseParams::default()
                        };
                        let variants = [
                            base,
                            NoiseParams { scale: par, ..base },
                            NoiseParams {
                                detail: par,
                                ..base
                            },
                            NoiseParams {
                                roughness: par,
                                ..base
                            },
                            NoiseParams {
                                lacunarity: par,
                                ..base
                            },
                            NoiseParams {
                                offset: par,
                                gain: par,
                                ..base
                            },
                            NoiseParams {
                                distortion: par,
                                ..base
                            },
                        ];
                        for params in variants {
                            let (v, c) = noise_texture(p, y, &params, true);
                            assert!(
                                v.is_finite() && c.is_finite(),
                                "{params:?} at {p} -> {v} {c}"
                            );
                            assert_eq!(v, c.x);
                        }
                    }
                }
            }
        }
        // The building blocks never panic either (they may return NaN like Cycles does).
        for &x in &specials {
            let _ = (
                snoise_1d(x),
                snoise_2d(Vec2::splat(x)),
                snoise_3d(Vec3::splat(x)),
                snoise_4d(Vec4::splat(x)),
            );
            let _ = fbm(Vec3::splat(x), x, x, x, true)
                + hybrid_multi_fractal(x, f32::INFINITY, x, x, x, x);
        }
    }

    #[test]
    fn large_coordinates_wrap() {
        // Beyond 1e5 the noise repeats (up to float rounding of the wrapped coordinate).
        let p = Vec3::new(0.3, 0.6, 0.9);
        let far = p + Vec3::splat(200_000.0);
        assert!((snoise_3d(p) - snoise_3d(far)).abs() < 0.05);
        // And at 1e6+ the lattice is offset by half a cell so it does not collapse to zero.
        assert_ne!(snoise_3d(Vec3::splat(3e6)), 0.0);
        assert_ne!(snoise_1d(-2e6), 0.0);
    }

    // Generated by /work/scratch/measure.py from Cycles 5.0 renders (verify.py configurations).
    #[rustfmt::skip]
    const MEASURED: &[Measured] = &[
    Measured { dims: 1, kind: NoiseType::Fbm, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [0.49376774, 0.5265075, 0.32700837] },
    Measured { dims: 1, kind: NoiseType::Fbm, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.50578403, 0.3376883, 0.54887533] },
    Measured { dims: 1, kind: NoiseType::Fbm, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [0.43118277, 0.6114494, 0.3691914] },
    Measured { dims: 1, kind: NoiseType::Multifractal, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [0.9657262, 1.0422763, 0.38941136] },
    Measured { dims: 1, kind: NoiseType::Multifractal, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.9896029, 0.4278539, 1.2125893] },
    Measured { dims: 1, kind: NoiseType::Multifractal, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [0.7154107, 1.5492591, 0.36762497] },
    Measured { dims: 1, kind: NoiseType::HybridMultifractal, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [1.3748678, 1.5286648, 0.44447178] },
    Measured { dims: 1, kind: NoiseType::HybridMultifractal, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [1.3502245, 0.7725048, 1.5861465] },
    Measured { dims: 1, kind: NoiseType::HybridMultifractal, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [1.0298173, 1.8677658, 0.27050683] },
    Measured { dims: 1, kind: NoiseType::RidgedMultifractal, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [0.8372332, 0.46847785, 0.104344785] },
    Measured { dims: 1, kind: NoiseType::RidgedMultifractal, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.56971395, 0.5749195, 0.7224496] },
    Measured { dims: 1, kind: NoiseType::RidgedMultifractal, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [0.557249, 0.28814492, 0.03023818] },
    Measured { dims: 1, kind: NoiseType::HeteroTerrain, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [1.6513712, 1.5795962, 0.5094868] },
    Measured { dims: 1, kind: NoiseType::HeteroTerrain, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [1.7777548, 0.9412829, 2.0439525] },
    Measured { dims: 1, kind: NoiseType::HeteroTerrain, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [1.2883413, 3.0724525, 0.35630423] },
    Measured { dims: 1, kind: NoiseType::Fbm, normalize: false, scale: 5.0, detail: 4.3, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [-0.07546255, 0.2194411, -0.79896003] },
    Measured { dims: 1, kind: NoiseType::Fbm, normalize: false, scale: 1.0, detail: 1.7, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 1.5, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [-0.34073034, 0.68416107, -0.19675507] },
    Measured { dims: 2, kind: NoiseType::Fbm, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [0.6842059, 0.4175712, 0.5495777] },
    Measured { dims: 2, kind: NoiseType::Fbm, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.4778211, 0.370947, 0.46486497] },
    Measured { dims: 2, kind: NoiseType::Fbm, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [0.45216933, 0.3667948, 0.6065223] },
    Measured { dims: 2, kind: NoiseType::Multifractal, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [1.8198972, 0.6949495, 1.1853957] },
    Measured { dims: 2, kind: NoiseType::Multifractal, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.8237985, 0.5304654, 0.85430104] },
    Measured { dims: 2, kind: NoiseType::Multifractal, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [0.7936808, 0.45282453, 1.4879628] },
    Measured { dims: 2, kind: NoiseType::HybridMultifractal, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [2.2040458, 1.0656242, 1.5599633] },
    Measured { dims: 2, kind: NoiseType::HybridMultifractal, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [1.0949105, 0.69520223, 1.2194456] },
    Measured { dims: 2, kind: NoiseType::HybridMultifractal, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [1.3355411, 0.52506256, 2.0299165] },
    Measured { dims: 2, kind: NoiseType::RidgedMultifractal, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [0.03378653, 0.60923207, 0.4649734] },
    Measured { dims: 2, kind: NoiseType::RidgedMultifractal, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.25153127, 0.26092452, 0.7078466] },
    Measured { dims: 2, kind: NoiseType::RidgedMultifractal, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [0.73056495, 0.1385703, 0.48314446] },
    Measured { dims: 2, kind: NoiseType::HeteroTerrain, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [3.2382462, 1.2068902, 2.0933075] },
    Measured { dims: 2, kind: NoiseType::HeteroTerrain, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [1.1101843, 0.83148444, 1.350879] },
    Measured { dims: 2, kind: NoiseType::HeteroTerrain, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [1.507841, 0.64560974, 2.653017] },
    Measured { dims: 2, kind: NoiseType::Fbm, normalize: false, scale: 5.0, detail: 4.3, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [0.77172613, -0.3436588, 0.2200034] },
    Measured { dims: 2, kind: NoiseType::Fbm, normalize: false, scale: 1.0, detail: 1.7, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 1.5, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [-0.026899088, 0.30518654, 0.78913677] },
    Measured { dims: 3, kind: NoiseType::Fbm, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [0.5205662, 0.44991797, 0.6476446] },
    Measured { dims: 3, kind: NoiseType::Fbm, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.42482477, 0.49194247, 0.51837194] },
    Measured { dims: 3, kind: NoiseType::Fbm, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [0.53890574, 0.55505866, 0.45247307] },
    Measured { dims: 3, kind: NoiseType::Multifractal, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [1.0846847, 0.7435939, 1.6804991] },
    Measured { dims: 3, kind: NoiseType::Multifractal, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.6372217, 0.96020025, 0.9907644] },
    Measured { dims: 3, kind: NoiseType::Multifractal, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [1.1517353, 1.2433286, 0.7616447] },
    Measured { dims: 3, kind: NoiseType::HybridMultifractal, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [1.5994405, 1.1648388, 2.1905766] },
    Measured { dims: 3, kind: NoiseType::HybridMultifractal, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.8059258, 1.3390613, 1.3426348] },
    Measured { dims: 3, kind: NoiseType::HybridMultifractal, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [1.5145246, 1.6522543, 1.1047369] },
    Measured { dims: 3, kind: NoiseType::RidgedMultifractal, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [0.9317475, 0.41172928, 0.22228017] },
    Measured { dims: 3, kind: NoiseType::RidgedMultifractal, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.18197833, 0.77271765, 0.31081957] },
    Measured { dims: 3, kind: NoiseType::RidgedMultifractal, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [0.539862, 0.5055613, 0.5151329] },
    Measured { dims: 3, kind: NoiseType::HeteroTerrain, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [1.7688752, 1.5099571, 2.774489] },
    Measured { dims: 3, kind: NoiseType::HeteroTerrain, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.840331, 1.5158168, 1.3625908] },
    Measured { dims: 3, kind: NoiseType::HeteroTerrain, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [1.9704392, 2.4799662, 1.6789111] },
    Measured { dims: 3, kind: NoiseType::Fbm, normalize: false, scale: 5.0, detail: 4.3, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [0.051407315, -0.18110971, 0.6063212] },
    Measured { dims: 3, kind: NoiseType::Fbm, normalize: false, scale: 1.0, detail: 1.7, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 1.5, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [-0.19408244, -0.045498382, -0.115687914] },
    Measured { dims: 4, kind: NoiseType::Fbm, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [0.58719116, 0.43631715, 0.5656841] },
    Measured { dims: 4, kind: NoiseType::Fbm, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.46136975, 0.43612063, 0.49638188] },
    Measured { dims: 4, kind: NoiseType::Fbm, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [0.48479754, 0.52082956, 0.5105104] },
    Measured { dims: 4, kind: NoiseType::Multifractal, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [1.3855779, 0.7268422, 1.2836217] },
    Measured { dims: 4, kind: NoiseType::Multifractal, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.84712124, 0.73968935, 0.97784215] },
    Measured { dims: 4, kind: NoiseType::Multifractal, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [0.89940655, 1.091882, 1.0322765] },
    Measured { dims: 4, kind: NoiseType::HybridMultifractal, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [1.9271394, 0.9823116, 1.6716182] },
    Measured { dims: 4, kind: NoiseType::HybridMultifractal, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [1.272376, 1.0776278, 1.4345891] },
    Measured { dims: 4, kind: NoiseType::HybridMultifractal, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [1.2430373, 1.5051589, 1.4606305] },
    Measured { dims: 4, kind: NoiseType::RidgedMultifractal, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [0.46112356, 0.5022405, 0.5755863] },
    Measured { dims: 4, kind: NoiseType::RidgedMultifractal, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [0.8253059, 0.6357283, 0.7530681] },
    Measured { dims: 4, kind: NoiseType::RidgedMultifractal, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [0.5146644, 0.92459726, 0.6203704] },
    Measured { dims: 4, kind: NoiseType::HeteroTerrain, normalize: true, scale: 5.0, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [2.2803075, 1.2526281, 2.18181] },
    Measured { dims: 4, kind: NoiseType::HeteroTerrain, normalize: true, scale: 2.3, detail: 2.5, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.7, p: [-6.9, -3.6399999, -6.132], w: -2.362, color: [1.4458072, 1.3164561, 1.5428184] },
    Measured { dims: 4, kind: NoiseType::HeteroTerrain, normalize: true, scale: 1.0, detail: 15.0, roughness: 0.55, lacunarity: 1.9, offset: 0.8, gain: 1.3, distortion: 0.0, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [1.9176137, 2.0450826, 2.0771637] },
    Measured { dims: 4, kind: NoiseType::Fbm, normalize: false, scale: 5.0, detail: 4.3, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 0.0, p: [0.596, -0.69200003, 0.21200001], w: 0.992, color: [0.3540515, -0.25218698, 0.2987282] },
    Measured { dims: 4, kind: NoiseType::Fbm, normalize: false, scale: 1.0, detail: 1.7, roughness: 0.6, lacunarity: 2.1, offset: 0.8, gain: 1.3, distortion: 1.5, p: [1000.482, -999.896, 1003.456], w: -1002.14, color: [0.108289346, 0.058684118, -0.13936634] },
    ];
}
