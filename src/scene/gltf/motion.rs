//! `TESELA_motion`: a node's transform over the shutter (motion blur; docs/extensions.md).
//!
//! `{"times": [t0, t1, ...], "matrices": [[16 numbers, column-major], ...]}`: the node's local
//! matrix at each shutter-normalised time (increasing, within `[0, 1]`); its parents'
//! transforms apply to every key. The node's own `matrix` stays its transform at the frame's
//! instant (what tools that ignore the extension show).

use glam::Mat4;
use serde_json::Value;

use super::{LoadError, Loader, extension, invalid, member, orthonormalize};
use crate::motion::TransformMotion;

impl<'a> Loader<'a> {
    /// The world keys of node `ni` (child of `parent`) over the shutter, or `None` without
    /// `TESELA_motion` or when every key is the same transform.
    pub(crate) fn node_motion(
        &mut self,
        ni: usize,
        parent: Mat4,
    ) -> Result<Option<Vec<(f32, Mat4)>>, LoadError> {
        let Some(ext) = extension(self.raw_item("nodes", ni), "TESELA_motion") else {
            return Ok(None);
        };
        let what = format!("node {ni} TESELA_motion");
        let numbers = |v: Option<&Value>, name: &str| -> Result<Vec<f32>, LoadError> {
            let a = v
                .and_then(Value::as_array)
                .ok_or_else(|| invalid(format!("{what}: `{name}` is missing or not an array")))?;
            a.iter()
                .map(|x| {
                    x.as_f64()
                        .map(|x| x as f32)
                        .ok_or_else(|| invalid(format!("{what}: `{name}` holds {x}, not a number")))
                })
                .collect()
        };
        let times = numbers(member(ext, "times"), "times")?;
        let matrices = member(ext, "matrices")
            .and_then(Value::as_array)
            .ok_or_else(|| invalid(format!("{what}: `matrices` is missing or not an array")))?;
        if matrices.len() != times.len() {
            return Err(invalid(format!(
                "{what}: {} matrices for {} times",
                matrices.len(),
                times.len()
            )));
        }
        let mut keys = Vec::with_capacity(times.len());
        for (k, (t, m)) in times.iter().zip(matrices).enumerate() {
            let m = numbers(Some(m), &format!("matrices[{k}]"))?;
            let cols: [f32; 16] = m.try_into().map_err(|m: Vec<f32>| {
                invalid(format!(
                    "{what}: matrices[{k}] has {} numbers, not 16",
                    m.len()
                ))
            })?;
            keys.push((*t, parent * Mat4::from_cols_array(&cols)));
        }
        // Checked here so that a bad key is reported with its node.
        let motion = TransformMotion::new(&keys).map_err(|e| invalid(format!("{what}: {e}")))?;
        Ok((!motion.is_static()).then_some(keys))
    }

    /// The camera keys of node `ni`: rigid (scale removed, as the camera's own transform).
    pub(crate) fn camera_motion(
        &mut self,
        ni: usize,
        keys: &[(f32, Mat4)],
    ) -> Result<TransformMotion, LoadError> {
        let rigid: Option<Vec<(f32, Mat4)>> = keys
            .iter()
            .map(|(t, m)| orthonormalize(*m).map(|m| (*t, m)))
            .collect();
        let rigid = rigid.ok_or_else(|| {
            invalid(format!(
                "node {ni} TESELA_motion: a camera key has no orientation (zero scale)"
            ))
        })?;
        TransformMotion::new(&rigid).map_err(|e| invalid(format!("node {ni} TESELA_motion: {e}")))
    }
}
