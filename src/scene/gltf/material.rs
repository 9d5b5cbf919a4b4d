//! Materials, textures, samplers and images.

use ::gltf::json;
use glam::{Vec2, Vec3};
use json::texture::{MagFilter, WrappingMode};
use json::validation::Checked;
use serde_json::Value;

use super::{
    LoadError, LoadErrorKind, Loader, extension, invalid, member, num, rgb, short_uri, uri,
};
use crate::scene::{AlphaMode, Image, Material, TexRef, Texture, UvTransform, Wrap};

/// Largest accepted image side, in pixels.
const MAX_IMAGE_SIDE: u32 = super::image_file::MAX_SIDE;

/// Decodes PNG, JPEG or WebP (`EXT_texture_webp`) bytes into RGBA8, rows top to bottom.
pub(crate) fn decode_image(bytes: &[u8]) -> Result<Image, String> {
    use image::ImageFormat::{Jpeg, Png, WebP};
    let img = super::image_file::read(
        bytes,
        &[Png, Jpeg, WebP],
        ("PNG, JPEG and WebP", "a PNG, JPEG or WebP"),
    )?;
    Ok(super::image_file::bytes_image(&img))
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

/// `v[key]` as a finite `f32`, `default` when absent; `Err` when present but not a finite number.
fn factor(v: &Value, key: &str, default: f32) -> Result<f32, ()> {
    match member(v, key) {
        None => Ok(default),
        Some(x) => x
            .as_f64()
            .map(|x| x as f32)
            .filter(|x| x.is_finite())
            .ok_or(()),
    }
}

/// `v[key]` as a finite `[f32; N]`, `default` when absent; `Err` when malformed.
fn factors<const N: usize>(v: &Value, key: &str, default: [f32; N]) -> Result<[f32; N], ()> {
    let Some(x) = member(v, key) else {
        return Ok(default);
    };
    let a = x.as_array().filter(|a| a.len() == N).ok_or(())?;
    let mut out = default;
    for (o, x) in out.iter_mut().zip(a) {
        *o = x
            .as_f64()
            .map(|x| x as f32)
            .filter(|x| x.is_finite())
            .ok_or(())?;
    }
    Ok(out)
}

impl<'a> Loader<'a> {
    /// The scene material for glTF material `gi` (or the default material for `None`);
    /// `vertex_color`: the primitive has COLOR_0, which multiplies the base colour (a variant of
    /// the material; graph materials read colour attributes by name instead).
    pub(crate) fn material(
        &mut self,
        gi: Option<usize>,
        vertex_color: bool,
    ) -> Result<usize, LoadError> {
        if let Some(&m) = self.materials.get(&(gi, vertex_color)) {
            return Ok(m);
        }
        let mut m = match gi {
            Some(gi) => self.build_material(gi)?,
            None => Material::default(),
        };
        // A graph material has one variant: it reads colour attributes itself.
        let has_graph = m.graph.is_some();
        m.vertex_color = vertex_color && !has_graph;
        self.scene.materials.push(m);
        let idx = self.scene.materials.len() - 1;
        self.materials.insert((gi, vertex_color), idx);
        if has_graph {
            self.materials.insert((gi, !vertex_color), idx);
        }
        Ok(idx)
    }

    /// A warning about material `gi`, once.
    fn warn_material(&mut self, gi: usize, name: &str, what: String) {
        self.warn_once(format!("material {gi} (`{name}`): {what}"));
    }

    /// `raw[key]` as a factor of material `gi`: malformed values are warned about and take
    /// `default`; the result is clamped to `[lo, hi]`.
    #[allow(clippy::too_many_arguments)]
    fn mat_factor(
        &mut self,
        gi: usize,
        name: &str,
        raw: &Value,
        what: &str,
        key: &str,
        default: f32,
        lo: f32,
        hi: f32,
    ) -> f32 {
        match factor(raw, key, default) {
            Ok(v) => v.clamp(lo, hi),
            Err(()) => {
                self.warn_material(
                    gi,
                    name,
                    format!("{what} `{key}` is not a finite number; using {default}"),
                );
                default
            }
        }
    }

    fn build_material(&mut self, gi: usize) -> Result<Material, LoadError> {
        let m = self.root.materials.get(gi).ok_or_else(|| {
            invalid(format!(
                "material {gi} does not exist (the file has {})",
                self.root.materials.len()
            ))
        })?;
        let raw = self.raw_item("materials", gi);
        let name = m.name.clone().unwrap_or_else(|| format!("material{gi}"));
        let raw_pbr = member(raw, "pbrMetallicRoughness").unwrap_or(&Value::Null);
        let pbr = &m.pbr_metallic_roughness;
        let bc = pbr.base_color_factor.0;
        let base_color = Vec3::new(bc[0], bc[1], bc[2]);
        let base_color = if base_color.is_finite() {
            base_color.clamp(Vec3::ZERO, Vec3::ONE)
        } else {
            Vec3::ONE
        };
        let alpha = finite_or(bc[3], 1.0).clamp(0.0, 1.0);
        let alpha_mode = match &m.alpha_mode {
            Checked::Valid(json::material::AlphaMode::Opaque) => AlphaMode::Opaque,
            Checked::Valid(json::material::AlphaMode::Blend) => AlphaMode::Blend,
            Checked::Valid(json::material::AlphaMode::Mask) => {
                let c = m.alpha_cutoff.map_or(0.5, |c| c.0);
                let cutoff = if c.is_finite() && c >= 0.0 {
                    c
                } else {
                    self.warn_material(
                        gi,
                        &name,
                        format!("alphaCutoff {c} is not a non-negative number; using 0.5"),
                    );
                    0.5
                };
                AlphaMode::Mask { cutoff }
            }
            Checked::Invalid => {
                self.warn_material(
                    gi,
                    &name,
                    "alphaMode is not OPAQUE, MASK or BLEND; rendered opaque".into(),
                );
                AlphaMode::Opaque
            }
        };
        let base_color_texture = self.tex_info(
            member(raw_pbr, "baseColorTexture"),
            gi,
            &name,
            "baseColorTexture",
        )?;
        let metallic_roughness_texture = self.tex_info(
            member(raw_pbr, "metallicRoughnessTexture"),
            gi,
            &name,
            "metallicRoughnessTexture",
        )?;
        let emission_texture =
            self.tex_info(member(raw, "emissiveTexture"), gi, &name, "emissiveTexture")?;
        let raw_normal = member(raw, "normalTexture");
        let normal_texture = self.tex_info(raw_normal, gi, &name, "normalTexture")?;
        let normal_scale = match raw_normal {
            Some(n) => self.mat_factor(
                gi,
                &name,
                n,
                "normalTexture",
                "scale",
                1.0,
                f32::MIN,
                f32::MAX,
            ),
            None => 1.0,
        };
        self.occlusion(raw, gi, &name);
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
        let raw_transmission = extension(raw, "KHR_materials_transmission");
        let transmission = raw_transmission
            .and_then(|e| num(e, "transmissionFactor"))
            .unwrap_or(0.0) as f32;
        let transmission_texture = match raw_transmission {
            Some(e) => self.tex_info(
                member(e, "transmissionTexture"),
                gi,
                &name,
                "KHR_materials_transmission.transmissionTexture",
            )?,
            None => None,
        };
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
        let (specular_texture, specular_color_texture) = match spec {
            Some(e) => (
                self.tex_info(
                    member(e, "specularTexture"),
                    gi,
                    &name,
                    "KHR_materials_specular.specularTexture",
                )?,
                self.tex_info(
                    member(e, "specularColorTexture"),
                    gi,
                    &name,
                    "KHR_materials_specular.specularColorTexture",
                )?,
            ),
            None => (None, None),
        };
        let clearcoat = match extension(raw, "KHR_materials_clearcoat") {
            Some(e) => Some(self.clearcoat(e, gi, &name)?),
            None => None,
        };
        let sheen = match extension(raw, "KHR_materials_sheen") {
            Some(e) => Some(self.sheen(e, gi, &name)?),
            None => None,
        };
        let anisotropy = match extension(raw, "KHR_materials_anisotropy") {
            Some(e) => Some(self.anisotropy(e, gi, &name)?),
            None => None,
        };
        let transmissive = transmission > 0.0 || transmission_texture.is_some();
        let volume =
            extension(raw, "KHR_materials_volume").map(|e| self.volume(e, gi, &name, transmissive));
        let double_sided = m.double_sided;
        let emission_two_sided = extension(raw, "TESELA_emission")
            .and_then(|e| member(e, "two_sided"))
            .and_then(Value::as_bool)
            .unwrap_or(double_sided);
        let pass_index = extension(raw, "TESELA_material_graph")
            .and_then(|g| member(g, "pass_index"))
            .and_then(Value::as_u64)
            .map_or(0, |v| v.min(u32::MAX as u64) as u32);
        let graph = match extension(raw, "TESELA_material_graph") {
            Some(g) => Some(std::sync::Arc::new(self.material_graph(g, gi, &name)?)),
            None => None,
        };
        let mut material = Material {
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
            alpha,
            alpha_mode,
            vertex_color: false,
            normal_texture,
            normal_scale,
            transmission_texture,
            specular_texture,
            specular_color_texture,
            clearcoat,
            sheen,
            anisotropy,
            volume,
            graph,
            pass_index,
            unlit: extension(raw, "KHR_materials_unlit").is_some(),
            glossiness_texture: None,
        };
        if let Some(e) = extension(raw, "KHR_materials_pbrSpecularGlossiness") {
            self.specular_glossiness(e, gi, &mut material)?;
        }
        Ok(material)
    }

    /// `KHR_materials_pbrSpecularGlossiness` in place of the metallic-roughness factors, as
    /// Blender's importer reads it into a Principled BSDF: base colour and alpha = diffuse
    /// factor × texture; Specular Tint = specular factor × the RGB of the specular-glossiness
    /// texture, with IOR 1000 (a Fresnel reflectance of 1 at normal incidence, so the tint is
    /// the specular colour at every angle but grazing); roughness = 1 − glossiness factor ×
    /// its alpha; not metallic.
    fn specular_glossiness(
        &mut self,
        e: &Value,
        gi: usize,
        m: &mut Material,
    ) -> Result<(), LoadError> {
        const EXT: &str = "KHR_materials_pbrSpecularGlossiness";
        let name = m.name.clone();
        let diffuse = factors::<4>(e, "diffuseFactor", [1.0; 4]).unwrap_or_else(|()| {
            self.warn_material(
                gi,
                &name,
                format!("{EXT} `diffuseFactor` is malformed; using white"),
            );
            [1.0; 4]
        });
        m.base_color = Vec3::new(diffuse[0], diffuse[1], diffuse[2]).clamp(Vec3::ZERO, Vec3::ONE);
        m.alpha = diffuse[3].clamp(0.0, 1.0);
        m.base_color_texture = self.tex_info(
            member(e, "diffuseTexture"),
            gi,
            &name,
            &format!("{EXT}.diffuseTexture"),
        )?;
        let specular = factors::<3>(e, "specularFactor", [1.0; 3]).unwrap_or_else(|()| {
            self.warn_material(
                gi,
                &name,
                format!("{EXT} `specularFactor` is malformed; using white"),
            );
            [1.0; 3]
        });
        let glossiness = self.mat_factor(gi, &name, e, EXT, "glossinessFactor", 1.0, 0.0, 1.0);
        let texture = self.tex_info(
            member(e, "specularGlossinessTexture"),
            gi,
            &name,
            &format!("{EXT}.specularGlossinessTexture"),
        )?;
        m.metallic = 0.0;
        m.metallic_roughness_texture = None;
        m.roughness = 1.0 - glossiness;
        m.glossiness_texture = texture.filter(|_| glossiness > 0.0);
        m.specular = 1.0;
        m.specular_color = Vec3::from_array(specular).max(Vec3::ZERO);
        m.specular_color_texture = texture;
        m.ior = 1000.0;
        Ok(())
    }

    /// `occlusionTexture` is read and checked but not rendered: a path tracer computes the
    /// occlusion an ambient-occlusion map approximates (so does Blender's importer, which
    /// leaves it unconnected). A broken reference is warned about, not an error.
    fn occlusion(&mut self, raw: &Value, gi: usize, name: &str) {
        let Some(o) = member(raw, "occlusionTexture") else {
            return;
        };
        let ok = member(o, "index")
            .and_then(Value::as_u64)
            .is_some_and(|i| (i as usize) < self.root.textures.len());
        if !ok {
            self.warn_material(
                gi,
                name,
                "occlusionTexture does not name an existing texture (it is not rendered anyway)"
                    .into(),
            );
        }
    }

    fn clearcoat(
        &mut self,
        e: &Value,
        gi: usize,
        name: &str,
    ) -> Result<crate::scene::Clearcoat, LoadError> {
        let what = "KHR_materials_clearcoat";
        let factor = self.mat_factor(gi, name, e, what, "clearcoatFactor", 0.0, 0.0, 1.0);
        let roughness =
            self.mat_factor(gi, name, e, what, "clearcoatRoughnessFactor", 0.0, 0.0, 1.0);
        let raw_normal = member(e, "clearcoatNormalTexture");
        let normal_scale = match raw_normal {
            Some(n) => self.mat_factor(
                gi,
                name,
                n,
                "clearcoatNormalTexture",
                "scale",
                1.0,
                f32::MIN,
                f32::MAX,
            ),
            None => 1.0,
        };
        Ok(crate::scene::Clearcoat {
            factor,
            texture: self.tex_info(
                member(e, "clearcoatTexture"),
                gi,
                name,
                "KHR_materials_clearcoat.clearcoatTexture",
            )?,
            roughness,
            roughness_texture: self.tex_info(
                member(e, "clearcoatRoughnessTexture"),
                gi,
                name,
                "KHR_materials_clearcoat.clearcoatRoughnessTexture",
            )?,
            normal_texture: self.tex_info(
                raw_normal,
                gi,
                name,
                "KHR_materials_clearcoat.clearcoatNormalTexture",
            )?,
            normal_scale,
        })
    }

    fn sheen(
        &mut self,
        e: &Value,
        gi: usize,
        name: &str,
    ) -> Result<crate::scene::Sheen, LoadError> {
        let what = "KHR_materials_sheen";
        let color = match factors(e, "sheenColorFactor", [0.0; 3]) {
            Ok(c) => Vec3::from_array(c).max(Vec3::ZERO),
            Err(()) => {
                self.warn_material(
                    gi,
                    name,
                    format!("{what} `sheenColorFactor` is not three finite numbers; using black"),
                );
                Vec3::ZERO
            }
        };
        let roughness = self.mat_factor(gi, name, e, what, "sheenRoughnessFactor", 0.0, 0.0, 1.0);
        Ok(crate::scene::Sheen {
            color,
            color_texture: self.tex_info(
                member(e, "sheenColorTexture"),
                gi,
                name,
                "KHR_materials_sheen.sheenColorTexture",
            )?,
            roughness,
            roughness_texture: self.tex_info(
                member(e, "sheenRoughnessTexture"),
                gi,
                name,
                "KHR_materials_sheen.sheenRoughnessTexture",
            )?,
        })
    }

    fn anisotropy(
        &mut self,
        e: &Value,
        gi: usize,
        name: &str,
    ) -> Result<crate::scene::Anisotropy, LoadError> {
        let what = "KHR_materials_anisotropy";
        let strength = self.mat_factor(gi, name, e, what, "anisotropyStrength", 0.0, 0.0, 1.0);
        let rotation = self.mat_factor(gi, name, e, what, "anisotropyRotation", 0.0, -1.0e6, 1.0e6);
        Ok(crate::scene::Anisotropy {
            strength,
            rotation,
            texture: self.tex_info(
                member(e, "anisotropyTexture"),
                gi,
                name,
                "KHR_materials_anisotropy.anisotropyTexture",
            )?,
        })
    }

    /// `KHR_materials_volume`: the renderer refracts through every transmissive mesh as a solid
    /// (as Cycles does), so thin-walled (thickness 0) surfaces render as solids, with a note;
    /// attenuation applies inside the mesh (Beer's law). The thickness texture only serves
    /// rasterisers' approximations and is not needed by a path tracer.
    fn volume(
        &mut self,
        e: &Value,
        gi: usize,
        name: &str,
        transmissive: bool,
    ) -> crate::scene::Volume {
        let what = "KHR_materials_volume";
        let thickness = self.mat_factor(gi, name, e, what, "thicknessFactor", 0.0, 0.0, f32::MAX);
        let attenuation_distance = match member(e, "attenuationDistance") {
            None => f32::INFINITY,
            Some(_) => self.mat_factor(
                gi,
                name,
                e,
                what,
                "attenuationDistance",
                f32::INFINITY,
                0.0,
                f32::INFINITY,
            ),
        };
        let attenuation_color = match factors(e, "attenuationColor", [1.0; 3]) {
            Ok(c) => Vec3::from_array(c).max(Vec3::ZERO),
            Err(()) => {
                self.warn_material(
                    gi,
                    name,
                    format!("{what} `attenuationColor` is not three finite numbers; using white"),
                );
                Vec3::ONE
            }
        };
        if transmissive && thickness == 0.0 {
            self.warn_material(
                gi,
                name,
                format!(
                    "{what}: thickness 0 means thin-walled, which is rendered as a solid (transmissive meshes refract as solids)"
                ),
            );
        }
        if transmissive
            && thickness == 0.0
            && attenuation_distance.is_finite()
            && attenuation_color != Vec3::ONE
        {
            self.warn_material(
                gi,
                name,
                format!(
                    "{what}: attenuation (colour {attenuation_color}, distance {attenuation_distance} m) applies only to volumes (thickness > 0); the thin-walled interior renders clear"
                ),
            );
        }
        crate::scene::Volume {
            thickness,
            attenuation_color,
            attenuation_distance,
        }
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
            let in_node = |e: LoadError| {
                LoadError::new(
                    e.kind,
                    format!(
                        "material {gi} (`{name}`), node `{}`: {}",
                        node.name, e.message
                    ),
                )
            };
            node.image = Some(self.graph_image(ii as usize).map_err(in_node)?);
            if let Some(tiles) = node.props.get("tiles") {
                let mut resolved = Vec::new();
                for t in tiles.as_array().into_iter().flatten() {
                    let pair = t.as_array().map(Vec::as_slice);
                    let Some([number, image]) = pair else {
                        return Err(in_node(invalid(
                            "`tiles` entries must be [tile number, image]".into(),
                        )));
                    };
                    let (Some(number), Some(image)) = (number.as_u64(), image.as_u64()) else {
                        return Err(in_node(invalid(
                            "`tiles` entries must be [tile number, image]".into(),
                        )));
                    };
                    let image = self.graph_image(image as usize).map_err(in_node)?;
                    resolved.push((number.min(u32::MAX as u64) as u32, image));
                }
                node.tiles = resolved;
            }
        }
        Ok(graph)
    }

    /// The scene image of entry `ii` of the root `TESELA_images` list when the file has one,
    /// else of glTF image `ii`.
    pub(super) fn graph_image(&mut self, ii: usize) -> Result<usize, LoadError> {
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
        if member(e, "encoded").and_then(Value::as_bool) == Some(true) {
            return self.encoded_image(e, &label);
        }
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

    /// A `TESELA_images` entry holding a whole image file in its bufferView
    /// ([`super::image_file`]); `linearize` asks for float texels to be decoded from sRGB,
    /// `premultiply` for straight float alpha to be associated.
    fn encoded_image(&mut self, e: &Value, label: &str) -> Result<Image, LoadError> {
        let vi = member(e, "bufferView")
            .and_then(Value::as_u64)
            .ok_or_else(|| invalid(format!("{label}: no `bufferView`")))? as usize;
        let (bytes, _) = self
            .reader
            .view(vi, label)
            .map_err(|err| LoadError::new(err.kind, format!("{label}: {}", err.message)))?;
        let associate = member(e, "premultiply").and_then(Value::as_bool) == Some(true);
        let linearize = member(e, "linearize").and_then(Value::as_bool) == Some(true);
        let file = member(e, "file").and_then(Value::as_str).unwrap_or("");
        super::image_file::decode(bytes, associate, linearize).map_err(|err| {
            invalid(format!(
                "{label} (`{file}`): cannot decode the image: {err}"
            ))
        })
    }

    /// A textureInfo (`raw`: its JSON object) of material `gi`'s `slot`: the texture, its
    /// `texCoord` and `KHR_texture_transform` (whose `texCoord` overrides). A missing or
    /// malformed index is an error naming the material and the slot; a malformed `texCoord`
    /// or transform is warned about and ignored.
    fn tex_info(
        &mut self,
        raw: Option<&Value>,
        gi: usize,
        name: &str,
        slot: &str,
    ) -> Result<Option<TexRef>, LoadError> {
        let Some(raw) = raw else { return Ok(None) };
        let ti = member(raw, "index")
            .and_then(Value::as_u64)
            .ok_or_else(|| {
                invalid(format!(
                    "material {gi} (`{name}`) {slot}: `index` is not a non-negative integer"
                ))
            })? as usize;
        let mut texcoord = match member(raw, "texCoord") {
            None => 0,
            Some(v) => match v.as_u64().and_then(|v| u32::try_from(v).ok()) {
                Some(t) => t,
                None => {
                    self.warn_material(
                        gi,
                        name,
                        format!("{slot}: texCoord {v} is not a set index; TEXCOORD_0 is used"),
                    );
                    0
                }
            },
        };
        let mut transform = None;
        if let Some(t) = extension(raw, "KHR_texture_transform") {
            let parsed = (
                factors(t, "offset", [0.0, 0.0]),
                factor(t, "rotation", 0.0),
                factors(t, "scale", [1.0, 1.0]),
            );
            match parsed {
                (Ok(offset), Ok(rotation), Ok(scale)) => {
                    let tr = UvTransform {
                        offset: Vec2::from_array(offset),
                        rotation,
                        scale: Vec2::from_array(scale),
                    };
                    if tr.matrix().iter().all(|x| x.is_finite()) {
                        let identity = offset == [0.0, 0.0] && rotation == 0.0 && scale == [1.0, 1.0];
                        transform = (!identity).then_some(tr);
                    } else {
                        self.warn_material(
                            gi,
                            name,
                            format!("{slot}: KHR_texture_transform overflows; ignored"),
                        );
                    }
                }
                _ => self.warn_material(
                    gi,
                    name,
                    format!(
                        "{slot}: KHR_texture_transform has a malformed or non-finite offset, rotation or scale; ignored"
                    ),
                ),
            }
            if let Some(v) = member(t, "texCoord") {
                match v.as_u64().and_then(|v| u32::try_from(v).ok()) {
                    Some(tc) => texcoord = tc,
                    None => self.warn_material(
                        gi,
                        name,
                        format!(
                            "{slot}: KHR_texture_transform texCoord {v} is not a set index; ignored"
                        ),
                    ),
                }
            }
        }
        let raw_texture = self.raw_item("textures", ti);
        if raw_texture.is_object() && self.texture_source(ti).is_none() {
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
            texcoord,
            transform,
        }))
    }

    /// The image texture `ti` reads: `EXT_texture_webp`'s source when it has one (the
    /// extension's rule: a client that decodes WebP prefers it), else `source`, the fallback.
    fn texture_source(&self, ti: usize) -> Option<usize> {
        let raw = self.raw_item("textures", ti);
        let index = |v: Option<&Value>| v.and_then(Value::as_u64).map(|i| i as usize);
        index(extension(raw, "EXT_texture_webp").and_then(|e| member(e, "source")))
            .or_else(|| index(member(raw, "source")))
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
        let Some(source) = self.texture_source(ti) else {
            return Err(LoadError::new(
                LoadErrorKind::Unsupported,
                format!(
                    "texture {ti} has no `source` (only an extension's image format, which is not supported)"
                ),
            ));
        };
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
            .image(source)
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
