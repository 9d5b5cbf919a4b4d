//! Ray–triangle acceleration: an `obvhs` compressed wide BVH (CWBVH8) over every triangle.
//!
//! Triangles are stored in BVH leaf order so a leaf's triangles are contiguous in memory.
//! Intersection is Möller–Trumbore in single precision; callers offset ray origins
//! (see [`offset_origin`]) because the test is not watertight.

use glam::{UVec2, Vec3, Vec3A};
use obvhs::{
    BvhBuildParams,
    cwbvh::builder::build_cwbvh_from_tris,
    cwbvh::{CwBvh, node::CwBvhNode},
    ray::Ray as BvhRay,
    triangle::Triangle,
};

/// Scratch state of one traversal (the node stack), reused from ray to ray by a thread:
/// making a fresh one clears 256 bytes, a measurable share of a ray in a small scene.
pub use obvhs::cwbvh::Traversal;
use std::time::Duration;

/// Largest coordinate magnitude the BVH accepts (metres). Beyond it the builder's surface-area
/// costs overflow `f32` (obvhs then indexes out of bounds: found by fuzzing), so the loader
/// refuses such vertices and [`Accel::build`] replaces any triangle reaching past it by an
/// empty one that no ray hits.
pub const MAX_COORD: f32 = 1e12;

/// Up to this many triangles a ray tests each one instead of traversing the BVH (an area
/// light's few triangles in the emitter BVH, tiny scenes).
pub(crate) const BRUTE_FORCE: usize = 8;

/// A triangle prepared for intersection: `v0` and the edges `e1 = v1 - v0`, `e2 = v2 - v0`.
#[derive(Clone, Copy, Debug)]
struct PackedTriangle {
    v0: Vec3A,
    e1: Vec3A,
    e2: Vec3A,
}

/// The closest intersection along a ray.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Ray parameter of the hit (distance for a unit direction).
    pub t: f32,
    /// The key the triangle was given to [`Accel::build_from`] with (for a scene: mesh index,
    /// triangle index within the mesh).
    pub key: [u32; 2],
    /// Barycentric weight of vertex 1.
    pub u: f32,
    /// Barycentric weight of vertex 2 (vertex 0 has `1 - u - v`).
    pub v: f32,
    /// The hit point `v0 + u e1 + v e2` (world space), from the triangle data the test just
    /// read (no second look-up of the vertices).
    pub p: Vec3,
    /// `e1 × e2`: the unnormalised geometric normal by the right-hand rule (zero for a
    /// degenerate triangle).
    pub ng: Vec3,
    /// The instance whose mesh was hit ([`NO_INSTANCE`] for a world-space mesh).
    pub instance: u32,
}

/// [`Hit::instance`] of a world-space mesh.
pub const NO_INSTANCE: u32 = u32::MAX;

/// A BVH over triangles.
pub struct Accel {
    bvh: CwBvh,
    tris: Vec<PackedTriangle>,
    /// For each stored triangle (BVH leaf order), its key.
    keys: Vec<[u32; 2]>,
    /// Traverse with the AVX2 node test (the CPU has it, see [`avx2_available`]).
    avx2: bool,
    /// Prefetch what a node test finds (see [`prefetch_hits`]): the BVH is larger than
    /// [`PREFETCH_BYTES`], so its loads miss the cache.
    prefetch: bool,
}

/// Nodes and triangles beyond this size are traversed with prefetching: about a core's L2
/// cache. Smaller BVHs stay in the cache, where the prefetches would only cost instructions.
const PREFETCH_BYTES: usize = 1 << 20;

/// Whether this CPU runs [`node_hits_avx2`] and the instructions the traversal compiled beside
/// it uses (the portable build targets plain x86-64: SSE2, no POPCNT or LZCNT).
pub(crate) fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("bmi1")
            && std::is_x86_feature_detected!("bmi2")
            && std::is_x86_feature_detected!("lzcnt")
            && std::is_x86_feature_detected!("popcnt")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// obvhs' lower bound on a child box's entry distance.
const NODE_EPSILON: f32 = 0.0001;

/// The hit mask of `node`'s children for `ray` (obvhs' `CwBvhNode::intersect_ray`): the
/// AVX2 test when `AVX2` (only instantiated inside functions compiled for it), else obvhs'.
#[inline(always)]
fn node_hits<const AVX2: bool>(node: &CwBvhNode, ray: &BvhRay, oct_inv4: u32) -> u32 {
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: `AVX2` is only true in the traversals run when `avx2_available()`.
        return unsafe { node_hits_avx2(node, ray, oct_inv4) };
    }
    node.intersect_ray(ray, oct_inv4)
}

/// obvhs' SSE slab test of a CWBVH8 node, all eight children at once: the same operations in
/// the same order per child (multiply, then add; max/min with the same operands), so the
/// hit mask is bit for bit obvhs'. The quantised planes widen from bytes in two instructions,
/// where SSE2 converts them one at a time (the test's dominant cost).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn node_hits_avx2(node: &CwBvhNode, ray: &BvhRay, oct_inv4: u32) -> u32 {
    use std::arch::x86_64::*;
    let dir_inv = node.compute_extent() * ray.inv_direction;
    let orig = (Vec3A::from(node.p) - ray.origin) * ray.inv_direction;
    // SAFETY: each load reads the 8 bytes of `v`.
    let planes = |v: &[u8; 8]| unsafe {
        _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(
            v.as_ptr() as *const __m128i
        )))
    };
    let slab = |lo: &[u8; 8], hi: &[u8; 8], negative: bool, inv: f32, org: f32| {
        let (lo, hi) = (planes(lo), planes(hi));
        let (near, far) = if negative { (hi, lo) } else { (lo, hi) };
        let (inv, org) = (_mm256_set1_ps(inv), _mm256_set1_ps(org));
        (
            _mm256_add_ps(_mm256_mul_ps(near, inv), org),
            _mm256_add_ps(_mm256_mul_ps(far, inv), org),
        )
    };
    let d = ray.direction;
    let (x0, x1) = slab(
        &node.child_min_x,
        &node.child_max_x,
        d.x < 0.0,
        dir_inv.x,
        orig.x,
    );
    let (y0, y1) = slab(
        &node.child_min_y,
        &node.child_max_y,
        d.y < 0.0,
        dir_inv.y,
        orig.y,
    );
    let (z0, z1) = slab(
        &node.child_min_z,
        &node.child_max_z,
        d.z < 0.0,
        dir_inv.z,
        orig.z,
    );
    let mask = {
        let tmin = _mm256_max_ps(x0, _mm256_max_ps(y0, z0));
        let tmax = _mm256_min_ps(x1, _mm256_min_ps(y1, z1));
        let tmin = _mm256_max_ps(tmin, _mm256_set1_ps(NODE_EPSILON));
        let tmax = _mm256_min_ps(tmax, _mm256_set1_ps(ray.tmax));
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OS>(tmin, tmax)) as u32
    };
    let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
    let mut hits = 0u32;
    let mut m = mask;
    while m != 0 {
        let shift = m.trailing_zeros() * 8;
        hits |= ((child_bits8 >> shift) as u32 & 0xff) << ((bit_index8 >> shift) as u32 & 0xff);
        m &= m - 1;
    }
    hits
}

/// Asks the cache for what the traversal reads next after a node test with hit mask `hits`:
/// every hit interior child and the triangles of every hit leaf. The traversal visits them one
/// at a time, so without this each cache miss waits for the one before; with it their misses
/// overlap (traversal of a million triangles is bound by these loads).
#[inline(always)]
fn prefetch_hits(bvh: &CwBvh, tris: &[PackedTriangle], node: &CwBvhNode, hits: u32, oct_inv4: u32) {
    let mut children = hits >> 24;
    while children != 0 {
        let slot = children.trailing_zeros() ^ (oct_inv4 & 0xff);
        let below = (node.imask as u32 & !(u32::MAX << slot)).count_ones();
        if let Some(child) = bvh.nodes.get((node.child_base_idx + below) as usize) {
            prefetch(std::slice::from_ref(child));
        }
        children &= children - 1;
    }
    let leaves = hits & 0x00ff_ffff;
    if leaves != 0 {
        let base = node.primitive_base_idx as usize;
        let first = base + leaves.trailing_zeros() as usize;
        let last = base + 31 - leaves.leading_zeros() as usize;
        if let Some(group) = tris.get(first..=last) {
            prefetch(group);
        }
    }
}

/// Prefetches each cache line `items` spans, once.
#[inline(always)]
fn prefetch<T>(items: &[T]) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let start = items.as_ptr() as *const i8;
        let bytes = std::mem::size_of_val(items);
        if bytes == 0 {
            return;
        }
        let last = start.wrapping_add(bytes - 1);
        // From the start of the first line to the last line, one prefetch per line.
        let mut p = start.wrapping_sub(start as usize % 64);
        while p <= last {
            // SAFETY: prefetching has no architectural effect (an address need not be valid).
            unsafe { _mm_prefetch::<_MM_HINT_T0>(p) };
            p = p.wrapping_add(64);
        }
    }
}

/// Möller–Trumbore: `(t, u, v)` of the hit inside `(tmin, tmax)`, else `None`.
#[inline(always)]
fn intersect_triangle(
    tri: &PackedTriangle,
    o: Vec3A,
    d: Vec3A,
    tmin: f32,
    tmax: f32,
) -> Option<(f32, f32, f32)> {
    let pvec = d.cross(tri.e2);
    let det = tri.e1.dot(pvec);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let tvec = o - tri.v0;
    let u = tvec.dot(pvec) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qvec = tvec.cross(tri.e1);
    let v = d.dot(qvec) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = tri.e2.dot(qvec) * inv;
    (t > tmin && t < tmax).then_some((t, u, v))
}

impl Accel {
    /// Makes the triangles whose key is `[mesh, _]` unhittable in place (zero edges: the
    /// determinant of every ray against them is 0), without building the BVH again; its
    /// boxes still enclose them, which costs traversal only. Returns how many there were.
    pub fn remove_mesh(&mut self, mesh: u32) -> usize {
        let mut n = 0;
        for (t, k) in self.tris.iter_mut().zip(&self.keys) {
            if k[0] == mesh {
                t.e1 = Vec3A::ZERO;
                t.e2 = Vec3A::ZERO;
                n += 1;
            }
        }
        n
    }

    /// Builds the BVH over `triangles` (world-space vertex triples); triangle `i` has the
    /// key `[0, i]`.
    pub fn build(triangles: &[[Vec3; 3]]) -> Accel {
        let keys = (0..triangles.len() as u32).map(|i| [0, i]);
        Accel::build_from(triangles.len(), triangles.iter().copied(), keys)
    }

    /// Builds the BVH over the `n` triangles of `triangles`, each with the matching item of
    /// `keys` (returned in [`Hit::key`]), without an intermediate copy of the scene (a
    /// 10-million-triangle scene saves 360 MB at the build's peak).
    pub fn build_from(
        n: usize,
        triangles: impl Iterator<Item = [Vec3; 3]>,
        keys: impl Iterator<Item = [u32; 2]>,
    ) -> Accel {
        let mut input: Vec<Triangle> = Vec::with_capacity(n);
        input.extend(triangles.map(|t| {
            let inside = t.iter().all(|v| v.abs().max_element() <= MAX_COORD);
            let t = if inside { t } else { [Vec3::ZERO; 3] };
            Triangle {
                v0: t[0].into(),
                v1: t[1].into(),
                v2: t[2].into(),
            }
        }));
        if input.is_empty() {
            return Accel {
                bvh: CwBvh::default(),
                tris: Vec::new(),
                keys: Vec::new(),
                avx2: false,
                prefetch: false,
            };
        }
        let mut build_time = Duration::ZERO;
        let bvh = build_cwbvh_from_tris(&input, BvhBuildParams::medium_build(), &mut build_time);
        let tris: Vec<PackedTriangle> = bvh
            .primitive_indices
            .iter()
            .map(|&i| {
                let t = &input[i as usize];
                PackedTriangle {
                    v0: t.v0,
                    e1: t.v1 - t.v0,
                    e2: t.v2 - t.v0,
                }
            })
            .collect();
        drop(input);
        let input_keys: Vec<[u32; 2]> = keys.take(n).collect();
        let keys = bvh
            .primitive_indices
            .iter()
            .map(|&i| input_keys.get(i as usize).copied().unwrap_or([u32::MAX; 2]))
            .collect();
        let bytes = bvh.nodes.len() * std::mem::size_of::<CwBvhNode>()
            + tris.len() * std::mem::size_of::<PackedTriangle>();
        Accel {
            bvh,
            tris,
            keys,
            avx2: avx2_available(),
            prefetch: bytes > PREFETCH_BYTES,
        }
    }

    /// Traverses with the portable SSE2 node test even where AVX2 is available (tests compare
    /// the two).
    pub fn portable(mut self) -> Accel {
        self.avx2 = false;
        self
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// Whether there is no triangle.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// Closest hit of the ray `o + t d` with `t` in `(tmin, tmax)`.
    pub fn intersect(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        self.intersect_with(&mut Traversal::default(), o, d, tmin, tmax)
    }

    /// [`Accel::intersect`] with the caller's traversal state.
    #[inline]
    pub fn intersect_with(
        &self,
        trav: &mut Traversal,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> Option<Hit> {
        if self.tris.is_empty() {
            return None;
        }
        if self.tris.len() <= BRUTE_FORCE {
            let (o, d) = (Vec3A::from(o), Vec3A::from(d));
            let mut best = None;
            let mut tmax = tmax;
            for (i, tri) in self.tris.iter().enumerate() {
                if let Some((t, u, v)) = intersect_triangle(tri, o, d, tmin, tmax) {
                    tmax = t;
                    best = Some((i, u, v));
                }
            }
            return best.map(|(i, u, v)| self.hit(i, tmax, u, v));
        }
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is only set where `avx2_available()`.
            return unsafe { self.closest_avx2(trav, o, d, tmin, tmax) };
        }
        match self.prefetch {
            true => self.closest::<false, true>(trav, o, d, tmin, tmax),
            false => self.closest::<false, false>(trav, o, d, tmin, tmax),
        }
    }

    /// [`Accel::closest`] compiled for AVX2 and the bit instructions the traversal counts with.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
    unsafe fn closest_avx2(
        &self,
        trav: &mut Traversal,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> Option<Hit> {
        match self.prefetch {
            true => self.closest::<true, true>(trav, o, d, tmin, tmax),
            false => self.closest::<true, false>(trav, o, d, tmin, tmax),
        }
    }

    /// The BVH part of [`Accel::intersect_with`].
    #[inline(always)]
    fn closest<const AVX2: bool, const PREFETCH: bool>(
        &self,
        trav: &mut Traversal,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> Option<Hit> {
        // obvhs' closest-hit traversal (its `ray_traverse`), on the reused state.
        let mut ray = BvhRay::new(o.into(), positive_zeros(d).into(), tmin, tmax);
        let (mut best, mut bu, mut bv) = (usize::MAX, 0.0, 0.0);
        trav.reinit(ray.direction);
        let mut node;
        obvhs::traverse!(
            self.bvh,
            node,
            trav,
            {
                let hits = node_hits::<AVX2>(node, &ray, trav.oct_inv4);
                if PREFETCH {
                    prefetch_hits(&self.bvh, &self.tris, node, hits, trav.oct_inv4);
                }
                hits
            },
            {
                let id = trav.primitive_id as usize;
                let tri = &self.tris[id];
                if let Some((t, u, v)) =
                    intersect_triangle(tri, ray.origin, ray.direction, ray.tmin, ray.tmax)
                {
                    (best, bu, bv) = (id, u, v);
                    ray.tmax = t;
                }
            }
        );
        (best != usize::MAX).then(|| self.hit(best, ray.tmax, bu, bv))
    }

    /// The hit record of stored triangle `i` at `(t, u, v)`.
    #[inline]
    fn hit(&self, i: usize, t: f32, u: f32, v: f32) -> Hit {
        let tri = &self.tris[i];
        Hit {
            t,
            key: self.keys[i],
            u,
            v,
            p: (tri.v0 + tri.e1 * u + tri.e2 * v).into(),
            ng: tri.e1.cross(tri.e2).into(),
            instance: NO_INSTANCE,
        }
    }

    /// True when any triangle lies on the ray with `t` in `(tmin, tmax)`.
    pub fn occluded(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> bool {
        self.occluded_with(&mut Traversal::default(), o, d, tmin, tmax)
    }

    /// [`Accel::occluded`] with the caller's traversal state.
    #[inline]
    pub fn occluded_with(
        &self,
        trav: &mut Traversal,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> bool {
        if self.tris.is_empty() {
            return false;
        }
        if self.tris.len() <= BRUTE_FORCE {
            let (o, d) = (Vec3A::from(o), Vec3A::from(d));
            return (self.tris.iter()).any(|t| intersect_triangle(t, o, d, tmin, tmax).is_some());
        }
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is only set where `avx2_available()`.
            return unsafe { self.any_hit_avx2(trav, o, d, tmin, tmax) };
        }
        match self.prefetch {
            true => self.any_hit::<false, true>(trav, o, d, tmin, tmax),
            false => self.any_hit::<false, false>(trav, o, d, tmin, tmax),
        }
    }

    /// [`Accel::any_hit`] compiled for AVX2 and the bit instructions the traversal counts with.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
    unsafe fn any_hit_avx2(
        &self,
        trav: &mut Traversal,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> bool {
        match self.prefetch {
            true => self.any_hit::<true, true>(trav, o, d, tmin, tmax),
            false => self.any_hit::<true, false>(trav, o, d, tmin, tmax),
        }
    }

    /// The BVH part of [`Accel::occluded_with`].
    #[inline(always)]
    fn any_hit<const AVX2: bool, const PREFETCH: bool>(
        &self,
        trav: &mut Traversal,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> bool {
        // obvhs' any-hit traversal (its `ray_traverse_miss`), on the reused state.
        let ray = BvhRay::new(o.into(), positive_zeros(d).into(), tmin, tmax);
        trav.reinit(ray.direction);
        let mut node;
        let mut hit = false;
        'found: {
            obvhs::traverse!(
                self.bvh,
                node,
                trav,
                {
                    let hits = node_hits::<AVX2>(node, &ray, trav.oct_inv4);
                    if PREFETCH {
                        prefetch_hits(&self.bvh, &self.tris, node, hits, trav.oct_inv4);
                    }
                    hits
                },
                {
                    let tri = &self.tris[trav.primitive_id as usize];
                    if intersect_triangle(tri, ray.origin, ray.direction, ray.tmin, ray.tmax)
                        .is_some()
                    {
                        hit = true;
                        break 'found;
                    }
                }
            );
        }
        hit
    }
}

/// Replaces `-0.0` components by `+0.0`: obvhs takes the traversal octant from the sign test
/// `< 0` but inverts `-0.0` to `-1/ε`, so a direction with a negative zero misses everything.
#[inline(always)]
pub(crate) fn positive_zeros(d: Vec3) -> Vec3 {
    d + Vec3::ZERO
}

/// Moves a surface point off its surface along the geometric normal `ng` to the side of `w`,
/// by a distance proportional to the point's magnitude (the rounding error of its coordinates),
/// so a ray leaving from it does not hit the same surface again.
#[inline]
pub fn offset_origin(p: Vec3, ng: Vec3, w: Vec3) -> Vec3 {
    let scale = 1e-4 * (1.0 + p.abs().max_element());
    let n = if ng.dot(w) >= 0.0 { ng } else { -ng };
    p + n * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The BVH over `tris` as given (a few triangles: tested one by one) and with sixteen far
    /// away triangles added (then the CWBVH is traversed).
    fn both(tris: &[[Vec3; 3]]) -> [Accel; 2] {
        let mut padded = tris.to_vec();
        for i in 0..16 {
            let c = Vec3::new(1000.0 + i as f32, 1000.0, 0.0);
            padded.push([c, c + Vec3::X, c + Vec3::Y]);
        }
        let [a, b] = [Accel::build(tris), Accel::build(&padded)];
        assert!(a.tris.len() <= BRUTE_FORCE && b.tris.len() > BRUTE_FORCE);
        [a, b]
    }

    /// A reproducible stream of numbers uniform in `[-1, 1)` (an LCG seeded with `state`).
    fn uniform(mut state: u64) -> impl FnMut() -> f32 {
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        }
    }

    fn quad(z: f32) -> Vec<[Vec3; 3]> {
        let a = Vec3::new(-1.0, -1.0, z);
        let b = Vec3::new(1.0, -1.0, z);
        let c = Vec3::new(1.0, 1.0, z);
        let d = Vec3::new(-1.0, 1.0, z);
        vec![[a, b, c], [a, c, d]]
    }

    #[test]
    fn closest_hit_and_occlusion() {
        let mut tris = quad(0.0);
        tris.extend(quad(-2.0));
        for accel in both(&tris) {
            let h = accel
                .intersect(Vec3::new(0.2, 0.3, 5.0), -Vec3::Z, 0.0, f32::INFINITY)
                .unwrap();
            assert!((h.t - 5.0).abs() < 1e-5);
            assert!(h.key[1] < 2, "nearest quad is the first one");
            assert!(accel.occluded(Vec3::new(0.2, 0.3, 5.0), -Vec3::Z, 0.0, 6.0));
            assert!(!accel.occluded(Vec3::new(0.2, 0.3, 5.0), -Vec3::Z, 0.0, 4.9));
            assert!(
                accel
                    .intersect(Vec3::new(3.0, 0.0, 5.0), -Vec3::Z, 0.0, f32::INFINITY)
                    .is_none()
            );
        }
    }

    #[test]
    fn shared_edge_has_no_gap() {
        // Rays through the diagonal shared by the two triangles must hit one of them.
        for accel in both(&quad(0.0)) {
            for i in 0..1000 {
                let s = -0.99 + 1.98 * i as f32 / 999.0;
                let o = Vec3::new(s, s, 1.0);
                assert!(
                    accel.intersect(o, -Vec3::Z, 0.0, 10.0).is_some(),
                    "gap at {s}"
                );
            }
        }
    }

    #[test]
    fn negative_zero_direction_components_hit() {
        for accel in both(&quad(0.0)) {
            for d in [
                Vec3::new(-0.0, 0.0, -1.0),
                Vec3::new(0.0, -0.0, -1.0),
                Vec3::new(-0.0, -0.0, -1.0),
            ] {
                assert!(
                    accel
                        .intersect(Vec3::new(0.3, 0.2, 1.0), d, 0.0, 10.0)
                        .is_some()
                );
                assert!(accel.occluded(Vec3::new(0.3, 0.2, 1.0), d, 0.0, 10.0));
            }
        }
    }

    #[test]
    fn triangles_beyond_the_coordinate_limit_are_left_out() {
        // Surface areas beyond f32::MAX once made the CWBVH conversion panic.
        let mut tris = quad(0.0);
        for e in [19.5f32, 25.0, 38.0] {
            let x = 10f32.powf(e);
            tris.push([Vec3::ZERO, Vec3::new(x, 0.0, 0.0), Vec3::new(0.0, x, 0.0)]);
        }
        tris.push([Vec3::ZERO, Vec3::INFINITY, Vec3::NAN]);
        for accel in both(&tris) {
            let h = accel
                .intersect(Vec3::new(0.5, 0.5, 1.0), -Vec3::Z, 0.0, f32::INFINITY)
                .unwrap();
            assert!(h.key[1] < 2 && (h.t - 1.0).abs() < 1e-6);
            assert!(
                accel
                    .intersect(Vec3::new(5.0, 5.0, 1.0), -Vec3::Z, 0.0, f32::INFINITY)
                    .is_none()
            );
        }
    }

    #[test]
    fn barycentrics_locate_the_hit() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        for accel in both(&[tri]) {
            let h = accel
                .intersect(Vec3::new(0.25, 0.5, 1.0), -Vec3::Z, 0.0, 10.0)
                .unwrap();
            assert!((h.u - 0.25).abs() < 1e-6 && (h.v - 0.5).abs() < 1e-6);
            assert!((h.p - Vec3::new(0.25, 0.5, 0.0)).length() < 1e-6);
            assert_eq!(h.ng, Vec3::Z);
            assert_eq!(h.key, [0, 0]);
        }
    }

    #[test]
    fn testing_each_triangle_agrees_with_the_bvh() {
        // Eight random triangles, random rays: the same closest hits and occlusion either way.
        let mut rnd = uniform(0x853c_49e6_748f_ea9bu64);
        let mut v = move || Vec3::new(rnd(), rnd(), rnd());
        let tris: Vec<[Vec3; 3]> = (0..8).map(|_| [v(), v(), v()]).collect();
        let [small, big] = both(&tris);
        let mut hits = 0;
        for _ in 0..20_000 {
            let o = v() * 3.0;
            let d = (v() - o * 0.3).normalize();
            let tmax = 3.0 + 2.0 * v().x;
            let (a, b) = (
                small.intersect(o, d, 0.0, tmax),
                big.intersect(o, d, 0.0, tmax),
            );
            assert_eq!(a.map(|h| (h.t, h.key)), b.map(|h| (h.t, h.key)));
            assert_eq!(
                small.occluded(o, d, 0.0, tmax),
                big.occluded(o, d, 0.0, tmax)
            );
            hits += a.is_some() as u32;
        }
        assert!(hits > 1000, "{hits} hits");
    }

    #[test]
    fn avx2_node_test_traverses_as_the_portable_one() {
        // Two thousand random small triangles (a deep CWBVH with leaves of several
        // triangles), rays from everywhere including axis-parallel and negative directions:
        // the AVX2 traversal returns the same hits, to the bit, as obvhs' SSE2 one.
        if !avx2_available() {
            eprintln!("no AVX2 on this CPU: only the portable traversal runs");
            return;
        }
        let mut rnd = uniform(0x2545_f491_4f6c_dd1du64);
        let tris: Vec<[Vec3; 3]> = (0..2000)
            .map(|_| {
                let c = Vec3::new(rnd(), rnd(), rnd()) * 4.0;
                let mut e = || Vec3::new(rnd(), rnd(), rnd()) * 0.3;
                [c, c + e(), c + e()]
            })
            .collect();
        let fast = Accel::build(&tris);
        assert!(fast.avx2);
        let slow = Accel::build(&tris).portable();
        let (mut hits, mut blocked) = (0, 0);
        for i in 0..40_000 {
            let o = Vec3::new(rnd(), rnd(), rnd()) * 6.0;
            let mut d = Vec3::new(rnd(), rnd(), rnd());
            if i % 7 == 0 {
                d *= Vec3::new(1.0, 0.0, (i % 2) as f32); // axis-parallel, zero components
            }
            let Some(d) = d.try_normalize() else { continue };
            let tmax = if i % 3 == 0 {
                f32::INFINITY
            } else {
                2.0 + 6.0 * rnd().abs()
            };
            let (a, b) = (
                fast.intersect(o, d, 0.0, tmax),
                slow.intersect(o, d, 0.0, tmax),
            );
            assert_eq!(
                a.map(|h| (h.t.to_bits(), h.key, h.u.to_bits(), h.v.to_bits())),
                b.map(|h| (h.t.to_bits(), h.key, h.u.to_bits(), h.v.to_bits()))
            );
            let (p, q) = (
                fast.occluded(o, d, 0.0, tmax),
                slow.occluded(o, d, 0.0, tmax),
            );
            assert_eq!(p, q);
            hits += a.is_some() as u32;
            blocked += p as u32;
        }
        assert!(
            hits > 2000 && blocked >= hits,
            "{hits} hits, {blocked} occluded"
        );
    }

    #[test]
    fn prefetching_traversal_finds_the_same_hits() {
        // Thirty thousand triangles (1.4 MB with the nodes: above the prefetch size) in a
        // cube, rays from inside and outside it: closest and any hits are the same, to the
        // bit, with and without prefetching, for the AVX2 and the portable node test.
        let mut rnd = uniform(0x9e37_79b9_7f4a_7c15u64);
        let tris: Vec<[Vec3; 3]> = (0..30_000)
            .map(|_| {
                let c = Vec3::new(rnd(), rnd(), rnd()) * 4.0;
                let mut e = || Vec3::new(rnd(), rnd(), rnd()) * 0.2;
                [c, c + e(), c + e()]
            })
            .collect();
        let with = Accel::build(&tris);
        assert!(
            with.prefetch,
            "30,000 triangles are traversed with prefetching"
        );
        let variants = [
            with,
            Accel {
                prefetch: false,
                ..Accel::build(&tris)
            },
            Accel::build(&tris).portable(),
            Accel {
                prefetch: false,
                ..Accel::build(&tris).portable()
            },
        ];
        let key = |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.key, h.u.to_bits(), h.v.to_bits()));
        let (mut hits, mut blocked) = (0, 0);
        for _ in 0..20_000 {
            let o = Vec3::new(rnd(), rnd(), rnd()) * 6.0;
            let Some(d) = Vec3::new(rnd(), rnd(), rnd()).try_normalize() else {
                continue;
            };
            let tmax = 1.0 + 8.0 * rnd().abs();
            let first = key(variants[0].intersect(o, d, 0.0, tmax));
            let occluded = variants[0].occluded(o, d, 0.0, tmax);
            for v in &variants[1..] {
                assert_eq!(key(v.intersect(o, d, 0.0, tmax)), first);
                assert_eq!(v.occluded(o, d, 0.0, tmax), occluded);
            }
            hits += first.is_some() as u32;
            blocked += occluded as u32;
        }
        assert!(
            hits > 5000 && blocked >= hits,
            "{hits} hits, {blocked} occluded"
        );
    }
}
