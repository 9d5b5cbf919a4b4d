//! Motion blur: transforms that change over the shutter interval, interpolated as Cycles
//! interpolates them.
//!
//! Times are shutter-normalised: 0 is the moment the shutter opens, 1 the moment it closes;
//! each camera path draws one time and every ray of the path uses it. A motion is a list of
//! keys (a time and an affine transform). Each key's matrix `M = [A | t]` is decomposed into
//! the translation `t`, a rotation `R` and an upper-triangular stretch `U` (scale on the
//! diagonal, shear above it) with `A = R U`: `R`'s columns are `A`'s columns orthonormalised
//! in order (Gram-Schmidt), and a mirroring `A` takes `-R` and `-U`. Between two keys the
//! rotation's quaternions are slerped (normalised lerp when they are within 0.9995 in cosine;
//! consecutive quaternions are put in one hemisphere so the rotation takes the short way) and
//! `t` and `U` are lerped; a key whose scale is zero takes its neighbour's rotation.

use glam::{Affine3A, Mat3, Mat4, Quat, Vec3, Vec4};

/// One key of a transform, decomposed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decomposed {
    pub rotation: Quat,
    pub translation: Vec3,
    /// Upper triangular: the linear part is `rotation · stretch`.
    pub stretch: Mat3,
}

impl Decomposed {
    /// The decomposition of the affine `m` (its last row is ignored).
    pub fn new(m: &Mat4) -> Decomposed {
        let a = Mat3::from_mat4(*m);
        let (mut x, mut y, mut z) = (a.x_axis, a.y_axis, a.z_axis);
        x = x.normalize_or_zero();
        y = (y - x * x.dot(y)).normalize_or_zero();
        z = z - x * x.dot(z);
        z = (z - y * y.dot(z)).normalize_or_zero();
        let mut r = Mat3::from_cols(x, y, z);
        // Columns lost to a zero scale: complete the frame.
        if r.determinant().abs() < 0.5 {
            r = complete_frame(x, y, z);
        }
        if r.determinant() < 0.0 {
            r = -r;
        }
        let stretch = r.transpose() * a;
        Decomposed {
            rotation: Quat::from_mat3(&r).normalize(),
            translation: m.w_axis.truncate(),
            stretch,
        }
    }

    /// The affine transform this decomposes.
    pub fn compose(&self) -> Mat4 {
        let a = Mat3::from_quat(self.rotation) * self.stretch;
        Mat4::from_cols(
            a.x_axis.extend(0.0),
            a.y_axis.extend(0.0),
            a.z_axis.extend(0.0),
            self.translation.extend(1.0),
        )
    }

    fn zero_scale(&self) -> bool {
        let s = self.stretch;
        s.x_axis.x == 0.0 && s.y_axis.y == 0.0 && s.z_axis.z == 0.0
    }
}

/// An orthonormal right-handed frame keeping the non-zero ones of the unit (or zero) vectors
/// `x`, `y`, `z`.
fn complete_frame(x: Vec3, y: Vec3, z: Vec3) -> Mat3 {
    let nz = |v: Vec3| v.length_squared() > 0.5;
    let (x, y) = match (nz(x), nz(y), nz(z)) {
        (true, true, _) => (x, y),
        (true, false, true) => (x, z.cross(x)),
        (false, true, true) => (y.cross(z), y),
        (true, false, false) => (x, x.any_orthonormal_vector()),
        (false, true, false) => (y.any_orthonormal_vector().cross(y), y),
        (false, false, true) => {
            let x = z.any_orthonormal_vector();
            (x, z.cross(x))
        }
        (false, false, false) => (Vec3::X, Vec3::Y),
    };
    Mat3::from_cols(x, y, x.cross(y))
}

/// Cycles' quaternion interpolation: slerp, or a normalised lerp for nearly equal rotations.
#[inline]
pub fn quat_interpolate(q1: Quat, q2: Quat, t: f32) -> Quat {
    let (a, b) = (Vec4::from(q1), Vec4::from(q2));
    let c = a.dot(b);
    if c > 0.9995 {
        return Quat::from_vec4(((1.0 - t) * a + t * b).normalize());
    }
    let theta = c.clamp(-1.0, 1.0).acos();
    let perp = (b - a * c).normalize();
    let tt = theta * t;
    Quat::from_vec4(a * tt.cos() + perp * tt.sin())
}

/// A transform over the shutter: keys at increasing times in `[0, 1]`.
#[derive(Clone, Debug, PartialEq)]
pub struct TransformMotion {
    times: Vec<f32>,
    keys: Vec<Decomposed>,
}

/// Sub-steps per key interval that [`TransformMotion::bounds`] samples.
const BOUND_STEPS: usize = 8;

impl TransformMotion {
    /// The motion through `keys` (time, affine matrix), or why it cannot be one: fewer than
    /// two keys, times not increasing within `[0, 1]`, or a matrix not finite or not affine.
    pub fn new(keys: &[(f32, Mat4)]) -> Result<TransformMotion, String> {
        if keys.len() < 2 {
            return Err(format!("{} key(s); a motion needs at least 2", keys.len()));
        }
        let mut times = Vec::with_capacity(keys.len());
        let mut dec: Vec<Decomposed> = Vec::with_capacity(keys.len());
        for (k, (t, m)) in keys.iter().enumerate() {
            if !(t.is_finite() && (0.0..=1.0).contains(t)) || times.last().is_some_and(|p| p >= t) {
                return Err(format!(
                    "key {k}: time {t} (times must increase within [0, 1])"
                ));
            }
            if !m.is_finite() || m.row(3) != Vec4::W {
                return Err(format!("key {k}: the matrix is not finite and affine"));
            }
            let mut d = Decomposed::new(m);
            if let Some(p) = dec.last()
                && Vec4::from(p.rotation).dot(Vec4::from(d.rotation)) < 0.0
            {
                d.rotation = -d.rotation;
            }
            times.push(*t);
            dec.push(d);
        }
        for i in 0..dec.len() {
            if dec[i].zero_scale() {
                let n = if i > 0 { i - 1 } else { 1 };
                dec[i].rotation = dec[n].rotation;
            }
        }
        Ok(TransformMotion { times, keys: dec })
    }

    /// Key times.
    pub fn times(&self) -> &[f32] {
        &self.times
    }

    /// The decomposed keys.
    pub fn keys(&self) -> &[Decomposed] {
        &self.keys
    }

    /// Whether every key is the same transform (no motion at all).
    pub fn is_static(&self) -> bool {
        self.keys.windows(2).all(|w| w[0] == w[1])
    }

    /// The key interval holding `time` (clamped to the keys' span) and the fraction within it.
    #[inline]
    fn segment(&self, time: f32) -> (usize, f32) {
        let n = self.times.len();
        let time = time.clamp(self.times[0], self.times[n - 1]);
        let mut i = 0;
        while i + 2 < n && time >= self.times[i + 1] {
            i += 1;
        }
        let (t0, t1) = (self.times[i], self.times[i + 1]);
        (i, ((time - t0) / (t1 - t0)).clamp(0.0, 1.0))
    }

    /// The decomposed transform at `time`.
    #[inline]
    pub fn decomposed_at(&self, time: f32) -> Decomposed {
        let (i, t) = self.segment(time);
        let (a, b) = (&self.keys[i], &self.keys[i + 1]);
        Decomposed {
            rotation: quat_interpolate(a.rotation, b.rotation, t),
            translation: a.translation.lerp(b.translation, t),
            stretch: a.stretch * (1.0 - t) + b.stretch * t,
        }
    }

    /// The transform at `time` (clamped to `[first key, last key]`).
    #[inline]
    pub fn at(&self, time: f32) -> Mat4 {
        self.decomposed_at(time).compose()
    }

    /// [`TransformMotion::at`] as an affine transform.
    #[inline]
    pub fn affine_at(&self, time: f32) -> Affine3A {
        Affine3A::from_mat4(self.at(time))
    }

    /// World bounds of the box `[lo, hi]` moved through every time of the shutter: the boxes
    /// of its corners at sub-steps of each key interval, widened by how far a corner's path
    /// can leave the straight line between two sub-steps (the rotation's arc and its product
    /// with the changing stretch).
    pub fn bounds(&self, lo: Vec3, hi: Vec3) -> (Vec3, Vec3) {
        let corners: [Vec3; 8] = std::array::from_fn(|k| {
            Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        });
        let (mut blo, mut bhi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        let mut pad = 0.0f32;
        for i in 0..self.keys.len() - 1 {
            let (a, b) = (&self.keys[i], &self.keys[i + 1]);
            let (t0, t1) = (self.times[i], self.times[i + 1]);
            let mut prev: Option<Decomposed> = None;
            for s in 0..=BOUND_STEPS {
                let time = t0 + (t1 - t0) * s as f32 / BOUND_STEPS as f32;
                let d = if s == BOUND_STEPS {
                    *b
                } else if s == 0 {
                    *a
                } else {
                    self.decomposed_at(time)
                };
                let m = d.compose();
                for c in &corners {
                    let p = m.transform_point3(*c);
                    blo = blo.min(p);
                    bhi = bhi.max(p);
                }
                if let Some(p) = prev {
                    let cos = Vec4::from(p.rotation)
                        .dot(Vec4::from(d.rotation))
                        .abs()
                        .min(1.0);
                    // Half the rotation angle between the sub-steps.
                    let half = cos.acos();
                    let (q_max, dq_max) = corners.iter().fold((0.0f32, 0.0f32), |(q, dq), c| {
                        let (q0, q1) = (p.stretch * *c, d.stretch * *c);
                        (
                            q.max(q0.length()).max(q1.length()),
                            dq.max((q1 - q0).length()),
                        )
                    });
                    // Arc against chord, plus the stretch's change turning with the rotation;
                    // doubled for the interpolation's own rounding and the lerp fallback.
                    let dev = (1.0 - half.cos()) * q_max + 0.5 * half.sin() * dq_max;
                    pad = pad.max(2.0 * dev);
                }
                prev = Some(d);
            }
        }
        // Relative slack for float rounding of the transformed corners.
        let slack = pad + 1e-6 * blo.abs().max(bhi.abs()).max_element();
        (blo - Vec3::splat(slack), bhi + Vec3::splat(slack))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};

    fn close(a: &Mat4, b: &Mat4, tol: f32) -> bool {
        a.abs_diff_eq(*b, tol)
    }

    #[test]
    fn keys_are_reproduced_at_their_times() {
        let m0 = Mat4::from_scale_rotation_translation(
            Vec3::new(1.5, 0.5, 2.0),
            Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
            Vec3::new(1.0, -2.0, 3.0),
        );
        // A sheared, mirrored matrix.
        let shear = Mat4::from_cols(
            Vec4::new(1.0, 0.0, 0.0, 0.0),
            Vec4::new(0.4, 1.0, 0.0, 0.0),
            Vec4::new(0.0, -0.3, -1.0, 0.0),
            Vec4::W,
        );
        let m1 = Mat4::from_rotation_z(2.5) * shear * Mat4::from_translation(Vec3::X);
        let m2 = Mat4::from_translation(Vec3::new(0.0, 4.0, 0.0));
        let motion = TransformMotion::new(&[(0.0, m0), (0.5, m1), (1.0, m2)]).unwrap();
        for (t, m) in [(0.0, m0), (0.5, m1), (1.0, m2)] {
            let got = motion.at(t);
            assert!(close(&got, &m, 1e-5), "at {t}: {got} vs {m}");
            assert!(close(&Decomposed::new(&m).compose(), &m, 1e-5));
        }
        // The interpolation between keys is the decomposed one.
        let (d0, d1) = (Decomposed::new(&m0), Decomposed::new(&m1));
        let q1 = if Vec4::from(d0.rotation).dot(Vec4::from(d1.rotation)) < 0.0 {
            -d1.rotation
        } else {
            d1.rotation
        };
        let mid = Decomposed {
            rotation: quat_interpolate(d0.rotation, q1, 0.5),
            translation: (d0.translation + d1.translation) * 0.5,
            stretch: (d0.stretch + d1.stretch) * 0.5,
        };
        assert!(close(&motion.at(0.25), &mid.compose(), 1e-5));
    }

    #[test]
    fn midpoint_of_a_rotation_is_the_half_angle() {
        for angle in [FRAC_PI_2, 0.01, 3.0] {
            let a = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0));
            let b = a * Mat4::from_rotation_y(angle);
            let motion = TransformMotion::new(&[(0.0, a), (1.0, b)]).unwrap();
            let want = a * Mat4::from_rotation_y(angle * 0.5);
            assert!(close(&motion.at(0.5), &want, 1e-5), "{angle}");
            let want = a * Mat4::from_rotation_y(angle * 0.25);
            assert!(close(&motion.at(0.25), &want, 1e-5), "{angle}");
        }
        // Quaternions of opposite signs still turn the short way.
        let b = Mat4::from_rotation_z(8.0 * FRAC_PI_4 - 1.0);
        let motion = TransformMotion::new(&[(0.0, Mat4::IDENTITY), (1.0, b)]).unwrap();
        let want = Mat4::from_rotation_z(-0.5);
        assert!(close(&motion.at(0.5), &want, 1e-5));
    }

    #[test]
    fn times_outside_clamp_and_bad_keys_are_refused() {
        let a = Mat4::IDENTITY;
        let b = Mat4::from_translation(Vec3::X);
        let m = TransformMotion::new(&[(0.0, a), (1.0, b)]).unwrap();
        assert_eq!(m.at(-1.0), a);
        assert!(close(&m.at(2.0), &b, 1e-6));
        assert!(TransformMotion::new(&[(0.0, a)]).is_err());
        assert!(TransformMotion::new(&[(0.5, a), (0.5, b)]).is_err());
        assert!(TransformMotion::new(&[(0.0, a), (1.0, Mat4::NAN)]).is_err());
        assert!(!m.is_static());
        assert!(
            TransformMotion::new(&[(0.0, b), (1.0, b)])
                .unwrap()
                .is_static()
        );
    }

    #[test]
    fn bounds_cover_the_swept_path() {
        let (lo, hi) = (Vec3::new(-1.0, -0.2, -0.5), Vec3::new(2.0, 0.3, 0.5));
        let cases = [
            // A half turn in one interval: the arc bulges far past the keys' boxes.
            vec![(0.0, Mat4::IDENTITY), (1.0, Mat4::from_rotation_z(3.1))],
            vec![
                (0.0, Mat4::from_translation(Vec3::new(-3.0, 0.0, 0.0))),
                (
                    0.5,
                    Mat4::from_scale_rotation_translation(
                        Vec3::new(2.0, 0.5, 1.0),
                        Quat::from_rotation_x(1.5),
                        Vec3::ZERO,
                    ),
                ),
                (
                    1.0,
                    Mat4::from_scale_rotation_translation(
                        Vec3::splat(0.2),
                        Quat::from_rotation_y(-2.0),
                        Vec3::new(3.0, 1.0, 0.0),
                    ),
                ),
            ],
        ];
        for keys in cases {
            let m = TransformMotion::new(&keys).unwrap();
            let (blo, bhi) = m.bounds(lo, hi);
            for k in 0..=2000 {
                let t = k as f32 / 2000.0;
                let at = m.at(t);
                for c in 0..8 {
                    let p = Vec3::new(
                        if c & 1 == 0 { lo.x } else { hi.x },
                        if c & 2 == 0 { lo.y } else { hi.y },
                        if c & 4 == 0 { lo.z } else { hi.z },
                    );
                    let w = at.transform_point3(p);
                    assert!(
                        w.cmpge(blo).all() && w.cmple(bhi).all(),
                        "t {t}: {w} outside {blo} {bhi}"
                    );
                }
            }
            // Not absurdly loose: within a tenth of the size of the keys' own union.
            let (mut klo, mut khi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
            for k in 0..=2000 {
                let at = m.at(k as f32 / 2000.0);
                let (l, h) = crate::scene::instance::transform_bounds(&at, lo, hi);
                klo = klo.min(l);
                khi = khi.max(h);
            }
            let size = (khi - klo).max_element();
            assert!(((blo - klo).abs().max_element()) < 0.1 * size);
            assert!(((bhi - khi).abs().max_element()) < 0.1 * size);
        }
    }
}
