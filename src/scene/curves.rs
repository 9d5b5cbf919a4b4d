//! Curves (Blender's hair and fur, and other strand geometry) as triangle tubes.
//!
//! Cycles renders a curve as a round tube swept along it ("3D curves"): through its control
//! points with a uniform Catmull-Rom spline (end points repeated), or along straight segments
//! for poly curves, the radius interpolated the same way, the ends rounded. Tesela builds that
//! surface from triangles: rings of vertices at a few points per segment, framed by parallel
//! transport so the tube does not twist, closed by hemispherical caps; [`Detail`] says how
//! many, fine for a few strands and coarser for fur of hundreds of thousands. Normals point
//! out of the tube (the swept circle's), tangents along the curve (Cycles' `dPdu`), and every
//! vertex carries what Hair Info reads in [`CURVE_LAYER`].

use glam::{Vec3, Vec4};

/// Name of the vertex layer holding `(intercept, curve length, random, radius)` per vertex:
/// Hair Info's Intercept (0 at the root to 1 at the tip, by control-polygon length, as Cycles
/// measures it), Length, Random (`hash_uint2_to_float(curve, 0)`) and the radius (object space).
pub const CURVE_LAYER: &str = "tesela:curve";

/// How finely tubes are built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detail {
    /// Vertices around the tube.
    pub sides: usize,
    /// Rings per Catmull-Rom segment (a poly segment is straight: one).
    pub steps: usize,
    /// Rings of each hemispherical end cap, besides its pole.
    pub cap_rings: usize,
}

impl Detail {
    /// From finest to coarsest.
    const LEVELS: [Detail; 4] = [
        Detail {
            sides: 8,
            steps: 4,
            cap_rings: 2,
        },
        Detail {
            sides: 6,
            steps: 2,
            cap_rings: 1,
        },
        Detail {
            sides: 4,
            steps: 2,
            cap_rings: 1,
        },
        Detail {
            sides: 3,
            steps: 1,
            cap_rings: 0,
        },
    ];

    /// The finest detail whose triangles for `curves` strands of `segments` segments in all
    /// stay within `budget` (the coarsest if none does).
    pub fn within(curves: usize, segments: usize, linear: bool, budget: usize) -> Detail {
        let tris = |d: &Detail| {
            let steps = if linear { 1 } else { d.steps };
            2 * d.sides * (segments * steps + curves * (2 * d.cap_rings + 1))
        };
        *Self::LEVELS
            .iter()
            .find(|d| tris(d) <= budget)
            .unwrap_or(&Self::LEVELS[3])
    }
}

impl Default for Detail {
    fn default() -> Self {
        Self::LEVELS[0]
    }
}

/// Strands in one object space: each `(c, a, b)` of `curves` is curve number `c` (what its
/// Random is made of) with points `a..b`, built at `detail`.
pub struct Strands<'a> {
    pub detail: Detail,
    pub points: &'a [Vec3],
    pub radii: &'a [f32],
    pub curves: &'a [(u32, u32, u32)],
    /// Straight segments (Blender's poly curves) instead of Catmull-Rom.
    pub linear: bool,
}

/// A tube mesh in the strands' space.
#[derive(Default)]
pub struct Tubes {
    detail: Detail,
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    /// Unit curve direction, `w` = 1.
    pub tangents: Vec<Vec4>,
    /// See [`CURVE_LAYER`].
    pub info: Vec<Vec4>,
    pub tris: Vec<[u32; 3]>,
}

/// A ring of the tube: its centre, radius, unit tangent, the unit normal its first vertex
/// lies along (perpendicular to the tangent) and the Hair Info of its vertices.
#[derive(Clone, Copy)]
struct Ring {
    c: Vec3,
    r: f32,
    t: Vec3,
    u: Vec3,
    info: Vec4,
}

/// Uniform Catmull-Rom through `p1` (t = 0) and `p2` (t = 1): value and derivative.
#[inline]
fn catmull_rom(p0: Vec4, p1: Vec4, p2: Vec4, p3: Vec4, t: f32) -> (Vec4, Vec4) {
    let (t2, t3) = (t * t, t * t * t);
    let a = 2.0 * p1;
    let b = p2 - p0;
    let c = 2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3;
    let d = -p0 + 3.0 * p1 - 3.0 * p2 + p3;
    (
        0.5 * (a + b * t + c * t2 + d * t3),
        0.5 * (b + 2.0 * c * t + 3.0 * d * t2),
    )
}

/// A unit vector perpendicular to unit `t`.
fn perpendicular(t: Vec3) -> Vec3 {
    let a = if t.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    t.cross(a).normalize()
}

impl Tubes {
    /// A vertex of `ring` at `c + r n` (unit outward normal `n`).
    fn vertex(&mut self, ring: &Ring, n: Vec3) {
        self.positions.push(ring.c + ring.r * n);
        self.normals.push(n);
        self.tangents.push(ring.t.extend(1.0));
        self.info.push(ring.info);
    }

    /// The `sides` vertices around `ring`'s centre whose normals leave the plane of `u` and
    /// `t × u` by the angle `lift` towards `dir` (0: the ring itself); the first one's index.
    fn circle(&mut self, ring: &Ring, lift: f32, dir: Vec3) -> u32 {
        let first = self.positions.len() as u32;
        let v = ring.t.cross(ring.u);
        let sides = self.detail.sides;
        let (sin_lift, cos_lift) = lift.sin_cos();
        for k in 0..sides {
            let a = std::f32::consts::TAU * k as f32 / sides as f32;
            let n = (ring.u * a.cos() + v * a.sin()) * cos_lift + dir * sin_lift;
            self.vertex(ring, n);
        }
        first
    }

    /// Triangles between two consecutive rings.
    fn band(&mut self, a: u32, b: u32) {
        let sides = self.detail.sides as u32;
        for k in 0..sides {
            let k1 = (k + 1) % sides;
            self.tris.push([a + k, a + k1, b + k1]);
            self.tris.push([a + k, b + k1, b + k]);
        }
    }

    /// A hemispherical cap on the vertices `edge` of `ring`, bulging along `dir` (±its tangent).
    fn cap(&mut self, edge: u32, ring: &Ring, dir: Vec3) {
        let at_tip = dir.dot(ring.t) > 0.0;
        let mut prev = edge;
        let Detail {
            sides, cap_rings, ..
        } = self.detail;
        for i in 1..=cap_rings {
            let lift = std::f32::consts::FRAC_PI_2 * i as f32 / (cap_rings + 1) as f32;
            let first = self.circle(ring, lift, dir);
            if at_tip {
                self.band(prev, first);
            } else {
                self.band(first, prev);
            }
            prev = first;
        }
        let pole = self.positions.len() as u32;
        self.vertex(ring, dir);
        let sides = sides as u32;
        for k in 0..sides {
            let k1 = (k + 1) % sides;
            if at_tip {
                self.tris.push([prev + k, prev + k1, pole]);
            } else {
                self.tris.push([prev + k1, prev + k, pole]);
            }
        }
    }
}

/// The tubes of every strand with at least two points and a positive radius somewhere.
/// Malformed ranges (out of order or past the points) are skipped, as are strands with
/// non-finite points; the caller validates and reports.
pub fn tessellate(s: &Strands) -> Tubes {
    let mut out = Tubes {
        detail: s.detail,
        ..Default::default()
    };
    for &(curve, a, b) in s.curves {
        let (a, b) = (a as usize, b as usize);
        if a >= b || b > s.points.len() || b > s.radii.len() || b - a < 2 {
            continue;
        }
        let pts = &s.points[a..b];
        let rad = &s.radii[a..b];
        if pts.iter().any(|p| !p.is_finite()) || rad.iter().any(|r| !r.is_finite()) {
            continue;
        }
        // Intercept by control-polygon length, as Cycles computes it.
        let mut along = Vec::with_capacity(pts.len());
        let mut length = 0.0f32;
        for (i, p) in pts.iter().enumerate() {
            if i > 0 {
                length += (*p - pts[i - 1]).length();
            }
            along.push(length);
        }
        if length <= 0.0 {
            continue;
        }
        let random = crate::shading::tex::hash::hash_uint2_to_float(curve, 0);
        let key = |i: isize| {
            let i = i.clamp(0, pts.len() as isize - 1) as usize;
            pts[i].extend(rad[i].max(0.0))
        };
        // Centre, radius, unit tangent and intercept of every ring along the curve.
        let steps = if s.linear { 1 } else { s.detail.steps };
        let mut samples: Vec<(Vec3, f32, Vec3, f32)> = Vec::new();
        for seg in 0..pts.len() - 1 {
            let i = seg as isize;
            let last = seg == pts.len() - 2;
            for step in 0..steps + usize::from(last) {
                let t = step as f32 / steps as f32;
                let (p, d) = if s.linear {
                    let (p1, p2) = (key(i), key(i + 1));
                    (p1.lerp(p2, t), p2 - p1)
                } else {
                    catmull_rom(key(i - 1), key(i), key(i + 1), key(i + 2), t)
                };
                let dir = d.truncate();
                let tan = if dir.length_squared() > 0.0 {
                    dir.normalize()
                } else {
                    (pts[seg + 1] - pts[seg]).normalize_or_zero()
                };
                if tan == Vec3::ZERO {
                    continue;
                }
                let s_along = along[seg] + (along[seg + 1] - along[seg]) * t;
                samples.push((p.truncate(), p.w.max(0.0), tan, s_along / length));
            }
        }
        if samples.len() < 2 || samples.iter().all(|&(_, r, _, _)| r <= 0.0) {
            continue;
        }
        let info = |r: f32, x: f32| Vec4::new(x, length, random, r);
        // Parallel transport of the ring frame: the normal is rotated with the tangent.
        let mut u = perpendicular(samples[0].2);
        let mut prev: Option<(u32, Ring)> = None;
        let mut first: Option<(u32, Ring)> = None;
        for (k, &(c, r, t, x)) in samples.iter().enumerate() {
            if k > 0 {
                let t0 = samples[k - 1].2;
                let axis = t0.cross(t);
                let sin = axis.length();
                if sin > 1e-7 {
                    let cos = t0.dot(t).clamp(-1.0, 1.0);
                    u = glam::Quat::from_axis_angle(axis / sin, sin.atan2(cos)) * u;
                }
                u = (u - t * t.dot(u)).normalize_or(perpendicular(t));
            }
            let ring = Ring {
                c,
                r,
                t,
                u,
                info: info(r, x),
            };
            let at = out.circle(&ring, 0.0, ring.t);
            match prev {
                Some((p, _)) => out.band(p, at),
                None => first = Some((at, ring)),
            }
            prev = Some((at, ring));
        }
        if let (Some((a, root)), Some((b, tip))) = (first, prev) {
            out.cap(a, &root, -root.t);
            out.cap(b, &tip, tip.t);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strand(linear: bool) -> Tubes {
        let points = [
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.5, 0.0, 2.0),
        ];
        tessellate(&Strands {
            detail: Detail::default(),
            points: &points,
            radii: &[0.1, 0.1, 0.05],
            curves: &[(0, 0, 3)],
            linear,
        })
    }

    /// Every triangle faces away from the curve (its winding agrees with the outward
    /// normals), and the tube passes through its control points at their radii.
    #[test]
    fn tubes_face_outwards_and_pass_through_the_points() {
        for linear in [false, true] {
            let t = strand(linear);
            assert!(!t.tris.is_empty());
            for tri in &t.tris {
                let [a, b, c] = tri.map(|i| t.positions[i as usize]);
                let n = (b - a).cross(c - a);
                let avg: Vec3 = tri.iter().map(|&i| t.normals[i as usize]).sum();
                assert!(
                    n.dot(avg) > 0.0,
                    "linear {linear}: a triangle faces inwards"
                );
            }
            // The ring at the middle control point: every vertex 0.1 from it.
            let mid = Vec3::new(0.0, 0.0, 1.0);
            let ring: Vec<f32> = t
                .positions
                .iter()
                .map(|p| (*p - mid).length())
                .filter(|d| (*d - 0.1).abs() < 1e-4)
                .collect();
            assert!(
                ring.len() >= Detail::default().sides,
                "linear {linear}: no ring at the control point"
            );
        }
    }

    /// Intercept runs from 0 at the root to 1 at the tip; length and random are the curve's.
    #[test]
    fn hair_info_along_the_strand() {
        let t = strand(false);
        let (lo, hi) = t
            .info
            .iter()
            .fold((f32::MAX, f32::MIN), |(l, h), i| (l.min(i.x), h.max(i.x)));
        assert_eq!((lo, hi), (0.0, 1.0));
        let len = 1.0 + (0.25f32 + 1.0).sqrt();
        assert!(t.info.iter().all(|i| (i.y - len).abs() < 1e-5));
        let r = crate::shading::tex::hash::hash_uint2_to_float(0, 0);
        assert!(t.info.iter().all(|i| i.z == r));
    }

    /// Fur of many strands is built coarser, within the budget where a level fits it.
    #[test]
    fn detail_follows_the_budget() {
        assert_eq!(Detail::within(10, 40, false, 1 << 22), Detail::default());
        let fur = Detail::within(200_000, 800_000, false, 1 << 23);
        assert!(fur.sides < 8);
        let s = fur.steps;
        let tris = 2 * fur.sides * (800_000 * s + 200_000 * (2 * fur.cap_rings + 1));
        assert!(tris <= 1 << 23, "{fur:?}: {tris}");
    }

    #[test]
    fn malformed_strands_are_skipped() {
        let points = [Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 0.0, 0.0)];
        let t = tessellate(&Strands {
            detail: Detail::default(),
            points: &points,
            radii: &[0.1; 3],
            curves: &[(0, 0, 2), (1, 2, 1), (2, 1, 3), (3, 3, 9)],
            linear: false,
        });
        // Only the first curve is whole and finite.
        assert!(t.positions.iter().all(|p| p.is_finite()));
        assert!(!t.tris.is_empty());
    }
}
