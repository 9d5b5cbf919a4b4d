//! Cycles' `MULTIPLE_SCATTERING` sky (Fernando García Liñán's spectral model): radiance at
//! four wavelengths (630, 560, 490, 430 nm), single scattering ray-marched through a
//! spherical atmosphere (lengths in km) with the sun's transmittance from a precomputed table,
//! plus an analytic fit of Earth's higher-order scattering and the light of a grey ground;
//! converted to XYZ by a fitted 4 x 3 matrix.
//!
//! Coefficients are per km; the phase functions are per steradian; the sun's spectral
//! irradiance is the model's (so the table is radiance in Cycles' units).

use super::{Atmosphere, HEIGHT, WIDTH, ray_sphere_intersection};
use glam::{Vec3, Vec4};
use rayon::prelude::*;
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, PI, TAU};

const GROUND_ALBEDO: f32 = 0.3;
const PHASE_ISOTROPIC: f32 = 1.0 / (4.0 * PI);
const RAYLEIGH_PHASE_SCALE: f32 = (3.0 / 16.0) * FRAC_1_PI;
/// Aerosol anisotropy (Henyey-Greenstein `g`).
const G: f32 = 0.8;
/// Earth's radius and the atmosphere's thickness (km).
pub(super) const EARTH_RADIUS: f32 = 6371.0;
const ATMOSPHERE_THICKNESS: f32 = 100.0;
const ATMOSPHERE_RADIUS: f32 = EARTH_RADIUS + ATMOSPHERE_THICKNESS;
const TRANSMITTANCE_STEPS: usize = 64;
const IN_SCATTERING_STEPS: usize = 64;
/// The transmittance table: cosine of the sun's zenith angle in `[-1, 1]` across, normalised
/// altitude in `[0, 1]` down.
const TRANSMITTANCE_RES_X: usize = 256;
const TRANSMITTANCE_RES_Y: usize = 64;

const SUN_SPECTRAL_IRRADIANCE: Vec4 = Vec4::new(1.679, 1.828, 1.986, 1.307);
const MOLECULAR_SCATTERING_COEFFICIENT_BASE: Vec4 =
    Vec4::new(6.605e-3, 1.067e-2, 1.842e-2, 3.156e-2);
const OZONE_ABSORPTION_CROSS_SECTION: Vec4 = Vec4::new(3.472e-25, 3.914e-25, 1.349e-25, 11.03e-27);
/// Mean ozone column (Dobson units) of monthly means.
const OZONE_MEAN_DOBSON: f32 = 334.5;
const AEROSOL_ABSORPTION_CROSS_SECTION: Vec4 =
    Vec4::new(2.8722e-24, 4.6168e-24, 7.9706e-24, 1.3578e-23);
const AEROSOL_SCATTERING_CROSS_SECTION: Vec4 =
    Vec4::new(1.5908e-22, 1.7711e-22, 2.0942e-22, 2.4033e-22);
const AEROSOL_BASE_DENSITY: f32 = 1.3681e20;
const AEROSOL_BACKGROUND_DENSITY: f32 = 2e6;
const AEROSOL_HEIGHT_SCALE: f32 = 0.73;
/// Rows: the XYZ weight of each of the four wavelengths.
const SPECTRAL_XYZ: [Vec3; 4] = [
    Vec3::new(53.386_917, 22.981_337, 0.0),
    Vec3::new(43.904_846, 71.347_8, 0.102_506_87),
    Vec3::new(1.613_727_8, 18.422_96, 31.742_92),
    Vec3::new(20.762_669, 2.361_421_4, 110.480_1),
];

#[inline]
fn exp4(v: Vec4) -> Vec4 {
    Vec4::new(v.x.exp(), v.y.exp(), v.z.exp(), v.w.exp())
}

fn spectral_to_xyz(l: Vec4) -> Vec3 {
    SPECTRAL_XYZ[0] * l.x + SPECTRAL_XYZ[1] * l.y + SPECTRAL_XYZ[2] * l.z + SPECTRAL_XYZ[3] * l.w
}

/// Rayleigh phase, per steradian, of the cosine between the directions of travel.
fn molecular_phase(cos_theta: f32) -> f32 {
    RAYLEIGH_PHASE_SCALE * (1.0 + cos_theta * cos_theta)
}

/// Henyey-Greenstein phase, per steradian, in the model's sign convention (`cos_theta` between
/// the view direction reversed and the sun direction).
fn aerosol_phase(cos_theta: f32) -> f32 {
    let den = 1.0 + G * G + 2.0 * G * cos_theta;
    (1.0 - G * G) / (4.0 * PI * den * den.sqrt())
}

/// The unit direction towards a sun of zenith-angle cosine `c` (in the x-z plane, towards -x).
#[inline]
fn sun_direction(c: f32) -> Vec3 {
    Vec3::new(-(1.0 - c * c).max(0.0).sqrt(), 0.0, c)
}

/// Absorption and scattering coefficients (per km) at one altitude.
struct Collision {
    extinction: Vec4,
    aerosol_scattering: Vec4,
    molecular_scattering: Vec4,
}

struct Model {
    air: f32,
    aerosol: f32,
    ozone: f32,
    /// `TRANSMITTANCE_RES_Y` rows of `TRANSMITTANCE_RES_X`; empty until [`Model::with_lut`].
    lut: Vec<Vec4>,
    /// What the in-scattering needs of each altitude, tabulated ([`ALTITUDE_TABLE`] entries
    /// over `[0, ATMOSPHERE_THICKNESS]`; empty until [`Model::with_lut`]).
    by_altitude: Vec<AtAltitude>,
}

/// Entries of the altitude table: linear interpolation over 24 m steps is within 2e-4 of the
/// exact coefficients (the aerosols' 0.73 km scale height is the sharpest profile), and saves
/// the five transcendental functions of each step.
const ALTITUDE_TABLE: usize = 4097;

/// The altitude-only terms of one in-scattering step.
#[derive(Clone, Copy)]
struct AtAltitude {
    extinction: Vec4,
    aerosol_scattering: Vec4,
    molecular_scattering: Vec4,
    /// Transmittance from the ground straight up to this altitude.
    ground_to_here: Vec4,
    /// Solid angle the planet subtends (sr).
    omega: f32,
}

impl AtAltitude {
    fn lerp(&self, o: &AtAltitude, f: f32) -> AtAltitude {
        AtAltitude {
            extinction: self.extinction.lerp(o.extinction, f),
            aerosol_scattering: self.aerosol_scattering.lerp(o.aerosol_scattering, f),
            molecular_scattering: self.molecular_scattering.lerp(o.molecular_scattering, f),
            ground_to_here: self.ground_to_here.lerp(o.ground_to_here, f),
            omega: self.omega + (o.omega - self.omega) * f,
        }
    }
}

impl Model {
    fn new(a: &Atmosphere) -> Model {
        Model {
            air: a.air,
            aerosol: a.aerosol,
            ozone: a.ozone,
            lut: Vec::new(),
            by_altitude: Vec::new(),
        }
    }

    fn with_lut(mut self) -> Model {
        let lut: Vec<Vec4> = (0..TRANSMITTANCE_RES_Y)
            .into_par_iter()
            .flat_map_iter(|y| {
                let m = &self;
                (0..TRANSMITTANCE_RES_X).map(move |x| {
                    let u = x as f32 / (TRANSMITTANCE_RES_X - 1) as f32;
                    let v = y as f32 / (TRANSMITTANCE_RES_Y - 1) as f32;
                    m.transmittance(u * 2.0 - 1.0, v)
                })
            })
            .collect();
        self.lut = lut;
        let by_altitude = (0..ALTITUDE_TABLE)
            .map(|i| {
                let h = i as f32 * (ATMOSPHERE_THICKNESS / (ALTITUDE_TABLE - 1) as f32);
                self.at_altitude(h)
            })
            .collect();
        self.by_altitude = by_altitude;
        self
    }

    /// The altitude terms at `h` km, exactly (needs the transmittance table).
    fn at_altitude(&self, h: f32) -> AtAltitude {
        let k = self.collision(h);
        let d = EARTH_RADIUS + h;
        AtAltitude {
            extinction: k.extinction,
            aerosol_scattering: k.aerosol_scattering,
            molecular_scattering: k.molecular_scattering,
            // T(ground, sun) = T(ground, sample) T(sample, sun), both straight up in the table.
            ground_to_here: self.lookup_transmittance_up(0.0)
                / self.lookup_transmittance_up(h / ATMOSPHERE_THICKNESS),
            omega: TAU * (1.0 - (1.0 - (EARTH_RADIUS / d).powi(2)).max(0.0).sqrt()),
        }
    }

    /// [`Model::at_altitude`] interpolated in the table (exact outside it).
    #[inline]
    fn at_altitude_fast(&self, h: f32) -> AtAltitude {
        let x = h * ((ALTITUDE_TABLE - 1) as f32 / ATMOSPHERE_THICKNESS);
        if !(0.0..(ALTITUDE_TABLE - 1) as f32).contains(&x) {
            return self.at_altitude(h);
        }
        let i = x as usize;
        self.by_altitude[i].lerp(&self.by_altitude[i + 1], x - i as f32)
    }

    #[inline]
    fn collision(&self, h: f32) -> Collision {
        let aerosol_density = AEROSOL_BASE_DENSITY
            * ((-h / AEROSOL_HEIGHT_SCALE).exp()
                + AEROSOL_BACKGROUND_DENSITY / AEROSOL_BASE_DENSITY)
            * self.aerosol;
        let aerosol_absorption = AEROSOL_ABSORPTION_CROSS_SECTION * aerosol_density;
        let aerosol_scattering = AEROSOL_SCATTERING_CROSS_SECTION * aerosol_density;
        let log_h = h.max(1e-4).ln();
        let ozone_density =
            3.785_474e20 * (-(log_h - 3.22261) * (log_h - 3.22261) * 5.555_555_5 - log_h).exp();
        let molecular_absorption =
            OZONE_ABSORPTION_CROSS_SECTION * (OZONE_MEAN_DOBSON * ozone_density * self.ozone);
        let molecular_scattering = MOLECULAR_SCATTERING_COEFFICIENT_BASE
            * ((-0.077_719_71 * h.powf(1.163_642_4)).exp() * self.air);
        Collision {
            extinction: aerosol_absorption
                + aerosol_scattering
                + molecular_absorption
                + molecular_scattering,
            aerosol_scattering,
            molecular_scattering,
        }
    }

    /// Transmittance from normalised altitude `v` to the top of the atmosphere towards a sun
    /// of zenith-angle cosine `c` (ray-marched; the ground does not block it).
    fn transmittance(&self, c: f32, v: f32) -> Vec4 {
        let dir = sun_direction(c);
        let origin = Vec3::new(0.0, 0.0, EARTH_RADIUS + v * ATMOSPHERE_THICKNESS);
        let t_d = ray_sphere_intersection(origin, dir, ATMOSPHERE_RADIUS);
        let dt = t_d / TRANSMITTANCE_STEPS as f32;
        let mut depth = Vec4::ZERO;
        for step in 0..TRANSMITTANCE_STEPS {
            let x = origin + dir * ((step as f32 + 0.5) * dt);
            let h = (x.length() - EARTH_RADIUS).max(0.0);
            depth += self.collision(h).extinction * dt;
        }
        exp4(-depth)
    }

    /// Row `y`, columns `x1`, `x2` of the table.
    #[inline]
    fn lut_at(&self, x: usize, y: usize) -> Vec4 {
        self.lut[y * TRANSMITTANCE_RES_X + x]
    }

    fn lookup_transmittance(&self, c: f32, v: f32) -> Vec4 {
        let x = (TRANSMITTANCE_RES_X - 1) as f32 * (c * 0.5 + 0.5).clamp(0.0, 1.0);
        let y = (TRANSMITTANCE_RES_Y - 1) as f32 * v.clamp(0.0, 1.0);
        let (x1, y1) = (x as usize, y as usize);
        let x2 = (x1 + 1).min(TRANSMITTANCE_RES_X - 1);
        let y2 = (y1 + 1).min(TRANSMITTANCE_RES_Y - 1);
        let (fx, fy) = (x - x1 as f32, y - y1 as f32);
        let bottom = self.lut_at(x1, y1).lerp(self.lut_at(x2, y1), fx);
        let top = self.lut_at(x1, y2).lerp(self.lut_at(x2, y2), fx);
        bottom.lerp(top, fy)
    }

    fn lookup_transmittance_at_ground(&self, c: f32) -> Vec4 {
        let x = (TRANSMITTANCE_RES_X - 1) as f32 * (c * 0.5 + 0.5).clamp(0.0, 1.0);
        let x1 = x as usize;
        let x2 = (x1 + 1).min(TRANSMITTANCE_RES_X - 1);
        self.lut_at(x1, 0).lerp(self.lut_at(x2, 0), x - x1 as f32)
    }

    /// Transmittance straight up from normalised altitude `v`.
    fn lookup_transmittance_up(&self, v: f32) -> Vec4 {
        let y = (TRANSMITTANCE_RES_Y - 1) as f32 * v.clamp(0.0, 1.0);
        let y1 = y as usize;
        let y2 = (y1 + 1).min(TRANSMITTANCE_RES_Y - 1);
        let x = TRANSMITTANCE_RES_X - 1;
        self.lut_at(x, y1).lerp(self.lut_at(x, y2), y - y1 as f32)
    }

    /// Higher-order scattering per unit scattering coefficient at a point of altitude terms
    /// `at` with the sun at zenith cosine `c`: the light of the ground seen over the solid
    /// angle it subtends, plus the model's fit of the rest.
    fn multiscattering(&self, c: f32, at: &AtAltitude) -> Vec4 {
        let t_to_ground = self.lookup_transmittance_at_ground(c);
        let l_ground = (t_to_ground * at.ground_to_here)
            * (PHASE_ISOTROPIC * at.omega * GROUND_ALBEDO * FRAC_1_PI * c);
        let l_ms = Vec4::new(0.217, 0.347, 0.594, 1.0) * (0.02 / (1.0 + 5.0 * (-17.92 * c).exp()));
        l_ms + l_ground
    }

    /// Radiance scattered into the ray `origin + t dir`, `t ∈ [0, t_d]`, towards the origin.
    fn inscattering(&self, sun: Vec3, origin: Vec3, dir: Vec3, t_d: f32) -> Vec4 {
        let cos_theta = (-dir).dot(sun);
        let molecular_p = molecular_phase(cos_theta);
        let aerosol_p = aerosol_phase(cos_theta);
        let dt = t_d / IN_SCATTERING_STEPS as f32;
        let mut l = Vec4::ZERO;
        let mut transmittance = Vec4::ONE;
        for i in 0..IN_SCATTERING_STEPS {
            let x = origin + dir * ((i as f32 + 0.5) * dt);
            let d = x.length();
            let zenith = x / d;
            let h = (d - EARTH_RADIUS).max(0.0);
            let v = h / ATMOSPHERE_THICKNESS;
            let c = zenith.dot(sun);
            let k = self.at_altitude_fast(h);
            let to_sun = self.lookup_transmittance(c, v);
            let ms = self.multiscattering(c, &k);
            let s = SUN_SPECTRAL_IRRADIANCE
                * (k.molecular_scattering * (to_sun * molecular_p + ms)
                    + k.aerosol_scattering * (to_sun * aerosol_p + ms));
            let step = exp4(-k.extinction * dt);
            // The segment's in-scattering integrated exactly for constant coefficients
            // (Hillaire's energy-conserving form).
            let s_int = (s - s * step) / k.extinction.max(Vec4::splat(1e-7));
            l += transmittance * s_int;
            transmittance *= step;
        }
        l
    }
}

/// Altitude in km, clamped as Cycles does against numerical trouble.
fn altitude_km(a: &Atmosphere) -> f32 {
    a.altitude.clamp(1.0, 99999.0) / 1000.0
}

/// The sky table ([`super::SkyTable`]'s layout): each row's left half ray-marched, the right
/// half its mirror image (the sky is symmetric about the sun's vertical plane).
pub fn precompute_texture(a: &Atmosphere) -> Vec<Vec3> {
    let model = Model::new(a).with_lut();
    let altitude = altitude_km(a);
    let sun = sun_direction((FRAC_PI_2 - a.sun_elevation).cos());
    let origin = Vec3::new(0.0, 0.0, EARTH_RADIUS + altitude);
    let mut pixels = vec![Vec3::ZERO; WIDTH * HEIGHT];
    pixels
        .par_chunks_mut(WIDTH)
        .enumerate()
        .for_each(|(y, row)| {
            let l = ((y as f32 + 0.5) / HEIGHT as f32) * 2.0 - 1.0;
            let elevation = (l * l).copysign(l) * FRAC_PI_2;
            let (se, ce) = elevation.sin_cos();
            for x in 0..WIDTH / 2 {
                let azimuth = TAU * (x as f32 + 0.5) / WIDTH as f32;
                let (sa, ca) = azimuth.sin_cos();
                let dir = Vec3::new(ce * ca, ce * sa, se);
                let atmosphere = ray_sphere_intersection(origin, dir, ATMOSPHERE_RADIUS);
                let ground = ray_sphere_intersection(origin, dir, EARTH_RADIUS);
                let t_d = if ground < 0.0 { atmosphere } else { ground };
                let xyz = spectral_to_xyz(model.inscattering(sun, origin, dir, t_d));
                row[x] = xyz;
                row[WIDTH - 1 - x] = xyz;
            }
        });
    pixels
}

/// The sun disc's XYZ radiance at its lowest and highest points: the sun's irradiance spread
/// over the disc's solid angle, attenuated along the way down.
pub fn precompute_sun(a: &Atmosphere, angular_diameter: f32) -> (Vec3, Vec3) {
    let model = Model::new(a);
    let v = altitude_km(a) / ATMOSPHERE_THICKNESS;
    let half = angular_diameter / 2.0;
    let solid_angle = TAU * (1.0 - half.cos());
    let at = |elevation: f32| {
        let t = model.transmittance((FRAC_PI_2 - elevation).cos(), v);
        spectral_to_xyz(SUN_SPECTRAL_IRRADIANCE * t / solid_angle)
    };
    (at(a.sun_elevation - half), at(a.sun_elevation + half))
}
