//! The world: what rays that leave the scene see. A constant colour ([`super::Scene::background`],
//! also the fallback) or a node graph (Blender's world node tree: Background, Environment
//! Texture, Mix Shader, Light Path, ...), evaluated per direction by
//! [`crate::emitter::Environment`]. Environment images for the command line (`--env`) are read
//! here too (OpenEXR and Radiance HDR).

use super::Image;
use crate::shading::graph::{Graph, Node};
use serde_json::json;
use std::path::Path;

/// How the world is importance-sampled as a light (Blender's `world.cycles.sampling_method`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum WorldSampling {
    /// A map at the environment image's resolution (capped), else 1024 x 512.
    #[default]
    Automatic,
    /// A map `n` x `n / 2` (`sample_map_resolution`).
    Manual(u32),
    /// Not a light: only BSDF-sampled rays find the world.
    None,
}

/// The world of a scene.
#[derive(Clone, Debug)]
pub struct World {
    /// Blender's world name, for messages.
    pub name: String,
    /// The world's node graph (`surface` = what reaches the World Output's Surface); `None`:
    /// the constant [`super::Scene::background`].
    pub graph: Option<Graph>,
    /// Whether camera rays see the world (`world.cycles_visibility.camera`); when not, they
    /// see black (the world still lights the scene).
    pub visible_camera: bool,
    /// Whether diffuse / glossy (reflection) / transmission closures see the world, by the
    /// rays they scatter and by sampling it (`world.cycles_visibility`).
    pub visible_diffuse: bool,
    pub visible_glossy: bool,
    pub visible_transmission: bool,
    pub sampling: WorldSampling,
}

impl Default for World {
    fn default() -> Self {
        World {
            name: "World".into(),
            graph: None,
            visible_camera: true,
            visible_diffuse: true,
            visible_glossy: true,
            visible_transmission: true,
            sampling: WorldSampling::Automatic,
        }
    }
}

/// Largest environment image side accepted, and most texels.
pub const MAX_ENV_SIDE: usize = 1 << 20;
pub const MAX_ENV_TEXELS: usize = 1 << 27;

/// Reads an environment image (`.exr`, OpenEXR, or `.hdr`, Radiance RGBE) as linear float RGBA,
/// rows top to bottom. Non-finite texels read as 0 and negative ones as 0; the second value
/// says how many were replaced.
pub fn read_environment_image(path: &Path) -> Result<(Image, usize), String> {
    let shown = path.display();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let check = |w: usize, h: usize| -> Result<(), String> {
        if w == 0 || h == 0 {
            return Err(format!("{shown}: the image is empty ({w}x{h})"));
        }
        if w > MAX_ENV_SIDE || h > MAX_ENV_SIDE || w.saturating_mul(h) > MAX_ENV_TEXELS {
            return Err(format!(
                "{shown}: the image is too large ({w}x{h}; at most {MAX_ENV_TEXELS} texels)"
            ));
        }
        Ok(())
    };
    let (w, h, mut px): (usize, usize, Vec<[f32; 4]>) = match ext.as_deref() {
        Some("exr") => {
            let meta = exr::meta::MetaData::read_from_file(path, false)
                .map_err(|e| format!("{shown}: not a readable OpenEXR file: {e}"))?;
            let header = meta
                .headers
                .first()
                .ok_or_else(|| format!("{shown}: the OpenEXR file has no layers"))?;
            let size = header.layer_size;
            check(size.width(), size.height())?;
            let img = exr::prelude::read_first_rgba_layer_from_file(
                path,
                |res, _| {
                    (
                        res.width(),
                        vec![[0.0f32, 0.0, 0.0, 1.0]; res.width() * res.height()],
                    )
                },
                |(w, px): &mut (usize, Vec<[f32; 4]>), pos, (r, g, b, a): (f32, f32, f32, f32)| {
                    px[pos.y() * *w + pos.x()] = [r, g, b, a];
                },
            )
            .map_err(|e| format!("{shown}: cannot read the OpenEXR image: {e}"))?;
            let size = img.layer_data.size;
            let (_, px) = img.layer_data.channel_data.pixels;
            (size.width(), size.height(), px)
        }
        Some("hdr") => {
            let file = std::fs::File::open(path).map_err(|e| format!("{shown}: {e}"))?;
            let reader = std::io::BufReader::new(file);
            let dec = image::codecs::hdr::HdrDecoder::new(reader)
                .map_err(|e| format!("{shown}: not a readable Radiance HDR file: {e}"))?;
            let meta = dec.metadata();
            let (w, h) = (meta.width as usize, meta.height as usize);
            check(w, h)?;
            let mut reader = image::ImageReader::open(path)
                .map_err(|e| format!("{shown}: {e}"))?
                .with_guessed_format()
                .map_err(|e| format!("{shown}: {e}"))?;
            reader.set_format(image::ImageFormat::Hdr);
            reader.no_limits();
            let img = reader
                .decode()
                .map_err(|e| format!("{shown}: cannot read the Radiance HDR image: {e}"))?
                .into_rgb32f();
            let px = img
                .as_raw()
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2], 1.0])
                .collect();
            (w, h, px)
        }
        _ => {
            return Err(format!(
                "{shown}: unknown environment image format (use a .exr or .hdr file)"
            ));
        }
    };
    if px.len() != w * h {
        return Err(format!("{shown}: the image's pixel data is incomplete"));
    }
    let mut bad = 0;
    for p in &mut px {
        for c in p.iter_mut().take(3) {
            if !c.is_finite() || *c < 0.0 {
                *c = 0.0;
                bad += 1;
            }
        }
        if !p[3].is_finite() {
            p[3] = 1.0;
        }
    }
    Ok((
        Image {
            width: w as u32,
            height: h as u32,
            rgba8: Vec::new(),
            float: px,
        },
        bad,
    ))
}

/// The world graph of an equirectangular environment image `image` (an index into the
/// scene's images) times `strength`, turned by `rotation_deg` about Blender's Z axis (a
/// Mapping node's Z rotation, as an artist would set it): Texture Coordinate > Mapping >
/// Environment Texture > Background.
pub fn environment_graph(image: usize, strength: f32, rotation_deg: f32) -> Graph {
    let mut g = Graph::default();
    let mut env = Node::new("ShaderNodeTexEnvironment")
        .prop("projection", json!("EQUIRECTANGULAR"))
        .prop("interpolation", json!("Linear"))
        .prop("colorspace", json!("Non-Color"));
    env.image = Some(image);
    if rotation_deg != 0.0 {
        let tc = g.add(Node::new("ShaderNodeTexCoord"));
        let map = g.add(
            Node::new("ShaderNodeMapping")
                .prop("vector_type", json!("POINT"))
                .link("Vector", tc, "Generated")
                .with("Location", &[0.0, 0.0, 0.0])
                .with("Rotation", &[0.0, 0.0, rotation_deg.to_radians()])
                .with("Scale", &[1.0, 1.0, 1.0]),
        );
        env = env.link("Vector", map, "Vector");
    }
    let env = g.add(env);
    let bg = g.add(
        Node::new("ShaderNodeBackground")
            .link("Color", env, "Color")
            .with("Strength", &[strength]),
    );
    g.surface = Some((bg, "Background".into()));
    g
}
