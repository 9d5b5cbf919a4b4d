//! Albedo tables that Cycles precomputes (`cycles_precompute.cpp`, stored in
//! `scene/shader.tables`), regenerated here from their definitions by deterministic quadrature
//! on first use (no copied data), and read with Cycles' (bi/tri)linear `lookup_table_read_*`.
//!
//! Grid conventions are Cycles': `rough = sqrt(alpha)` in `x`, `μ = cos θi` in `y`, and
//! for IOR tables `z` with `ior = ior_from_F0(z⁴)` (so `z = sqrt(|(ior-1)/(ior+1)|)`); node
//! coordinates are `i / (n-1)` clamped to `[1e-4, 1]` (`z` to `[1e-4, 0.99]`).

use super::fresnel;
use super::microfacet::sample_visible_normal;
use glam::{Vec2, Vec3};
use std::sync::OnceLock;

/// Quadrature points per table entry (a `Q × Q` midpoint grid over the visible-normal
/// sampler's unit square; the integrands are smooth but for the horizon).
const Q: usize = 24;

/// Cycles' `ior_from_F0`.
#[inline]
pub fn ior_from_f0(f0: f32) -> f32 {
    let s = f0.clamp(0.0, 0.99).sqrt();
    (1.0 + s) / (1.0 - s)
}

/// Cycles' `lookup_table_read` on one row.
#[inline]
fn read1(t: &[f32], x: f32, size: usize) -> f32 {
    let x = x.clamp(0.0, 1.0) * (size - 1) as f32;
    let i = (x as usize).min(size - 1);
    let n = (i + 1).min(size - 1);
    let f = x - i as f32;
    if f == 0.0 {
        t[i]
    } else {
        (1.0 - f) * t[i] + f * t[n]
    }
}

#[inline]
fn read2(t: &[f32], x: f32, y: f32, nx: usize, ny: usize) -> f32 {
    let y = y.clamp(0.0, 1.0) * (ny - 1) as f32;
    let i = (y as usize).min(ny - 1);
    let n = (i + 1).min(ny - 1);
    let f = y - i as f32;
    let d0 = read1(&t[nx * i..], x, nx);
    if f == 0.0 {
        return d0;
    }
    (1.0 - f) * d0 + f * read1(&t[nx * n..], x, nx)
}

#[inline]
fn read3(t: &[f32], x: f32, y: f32, z: f32, n: usize) -> f32 {
    let z = z.clamp(0.0, 1.0) * (n - 1) as f32;
    let i = (z as usize).min(n - 1);
    let k = (i + 1).min(n - 1);
    let f = z - i as f32;
    let d0 = read2(&t[n * n * i..], x, y, n, n);
    if f == 0.0 {
        return d0;
    }
    (1.0 - f) * d0 + f * read2(&t[n * n * k..], x, y, n, n)
}

/// Mean of `g(wi, h)` over GGX visible normals of `wi = (sqrt(1-μ²), 0, μ)`.
fn vndf_mean(alpha: f32, mu: f32, g: &dyn Fn(Vec3, Vec3) -> f32) -> f32 {
    let wi = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let mut sum = 0.0f64;
    for a in 0..Q {
        for b in 0..Q {
            let u = Vec2::new((a as f32 + 0.5) / Q as f32, (b as f32 + 0.5) / Q as f32);
            let h = sample_visible_normal(wi, alpha, u);
            sum += g(wi, h) as f64;
        }
    }
    (sum / (Q * Q) as f64) as f32
}

const N_IOR: usize = 16;

/// Cycles' `ggx_gen_schlick_ior_s`: for a reflection-only GGX lobe with the dielectric Fresnel
/// of `ior > 1`, the mean over visible normals of `clamp((F(wi·h) - F0) / (1 - F0), 0, 1)`,
/// counting reflections below the horizon as 0. The lobe's Fresnel estimate is then
/// `mix(F0, 1, s)` (`bsdf_microfacet_estimate_albedo`).
fn gen_schlick_ior_s() -> &'static [f32] {
    static T: OnceLock<Vec<f32>> = OnceLock::new();
    T.get_or_init(|| {
        let n = N_IOR;
        let node = |i: usize| i as f32 / (n - 1) as f32;
        let mut t = Vec::with_capacity(n * n * n);
        for z in 0..n {
            let zz = node(z).clamp(1e-4, 0.99);
            let ior = ior_from_f0(zz * zz * zz * zz);
            let f0 = fresnel::f0_from_ior(ior);
            for y in 0..n {
                let mu = node(y).clamp(1e-4, 1.0);
                for x in 0..n {
                    let rough = node(x).clamp(1e-4, 1.0);
                    let s = vndf_mean(rough * rough, mu, &|wi, h| {
                        let c = wi.dot(h);
                        let wo = 2.0 * c * h - wi;
                        if wo.z <= 0.0 || c <= 0.0 {
                            return 0.0;
                        }
                        let f = fresnel::dielectric(c, ior).0;
                        ((f - f0) / (1.0 - f0)).clamp(0.0, 1.0)
                    });
                    t.push(s.clamp(0.0, 1.0));
                }
            }
        }
        t
    })
}

/// Cycles' Fresnel estimate of a reflection-only GGX lobe with the dielectric Fresnel of
/// `ior` (`bsdf_microfacet_estimate_albedo`, DIELECTRIC case): `mix(F0, 1, s(√α, μ, z))` for
/// `ior > 1`, else the Fresnel reflectance at `μ`.
pub fn dielectric_reflection_albedo(alpha: f32, mu: f32, ior: f32) -> f32 {
    if ior > 1.0 {
        let f0 = fresnel::f0_from_ior(ior);
        let z = ((ior - 1.0) / (ior + 1.0)).abs().sqrt();
        let s = read3(gen_schlick_ior_s(), alpha.max(0.0).sqrt(), mu, z, N_IOR);
        f0 + (1.0 - f0) * s
    } else {
        fresnel::dielectric(mu, ior).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_interpolates_like_cycles() {
        // A table that is linear in each coordinate is reproduced exactly between nodes.
        let n = 4;
        let t: Vec<f32> = (0..n * n * n)
            .map(|i| {
                let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
                x as f32 + 10.0 * y as f32 + 100.0 * z as f32
            })
            .collect();
        let v = read3(&t, 0.5, 0.25, 1.0, n);
        assert!((v - (1.5 + 7.5 + 300.0)).abs() < 1e-4, "{v}");
        assert_eq!(read3(&t, 2.0, -1.0, 0.0, n), 3.0);
    }

    #[test]
    fn smooth_limit_is_the_fresnel_reflectance() {
        // At the smallest roughness the estimate is F(μ) itself.
        for ior in [1.33f32, 1.5, 2.0] {
            for mu in [1.0f32, 0.8, 0.4] {
                let got = dielectric_reflection_albedo(1e-8, mu, ior);
                let want = fresnel::dielectric(mu, ior).0;
                // Trilinear interpolation across the IOR and μ nodes.
                assert!(
                    (got - want).abs() < 0.01,
                    "ior {ior} μ {mu}: {got} vs {want}"
                );
            }
        }
    }
}
