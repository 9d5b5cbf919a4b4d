//! The renderer's scene description: everything the loaders produce and the renderer consumes.
//!
//! All geometry is flattened to **world space** (right-handed, +Y up as in glTF, metres).
//! Colours are **linear** RGB; radiometric quantities are in watts (W/sr for intensity,
//! W/m² for irradiance, W/(m² sr) for radiance).

pub mod builtin;
pub mod error;
pub mod gltf;
pub mod gltf_write;

pub use error::{LoadError, LoadErrorKind};

use glam::{Mat4, Vec2, Vec3};
use std::sync::Arc;

/// A triangle mesh in world space with one material.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub name: String,
    /// Vertex positions, world space.
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals, world space, unit length (may be empty: then the
    /// geometric normal is used everywhere).
    pub normals: Vec<Vec3>,
    /// Per-vertex texture coordinates (set 0); may be empty.
    pub uvs: Vec<Vec2>,
    /// Counter-clockwise triangles (front face by the right-hand rule, after any
    /// negative-determinant transform has been compensated by the loader).
    pub indices: Vec<[u32; 3]>,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Camera rays pass through this mesh (a Blender light with camera visibility off);
    /// every other ray sees it.
    pub hidden_from_camera: bool,
    /// What shading reads beyond positions, normals and the first UV set.
    pub attrs: MeshAttributes,
}

/// Per-object data the shading graph can read (Blender's Object Info node).
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectInfo {
    /// Blender's per-object random number in `[0, 1)`.
    pub random: f32,
    pub pass_index: f32,
    pub color: glam::Vec4,
    /// Object origin, renderer world space.
    pub location: Vec3,
}

impl Default for ObjectInfo {
    fn default() -> Self {
        ObjectInfo {
            random: 0.0,
            pass_index: 0.0,
            color: glam::Vec4::ONE,
            location: Vec3::ZERO,
        }
    }
}

/// Vertex attributes and object data beyond the basics; everything may be empty.
#[derive(Clone, Debug)]
pub struct MeshAttributes {
    /// Names of the UV sets: `uv_names[0]` names [`Mesh::uvs`], `uv_names[k]` names
    /// `extra_uvs[k - 1]` (may be shorter than the sets: unnamed).
    pub uv_names: Vec<String>,
    /// UV sets 1, 2, ... (glTF convention: `(0, 0)` is the image's top-left corner).
    pub extra_uvs: Vec<Vec<Vec2>>,
    /// Vertex colours (linear RGBA), with their names.
    pub colors: Vec<(String, Vec<glam::Vec4>)>,
    /// Per-vertex tangents, world space: `xyz` unit tangent along +u, `w` the bitangent sign
    /// (MikkTSpace, for UV set 0). Empty when the mesh has none.
    pub tangents: Vec<glam::Vec4>,
    /// World → object space (the space of the node's mesh data).
    pub to_object: Mat4,
    /// Texture space (Generated coordinates): `(location, size)` in object space; generated
    /// coordinates are `(p_object - location) / size · ½ + ½`.
    pub texspace: Option<(Vec3, Vec3)>,
    pub object: ObjectInfo,
}

impl Default for MeshAttributes {
    fn default() -> Self {
        MeshAttributes {
            uv_names: Vec::new(),
            extra_uvs: Vec::new(),
            colors: Vec::new(),
            tangents: Vec::new(),
            to_object: Mat4::IDENTITY,
            texspace: None,
            object: ObjectInfo::default(),
        }
    }
}

impl Mesh {
    /// The three vertex indices of triangle `tri`.
    #[inline(always)]
    pub fn corners(&self, tri: u32) -> [usize; 3] {
        let [a, b, c] = self.indices[tri as usize];
        [a as usize, b as usize, c as usize]
    }

    /// Barycentric interpolation `a·b0 + b·b1 + c·b2` of a per-vertex attribute at triangle
    /// `tri` with barycentrics `(b1, b2)`; `None` when the attribute is empty. The one place
    /// where vertex attributes are interpolated.
    #[inline(always)]
    pub fn interpolate<T>(&self, data: &[T], tri: u32, b1: f32, b2: f32) -> Option<T>
    where
        T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
    {
        if data.is_empty() {
            return None;
        }
        let [i0, i1, i2] = self.corners(tri);
        let b0 = 1.0 - b1 - b2;
        Some(data[i0] * b0 + data[i1] * b1 + data[i2] * b2)
    }

    /// Interpolated unit shading normal, or `None` without vertex normals (or where they cancel).
    #[inline(always)]
    pub fn shading_normal(&self, tri: u32, b1: f32, b2: f32) -> Option<Vec3> {
        let s = self.interpolate(&self.normals, tri, b1, b2)?;
        let l = s.length();
        (l > 1e-12 && l.is_finite()).then(|| s / l)
    }

    /// UV set `set` (glTF convention), zero where the mesh has none.
    #[inline]
    pub fn uv(&self, set: usize, tri: u32, b1: f32, b2: f32) -> Vec2 {
        let data = if set == 0 {
            &self.uvs[..]
        } else {
            self.attrs
                .extra_uvs
                .get(set - 1)
                .map_or(&[][..], |v| &v[..])
        };
        self.interpolate(data, tri, b1, b2).unwrap_or(Vec2::ZERO)
    }

    /// The index of the UV set called `name` (`""`: set 0).
    pub fn uv_set(&self, name: &str) -> Option<usize> {
        if name.is_empty() {
            return Some(0);
        }
        self.attrs.uv_names.iter().position(|n| n == name)
    }
}

/// How a texture is sampled at a texel boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    #[default]
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

/// A decoded image, rows top to bottom (as in PNG/JPEG files): 8-bit RGBA (`rgba8`), or
/// linear float RGBA (`float`) for high-dynamic-range and 16-bit data; one of the two is empty.
#[derive(Clone, Debug, Default)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<[u8; 4]>,
    pub float: Vec<[f32; 4]>,
}

/// A texture: an image and how to sample it.
#[derive(Clone, Debug)]
pub struct Texture {
    /// Index into [`Scene::images`].
    pub image: usize,
    pub wrap_s: Wrap,
    pub wrap_t: Wrap,
    /// Nearest-texel magnification (glTF NEAREST); otherwise bilinear.
    pub nearest: bool,
}

/// A material's reference to a texture.
#[derive(Clone, Copy, Debug)]
pub struct TexRef {
    /// Index into [`Scene::textures`].
    pub texture: usize,
    /// Which TEXCOORD set (only 0 is loaded; others fall back to 0).
    pub texcoord: u32,
}

/// glTF metallic-roughness material with the KHR extensions Tesela understands.
#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    /// Linear base colour factor (RGB); alpha is ignored.
    pub base_color: Vec3,
    /// sRGB-encoded base colour texture, multiplied with `base_color`.
    pub base_color_texture: Option<TexRef>,
    pub metallic: f32,
    /// Perceptual roughness in [0, 1] (GGX alpha = roughness²).
    pub roughness: f32,
    /// Linear texture: roughness in G, metallic in B.
    pub metallic_roughness_texture: Option<TexRef>,
    /// Emitted radiance, W/(m² sr): `emissiveFactor * KHR_materials_emissive_strength`.
    pub emission: Vec3,
    /// sRGB-encoded emissive texture, multiplied with `emission`.
    pub emission_texture: Option<TexRef>,
    /// Whether emission leaves both faces (glTF `doubleSided`, or `TESELA_emission.two_sided`).
    pub emission_two_sided: bool,
    /// `KHR_materials_transmission` factor in [0, 1].
    pub transmission: f32,
    /// `KHR_materials_ior` (default 1.5).
    pub ior: f32,
    /// `KHR_materials_specular` specularFactor (default 1; 0 = purely Lambertian dielectric).
    pub specular: f32,
    /// `KHR_materials_specular` specularColorFactor (linear).
    pub specular_color: Vec3,
    /// glTF `doubleSided`.
    pub double_sided: bool,
    /// The material's node graph (`TESELA_material_graph`); without one, the renderer shades
    /// with the glTF metallic-roughness preset graph built from the factors above.
    pub graph: Option<Arc<crate::shading::Graph>>,
}

impl Default for Material {
    /// The glTF default material: white, fully metallic, fully rough.
    fn default() -> Self {
        Material {
            name: "default".into(),
            base_color: Vec3::ONE,
            base_color_texture: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            emission: Vec3::ZERO,
            emission_texture: None,
            emission_two_sided: false,
            transmission: 0.0,
            ior: 1.5,
            specular: 1.0,
            specular_color: Vec3::ONE,
            double_sided: false,
            graph: None,
        }
    }
}

impl Material {
    /// A white Lambertian material (used by built-in scenes and tests).
    pub fn diffuse(name: &str, color: Vec3) -> Self {
        Material {
            name: name.into(),
            base_color: color,
            metallic: 0.0,
            roughness: 1.0,
            specular: 0.0,
            ..Default::default()
        }
    }

    /// A perfect mirror (metallic 1, roughness 0).
    pub fn mirror(name: &str, color: Vec3) -> Self {
        Material {
            name: name.into(),
            base_color: color,
            metallic: 1.0,
            roughness: 0.0,
            ..Default::default()
        }
    }

    /// An ideal dielectric (transmission 1, roughness 0).
    pub fn glass(name: &str, ior: f32) -> Self {
        Material {
            name: name.into(),
            base_color: Vec3::ONE,
            metallic: 0.0,
            roughness: 0.0,
            transmission: 1.0,
            ior,
            ..Default::default()
        }
    }

    /// A black Lambertian emitter of radiance `radiance`.
    pub fn emitter(name: &str, radiance: Vec3, two_sided: bool) -> Self {
        Material {
            emission: radiance,
            emission_two_sided: two_sided,
            double_sided: two_sided,
            ..Material::diffuse(name, Vec3::ZERO)
        }
    }

    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }
}

/// How a spot light falls off between its inner and outer cone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpotFalloff {
    /// glTF KHR_lights_punctual: `clamp((cos θ - cos_outer) / (cos_inner - cos_outer), 0, 1)²`.
    Gltf { cos_inner: f32, cos_outer: f32 },
    /// Cycles: `smoothstep(0, 1, (cos θ - cos_half) / smooth)` with
    /// `smooth = (1 - cos_half) * blend`; a hard edge when `smooth` is 0.
    Cycles { cos_half: f32, smooth: f32 },
}

/// Lights other than emissive meshes (those are found from their materials).
#[derive(Clone, Debug)]
pub enum Light {
    /// Isotropic point light of radiant intensity `intensity` (W/sr).
    Point { position: Vec3, intensity: Vec3 },
    /// Spot light: `intensity` (W/sr) on its axis `direction` (unit, pointing away from the light).
    Spot {
        position: Vec3,
        direction: Vec3,
        intensity: Vec3,
        falloff: SpotFalloff,
    },
    /// Directional light: light travels along `direction` (unit); `irradiance` (W/m²) on a
    /// surface facing it. `angle` is the angular diameter of the source (radians, 0 = delta).
    Directional {
        direction: Vec3,
        irradiance: Vec3,
        angle: f32,
    },
}

/// Camera projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Vertical field of view in radians.
    Perspective { yfov: f32 },
    /// Half-height of the view volume in metres.
    Orthographic { ymag: f32 },
}

/// A camera looking down its local -Z with +Y up (glTF convention).
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    pub projection: Projection,
    /// Camera-to-world transform (rigid; scale is removed by the loader).
    pub to_world: Mat4,
    /// The file's aspect ratio (width/height), if it states one.
    pub aspect: Option<f32>,
}

/// Render settings a scene file may carry (the add-on's `TESELA_render` extension).
/// The CLI's options override each of them.
#[derive(Clone, Debug, Default)]
pub struct RenderSettings {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub spp: Option<u32>,
    pub max_depth: Option<u32>,
    pub seed: Option<u64>,
    pub integrator: Option<String>,
}

/// A complete scene.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    pub images: Vec<Image>,
    pub lights: Vec<Light>,
    pub camera: Option<Camera>,
    /// Constant background radiance seen by rays that leave the scene, W/(m² sr).
    pub background: Vec3,
    pub settings: RenderSettings,
    /// Non-fatal problems found while loading (unknown optional extensions, skipped primitives...).
    pub warnings: Vec<String>,
}

impl Scene {
    /// Axis-aligned bounds of all mesh vertices, or `None` for a scene without geometry.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        let mut any = false;
        for m in &self.meshes {
            for p in &m.positions {
                lo = lo.min(*p);
                hi = hi.max(*p);
                any = true;
            }
        }
        any.then_some((lo, hi))
    }

    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.indices.len()).sum()
    }
}
