//! Splitting the input into its JSON document and the GLB binary chunk.

use crate::scene::error::{LoadError, LoadErrorKind};

const GLB_MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// The parts of a glTF file: its JSON text and, for GLB, the first BIN chunk.
#[derive(Debug)]
pub(crate) struct Container<'a> {
    pub json: &'a [u8],
    pub bin: Option<&'a [u8]>,
}

fn format(msg: impl Into<String>) -> LoadError {
    LoadError::new(LoadErrorKind::Format, msg)
}

fn read_u32(bytes: &[u8], at: usize) -> Option<u32> {
    let end = at.checked_add(4)?;
    let b = bytes.get(at..end)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Recognises GLB (by its magic) or JSON text (by its first non-blank character).
pub(crate) fn split(bytes: &[u8]) -> Result<Container<'_>, LoadError> {
    if bytes.is_empty() {
        return Err(format("empty file (not a glTF file)"));
    }
    if bytes.starts_with(GLB_MAGIC) {
        return split_glb(bytes);
    }
    let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    match text.iter().find(|b| !b.is_ascii_whitespace()) {
        Some(b'{') => Ok(Container {
            json: text,
            bin: None,
        }),
        None => Err(format("file holds only blank space (not a glTF file)")),
        Some(_) => {
            if bytes.len() >= 4 && bytes[..4].eq_ignore_ascii_case(b"gltf") {
                Err(format(format!(
                    "bad GLB magic {:?} (expected `glTF`)",
                    String::from_utf8_lossy(&bytes[..4])
                )))
            } else {
                Err(format(
                    "not a glTF file: neither a GLB (magic `glTF`) nor a JSON object",
                ))
            }
        }
    }
}

fn split_glb(bytes: &[u8]) -> Result<Container<'_>, LoadError> {
    if bytes.len() < 12 {
        return Err(format(format!(
            "truncated GLB: {} bytes, shorter than the 12-byte header",
            bytes.len()
        )));
    }
    let version = read_u32(bytes, 4).unwrap_or(0);
    if version != 2 {
        return Err(LoadError::new(
            LoadErrorKind::Unsupported,
            format!("unsupported GLB version {version} (only glTF 2.0 is supported)"),
        ));
    }
    let length = read_u32(bytes, 8).unwrap_or(0) as usize;
    if length > bytes.len() {
        return Err(format(format!(
            "truncated GLB: header says {length} bytes but the file has {}",
            bytes.len()
        )));
    }
    if length < 12 {
        return Err(format(format!(
            "invalid GLB: header length {length} is shorter than the header"
        )));
    }
    let bytes = &bytes[..length];
    let mut at = 12usize;
    let mut json = None;
    let mut bin = None;
    let mut index = 0usize;
    while at < bytes.len() {
        let (Some(chunk_len), Some(chunk_type)) = (read_u32(bytes, at), read_u32(bytes, at + 4))
        else {
            return Err(format(format!(
                "truncated GLB: chunk {index} header at byte {at} is cut off"
            )));
        };
        let start = at + 8;
        let end = start
            .checked_add(chunk_len as usize)
            .filter(|&e| e <= bytes.len())
            .ok_or_else(|| {
                format(format!(
                    "truncated GLB: chunk {index} ({chunk_len} bytes at byte {start}) runs past the end of the file ({} bytes)",
                    bytes.len()
                ))
            })?;
        let data = &bytes[start..end];
        match chunk_type {
            CHUNK_JSON if index == 0 => json = Some(data),
            CHUNK_JSON => return Err(format("invalid GLB: more than one JSON chunk")),
            CHUNK_BIN if index == 1 => bin = Some(data),
            _ if index == 0 => {
                return Err(format("invalid GLB: the first chunk is not the JSON chunk"));
            }
            _ => {} // unknown chunks (and later BIN chunks) are skipped, as the spec asks
        }
        // Chunks are 4-byte aligned; tolerate a missing final padding.
        at = end.checked_add(3).map(|e| e & !3).unwrap_or(usize::MAX);
        index += 1;
    }
    let json = json.ok_or_else(|| format("invalid GLB: no JSON chunk"))?;
    Ok(Container { json, bin })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
        let mut out = Vec::new();
        let pad = |v: &mut Vec<u8>, b: u8| {
            while !v.len().is_multiple_of(4) {
                v.push(b)
            }
        };
        let mut j = json.to_vec();
        pad(&mut j, b' ');
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&0u32.to_le_bytes());
        out.extend_from_slice(&(j.len() as u32).to_le_bytes());
        out.extend_from_slice(&CHUNK_JSON.to_le_bytes());
        out.extend_from_slice(&j);
        if let Some(b) = bin {
            let mut b = b.to_vec();
            pad(&mut b, 0);
            out.extend_from_slice(&(b.len() as u32).to_le_bytes());
            out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
            out.extend_from_slice(&b);
        }
        let n = out.len() as u32;
        out[8..12].copy_from_slice(&n.to_le_bytes());
        out
    }

    #[test]
    fn glb_chunks_are_found() {
        let f = glb(b"{}", Some(&[1, 2, 3, 4]));
        let c = split(&f).unwrap();
        assert_eq!(c.json.trim_ascii(), b"{}");
        assert_eq!(c.bin, Some(&[1u8, 2, 3, 4][..]));
    }

    #[test]
    fn every_truncation_of_a_glb_is_an_error_not_a_panic() {
        let f = glb(b"{\"asset\":{\"version\":\"2.0\"}}", Some(&[7; 16]));
        for n in 0..f.len() {
            assert!(split(&f[..n]).is_err(), "prefix of {n} bytes accepted");
        }
    }

    #[test]
    fn json_and_garbage() {
        assert!(split(b"  \n{\"a\":1}").is_ok());
        assert!(split(b"\xEF\xBB\xBF{}").is_ok());
        let e = split(b"").unwrap_err();
        assert!(e.message.contains("empty"), "{e}");
        let e = split(b"GLTF\x02\0\0\0").unwrap_err();
        assert!(e.message.contains("magic"), "{e}");
        let e = split(b"\x89PNG....").unwrap_err();
        assert!(e.message.contains("not a glTF"), "{e}");
    }
}
