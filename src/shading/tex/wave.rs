//! Blender's Wave Texture node (`ShaderNodeTexWave`), as Cycles 5.0 evaluates it
//! (`kernel/svm/wave.h`).
//!
//! At `q = (p * scale + 1e-6) * 0.999999` (a nudge against precision issues on unit
//! coordinates), the phase is
//! - Bands: `n = 20 q.x` (or `.y`, `.z`), Diagonal `n = 10 (q.x + q.y + q.z)`;
//! - Rings: `n = 20 |q'|`, `q'` being `q` with the axis' own component zeroed (X, Y, Z), or `q`
//!   itself (Spherical);
//!
//! then `n += phase_offset`, and with distortion `d != 0`,
//! `n += d (2 fbm(q * detail_scale, detail, detail_roughness, lacunarity 2, normalized) - 1)`
//! (the fBm of [`super::noise::fbm`]). The profile makes it a value in `[0, 1]`:
//! Sine `0.5 + 0.5 sin(n - pi/2)`, Saw `frac(n / 2pi)`, Triangle `2 |n/2pi - round(n/2pi)|`.
//! Color is `(Fac, Fac, Fac)`.
//!
//! Rounding follows Cycles' x86 AVX2 kernel (FMAs, `/ 2pi` as `* (1 / 2pi)`): bit-exact
//! against Cycles 5.0 renders.

use glam::Vec3;

use super::noise::fbm;

/// The node's "Wave Type" menu.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum WaveType {
    #[default]
    Bands,
    Rings,
}

/// The direction of bands ("Bands Direction") or the axis of rings ("Rings Direction");
/// `Diagonal` applies to bands only and `Spherical` to rings only (each falls back to the
/// other's meaning: diagonal rings and spherical bands do not exist in Blender).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum WaveDirection {
    #[default]
    X,
    Y,
    Z,
    Diagonal,
    Spherical,
}

/// The node's "Wave Profile" menu.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum WaveProfile {
    #[default]
    Sine,
    Saw,
    Triangle,
}

/// The node's settings and unlinked inputs (Blender's defaults in `Default`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaveParams {
    pub wave_type: WaveType,
    pub direction: WaveDirection,
    pub profile: WaveProfile,
    pub scale: f32,
    pub distortion: f32,
    pub detail: f32,
    pub detail_scale: f32,
    pub detail_roughness: f32,
    pub phase_offset: f32,
}

impl Default for WaveParams {
    fn default() -> Self {
        Self {
            wave_type: WaveType::Bands,
            direction: WaveDirection::X,
            profile: WaveProfile::Sine,
            scale: 5.0,
            distortion: 0.0,
            detail: 2.0,
            detail_scale: 1.0,
            detail_roughness: 0.5,
            phase_offset: 0.0,
        }
    }
}

/// The Wave Texture node: returns `(Color, Fac)` at texture coordinate `p`.
pub fn wave(p: Vec3, params: &WaveParams) -> (Vec3, f32) {
    // Cycles' x86 AVX2 kernel fuses `p * scale + 1e-6` into one FMA (measured: without it, the
    // phase differs by an ulp on ~15 % of pixels).
    let nudge = |x: f32| x.mul_add(params.scale, 0.000001) * 0.999999;
    let f = wave_fac(Vec3::new(nudge(p.x), nudge(p.y), nudge(p.z)), params);
    (Vec3::splat(f), f)
}

/// `svm_wave` after the nudge `p = (p + 1e-6) * 0.999999`.
fn wave_fac(p: Vec3, w: &WaveParams) -> f32 {
    let mut n = match w.wave_type {
        WaveType::Bands => match w.direction {
            WaveDirection::X => p.x * 20.0,
            WaveDirection::Y => p.y * 20.0,
            WaveDirection::Z => p.z * 20.0,
            WaveDirection::Diagonal | WaveDirection::Spherical => (p.x + p.y + p.z) * 10.0,
        },
        WaveType::Rings => {
            let rp = match w.direction {
                WaveDirection::X => p * Vec3::new(0.0, 1.0, 1.0),
                WaveDirection::Y => p * Vec3::new(1.0, 0.0, 1.0),
                WaveDirection::Z => p * Vec3::new(1.0, 1.0, 0.0),
                WaveDirection::Diagonal | WaveDirection::Spherical => p,
            };
            (rp.x * rp.x + rp.y * rp.y + rp.z * rp.z).sqrt() * 20.0
        }
    };
    n += w.phase_offset;
    if w.distortion != 0.0 {
        let noise = fbm(p * w.detail_scale, w.detail, w.detail_roughness, 2.0, true);
        n = w.distortion.mul_add(noise.mul_add(2.0, -1.0), n);
    }
    // Cycles is built with fast math: `n / 2pi` is `n * (1 / 2pi)` (measured: ulp-exact so).
    const INV_TWO_PI: f32 = 1.0 / core::f32::consts::TAU;
    match w.profile {
        WaveProfile::Sine => 0.5 + 0.5 * (n - core::f32::consts::FRAC_PI_2).sin(),
        WaveProfile::Saw => {
            let n = n * INV_TWO_PI;
            n - n.floor()
        }
        WaveProfile::Triangle => {
            let n = n * INV_TWO_PI;
            (n - (n + 0.5).floor()).abs() * 2.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_measured_from_cycles() {
        // Measured from Cycles 5.0 renders: (params, p, Fac).
        for (w, p, fac) in measured() {
            let got = wave(Vec3::from_array(p), &w).1;
            assert!((got - fac).abs() < 1e-6, "{w:?} {p:?}: {got} vs {fac}");
        }
    }

    fn measured() -> Vec<(WaveParams, [f32; 3], f32)> {
        let (a, b) = (
            [1.3965002, -1.0534997, 0.86901003],
            [-1.3474997, 0.36750025, -0.47309995],
        );
        let rings_z = WaveParams {
            wave_type: WaveType::Rings,
            direction: WaveDirection::Z,
            scale: 1.3,
            distortion: 6.0,
            detail: 7.5,
            detail_roughness: 0.8,
            ..Default::default()
        };
        let diag_saw = WaveParams {
            direction: WaveDirection::Diagonal,
            profile: WaveProfile::Saw,
            scale: 0.8,
            distortion: 2.5,
            detail: 3.4,
            detail_scale: 2.2,
            detail_roughness: 0.65,
            ..Default::default()
        };
        let sphere_tri = WaveParams {
            wave_type: WaveType::Rings,
            direction: WaveDirection::Spherical,
            profile: WaveProfile::Triangle,
            scale: 0.9,
            phase_offset: -1.3,
            ..Default::default()
        };
        let bands_y = WaveParams {
            direction: WaveDirection::Y,
            scale: 0.9,
            phase_offset: 0.7,
            ..Default::default()
        };
        vec![
            (rings_z, a, 0.7473034),
            (rings_z, b, 0.7425471),
            (diag_saw, a, 0.52633286),
            (diag_saw, b, 0.19126141),
            (sphere_tri, a, 0.777586),
            (sphere_tri, b, 0.035387993),
            (bands_y, a, 0.083586395),
            (bands_y, b, 0.2433764),
        ]
    }

    #[test]
    fn in_unit_range() {
        let types = [WaveType::Bands, WaveType::Rings];
        let dirs = [
            WaveDirection::X,
            WaveDirection::Y,
            WaveDirection::Z,
            WaveDirection::Diagonal,
            WaveDirection::Spherical,
        ];
        let profiles = [WaveProfile::Sine, WaveProfile::Saw, WaveProfile::Triangle];
        for wave_type in types {
            for direction in dirs {
                for profile in profiles {
                    let w = WaveParams {
                        wave_type,
                        direction,
                        profile,
                        distortion: 3.0,
                        detail: 2.5,
                        ..Default::default()
                    };
                    for i in 0..100 {
                        let p = Vec3::new(
                            i as f32 * 0.037 - 1.5,
                            0.3 - i as f32 * 0.021,
                            0.01 * i as f32,
                        );
                        let f = wave(p, &w).1;
                        assert!((0.0..=1.0).contains(&f), "{w:?} {p}: {f}");
                    }
                }
            }
        }
        for x in [f32::NAN, f32::INFINITY, 1e30, -1e30] {
            let w = WaveParams {
                distortion: 1.0,
                detail: x,
                detail_scale: x,
                ..Default::default()
            };
            let _ = wave(Vec3::splat(x), &w);
        }
    }
}
