//! IES light profiles (IESNA LM-63 photometric files), read and looked up as Cycles does.
//!
//! A profile is a table of intensities over two angles of the light's local frame: the
//! vertical angle `v = acos(-z)` (0 along the light's -Z, its axis) and the horizontal angle
//! `h = atan2(x, y) + π`, for a unit local direction `(x, y, z)` pointing from the light
//! towards the lit point. Values are candela × the file's multipliers × `4π / 177.83`
//! (177.83 lm/W is D65's luminous efficacy, and Blender's light power is per 4π sr), so a
//! profile of `177.83 / 4π ≈ 14.15` cd everywhere renders the light unchanged. The renderer
//! multiplies the light's emitted radiance by it.
//!
//! As Cycles: photometric types A and B are recast into type C's angles, type C's symmetric
//! halves and quadrants are mirrored to the full circle, and the lookup is Catmull-Rom in both
//! angles (zero outside the table's angles, clamped at zero).

use std::f32::consts::PI;
use std::sync::Arc;

use glam::{Mat3, Vec2, Vec3};

use super::{Emitter, EmitterInstance, EmitterQueryRecord};
use crate::scene::Scene;

/// Candela to Blender watts per steradian × 4π: `4π / 177.83`.
const CANDELA_TO_PROFILE: f64 = 0.070_665_076_839_4;

/// More values than any real file has; a count beyond it is a broken file, not an
/// allocation to attempt.
const MAX_VALUES: usize = 1 << 22;

/// A parsed profile: intensities at `h` × `v` angles (radians, increasing).
#[derive(Clone, Debug, PartialEq)]
pub struct IesProfile {
    h: Vec<f32>,
    v: Vec<f32>,
    /// `values[i * v.len() + j]` at `(h[i], v[j])`.
    values: Vec<f32>,
    /// The profile's mean over the sphere of directions (for the light's share of shadow rays).
    mean: f32,
}

/// Numbers of the file after its `TILT=` line, read in order.
struct Numbers<'a> {
    tokens: std::str::SplitAsciiWhitespace<'a>,
    read: usize,
}

impl<'a> Numbers<'a> {
    fn next(&mut self, what: &str) -> Result<f64, String> {
        let t = self.tokens.next().ok_or_else(|| {
            format!(
                "the file ends before its {what} (after {} numbers)",
                self.read
            )
        })?;
        self.read += 1;
        match t.strip_prefix('+').unwrap_or(t).parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(format!("{what}: `{t}` is not a number")),
        }
    }

    fn count(&mut self, what: &str) -> Result<usize, String> {
        let x = self.next(what)?;
        if x < 0.0 || x.fract() != 0.0 || x > MAX_VALUES as f64 {
            return Err(format!("{what}: {x} is not a count"));
        }
        Ok(x as usize)
    }
}

impl IesProfile {
    /// Reads an LM-63 file's text. Errors say what is wrong with it.
    pub fn parse(text: &str) -> Result<IesProfile, String> {
        // Some writers separate numbers with commas.
        let text = text.replace(',', " ");
        let at = text
            .find("\nTILT=")
            .ok_or("it has no `TILT=` line (not an IES LM-63 file)")?;
        let tilt = &text[at + 1..];
        let (include, rest) = if let Some(rest) = tilt.strip_prefix("TILT=INCLUDE") {
            (true, rest)
        } else {
            let end = tilt.find('\n').ok_or("it ends at its `TILT=` line")?;
            (false, &tilt[end + 1..])
        };
        let mut n = Numbers {
            tokens: rest.split_ascii_whitespace(),
            read: 0,
        };
        if include {
            // The lamp's tilt table changes nothing Cycles renders: skip it.
            n.next("lamp-to-luminaire geometry")?;
            let pairs = n.count("number of tilt angles")?;
            for _ in 0..2 * pairs {
                n.next("tilt table")?;
            }
        }
        n.next("number of lamps")?;
        n.next("lumens per lamp")?;
        let mut factor = n.next("candela multiplier")?;
        let nv = n.count("number of vertical angles")?;
        let nh = n.count("number of horizontal angles")?;
        let kind = n.next("photometric type")?;
        n.next("units type")?;
        for what in ["width", "length", "height"] {
            n.next(what)?;
        }
        factor *= n.next("ballast factor")?;
        factor *= n.next("ballast-lamp photometric factor")?;
        n.next("input watts")?;
        factor *= CANDELA_TO_PROFILE;
        if nv == 0 || nh == 0 {
            return Err(format!("it has {nv} vertical and {nh} horizontal angles"));
        }
        if nv.saturating_mul(nh) > MAX_VALUES {
            return Err(format!("its {nv} × {nh} angles are too many"));
        }
        let mut v = Vec::with_capacity(nv.min(1024));
        for _ in 0..nv {
            v.push(n.next("vertical angles")? as f32);
        }
        let mut h = Vec::with_capacity(nh.min(1024));
        for _ in 0..nh {
            h.push(n.next("horizontal angles")? as f32);
        }
        let mut table = Vec::with_capacity(nh.min(1024));
        for _ in 0..nh {
            let mut row = Vec::with_capacity(nv.min(1024));
            for _ in 0..nv {
                row.push((factor * n.next("candela values")?) as f32);
            }
            table.push(row);
        }
        let (h, v, table) = match kind {
            1.0 => type_c(h, v, table),
            2.0 => type_b(h, v, table),
            3.0 => type_a(h, v, table),
            _ => {
                return Err(format!(
                    "its photometric type {kind} is not 1 (C), 2 (B) or 3 (A)"
                ));
            }
        };
        for (name, a) in [("horizontal", &h), ("vertical", &v)] {
            if a.windows(2).any(|w| w[0] >= w[1]) {
                return Err(format!("its {name} angles are not increasing"));
            }
        }
        let deg = PI / 180.0;
        let mut p = IesProfile {
            h: h.iter().map(|a| a * deg).collect(),
            v: v.iter().map(|a| a * deg).collect(),
            values: table.concat(),
            mean: 0.0,
        };
        p.mean = p.sphere_mean();
        Ok(p)
    }

    /// The mean over the sphere of directions (midpoint rule in `cos v` and `h`).
    fn sphere_mean(&self) -> f32 {
        const N: usize = 96;
        let mut sum = 0.0f64;
        for i in 0..N {
            let v = (1.0 - 2.0 * (i as f32 + 0.5) / N as f32).acos();
            for j in 0..2 * N {
                let h = 2.0 * PI * (j as f32 + 0.5) / (2 * N) as f32;
                sum += self.at(h, v) as f64;
            }
        }
        (sum / (2 * N * N) as f64) as f32
    }

    /// The profile at horizontal angle `h` ∈ [0, 2π] and vertical angle `v` ∈ [0, π]
    /// (radians): Catmull-Rom in `v` at the four nearest horizontal angles, then in `h`; zero
    /// outside the table's range. Ends the table does not wrap around repeat their value.
    pub fn at(&self, h: f32, v: f32) -> f32 {
        let (hs, vs) = (&self.h, &self.v);
        let (nh, nv) = (hs.len(), vs.len());
        let (v_low, v_high, h_low, h_high) = (vs[0], vs[nv - 1], hs[0], hs[nh - 1]);
        // NaN angles fail these comparisons, and give zero.
        let inside = v >= v_low && v < v_high && h >= h_low && h < h_high;
        if !inside {
            return 0.0;
        }
        // Cycles' tests, in f32: 360° (and 180°) converted to radians equal 2π (π), which the
        // tolerance does not reach, so a full table's ends repeat their values as open ends.
        let wrap_h = h_low < 1e-7 && h_high > 2.0 * PI - 1e-7;
        let wrap_vlow = v_low < 1e-7;
        let wrap_vhigh = v_high > PI - 1e-7;
        // The cell [a[i], a[i+1]] holding x: i = how many of a[1..] lie below x.
        let hi = hs[1..].partition_point(|&a| a < h);
        let vi = vs[1..].partition_point(|&a| a < v);
        let h_frac = (h - hs[hi]) / (hs[hi + 1] - hs[hi]);
        let v_frac = (v - vs[vi]) / (vs[vi + 1] - vs[vi]);
        let column = |k: usize| {
            let c = &self.values[k * nv..(k + 1) * nv];
            let (b, cc) = (c[vi], c[vi + 1]);
            let a = if vi > 0 {
                c[vi - 1]
            } else if wrap_vlow {
                // Across the pole: the light is assumed symmetric about its axis.
                c[1]
            } else {
                b
            };
            let d = if vi + 2 < nv {
                c[vi + 2]
            } else if wrap_vhigh {
                c[nv - 2]
            } else {
                cc
            };
            catmull_rom(a, b, cc, d, v_frac)
        };
        let b = column(hi);
        let c = column(hi + 1);
        // The last horizontal angle (2π) repeats the first: wrap to the one before it.
        let a = if hi > 0 {
            column(hi - 1)
        } else if wrap_h {
            column(nh - 2)
        } else {
            b
        };
        // As Cycles, a missing outer point falls back to `b` (not `c`) horizontally.
        let d = if hi + 2 < nh {
            column(hi + 2)
        } else if wrap_h {
            column(1)
        } else {
            b
        };
        catmull_rom(a, b, c, d, h_frac).max(0.0)
    }

    /// The profile towards `local`, a direction (any length) in the light's frame pointing
    /// from the light towards the lit point.
    #[inline]
    pub fn towards(&self, local: Vec3) -> f32 {
        let d = local.normalize();
        let v = (-d.z).clamp(-1.0, 1.0).acos();
        let h = d.x.atan2(d.y) + PI;
        self.at(h, v)
    }

    /// The profile's mean over the sphere of directions.
    pub fn mean(&self) -> f32 {
        self.mean
    }
}

/// Cycles' cubic between `b` (x = 0) and `c` (x = 1), `a` and `d` the outer neighbours.
#[inline]
fn catmull_rom(a: f32, b: f32, c: f32, d: f32, x: f32) -> f32 {
    0.5 * (((d + 3.0 * (b - c) - a) * x + (2.0 * a - 5.0 * b + 4.0 * c - d)) * x + (c - a)) * x + b
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() < 1e-4
}

type Table = (Vec<f32>, Vec<f32>, Vec<Vec<f32>>);

/// Type C: horizontal angles about the vertical axis; a quadrant (0-90°) or a half (0-180°)
/// is mirrored to the full circle, a single angle is the same all around, and a table
/// starting at 90° is turned to start at 0°.
fn type_c(mut h: Vec<f32>, v: Vec<f32>, mut t: Vec<Vec<f32>>) -> Table {
    if close(h[0], 90.0) {
        h.iter_mut().for_each(|a| *a -= 90.0);
    }
    if h.len() == 1 {
        h = vec![0.0, 360.0];
        t.push(t[0].clone());
    }
    if close(h[h.len() - 1], 90.0) {
        for i in (0..h.len() - 1).rev() {
            h.push(180.0 - h[i]);
            t.push(t[i].clone());
        }
    }
    if close(h[h.len() - 1], 180.0) {
        for i in (0..h.len() - 1).rev() {
            h.push(360.0 - h[i]);
            t.push(t[i].clone());
        }
    }
    // Files that leave out the 360° entry (it repeats 0°) get it back when their spacing
    // says where it was.
    let n = h.len();
    if close(h[0], 0.0) && !close(h[n - 1], 360.0) && n >= 2 {
        let gap = 360.0 - h[n - 1];
        if close(h[n - 1] - h[n - 2], gap) || close(h[1] - h[0], gap) {
            h.push(360.0);
            t.push(t[0].clone());
        }
    }
    (h, v, t)
}

/// Type B: the polar axis is horizontal. As Cycles, the angles are swapped into type C's
/// frame (rotate the light for the standard's orientation), and 0-90° ranges are mirrored
/// to -90-90°, then shifted to 0-180°.
fn type_b(h: Vec<f32>, v: Vec<f32>, t: Vec<Vec<f32>>) -> Table {
    let (nh, nv) = (h.len(), v.len());
    let mut t: Vec<Vec<f32>> = (0..nv)
        .map(|j| (0..nh).map(|i| t[i][j]).collect())
        .collect();
    let (mut h, mut v) = (v, h);
    if close(h[0], 0.0) {
        let n = h.len();
        let mut nh2 = Vec::with_capacity(2 * n - 1);
        let mut nt = Vec::with_capacity(2 * n - 1);
        for i in (1..n).rev() {
            nh2.push(90.0 - h[i]);
            nt.push(t[i].clone());
        }
        for i in 0..n {
            nh2.push(90.0 + h[i]);
            nt.push(t[i].clone());
        }
        h = nh2;
        t = nt;
    } else {
        h.iter_mut().for_each(|a| *a += 90.0);
    }
    if close(v[0], 0.0) {
        let n = v.len();
        let mut nv2 = Vec::with_capacity(2 * n - 1);
        for i in (1..n).rev() {
            nv2.push(90.0 - v[i]);
        }
        for &a in &v {
            nv2.push(90.0 + a);
        }
        for row in &mut t {
            let mut r: Vec<f32> = row[1..].iter().rev().copied().collect();
            r.extend_from_slice(row);
            *row = r;
        }
        v = nv2;
    } else {
        v.iter_mut().for_each(|a| *a += 90.0);
    }
    (h, v, t)
}

/// Type A: vertical angles from -90° are shifted to start at 0°; horizontal angles -90-90°
/// map to 270-90° of type C (a 0-90° table is mirrored to 180-270°).
fn type_a(h: Vec<f32>, mut v: Vec<f32>, t: Vec<Vec<f32>>) -> Table {
    v.iter_mut().for_each(|a| *a += 90.0);
    let mut nh = Vec::with_capacity(2 * h.len());
    let mut nt = Vec::with_capacity(2 * h.len());
    for i in (0..h.len()).rev() {
        nh.push(180.0 - h[i]);
        nt.push(t[i].clone());
    }
    if close(h[0], 0.0) {
        for i in 1..h.len() {
            nh.push(180.0 + h[i]);
            nt.push(t[i].clone());
        }
    }
    (nh, v, nt)
}

/// A light whose emitted radiance a profile multiplies, for light leaving the light's
/// (sampled) point in world direction `w` by `profile.towards(to_local · w)`. `to_local` is
/// the transpose of the light node's world matrix: Cycles takes the incoming direction into
/// light object space as it would a normal.
#[derive(Clone, Debug)]
pub struct IesLight {
    pub light: Box<EmitterInstance>,
    pub profile: Arc<IesProfile>,
    pub to_local: Mat3,
    /// `light.is_delta()`, kept here so that asking an emitter never recurses.
    delta: bool,
}

impl IesLight {
    pub fn new(light: EmitterInstance, profile: Arc<IesProfile>, to_local: Mat3) -> IesLight {
        IesLight {
            delta: light.is_delta(),
            light: Box::new(light),
            profile,
            to_local,
        }
    }

    /// The profile for light leaving the light's sampled point towards `rec.ref_p`.
    #[inline]
    fn factor(&self, rec: &EmitterQueryRecord) -> f32 {
        self.profile.towards(self.to_local * -rec.wi)
    }
}

// Out of line: these call back into the dispatch over emitters, which must stay inlinable
// into the hot paths of scenes without profiles.
impl Emitter for IesLight {
    #[inline(never)]
    fn sample(&self, scene: &Scene, rec: &mut EmitterQueryRecord, u: Vec2) -> Vec3 {
        let l = self.light.sample(scene, rec, u);
        if l == Vec3::ZERO {
            return l;
        }
        l * self.factor(rec)
    }

    #[inline(never)]
    fn eval(&self, scene: &Scene, rec: &EmitterQueryRecord) -> Vec3 {
        let l = self.light.eval(scene, rec);
        if l == Vec3::ZERO {
            return l;
        }
        l * self.factor(rec)
    }

    #[inline(never)]
    fn pdf(&self, scene: &Scene, rec: &EmitterQueryRecord) -> f32 {
        self.light.pdf(scene, rec)
    }

    fn power(&self, scene: &Scene, scene_radius: f32) -> f32 {
        // The mean, kept from zero: a narrow beam the mean's grid missed still gets shadow rays.
        let peak = self.profile.values.iter().fold(0.0f32, |m, &x| m.max(x));
        self.light.power(scene, scene_radius) * self.profile.mean.max(1e-3 * peak)
    }

    #[inline]
    fn is_delta(&self) -> bool {
        self.delta
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An LM-63 file: `v` and `h` angles (degrees), `rows` of candela per horizontal angle.
    fn file(kind: u32, v: &[f32], h: &[f32], rows: &[&[f32]], multiplier: f32) -> String {
        let join = |a: &[f32]| {
            a.iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(" ")
        };
        let mut s = format!(
            "IESNA:LM-63-2002\n[TEST] synthetic\nTILT=NONE\n1 1000 {multiplier} {} {} {kind} 1 0 0 0\n1.0 1.0 100\n{}\n{}\n",
            v.len(),
            h.len(),
            join(v),
            join(h)
        );
        for r in rows {
            s += &join(r);
            s += "\n";
        }
        s
    }

    const K: f32 = CANDELA_TO_PROFILE as f32;

    #[test]
    fn a_uniform_profile_is_its_candela_times_four_pi_over_d65_efficacy() {
        let p =
            IesProfile::parse(&file(1, &[0.0, 90.0, 180.0], &[0.0], &[&[100.0; 3]], 2.0)).unwrap();
        for d in [
            Vec3::NEG_Z,
            Vec3::X,
            Vec3::new(0.3, -0.5, 0.2),
            Vec3::Z * 0.99 + Vec3::X * 0.1,
        ] {
            let f = p.towards(d);
            assert!((f - 200.0 * K).abs() < 1e-4, "{d}: {f}");
        }
        // 180° itself is outside [v_low, v_high): straight up is dark, as in Cycles.
        assert_eq!(p.towards(Vec3::Z), 0.0);
        assert!(
            (p.mean() - 200.0 * K).abs() < 1e-3 * 200.0 * K,
            "{}",
            p.mean()
        );
    }

    #[test]
    fn a_downlight_lights_the_light_axis_minus_z_and_falls_off_with_the_vertical_angle() {
        let v = [0.0, 15.0, 30.0, 45.0, 60.0, 90.0];
        let row: &[f32] = &[1000.0, 900.0, 500.0, 100.0, 10.0, 0.0];
        let p = IesProfile::parse(&file(1, &v, &[0.0], &[row], 1.0)).unwrap();
        assert!((p.towards(Vec3::NEG_Z) - 1000.0 * K).abs() < 1e-3);
        // At a table angle the cubic passes through the value.
        let at30 = Vec3::new(0.0, 30f32.to_radians().sin(), -30f32.to_radians().cos());
        assert!(
            (p.towards(at30) - 500.0 * K).abs() < 1e-2,
            "{}",
            p.towards(at30)
        );
        // The same all around the axis.
        let rotated = Vec3::new(at30.y, 0.0, at30.z);
        assert!((p.towards(rotated) - p.towards(at30)).abs() < 1e-4);
        // Beyond the table's last angle (90°): nothing.
        assert_eq!(p.towards(Vec3::new(0.0, 1.0, 0.2)), 0.0);
    }

    #[test]
    fn quadrants_and_halves_mirror_to_the_full_circle() {
        let v = [0.0, 45.0, 90.0];
        // One quadrant: 0° bright, 90° dim.
        let q = file(
            1,
            &v,
            &[0.0, 45.0, 90.0],
            &[&[100.0; 3], &[50.0; 3], &[10.0; 3]],
            1.0,
        );
        let p = IesProfile::parse(&q).unwrap();
        assert_eq!(p.h.len(), 9);
        assert!((p.h[8] - 2.0 * PI).abs() < 1e-5);
        // h = atan2(x, y) + π: -y is h = 0 (and 2π), +x is h = 3π/2 (mirrors 90°).
        let dir = |h: f32| {
            let a = h - PI;
            Vec3::new(a.sin(), a.cos(), -1.0)
        };
        let f = |h: f32| p.towards(dir(h));
        assert!((f(0.001) - 100.0 * K).abs() < 0.05);
        assert!((f(PI / 2.0) - 10.0 * K).abs() < 1e-3);
        assert!((f(1.5 * PI) - 10.0 * K).abs() < 1e-3);
        assert!((f(PI) - 100.0 * K).abs() < 1e-3);
        assert!((f(PI / 2.0 - 0.3) - f(PI / 2.0 + 0.3)).abs() < 1e-4);
        // A half 0-180° mirrors about 180°.
        let half = file(
            1,
            &v,
            &[0.0, 90.0, 180.0],
            &[&[100.0; 3], &[50.0; 3], &[10.0; 3]],
            1.0,
        );
        let p = IesProfile::parse(&half).unwrap();
        let f = |h: f32| p.towards(dir(h));
        assert!((f(PI / 2.0) - 50.0 * K).abs() < 1e-3);
        assert!((f(1.5 * PI) - 50.0 * K).abs() < 1e-3);
        assert!((f(PI) - 10.0 * K).abs() < 1e-3);
    }

    #[test]
    fn a_full_circle_without_its_360_entry_gets_it_back_from_its_spacing() {
        let h = [0.0, 90.0, 180.0, 270.0];
        let rows: [&[f32]; 4] = [&[10.0, 10.0], &[20.0, 20.0], &[30.0, 30.0], &[40.0, 40.0]];
        let p = IesProfile::parse(&file(1, &[0.0, 90.0], &h, &rows, 1.0)).unwrap();
        assert_eq!(p.h.len(), 5);
        assert_eq!(p.values[4 * 2], p.values[0]);
        assert!((p.values[0] - 10.0 * K).abs() < 1e-5);
    }

    #[test]
    fn commas_tilt_tables_and_types_a_and_b_are_read() {
        let text = "IESNA91\nTILT=INCLUDE\n1\n3\n0,45,90\n1,0.9,0.8\n1 1000 1 3 1 1 1 0 0 0\n1 1 50\n0 45 90\n0\n7 7 7\n";
        let p = IesProfile::parse(text).unwrap();
        assert!((p.towards(Vec3::new(0.2, 0.1, -1.0)) - 7.0 * K).abs() < 1e-4);
        // Type B: angles swap and mirror; the profile is everywhere defined where the table is.
        let b = file(
            2,
            &[0.0, 45.0, 90.0],
            &[0.0, 90.0],
            &[&[5.0; 3], &[5.0; 3]],
            1.0,
        );
        let p = IesProfile::parse(&b).unwrap();
        assert_eq!(p.v.first().copied(), Some(0.0));
        assert!((p.h[p.h.len() - 1] - PI).abs() < 1e-5);
        // Type A.
        let a = file(
            3,
            &[-90.0, 0.0, 90.0],
            &[0.0, 90.0],
            &[&[5.0; 3], &[5.0; 3]],
            1.0,
        );
        let p = IesProfile::parse(&a).unwrap();
        assert!((p.towards(Vec3::new(0.0, 0.3, -1.0)) - 5.0 * K).abs() < 1e-4);
    }

    #[test]
    fn malformed_files_are_errors_that_say_what_is_wrong() {
        let good = file(1, &[0.0, 90.0], &[0.0], &[&[1.0, 1.0]], 1.0);
        assert!(IesProfile::parse(&good).is_ok());
        let cases: Vec<(String, &str)> = vec![
            (String::new(), "TILT"),
            ("IESNA:LM-63-2002\nno tilt here\n".into(), "TILT"),
            ("x\nTILT=NONE".into(), "TILT"),
            (good.replace("\n1.0 1.0 100", "\n1.0 1.0"), "ends"),
            (
                file(7, &[0.0, 90.0], &[0.0], &[&[1.0, 1.0]], 1.0),
                "photometric type",
            ),
            (
                good.replace("1 1000 1 2 1 1", "1 1000 1 -2 1 1"),
                "not a count",
            ),
            (
                good.replace("1 1000 1 2 1 1", "1 1000 1 0 1 1"),
                "0 vertical",
            ),
            (
                good.replace("1 1000 1 2 1 1", "1 1000 1 4000000 4000000 1"),
                "too many",
            ),
            (good.replace("\n0 90\n", "\n90 0\n"), "not increasing"),
            (
                good.replace("\n0 90\n", "\n0 abc\n"),
                "vertical angles: `abc` is not a number",
            ),
            (good.replace("\n0 90\n", "\n0 inf\n"), "not a number"),
            (good.replace("1 1\n", "1\n"), "ends before its candela"),
        ];
        for (text, wanted) in cases {
            let e = IesProfile::parse(&text).expect_err(&text);
            assert!(e.contains(wanted), "{text:?}: {e}");
        }
        // Odd bytes never panic.
        for n in 0..good.len() {
            let _ = IesProfile::parse(&good[..n]);
        }
        let _ = IesProfile::parse("\nTILT=INCLUDE");
        let _ = IesProfile::parse("\nTILT=INCLUDE 1 99999999999");
    }

    #[test]
    fn lookups_never_panic_or_go_negative() {
        let v = [0.0, 10.0, 20.0, 90.0];
        let row: &[f32] = &[100.0, 0.0, 100.0, 0.0];
        let p = IesProfile::parse(&file(1, &v, &[0.0, 30.0, 90.0], &[row; 3], 1.0)).unwrap();
        for i in 0..2000 {
            let (a, z) = (i as f32 * 2.399, 1.0 - (i as f32 + 0.5) / 1000.0);
            let r = (1.0 - z * z).max(0.0).sqrt();
            let f = p.towards(Vec3::new(r * a.cos(), r * a.sin(), z));
            assert!(f >= 0.0 && f.is_finite());
        }
        assert_eq!(p.towards(Vec3::ZERO), 0.0);
        assert_eq!(p.towards(Vec3::NAN), 0.0);
        assert_eq!(p.at(7.0, 0.1), 0.0);
    }
}
