//! `EXT_meshopt_compression` (and its ratified twin `KHR_meshopt_compression`): bufferViews
//! whose bytes are a meshoptimizer stream (gltfpack's `-c`, glTF-Transform's `meshopt`).
//!
//! A compressed view names, in its extension, the buffer range holding the stream and the
//! layout it decodes to (`count` elements of `byteStride` bytes, a mode and a filter). The
//! view's own `buffer` is then often a *fallback* buffer with no data at all. Every compressed
//! view is decoded once, before the accessors are read, and served in place of its bytes.

use std::collections::HashMap;

use meshoptimizer_rs::Workspace;
use meshoptimizer_rs::codec::{self, Filter, Mode};
use serde_json::Value;

use super::{extension, member};
use crate::scene::error::{LoadError, LoadErrorKind};

pub(crate) const EXTENSIONS: [&str; 2] = ["EXT_meshopt_compression", "KHR_meshopt_compression"];

fn invalid(msg: String) -> LoadError {
    LoadError::new(LoadErrorKind::Invalid, msg)
}

/// The meshopt extension object on `v`, and its name.
fn meshopt_extension(v: &Value) -> Option<(&'static str, &Value)> {
    EXTENSIONS
        .iter()
        .find_map(|&name| extension(v, name).map(|e| (name, e)))
}

/// Whether buffer `i` is a meshopt fallback buffer: one that may have no data, as every view
/// on it is decoded from elsewhere.
pub(crate) fn is_fallback_buffer(raw: &Value, i: usize) -> bool {
    member(raw, "buffers")
        .and_then(|b| b.get(i))
        .and_then(meshopt_extension)
        .and_then(|(_, e)| member(e, "fallback"))
        .and_then(Value::as_bool)
        .unwrap_or(false)
}

/// Decodes every compressed bufferView: view index -> its `byteLength` bytes.
pub(crate) fn decode_views(
    raw: &Value,
    buffers: &[&[u8]],
) -> Result<HashMap<usize, Vec<u8>>, LoadError> {
    let mut out = HashMap::new();
    let Some(views) = member(raw, "bufferViews").and_then(Value::as_array) else {
        return Ok(out);
    };
    let mut workspace = Workspace::default();
    for (vi, view) in views.iter().enumerate() {
        let Some((name, ext)) = meshopt_extension(view) else {
            continue;
        };
        let tag = format!("bufferView {vi}: {name}");
        let int = |key: &str| -> Result<usize, LoadError> {
            member(ext, key)
                .and_then(Value::as_u64)
                .and_then(|v| usize::try_from(v).ok())
                .ok_or_else(|| invalid(format!("{tag}: {key} is missing or not an integer")))
        };
        let text = |key: &str, default: &'static str| -> Result<String, LoadError> {
            match member(ext, key) {
                None => Ok(default.to_string()),
                Some(v) => v
                    .as_str()
                    .map(str::to_string)
                    .ok_or_else(|| invalid(format!("{tag}: {key} is not a string"))),
            }
        };
        let bi = int("buffer")?;
        let offset = member(ext, "byteOffset")
            .map(|_| int("byteOffset"))
            .transpose()?
            .unwrap_or(0);
        let length = int("byteLength")?;
        let stride = int("byteStride")?;
        let count = int("count")?;
        let mode_name = text("mode", "")?;
        let filter_name = text("filter", "NONE")?;
        let mode = Mode::parse(&mode_name)
            .map_err(|_| invalid(format!("{tag}: unknown mode `{mode_name}`")))?;
        let filter = Filter::parse(&filter_name)
            .map_err(|_| invalid(format!("{tag}: unknown filter `{filter_name}`")))?;
        let buf = buffers.get(bi).ok_or_else(|| {
            invalid(format!(
                "{tag}: buffer {bi} does not exist (the file has {})",
                buffers.len()
            ))
        })?;
        let source = offset
            .checked_add(length)
            .and_then(|end| buf.get(offset..end))
            .ok_or_else(|| {
                invalid(format!(
                    "{tag}: byteOffset {offset} + byteLength {length} exceeds buffer {bi} of {} bytes",
                    buf.len()
                ))
            })?;
        let layout = codec::BufferView::new(mode, filter, count, stride).map_err(|e| {
            invalid(format!(
                "{tag}: {count} x {stride} bytes as {mode_name}: {e}"
            ))
        })?;
        let want = member(view, "byteLength").and_then(Value::as_u64);
        if want != Some(layout.byte_length() as u64) {
            return Err(invalid(format!(
                "{tag}: decodes to {} bytes where the view's byteLength is {}",
                layout.byte_length(),
                want.map_or_else(|| "missing".to_string(), |w| w.to_string())
            )));
        }
        let decoded = if name == "KHR_meshopt_compression" && mode == Mode::Attributes {
            // The ratified extension also allows version 1 of the vertex codec, which the
            // EXT view decoder refuses: decode the stream, then apply the filter.
            codec::decode_vertex_buffer(count, stride, source, &mut workspace).and_then(
                |mut data| {
                    let ws = &mut workspace;
                    match filter {
                        Filter::None => Ok(()),
                        Filter::Octahedral => {
                            codec::decode_filter_oct(&mut data, count, stride, ws)
                        }
                        Filter::Quaternion => {
                            codec::decode_filter_quat(&mut data, count, stride, ws)
                        }
                        Filter::Exponential => {
                            codec::decode_filter_exp(&mut data, count, stride, ws)
                        }
                    }
                    .map(|()| data)
                },
            )
        } else {
            layout.decode(source, &mut workspace)
        };
        let bytes =
            decoded.map_err(|e| invalid(format!("{tag}: the stream does not decode: {e}")))?;
        out.insert(vi, bytes);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use meshoptimizer_rs::codec::{IndexEncoding, VertexEncoding};
    use meshoptimizer_rs::codec::{encode_index_buffer, encode_vertex_buffer};

    use super::*;
    use crate::scene::gltf::load_from_slice;

    const POSITIONS: [[f32; 3]; 4] = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]];
    const INDICES: [u32; 6] = [0, 1, 2, 0, 2, 3];

    /// A quad whose positions and indices are meshopt streams in buffer 0, the views on a
    /// fallback buffer 1 without data, as gltfpack writes them.
    fn quad(ext: &str, corrupt: bool) -> Vec<u8> {
        let mut ws = Workspace::default();
        let verts: Vec<u8> = POSITIONS
            .iter()
            .flatten()
            .flat_map(|f| f.to_le_bytes())
            .collect();
        let v = encode_vertex_buffer(&verts, 4, 12, VertexEncoding::new(0, 2).unwrap(), &mut ws)
            .unwrap();
        let mut i = encode_index_buffer(&INDICES, IndexEncoding::DEFAULT, &mut ws).unwrap();
        if corrupt {
            i.truncate(3);
        }
        let mut blob = v.clone();
        blob.resize(v.len().next_multiple_of(4), 0);
        let i_off = blob.len();
        blob.extend_from_slice(&i);
        let b64 = |b: &[u8]| {
            use base64::Engine;
            base64::engine::general_purpose::STANDARD.encode(b)
        };
        let doc = serde_json::json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": [ext], "extensionsRequired": [ext],
            "buffers": [
                {"byteLength": blob.len(),
                 "uri": format!("data:application/octet-stream;base64,{}", b64(&blob))},
                {"byteLength": 72, "extensions": {ext: {"fallback": true}}}
            ],
            "bufferViews": [
                {"buffer": 1, "byteLength": 48, "byteStride": 12, "extensions": {ext: {
                    "buffer": 0, "byteLength": v.len(), "byteStride": 12, "count": 4,
                    "mode": "ATTRIBUTES"}}},
                {"buffer": 1, "byteOffset": 48, "byteLength": 24, "extensions": {ext: {
                    "buffer": 0, "byteOffset": i_off, "byteLength": i.len(), "byteStride": 4,
                    "count": 6, "mode": "TRIANGLES"}}}
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]},
                {"bufferView": 1, "componentType": 5125, "count": 6, "type": "SCALAR"}
            ],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "nodes": [{"mesh": 0}],
            "scenes": [{"nodes": [0]}]
        });
        serde_json::to_vec(&doc).unwrap()
    }

    #[test]
    fn compressed_views_decode_to_the_original_mesh() {
        for ext in EXTENSIONS {
            let s = load_from_slice(&quad(ext, false), None, "quad.gltf").unwrap();
            let m = &s.meshes[0];
            let p: Vec<[f32; 3]> = m.positions.iter().map(|p| p.to_array()).collect();
            assert_eq!(p, POSITIONS, "{ext}");
            let t: Vec<u32> = m.indices.iter().flatten().copied().collect();
            assert_eq!(t, INDICES, "{ext}");
        }
    }

    #[test]
    fn a_broken_stream_is_an_error_naming_the_view() {
        let e = load_from_slice(&quad(EXTENSIONS[0], true), None, "quad.gltf").unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("bufferView 1: EXT_meshopt_compression: the stream does not decode"),
            "{msg}"
        );
    }
}
