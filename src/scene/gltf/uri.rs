//! URI handling: `data:` URIs and relative file references confined to the scene's folder.

use std::path::{Path, PathBuf};

use base64::Engine;
use base64::engine::general_purpose::{GeneralPurpose, GeneralPurposeConfig};
use base64::engine::{DecodePaddingMode, general_purpose};

use crate::scene::error::{LoadError, LoadErrorKind};

/// Where a URI points.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Target {
    /// Inline data (already decoded).
    Data { mime: String, bytes: Vec<u8> },
    /// A file inside the scene's folder (already checked lexically).
    File(PathBuf),
}

fn refused(msg: String) -> LoadError {
    LoadError::new(LoadErrorKind::Refused, msg)
}

/// Decodes `%XX` escapes; other bytes pass through. The result must be UTF-8.
pub(crate) fn percent_decode(s: &str) -> Result<String, LoadError> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = |c: u8| (c as char).to_digit(16);
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8(out).map_err(|_| {
        LoadError::new(
            LoadErrorKind::Invalid,
            format!("URI `{s}` is not UTF-8 after percent-decoding"),
        )
    })
}

/// The URI's scheme (`http`, `data`, ...), if it has one.
fn scheme(uri: &str) -> Option<&str> {
    let colon = uri.find(':')?;
    let head = &uri[..colon];
    let mut chars = head.chars();
    let first = chars.next()?;
    (first.is_ascii_alphabetic()
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.')))
    .then_some(head)
}

/// Decodes a `data:` URI (`data:[<mime>][;base64],<data>`).
fn decode_data_uri(uri: &str) -> Result<Target, LoadError> {
    let rest = &uri[5..];
    let comma = rest.find(',').ok_or_else(|| {
        LoadError::new(LoadErrorKind::Invalid, "data URI without a `,`".to_string())
    })?;
    let header = &rest[..comma];
    let payload = &rest[comma + 1..];
    let (mime, base64) = match header.len().checked_sub(7) {
        Some(n) if header.is_char_boundary(n) && header[n..].eq_ignore_ascii_case(";base64") => {
            (&header[..n], true)
        }
        _ => (header, false),
    };
    let mime = mime
        .split(';')
        .next()
        .unwrap_or("")
        .trim()
        .to_ascii_lowercase();
    let bytes = if base64 {
        let clean: Vec<u8> = payload
            .bytes()
            .filter(|b| !b.is_ascii_whitespace())
            .collect();
        let engine = GeneralPurpose::new(
            &base64::alphabet::STANDARD,
            GeneralPurposeConfig::new().with_decode_padding_mode(DecodePaddingMode::Indifferent),
        );
        engine
            .decode(&clean)
            .or_else(|_| general_purpose::URL_SAFE_NO_PAD.decode(clean.trim_ascii_end()))
            .map_err(|e| {
                LoadError::new(
                    LoadErrorKind::Invalid,
                    format!("data URI ({mime}) has invalid base64: {e}"),
                )
            })?
    } else {
        percent_decode(payload)?.into_bytes()
    };
    Ok(Target::Data { mime, bytes })
}

/// Resolves `uri` against `base_dir`. Relative paths only: `..`, absolute paths and schemes
/// other than `data:` are refused. `base_dir == None` refuses every file reference.
pub(crate) fn resolve(uri: &str, base_dir: Option<&Path>) -> Result<Target, LoadError> {
    if let Some(s) = scheme(uri) {
        if s.eq_ignore_ascii_case("data") {
            return decode_data_uri(uri);
        }
        if s.len() == 1 {
            return Err(refused(format!(
                "URI `{uri}` is an absolute path; only files inside the scene's folder may be read"
            )));
        }
        return Err(refused(format!(
            "URI `{uri}`: scheme `{s}:` is not allowed; only relative paths inside the scene's folder and data: URIs are"
        )));
    }
    // Drop a query or fragment, then percent-decode.
    let path_part = uri.split(['?', '#']).next().unwrap_or("");
    let decoded = percent_decode(path_part)?;
    if decoded.is_empty() {
        return Err(LoadError::new(
            LoadErrorKind::Invalid,
            format!("URI `{uri}` is empty"),
        ));
    }
    if decoded.starts_with('/') || decoded.starts_with('\\') || scheme(&decoded).is_some() {
        return Err(refused(format!(
            "URI `{uri}` is an absolute path; only files inside the scene's folder may be read"
        )));
    }
    let mut rel = PathBuf::new();
    for part in decoded.split(['/', '\\']) {
        match part {
            "" | "." => {}
            ".." => {
                return Err(refused(format!(
                    "URI `{uri}` leaves the scene's folder (`..`); only files inside it may be read"
                )));
            }
            p if p.contains('\0') => {
                return Err(LoadError::new(
                    LoadErrorKind::Invalid,
                    format!("URI `{uri}` contains a NUL character"),
                ));
            }
            p => rel.push(p),
        }
    }
    if rel.as_os_str().is_empty() {
        return Err(LoadError::new(
            LoadErrorKind::Invalid,
            format!("URI `{uri}` names no file"),
        ));
    }
    let Some(base) = base_dir else {
        return Err(refused(format!(
            "URI `{uri}` refers to an external file, but no base directory was given (external files are refused)"
        )));
    };
    Ok(Target::File(base.join(rel)))
}

/// Reads a file found by [`resolve`], checking (after resolving symlinks) that it is
/// still inside `base_dir`. `min_len`: the file must hold at least this many bytes,
/// checked before reading.
pub(crate) fn read_file(
    path: &Path,
    base_dir: &Path,
    uri: &str,
    min_len: Option<u64>,
) -> Result<Vec<u8>, LoadError> {
    let io = |e: std::io::Error| {
        LoadError::new(
            LoadErrorKind::Io,
            format!("cannot read `{uri}` ({}): {e}", path.display()),
        )
    };
    let canon = std::fs::canonicalize(path).map_err(io)?;
    let base = std::fs::canonicalize(base_dir).map_err(io)?;
    if !canon.starts_with(&base) {
        return Err(refused(format!(
            "URI `{uri}` resolves to {} outside the scene's folder",
            canon.display()
        )));
    }
    let meta = std::fs::metadata(&canon).map_err(io)?;
    if !meta.is_file() {
        return Err(LoadError::new(
            LoadErrorKind::Io,
            format!("cannot read `{uri}`: not a regular file"),
        ));
    }
    if let Some(min) = min_len
        && meta.len() < min
    {
        return Err(LoadError::new(
            LoadErrorKind::Invalid,
            format!(
                "`{uri}` is {} bytes, shorter than the buffer's byteLength {min}",
                meta.len()
            ),
        ));
    }
    std::fs::read(&canon).map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn base() -> &'static Path {
        Path::new("/scenes/a")
    }

    #[test]
    fn relative_paths_resolve_inside_the_folder() {
        assert_eq!(
            resolve("Box0.bin", Some(base())).unwrap(),
            Target::File(PathBuf::from("/scenes/a/Box0.bin"))
        );
        assert_eq!(
            resolve("tex/My%20Image.png", Some(base())).unwrap(),
            Target::File(PathBuf::from("/scenes/a/tex/My Image.png"))
        );
        assert_eq!(
            resolve("./Box With Spaces.bin", Some(base())).unwrap(),
            Target::File(PathBuf::from("/scenes/a/Box With Spaces.bin"))
        );
        assert_eq!(
            resolve("Unicode❤♻Binary.bin", Some(base())).unwrap(),
            Target::File(PathBuf::from("/scenes/a/Unicode❤♻Binary.bin"))
        );
        assert_eq!(
            resolve("%E2%9D%A4.png", Some(base())).unwrap(),
            Target::File(PathBuf::from("/scenes/a/❤.png"))
        );
    }

    #[test]
    fn escapes_are_refused() {
        for uri in [
            "../secret.bin",
            "a/../../secret.bin",
            "a/../b.bin",
            "%2e%2e/secret.bin",
            "..%2Fsecret.bin",
            "a\\..\\..\\x.bin",
            "/etc/passwd",
            "%2Fetc%2Fpasswd",
            "\\\\server\\share\\x.bin",
            "C:/Windows/x.bin",
            "C:\\x.bin",
            "http://example.com/x.bin",
            "https://example.com/x.bin",
            "file:///etc/passwd",
            "ftp:x",
        ] {
            let e = resolve(uri, Some(base())).expect_err(uri);
            assert_eq!(e.kind, LoadErrorKind::Refused, "{uri}: {e}");
        }
        let e = resolve("http://x/y.bin", Some(base())).unwrap_err();
        assert!(e.message.contains("scheme `http:`"), "{e}");
        let e = resolve("ok.bin", None).unwrap_err();
        assert!(e.message.contains("no base directory"), "{e}");
    }

    #[test]
    fn data_uris_decode() {
        let t = resolve("data:application/octet-stream;base64,AAEC", None).unwrap();
        assert_eq!(
            t,
            Target::Data {
                mime: "application/octet-stream".into(),
                bytes: vec![0, 1, 2]
            }
        );
        let t = resolve("data:application/gltf-buffer;base64,AAECAw==", None).unwrap();
        assert!(matches!(t, Target::Data { bytes, .. } if bytes == vec![0, 1, 2, 3]));
        let t = resolve("data:,hello%20world", None).unwrap();
        assert!(matches!(t, Target::Data { bytes, .. } if bytes == b"hello world"));
        assert!(resolve("data:application/octet-stream;base64,@@@", None).is_err());
        assert!(resolve("data:application/octet-stream;base64", None).is_err());
    }

    #[test]
    fn percent_decoding_edge_cases() {
        assert_eq!(percent_decode("a%").unwrap(), "a%");
        assert_eq!(percent_decode("a%2").unwrap(), "a%2");
        assert_eq!(percent_decode("%zz").unwrap(), "%zz");
        assert_eq!(percent_decode("%41%42").unwrap(), "AB");
        assert!(percent_decode("%FF").is_err());
    }
}
