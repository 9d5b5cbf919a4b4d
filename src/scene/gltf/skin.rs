//! Skinned meshes in the pose their nodes give (glTF's skins, without animation): each vertex
//! is moved by the weighted sum of its joints' matrices, `Σ w_k · J_k` with
//! `J = world(joint) · inverseBindMatrix`, as viewers and Blender's importer show a skinned
//! model at rest. The result is in world space: a skinned mesh's own node transform is not
//! applied (glTF: only the joints place it).

use glam::{Mat3, Mat4, Vec3, Vec4};
use gltf::json;
use json::accessor::Type;
use json::mesh::Semantic;
use json::validation::Checked;
use serde_json::Value;

use super::{LoadError, Loader, invalid, member};

/// The joint matrices of a node's skin, world space.
pub(crate) struct Skinning {
    pub joints: Vec<Mat4>,
    /// Where a vertex without weights stays: the node's own world transform.
    pub unweighted: Mat4,
}

impl Loader<'_> {
    /// The skin of node `ni`, if it has one: its joints' matrices in the pose the nodes give.
    pub(crate) fn skinning(
        &self,
        ni: usize,
        node_world: Mat4,
    ) -> Result<Option<Skinning>, LoadError> {
        let Some(si) = member(self.raw_item("nodes", ni), "skin").and_then(Value::as_u64) else {
            return Ok(None);
        };
        let si = si as usize;
        let skin = self.raw_item("skins", si);
        let Some(joints) = member(skin, "joints").and_then(Value::as_array) else {
            return Err(invalid(format!(
                "node {ni}: skin {si} does not exist or has no `joints` array"
            )));
        };
        let n = self.root.nodes.len();
        let mut world = Vec::with_capacity(joints.len());
        for (k, j) in joints.iter().enumerate() {
            let j = j
                .as_u64()
                .map(|j| j as usize)
                .filter(|&j| j < n)
                .ok_or_else(|| {
                    invalid(format!(
                        "skin {si}: joint {k} is not a node of the file (it has {n})"
                    ))
                })?;
            world.push(
                self.origins
                    .node_world
                    .get(j)
                    .copied()
                    .unwrap_or(Mat4::IDENTITY),
            );
        }
        let inverse_bind = match member(skin, "inverseBindMatrices").and_then(Value::as_u64) {
            Some(ai) => {
                let what = format!("inverseBindMatrices of skin {si}");
                let m = self.reader.read_f32(ai as usize, &what, Type::Mat4)?;
                if m.count < joints.len() {
                    return Err(invalid(format!(
                        "accessor {ai} ({what}): {} matrices for {} joints",
                        m.count,
                        joints.len()
                    )));
                }
                m.data
                    .chunks_exact(16)
                    .map(|c| Mat4::from_cols_slice(c))
                    .collect()
            }
            None => vec![Mat4::IDENTITY; joints.len()],
        };
        let joints: Vec<Mat4> = world
            .iter()
            .zip(&inverse_bind)
            .map(|(w, ib)| *w * *ib)
            .collect();
        if let Some(k) = joints.iter().position(|m| !m.is_finite()) {
            return Err(invalid(format!(
                "skin {si}: joint {k}'s matrix is not finite"
            )));
        }
        Ok(Some(Skinning {
            joints,
            unweighted: node_world,
        }))
    }

    /// Moves a primitive's vertices (and normals, tangents) by skin `s`, from JOINTS_n and
    /// WEIGHTS_n (every set the primitive has). Weights are taken relative to their sum; a
    /// vertex without weight keeps the node's transform.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn skin_vertices(
        &self,
        prim: &json::mesh::Primitive,
        (mi, pi): (usize, usize),
        s: &Skinning,
        positions: &mut [Vec3],
        normals: &mut [Vec3],
        tangents: &mut [Vec4],
    ) -> Result<(), LoadError> {
        let count = positions.len();
        let mut blend = vec![Mat4::ZERO; count];
        let mut total = vec![0.0f32; count];
        for set in 0.. {
            let attr = |sem: Semantic| prim.attributes.get(&Checked::Valid(sem)).map(|a| a.value());
            let (Some(ja), Some(wa)) = (attr(Semantic::Joints(set)), attr(Semantic::Weights(set)))
            else {
                break;
            };
            let what = |a: &str| format!("{a}_{set} of mesh {mi} primitive {pi}");
            let j = self.reader.read_f32(ja, &what("JOINTS"), Type::Vec4)?;
            let w = self.reader.read_f32(wa, &what("WEIGHTS"), Type::Vec4)?;
            if j.count != count || w.count != count {
                return Err(invalid(format!(
                    "mesh {mi} primitive {pi}: JOINTS_{set}/WEIGHTS_{set} have {}/{} elements for {count} vertices",
                    j.count, w.count
                )));
            }
            for v in 0..count {
                for c in 0..4 {
                    let weight = w.data[4 * v + c];
                    if weight == 0.0 {
                        continue;
                    }
                    if !(weight.is_finite() && weight > 0.0) {
                        return Err(invalid(format!(
                            "accessor {wa} ({}): vertex {v} has weight {weight}",
                            what("WEIGHTS")
                        )));
                    }
                    let joint = j.data[4 * v + c];
                    let m = s.joints.get(joint as usize).filter(|_| joint >= 0.0).ok_or_else(|| {
                        invalid(format!(
                            "accessor {ja} ({}): vertex {v} names joint {joint}, the skin has {}",
                            what("JOINTS"),
                            s.joints.len()
                        ))
                    })?;
                    blend[v] += *m * weight;
                    total[v] += weight;
                }
            }
        }
        for v in 0..count {
            let m = if total[v] > 0.0 {
                blend[v] * (1.0 / total[v])
            } else {
                s.unweighted
            };
            positions[v] = m.transform_point3(positions[v]);
            let m3 = Mat3::from_mat4(m);
            if let Some(n) = normals.get_mut(v) {
                let inv_t = m3.inverse().transpose();
                *n = (inv_t * *n).normalize_or_zero();
            }
            if let Some(t) = tangents.get_mut(v) {
                let d = (m3 * t.truncate()).normalize_or_zero();
                *t = d.extend(t.w);
            }
        }
        Ok(())
    }
}
