//! Instances: one mesh, stored once in its object space, placed many times.
//!
//! An instance maps its mesh's object space to world space by an affine `to_world`
//! (positions `p_w = M p_o`). Normals go through the inverse transpose of the linear part
//! (`n_w ∝ M⁻ᵀ n_o`), which keeps the object's front side in front under a mirroring
//! (negative determinant) transform, as baking a mirrored glTF node does by reversing the
//! winding. Tangents go through `M` and their bitangent sign flips with the determinant's.

use super::{Mesh, ObjectInfo};
use glam::{Mat3, Mat4, Vec3, Vec4};

/// Smallest `|det|` of an instance's linear part (a placement squashed flatter than this is
/// singular: its normals and the inverse ray transform are undefined).
pub const MIN_DETERMINANT: f32 = 1e-30;

/// One placement of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// Index into [`super::Scene::meshes`] (a mesh in object space).
    pub mesh: usize,
    /// Object → world (affine, finite, invertible: see [`Instance::check`]).
    pub to_world: Mat4,
    /// Index into [`super::Scene::materials`] replacing the mesh's material.
    pub material: Option<usize>,
    /// Blender's Object Info of this instance (its own random number and location).
    pub object: ObjectInfo,
    /// Object → world over the shutter (motion blur), or `None` for a still instance
    /// (`to_world` is then its transform at every time). A moving instance's `to_world` is
    /// its transform at the frame's instant, which shading reads.
    pub motion: Option<std::sync::Arc<crate::motion::TransformMotion>>,
}

impl Instance {
    /// Why `to_world` cannot place a mesh (not finite, not affine, singular), or `None`.
    pub fn check(to_world: &Mat4) -> Option<&'static str> {
        if !to_world.is_finite() {
            return Some("its transform is not finite");
        }
        if to_world.row(3) != Vec4::W {
            return Some("its transform is not affine (last row is not 0 0 0 1)");
        }
        let det = Mat3::from_mat4(*to_world).determinant();
        if !(det.abs() >= MIN_DETERMINANT && det.is_finite()) {
            return Some("its transform is singular (zero scale)");
        }
        None
    }

    /// The matrix normals go through (inverse transpose of the linear part).
    pub fn normal_matrix(&self) -> Mat3 {
        Mat3::from_mat4(self.to_world).inverse().transpose()
    }

    /// Object → world at shutter time `time` (see [`crate::motion`]).
    #[inline]
    pub fn to_world_at(&self, time: f32) -> Mat4 {
        match &self.motion {
            Some(m) => m.at(time),
            None => self.to_world,
        }
    }

    /// [`Instance::normal_matrix`] at shutter time `time`.
    #[inline]
    pub fn normal_matrix_at(&self, time: f32) -> Mat3 {
        match &self.motion {
            Some(m) => Mat3::from_mat4(m.at(time)).inverse().transpose(),
            None => self.normal_matrix(),
        }
    }

    /// Whether the transform mirrors (negative determinant).
    pub fn mirrors(&self) -> bool {
        Mat3::from_mat4(self.to_world).determinant() < 0.0
    }
}

/// World bounds of the box `[lo, hi]` under `m` (the box around its eight transformed corners).
pub fn transform_bounds(m: &Mat4, lo: Vec3, hi: Vec3) -> (Vec3, Vec3) {
    let c = m.transform_point3((lo + hi) * 0.5);
    let e = (hi - lo) * 0.5;
    let l = Mat3::from_mat4(*m);
    let r = l.x_axis.abs() * e.x + l.y_axis.abs() * e.y + l.z_axis.abs() * e.z;
    (c - r, c + r)
}

impl Mesh {
    /// The mesh as `inst` places it, baked into world space: positions, normals and tangents
    /// transformed, the winding reversed under a mirroring transform (so the geometric normal
    /// by the right-hand rule agrees with `M⁻ᵀ n_o`), the instance's material and object data.
    pub fn placed(&self, inst: &Instance) -> Mesh {
        let m = inst.to_world;
        let nm = inst.normal_matrix();
        let l = Mat3::from_mat4(m);
        let flip = inst.mirrors();
        let sign = if flip { -1.0 } else { 1.0 };
        // A normal that vanishes drops them all (the geometric normal is used), as the loader
        // does when baking.
        let normals = (self.normals.iter())
            .map(|n| (nm * *n).try_normalize())
            .collect::<Option<Vec<_>>>()
            .unwrap_or_default();
        let mut attrs = self.attrs.clone();
        attrs.tangents = (self.attrs.tangents.iter())
            .map(|t| {
                let v = (l * t.truncate()).normalize_or_zero();
                v.extend(if t.w < 0.0 { -sign } else { sign })
            })
            .collect();
        attrs.to_object = self.attrs.to_object * m.inverse();
        attrs.object = inst.object.clone();
        Mesh {
            name: self.name.clone(),
            positions: self
                .positions
                .iter()
                .map(|p| m.transform_point3(*p))
                .collect(),
            normals,
            uvs: self.uvs.clone(),
            indices: if flip {
                self.indices.iter().map(|t| [t[0], t[2], t[1]]).collect()
            } else {
                self.indices.clone()
            },
            material: inst.material.unwrap_or(self.material),
            attrs,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn singular_and_non_finite_transforms_are_refused() {
        assert!(Instance::check(&Mat4::IDENTITY).is_none());
        assert!(Instance::check(&Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0))).is_some());
        assert!(Instance::check(&Mat4::from_translation(Vec3::NAN)).is_some());
        let mut m = Mat4::IDENTITY;
        m.x_axis.w = 1.0;
        assert!(Instance::check(&m).is_some());
        assert!(Instance::check(&Mat4::from_scale(Vec3::new(-1.0, 2.0, 3.0))).is_none());
    }

    #[test]
    fn transformed_bounds_contain_every_transformed_corner() {
        let m = Mat4::from_scale_rotation_translation(
            Vec3::new(2.0, -1.0, 0.5),
            Quat::from_euler(glam::EulerRot::XYZ, 0.3, 1.1, -0.7),
            Vec3::new(4.0, 5.0, 6.0),
        );
        let (lo, hi) = (Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.0, 2.5));
        let (tl, th) = transform_bounds(&m, lo, hi);
        let mut touched = [false; 6];
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let p = m.transform_point3(c);
            assert!(p.cmpge(tl - 1e-5).all() && p.cmple(th + 1e-5).all());
            for k in 0..3 {
                touched[k] |= (p[k] - tl[k]).abs() < 1e-4;
                touched[k + 3] |= (p[k] - th[k]).abs() < 1e-4;
            }
        }
        assert!(touched.iter().all(|t| *t), "the box is tight: {touched:?}");
    }

    #[test]
    fn a_mirrored_placement_keeps_the_front_side() {
        let mesh = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: vec![Vec3::Z; 3],
            indices: vec![[0, 1, 2]],
            ..Default::default()
        };
        let inst = Instance {
            motion: None,
            mesh: 0,
            to_world: Mat4::from_scale(Vec3::new(-2.0, 1.0, 1.0)),
            material: None,
            object: ObjectInfo::default(),
        };
        let w = mesh.placed(&inst);
        let [a, b, c] = w.indices[0].map(|i| w.positions[i as usize]);
        let ng = (b - a).cross(c - a);
        assert!(ng.dot(Vec3::Z) > 0.0 && w.normals[0] == Vec3::Z, "{ng}");
        assert!(
            (ng.length() * 0.5 - 1.0).abs() < 1e-6,
            "area scales by |det|"
        );
    }
}
