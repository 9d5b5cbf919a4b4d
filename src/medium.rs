//! Homogeneous interiors: a closed mesh whose material has a volume (Blender's Volume
//! Absorption, Volume Scatter, Principled Volume and Emission in the Volume input; glTF's
//! `KHR_materials_volume` attenuation) fills its inside with a medium that absorbs, scatters
//! (Henyey–Greenstein) and emits. Like Cycles' volume stack, a ray enters the interior when it
//! crosses such a surface from its front (outer) side and leaves it when it crosses back;
//! surfaces without a volume leave the current medium as it is. Outside such meshes rays travel
//! in the world's medium (its World Output's Volume; clear without one). One level: a medium
//! inside another is left into the world's.
//!
//! Path segments in a scattering medium sample a free-flight distance by spectral MIS (one of
//! the three channels' extinctions chosen, the density the mixture of the three), so chromatic
//! media stay unbiased in every channel; emission along a segment is integrated in closed form.

use crate::render_scene::{Intersection, RenderScene};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// The optical properties of a homogeneous medium, per channel, in 1/m (emission: W/(m³ sr),
/// radiance added per metre travelled).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Medium {
    /// Absorption coefficient σ_a.
    pub sigma_a: Vec3,
    /// Scattering coefficient σ_s.
    pub sigma_s: Vec3,
    /// Henyey–Greenstein mean cosine of the scattering angle (positive: forward).
    pub g: f32,
    /// Emitted radiance per unit length.
    pub emission: Vec3,
}

impl Medium {
    /// A medium that only absorbs.
    pub fn absorbing(sigma_a: Vec3) -> Medium {
        Medium {
            sigma_a: sigma_a.max(Vec3::ZERO),
            ..Default::default()
        }
    }

    /// Extinction coefficient σ_t = σ_a + σ_s.
    #[inline(always)]
    pub fn sigma_t(&self) -> Vec3 {
        self.sigma_a + self.sigma_s
    }

    /// Whether the medium does nothing to light (vacuum).
    #[inline(always)]
    pub fn is_clear(&self) -> bool {
        *self == Medium::default()
    }

    /// Whether a path segment in it needs distance sampling (it scatters or emits); a medium
    /// that only absorbs is handled by Beer's law alone.
    #[inline(always)]
    pub fn scatters_or_emits(&self) -> bool {
        self.sigma_s != Vec3::ZERO || self.emission != Vec3::ZERO
    }

    /// The medium with every coefficient finite, non-negative and `g` in (-1, 1).
    pub fn sanitized(self) -> Medium {
        let c = |v: Vec3| Vec3::new(finite_nonneg(v.x), finite_nonneg(v.y), finite_nonneg(v.z));
        Medium {
            sigma_a: c(self.sigma_a),
            sigma_s: c(self.sigma_s),
            g: if self.g.is_finite() {
                self.g.clamp(-0.99, 0.99)
            } else {
                0.0
            },
            emission: c(self.emission),
        }
    }

    /// Radiance emitted along a segment of length `t` towards its start:
    /// `∫₀ᵗ exp(-σ_t s) E ds = E (1 - exp(-σ_t t)) / σ_t` per channel (`E t` where σ_t = 0; an
    /// infinite clear segment adds nothing rather than infinity).
    #[inline]
    pub fn emitted_along(&self, t: f32) -> Vec3 {
        if self.emission == Vec3::ZERO {
            return Vec3::ZERO;
        }
        let st = self.sigma_t();
        let f = |e: f32, s: f32| {
            if e <= 0.0 {
                0.0
            } else if s > 0.0 {
                e * -(-s * t).exp_m1() / s
            } else if t.is_finite() {
                e * t
            } else {
                0.0
            }
        };
        Vec3::new(
            f(self.emission.x, st.x),
            f(self.emission.y, st.y),
            f(self.emission.z, st.z),
        )
    }

    /// Samples where a segment of length `tmax` (may be infinite) first interacts, for a path
    /// of `throughput`, with the random numbers `u` (channel choice, distance). The channel
    /// whose extinction drives the distance is chosen with probability `π_c ∝ |throughput_c
    /// albedo_c|` (Cycles' choice; uniform when that is zero), and the density of the distance
    /// is the mixture `Σ π_c σ_c exp(-σ_c t)`, so every channel's estimate stays unbiased. See
    /// [`FreeFlight`].
    #[inline]
    pub fn sample_free_flight(&self, tmax: f32, throughput: Vec3, u: Vec2) -> FreeFlight {
        let st = self.sigma_t();
        let albedo = Vec3::select(st.cmpgt(Vec3::ZERO), self.sigma_s / st, Vec3::ZERO);
        let w = (throughput * albedo).abs();
        let sum = w.element_sum();
        let pi = if sum > 0.0 && sum.is_finite() {
            w / sum
        } else {
            Vec3::splat(1.0 / 3.0)
        };
        let c = if u.x < pi.x {
            0
        } else if u.x < pi.x + pi.y || pi.z <= 0.0 {
            1
        } else {
            2
        };
        let s = st[c];
        let t = if s > 0.0 {
            -(-u.y).ln_1p() / s
        } else {
            f32::INFINITY
        };
        if t < tmax {
            let tr = transmittance(st, t);
            let pdf = (pi * st * tr).element_sum();
            if pdf > 0.0 && pdf.is_finite() {
                return FreeFlight::Scatter {
                    t,
                    weight: self.sigma_s * tr / pdf,
                    passing: tr / (pi * tr).element_sum(),
                };
            }
        }
        let tr = transmittance(st, tmax);
        let p = (pi * tr).element_sum();
        FreeFlight::Pass {
            weight: if p > 0.0 { tr / p } else { Vec3::ZERO },
        }
    }
}

/// The outcome of [`Medium::sample_free_flight`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FreeFlight {
    /// The light scatters at distance `t`: the path throughput is multiplied by `weight`
    /// (`σ_s T(t) / p(t)`); `passing` (`T(t) / P(> t)`) weighs what the segment met before `t`.
    Scatter { t: f32, weight: Vec3, passing: Vec3 },
    /// The segment reaches its end: throughput times `weight` (`T(tmax) / P(> tmax)`).
    Pass { weight: Vec3 },
}

#[inline]
fn finite_nonneg(x: f32) -> f32 {
    if x.is_finite() { x.max(0.0) } else { 0.0 }
}

/// Beer–Lambert transmittance `exp(-σ t)` per channel over distance `t` (which may be
/// infinite); a channel with `σ = 0` transmits everything.
#[inline]
pub fn transmittance(sigma: Vec3, t: f32) -> Vec3 {
    let f = |s: f32| if s > 0.0 { (-s * t).exp() } else { 1.0 };
    Vec3::new(f(sigma.x), f(sigma.y), f(sigma.z))
}

/// The Henyey–Greenstein phase function with mean cosine `g`, per steradian, of light going on
/// along `wo` after travelling along `d` (both unit; `cos = d · wo`, 1 = straight on). It is its
/// own sampling density.
#[inline]
pub fn henyey_greenstein(g: f32, cos: f32) -> f32 {
    let denom = 1.0 + g * g - 2.0 * g * cos;
    (1.0 - g * g) / (4.0 * PI * denom * denom.max(1e-12).sqrt())
}

/// Samples a direction from [`henyey_greenstein`] around the travel direction `d` (unit) with
/// `u ∈ [0,1)²`; returns the direction and its density per steradian.
#[inline]
pub fn sample_henyey_greenstein(g: f32, d: Vec3, u: Vec2) -> (Vec3, f32) {
    let cos = if g.abs() < 1e-3 {
        1.0 - 2.0 * u.x
    } else {
        let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
        (1.0 + g * g - s * s) / (2.0 * g)
    }
    .clamp(-1.0, 1.0);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let frame = crate::frame::Frame::from_normal(d);
    let (sin_phi, cos_phi) = crate::trig::sin_cos(phi);
    let wo = frame.to_world(Vec3::new(sin * cos_phi, sin * sin_phi, cos));
    (wo, henyey_greenstein(g, cos))
}

/// The medium a ray is in after it meets `its` travelling along `d` and leaves along `wo`,
/// when it was in `current` before: a crossing into a mesh with a volume (from the side its
/// normal points to) enters its interior, a crossing out of one leaves into the world's medium,
/// and reflections and surfaces without a volume change nothing.
#[inline]
pub fn after(
    scene: &RenderScene,
    its: &Intersection,
    d: Vec3,
    wo: Vec3,
    current: Medium,
) -> Medium {
    let (into, out) = (d.dot(its.ng), wo.dot(its.ng));
    if into * out <= 0.0 {
        return current;
    }
    let m = scene.programs[its.material as usize].medium();
    if m.is_clear() {
        current
    } else if into < 0.0 {
        *m
    } else {
        scene.world_medium
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transmittance_is_beers_law_and_clear_channels_pass_any_distance() {
        let t = transmittance(Vec3::new(0.0, 1.0, 2.0), 0.5);
        assert_eq!(t.x, 1.0);
        assert!((t.y - (-0.5f32).exp()).abs() < 1e-7);
        assert!((t.z - (-1.0f32).exp()).abs() < 1e-7);
        assert_eq!(
            transmittance(Vec3::new(0.0, 1.0, 0.0), f32::INFINITY),
            Vec3::new(1.0, 0.0, 1.0)
        );
    }

    #[test]
    fn henyey_greenstein_integrates_to_one_and_has_mean_cosine_g() {
        for g in [-0.7f32, 0.0, 0.3, 0.9] {
            let n = 200_000;
            let (mut total, mut mean) = (0.0f64, 0.0f64);
            for i in 0..n {
                let cos = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                let p = henyey_greenstein(g, cos as f32) as f64 * 2.0 * std::f64::consts::PI;
                total += p * 2.0 / n as f64;
                mean += p * cos * 2.0 / n as f64;
            }
            assert!((total - 1.0).abs() < 2e-3, "g {g}: ∫p = {total}");
            assert!((mean - g as f64).abs() < 2e-3, "g {g}: mean cos {mean}");
        }
    }

    /// The free-flight estimator is unbiased: the mean of (scatter weight / σ_s) over many
    /// samples is `∫₀^tmax T(t) dt` per channel, and the mean pass weight is `T(tmax)`, for a
    /// strongly chromatic medium (one channel clear).
    #[test]
    fn free_flight_weights_are_unbiased_per_channel() {
        let m = Medium {
            sigma_a: Vec3::new(0.5, 0.0, 0.0),
            sigma_s: Vec3::new(1.0, 2.0, 0.0),
            ..Default::default()
        };
        let tmax = 1.3;
        let st = m.sigma_t();
        for throughput in [Vec3::ONE, Vec3::new(0.1, 1.0, 3.0)] {
            let n = 400_000;
            let (mut inside, mut pass) = (Vec3::ZERO, Vec3::ZERO);
            let mut rng = crate::sampler::Sampler::new(7, 0, 0);
            for _ in 0..n {
                match m.sample_free_flight(tmax, throughput, rng.next_2d()) {
                    FreeFlight::Scatter { weight, .. } => inside += weight,
                    FreeFlight::Pass { weight } => pass += weight,
                }
            }
            inside /= n as f32;
            pass /= n as f32;
            for c in 0..2 {
                // E[σ_s T / p] = σ_s ∫ T = σ_s (1 - e^{-σ_t tmax}) / σ_t.
                let want = m.sigma_s[c] * (1.0 - (-st[c] * tmax).exp()) / st[c];
                assert!(
                    (inside[c] - want).abs() < 0.01 * want,
                    "channel {c}: {inside} vs {want}"
                );
                let want = (-st[c] * tmax).exp();
                assert!(
                    (pass[c] - want).abs() < 0.01 * want,
                    "channel {c}: {pass} vs {want}"
                );
            }
            assert_eq!(inside.z, 0.0);
            assert!(
                (pass.z - 1.0).abs() < 0.01,
                "the clear channel passes: {pass}"
            );
        }
    }

    #[test]
    fn emission_along_a_segment_is_integrated_in_closed_form() {
        let m = Medium {
            sigma_s: Vec3::new(2.0, 0.0, 0.0),
            emission: Vec3::new(1.0, 3.0, 0.0),
            ..Default::default()
        };
        let e = m.emitted_along(0.5);
        assert!((e.x - (1.0 - (-1.0f32).exp()) / 2.0).abs() < 1e-6);
        assert!((e.y - 1.5).abs() < 1e-6);
        assert_eq!(e.z, 0.0);
        assert_eq!(m.emitted_along(f32::INFINITY).y, 0.0);
        assert!((m.emitted_along(f32::INFINITY).x - 0.5).abs() < 1e-6);
    }
}
