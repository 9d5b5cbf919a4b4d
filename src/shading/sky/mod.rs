//! The atmosphere models behind the Sky Texture (Cycles' `SINGLE_SCATTERING` and
//! `MULTIPLE_SCATTERING`): a table of the sky's CIE XYZ radiance seen from a point above the
//! ground, precomputed once per set of parameters, and the two radiances of the sun disc (at
//! its lowest and highest point).
//!
//! The table is `WIDTH x HEIGHT` texels (Cycles' 512 x 256), row 0 at the nadir, as Cycles'
//! `SkyLoader` stores it: column `x` looks along azimuth `2π (x + ½) / WIDTH` measured from the
//! direction away from the sun (the sun is at `x = ½`), the rows follow the elevation
//! non-linearly (`e = sign(l) l² π/2` with `l = 2 v - 1`), so that the horizon gets more texels.

pub mod multiple_scattering;
pub mod single_scattering;

use glam::Vec3;
use std::f32::consts::FRAC_PI_2;
use std::sync::{Arc, Mutex, Weak};

/// Table width (azimuth) and height (elevation), as Cycles'.
pub const WIDTH: usize = 512;
pub const HEIGHT: usize = 256;

/// Which atmosphere model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Model {
    /// Nishita's single scattering, 21 wavelengths (Blender ≤ 4.x calls it `NISHITA`).
    Single,
    /// García Liñán's spectral model with a multiple scattering fit, 4 wavelengths.
    Multiple,
}

/// The parameters the table depends on (the sun's rotation only turns it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Atmosphere {
    pub model: Model,
    /// Radians above the horizon, in `[-π/2, π/2]`.
    pub sun_elevation: f32,
    /// Metres above sea level (clamped by each model as Cycles does).
    pub altitude: f32,
    /// Density multipliers of air molecules, aerosols and ozone (1: Earth's).
    pub air: f32,
    pub aerosol: f32,
    pub ozone: f32,
}

/// The precomputed sky: XYZ radiance per texel (row-major, row 0 at the nadir).
#[derive(Clone)]
pub struct SkyTable {
    xyz: Vec<Vec3>,
}

impl std::fmt::Debug for SkyTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SkyTable({WIDTH}x{HEIGHT})")
    }
}

impl SkyTable {
    /// Precomputes the table of `atmosphere` (rows in parallel).
    pub fn new(atmosphere: &Atmosphere) -> SkyTable {
        let xyz = match atmosphere.model {
            Model::Multiple => multiple_scattering::precompute_texture(atmosphere),
            Model::Single => single_scattering::precompute_texture(atmosphere),
        };
        debug_assert_eq!(xyz.len(), WIDTH * HEIGHT);
        SkyTable { xyz }
    }

    /// The table of `atmosphere`, shared with any other still in use for the same parameters:
    /// rebuilding a scene's lights recompiles its world, which need not precompute again.
    pub fn shared(atmosphere: &Atmosphere) -> Arc<SkyTable> {
        static LIVE: Mutex<Vec<(Atmosphere, Weak<SkyTable>)>> = Mutex::new(Vec::new());
        let mut live = LIVE.lock().unwrap_or_else(|e| e.into_inner());
        live.retain(|(_, w)| w.strong_count() > 0);
        if let Some(t) = live
            .iter()
            .find(|(a, _)| a == atmosphere)
            .and_then(|(_, w)| w.upgrade())
        {
            return t;
        }
        let t = Arc::new(SkyTable::new(atmosphere));
        live.push((*atmosphere, Arc::downgrade(&t)));
        t
    }

    /// Texel `(x, y)`.
    #[inline]
    pub fn texel(&self, x: usize, y: usize) -> Vec3 {
        self.xyz[y * WIDTH + x]
    }

    /// Bilinear lookup at `(u, v) ∈ [0, 1]²` with texel centres at `(i + ½) / n` and the edge
    /// texels extended (Cycles' linear interpolation with `EXTENSION_EXTEND`).
    #[inline]
    pub fn lookup(&self, u: f32, v: f32) -> Vec3 {
        let coord = |t: f32, n: usize| {
            let x = t * n as f32 - 0.5;
            let i = x.floor();
            let f = if x.is_finite() { x - i } else { 0.0 };
            let clamp = |k: f32| (k.max(0.0) as usize).min(n - 1);
            (clamp(i), clamp(i + 1.0), f)
        };
        let (x0, x1, fx) = coord(u, WIDTH);
        let (y0, y1, fy) = coord(v, HEIGHT);
        let row = |y| self.texel(x0, y).lerp(self.texel(x1, y), fx);
        row(y0).lerp(row(y1), fy)
    }
}

/// The sun disc's XYZ radiance at its lowest and highest point (`(bottom, top)`), for a disc
/// of `angular_diameter` radians; black when the sun is below the horizon (single scattering).
pub fn sun_radiance(atmosphere: &Atmosphere, angular_diameter: f32) -> (Vec3, Vec3) {
    match atmosphere.model {
        Model::Multiple => multiple_scattering::precompute_sun(atmosphere, angular_diameter),
        Model::Single => single_scattering::precompute_sun(atmosphere, angular_diameter),
    }
}

/// How far below the horizon (radians) the ground's edge lies seen from `altitude` metres:
/// the sun disc is drawn only above it.
pub fn earth_intersection_angle(altitude: f32) -> f32 {
    FRAC_PI_2
        - (multiple_scattering::EARTH_RADIUS
            / (multiple_scattering::EARTH_RADIUS + altitude / 1000.0))
            .clamp(-1.0, 1.0)
            .asin()
}

/// The point at distance `t` along the ray where it leaves a sphere of `radius` about the
/// origin (or enters it when the origin is outside), `-1` if it misses: Cycles' sky
/// `ray_sphere_intersection`.
#[inline]
fn ray_sphere_intersection(pos: Vec3, dir: Vec3, radius: f32) -> f32 {
    let b = pos.dot(dir);
    let c = pos.dot(pos) - radius * radius;
    if c > 0.0 && b > 0.0 {
        return -1.0;
    }
    let d = b * b - c;
    if d < 0.0 {
        return -1.0;
    }
    if d >= b * b {
        return -b + d.sqrt();
    }
    -b - d.sqrt()
}

#[cfg(test)]
mod tests;
