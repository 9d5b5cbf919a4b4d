//! Materials, textures, samplers and images.

use ::gltf::json;
use glam::Vec3;
use json::texture::{MagFilter, WrappingMode};
use json::validation::Checked;
use serde_json::Value;

use super::{
    LoadError, LoadErrorKind, Loader, extension, invalid, member, num, rgb, short_uri, uri,
};
use crate::scene::{Image, Material, TexRef, Texture, Wrap};

/// Largest accepted image side, in pixels.
const MAX_IMAGE_SIDE: u32 = 16384;
/// Largest decoder allocation for one image.
const MAX_IMAGE_ALLOC: u64 = 512 << 20;

/// Decodes PNG or JPEG bytes into RGBA8, rows top to bottom.
pub(crate) fn decode_image(bytes: &[u8]) -> Result<Image, String> {
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?;
    match reader.format() {
        Some(image::ImageFormat::Png | image::ImageFormat::Jpeg) => {}
        Some(f) => {
            return Err(format!(
                "unsupported image format {f:?} (PNG and JPEG are supported)"
            ));
        }
        None => return Err("not a PNG or JPEG image".into()),
    }
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_IMAGE_SIDE);
    limits.max_image_height = Some(MAX_IMAGE_SIDE);
    limits.max_alloc = Some(MAX_IMAGE_ALLOC);
    reader.limits(limits);
    let img = reader.decode().map_err(|e| e.to_string())?;
    let rgba = img.to_rgba8();
    let (width, height) = rgba.dimensions();
    let rgba8 = rgba
        .into_raw()
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect();
    Ok(Image {
        width,
        height,
        rgba8,
        float: Vec::new(),
    })
}

fn wrap(m: &Checked<WrappingMode>) -> Wrap {
    match m {
        Checked::Valid(WrappingMode::ClampToEdge) => Wrap::ClampToEdge,
        Checked::Valid(WrappingMode::MirroredRepeat) => Wrap::MirroredRepeat,
        _ => Wrap::Repeat,
    }
}

fn finite_or(v: f32, default: f32) -> f32 {
    if v.is_finite() { v } else { default }
}

impl<'a> Loader<'a> {
    /// The scene material for glTF material `gi` (or the default material for `None`).
    pub(crate) fn material(&mut self, gi: Option<usize>) -> Result<usize, LoadError> {
        let Some(gi) = gi else {
            if let Some(d) = self.default_material {
                return Ok(d);
            }
            self.scene.materials.push(Material::default());
            let d = self.scene.materials.len() - 1;
            self.default_material = Some(d);
            return Ok(d);
        };
        if let Some(&m) = self.materials.get(&gi) {
            return Ok(m);
        }
        let m = self.build_material(gi)?;
        self.scene.materials.push(m);
        let idx = self.scene.materials.len() - 1;
        self.materials.insert(gi, idx);
        Ok(idx)
    }

    fn build_material(&mut self, gi: usize) -> Result<Material, LoadError> {
        let m = self.root.materials.get(gi).ok_or_else(|| {
            invalid(format!(
                "material {gi} does not exist (the file has {})",
                self.root.materials.len()
            ))
        })?;
        let raw = self.raw_item("materials", gi);
        let raw_pbr = member(raw, "pbrMetallicRoughness").unwrap_or(&Value::Null);
        let pbr = &m.pbr_metallic_roughness;
        let bc = pbr.base_color_factor.0;
        let base_color = Vec3::new(bc[0], bc[1], bc[2]);
        let base_color = if base_color.is_finite() {
            base_color.clamp(Vec3::ZERO, Vec3::ONE)
        } else {
            Vec3::ONE
        };
        let base_color_texture = self.tex_ref(
            pbr.base_color_texture.as_ref(),
            member(raw_pbr, "baseColorTexture"),
            gi,
            "baseColorTexture",
        )?;
        let metallic_roughness_texture = self.tex_ref(
            pbr.metallic_roughness_texture.as_ref(),
            member(raw_pbr, "metallicRoughnessTexture"),
            gi,
            "metallicRoughnessTexture",
        )?;
        let emission_texture = self.tex_ref(
            m.emissive_texture.as_ref(),
            member(raw, "emissiveTexture"),
            gi,
            "emissiveTexture",
        )?;
        let strength = extension(raw, "KHR_materials_emissive_strength")
            .and_then(|e| num(e, "emissiveStrength"))
            .unwrap_or(1.0) as f32;
        let mut emission = Vec3::from_array(m.emissive_factor.0) * strength;
        if !emission.is_finite() || emission.min_element() < 0.0 {
            self.warn_once(format!(
                "material {gi}: emission {emission} is invalid and is ignored"
            ));
            emission = Vec3::ZERO;
        }
        let transmission = extension(raw, "KHR_materials_transmission")
            .and_then(|e| num(e, "transmissionFactor"))
            .unwrap_or(0.0) as f32;
        let mut ior = extension(raw, "KHR_materials_ior")
            .and_then(|e| num(e, "ior"))
            .unwrap_or(1.5) as f32;
        if !(ior.is_finite() && ior >= 1.0) {
            self.warn_once(format!(
                "material {gi}: KHR_materials_ior {ior} is invalid; using 1.5"
            ));
            ior = 1.5;
        }
        let spec = extension(raw, "KHR_materials_specular");
        let specular = spec.and_then(|e| num(e, "specularFactor")).unwrap_or(1.0) as f32;
        let specular_color = spec
            .and_then(|e| rgb(e, "specularColorFactor"))
            .filter(|c| c.is_finite())
            .unwrap_or(Vec3::ONE)
            .max(Vec3::ZERO);
        let double_sided = m.double_sided;
        let emission_two_sided = extension(raw, "TESELA_emission")
            .and_then(|e| member(e, "two_sided"))
            .and_then(Value::as_bool)
            .unwrap_or(double_sided);
        let name = m.name.clone().unwrap_or_else(|| format!("material{gi}"));
        let graph = match extension(raw, "TESELA_material_graph") {
            Some(g) => Some(std::sync::Arc::new(self.material_graph(g, gi, &name)?)),
            None => None,
        };
        Ok(Material {
            name,
            base_color,
            base_color_texture,
            metallic: finite_or(pbr.metallic_factor.0, 1.0).clamp(0.0, 1.0),
            roughness: finite_or(pbr.roughness_factor.0, 1.0).clamp(0.0, 1.0),
            metallic_roughness_texture,
            emission,
            emission_texture,
            emission_two_sided,
            transmission: finite_or(transmission, 0.0).clamp(0.0, 1.0),
            ior,
            specular: finite_or(specular, 1.0).clamp(0.0, 1.0),
            specular_color,
            double_sided,
            graph,
        })
    }

    /// Parses a `TESELA_material_graph` and resolves its image references. A graph that does
    /// not parse is an error naming the material; an image that cannot be loaded is too.
    fn material_graph(
        &mut self,
        g: &Value,
        gi: usize,
        name: &str,
    ) -> Result<crate::shading::Graph, LoadError> {
        let mut graph = crate::shading::Graph::from_json(g).map_err(|e| {
            invalid(format!(
                "material {gi} (`{name}`): TESELA_material_graph: {e}"
            ))
        })?;
        for node in &mut graph.nodes {
            let Some(ii) = node.props.get("image").and_then(Value::as_u64) else {
                continue;
            };
            let ii = ii as usize;
            let image = self.graph_image(ii).map_err(|e| {
                LoadError::new(
                    e.kind,
                    format!(
                        "material {gi} (`{name}`), node `{}`: {}",
                        node.name, e.message
                    ),
                )
            })?;
            node.image = Some(image);
        }
        Ok(graph)
    }

    /// The scene image of entry `ii` of the root `TESELA_images` list when the file has one,
    /// else of glTF image `ii`.
    fn graph_image(&mut self, ii: usize) -> Result<usize, LoadError> {
        let list = self
            .raw_root_extension("TESELA_images")
            .and_then(|e| member(e, "images"))
            .and_then(Value::as_array);
        let Some(list) = list else {
            return self.image(ii);
        };
        if let Some(&i) = self.raw_images.get(&ii) {
            return Ok(i);
        }
        let entry = list.get(ii).ok_or_else(|| {
            invalid(format!(
                "TESELA_images image {ii} does not exist (the file has {})",
                list.len()
            ))
        })?;
        let img = self.raw_image(entry, ii)?;
        self.scene.images.push(img);
        let idx = self.scene.images.len() - 1;
        self.raw_images.insert(ii, idx);
        Ok(idx)
    }

    /// Decodes one `TESELA_images` entry: raw pixel rows, top to bottom, in a bufferView.
    fn raw_image(&mut self, e: &Value, ii: usize) -> Result<Image, LoadError> {
        let label = format!("TESELA_images image {ii}");
        let dim = |k: &str| -> Result<u32, LoadError> {
            member(e, k)
                .and_then(Value::as_u64)
                .filter(|&v| v > 0 && v <= MAX_IMAGE_SIDE as u64)
                .map(|v| v as u32)
                .ok_or_else(|| {
                    invalid(format!(
                        "{label}: `{k}` must be an integer in 1..={MAX_IMAGE_SIDE}"
                    ))
                })
        };
        let (w, h) = (dim("width")?, dim("height")?);
        let channels = member(e, "channels")
            .and_then(Value::as_u64)
            .filter(|c| (1..=4).contains(c))
            .ok_or_else(|| invalid(format!("{label}: `channels` must be 1 to 4")))?
            as usize;
        let comp = member(e, "component")
            .and_then(Value::as_str)
            .unwrap_or("u8");
        let size = match comp {
            "u8" => 1,
            "u16" | "f16" => 2,
            "f32" => 4,
            other => {
                return Err(invalid(format!(
                    "{label}: component `{other}` is not one of u8, u16, f16, f32"
                )));
            }
        };
        let vi = member(e, "bufferView")
            .and_then(Value::as_u64)
            .ok_or_else(|| invalid(format!("{label}: no `bufferView`")))? as usize;
        let (bytes, _) = self
            .reader
            .view(vi, &label)
            .map_err(|err| LoadError::new(err.kind, format!("{label}: {}", err.message)))?;
        let n = w as usize * h as usize;
        let need = n * channels * size;
        if bytes.len() < need {
            return Err(invalid(format!(
                "{label}: bufferView {vi} holds {} bytes, {w}x{h}x{channels} {comp} needs {need}",
                bytes.len()
            )));
        }
        let value = |i: usize| -> f32 {
            let b = &bytes[i * size..(i + 1) * size];
            match comp {
                "u8" => b[0] as f32 / 255.0,
                "u16" => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
                "f16" => half_to_f32(u16::from_le_bytes([b[0], b[1]])),
                _ => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            }
        };
        let srgb_bytes = comp == "u8";
        let mut rgba8 = Vec::new();
        let mut float = Vec::new();
        let mut bad = 0usize;
        for p in 0..n {
            let mut px = [0.0f32, 0.0, 0.0, 1.0];
            for (c, out) in px.iter_mut().enumerate().take(channels) {
                let mut v = value(p * channels + c);
                if !v.is_finite() {
                    v = 0.0;
                    bad += 1;
                }
                *out = v;
            }
            if channels < 3 {
                px[1] = px[0];
                px[2] = px[0];
                if channels == 2 {
                    px[3] = value(p * channels + 1);
                }
            }
            if srgb_bytes {
                rgba8.push(px.map(|v| (v * 255.0).round().clamp(0.0, 255.0) as u8));
            } else {
                float.push(px);
            }
        }
        if bad > 0 {
            self.warn_once(format!(
                "{label}: {bad} texel values are not finite and read as 0"
            ));
        }
        Ok(Image {
            width: w,
            height: h,
            rgba8,
            float,
        })
    }

    fn tex_ref(
        &mut self,
        info: Option<&json::texture::Info>,
        raw: Option<&Value>,
        gi: usize,
        slot: &str,
    ) -> Result<Option<TexRef>, LoadError> {
        let Some(info) = info else { return Ok(None) };
        if raw
            .and_then(|r| extension(r, "KHR_texture_transform"))
            .is_some()
        {
            self.warn_once(
                "KHR_texture_transform is not applied (textures are sampled untransformed)".into(),
            );
        }
        let ti = info.index.value();
        let raw_texture = self.raw_item("textures", ti);
        if raw_texture.is_object() && member(raw_texture, "source").is_none() {
            self.warn_once(format!(
                "texture {ti} has no `source` (only an extension's image format); material {gi} {slot} is left untextured"
            ));
            return Ok(None);
        }
        let texture = self
            .texture(ti)
            .map_err(|e| LoadError::new(e.kind, format!("material {gi} {slot}: {}", e.message)))?;
        Ok(Some(TexRef {
            texture,
            texcoord: info.tex_coord,
        }))
    }

    fn texture(&mut self, ti: usize) -> Result<usize, LoadError> {
        if let Some(&t) = self.textures.get(&ti) {
            return Ok(t);
        }
        let t = self.root.textures.get(ti).ok_or_else(|| {
            invalid(format!(
                "texture {ti} does not exist (the file has {})",
                self.root.textures.len()
            ))
        })?;
        if member(self.raw_item("textures", ti), "source").is_none() {
            return Err(LoadError::new(
                LoadErrorKind::Unsupported,
                format!(
                    "texture {ti} has no `source` (only an extension's image format, which is not supported)"
                ),
            ));
        }
        let (wrap_s, wrap_t, nearest) = match t.sampler {
            Some(si) => {
                let s = self.root.samplers.get(si.value()).ok_or_else(|| {
                    invalid(format!(
                        "texture {ti}: sampler {} does not exist (the file has {})",
                        si.value(),
                        self.root.samplers.len()
                    ))
                })?;
                (
                    wrap(&s.wrap_s),
                    wrap(&s.wrap_t),
                    matches!(s.mag_filter, Some(Checked::Valid(MagFilter::Nearest))),
                )
            }
            None => (Wrap::Repeat, Wrap::Repeat, false),
        };
        let image = self
            .image(t.source.value())
            .map_err(|e| LoadError::new(e.kind, format!("texture {ti}: {}", e.message)))?;
        self.scene.textures.push(Texture {
            image,
            wrap_s,
            wrap_t,
            nearest,
        });
        let idx = self.scene.textures.len() - 1;
        self.textures.insert(ti, idx);
        Ok(idx)
    }

    fn image(&mut self, ii: usize) -> Result<usize, LoadError> {
        if let Some(&i) = self.images.get(&ii) {
            return Ok(i);
        }
        let im = self.root.images.get(ii).ok_or_else(|| {
            invalid(format!(
                "image {ii} does not exist (the file has {})",
                self.root.images.len()
            ))
        })?;
        let (label, bytes): (String, std::borrow::Cow<'_, [u8]>) = match (&im.uri, im.buffer_view) {
            (Some(u), _) => {
                let label = format!("image {ii} (`{}`)", short_uri(u));
                let ctx = |e: LoadError| LoadError::new(e.kind, format!("{label}: {}", e.message));
                let bytes = match uri::resolve(u, self.base_dir).map_err(ctx)? {
                    uri::Target::Data { bytes, .. } => bytes,
                    uri::Target::File(p) => {
                        let base = self.base_dir.unwrap_or(std::path::Path::new("."));
                        uri::read_file(&p, base, u, None).map_err(ctx)?
                    }
                };
                (label, bytes.into())
            }
            (None, Some(vi)) => {
                let label = format!("image {ii} (bufferView {})", vi.value());
                let (bytes, _) = self
                    .reader
                    .view(vi.value(), &label)
                    .map_err(|e| LoadError::new(e.kind, format!("{label}: {}", e.message)))?;
                (label, bytes.into())
            }
            (None, None) => {
                return Err(invalid(format!(
                    "image {ii} has neither a uri nor a bufferView"
                )));
            }
        };
        let decoded = decode_image(&bytes).map_err(|e| {
            LoadError::new(
                LoadErrorKind::Invalid,
                format!("{label}: cannot decode the image: {e}"),
            )
        })?;
        self.scene.images.push(decoded);
        let idx = self.scene.images.len() - 1;
        self.images.insert(ii, idx);
        Ok(idx)
    }
}

/// IEEE 754 half → single precision.
fn half_to_f32(h: u16) -> f32 {
    let sign = ((h >> 15) as u32) << 31;
    let exp = ((h >> 10) & 0x1f) as u32;
    let frac = (h & 0x3ff) as u32;
    let bits = match (exp, frac) {
        (0, 0) => sign,
        (0, f) => {
            // Subnormal: normalise.
            let mut e = 127 - 15 + 1;
            let mut f = f;
            while f & 0x400 == 0 {
                f <<= 1;
                e -= 1;
            }
            sign | (e << 23) | ((f & 0x3ff) << 13)
        }
        (31, 0) => sign | 0x7f80_0000,
        (31, f) => sign | 0x7f80_0000 | (f << 13),
        (e, f) => sign | ((e + 127 - 15) << 23) | (f << 13),
    };
    f32::from_bits(bits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_floats() {
        assert_eq!(half_to_f32(0x3c00), 1.0);
        assert_eq!(half_to_f32(0xc000), -2.0);
        assert_eq!(half_to_f32(0x7bff), 65504.0);
        assert_eq!(half_to_f32(0x0001), 2f32.powi(-24));
        assert!(half_to_f32(0x7c00).is_infinite());
    }

    #[test]
    fn garbage_images_are_errors() {
        assert!(decode_image(b"").is_err());
        assert!(decode_image(b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR").is_err());
        assert!(decode_image(&[0xFF, 0xD8, 0xFF, 0xE0, 0, 16]).is_err());
        assert!(decode_image(b"GIF89a").is_err());
    }
}
