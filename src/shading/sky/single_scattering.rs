//! Cycles' `SINGLE_SCATTERING` sky (Nishita's model as Blender's "Nishita" sky): Rayleigh and
//! Mie single scattering plus ozone absorption at 21 wavelengths (380-780 nm), lengths in
//! metres, exponential density profiles (ozone: a tent around 25 km); the upper hemisphere is
//! ray-marched, the lower one fades the horizon row out. Spectra become XYZ through the CIE
//! 1931 colour matching functions.

use super::{Atmosphere, HEIGHT, WIDTH};
use glam::Vec3;
use rayon::prelude::*;
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, PI, TAU};

/// Scale heights (m), Mie scattering coefficient (per m) and anisotropy.
const RAYLEIGH_SCALE: f32 = 8e3;
const MIE_SCALE: f32 = 1.2e3;
const MIE_COEFF: f32 = 2e-5;
const MIE_G: f32 = 0.76;
/// Radii of the Earth and of the top of the atmosphere (m).
const EARTH_RADIUS: f32 = 6360e3;
const ATMOSPHERE_RADIUS: f32 = 6420e3;
/// Segments of the view ray.
const STEPS: usize = 32;
const NUM_WAVELENGTHS: usize = 21;
/// Wavelength step (nm).
const STEP_LAMBDA: f32 = 20.0;
/// Sun irradiance at the top of the atmosphere (W m⁻² nm⁻¹), per wavelength.
const IRRADIANCE: [f32; NUM_WAVELENGTHS] = [
    1.457_568_3,
    1.565_963,
    1.651_484_5,
    1.714_962_4,
    1.757_979_8,
    1.782_564,
    1.790_951_1,
    1.785_415_5,
    1.768_155_5,
    1.741_220_7,
    1.706_471_3,
    1.665_560_9,
    1.619_934_4,
    1.570_836,
    1.519_323_4,
    1.466_285,
    1.412_458_5,
    1.358_449_6,
    1.304_749_1,
    1.251_749_6,
    1.199_76,
];
/// Rayleigh scattering coefficient at sea level (per m), per wavelength.
const RAYLEIGH_COEFF: [f32; NUM_WAVELENGTHS] = [
    0.000_054_248_2,
    0.000_044_185_5,
    0.000_036_351_52,
    0.000_030_179_29,
    0.000_025_263_2,
    0.000_021_308_593,
    0.000_018_098_38,
    0.000_015_470_57,
    0.000_013_302_85,
    0.000_011_501_848,
    0.000_009_995_574,
    0.000_008_728,
    0.000_007_655_137,
    0.000_006_742_172,
    0.000_005_961_341,
    0.000_005_290_346,
    0.000_004_711_157,
    0.000_004_209_105,
    0.000_003_772_184,
    0.000_003_390_512_5,
    0.000_003_055_915_3,
];
/// Ozone absorption coefficient at the profile's peak (per m), per wavelength.
const OZONE_COEFF: [f32; NUM_WAVELENGTHS] = [
    0.000_000_003_251_268_5,
    0.000_000_005_853_953_7,
    0.000_000_019_771_91,
    0.000_000_073_095_69,
    0.000_000_200_845_62,
    0.000_000_403_839_6,
    0.000_000_635_513_34,
    0.000_000_967_070_4,
    0.000_001_547_974,
    0.000_002_090_386_5,
    0.000_002_461_280_6,
    0.000_002_735_513,
    0.000_002_151_258_6,
    0.000_001_590_518_4,
    0.000_001_123_562,
    0.000_000_735_275_5,
    0.000_000_464_501_3,
    0.000_000_330_960_8,
    0.000_000_225_126_12,
    0.000_000_148_791_3,
    0.000_000_168_286_23,
];
/// CIE 1931 colour matching functions (x̄, ȳ, z̄), per wavelength.
const CMF_XYZ: [[f32; 3]; NUM_WAVELENGTHS] = [
    [0.001_368, 0.000_039, 0.006_450_001],
    [0.014_31, 0.000_396, 0.067_850_01],
    [0.134_38, 0.004, 0.6456],
    [0.348_28, 0.023, 1.747_06],
    [0.2908, 0.06, 1.6692],
    [0.095_64, 0.139_02, 0.812_950_1],
    [0.0049, 0.323, 0.272],
    [0.063_27, 0.71, 0.078_249_99],
    [0.2904, 0.954, 0.0203],
    [0.5945, 0.995, 0.0039],
    [0.9163, 0.87, 0.001_650_001],
    [1.0622, 0.631, 0.0008],
    [0.854_449_9, 0.381, 0.00019],
    [0.4479, 0.175, 0.00002],
    [0.1649, 0.061, 0.0],
    [0.04677, 0.017, 0.0],
    [0.011_359_16, 0.004_102, 0.0],
    [0.002_899_327, 0.001_047, 0.0],
    [0.000_690_078_6, 0.000_249_2, 0.0],
    [0.000_166_150_5, 0.00006, 0.0],
    [0.000_041_509_94, 0.000_014_99, 0.0],
];

/// Gauss-Laguerre (n = 8) nodes along the ray (as fractions of its length, the last still
/// inside the atmosphere) and weights with the `exp(x)` factor folded in: the optical depth of
/// an exponentially thinning medium in eight density evaluations.
const QUADRATURE_NODES: [f32; 8] = [
    0.006_811_185,
    0.036_148_07,
    0.090_043_46,
    0.170_668,
    0.281_836_2,
    0.430_340_6,
    0.629_627_1,
    0.914_525_3,
];
const QUADRATURE_WEIGHTS: [f32; 8] = [
    0.017_508_936,
    0.041_354_774,
    0.066_788_39,
    0.095_076_99,
    0.128_341_64,
    0.170_743_02,
    0.232_723_33,
    0.356_249_05,
];

fn geographical_to_direction(lat: f32, lon: f32) -> Vec3 {
    Vec3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin())
}

fn spectrum_to_xyz(s: &[f32; NUM_WAVELENGTHS]) -> Vec3 {
    let mut xyz = Vec3::ZERO;
    for (c, &v) in CMF_XYZ.iter().zip(s) {
        xyz += Vec3::from_array(*c) * v;
    }
    xyz * STEP_LAMBDA
}

/// Relative densities `(Rayleigh, Mie, ozone)` at `h` metres above sea level.
#[inline]
fn density(h: f32) -> Vec3 {
    Vec3::new(
        (-h / RAYLEIGH_SCALE).exp(),
        (-h / MIE_SCALE).exp(),
        (1.0 - (h - 25000.0).abs() / 15000.0).max(0.0),
    )
}

/// Rayleigh phase (per steradian) of the cosine between view and sun directions.
fn phase_rayleigh(mu: f32) -> f32 {
    (0.1875 * FRAC_1_PI) * (1.0 + mu * mu)
}

/// Cornette-Shanks phase (per steradian).
fn phase_mie(mu: f32) -> f32 {
    let g2 = MIE_G * MIE_G;
    (3.0 * (1.0 - g2) * (1.0 + mu * mu))
        / (8.0 * PI * (2.0 + g2) * (1.0 + g2 - 2.0 * MIE_G * mu).powf(1.5))
}

/// Entries of the density table over `[0, ATMOSPHERE_RADIUS - EARTH_RADIUS]`: linear
/// interpolation over 15 m steps is within 2e-5 of the exact profiles (Mie's 1.2 km scale
/// height is the sharpest).
const DENSITY_TABLE: usize = 4097;
const TOP: f32 = ATMOSPHERE_RADIUS - EARTH_RADIUS;

/// [`density`] tabulated.
struct Densities(Vec<Vec3>);

impl Densities {
    fn new() -> Densities {
        Densities(
            (0..DENSITY_TABLE)
                .map(|i| density(i as f32 * (TOP / (DENSITY_TABLE - 1) as f32)))
                .collect(),
        )
    }

    /// [`density`] at `h` metres, interpolated (exact outside the table).
    #[inline]
    fn at(&self, h: f32) -> Vec3 {
        let x = h * ((DENSITY_TABLE - 1) as f32 / TOP);
        if !(0.0..(DENSITY_TABLE - 1) as f32).contains(&x) {
            return density(h);
        }
        let i = x as usize;
        self.0[i].lerp(self.0[i + 1], x - i as f32)
    }
}

/// Whether the ray from `pos` along `dir` hits the ground.
fn surface_intersection(pos: Vec3, dir: Vec3) -> bool {
    if dir.z >= 0.0 {
        return false;
    }
    let b = -2.0 * dir.dot(-pos);
    let c = pos.length_squared() - EARTH_RADIUS * EARTH_RADIUS;
    b * b - 4.0 * c >= 0.0
}

/// Where the ray from `pos` (inside the atmosphere) along `dir` leaves it.
fn atmosphere_intersection(pos: Vec3, dir: Vec3) -> Vec3 {
    let b = -2.0 * dir.dot(-pos);
    let c = pos.length_squared() - ATMOSPHERE_RADIUS * ATMOSPHERE_RADIUS;
    let t = (-b + (b * b - 4.0 * c).sqrt()) / 2.0;
    pos + dir * t
}

/// Optical depth factors `(Rayleigh, Mie, ozone)` (density x metres) from `origin` along
/// `dir` to the top of the atmosphere.
fn ray_optical_depth(table: &Densities, origin: Vec3, dir: Vec3) -> Vec3 {
    let end = atmosphere_intersection(origin, dir);
    let length = origin.distance(end);
    let segment = dir * length;
    let mut depth = Vec3::ZERO;
    for (&x, &w) in QUADRATURE_NODES.iter().zip(&QUADRATURE_WEIGHTS) {
        let p = origin + segment * x;
        depth += table.at(p.length() - EARTH_RADIUS) * w;
    }
    depth * length
}

/// Spectral radiance scattered once towards `origin` along the ray `origin + t dir`.
fn single_scattering(
    table: &Densities,
    dir: Vec3,
    sun: Vec3,
    origin: Vec3,
    scale: Vec3,
) -> [f32; NUM_WAVELENGTHS] {
    let end = atmosphere_intersection(origin, dir);
    let length = origin.distance(end);
    let seg_len = length / STEPS as f32;
    let segment = dir * seg_len;
    let mut depth = Vec3::ZERO;
    let mut spectrum = [0.0f32; NUM_WAVELENGTHS];
    let mu = dir.dot(sun);
    let (pr, pm) = (phase_rayleigh(mu), phase_mie(mu));
    // Each segment is evaluated at its middle.
    let mut p = origin + segment * 0.5;
    for _ in 0..STEPS {
        let d = scale * table.at(p.length() - EARTH_RADIUS);
        depth += d * seg_len;
        if !surface_intersection(p, sun) {
            let total = depth + scale * ray_optical_depth(table, p, sun);
            for (wl, out) in spectrum.iter_mut().enumerate() {
                let tau = total.x * RAYLEIGH_COEFF[wl]
                    + total.y * (1.11 * MIE_COEFF)
                    + total.z * OZONE_COEFF[wl];
                let scattering = pr * d.x * RAYLEIGH_COEFF[wl] + pm * d.y * MIE_COEFF;
                *out += (-tau).exp() * scattering * IRRADIANCE[wl] * seg_len;
            }
        }
        p += segment;
    }
    spectrum
}

fn altitude_m(a: &Atmosphere) -> f32 {
    a.altitude.clamp(1.0, 59999.0)
}

/// Row `y`'s elevation (radians); rows below the middle are below the horizon.
#[inline]
fn row_latitude(y: usize) -> f32 {
    let t = y as f32 / (HEIGHT / 2) as f32 - 1.0;
    FRAC_PI_2 * t * t
}

/// The sky table ([`super::SkyTable`]'s layout): the upper half ray-marched (each row's left
/// half, mirrored), the lower half the horizon row faded out with depression.
pub fn precompute_texture(a: &Atmosphere) -> Vec<Vec3> {
    let origin = Vec3::new(0.0, 0.0, EARTH_RADIUS + altitude_m(a));
    let sun = geographical_to_direction(a.sun_elevation, 0.0);
    let scale = Vec3::new(a.air, a.aerosol, a.ozone);
    let half = HEIGHT / 2;
    let table = Densities::new();
    let mut pixels = vec![Vec3::ZERO; WIDTH * HEIGHT];
    pixels[half * WIDTH..]
        .par_chunks_mut(WIDTH)
        .enumerate()
        .for_each(|(k, row)| {
            let latitude = row_latitude(half + k);
            for x in 0..WIDTH / 2 {
                let longitude = TAU / WIDTH as f32 * x as f32 - PI;
                let dir = geographical_to_direction(latitude, longitude);
                let xyz = spectrum_to_xyz(&single_scattering(&table, dir, sun, origin, scale));
                row[x] = xyz;
                row[WIDTH - 1 - x] = xyz;
            }
        });
    let (below, above) = pixels.split_at_mut(half * WIDTH);
    let horizon = &above[..WIDTH];
    for (y, row) in below.chunks_exact_mut(WIDTH).enumerate() {
        // As Cycles: `z` of the row's (mirrored, upward) latitude sets the fade.
        let z = row_latitude(y).sin();
        let fade = if z < 0.4 {
            let f = 1.0 - z * 2.5;
            f * f * f
        } else {
            0.0
        };
        for (out, h) in row.iter_mut().zip(horizon) {
            *out = *h * fade;
        }
    }
    pixels
}

/// The sun disc's XYZ radiance at its lowest and highest points (black when the disc is
/// entirely below the horizon): the irradiance over the disc's solid angle, attenuated by
/// Rayleigh and Mie extinction (not ozone, as Cycles).
pub fn precompute_sun(a: &Atmosphere, angular_diameter: f32) -> (Vec3, Vec3) {
    let origin = Vec3::new(0.0, 0.0, EARTH_RADIUS + altitude_m(a));
    let half = angular_diameter / 2.0;
    let solid_angle = TAU * (1.0 - half.cos());
    let bottom = (a.sun_elevation - half).max(0.0);
    let top = (a.sun_elevation + half).max(0.0);
    if top <= 0.0 {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    let table = Densities::new();
    let at = |elevation: f32| {
        let depth = ray_optical_depth(&table, origin, geographical_to_direction(elevation, 0.0));
        let mut s = [0.0f32; NUM_WAVELENGTHS];
        for (wl, out) in s.iter_mut().enumerate() {
            let tau = RAYLEIGH_COEFF[wl] * depth.x * a.air + 1.11 * MIE_COEFF * depth.y * a.aerosol;
            *out = IRRADIANCE[wl] * (-tau).exp() / solid_angle;
        }
        spectrum_to_xyz(&s)
    };
    (at(bottom), at(top))
}
