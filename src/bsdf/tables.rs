//! Albedo and energy-compensation tables that Cycles precomputes (`cycles_precompute.cpp`, stored in
//! `scene/shader.tables`), computed here from their definitions by deterministic quadrature (no
//! copied data), and read with Cycles' (bi/tri)linear `lookup_table_read_*`.
//!
//! The quadrature takes about 0.8 CPU seconds (0.55 of it for glass), which every render would
//! pay before its first sample; so its result is embedded (`tables.bin`, written by the test
//! `embedded_tables_are_the_quadrature`, which also checks it), and every machine reads the same
//! values whatever its libm.
//!
//! Grid conventions are Cycles': `rough = sqrt(alpha)` in `x`, `μ = cos θi` in `y`, and
//! for IOR tables `z` with `ior = ior_from_F0(z⁴)` (so `z = sqrt(|(ior-1)/(ior+1)|)`); node
//! coordinates are `i / (n-1)` clamped to `[1e-4, 1]` (`z` to `[1e-4, 0.99]`).

use super::fresnel;
use super::microfacet::sample_visible_normal;
use glam::{Vec2, Vec3};
use std::sync::OnceLock;

/// Quadrature points per table entry: a grid over the visible-normal sampler's unit square,
/// rows in `u.x` × columns in `u.y` (see [`vndf_mean`]).
const Q: (usize, usize) = (40, 16);

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

/// Mean of `g(wi, h)` over GGX visible normals of `wi = (sqrt(1-μ²), 0, μ)`: a midpoint
/// rule over the sampler's unit square after the substitution `u.x = 1 - (1 - t)³`, which packs
/// points towards `u.x = 1`, the rim of the projected disk where GGX's long tail of steep
/// microfacets (the source of the single-scattering loss at low roughness) lives.
fn vndf_mean(alpha: f32, mu: f32, g: &dyn Fn(Vec3, Vec3) -> f32) -> f32 {
    vndf_mean_q(alpha, mu, Q, g)
}

/// [`vndf_mean`] with `q = (rows in u.x, columns in u.y)`.
fn vndf_mean_q(alpha: f32, mu: f32, q: (usize, usize), g: &dyn Fn(Vec3, Vec3) -> f32) -> f32 {
    let (qx, qy) = q;
    let wi = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let mut sum = 0.0f64;
    for a in 0..qx {
        let t = (a as f64 + 0.5) / qx as f64;
        let ux = 1.0 - (1.0 - t).powi(3);
        let jac = 3.0 * (1.0 - t) * (1.0 - t);
        let mut row = 0.0f64;
        for b in 0..qy {
            let u = Vec2::new(ux as f32, (b as f32 + 0.5) / qy as f32);
            let h = sample_visible_normal(wi, alpha, u);
            row += g(wi, h) as f64;
        }
        sum += jac * row;
    }
    (sum / (qx * qy) as f64) as f32
}

/// The grid for the μ-averaged tables (16 Gauss nodes in μ each).
const Q_AVG: (usize, usize) = (24, 12);

/// `f(i)` for `i in 0..n`, computed on all cores with scoped threads (not rayon: a rayon worker
/// waiting here could steal a render job that needs the table being built).
fn parallel_map(n: usize, f: &(dyn Fn(usize) -> Vec<f32> + Sync)) -> Vec<f32> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |t| t.get())
        .min(n)
        .max(1);
    let mut parts: Vec<(usize, Vec<f32>)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|k| {
                s.spawn(move || {
                    (k..n)
                        .step_by(threads)
                        .map(|i| (i, f(i)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("table thread"))
            .collect()
    });
    parts.sort_by_key(|p| p.0);
    parts.into_iter().flat_map(|p| p.1).collect()
}

const N_IOR: usize = 16;

/// Cycles' `ggx_gen_schlick_ior_s`: for a reflection-only GGX lobe with the dielectric Fresnel
/// of `ior > 1`, the mean over visible normals of `clamp((F(wi·h) - F0) / (1 - F0), 0, 1)`,
/// counting reflections below the horizon as 0. The lobe's Fresnel estimate is then
/// `mix(F0, 1, s)` (`bsdf_microfacet_estimate_albedo`).
fn compute_schlick_ior_s() -> Vec<f32> {
    let n = N_IOR;
    parallel_map(n, &|z| {
        let zz = node(z, n).clamp(1e-4, 0.99);
        let ior = ior_from_f0(zz * zz * zz * zz);
        let f0 = fresnel::f0_from_ior(ior);
        let mut t = Vec::with_capacity(n * n);
        for y in 0..n {
            let mu = node(y, n).clamp(1e-4, 1.0);
            for x in 0..n {
                let rough = node(x, n).clamp(1e-4, 1.0);
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
        t
    })
}

/// Cycles' interpolation factor `s(√α, μ, z)` of the `ggx_gen_schlick_ior_s` table for a
/// reflection-only GGX lobe of index `ior` (either side of 1: `z` is symmetric).
pub fn reflection_fresnel_s(alpha: f32, mu: f32, ior: f32) -> f32 {
    let z = ((ior - 1.0) / (ior + 1.0)).abs().sqrt();
    read3(&tables().schlick_ior_s, alpha.max(0.0).sqrt(), mu, z, N_IOR)
}

/// Cycles' Fresnel estimate of a reflection-only GGX lobe with the dielectric Fresnel of
/// `ior` (`bsdf_microfacet_estimate_albedo`, DIELECTRIC case): `mix(F0, 1, s(√α, μ, z))` for
/// `ior > 1`, else the Fresnel reflectance at `μ`.
pub fn dielectric_reflection_albedo(alpha: f32, mu: f32, ior: f32) -> f32 {
    if ior > 1.0 {
        let f0 = fresnel::f0_from_ior(ior);
        f0 + (1.0 - f0) * reflection_fresnel_s(alpha, mu, ior)
    } else {
        fresnel::dielectric(mu, ior).0
    }
}

// ---------------------------------------------------------------------------------------------
// Multiscatter GGX energy compensation (Cycles' `microfacet_ggx_preserve_energy`).

const N_E: usize = 32;

#[inline]
fn node(i: usize, n: usize) -> f32 {
    i as f32 / (n - 1) as f32
}

/// Gauss–Legendre nodes and weights on `[0, 1]` (16 points).
fn gauss16() -> [(f32, f32); 16] {
    const X: [f64; 8] = [
        0.095_012_509_837_637_44,
        0.281_603_550_779_258_9,
        0.458_016_777_657_227_4,
        0.617_876_244_402_643_8,
        0.755_404_408_355_003,
        0.865_631_202_387_831_8,
        0.944_575_023_073_232_6,
        0.989_400_934_991_649_9,
    ];
    const W: [f64; 8] = [
        0.189_450_610_455_068_5,
        0.182_603_415_044_923_6,
        0.169_156_519_395_002_5,
        0.149_595_988_816_576_7,
        0.124_628_971_255_533_9,
        0.095_158_511_682_492_8,
        0.062_253_523_938_647_9,
        0.027_152_459_411_754_1,
    ];
    let mut out = [(0.0, 0.0); 16];
    for i in 0..8 {
        out[2 * i] = ((0.5 - 0.5 * X[i]) as f32, (0.5 * W[i]) as f32);
        out[2 * i + 1] = ((0.5 + 0.5 * X[i]) as f32, (0.5 * W[i]) as f32);
    }
    out
}

/// Single-scattering albedo of a white GGX mirror: mean of `G2 / G1(wi)` over visible normals,
/// reflections below the horizon counting 0 (Cycles' `ggx_E` integrand).
fn e_mirror(alpha: f32, mu: f32, q: (usize, usize)) -> f32 {
    vndf_mean_q(alpha, mu, q, &|wi, h| {
        let wo = 2.0 * wi.dot(h) * h - wi;
        if wo.z <= 0.0 {
            return 0.0;
        }
        super::microfacet::ggx_g2(wi, wo, alpha) / super::microfacet::ggx_g1(wi, alpha)
    })
}

/// Single-scattering albedo of white GGX glass of relative index `eta` (Cycles' `ggx_glass_E`
/// integrand, the Fresnel choice taken in expectation; an index within 1e-4 of 1 refracts
/// as a delta of weight 1, as Cycles treats it).
fn e_glass(alpha: f32, mu: f32, eta: f32, q: (usize, usize)) -> f32 {
    let g1i = super::microfacet::ggx_g1(Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu), alpha);
    vndf_mean_q(alpha, mu, q, &|wi, h| {
        let c = wi.dot(h);
        if c <= 0.0 {
            return 0.0;
        }
        let (f, cos_t, _) = fresnel::dielectric(c, eta);
        let mut e = 0.0;
        let wr = 2.0 * c * h - wi;
        if wr.z > 0.0 {
            e += f * super::microfacet::ggx_g2(wi, wr, alpha) / g1i;
        }
        if f < 1.0 {
            if (eta - 1.0).abs() < 1e-4 {
                e += 1.0 - f;
            } else {
                let wt = ((c / eta - cos_t) * h - wi / eta).normalize();
                if wt.z < 0.0 {
                    e += (1.0 - f) * super::microfacet::ggx_g2(wi, wt, alpha) / g1i;
                }
            }
        }
        e
    })
}

/// Cycles' `ggx_E` (x = √α, y = μ) and `ggx_Eavg` (`∫ 2μ E dμ`, by 16-point Gauss–Legendre).
fn compute_ggx_e() -> (Vec<f32>, Vec<f32>) {
    let e = parallel_map(N_E, &|y| {
        let mu = node(y, N_E).clamp(1e-4, 1.0);
        (0..N_E)
            .map(|x| {
                let rough = node(x, N_E).clamp(1e-4, 1.0);
                e_mirror(rough * rough, mu, Q).clamp(0.0, 1.0)
            })
            .collect()
    });
    let g = gauss16();
    let avg = parallel_map(N_E, &|x| {
        let rough = node(x, N_E).clamp(1e-4, 1.0);
        let s: f32 = g
            .iter()
            .map(|&(mu, w)| w * 2.0 * mu * e_mirror(rough * rough, mu, Q_AVG))
            .sum();
        vec![s.clamp(0.0, 1.0)]
    });
    (e, avg)
}

/// Cycles' `ggx_glass_E` / `ggx_glass_inv_E` (x = √α, y = μ, z as for IOR tables; `inv` for
/// relative indices below 1) and their `Eavg` (x = √α, y = z).
fn compute_ggx_glass(inv: bool) -> (Vec<f32>, Vec<f32>) {
    let n = N_IOR;
    let g = gauss16();
    let ior_at = |z: usize| {
        let zz = node(z, n).clamp(1e-4, 0.99);
        let ior = ior_from_f0(zz * zz * zz * zz);
        if inv { 1.0 / ior } else { ior }
    };
    let e = parallel_map(n, &|z| {
        let ior = ior_at(z);
        let mut t = Vec::with_capacity(n * n);
        for y in 0..n {
            let mu = node(y, n).clamp(1e-4, 1.0);
            for x in 0..n {
                let rough = node(x, n).clamp(1e-4, 1.0);
                t.push(e_glass(rough * rough, mu, ior, Q).clamp(0.0, 1.0));
            }
        }
        t
    });
    let avg = parallel_map(n, &|z| {
        let ior = ior_at(z);
        (0..n)
            .map(|x| {
                let rough = node(x, n).clamp(1e-4, 1.0);
                let s: f32 = g
                    .iter()
                    .map(|&(mu, w)| w * 2.0 * mu * e_glass(rough * rough, mu, ior, Q_AVG))
                    .sum();
                s.clamp(0.0, 1.0)
            })
            .collect()
    });
    (e, avg)
}

/// Every quadrature table, in the order and lengths of `tables.bin`.
struct Tables {
    schlick_ior_s: Vec<f32>,
    ggx_e: (Vec<f32>, Vec<f32>),
    /// `[η > 1, η < 1]`.
    ggx_glass: [(Vec<f32>, Vec<f32>); 2],
}

/// `tables.bin`: [`TABLES_MAGIC`], then the tables' f32 values, little-endian.
static EMBEDDED: &[u8] = include_bytes!("tables.bin");
const TABLES_MAGIC: &[u8; 16] = b"tesela-tables-1\n";

impl Tables {
    fn lengths() -> [usize; 7] {
        let cube = N_IOR * N_IOR * N_IOR;
        let square = N_IOR * N_IOR;
        [cube, N_E * N_E, N_E, cube, square, cube, square]
    }

    fn compute() -> Tables {
        Tables {
            schlick_ior_s: compute_schlick_ior_s(),
            ggx_e: compute_ggx_e(),
            ggx_glass: [compute_ggx_glass(false), compute_ggx_glass(true)],
        }
    }

    #[cfg(test)]
    fn parts(&self) -> [&[f32]; 7] {
        let [g, gi] = &self.ggx_glass;
        [
            &self.schlick_ior_s,
            &self.ggx_e.0,
            &self.ggx_e.1,
            &g.0,
            &g.1,
            &gi.0,
            &gi.1,
        ]
    }

    #[cfg(test)]
    fn encode(&self) -> Vec<u8> {
        let mut out = TABLES_MAGIC.to_vec();
        for part in self.parts() {
            out.extend(part.iter().flat_map(|v| v.to_le_bytes()));
        }
        out
    }

    /// The tables of `bytes`, or None if they are not `encode`'s output for today's sizes.
    fn decode(bytes: &[u8]) -> Option<Tables> {
        let body = bytes.strip_prefix(TABLES_MAGIC)?;
        let lengths = Tables::lengths();
        if body.len() != 4 * lengths.iter().sum::<usize>() {
            return None;
        }
        let mut values = body
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]));
        let mut parts = lengths.map(|n| values.by_ref().take(n).collect::<Vec<f32>>());
        let mut take = |i: usize| std::mem::take(&mut parts[i]);
        Some(Tables {
            schlick_ior_s: take(0),
            ggx_e: (take(1), take(2)),
            ggx_glass: [(take(3), take(4)), (take(5), take(6))],
        })
    }
}

/// The embedded tables (computed instead, should they not fit today's sizes).
fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| Tables::decode(EMBEDDED).unwrap_or_else(Tables::compute))
}

/// `(E(μ), E_avg)` of a white single-scattering GGX mirror with alphas `(ax, ay)` (Cycles
/// looks up `rough = (ax·ay)^(1/4)`).
pub fn ggx_e(alpha_x: f32, alpha_y: f32, mu: f32) -> (f32, f32) {
    let rough = (alpha_x * alpha_y).max(0.0).sqrt().sqrt();
    let (e, avg) = &tables().ggx_e;
    (read2(e, rough, mu, N_E, N_E), read1(avg, rough, N_E))
}

/// `(E(μ), E_avg)` of white single-scattering GGX glass of relative index `eta`.
pub fn ggx_glass_e(alpha: f32, mu: f32, eta: f32) -> (f32, f32) {
    let rough = alpha.max(0.0).sqrt();
    let (inv, eta) = if eta < 1.0 {
        (true, 1.0 / eta)
    } else {
        (false, eta)
    };
    let z = ((eta - 1.0) / (eta + 1.0)).abs().sqrt();
    let (e, avg) = &tables().ggx_glass[inv as usize];
    (
        read3(e, rough, mu, z, N_IOR),
        read2(avg, rough, z, N_IOR, N_IOR),
    )
}

/// The factor Cycles' Multiscatter GGX applies to a single-scattering lobe of albedo `e` at
/// this `μ` (`microfacet_ggx_preserve_energy`, energy scale times darkening):
/// `1/E` for a white lobe, else `1 + F_ms (1 - E) / E` with the multiple-bounce Fresnel
/// `F_ms = F_ss E_avg / (1 - F_ss (1 - E_avg))` (Kulla and Conty 2017), `F_ss` the lobe's
/// average single-scattering Fresnel (or colour).
pub fn multiscatter_factor(e: f32, e_avg: f32, fss: Vec3) -> Vec3 {
    if e <= 0.0 {
        return Vec3::ONE;
    }
    let missing = (1.0 - e) / e;
    if fss == Vec3::ONE {
        return Vec3::splat(1.0 + missing);
    }
    let fms = fss * e_avg / (Vec3::ONE - fss * (1.0 - e_avg));
    Vec3::ONE + fms * missing
}

/// Hemispherical average of the dielectric Fresnel reflectance, `F_ss = ∫ 2μ F(μ, η) dμ`
/// (Cycles uses a polynomial fit of this integral; here it is tabulated over the IOR
/// parametrisation, 64 nodes each for `η > 1` and `η < 1`, by 64-point midpoint quadrature
/// in `μ²`).
pub fn fresnel_dielectric_fss(eta: f32) -> f32 {
    const N: usize = 64;
    static T: [OnceLock<Vec<f32>>; 2] = [OnceLock::new(), OnceLock::new()];
    let inv = eta < 1.0;
    let t = T[inv as usize].get_or_init(|| {
        (0..N)
            .map(|i| {
                let z = node(i, N).min(0.999);
                let mut e = ior_from_f0(z * z * z * z);
                if inv {
                    e = 1.0 / e;
                }
                // ∫ 2μ F dμ = ∫ F d(μ²): midpoints in μ².
                let m = 256;
                (0..m)
                    .map(|k| {
                        let mu = ((k as f32 + 0.5) / m as f32).sqrt();
                        fresnel::dielectric(mu, e).0
                    })
                    .sum::<f32>()
                    / m as f32
            })
            .collect()
    });
    let e = if inv { 1.0 / eta } else { eta };
    let z = ((e - 1.0) / (e + 1.0)).abs().sqrt();
    read1(t, z, N)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The embedded tables are this code's quadrature (within float rounding of another libm
    /// or CPU). With `TESELA_WRITE_TABLES=1` the test writes them anew instead.
    #[test]
    fn embedded_tables_are_the_quadrature() {
        let computed = Tables::compute();
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/src/bsdf/tables.bin");
        if std::env::var_os("TESELA_WRITE_TABLES").is_some() {
            std::fs::write(path, computed.encode()).expect("write tables.bin");
            return;
        }
        let embedded = Tables::decode(EMBEDDED)
            .expect("tables.bin does not fit today's table sizes: run with TESELA_WRITE_TABLES=1");
        for (i, (a, b)) in computed.parts().iter().zip(embedded.parts()).enumerate() {
            assert_eq!(a.len(), b.len());
            for (k, (x, y)) in a.iter().zip(b).enumerate() {
                assert!(
                    (x - y).abs() <= 1e-6,
                    "table {i} entry {k}: quadrature {x}, embedded {y} (regenerate with \
                     TESELA_WRITE_TABLES=1 if the definition changed)"
                );
            }
        }
        assert!(Tables::decode(&EMBEDDED[1..]).is_none());
        assert!(Tables::decode(&EMBEDDED[..EMBEDDED.len() - 4]).is_none());
    }

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
    fn energy_tables_limits() {
        // A smooth mirror loses nothing; the factor of a white lobe is 1/E.
        let (e, avg) = ggx_e(1e-8, 1e-8, 0.7);
        assert!(
            (e - 1.0).abs() < 2e-3 && (avg - 1.0).abs() < 2e-3,
            "{e} {avg}"
        );
        let (e, avg) = ggx_e(1.0, 1.0, 1.0);
        assert!(
            e > 0.25 && e < 0.35 && avg > 0.35 && avg < 0.45,
            "{e} {avg}"
        );
        assert_eq!(multiscatter_factor(0.5, 0.4, Vec3::ONE), Vec3::splat(2.0));
        let f = multiscatter_factor(0.5, 0.4, Vec3::splat(0.5));
        assert!(f.x > 1.0 && f.x < 2.0);
        // Smooth glass: E = R + T = 1.
        for eta in [1.5f32, 0.7] {
            let (e, _) = ggx_glass_e(1e-8, 0.6, eta);
            assert!((e - 1.0).abs() < 2e-3, "{eta}: {e}");
        }
    }

    #[test]
    fn hemispherical_fresnel_average() {
        // Against a fine midpoint rule in f64 of ∫ 2μ F dμ.
        for eta in [1.1f32, 1.33, 1.5, 2.4, 0.8, 0.6] {
            let m = 20_000;
            let want: f64 = (0..m)
                .map(|k| {
                    let mu = (k as f64 + 0.5) / m as f64;
                    2.0 * mu * fresnel::dielectric(mu as f32, eta).0 as f64
                })
                .sum::<f64>()
                / m as f64;
            let got = fresnel_dielectric_fss(eta) as f64;
            assert!((got - want).abs() < 1.5e-3, "η {eta}: {got} vs {want}");
        }
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
