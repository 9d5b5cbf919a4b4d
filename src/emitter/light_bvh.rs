//! A small bounding-volume hierarchy over the shapes of Blender lights (spheres, disks,
//! rectangles), which are not part of the scene's triangle BVH: lights never occlude. Rays ask
//! it for every light whose bounds they cross; the caller intersects the shapes.

use glam::Vec3;

/// Leaves hold at most this many lights.
const LEAF: usize = 2;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// Leaf: `count > 0` lights from `first` in [`LightBvh::order`]; inner: children at
    /// `first` and `first + 1`.
    first: u32,
    count: u32,
}

#[derive(Clone, Debug, Default)]
pub struct LightBvh {
    nodes: Vec<Node>,
    /// Item indices in leaf order.
    order: Vec<u32>,
    /// Each item's box (by item index).
    boxes: Vec<(Vec3, Vec3)>,
}

impl LightBvh {
    /// A hierarchy over axis-aligned boxes `(lo, hi)`; item `i` is reported as `i`.
    pub fn new(bounds: &[(Vec3, Vec3)]) -> LightBvh {
        let mut bvh = LightBvh {
            nodes: Vec::with_capacity(2 * bounds.len().max(1)),
            order: (0..bounds.len() as u32).collect(),
            boxes: bounds.to_vec(),
        };
        if bounds.is_empty() {
            return bvh;
        }
        bvh.nodes.push(Node {
            lo: Vec3::ZERO,
            hi: Vec3::ZERO,
            first: 0,
            count: 0,
        });
        bvh.build(bounds, 0, 0, bounds.len());
        bvh
    }

    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// Fills node `ni` with items `order[start..end]`: median split along the widest axis of
    /// the boxes' centres.
    fn build(&mut self, bounds: &[(Vec3, Vec3)], ni: usize, start: usize, end: usize) {
        let items = &mut self.order[start..end];
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        let (mut clo, mut chi) = (lo, hi);
        for &i in items.iter() {
            let (a, b) = bounds[i as usize];
            lo = lo.min(a);
            hi = hi.max(b);
            let c = 0.5 * (a + b);
            clo = clo.min(c);
            chi = chi.max(c);
        }
        if items.len() <= LEAF {
            self.nodes[ni] = Node {
                lo,
                hi,
                first: start as u32,
                count: items.len() as u32,
            };
            return;
        }
        let ext = chi - clo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let key = |i: &u32| {
            let (a, b) = bounds[*i as usize];
            (a + b)[axis]
        };
        let mid = items.len() / 2;
        items.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
        let child = self.nodes.len();
        for _ in 0..2 {
            self.nodes.push(Node {
                lo: Vec3::ZERO,
                hi: Vec3::ZERO,
                first: 0,
                count: 0,
            });
        }
        self.nodes[ni] = Node {
            lo,
            hi,
            first: child as u32,
            count: 0,
        };
        self.build(bounds, child, start, start + mid);
        self.build(bounds, child + 1, start + mid, end);
    }

    /// Calls `f(item)` for every item whose box the ray `o + t d`, `t ∈ [0, tmax]`, crosses
    /// (in no particular order).
    #[inline]
    pub fn visit(&self, o: Vec3, d: Vec3, tmax: f32, mut f: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = d.recip();
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let n = self.nodes[stack[top] as usize];
            if !slab(n.lo, n.hi, o, inv, tmax) {
                continue;
            }
            if n.count > 0 {
                for &i in &self.order[n.first as usize..(n.first + n.count) as usize] {
                    let (lo, hi) = self.boxes[i as usize];
                    if slab(lo, hi, o, inv, tmax) {
                        f(i);
                    }
                }
            } else if top + 2 <= stack.len() {
                stack[top] = n.first;
                stack[top + 1] = n.first + 1;
                top += 2;
            }
        }
    }
}

/// Whether the ray crosses the box within `[0, tmax]` (NaN-safe: zero direction components
/// give infinite reciprocals, and `min`/`max` drop the NaNs of `0 · ∞`).
#[inline]
fn slab(lo: Vec3, hi: Vec3, o: Vec3, inv: Vec3, tmax: f32) -> bool {
    let t0 = (lo - o) * inv;
    let t1 = (hi - o) * inv;
    let tn = t0.min(t1).max_element().max(0.0);
    let tf = t0.max(t1).min_element().min(tmax);
    tn <= tf * (1.0 + 4.0 * f32::EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visits_exactly_the_boxes_a_ray_crosses() {
        let mut rng = crate::sampler::Sampler::new(3, 0, 0);
        let mut boxes = Vec::new();
        for _ in 0..300 {
            let c = Vec3::new(rng.next_1d(), rng.next_1d(), rng.next_1d()) * 20.0 - 10.0;
            let r = rng.next_1d() * 0.5 + 0.01;
            boxes.push((c - r, c + r));
        }
        let bvh = LightBvh::new(&boxes);
        let inv_brute = |o: Vec3, d: Vec3, tmax: f32| -> Vec<u32> {
            let inv = d.recip();
            (0..boxes.len() as u32)
                .filter(|&i| slab(boxes[i as usize].0, boxes[i as usize].1, o, inv, tmax))
                .collect()
        };
        for k in 0..2000 {
            let o = Vec3::new(rng.next_1d(), rng.next_1d(), rng.next_1d()) * 24.0 - 12.0;
            let mut d = crate::sampling::square_to_uniform_sphere(rng.next_2d());
            if k % 7 == 0 {
                d = Vec3::new(0.0, d.y.signum(), 0.0);
            }
            let tmax = if k % 2 == 0 { f32::INFINITY } else { 8.0 };
            let mut got = Vec::new();
            bvh.visit(o, d, tmax, |i| got.push(i));
            got.sort();
            assert_eq!(got, inv_brute(o, d, tmax), "ray {o} {d}");
        }
    }
}
