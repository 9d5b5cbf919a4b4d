//! A glTF file kept in memory (its JSON and its resolved buffers), so that the interactive
//! session can load pieces of it again: a material, a light, the world, a camera, written as
//! small documents that share the file's buffers, images and textures.

use std::path::{Path, PathBuf};

use glam::Mat4;
use serde_json::Value;

use super::{
    LoadError, LoadErrorKind, container, load_parsed, parse_json, resolve_buffers, typed_document,
};
use crate::scene::Scene;

/// Which glTF node made each part of a loaded scene.
#[derive(Clone, Debug, Default)]
pub struct Origins {
    /// Per scene mesh: the node whose mesh was baked into it (world space), or `None` for a
    /// mesh stored in its object space for instances to place.
    pub mesh_node: Vec<Option<usize>>,
    /// Per scene instance: the node that placed it.
    pub instance_node: Vec<usize>,
    /// Per scene light: the node it sits on.
    pub light_node: Vec<usize>,
    /// Per glTF node reached by the walk: its world matrix (identity for the others).
    pub node_world: Vec<Mat4>,
    /// Per scene material: the glTF material it was made from (`None`: the default).
    pub material_gltf: Vec<Option<usize>>,
}

/// A parsed glTF file with its buffers in memory.
#[derive(Clone, Debug)]
pub struct Document {
    /// The file's JSON (the session edits it as the add-on's commands change the scene).
    pub raw: Value,
    buffers: Vec<Vec<u8>>,
    base_dir: Option<PathBuf>,
    name: String,
}

impl Document {
    /// Reads `.gltf` or `.glb` file `path` and resolves its buffers (external files inside
    /// its folder only, as [`super::load`]).
    pub fn read(path: &Path) -> Result<Document, LoadError> {
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| {
            LoadError::new(LoadErrorKind::Io, format!("cannot read the file: {e}")).in_file(&name)
        })?;
        let base = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let parse = || -> Result<(Value, Vec<Vec<u8>>), LoadError> {
            let c = container::split(&bytes)?;
            let raw = parse_json(c.json)?;
            let root = typed_document(&raw)?;
            let buffers = resolve_buffers(&raw, &root, c.bin, Some(&base))?;
            Ok((raw, buffers.into_iter().map(|b| b.into_owned()).collect()))
        };
        let (raw, buffers) = parse().map_err(|e| e.in_file(&name))?;
        Ok(Document {
            raw,
            buffers,
            base_dir: Some(base),
            name,
        })
    }

    /// The file's name, for messages.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of buffers (a piece's own buffers come after them).
    pub fn buffer_count(&self) -> usize {
        self.buffers.len()
    }

    /// Loads the document as it stands.
    pub fn load(&self) -> Result<(Scene, Origins), LoadError> {
        self.load_piece(&self.raw, &[])
    }

    /// Loads another document `raw` whose first buffers are this document's (same count and
    /// lengths) followed by `extra`; external images resolve in this document's folder.
    pub fn load_piece(&self, raw: &Value, extra: &[&[u8]]) -> Result<(Scene, Origins), LoadError> {
        let root = typed_document(raw).map_err(|e| e.in_file(&self.name))?;
        let mut buffers: Vec<&[u8]> = self.buffers.iter().map(|b| &b[..]).collect();
        buffers.extend_from_slice(extra);
        if root.buffers.len() != buffers.len() {
            return Err(LoadError::new(
                LoadErrorKind::Invalid,
                format!(
                    "the document lists {} buffers, {} are given",
                    root.buffers.len(),
                    buffers.len()
                ),
            )
            .in_file(&self.name));
        }
        for (i, (b, data)) in root.buffers.iter().zip(&buffers).enumerate() {
            if (data.len() as u64) < b.byte_length.0 && !super::meshopt::is_fallback_buffer(raw, i)
            {
                return Err(LoadError::new(
                    LoadErrorKind::Invalid,
                    format!(
                        "buffer {i} holds {} bytes, fewer than byteLength {}",
                        data.len(),
                        b.byte_length.0
                    ),
                )
                .in_file(&self.name));
            }
        }
        load_parsed(
            raw,
            &root,
            &buffers,
            self.base_dir.as_deref(),
            &super::LoadOptions::default(),
        )
        .map_err(|e| e.in_file(&self.name))
    }
}
