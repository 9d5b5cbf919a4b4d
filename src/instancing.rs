//! Two-level ray queries over instances: a top-level BVH (obvhs CWBVH) over the instances'
//! world bounds, and one bottom-level [`Accel`] per mesh in the mesh's object space, shared by
//! every instance of it.
//!
//! A ray `o + t d` (world space) enters instance `M` as `M⁻¹o + t M⁻¹d`: the object-space
//! direction is not renormalised, so the ray parameter `t` means the same point in both spaces
//! and the closest hit's `t` bounds the search in every later instance. Hits come back in world
//! space: `p_w = M p_o`, the geometric normal through `M⁻ᵀ` (see [`crate::scene::instance`]).
//!
//! A moving instance ([`crate::motion`]) has its top-level bound around its whole path over
//! the shutter, and a ray of time `time` enters it through the transform interpolated at
//! that time.

use crate::accel::{Accel, BRUTE_FORCE, Hit, Traversal, positive_zeros};
use crate::motion::TransformMotion;
use crate::scene::{Instance, Scene};
use glam::{Affine3A, Mat3A, UVec2, Vec3, Vec3A};
use obvhs::{
    BvhBuildParams, aabb::Aabb, cwbvh::CwBvh, cwbvh::builder::build_cwbvh, ray::Ray as BvhRay,
};
use std::time::Duration;

/// An instance as the traversal needs it.
#[derive(Clone, Copy, Debug)]
struct Placement {
    /// World → object.
    from_world: Affine3A,
    /// Object → world.
    to_world: Affine3A,
    /// Object → world for normals (`M⁻ᵀ`).
    normal: Mat3A,
    /// Index into [`InstanceAccel::blas`].
    blas: u32,
    /// Index into [`Scene::instances`].
    instance: u32,
    /// Index into [`InstanceAccel::motions`], or [`STILL`].
    motion: u32,
}

/// [`Placement::motion`] of an instance that does not move.
const STILL: u32 = u32::MAX;

impl Placement {
    /// The placement at shutter time `time`: itself when it does not move.
    #[inline(always)]
    fn at(&self, motions: &[std::sync::Arc<TransformMotion>], time: f32) -> Placement {
        if self.motion == STILL {
            return *self;
        }
        let to_world = motions[self.motion as usize].affine_at(time);
        Placement {
            from_world: to_world.inverse(),
            to_world,
            normal: to_world.matrix3.inverse().transpose(),
            ..*self
        }
    }
}

/// The instances of a scene, ready for ray queries.
pub struct InstanceAccel {
    tlas: CwBvh,
    /// In the top-level BVH's leaf order.
    placements: Vec<Placement>,
    blas: Vec<Accel>,
    /// The mesh each bottom level was built from.
    blas_mesh: Vec<usize>,
    /// The motions of the moving instances.
    motions: Vec<std::sync::Arc<TransformMotion>>,
}

impl InstanceAccel {
    /// The BVHs over `scene.instances` whose `keep(instance index)` holds, or `None` when no
    /// instance is kept. Instances that cannot be drawn (a missing mesh or material, a
    /// singular or non-finite transform) are left out. Bottom-level hits carry the key `[mesh index, triangle index]`.
    pub fn new(scene: &Scene, keep: impl Fn(usize) -> bool) -> Option<InstanceAccel> {
        Self::reusing(scene, keep, None, &[])
    }

    /// [`InstanceAccel::new`] taking the bottom levels of `old` for the meshes it has, except
    /// those `changed` lists (their triangles are new): after instances moved or a mesh was
    /// replaced, only the top level and the new meshes' levels are built.
    pub fn rebuilt(
        scene: &Scene,
        old: Option<InstanceAccel>,
        changed: &[usize],
    ) -> Option<InstanceAccel> {
        Self::reusing(scene, |_| true, old, changed)
    }

    fn reusing(
        scene: &Scene,
        keep: impl Fn(usize) -> bool,
        old: Option<InstanceAccel>,
        changed: &[usize],
    ) -> Option<InstanceAccel> {
        let mut reuse: std::collections::HashMap<usize, Accel> = old
            .map(|o| o.blas_mesh.into_iter().zip(o.blas).collect())
            .unwrap_or_default();
        for m in changed {
            reuse.remove(m);
        }
        let mut blas_mesh = Vec::new();
        let mut blas_of = vec![u32::MAX; scene.meshes.len()];
        let mut blas = Vec::new();
        let mut bounds = Vec::new();
        let mut placements = Vec::new();
        let mut motions = Vec::new();
        for (ii, inst) in scene.instances.iter().enumerate() {
            let Some(mesh) = scene.meshes.get(inst.mesh) else {
                continue;
            };
            let bad_material = inst.material.is_some_and(|m| m >= scene.materials.len());
            if !keep(ii)
                || mesh.indices.is_empty()
                || bad_material
                || Instance::check(&inst.to_world).is_some()
            {
                continue;
            }
            let Some((lo, hi)) = mesh.bounds() else {
                continue;
            };
            if blas_of[inst.mesh] == u32::MAX {
                blas_of[inst.mesh] = blas.len() as u32;
                blas_mesh.push(inst.mesh);
                let mi = inst.mesh as u32;
                blas.push(reuse.remove(&inst.mesh).unwrap_or_else(|| {
                    let tris = (mesh.indices.iter()).map(|t| t.map(|i| mesh.positions[i as usize]));
                    let keys = (0..mesh.indices.len() as u32).map(|ti| [mi, ti]);
                    Accel::build_from(mesh.indices.len(), tris, keys)
                }));
            }
            let (lo, hi) = match &inst.motion {
                Some(m) => m.bounds(lo, hi),
                None => crate::scene::instance::transform_bounds(&inst.to_world, lo, hi),
            };
            if !(lo.is_finite() && hi.is_finite()) {
                continue;
            }
            let to_world = Affine3A::from_mat4(inst.to_world);
            bounds.push(Aabb::new(lo.into(), hi.into()));
            let motion = match &inst.motion {
                Some(m) => {
                    motions.push(m.clone());
                    motions.len() as u32 - 1
                }
                None => STILL,
            };
            placements.push(Placement {
                from_world: to_world.inverse(),
                to_world,
                normal: to_world.matrix3.inverse().transpose(),
                blas: blas_of[inst.mesh],
                instance: ii as u32,
                motion,
            });
        }
        if placements.is_empty() {
            return None;
        }
        let tlas = if placements.len() <= BRUTE_FORCE {
            CwBvh::default()
        } else {
            let mut t = Duration::ZERO;
            let tlas = build_cwbvh(&bounds, BvhBuildParams::medium_build(), &mut t);
            placements = (tlas.primitive_indices.iter())
                .map(|&i| placements[i as usize])
                .collect();
            tlas
        };
        Some(InstanceAccel {
            tlas,
            placements,
            blas,
            blas_mesh,
            motions,
        })
    }

    /// Triangles over all instances (each instance counting its mesh's).
    pub fn triangles(&self) -> u64 {
        (self.placements.iter())
            .map(|p| self.blas[p.blas as usize].len() as u64)
            .sum()
    }

    /// Number of instances.
    pub fn len(&self) -> usize {
        self.placements.len()
    }

    /// Whether there is no instance (never: [`InstanceAccel::new`] returns `None` then).
    pub fn is_empty(&self) -> bool {
        self.placements.is_empty()
    }

    /// Whether some instance moves over the shutter.
    pub fn has_motion(&self) -> bool {
        !self.motions.is_empty()
    }

    /// The world ray in placement `pl`'s object space at shutter time `time`.
    #[inline(always)]
    fn enter(&self, pl: &Placement, o: Vec3A, d: Vec3A, time: f32) -> (Vec3A, Vec3A) {
        if pl.motion == STILL {
            return (
                pl.from_world.transform_point3a(o),
                pl.from_world.transform_vector3a(d),
            );
        }
        let from_world = self.motions[pl.motion as usize].affine_at(time).inverse();
        (
            from_world.transform_point3a(o),
            from_world.transform_vector3a(d),
        )
    }

    /// The closest hit of placement `pl` along the world ray, object-space record.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn hit_in(
        &self,
        pl: &Placement,
        bottom: &mut Traversal,
        o: Vec3A,
        d: Vec3A,
        tmin: f32,
        tmax: f32,
        time: f32,
    ) -> Option<Hit> {
        let (oo, dd) = self.enter(pl, o, d, time);
        self.blas[pl.blas as usize].intersect_with(bottom, oo.into(), dd.into(), tmin, tmax)
    }

    /// The world-space record of `h`, an object-space hit in placement `pl`.
    #[inline(always)]
    fn to_world(pl: &Placement, mut h: Hit) -> Hit {
        h.p = pl.to_world.transform_point3(h.p);
        h.ng = Vec3::from(pl.normal * Vec3A::from(h.ng));
        h.instance = pl.instance;
        h
    }

    /// Closest hit of the world ray `o + t d` with `t` in `(tmin, tmax)` at shutter time
    /// `time`; `top` and `bottom` are the two levels' traversal states.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn intersect_with(
        &self,
        top: &mut Traversal,
        bottom: &mut Traversal,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
        time: f32,
    ) -> Option<Hit> {
        let (oa, da) = (Vec3A::from(o), Vec3A::from(d));
        let mut best: Option<(Hit, usize)> = None;
        if self.placements.len() <= BRUTE_FORCE {
            let mut tmax = tmax;
            for (i, pl) in self.placements.iter().enumerate() {
                if let Some(h) = self.hit_in(pl, bottom, oa, da, tmin, tmax, time) {
                    tmax = h.t;
                    best = Some((h, i));
                }
            }
        } else {
            let mut ray = BvhRay::new(oa, positive_zeros(d).into(), tmin, tmax);
            top.reinit(ray.direction);
            let mut node;
            obvhs::traverse!(
                self.tlas,
                node,
                top,
                node.intersect_ray(&ray, top.oct_inv4),
                {
                    let i = top.primitive_id as usize;
                    let pl = &self.placements[i];
                    if let Some(h) = self.hit_in(pl, bottom, oa, da, ray.tmin, ray.tmax, time) {
                        ray.tmax = h.t;
                        best = Some((h, i));
                    }
                }
            );
        }
        best.map(|(h, i)| {
            let pl = &self.placements[i];
            if pl.motion == STILL {
                Self::to_world(pl, h)
            } else {
                Self::to_world(&pl.at(&self.motions, time), h)
            }
        })
    }

    /// True when some instance's triangle lies on the ray with `t` in `(tmin, tmax)` at
    /// shutter time `time`.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn occluded_with(
        &self,
        top: &mut Traversal,
        bottom: &mut Traversal,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
        time: f32,
    ) -> bool {
        let (oa, da) = (Vec3A::from(o), Vec3A::from(d));
        let blocks = |pl: &Placement, bottom: &mut Traversal| {
            let (oo, dd) = self.enter(pl, oa, da, time);
            self.blas[pl.blas as usize].occluded_with(bottom, oo.into(), dd.into(), tmin, tmax)
        };
        if self.placements.len() <= BRUTE_FORCE {
            return self.placements.iter().any(|pl| blocks(pl, bottom));
        }
        let ray = BvhRay::new(oa, positive_zeros(d).into(), tmin, tmax);
        top.reinit(ray.direction);
        let mut node;
        let mut hit = false;
        'found: {
            obvhs::traverse!(
                self.tlas,
                node,
                top,
                node.intersect_ray(&ray, top.oct_inv4),
                {
                    if blocks(&self.placements[top.primitive_id as usize], bottom) {
                        hit = true;
                        break 'found;
                    }
                }
            );
        }
        hit
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Mesh, ObjectInfo};
    use glam::{Mat4, Quat};

    fn lcg(state: &mut u64) -> f32 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*state >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    }

    /// A small random mesh (a dozen triangles around the origin).
    fn blob(state: &mut u64) -> Mesh {
        let mut v = || Vec3::new(lcg(state), lcg(state), lcg(state));
        let positions: Vec<Vec3> = (0..36).map(|_| v()).collect();
        Mesh {
            indices: (0..12).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect(),
            positions,
            ..Default::default()
        }
    }

    /// Random placements of one mesh (some mirrored) traced through the two levels agree with
    /// the same placements baked into world space in one BVH: the same closest triangle, `t`,
    /// point and (normalised) geometric normal, the same occlusion.
    fn agrees_with_baking(count: usize) {
        let mut state = 0x9e37_79b9_7f4a_7c15u64 ^ count as u64;
        let mut scene = Scene {
            meshes: vec![blob(&mut state)],
            ..Default::default()
        };
        for k in 0..count {
            let s = Vec3::new(
                0.3 + lcg(&mut state).abs(),
                0.3 + lcg(&mut state).abs(),
                0.3 + lcg(&mut state).abs(),
            ) * if k % 3 == 0 { -1.0 } else { 1.0 };
            let r = Quat::from_euler(
                glam::EulerRot::XYZ,
                lcg(&mut state) * 3.0,
                lcg(&mut state) * 3.0,
                lcg(&mut state) * 3.0,
            );
            let t = Vec3::new(lcg(&mut state), lcg(&mut state), lcg(&mut state)) * 6.0;
            scene.instances.push(Instance {
                motion: None,
                mesh: 0,
                to_world: Mat4::from_scale_rotation_translation(s, r, t),
                material: None,
                object: ObjectInfo::default(),
            });
        }
        let two_level = InstanceAccel::new(&scene, |_| true).unwrap();
        let baked: Vec<Mesh> = (scene.instances.iter())
            .map(|i| scene.meshes[0].placed(i))
            .collect();
        let tris = baked
            .iter()
            .flat_map(|m| (m.indices.iter()).map(|t| t.map(|i| m.positions[i as usize])));
        let keys = (0..count as u32).flat_map(|k| (0..12u32).map(move |t| [k, t]));
        let flat = Accel::build_from(count * 12, tris, keys);
        let (mut top, mut bottom) = (Traversal::default(), Traversal::default());
        let (mut hits, mut mismatches) = (0, 0);
        for _ in 0..20_000 {
            let o = Vec3::new(lcg(&mut state), lcg(&mut state), lcg(&mut state)) * 10.0;
            // Towards a random instance's origin, give or take its size.
            let k = ((lcg(&mut state) * 0.5 + 0.5) * count as f32) as usize;
            let centre = scene.instances[k.min(count - 1)].to_world.w_axis.truncate();
            let target = centre + Vec3::new(lcg(&mut state), lcg(&mut state), lcg(&mut state));
            let d = (target - o).normalize();
            let tmax = if lcg(&mut state) > 0.0 {
                f32::INFINITY
            } else {
                8.0
            };
            let a = two_level.intersect_with(&mut top, &mut bottom, o, d, 0.0, tmax, 0.5);
            let b = flat.intersect(o, d, 0.0, tmax);
            match (a, b) {
                (Some(a), Some(b)) => {
                    hits += 1;
                    assert_eq!((a.instance, a.key[1]), (b.key[0], b.key[1]));
                    assert!((a.t - b.t).abs() < 1e-4 * (1.0 + b.t), "{} {}", a.t, b.t);
                    assert!((a.p - b.p).length() < 1e-3, "{} {}", a.p, b.p);
                    let (na, nb) = (a.ng.normalize(), b.ng.normalize());
                    assert!(na.dot(nb) > 0.999, "normals {na} {nb}");
                }
                (None, None) => {}
                // A ray grazing an edge may meet it in one space and not in the other.
                _ => mismatches += 1,
            }
            assert_eq!(
                two_level.occluded_with(&mut top, &mut bottom, o, d, 0.0, tmax, 0.5),
                a.is_some(),
                "occlusion agrees with the closest hit"
            );
        }
        assert!(mismatches <= 5, "{mismatches} rays disagree");
        assert!(hits > 2000, "{hits} hits");
    }

    /// A unit box moving along +x from x = -3 at time 0 to x = +3 at time 1 (and a still box
    /// far away, so the traversal has a top level to go through): a ray down -z at x = c
    /// meets it only at the times when the box covers c, with the box's top at z = 0.5.
    fn moving_box_hit_at_the_right_times(extra_still: usize) {
        let mut state = 7u64;
        let mut cube = blob(&mut state);
        // An axis-aligned cube of side 1 around the origin, as 12 triangles.
        let c = |x: f32, y: f32, z: f32| Vec3::new(x - 0.5, y - 0.5, z - 0.5);
        cube.positions = (0..8)
            .map(|k| c((k & 1) as f32, ((k >> 1) & 1) as f32, ((k >> 2) & 1) as f32))
            .collect();
        cube.indices = vec![
            [0, 1, 3],
            [0, 3, 2],
            [4, 6, 7],
            [4, 7, 5],
            [0, 4, 5],
            [0, 5, 1],
            [2, 3, 7],
            [2, 7, 6],
            [0, 2, 6],
            [0, 6, 4],
            [1, 5, 7],
            [1, 7, 3],
        ];
        let keys = [
            (0.0, Mat4::from_translation(Vec3::new(-3.0, 0.0, 0.0))),
            (0.5, Mat4::IDENTITY),
            (1.0, Mat4::from_translation(Vec3::new(3.0, 0.0, 0.0))),
        ];
        let motion = std::sync::Arc::new(TransformMotion::new(&keys).unwrap());
        let mut scene = Scene {
            meshes: vec![cube],
            ..Default::default()
        };
        scene.instances.push(Instance {
            motion: Some(motion),
            mesh: 0,
            to_world: Mat4::IDENTITY,
            material: None,
            object: ObjectInfo::default(),
        });
        for k in 0..extra_still {
            scene.instances.push(Instance {
                motion: None,
                mesh: 0,
                to_world: Mat4::from_translation(Vec3::new(50.0 + 2.0 * k as f32, 0.0, 0.0)),
                material: None,
                object: ObjectInfo::default(),
            });
        }
        let accel = InstanceAccel::new(&scene, |_| true).unwrap();
        assert!(accel.has_motion());
        let (mut top, mut bottom) = (Traversal::default(), Traversal::default());
        let d = Vec3::new(0.0, 0.0, -1.0);
        for xi in -6..=6 {
            let x = xi as f32 * 0.5 + 0.01;
            let o = Vec3::new(x, 0.1, 5.0);
            for ti in 0..=100 {
                let time = ti as f32 / 100.0;
                let centre = -3.0 + 6.0 * time;
                let want = (x - centre).abs() < 0.5;
                // Grazing the box's sides is left out.
                if ((x - centre).abs() - 0.5).abs() < 1e-3 {
                    continue;
                }
                let hit = accel.intersect_with(&mut top, &mut bottom, o, d, 0.0, 100.0, time);
                assert_eq!(hit.is_some(), want, "x {x} time {time}");
                if let Some(h) = hit {
                    assert!(
                        (h.t - 4.5).abs() < 1e-4 && (h.p.z - 0.5).abs() < 1e-4,
                        "{h:?}"
                    );
                    assert!(h.ng.normalize().dot(Vec3::Z).abs() > 0.999);
                }
                let blocked = accel.occluded_with(&mut top, &mut bottom, o, d, 0.0, 100.0, time);
                assert_eq!(blocked, want, "occlusion at x {x} time {time}");
            }
        }
    }

    #[test]
    fn moving_box_is_hit_only_at_the_right_times() {
        moving_box_hit_at_the_right_times(0);
        moving_box_hit_at_the_right_times(BRUTE_FORCE + 4);
    }

    #[test]
    fn few_instances_agree_with_baking() {
        agrees_with_baking(5);
    }

    #[test]
    fn many_instances_agree_with_baking() {
        agrees_with_baking(300);
    }
}
