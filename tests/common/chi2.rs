//! Shared statistics for the sampling tests (nori's warptest, in Rust): Pearson's chi-square
//! test with pooling of sparse cells, the chi-square distribution via the regularized
//! incomplete gamma function, adaptive 2D cubature for expected cell counts, and a histogram
//! grid over directions.
//!
//! Included from the test crates with `#[path = "common/chi2.rs"] mod chi2_common;`.

#![allow(dead_code)]

use glam::{DVec3, Vec3};
use std::f64::consts::PI;
use tesela::frame::Frame;
use tesela::sampler::Sampler;

/// Significance level of every family of chi-square tests.
pub const SIGNIFICANCE: f64 = 0.01;

/// Cells whose expected count is below this are pooled (Cochran's rule).
pub const MIN_EXPECTED: f64 = 5.0;

/// Per-case significance that keeps the family-wise level at `alpha` over `m` cases (Šidák).
pub fn sidak(alpha: f64, m: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / m.max(1) as f64)
}

/// `ln Γ(x)` for `x > 0` (Lanczos, g = 7, 9 terms; ~1e-15 relative).
pub fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + 7.5;
    let mut a = C[0];
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularized upper incomplete gamma function `Q(a, x) = Γ(a, x) / Γ(a)`
/// (series for `x < a + 1`, Lentz's continued fraction otherwise; Numerical Recipes §6.2).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    assert!(a > 0.0 && x.is_finite(), "gamma_q({a}, {x})");
    if x <= 0.0 {
        return 1.0;
    }
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut ap, mut del) = (a, 1.0 / a);
        let mut sum = del;
        for _ in 0..100_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * front).max(0.0)
    } else {
        const TINY: f64 = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..100_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < TINY {
                d = TINY;
            }
            c = b + an / c;
            if c.abs() < TINY {
                c = TINY;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (front * h).clamp(0.0, 1.0)
    }
}

/// Upper tail `P[X > stat]` of the chi-square distribution with `dof` degrees of freedom.
pub fn chi2_sf(stat: f64, dof: usize) -> f64 {
    gamma_q(dof as f64 / 2.0, stat / 2.0)
}

/// Outcome of a Pearson test.
#[derive(Clone, Copy, Debug)]
pub struct Chi2 {
    pub stat: f64,
    pub dof: usize,
    pub p: f64,
    /// Cells that entered the statistic (after pooling).
    pub cells: usize,
    /// Cells merged into the pooled cell.
    pub pooled: usize,
}

/// Pearson's chi-square statistic of observed vs expected counts, nori-style: cells are taken
/// in order of increasing expected count; those expecting fewer than [`MIN_EXPECTED`] are pooled
/// (and pooling continues until the pooled cell itself reaches the minimum). A cell with zero
/// expected count but observed samples is an immediate failure (samples where the density is 0).
pub fn pearson(observed: &[f64], expected: &[f64]) -> Result<Chi2, String> {
    assert_eq!(observed.len(), expected.len());
    let mut idx: Vec<usize> = (0..observed.len()).collect();
    idx.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut stat, mut dof, mut pooled) = (0.0, 0usize, 0usize);
    let (mut pool_obs, mut pool_exp) = (0.0, 0.0);
    for &i in &idx {
        let (o, e) = (observed[i], expected[i]);
        if e <= 1e-9 {
            if o > 0.0 {
                return Err(format!(
                    "{o} samples in cell {i} whose expected count is {e:e} (the density is 0 there)"
                ));
            }
        } else if e < MIN_EXPECTED || (pool_exp > 0.0 && pool_exp < MIN_EXPECTED) {
            pool_obs += o;
            pool_exp += e;
            pooled += 1;
        } else {
            stat += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pool_exp > 0.0 {
        stat += (pool_obs - pool_exp) * (pool_obs - pool_exp) / pool_exp;
        dof += 1;
    } else if pool_obs > 0.0 {
        return Err(format!("{pool_obs} samples in pooled cells expecting none"));
    }
    let cells = dof;
    if dof < 2 {
        return Err(format!("too few cells ({dof}) for a chi-square test"));
    }
    dof -= 1;
    Ok(Chi2 {
        stat,
        dof,
        p: chi2_sf(stat, dof),
        cells,
        pooled,
    })
}

/// Runs [`pearson`], prints the result, and panics when the test rejects at level `alpha`.
pub fn assert_chi2(name: &str, observed: &[f64], expected: &[f64], alpha: f64) -> Chi2 {
    match pearson(observed, expected) {
        Ok(r) => {
            println!(
                "{name}: chi2 = {:.1}, dof = {}, p = {:.4} ({} cells, {} pooled)",
                r.stat, r.dof, r.p, r.cells, r.pooled
            );
            assert!(
                r.p >= alpha,
                "{name}: chi-square test rejected the sampler: chi2 = {:.1}, dof = {}, p = {:.3e} < {alpha:.3e}",
                r.stat,
                r.dof,
                r.p
            );
            r
        }
        Err(e) => panic!("{name}: {e}"),
    }
}

/// Two-outcome test: `k` successes out of `n` trials against probability `p`, as a 1-dof
/// chi-square (equivalent to the two-sided normal approximation of the binomial). Returns the
/// p-value; `p` of exactly 0 or 1 demands `k` of exactly 0 or `n`.
pub fn binomial_p_value(k: u64, n: u64, p: f64) -> f64 {
    let (k, n) = (k as f64, n as f64);
    if p <= 0.0 {
        return if k == 0.0 { 1.0 } else { 0.0 };
    }
    if p >= 1.0 {
        return if k == n { 1.0 } else { 0.0 };
    }
    let var = n * p * (1.0 - p);
    chi2_sf((k - n * p) * (k - n * p) / var, 1)
}

const GL3_X: [f64; 3] = [-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4];
const GL3_W: [f64; 3] = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];

fn gl3(f: &dyn Fn(f64, f64) -> f64, x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    let (cx, hx) = (0.5 * (x0 + x1), 0.5 * (x1 - x0));
    let (cy, hy) = (0.5 * (y0 + y1), 0.5 * (y1 - y0));
    let mut s = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            s += GL3_W[i] * GL3_W[j] * f(cx + hx * GL3_X[i], cy + hy * GL3_X[j]);
        }
    }
    s * hx * hy
}

#[allow(clippy::too_many_arguments)]
fn adapt(
    f: &dyn Fn(f64, f64) -> f64,
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    whole: f64,
    tol: f64,
    depth: u32,
) -> f64 {
    let (xm, ym) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let q = [
        gl3(f, x0, xm, y0, ym),
        gl3(f, xm, x1, y0, ym),
        gl3(f, x0, xm, ym, y1),
        gl3(f, xm, x1, ym, y1),
    ];
    let sum: f64 = q.iter().sum();
    if depth >= 7 || (sum - whole).abs() <= tol {
        return sum;
    }
    let t = tol * 0.5;
    adapt(f, x0, xm, y0, ym, q[0], t, depth + 1)
        + adapt(f, xm, x1, y0, ym, q[1], t, depth + 1)
        + adapt(f, x0, xm, ym, y1, q[2], t, depth + 1)
        + adapt(f, xm, x1, ym, y1, q[3], t, depth + 1)
}

/// Adaptive tensor Gauss–Legendre cubature of `f` over `[x0,x1]×[y0,y1]` to absolute
/// tolerance `tol` (subdivision stops at depth 7, enough for the discontinuities of
/// horizon, cone and polygon edges at the accuracy the tests need).
pub fn integrate(f: &dyn Fn(f64, f64) -> f64, x0: f64, x1: f64, y0: f64, y1: f64, tol: f64) -> f64 {
    let whole = gl3(f, x0, x1, y0, y1);
    adapt(f, x0, x1, y0, y1, whole, tol, 0)
}

/// A histogram grid over a cap of the unit sphere around `axis`: rows in
/// `θ = θ_max · x^γ` (γ > 1 concentrates rows near the axis, for peaked lobes), columns in
/// `φ = 2π y`. Directions beyond `θ_max` fall outside the grid.
pub struct DirGrid {
    s: DVec3,
    t: DVec3,
    n: DVec3,
    pub theta_max: f64,
    pub gamma: f64,
    pub nt: usize,
    pub np: usize,
}

impl DirGrid {
    pub fn new(axis: Vec3, theta_max: f64, gamma: f64, nt: usize, np: usize) -> Self {
        let f = Frame::from_normal(axis.normalize());
        DirGrid {
            s: f.s.as_dvec3(),
            t: f.t.as_dvec3(),
            n: f.n.as_dvec3(),
            theta_max: theta_max.min(PI),
            gamma,
            nt,
            np,
        }
    }

    /// The whole sphere around +Z.
    pub fn sphere(nt: usize, np: usize) -> Self {
        DirGrid::new(Vec3::Z, PI, 1.0, nt, np)
    }

    pub fn cells(&self) -> usize {
        self.nt * self.np
    }

    /// Direction at grid coordinates `(x, y) ∈ [0,1]²` and the Jacobian `dω / (dx dy)`.
    pub fn dir(&self, x: f64, y: f64) -> (DVec3, f64) {
        let theta = self.theta_max * x.powf(self.gamma);
        let dtheta = if self.gamma == 1.0 {
            self.theta_max
        } else {
            self.theta_max * self.gamma * x.powf(self.gamma - 1.0)
        };
        let phi = 2.0 * PI * y;
        let (st, ct) = theta.sin_cos();
        let l = DVec3::new(st * phi.cos(), st * phi.sin(), ct);
        (
            self.s * l.x + self.t * l.y + self.n * l.z,
            dtheta * 2.0 * PI * st,
        )
    }

    /// The cell holding direction `w`, or `None` beyond `θ_max` (or for a non-finite `w`).
    pub fn cell(&self, w: Vec3) -> Option<usize> {
        let w = w.as_dvec3();
        if !w.is_finite() || w.length_squared() == 0.0 {
            return None;
        }
        let l = DVec3::new(w.dot(self.s), w.dot(self.t), w.dot(self.n));
        let theta = l.x.hypot(l.y).atan2(l.z);
        if theta > self.theta_max {
            return None;
        }
        let x = (theta / self.theta_max).powf(1.0 / self.gamma);
        let mut phi = l.y.atan2(l.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        // Rows are closed above, `(θ_a, θ_b]`: a direction exactly on a row boundary such as the
        // horizon (z = 0, which the warps produce for `u` on the square's edge) belongs to the
        // row above it, where its density is defined by continuity.
        let i = ((x * self.nt as f64).ceil() as usize).clamp(1, self.nt) - 1;
        let j = ((phi / (2.0 * PI) * self.np as f64) as usize).min(self.np - 1);
        Some(i * self.np + j)
    }

    /// `∫_cell pdf dω` of cell `c` by the `m×m` midpoint rule.
    pub fn dense_cell_integral(&self, c: usize, pdf: &dyn Fn(Vec3) -> f64, m: usize) -> f64 {
        let (i, j) = (c / self.np, c % self.np);
        let (hx, hy) = (1.0 / (self.nt * m) as f64, 1.0 / (self.np * m) as f64);
        let mut s = 0.0;
        for a in 0..m {
            for b in 0..m {
                let x = (i * m + a) as f64 * hx + 0.5 * hx;
                let y = (j * m + b) as f64 * hy + 0.5 * hy;
                let (w, jac) = self.dir(x, y);
                s += pdf(w.as_vec3()) * jac;
            }
        }
        s * hx * hy
    }

    /// `n ∫_cell pdf dω` for every cell (`pdf` takes a unit direction).
    pub fn expected(&self, pdf: &dyn Fn(Vec3) -> f64, n: f64) -> Vec<f64> {
        let tol = 0.01 / n;
        let f = |x: f64, y: f64| {
            let (w, jac) = self.dir(x, y);
            if jac == 0.0 {
                0.0
            } else {
                pdf(w.as_vec3()) * jac
            }
        };
        let mut out = Vec::with_capacity(self.cells());
        for i in 0..self.nt {
            for j in 0..self.np {
                let (x0, x1) = (i as f64 / self.nt as f64, (i + 1) as f64 / self.nt as f64);
                let (y0, y1) = (j as f64 / self.np as f64, (j + 1) as f64 / self.np as f64);
                out.push(n * integrate(&f, x0, x1, y0, y1, tol));
            }
        }
        out
    }
}

/// Result of [`check_directions`].
#[derive(Clone, Copy, Debug)]
pub struct DirCheck {
    pub chi2: Chi2,
    /// `∫ pdf dω` over the grid (numerical).
    pub integral: f64,
    /// Fraction of samples that failed or fell outside the grid.
    pub rest_fraction: f64,
}

/// Draws `n` directions with `sample` (which may fail: `None`), histograms them on `grid`, and
/// runs Pearson's test against `n ∫ pdf` per cell plus one "rest" cell holding the failed or
/// out-of-grid samples, whose expected count is `n (1 - ∫_grid pdf)` (so a sampler that fails
/// more or less often than its density's missing mass says is caught too).
pub fn check_directions(
    name: &str,
    grid: &DirGrid,
    n: usize,
    seed: u64,
    sample: &mut dyn FnMut(&mut Sampler) -> Option<Vec3>,
    pdf: &dyn Fn(Vec3) -> f64,
    alpha: f64,
) -> DirCheck {
    check_directions_with(name, grid, n, seed, sample, pdf, alpha, false)
}

/// [`check_directions`] with every cell's expected count from the dense 128×128 midpoint
/// rule (`dense`), for piecewise-constant densities (an environment map) whose many sharp
/// steps the adaptive cubature can misjudge.
#[allow(clippy::too_many_arguments, dead_code)]
pub fn check_directions_with(
    name: &str,
    grid: &DirGrid,
    n: usize,
    seed: u64,
    sample: &mut dyn FnMut(&mut Sampler) -> Option<Vec3>,
    pdf: &dyn Fn(Vec3) -> f64,
    alpha: f64,
    dense: bool,
) -> DirCheck {
    let mut rng = Sampler::new(seed, 0, 0);
    let mut obs = vec![0.0; grid.cells() + 1];
    for _ in 0..n {
        let c = sample(&mut rng).and_then(|w| grid.cell(w));
        match c {
            Some(c) => obs[c] += 1.0,
            None => obs[grid.cells()] += 1.0,
        }
    }
    let mut exp = grid.expected(pdf, n as f64);
    // A cell the cubature found empty may still hold a sliver of the support that no node hit
    // (e.g. a corner just above the horizon). Before calling its samples an error, re-integrate
    // such cells with a dense 128×128 midpoint rule.
    for c in 0..grid.cells() {
        if dense || (exp[c] <= 1e-9 && obs[c] > 0.0) {
            exp[c] = n as f64 * grid.dense_cell_integral(c, pdf, 128);
        }
    }
    let inside: f64 = exp.iter().sum();
    let integral = inside / n as f64;
    exp.push((n as f64 - inside).max(0.0));
    let rest_fraction = obs[grid.cells()] / n as f64;
    println!("{name}: ∫pdf over grid = {integral:.6}, rest fraction = {rest_fraction:.6}");
    let chi2 = assert_chi2(name, &obs, &exp, alpha);
    DirCheck {
        chi2,
        integral,
        rest_fraction,
    }
}
