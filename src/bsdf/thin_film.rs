//! Thin-film interference on a dielectric (the Principled BSDF's Thin Film Thickness and IOR):
//! the reflectance of a film of thickness `d` and index `n₂` between the outside (`n₁ = 1`)
//! and the substrate (`n₃`), after Belcour and Barla 2017 ("A Practical Extension to
//! Microfacet Theory for the Modeling of Varying Iridescence"), as Cycles 5.0 evaluates it.
//!
//! The Airy sum over the light bouncing inside the film is, per polarisation,
//! `R = R₁₂ + Rₛ + Σ_{m≥1} 2 C_m Re(e^{i m φ} S(m·OPD))` with `OPD = 2 n₂ d cos θ₂` (nm),
//! `Rₛ = T₁₂² R₂₃ / (1 - R₁₂ R₂₃)`, `C_m = (Rₛ - T₁₂)(√(R₁₂R₂₃))^m`, `φ` the phase shifts of
//! the two reflections (0 or π for dielectrics). `S(x)` is, per RGB channel, the Fourier
//! transform of that channel's colour matching function taken over frequency `ν = 1/λ`,
//! normalised so that `S(0) = 1`: the spectral integral of the interference term in closed
//! form. The sum stops at `m = 3`, as Cycles' does (higher orders barely change it).

use glam::Vec3;
use std::sync::OnceLock;

/// Films at most this thick (nm) are no film (Cycles' `THINFILM_THICKNESS_CUTOFF`).
pub const THICKNESS_CUTOFF: f32 = 0.1;

/// A thin film over a dielectric: thickness in nanometres, index of refraction (absolute:
/// relative to the outside of the surface).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinFilm {
    pub thickness: f32,
    pub ior: f32,
}

impl ThinFilm {
    /// The film of Blender's inputs, or `None` where there is none (thickness at most
    /// [`THICKNESS_CUTOFF`], or not a number). The IOR is kept above 0 as Cycles keeps it.
    pub fn new(thickness: f32, ior: f32) -> Option<ThinFilm> {
        (thickness.is_finite() && thickness > THICKNESS_CUTOFF).then(|| ThinFilm {
            thickness: thickness.min(1e6),
            ior: if ior.is_finite() { ior.max(1e-5) } else { 1.33 },
        })
    }

    /// Reflectance per RGB channel at incidence `cos_i > 0` onto a substrate of relative
    /// index `eta` (inside over outside, as seen from the incident side), the film's index
    /// being `film_eta` relative to the incident side too. 1 under total internal reflection
    /// at either interface.
    pub fn reflectance(&self, cos_i: f32, eta: f32, film_eta: f32) -> Vec3 {
        // Below 1 nm the wave-optics sum no longer holds: blend the film towards the outside.
        let film = if self.thickness < 1.0 {
            let t = self.thickness;
            1.0 + (film_eta - 1.0) * (t * t * (3.0 - 2.0 * t))
        } else {
            film_eta
        };
        let Some(top) = Interface::new(cos_i, film) else {
            return Vec3::ONE;
        };
        let Some(bottom) = Interface::new(top.cos_t, eta / film) else {
            return Vec3::ONE;
        };
        let opd = 2.0 * film * self.thickness * top.cos_t;
        let table = table();
        let s = airy(table, top.r_s, bottom.r_s, opd, -top.sign_s * bottom.sign_s);
        let p = airy(table, top.r_p, bottom.r_p, opd, -top.sign_p * bottom.sign_p);
        ((s + p) * 0.5).clamp(Vec3::ZERO, Vec3::ONE)
    }

    /// [`ThinFilm::principled`] for light arriving from outside or (`inside`) from within a
    /// substrate of relative index `eta` seen from the incident side, `F0 = F0(eta)` scaled by
    /// `f0_scale` (Specular Tint): the film's index is relative to the outside, so from within
    /// it is taken relative to the substrate.
    pub fn on_dielectric(&self, cos_i: f32, eta: f32, inside: bool, f0_scale: Vec3) -> Vec3 {
        let film_eta = if inside { self.ior * eta } else { self.ior };
        let f0_tint = (super::fresnel::f0_from_ior(eta) * f0_scale).min(Vec3::ONE);
        self.principled(cos_i, eta, film_eta, f0_tint)
    }

    /// The Principled BSDF's reflectance with the film: [`ThinFilm::reflectance`] with each
    /// channel scaled towards `f0_tint / F0` (Specular Tint's scale of `F0 = F0(eta)`,
    /// `f0_tint` = the tinted, clamped `F0`) as much as it lies below 1 relative to `F0`,
    /// which is how Cycles lets Specular Tint act on an iridescent reflectance that may fall
    /// below `F0`.
    pub fn principled(&self, cos_i: f32, eta: f32, film_eta: f32, f0_tint: Vec3) -> Vec3 {
        let f = self.reflectance(cos_i, eta, film_eta);
        let f0 = super::fresnel::f0_from_ior(eta);
        if f0 <= 1e-5 || f == Vec3::ONE || f0 >= 1.0 {
            return f;
        }
        let scale = |f: f32, t: f32| {
            let s = ((f - 1.0) / (f0 - 1.0)).clamp(0.0, 1.0);
            f * (1.0 + (t / f0 - 1.0) * s)
        };
        Vec3::new(
            scale(f.x, f0_tint.x),
            scale(f.y, f0_tint.y),
            scale(f.z, f0_tint.z),
        )
    }
}

/// One interface's polarised reflectances and the sign of their amplitudes (the phase shift:
/// +1 for none, -1 for π), and the cosine on the far side.
struct Interface {
    r_s: f32,
    r_p: f32,
    sign_s: f32,
    sign_p: f32,
    cos_t: f32,
}

impl Interface {
    /// At incidence `cos_i ≥ 0` onto relative index `eta`; `None` under total internal
    /// reflection.
    fn new(cos_i: f32, eta: f32) -> Option<Interface> {
        let e2 = eta * eta - (1.0 - cos_i * cos_i);
        if e2 <= 0.0 {
            return None;
        }
        let cos_t = e2.sqrt() / eta;
        let a_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
        let a_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
        let sign = |a: f32| if a >= 0.0 { 1.0 } else { -1.0 };
        Some(Interface {
            r_s: a_s * a_s,
            r_p: a_p * a_p,
            sign_s: sign(a_s),
            sign_p: sign(a_p),
            cos_t,
        })
    }
}

/// The Airy sum of one polarisation, per channel; `phasor` is `e^{iφ}` (real: ±1).
fn airy(table: &Table, r12: f32, r23: f32, opd: f32, phasor: f32) -> Vec3 {
    let t121 = 1.0 - r12;
    let r123 = r12 * r23;
    let root = r123.sqrt();
    let rs = t121 * t121 * r23 / (1.0 - r123);
    let mut r = Vec3::splat(rs + r12);
    let mut cm = rs - t121;
    let mut ph = phasor;
    for m in 1..4 {
        cm *= root;
        // Re(e^{imφ} S) with a real phasor: only the real part of S is needed.
        r += table.lookup(m as f32 * opd) * (2.0 * cm * ph);
        ph *= phasor;
    }
    r
}

/// Entries of the sensitivity table over optical path differences 0 to [`TABLE_OPD`].
const TABLE_SIZE: usize = 512;
/// Optical path difference (nm) the table's last entry stands for: `60 µm / 2π`.
const TABLE_OPD: f32 = 60_000.0 / std::f32::consts::TAU;

/// `Re S(OPD)` per RGB channel: with a dielectric substrate the phase shifts are 0 or π, so
/// the imaginary part never enters the sum.
struct Table {
    re: Vec<Vec3>,
}

impl Table {
    /// Linear interpolation between entries, clamped at the ends.
    fn lookup(&self, opd: f32) -> Vec3 {
        let x = (opd / TABLE_OPD).clamp(0.0, 1.0) * (TABLE_SIZE - 1) as f32;
        let i = (x as usize).min(TABLE_SIZE - 1);
        let j = (i + 1).min(TABLE_SIZE - 1);
        let t = x - i as f32;
        self.re[i] * (1.0 - t) + self.re[j] * t
    }
}

/// The sensitivity table, built on first use: the colour matching functions resampled at
/// `N` frequencies `ν_n = n π / 60 µm⁻¹` (with the `dλ = dν / ν²` change of measure),
/// the real part of their discrete Fourier transform at `k = 0 .. TABLE_SIZE`, converted
/// from XYZ to the working RGB and normalised by each channel's `k = 0` term.
fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        const N: usize = 2 * (TABLE_SIZE - 1);
        let step = std::f64::consts::PI / 60.0;
        let samples: Vec<(usize, [f64; 3])> = (1..N)
            .filter_map(|n| {
                let nu = n as f64 * step;
                let xyz = crate::shading::nodes::color::wavelength_xyz((1000.0 / nu) as f32);
                (xyz != Vec3::ZERO).then(|| {
                    let w = 1.0 / (nu * nu);
                    (n, [xyz.x as f64 * w, xyz.y as f64 * w, xyz.z as f64 * w])
                })
            })
            .collect();
        let m = crate::shading::nodes::color::XYZ_TO_RGB;
        let to_rgb = |v: [f64; 3]| {
            let row = |r: Vec3| r.x as f64 * v[0] + r.y as f64 * v[1] + r.z as f64 * v[2];
            [row(m[0]), row(m[1]), row(m[2])]
        };
        let mut re = Vec::with_capacity(TABLE_SIZE);
        let mut norm = [1.0f64; 3];
        for k in 0..TABLE_SIZE {
            let mut a = [0.0f64; 3];
            for &(n, s) in &samples {
                let cos = (std::f64::consts::TAU * (k * n) as f64 / N as f64).cos();
                for c in 0..3 {
                    a[c] += s[c] * cos;
                }
            }
            let a = to_rgb(a);
            if k == 0 {
                norm = [1.0 / a[0], 1.0 / a[1], 1.0 / a[2]];
            }
            re.push(Vec3::new(
                (a[0] * norm[0]) as f32,
                (a[1] * norm[1]) as f32,
                (a[2] * norm[2]) as f32,
            ));
        }
        Table { re }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::fresnel;

    #[test]
    fn no_film_below_the_cutoff() {
        assert!(ThinFilm::new(0.1, 1.33).is_none());
        assert!(ThinFilm::new(f32::NAN, 1.33).is_none());
        assert!(ThinFilm::new(0.2, 1.33).is_some());
    }

    #[test]
    fn a_film_of_the_substrate_index_is_the_plain_fresnel() {
        // n₂ = n₃: no bottom interface, so no interference at any thickness.
        for d in [50.0, 300.0, 1200.0] {
            let f = ThinFilm::new(d, 1.5).unwrap();
            for c in [1.0, 0.7, 0.3, 0.05] {
                let r = f.reflectance(c, 1.5, 1.5);
                let plain = fresnel::dielectric(c, 1.5).0;
                assert!(
                    (r - Vec3::splat(plain)).abs().max_element() < 2e-3,
                    "{r} vs {plain}"
                );
            }
        }
    }

    #[test]
    fn a_thick_film_averages_to_the_incoherent_sum() {
        // At thicknesses far beyond the coherence the table covers, the interference terms
        // vanish and R = R₁₂ + T₁₂² R₂₃ / (1 − R₁₂ R₂₃), averaged over the polarisations.
        let f = ThinFilm::new(20_000.0, 1.33).unwrap();
        let c = 0.8;
        let r = f.reflectance(c, 1.5, 1.33);
        let top = Interface::new(c, 1.33).unwrap();
        let bottom = Interface::new(top.cos_t, 1.5 / 1.33).unwrap();
        let inc = |a: f32, b: f32| a + (1.0 - a) * (1.0 - a) * b / (1.0 - a * b);
        let want = 0.5 * (inc(top.r_s, bottom.r_s) + inc(top.r_p, bottom.r_p));
        assert!(
            (r - Vec3::splat(want)).abs().max_element() < 1e-3,
            "{r} vs {want}"
        );
    }

    /// The reflectance integrated over wavelengths directly (1 nm steps): the exact Airy
    /// reflectance of each polarisation, weighted by each RGB channel's colour matching
    /// function and normalised by its integral.
    fn spectral(d: f32, cos_i: f32, eta: f32, film: f32) -> Vec3 {
        let top = Interface::new(cos_i, film).unwrap();
        let bottom = Interface::new(top.cos_t, eta / film).unwrap();
        let m = crate::shading::nodes::color::XYZ_TO_RGB;
        let (mut num, mut den) = (Vec3::ZERO, Vec3::ZERO);
        for l in 380..780 {
            let lambda = l as f32;
            let xyz = crate::shading::nodes::color::wavelength_xyz(lambda);
            let rgb = Vec3::new(m[0].dot(xyz), m[1].dot(xyz), m[2].dot(xyz));
            let delta = std::f32::consts::TAU * 2.0 * film * d * top.cos_t / lambda;
            let pol = |r12: f32, s12: f32, r23: f32, s23: f32| {
                // Amplitudes r₁₂ (top, from outside) and r₂₃; r₂₁ = -r₁₂.
                let (a, b) = (s12 * r12.sqrt(), s23 * r23.sqrt());
                let (c, s) = (delta.cos(), delta.sin());
                let num = (a + b * c).powi(2) + (b * s).powi(2);
                let den = (1.0 + a * b * c).powi(2) + (a * b * s).powi(2);
                num / den
            };
            let r = 0.5
                * (pol(top.r_s, top.sign_s, bottom.r_s, bottom.sign_s)
                    + pol(top.r_p, top.sign_p, bottom.r_p, bottom.sign_p));
            num += rgb * r;
            den += rgb;
        }
        num / den
    }

    #[test]
    fn the_fourier_table_matches_the_spectral_integral() {
        // Soap films (air on both sides) and coatings on glass, thin to iridescent-thick, at
        // normal and oblique incidence: the colours the table gives are those of integrating
        // the interference over the spectrum, to within the sum's truncation and sampling.
        for (eta, film) in [(1.0, 1.33), (1.5, 1.33), (1.5, 2.0)] {
            for d in [80.0, 150.0, 300.0, 500.0, 800.0] {
                for c in [1.0, 0.6] {
                    let f = ThinFilm::new(d, film).unwrap();
                    let got = f.reflectance(c, eta, film);
                    let want = spectral(d, c, eta, film);
                    let err = (got - want).abs().max_element();
                    assert!(
                        err < 0.02,
                        "eta {eta} film {film} d {d} cos {c}: {got} vs {want}"
                    );
                }
            }
        }
        // And the colours do change with thickness (a bug that drops the interference
        // passes the test above only where the spectral colour is flat).
        let f = |d: f32| ThinFilm::new(d, 1.33).unwrap().reflectance(1.0, 1.0, 1.33);
        assert!((f(150.0) - f(300.0)).abs().max_element() > 0.02);
    }

    #[test]
    fn principled_tint_scales_towards_f0() {
        let f = ThinFilm::new(400.0, 1.33).unwrap();
        let eta = 1.5;
        let f0 = fresnel::f0_from_ior(eta);
        let white = f.principled(0.9, eta, 1.33, Vec3::splat(f0));
        assert_eq!(white, f.reflectance(0.9, eta, 1.33));
        let black = f.principled(0.9, eta, 1.33, Vec3::ZERO);
        assert!(black.max_element() < white.max_element());
        assert!(black.min_element() >= 0.0);
    }
}
