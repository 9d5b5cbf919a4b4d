//! The session protocol's bytes (docs/session.md): command frames read from the add-on and
//! the frames written back. Reading never panics on garbage: a frame that is not a command
//! becomes a [`CommandError`], a header that cannot be a frame a fatal [`io::Error`].

use std::io::{self, Read, Write};
use std::path::PathBuf;

use glam::Mat4;
use serde_json::{Map, Value, json};

/// HELLO's magic: a Tesela session (the pipe protocol's renderer says `TSLA`).
pub const MAGIC: &[u8; 4] = b"TSLS";
/// The session protocol's version.
pub const VERSION: u32 = 1;

/// Frame kinds, add-on -> session.
pub const COMMAND: u32 = 32;
/// Frame kinds, session -> add-on.
pub const HELLO: u32 = 1;
pub const LOG: u32 = 4;
pub const ERROR: u32 = 5;
pub const IMAGE: u32 = 16;
pub const STATS: u32 = 17;

/// Largest payload a frame may carry.
pub const MAX_PAYLOAD: u32 = 1 << 30;

/// LOG levels.
pub const LOG_DEBUG: u32 = 0;
pub const LOG_INFO: u32 = 1;
pub const LOG_WARNING: u32 = 2;

/// A camera for the view: the node's world matrix and its `TESELA_camera` object.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewCamera {
    pub matrix: Mat4,
    pub camera: Value,
}

/// The `view` command.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    pub width: u32,
    pub height: u32,
    pub camera: ViewCamera,
    /// `[x, y, w, h]` of the view, top-left origin.
    pub border: Option<[u32; 4]>,
}

/// What the add-on asks.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    Load {
        path: PathBuf,
    },
    View(View),
    /// The fields to change, as given (checked when applied).
    Settings(Map<String, Value>),
    Transform {
        node: String,
        matrix: Mat4,
    },
    Material {
        name: String,
        material: Value,
    },
    Light {
        node: String,
        light: Value,
        matrix: Option<Mat4>,
    },
    World {
        world: Value,
    },
    Visibility {
        node: String,
        visible: bool,
    },
    Mesh {
        name: String,
        path: PathBuf,
    },
    Pause,
    Resume,
    Stop,
}

/// A command with what came with it.
#[derive(Clone, Debug, PartialEq)]
pub struct Envelope {
    /// The `cmd` name.
    pub cmd: String,
    /// The add-on's `id`, echoed in an ERROR that answers the command (`null` without one).
    pub id: Value,
    pub command: Command,
    /// Fields the command does not know (ignored; reported as a LOG warning).
    pub unknown: Vec<String>,
}

/// A frame that could not be taken as a command.
#[derive(Clone, Debug, PartialEq)]
pub struct CommandError {
    /// The `cmd` it named, if it got that far.
    pub cmd: Option<String>,
    pub id: Value,
    pub message: String,
}

/// Reads one frame: `Ok(None)` at end of input between frames; an error when the input ends
/// inside a frame or the header announces more than [`MAX_PAYLOAD`] bytes.
pub fn read_frame(r: &mut impl Read) -> io::Result<Option<(u32, Vec<u8>)>> {
    let mut head = [0u8; 8];
    let mut got = 0;
    while got < head.len() {
        match r.read(&mut head[got..]) {
            Ok(0) if got == 0 => return Ok(None),
            Ok(0) => {
                return Err(io::Error::new(
                    io::ErrorKind::UnexpectedEof,
                    "the input ends inside a frame header",
                ));
            }
            Ok(n) => got += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    let kind = u32::from_le_bytes([head[0], head[1], head[2], head[3]]);
    let len = u32::from_le_bytes([head[4], head[5], head[6], head[7]]);
    if len > MAX_PAYLOAD {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "a frame of kind {kind} announces {len} bytes, more than 1 GiB: the framing is lost"
            ),
        ));
    }
    let mut payload = Vec::new();
    r.take(len as u64).read_to_end(&mut payload)?;
    if payload.len() < len as usize {
        return Err(io::Error::new(
            io::ErrorKind::UnexpectedEof,
            format!(
                "the input ends inside a frame ({} of {len} bytes)",
                payload.len()
            ),
        ));
    }
    Ok(Some((kind, payload)))
}

/// Takes frame `(kind, payload)` as a command.
pub fn parse_command(kind: u32, payload: &[u8]) -> Result<Envelope, CommandError> {
    let fail = |cmd: Option<&str>, id: &Value, message: String| CommandError {
        cmd: cmd.map(str::to_string),
        id: id.clone(),
        message,
    };
    if kind != COMMAND {
        return Err(fail(
            None,
            &Value::Null,
            format!("frame kind {kind} is not a command (commands are kind {COMMAND})"),
        ));
    }
    if payload.len() < 4 {
        return Err(fail(
            None,
            &Value::Null,
            format!(
                "a command payload starts with a u32 JSON length; this one has {} bytes",
                payload.len()
            ),
        ));
    }
    let n = u32::from_le_bytes([payload[0], payload[1], payload[2], payload[3]]) as usize;
    let Some(text) = payload.get(4..4 + n) else {
        return Err(fail(
            None,
            &Value::Null,
            format!(
                "the JSON length {n} runs past the payload's {} bytes",
                payload.len() - 4
            ),
        ));
    };
    if payload.len() > 4 + n {
        return Err(fail(
            None,
            &Value::Null,
            format!(
                "{} attachment bytes follow the JSON; no command of version {VERSION} takes an attachment",
                payload.len() - 4 - n
            ),
        ));
    }
    let value: Value = serde_json::from_slice(text)
        .map_err(|e| fail(None, &Value::Null, format!("the command is not JSON: {e}")))?;
    let Value::Object(mut obj) = value else {
        return Err(fail(
            None,
            &Value::Null,
            "the command is not a JSON object".into(),
        ));
    };
    let id = obj.remove("id").unwrap_or(Value::Null);
    let cmd = match obj.remove("cmd") {
        Some(Value::String(s)) => s,
        Some(other) => {
            return Err(fail(
                None,
                &id,
                format!("`cmd` must be a string, not {other}"),
            ));
        }
        None => return Err(fail(None, &id, "the command has no `cmd`".into())),
    };
    let mut fields = Fields {
        obj,
        cmd: &cmd,
        used: Vec::new(),
    };
    let command = fields.command().map_err(|m| fail(Some(&cmd), &id, m))?;
    let unknown = fields
        .obj
        .keys()
        .filter(|k| !fields.used.contains(k))
        .cloned()
        .collect();
    Ok(Envelope {
        cmd,
        id,
        command,
        unknown,
    })
}

/// A command's JSON fields, taken one by one.
struct Fields<'a> {
    obj: Map<String, Value>,
    cmd: &'a str,
    used: Vec<String>,
}

impl Fields<'_> {
    fn get(&mut self, key: &str) -> Option<Value> {
        self.used.push(key.to_string());
        self.obj.get(key).cloned()
    }

    fn required(&mut self, key: &str) -> Result<Value, String> {
        self.get(key)
            .ok_or_else(|| format!("`{}` needs the field `{key}`", self.cmd))
    }

    fn string(&mut self, key: &str) -> Result<String, String> {
        match self.required(key)? {
            Value::String(s) if !s.is_empty() => Ok(s),
            other => Err(format!("`{key}` must be a non-empty string, not {other}")),
        }
    }

    fn object(&mut self, key: &str) -> Result<Value, String> {
        match self.required(key)? {
            v @ Value::Object(_) => Ok(v),
            other => Err(format!("`{key}` must be a JSON object, not {other}")),
        }
    }

    fn matrix(&mut self, key: &str) -> Result<Option<Mat4>, String> {
        self.get(key).map(|v| matrix(&v, key)).transpose()
    }

    fn command(&mut self) -> Result<Command, String> {
        Ok(match self.cmd {
            "load" => Command::Load {
                path: PathBuf::from(self.string("path")?),
            },
            "view" => {
                let width = dimension(&self.required("width")?, "width")?;
                let height = dimension(&self.required("height")?, "height")?;
                let cam = self.object("camera")?;
                let m = cam
                    .get("matrix")
                    .ok_or("`camera` needs the field `matrix` (the camera's world matrix)")?;
                let camera = ViewCamera {
                    matrix: matrix(m, "camera.matrix")?,
                    camera: match cam.get("camera") {
                        Some(c @ Value::Object(_)) => c.clone(),
                        None => Value::Object(Map::new()),
                        Some(other) => {
                            return Err(format!(
                                "`camera.camera` must be the TESELA_camera object, not {other}"
                            ));
                        }
                    },
                };
                let border = match self.get("border") {
                    None | Some(Value::Null) => None,
                    Some(b) => {
                        let a = b.as_array().filter(|a| a.len() == 4).ok_or_else(|| {
                            format!("`border` must be [x, y, w, h] in pixels, not {b}")
                        })?;
                        let mut r = [0u32; 4];
                        for (i, v) in a.iter().enumerate() {
                            r[i] = v.as_u64().and_then(|v| u32::try_from(v).ok()).ok_or_else(
                                || format!("`border` must be 4 whole numbers >= 0, not {b}"),
                            )?;
                        }
                        let [x, y, w, h] = r;
                        if w == 0
                            || h == 0
                            || x as u64 + w as u64 > width as u64
                            || y as u64 + h as u64 > height as u64
                        {
                            return Err(format!(
                                "`border` {r:?} is empty or outside the {width}x{height} view"
                            ));
                        }
                        Some(r)
                    }
                };
                Command::View(View {
                    width,
                    height,
                    camera,
                    border,
                })
            }
            "settings" => {
                let obj = std::mem::take(&mut self.obj);
                self.used.extend(obj.keys().cloned());
                Command::Settings(obj)
            }
            "transform" => Command::Transform {
                node: self.string("node")?,
                matrix: self
                    .matrix("matrix")?
                    .ok_or("`transform` needs the field `matrix`")?,
            },
            "material" => Command::Material {
                name: self.string("name")?,
                material: self.object("material")?,
            },
            "light" => Command::Light {
                node: self.string("node")?,
                light: self.object("light")?,
                matrix: self.matrix("matrix")?,
            },
            "world" => Command::World {
                world: self.object("world")?,
            },
            "visibility" => Command::Visibility {
                node: self.string("node")?,
                visible: match self.required("visible")? {
                    Value::Bool(b) => b,
                    other => return Err(format!("`visible` must be true or false, not {other}")),
                },
            },
            "mesh" => Command::Mesh {
                name: self.string("name")?,
                path: PathBuf::from(self.string("path")?),
            },
            "pause" => Command::Pause,
            "resume" => Command::Resume,
            "stop" => Command::Stop,
            other => {
                return Err(format!(
                    "unknown command `{other}` (known: load, view, settings, transform, material, light, world, visibility, mesh, pause, resume, stop)"
                ));
            }
        })
    }
}

/// A view dimension: a whole number in `1..=65536`.
fn dimension(v: &Value, key: &str) -> Result<u32, String> {
    v.as_u64()
        .filter(|&n| (1..=65536).contains(&n))
        .map(|n| n as u32)
        .ok_or_else(|| format!("`{key}` must be a whole number of pixels in 1..=65536, not {v}"))
}

/// 16 finite numbers, column-major (a glTF node's `matrix`).
pub fn matrix(v: &Value, key: &str) -> Result<Mat4, String> {
    let a = v
        .as_array()
        .filter(|a| a.len() == 16)
        .ok_or_else(|| format!("`{key}` must be 16 numbers (column-major), not {v}"))?;
    let mut m = [0f32; 16];
    for (i, x) in a.iter().enumerate() {
        m[i] = x
            .as_f64()
            .map(|f| f as f32)
            .filter(|f| f.is_finite())
            .ok_or_else(|| format!("`{key}`[{i}] must be a finite number, not {x}"))?;
    }
    Ok(Mat4::from_cols_array(&m))
}

/// Writes one frame.
pub fn write_frame(out: &mut impl Write, kind: u32, payload: &[u8]) -> io::Result<()> {
    out.write_all(&kind.to_le_bytes())?;
    out.write_all(&(payload.len() as u32).to_le_bytes())?;
    out.write_all(payload)
}

/// HELLO's payload.
pub fn hello(threads: usize) -> Vec<u8> {
    let mut p = MAGIC.to_vec();
    p.extend_from_slice(&VERSION.to_le_bytes());
    let info = json!({
        "renderer": concat!("tesela ", env!("CARGO_PKG_VERSION")),
        "threads": threads,
    });
    p.extend_from_slice(info.to_string().as_bytes());
    p
}

/// LOG's payload.
pub fn log(level: u32, message: &str) -> Vec<u8> {
    let mut p = level.to_le_bytes().to_vec();
    p.extend_from_slice(message.as_bytes());
    p
}

/// ERROR's payload.
pub fn error(command: Option<&str>, id: &Value, message: &str, fatal: bool) -> Vec<u8> {
    json!({"command": command, "id": id, "message": message, "fatal": fatal})
        .to_string()
        .into_bytes()
}

/// Where an IMAGE lies in the view and what it holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageHeader {
    pub generation: u64,
    pub view_width: u32,
    pub view_height: u32,
    /// The window `[x, y, w, h]` in view pixels.
    pub window: [u32; 4],
    pub pixel_size: u32,
    pub data_width: u32,
    pub data_height: u32,
    pub samples: u32,
    /// Bit 0: the last image of the generation; bit 1: denoised.
    pub flags: u32,
}

/// IMAGE flag: the sample target is reached.
pub const FLAG_FINAL: u32 = 1;
/// IMAGE flag: the pixels are denoised.
pub const FLAG_DENOISED: u32 = 2;

/// IMAGE's payload: the header, then `pixels` (rows top to bottom).
pub fn image(h: &ImageHeader, pixels: &[[f32; 4]]) -> Vec<u8> {
    let mut p = Vec::with_capacity(52 + pixels.len() * 16);
    p.extend_from_slice(&h.generation.to_le_bytes());
    let [x, y, w, hh] = h.window;
    for v in [
        h.view_width,
        h.view_height,
        x,
        y,
        w,
        hh,
        h.pixel_size,
        h.data_width,
        h.data_height,
        h.samples,
        h.flags,
    ] {
        p.extend_from_slice(&v.to_le_bytes());
    }
    for px in pixels {
        for c in px {
            p.extend_from_slice(&c.to_le_bytes());
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(json: &str, attachment: &[u8]) -> Vec<u8> {
        let mut p = (json.len() as u32).to_le_bytes().to_vec();
        p.extend_from_slice(json.as_bytes());
        p.extend_from_slice(attachment);
        p
    }

    #[test]
    fn commands_parse_and_garbage_is_an_error() {
        let e = parse_command(COMMAND, &frame(r#"{"cmd":"pause","id":7,"x":1}"#, b"")).unwrap();
        assert_eq!(e.command, Command::Pause);
        assert_eq!(e.id, json!(7));
        assert_eq!(e.unknown, vec!["x".to_string()]);
        let m: Vec<f32> = (0..16).map(|i| i as f32).collect();
        let t = format!(r#"{{"cmd":"transform","node":"Cube","matrix":{m:?}}}"#);
        match parse_command(COMMAND, &frame(&t, b"")).unwrap().command {
            Command::Transform { node, matrix } => {
                assert_eq!(node, "Cube");
                assert_eq!(matrix.to_cols_array()[5], 5.0);
            }
            c => panic!("{c:?}"),
        }
        for (kind, payload, want) in [
            (COMMAND, frame(r#"{"cmd":"warp"}"#, b""), "unknown command"),
            (COMMAND, frame("{", b""), "not JSON"),
            (COMMAND, frame("[1]", b""), "not a JSON object"),
            (COMMAND, frame(r#"{"cmd":"pause"}"#, b"xx"), "attachment"),
            (COMMAND, vec![1, 0], "u32 JSON length"),
            (COMMAND, vec![200, 0, 0, 0, b'{'], "runs past"),
            (9, frame(r#"{"cmd":"pause"}"#, b""), "not a command"),
            (
                COMMAND,
                frame(r#"{"cmd":"view","width":0,"height":2,"camera":{}}"#, b""),
                "width",
            ),
            (
                COMMAND,
                frame(r#"{"cmd":"transform","node":"a","matrix":[1,2,3]}"#, b""),
                "16 numbers",
            ),
        ] {
            let e = parse_command(kind, &payload).unwrap_err();
            assert!(e.message.contains(want), "{want}: {}", e.message);
        }
    }

    #[test]
    fn garbage_never_panics() {
        // A fixed-seed stream of random payloads, some of them JSON-looking.
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let words: [&[u8]; 8] = [
            b"{",
            b"}",
            b"\"cmd\":",
            b"\"view\"",
            b"[",
            b"]",
            b"1e999",
            b",",
        ];
        let mut refused = 0;
        for _ in 0..20000 {
            let mut p = Vec::new();
            let n = next() % 40;
            for _ in 0..n {
                let r = next();
                if r % 3 == 0 {
                    p.extend_from_slice(words[(r >> 8) as usize % words.len()]);
                } else {
                    p.push((r >> 16) as u8);
                }
            }
            let mut framed = (p.len() as u32).to_le_bytes().to_vec();
            framed.extend_from_slice(&p);
            refused += parse_command(COMMAND, &framed).is_err() as u32;
            let _ = parse_command(COMMAND, &p);
            let _ = read_frame(&mut &p[..]);
        }
        // Random bytes are almost never a command: each is answered as an error.
        assert!(refused > 19_900, "{refused}");
    }

    #[test]
    fn frames_read_back_and_truncation_is_an_error() {
        let mut buf = Vec::new();
        write_frame(&mut buf, COMMAND, b"abc").unwrap();
        let mut r = &buf[..];
        assert_eq!(
            read_frame(&mut r).unwrap(),
            Some((COMMAND, b"abc".to_vec()))
        );
        assert_eq!(read_frame(&mut r).unwrap(), None);
        let mut cut = &buf[..9];
        assert!(read_frame(&mut cut).is_err());
        let mut huge = &[1u8, 0, 0, 0, 255, 255, 255, 255][..];
        assert!(read_frame(&mut huge).is_err());
    }
}
