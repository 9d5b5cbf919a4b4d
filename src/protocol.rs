//! The pipe protocol between `tesela render --pipe` and its reader (the Blender add-on).
//! Format: `docs/protocol.md`. Little-endian frames `u32 kind, u32 len, payload`.

use std::io::{self, Read, Write};

/// The newest version this renderer speaks; it also speaks [`VERSION_1`] (the default, so an
/// add-on that does not ask still understands it).
pub const VERSION: u32 = 2;
pub const VERSION_1: u32 = 1;
pub const MAGIC: &[u8; 4] = b"TSLA";
/// Largest payload a reader accepts.
pub const MAX_PAYLOAD: u32 = 1 << 30;

pub const HELLO: u32 = 1;
pub const TILE: u32 = 2;
pub const PROGRESS: u32 = 3;
pub const LOG: u32 = 4;
pub const ERROR: u32 = 5;
pub const DONE: u32 = 6;

/// A decoded frame.
#[derive(Clone, Debug, PartialEq)]
pub enum Message {
    Hello {
        version: u32,
        width: u32,
        height: u32,
        spp: u32,
        tile_count: u32,
        /// Version 2: every pass a tile carries, in order, as (Blender pass name, channel
        /// ids); the first is `("Combined", "RGBA")`. Empty in version 1 (RGBA only).
        passes: Vec<(String, String)>,
    },
    Tile {
        x: u32,
        y: u32,
        w: u32,
        h: u32,
        /// Version 1: `w·h` RGBA pixels. Version 2: each pass of HELLO in turn, `w·h` pixels
        /// of its channels.
        data: Vec<f32>,
    },
    Progress {
        tiles_done: u32,
        tiles_total: u32,
        spp: u32,
        elapsed: f64,
    },
    Log {
        level: u32,
        message: String,
    },
    Error(String),
    Done(String),
    /// A frame of a kind this reader does not know (skipped).
    Unknown(u32),
}

fn frame(out: &mut impl Write, kind: u32, payload: &[u8]) -> io::Result<()> {
    let mut header = [0u8; 8];
    header[..4].copy_from_slice(&kind.to_le_bytes());
    header[4..].copy_from_slice(&(payload.len() as u32).to_le_bytes());
    out.write_all(&header)?;
    out.write_all(payload)
}

fn u32s(values: &[u32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// Writes one message as a frame (not flushed).
pub fn write(out: &mut impl Write, msg: &Message) -> io::Result<()> {
    match msg {
        Message::Hello {
            version,
            width,
            height,
            spp,
            tile_count,
            passes,
        } => {
            let mut p = MAGIC.to_vec();
            p.extend(u32s(&[*version, *width, *height, *spp, *tile_count]));
            if *version >= 2 {
                p.extend(u32s(&[passes.len() as u32]));
                for (name, channels) in passes {
                    for text in [name, channels] {
                        p.extend(u32s(&[text.len() as u32]));
                        p.extend_from_slice(text.as_bytes());
                    }
                }
            }
            frame(out, HELLO, &p)
        }
        Message::Tile { x, y, w, h, data } => {
            let mut p = u32s(&[*x, *y, *w, *h]);
            p.reserve(data.len() * 4);
            for v in data {
                p.extend_from_slice(&v.to_le_bytes());
            }
            frame(out, TILE, &p)
        }
        Message::Progress {
            tiles_done,
            tiles_total,
            spp,
            elapsed,
        } => {
            let mut p = u32s(&[*tiles_done, *tiles_total, *spp]);
            p.extend_from_slice(&elapsed.to_le_bytes());
            frame(out, PROGRESS, &p)
        }
        Message::Log { level, message } => {
            let mut p = level.to_le_bytes().to_vec();
            p.extend_from_slice(message.as_bytes());
            frame(out, LOG, &p)
        }
        Message::Error(m) => frame(out, ERROR, m.as_bytes()),
        Message::Done(json) => frame(out, DONE, json.as_bytes()),
        Message::Unknown(kind) => frame(out, *kind, &[]),
    }
}

fn le_u32(b: &[u8], i: usize) -> u32 {
    u32::from_le_bytes([b[4 * i], b[4 * i + 1], b[4 * i + 2], b[4 * i + 3]])
}

fn bad(m: &str) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, m.to_string())
}

/// Reads one frame; `Ok(None)` at a clean end of stream (between frames).
pub fn read(input: &mut impl Read) -> io::Result<Option<Message>> {
    let mut header = [0u8; 8];
    let mut got = 0;
    while got < 8 {
        let n = input.read(&mut header[got..])?;
        if n == 0 {
            return if got == 0 {
                Ok(None)
            } else {
                Err(bad("truncated frame header"))
            };
        }
        got += n;
    }
    let kind = le_u32(&header, 0);
    let len = le_u32(&header, 1);
    if len > MAX_PAYLOAD {
        return Err(bad("frame payload too large"));
    }
    let mut p = vec![0u8; len as usize];
    input
        .read_exact(&mut p)
        .map_err(|_| bad("truncated frame payload"))?;
    let need = |n: usize| {
        if p.len() < n {
            Err(bad("frame payload too short"))
        } else {
            Ok(())
        }
    };
    Ok(Some(match kind {
        HELLO => {
            need(24)?;
            if &p[..4] != MAGIC {
                return Err(bad("not a Tesela renderer (bad magic)"));
            }
            let v = &p[4..];
            let version = le_u32(v, 0);
            let mut passes = Vec::new();
            if version == 2 {
                let mut at = 24;
                let next_u32 = |at: &mut usize| -> io::Result<u32> {
                    if p.len() < *at + 4 {
                        return Err(bad("HELLO pass list truncated"));
                    }
                    let x = le_u32(&p[*at..], 0);
                    *at += 4;
                    Ok(x)
                };
                let count = next_u32(&mut at)?;
                for _ in 0..count.min(1024) {
                    let mut texts = [String::new(), String::new()];
                    for t in &mut texts {
                        let n = next_u32(&mut at)? as usize;
                        if p.len() < at + n {
                            return Err(bad("HELLO pass list truncated"));
                        }
                        *t = String::from_utf8_lossy(&p[at..at + n]).into_owned();
                        at += n;
                    }
                    let [name, channels] = texts;
                    passes.push((name, channels));
                }
            }
            Message::Hello {
                version,
                width: le_u32(v, 1),
                height: le_u32(v, 2),
                spp: le_u32(v, 3),
                tile_count: le_u32(v, 4),
                passes,
            }
        }
        TILE => {
            need(16)?;
            let (x, y, w, h) = (le_u32(&p, 0), le_u32(&p, 1), le_u32(&p, 2), le_u32(&p, 3));
            let n = w as u64 * h as u64;
            let floats = (p.len() as u64 - 16) / 4;
            if !(p.len() - 16).is_multiple_of(4) || n == 0 || !floats.is_multiple_of(n) {
                return Err(bad("tile payload size does not match its size"));
            }
            let data = p[16..]
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect();
            Message::Tile { x, y, w, h, data }
        }
        PROGRESS => {
            need(20)?;
            let mut e = [0u8; 8];
            e.copy_from_slice(&p[12..20]);
            Message::Progress {
                tiles_done: le_u32(&p, 0),
                tiles_total: le_u32(&p, 1),
                spp: le_u32(&p, 2),
                elapsed: f64::from_le_bytes(e),
            }
        }
        LOG => {
            need(4)?;
            Message::Log {
                level: le_u32(&p, 0),
                message: String::from_utf8_lossy(&p[4..]).into_owned(),
            }
        }
        ERROR => Message::Error(String::from_utf8_lossy(&p).into_owned()),
        DONE => Message::Done(String::from_utf8_lossy(&p).into_owned()),
        k => Message::Unknown(k),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_every_kind() {
        let msgs = vec![
            Message::Hello {
                version: VERSION_1,
                width: 3,
                height: 2,
                spp: 4,
                tile_count: 1,
                passes: vec![],
            },
            Message::Hello {
                version: VERSION,
                width: 3,
                height: 2,
                spp: 4,
                tile_count: 1,
                passes: vec![
                    ("Combined".into(), "RGBA".into()),
                    ("Depth".into(), "Z".into()),
                    ("Denoising Normal".into(), "XYZ".into()),
                ],
            },
            Message::Tile {
                x: 0,
                y: 1,
                w: 2,
                h: 1,
                data: vec![1.0, 2.0, 3.0, 1.0, 0.5, 0.25, 0.0, 1.0],
            },
            Message::Tile {
                x: 0,
                y: 1,
                w: 2,
                h: 1,
                data: vec![1.0, 2.0, 3.0, 1.0, 0.5, 0.25, 0.0, 1.0, 7.0, 8.0],
            },
            Message::Progress {
                tiles_done: 1,
                tiles_total: 1,
                spp: 4,
                elapsed: 0.5,
            },
            Message::Log {
                level: 2,
                message: "héllo".into(),
            },
            Message::Error("boom".into()),
            Message::Done("{}".into()),
        ];
        let mut buf = Vec::new();
        for m in &msgs {
            write(&mut buf, m).unwrap();
        }
        let mut r = &buf[..];
        for m in &msgs {
            assert_eq!(read(&mut r).unwrap().as_ref(), Some(m));
        }
        assert_eq!(read(&mut r).unwrap(), None);
    }

    #[test]
    fn truncation_and_bad_magic_are_errors() {
        let mut buf = Vec::new();
        write(&mut buf, &Message::Error("abc".into())).unwrap();
        assert!(read(&mut &buf[..buf.len() - 1]).is_err());
        assert!(read(&mut &buf[..5]).is_err());
        let mut hello = Vec::new();
        frame(
            &mut hello,
            HELLO,
            b"XXXX\x01\0\0\0\x01\0\0\0\x01\0\0\0\x01\0\0\0\x01\0\0\0",
        )
        .unwrap();
        let e = read(&mut &hello[..]).unwrap_err();
        assert!(e.to_string().contains("bad magic"));
    }
}
