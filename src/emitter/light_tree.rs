//! A light tree: lights at finite positions chosen per shading point by an importance that
//! weighs each subtree's power by its distance and orientation (Conty Estevez & Kulla 2018, as
//! pbrt-v4's BVH light sampler and Cycles' light tree do). A binary tree over the lights'
//! bounds; sampling walks from the root, picking each child with probability proportional to
//! its importance at the point, and the probability of a light is the product of the choices
//! along its path (recomputed for MIS by walking up from its leaf).
//!
//! The importance is conservative: it is zero only where no light of the subtree can reach the
//! point (beyond every emission cone), so the choice stays unbiased.

use crate::sampling::pick;
use glam::Vec3;
use std::f32::consts::PI;

/// Bounds of the light a subtree emits: where from, how much, and in which directions. Light
/// leaves within `theta_o` of `axis` (the emitters' normals or spot axes), spreading up to a
/// further `theta_e` around each of those directions (π/2 for a Lambertian surface, 0 for a
/// spot's cone edge).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    pub lo: Vec3,
    pub hi: Vec3,
    /// Power (luminance-weighted W), > 0.
    pub phi: f32,
    pub axis: Vec3,
    pub theta_o: f32,
    pub theta_e: f32,
}

impl LightBounds {
    /// Bounds emitting in every direction (points, spheres, two-sided meshes).
    pub fn omni(lo: Vec3, hi: Vec3, phi: f32) -> LightBounds {
        LightBounds {
            lo,
            hi,
            phi,
            axis: Vec3::Z,
            theta_o: PI,
            theta_e: PI / 2.0,
        }
    }

    /// The union of two bounds.
    pub fn union(&self, b: &LightBounds) -> LightBounds {
        let (axis, theta_o) = cone_union(self.axis, self.theta_o, b.axis, b.theta_o);
        LightBounds {
            lo: self.lo.min(b.lo),
            hi: self.hi.max(b.hi),
            phi: self.phi + b.phi,
            axis,
            theta_o,
            theta_e: self.theta_e.max(b.theta_e),
        }
    }

    /// The importance of the subtree for a point at `p`: power × cos θ' / d², θ' the smallest
    /// angle between `p`'s direction from any point of the box and the emission cone; zero when
    /// `p` lies beyond every emission direction.
    #[inline]
    pub fn importance(&self, p: Vec3) -> f32 {
        let c = 0.5 * (self.lo + self.hi);
        let r = 0.5 * (self.hi - self.lo).length();
        let v = p - c;
        let d2 = v.length_squared();
        // Inside (or at) the bounding sphere nothing bounds the direction.
        if d2 <= r * r || d2 == 0.0 {
            return self.phi / (r * r).max(1e-12);
        }
        let d = d2.sqrt();
        let theta_b = (r / d).min(1.0).asin();
        let theta_p = if self.theta_o >= PI {
            0.0
        } else {
            let cos_w = (self.axis.dot(v) / d).clamp(-1.0, 1.0);
            (cos_w.acos() - self.theta_o - theta_b).max(0.0)
        };
        if theta_p > self.theta_e {
            return 0.0;
        }
        // (`max` also turns the NaN of absurd bounds into 0.)
        (self.phi * theta_p.cos().max(0.0) / d2.max(r * r)).max(0.0)
    }
}

/// The smallest cone (axis, half-angle) holding both cones.
fn cone_union(wa: Vec3, ta: f32, wb: Vec3, tb: f32) -> (Vec3, f32) {
    if ta >= PI || tb >= PI {
        return (wa, PI);
    }
    let d = wa.dot(wb).clamp(-1.0, 1.0).acos();
    if (d + tb).min(PI) <= ta {
        return (wa, ta);
    }
    if (d + ta).min(PI) <= tb {
        return (wb, tb);
    }
    let t = 0.5 * (ta + d + tb);
    if t >= PI {
        return (wa, PI);
    }
    let Some(k) = wa.cross(wb).try_normalize() else {
        return (wa, PI);
    };
    // Rotate wa towards wb by t - ta (Rodrigues; k ⟂ wa).
    let (s, co) = crate::trig::sin_cos(t - ta);
    let w = (wa * co + k.cross(wa) * s).normalize();
    (w, t)
}

#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: LightBounds,
    /// Inner: index of the first child (the second follows); leaf: the item.
    index: u32,
    leaf: bool,
    parent: u32,
}

#[derive(Clone, Debug, Default)]
pub struct LightTree {
    nodes: Vec<Node>,
    /// Item → its leaf node.
    leaf_of: Vec<u32>,
}

impl LightTree {
    /// A tree over `items` (reported by their position in the slice).
    pub fn new(items: &[LightBounds]) -> LightTree {
        let mut tree = LightTree {
            nodes: Vec::with_capacity(2 * items.len()),
            leaf_of: vec![u32::MAX; items.len()],
        };
        if items.is_empty() {
            return tree;
        }
        let mut order: Vec<u32> = (0..items.len() as u32).collect();
        tree.nodes.push(Node {
            bounds: items[0],
            index: 0,
            leaf: true,
            parent: u32::MAX,
        });
        tree.build(items, &mut order, 0);
        tree
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Fills node `ni` with `order`'s items: median split of the centres along the widest axis.
    fn build(&mut self, items: &[LightBounds], order: &mut [u32], ni: usize) -> LightBounds {
        if order.len() == 1 {
            let i = order[0];
            self.nodes[ni].bounds = items[i as usize];
            self.nodes[ni].index = i;
            self.nodes[ni].leaf = true;
            self.leaf_of[i as usize] = ni as u32;
            return items[i as usize];
        }
        let centre = |i: &u32| 0.5 * (items[*i as usize].lo + items[*i as usize].hi);
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for i in order.iter() {
            lo = lo.min(centre(i));
            hi = hi.max(centre(i));
        }
        let ext = hi - lo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let mid = order.len() / 2;
        order.select_nth_unstable_by(mid, |a, b| centre(a)[axis].total_cmp(&centre(b)[axis]));
        let first = self.nodes.len();
        for _ in 0..2 {
            self.nodes.push(Node {
                bounds: items[0],
                index: 0,
                leaf: true,
                parent: ni as u32,
            });
        }
        let (left, right) = order.split_at_mut(mid);
        let a = self.build(items, left, first);
        let b = self.build(items, right, first + 1);
        let bounds = a.union(&b);
        self.nodes[ni].bounds = bounds;
        self.nodes[ni].index = first as u32;
        self.nodes[ni].leaf = false;
        bounds
    }

    /// The importance of the whole tree for a point at `p` ([`LightBounds::importance`] of
    /// its root; zero for an empty tree).
    #[inline]
    pub fn importance(&self, p: Vec3) -> f32 {
        self.nodes.first().map_or(0.0, |n| n.bounds.importance(p))
    }

    /// Chooses an item for a point at `p`: `(item, probability)`, or `None` when no light can
    /// reach `p`.
    #[inline]
    pub fn sample(&self, p: Vec3, mut u: f32) -> Option<(usize, f32)> {
        let mut ni = 0usize;
        let mut pmf = 1.0f32;
        if self.nodes.is_empty() {
            return None;
        }
        if self.nodes[0].leaf {
            return (self.nodes[0].bounds.importance(p) > 0.0)
                .then_some((self.nodes[0].index as usize, 1.0));
        }
        loop {
            let n = &self.nodes[ni];
            if n.leaf {
                return Some((n.index as usize, pmf));
            }
            let (a, b) = (n.index as usize, n.index as usize + 1);
            let ia = self.nodes[a].bounds.importance(p);
            let ib = self.nodes[b].bounds.importance(p);
            let sum = ia + ib;
            if !(sum > 0.0 && sum.is_finite()) {
                return None;
            }
            let pa = ia / sum;
            let (first, rest) = pick(pa, u);
            u = rest;
            if first {
                pmf *= pa;
                ni = a;
            } else {
                pmf *= 1.0 - pa;
                ni = b;
            }
        }
    }

    /// The probability that [`LightTree::sample`] chooses `item` for a point at `p`.
    #[inline]
    pub fn pmf(&self, p: Vec3, item: usize) -> f32 {
        let Some(&leaf) = self.leaf_of.get(item) else {
            return 0.0;
        };
        if leaf == u32::MAX {
            return 0.0;
        }
        let mut ni = leaf as usize;
        if self.nodes[ni].parent == u32::MAX {
            return if self.nodes[ni].bounds.importance(p) > 0.0 {
                1.0
            } else {
                0.0
            };
        }
        let mut pmf = 1.0f32;
        while self.nodes[ni].parent != u32::MAX {
            let parent = self.nodes[ni].parent as usize;
            let first = self.nodes[parent].index as usize;
            let ia = self.nodes[first].bounds.importance(p);
            let ib = self.nodes[first + 1].bounds.importance(p);
            let sum = ia + ib;
            if !(sum > 0.0 && sum.is_finite()) {
                return 0.0;
            }
            let mine = if ni == first { ia } else { ib };
            // The same arithmetic as sampling's: the second child gets 1 - p_first.
            let pa = ia / sum;
            pmf *= if ni == first { pa } else { 1.0 - pa };
            if mine == 0.0 {
                return 0.0;
            }
            ni = parent;
        }
        pmf
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Sampler;

    fn random_bounds(rng: &mut Sampler) -> LightBounds {
        let c = Vec3::new(rng.next_1d(), rng.next_1d(), rng.next_1d()) * 10.0 - 5.0;
        let r = rng.next_1d() * 0.5;
        let phi = 10f32.powf(rng.next_1d() * 3.0);
        let kind = (rng.next_1d() * 3.0) as u32;
        let axis = crate::sampling::square_to_uniform_sphere(rng.next_2d());
        match kind {
            0 => LightBounds::omni(c - r, c + r, phi),
            1 => LightBounds {
                lo: c - r,
                hi: c + r,
                phi,
                axis,
                theta_o: 0.0,
                theta_e: PI / 2.0,
            },
            _ => LightBounds {
                lo: c,
                hi: c,
                phi,
                axis,
                theta_o: rng.next_1d() * 1.2,
                theta_e: 0.0,
            },
        }
    }

    #[test]
    fn pmf_matches_sampling() {
        let mut rng = Sampler::new(5, 0, 0);
        let items: Vec<LightBounds> = (0..57).map(|_| random_bounds(&mut rng)).collect();
        let tree = LightTree::new(&items);
        for _ in 0..50 {
            let p = Vec3::new(rng.next_1d(), rng.next_1d(), rng.next_1d()) * 12.0 - 6.0;
            let pmfs: Vec<f32> = (0..items.len()).map(|i| tree.pmf(p, i)).collect();
            // Subtrees whose children can both not reach p lose their share (sampling fails
            // there), so the probabilities may sum to less than 1, never more.
            let total: f32 = pmfs.iter().sum();
            assert!(total <= 1.0 + 1e-4, "Σ pmf = {total}");
            let mut counts = vec![0u32; items.len()];
            let mut failed = 0u32;
            let n = 20_000;
            for k in 0..n {
                let u = (k as f32 + 0.5) / n as f32;
                let Some((i, pmf)) = tree.sample(p, u) else {
                    failed += 1;
                    continue;
                };
                assert!(
                    (pmf - pmfs[i]).abs() <= 1e-4 * pmfs[i].max(1e-3),
                    "{pmf} vs {}",
                    pmfs[i]
                );
                counts[i] += 1;
            }
            // Stratified u: each light gets its share to within a couple of samples per level
            // of the tree.
            for (i, &c) in counts.iter().enumerate() {
                let want = pmfs[i] * n as f32;
                assert!((c as f32 - want).abs() <= 16.0, "light {i}: {c} vs {want}");
            }
            let want = (1.0 - total) * n as f32;
            assert!(
                (failed as f32 - want).abs() <= 64.0,
                "{failed} failures vs {want}"
            );
        }
    }

    #[test]
    fn importance_is_zero_only_outside_every_emission_cone() {
        // A spot at the origin pointing down +Z with a 30° cone: points inside get light.
        let spot = LightBounds {
            lo: Vec3::ZERO,
            hi: Vec3::ZERO,
            phi: 1.0,
            axis: Vec3::Z,
            theta_o: 30f32.to_radians(),
            theta_e: 0.0,
        };
        assert!(spot.importance(Vec3::new(0.2, 0.0, 1.0)) > 0.0);
        assert_eq!(spot.importance(Vec3::new(1.0, 0.0, 1.0)), 0.0);
        // A one-sided panel facing +Z: behind it nothing.
        let panel = LightBounds {
            lo: Vec3::new(-1.0, -1.0, 0.0),
            hi: Vec3::new(1.0, 1.0, 0.0),
            phi: 1.0,
            axis: Vec3::Z,
            theta_o: 0.0,
            theta_e: PI / 2.0,
        };
        assert!(panel.importance(Vec3::new(3.0, 0.0, 0.5)) > 0.0);
        assert_eq!(panel.importance(Vec3::new(0.0, 0.0, -5.0)), 0.0);
        // Their union keeps both.
        let u = spot.union(&panel);
        assert!(u.importance(Vec3::new(0.2, 0.0, 1.0)) > 0.0);
        assert!(u.importance(Vec3::new(3.0, 0.0, 0.5)) > 0.0);
    }
}
