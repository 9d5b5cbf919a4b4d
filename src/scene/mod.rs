//! The renderer's scene description: everything the loaders produce and the renderer consumes.
//!
//! Geometry is in **world space** (right-handed, +Y up as in glTF, metres), except the meshes
//! that [`Scene::instances`] place: those are in their own object space and are seen only
//! through their instances' transforms (see [`instance`]).
//! Colours are **linear** RGB; radiometric quantities are in watts (W/sr for intensity,
//! W/m² for irradiance, W/(m² sr) for radiance).

pub mod builtin;
pub mod curves;
pub mod error;
pub mod gltf;
pub mod gltf_write;
pub mod instance;
pub mod points;
pub mod world;

pub use error::{LoadError, LoadErrorKind};
pub use instance::Instance;
pub use world::{World, WorldSampling};

use glam::{Mat4, Vec2, Vec3};
use std::sync::Arc;

/// A triangle mesh with one material, in world space, or in object space when instances
/// place it (see [`Scene::instances`]); "world space" below means the mesh's space.
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
    /// The kinds of rays that see the object (Blender's Object > Visibility > Ray Visibility),
    /// as Light Path bits of [`crate::shading::globals::ray`]: `CAMERA`, `DIFFUSE`, `GLOSSY`,
    /// `TRANSMISSION` for the rays scattered by those closures, and `SHADOW` for shadow rays
    /// (off: it casts no shadow). Rays of other kinds pass through it, as in Cycles.
    pub visibility: u32,
    /// Blender's Object > Visibility > Holdout: camera rays (straight or through transparent
    /// surfaces) see a hole in the film where they meet the object (alpha 0 with a
    /// transparent film, black with an opaque one); every other ray sees its material.
    pub holdout: bool,
    /// Blender's Object > Visibility > Shadow Catcher: where camera rays first meet it, the
    /// film keeps only the shadows and reflections other objects cast on it
    /// ([`crate::film::catcher`]); every other ray sees it as an ordinary object.
    pub shadow_catcher: bool,
    /// The object is strands built as closed tubes ([`crate::scene::curves`]): rays leaving
    /// a tube pass through its wall, as Cycles' rays leave the curve they start on (light
    /// through a fibre, shadow rays from it).
    pub strands: bool,
    /// Blender's light and shadow linking of the object, as receiver, blocker and emitter.
    pub links: LightLinks,
    /// The particle an instance was placed by (Particle Info); `None` for other objects,
    /// which read Cycles' all-zero particle.
    pub particle: Option<Box<Particle>>,
    /// The Attribute node's object and instancer attributes the object's materials read.
    pub attributes: Option<Box<ObjectAttributes>>,
}

/// Values of the Attribute node's Object and Instancer types, as Cycles looks them up for
/// one object (custom properties and property paths, as RGBA; a name not found reads zero).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjectAttributes {
    /// Type Object: looked up on the object, then its data.
    pub object: Vec<(String, glam::Vec4)>,
    /// Type Instancer: looked up on an instance's particle settings and instancer first.
    pub instancer: Vec<(String, glam::Vec4)>,
}

impl ObjectAttributes {
    /// The value of `name` for the Object (`instancer` false) or Instancer type.
    pub fn get(&self, name: &str, instancer: bool) -> Option<glam::Vec4> {
        let list = if instancer {
            &self.instancer
        } else {
            &self.object
        };
        list.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
    }
}

/// One particle of a Blender particle system, as the Particle Info node reads it. Vectors in
/// Blender's world coordinates, times in frames.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Particle {
    /// The particle's index in its system.
    pub index: u32,
    /// Frames since its birth (the render frame minus its birth time).
    pub age: f32,
    pub lifetime: f32,
    pub location: Vec3,
    pub size: f32,
    pub velocity: Vec3,
    pub angular_velocity: Vec3,
}

/// Blender's light and shadow linking resolved into sets, as Cycles groups objects: objects
/// with the same link states in every receiver collection form one receiver set (set 0: the
/// objects no receiver collection names), likewise blocker sets; an emitter lights the
/// receiver sets whose bit is in `lights`, and of the objects on a shadow ray towards it only
/// those of a blocker set in `shadowed_by` block it. [`LightLinks::default`]: no linking.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightLinks {
    pub receiver_set: u8,
    pub blocker_set: u8,
    pub lights: u64,
    pub shadowed_by: u64,
}

impl LightLinks {
    /// Every set.
    pub const ALL: u64 = u64::MAX;
}

impl Default for LightLinks {
    fn default() -> Self {
        LightLinks {
            receiver_set: 0,
            blocker_set: 0,
            lights: LightLinks::ALL,
            shadowed_by: LightLinks::ALL,
        }
    }
}

impl ObjectInfo {
    /// Every kind of ray sees the object.
    pub const VISIBLE_TO_ALL: u32 = crate::shading::globals::ray::CAMERA
        | crate::shading::globals::ray::SHADOW
        | crate::shading::globals::ray::DIFFUSE
        | crate::shading::globals::ray::GLOSSY
        | crate::shading::globals::ray::TRANSMISSION;
}

impl Default for ObjectInfo {
    fn default() -> Self {
        ObjectInfo {
            random: 0.0,
            pass_index: 0.0,
            color: glam::Vec4::ONE,
            location: Vec3::ZERO,
            visibility: ObjectInfo::VISIBLE_TO_ALL,
            holdout: false,
            shadow_catcher: false,
            links: LightLinks::default(),
            particle: None,
            attributes: None,
            strands: false,
        }
    }
}

/// Vertex attributes and object data beyond the basics; everything may be empty.
#[derive(Clone, Debug)]
pub struct MeshAttributes {
    /// Names of the UV sets: `uv_names[0]` names [`Mesh::uvs`], `uv_names[k]` names
    /// `extra_uvs[k - 1]` (may be shorter than the sets: unnamed).
    pub uv_names: Vec<String>,
    /// UV sets 1, 2, ... (glTF convention: `(0, 0)` is the image's top-left corner); a set
    /// the file lacks, or that nothing reads, is empty.
    pub extra_uvs: Vec<Vec<Vec2>>,
    /// Vertex colours (linear RGBA), with their names.
    pub colors: Vec<(String, Vec<glam::Vec4>)>,
    /// Per-vertex tangents, world space: `xyz` unit tangent along +u, `w` the bitangent sign:
    /// the bitangent `w · cross(normal, tangent)` points along +v in Blender's UV convention
    /// (towards the image's top row, glTF's "+Y up" of normal maps). For the UV set of the
    /// material's normal map (set 0 unless its `texCoord` says otherwise): the file's TANGENT,
    /// else MikkTSpace. Empty when the mesh has none.
    pub tangents: Vec<glam::Vec4>,
    /// World → object space (the space of the node's mesh data).
    pub to_object: Mat4,
    /// Texture space (Generated coordinates): `(location, size)` in object space; generated
    /// coordinates are `(p_object - location) / size · ½ + ½`.
    pub texspace: Option<(Vec3, Vec3)>,
    /// Per-vertex object-space positions before the object's deform modifiers and shape keys
    /// (Blender's undeformed coordinates, which Generated coordinates use); empty when they
    /// are the positions themselves.
    pub orco: Vec<Vec3>,
    pub object: ObjectInfo,
}

/// The vertex colour layer that carries [`MeshAttributes::orco`] in a file (the add-on
/// writes it; it is not a colour the graph can read).
pub const ORCO_LAYER: &str = "tesela:orco";

impl Default for MeshAttributes {
    fn default() -> Self {
        MeshAttributes {
            uv_names: Vec::new(),
            extra_uvs: Vec::new(),
            colors: Vec::new(),
            tangents: Vec::new(),
            to_object: Mat4::IDENTITY,
            texspace: None,
            orco: Vec::new(),
            object: ObjectInfo::default(),
        }
    }
}

impl Mesh {
    /// Axis-aligned bounds of the vertices, `None` without any.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let lo = self.positions.iter().fold(Vec3::INFINITY, |l, p| l.min(*p));
        let hi = (self.positions.iter()).fold(Vec3::NEG_INFINITY, |h, p| h.max(*p));
        lo.cmple(hi).all().then_some((lo, hi))
    }

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

    /// UV set `set` (glTF convention): set 0 where the mesh lacks set `set` (the loader warns
    /// when a material reads a set its mesh does not have), zero where it has no UVs at all.
    #[inline]
    pub fn uv(&self, set: usize, tri: u32, b1: f32, b2: f32) -> Vec2 {
        let data = match set.checked_sub(1).and_then(|k| self.attrs.extra_uvs.get(k)) {
            Some(v) if !v.is_empty() => &v[..],
            _ => &self.uvs[..],
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
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexRef {
    /// Index into [`Scene::textures`].
    pub texture: usize,
    /// Which TEXCOORD set (after `KHR_texture_transform`'s `texCoord` override).
    pub texcoord: u32,
    /// `KHR_texture_transform`, applied to the texture coordinate before the lookup.
    pub transform: Option<UvTransform>,
}

/// `KHR_texture_transform`: `uv' = T(offset) · R(rotation) · S(scale) · uv` in glTF's UV
/// convention (`(0, 0)` top-left), with the extension's rotation matrix
/// `[cos, sin; -sin, cos]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    pub offset: Vec2,
    pub rotation: f32,
    pub scale: Vec2,
}

impl UvTransform {
    /// The 2×3 matrix, row-major: `u' = m[0] u + m[1] v + m[2]`, `v' = m[3] u + m[4] v + m[5]`.
    pub fn matrix(&self) -> [f32; 6] {
        let (s, c) = self.rotation.sin_cos();
        let (sx, sy) = (self.scale.x, self.scale.y);
        [
            c * sx,
            s * sy,
            self.offset.x,
            -s * sx,
            c * sy,
            self.offset.y,
        ]
    }

    /// `uv'` for `uv`.
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let m = self.matrix();
        Vec2::new(
            m[0] * uv.x + m[1] * uv.y + m[2],
            m[3] * uv.x + m[4] * uv.y + m[5],
        )
    }
}

/// glTF `alphaMode`: how the base colour's alpha becomes coverage (the Principled `Alpha`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored: fully opaque.
    #[default]
    Opaque,
    /// Alpha `>= cutoff` is opaque, below it fully transparent (exactly 1 or 0).
    Mask { cutoff: f32 },
    /// Alpha is partial coverage.
    Blend,
}

/// `KHR_materials_clearcoat` (Principled coat inputs; coat IOR 1.5 as the extension fixes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearcoat {
    pub factor: f32,
    /// Linear; R times `factor`.
    pub texture: Option<TexRef>,
    pub roughness: f32,
    /// Linear; G times `roughness`.
    pub roughness_texture: Option<TexRef>,
    /// Tangent-space normal map of the coat, with its `scale`.
    pub normal_texture: Option<TexRef>,
    pub normal_scale: f32,
}

/// `KHR_materials_sheen` (Principled sheen: weight 1, tint = sheen colour).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sheen {
    pub color: Vec3,
    /// sRGB; RGB times `color`.
    pub color_texture: Option<TexRef>,
    pub roughness: f32,
    /// Linear; A times `roughness`.
    pub roughness_texture: Option<TexRef>,
}

/// `KHR_materials_anisotropy` (Principled anisotropic inputs and tangent).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anisotropy {
    /// In `[0, 1]`.
    pub strength: f32,
    /// Radians, counter-clockwise from the tangent towards the bitangent.
    pub rotation: f32,
    /// Linear: RG the direction in tangent space (`2c - 1`), B times `strength`.
    pub texture: Option<TexRef>,
}

/// `KHR_materials_volume`: the renderer refracts through transmissive meshes as solids
/// whatever the thickness, and attenuates light inside them by Beer's law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Volume {
    /// 0 = thin-walled.
    pub thickness: f32,
    /// The colour white light becomes after `attenuation_distance` inside.
    pub attenuation_color: Vec3,
    /// Metres; infinite = no attenuation.
    pub attenuation_distance: f32,
}

impl Volume {
    /// The interior's absorption coefficient, 1/m: `σ_a = -ln(c) / d` per channel (the
    /// extension's definition), zero for thin-walled or non-attenuating volumes. A colour
    /// channel of 0 (an infinite coefficient) is taken as 1e-6.
    pub fn absorption(&self) -> Vec3 {
        let d = self.attenuation_distance;
        if self.thickness <= 0.0 || !d.is_finite() || d <= 0.0 {
            return Vec3::ZERO;
        }
        let c = self.attenuation_color.clamp(Vec3::splat(1e-6), Vec3::ONE);
        Vec3::new(-c.x.ln(), -c.y.ln(), -c.z.ln()) / d
    }
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
    /// Base colour factor alpha.
    pub alpha: f32,
    pub alpha_mode: AlphaMode,
    /// The mesh's COLOR_0 (the first colour set) multiplies the base colour and alpha (set by
    /// the loader on the variant of a glTF material used by primitives with COLOR_0).
    pub vertex_color: bool,
    /// Tangent-space normal map (linear), with glTF's `scale` on its X and Y.
    pub normal_texture: Option<TexRef>,
    pub normal_scale: f32,
    /// `KHR_materials_transmission` texture: R times `transmission`.
    pub transmission_texture: Option<TexRef>,
    /// `KHR_materials_specular` textures: A times `specular`; sRGB RGB times `specular_color`.
    pub specular_texture: Option<TexRef>,
    pub specular_color_texture: Option<TexRef>,
    pub clearcoat: Option<Clearcoat>,
    pub sheen: Option<Sheen>,
    pub anisotropy: Option<Anisotropy>,
    pub volume: Option<Volume>,
    /// The material's node graph (`TESELA_material_graph`); without one, the renderer shades
    /// with the glTF metallic-roughness preset graph built from the factors above.
    pub graph: Option<Arc<crate::shading::Graph>>,
    /// Blender's material pass index (the Material Index pass).
    pub pass_index: u32,
    /// `KHR_materials_unlit`: the base colour shown unshaded to the camera (see
    /// [`crate::shading::preset`]).
    pub unlit: bool,
    /// `KHR_materials_pbrSpecularGlossiness`'s texture when it varies the roughness: roughness
    /// = 1 − glossinessFactor × its alpha.
    pub glossiness_texture: Option<TexRef>,
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
            alpha: 1.0,
            alpha_mode: AlphaMode::Opaque,
            vertex_color: false,
            normal_texture: None,
            normal_scale: 1.0,
            transmission_texture: None,
            specular_texture: None,
            specular_color_texture: None,
            clearcoat: None,
            sheen: None,
            anisotropy: None,
            volume: None,
            graph: None,
            pass_index: 0,
            unlit: false,
            glossiness_texture: None,
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
    /// Cycles' falloff for a spot whose object is scaled unevenly: `cos θ` is taken of the
    /// direction in the light's own unscaled space, `normalize(local · w)`'s z for a world
    /// direction `w` leaving the light (rows of `local`: the light's x, y axes and its beam
    /// axis, each over its scale), so the cone is elliptic or wider or narrower than its size.
    CyclesScaled {
        cos_half: f32,
        smooth: f32,
        local: glam::Mat3,
    },
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
    /// A Blender light (`TESELA_light`): its shape with Cycles' parameters, which rays see it,
    /// and the IES profile its node tree applies, if any.
    Blender {
        shape: LightShape,
        visibility: LightVisibility,
        profile: Option<LightProfile>,
    },
}

/// An IES profile on a light: its emitted radiance towards world direction `w` (leaving the
/// light) is multiplied by `profile.towards(to_local · w)`, `to_local` the transpose of the
/// light node's world matrix (Cycles takes the direction into light object space as a normal).
#[derive(Clone, Debug)]
pub struct LightProfile {
    pub profile: std::sync::Arc<crate::emitter::ies::IesProfile>,
    pub to_local: glam::Mat3,
}

/// The shape of a Blender light, with the parameters Cycles renders it from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightShape {
    /// Point or spot light of radiant intensity `intensity` (W/sr). `radius` 0 is a delta light;
    /// otherwise Cycles' shapes of radiance `intensity / (π radius²)`: a sphere, or with
    /// `soft_falloff` (Blender's default) a disk of that radius always facing the lit point.
    Point {
        position: Vec3,
        intensity: Vec3,
        radius: f32,
        soft_falloff: bool,
        /// A spot's axis (unit, pointing away from the light) and falloff.
        spot: Option<(Vec3, SpotFalloff)>,
    },
    /// Sun: light travels along `direction` (unit); `irradiance` (W/m²) on a surface facing it,
    /// from a cone of directions of angular diameter `angle` (radians, 0 = delta).
    Sun {
        direction: Vec3,
        irradiance: Vec3,
        angle: f32,
    },
    /// Rectangle (`ellipse` false) or ellipse centred on `center`, spanned by the orthonormal
    /// `axis_u`, `axis_v` over `size_u × size_v` metres, emitting radiance `radiance` towards
    /// the side of the unit `normal` only, collimated by `spread` (radians, full angle; π = a
    /// Lambertian emitter, 0 = a parallel beam along the normal).
    Area {
        center: Vec3,
        axis_u: Vec3,
        axis_v: Vec3,
        normal: Vec3,
        size_u: f32,
        size_v: f32,
        ellipse: bool,
        radiance: Vec3,
        spread: f32,
    },
}

/// Which rays see a Blender light (Blender's Object > Visibility > Ray Visibility and the
/// light's own settings, as Cycles applies them). A Blender light is never an occluder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightVisibility {
    /// Camera rays see the light's shape.
    pub camera: bool,
    /// The light reaches diffuse / glossy (reflection) / transmission closures, by emitter
    /// sampling and by rays those closures scatter.
    pub diffuse: bool,
    pub glossy: bool,
    pub transmission: bool,
    /// Shadow rays test occlusion ("Cast Shadow"); without, the light reaches every point it
    /// faces.
    pub cast_shadow: bool,
    /// Rays scattered by surfaces hit the light's shape, weighted against emitter sampling
    /// (Cycles' "Multiple Importance"); without, only emitter sampling reaches it.
    pub mis: bool,
}

impl Default for LightVisibility {
    fn default() -> Self {
        LightVisibility {
            camera: true,
            diffuse: true,
            glossy: true,
            transmission: true,
            cast_shadow: true,
            mis: true,
        }
    }
}

/// Camera projection. Camera space: looking down -Z, +Y up, +X right (glTF; the same axes as a
/// Blender camera object's local space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Pinhole or thin lens. `yfov` is the full angle, in radians, that the image dimension
    /// chosen by [`Camera::fit`] spans: the height for glTF cameras ([`SensorFit::Vertical`]);
    /// for a Blender camera `2 atan(sensor / (2 lens))`.
    Perspective { yfov: f32 },
    /// Parallel projection. `ymag` is half the extent, in metres, of the image dimension chosen
    /// by [`Camera::fit`] (glTF `ymag`; Blender `ortho_scale / 2`).
    Orthographic { ymag: f32 },
    /// A panoramic camera (Blender/Cycles `PANO`).
    Panoramic(Panorama),
}

/// Which image dimension a camera's field of view (or orthographic extent) spans, Blender's
/// `sensor_fit`; the other dimension follows from the image aspect ratio.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SensorFit {
    /// The width if the image is wider than tall, else the height (Blender's AUTO).
    Auto,
    Horizontal,
    /// The height (glTF).
    #[default]
    Vertical,
}

impl SensorFit {
    /// Whether the fitted dimension is the width of an image `aspect` times wider than tall
    /// (its physical shape: pixels × pixel aspect).
    #[inline]
    pub fn is_horizontal(self, aspect: f32) -> bool {
        match self {
            SensorFit::Auto => aspect > 1.0,
            SensorFit::Horizontal => true,
            SensorFit::Vertical => false,
        }
    }
}

/// Panoramic projections as Cycles defines them. Image coordinates `(u, v)` run over
/// `[0, 1]²` from the bottom-left corner (plus the lens shift); directions are given in
/// Cycles' panorama space (+X the view axis, +Y left, +Z up), which is camera space
/// `(-y, z, -x)`. Angles in radians, lengths in millimetres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Panorama {
    /// Longitude `lon_min + u (lon_max - lon_min)` (positive to the right), latitude
    /// `lat_min + v (lat_max - lat_min)` (positive up).
    Equirectangular {
        latitude_min: f32,
        latitude_max: f32,
        longitude_min: f32,
        longitude_max: f32,
    },
    /// Angle from the view axis `θ = r · fov / 2`, `r` the distance from the image centre in
    /// units of the half width and half height (an ellipse on a non-square image); black
    /// outside `r = 1`.
    FisheyeEquidistant { fov: f32 },
    /// `r = 2 lens sin(θ / 2)` on a sensor of `sensor` mm across the fitted dimension
    /// ([`Camera::fit`]; Blender: `sensor_width`, or `sensor_height` for VERTICAL); black
    /// beyond `θ = fov / 2`.
    FisheyeEquisolid { fov: f32, lens: f32, sensor: f32 },
    /// `θ = -(k0 + k1 r + k2 r² + k3 r³ + k4 r⁴)`, `r` in mm on the sensor as for
    /// [`Panorama::FisheyeEquisolid`]; black beyond `|θ| = fov / 2`.
    FisheyeLensPolynomial { fov: f32, sensor: f32, k: [f32; 5] },
    /// A mirror ball filling the image's inscribed ellipse (Cycles' `mirrorball_to_direction`,
    /// in its mirror-ball space: `(x, y, z)` is camera space `(x, z, y)`); black outside it.
    Mirrorball,
    /// One face of an equiangular cube map (90° across each axis).
    EquiangularCubemapFace,
    /// Azimuth `-(u_min + u (u_max - u_min))` around the up axis, height
    /// `v_min + v (v_max - v_min)` on a cylinder of radius 1 (Blender's ranges divided by its
    /// radius).
    CentralCylindrical {
        u_min: f32,
        u_max: f32,
        v_min: f32,
        v_max: f32,
    },
}

/// A thin lens (depth of field), sampled as Cycles samples it: a point `a` on the unit disk
/// (concentric map) or on the regular polygon of `blades ≥ 3` corners inscribed in the unit
/// circle, rotated by `rotation`, then `a.x /= ratio`; the ray leaves the lens at
/// `radius · a` (camera space, on the lens plane z = 0) towards the point where the pinhole
/// ray of the pixel meets the plane in focus.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aperture {
    /// Lens radius in metres (Blender: `lens · 1e-3 / (2 f-stop)`; orthographic cameras
    /// `1 / (2 f-stop)`, as Cycles does).
    pub radius: f32,
    /// Metres from the lens to the plane in focus along the view axis (perspective and
    /// orthographic), or to the sphere in focus (panoramic).
    pub focus_distance: f32,
    /// 0 = a round aperture; otherwise at least 3.
    pub blades: u32,
    /// Rotation of the polygon, radians, counter-clockwise seen from behind the camera.
    pub rotation: f32,
    /// Anamorphic ratio: the aperture's horizontal size is divided by it (`> 0`).
    pub ratio: f32,
}

/// A camera looking down its local -Z with +Y up (glTF convention).
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    pub projection: Projection,
    /// Camera-to-world transform (rigid; scale is removed by the loader).
    pub to_world: Mat4,
    /// The file's aspect ratio (width/height), if it states one.
    pub aspect: Option<f32>,
    /// A pixel's width over its height (Blender's `pixel_aspect_x / pixel_aspect_y`): the
    /// image's shape, which fits and shapes the view, is `width · pixel_aspect : height`.
    pub pixel_aspect: f32,
    /// The image dimension `projection`'s extent spans.
    pub fit: SensorFit,
    /// Lens shift (Blender `shift_x`, `shift_y`): the image window moves right and up by these
    /// fractions of the fitted dimension's extent (panoramic cameras: `u` and `v` move by them).
    pub shift: Vec2,
    /// Clip distances in metres along the view axis, as Cycles applies them: a camera ray
    /// starts where the pinhole ray of its pixel crosses the plane `z = -clip_start` (at
    /// `clip_start` along the ray for panoramic cameras) and ends at `clip_end` the same way.
    /// A glTF camera's `znear`/`zfar` (0 and infinity without them).
    pub clip_start: f32,
    pub clip_end: f32,
    /// Depth of field; `None` = a pinhole.
    pub aperture: Option<Aperture>,
}

impl Default for Camera {
    /// A 40° pinhole at the origin (vertical fit, no shift, no clipping).
    fn default() -> Self {
        Camera {
            projection: Projection::Perspective {
                yfov: 40f32.to_radians(),
            },
            to_world: Mat4::IDENTITY,
            aspect: None,
            pixel_aspect: 1.0,
            fit: SensorFit::Vertical,
            shift: Vec2::ZERO,
            clip_start: 0.0,
            clip_end: f32::INFINITY,
            aperture: None,
        }
    }
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
    /// Blender's `render.film_transparent`: camera rays that see only the world give alpha 0
    /// (and no colour).
    pub film_transparent: bool,
    /// Cycles' Film > Transparent Glass (`cycles.film_transparent_glass`), with its roughness
    /// threshold (`cycles.film_transparent_roughness`): with a transparent film, the world seen
    /// through transmission no rougher than the threshold (and through transparent surfaces)
    /// is transparent too. `None`: off.
    pub film_transparent_glass: Option<f32>,
    /// The world's mist settings (the Mist pass).
    pub mist: Mist,
}

/// Blender's `world.mist_settings`: mist grows from `start` over `depth` metres of camera
/// distance with exponent `falloff` (quadratic 2, linear 1, inverse quadratic 0.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mist {
    pub start: f32,
    pub depth: f32,
    pub falloff: f32,
}

impl Default for Mist {
    /// Blender's defaults: start 5 m, depth 25 m, quadratic.
    fn default() -> Self {
        Mist {
            start: 5.0,
            depth: 25.0,
            falloff: 2.0,
        }
    }
}

impl Mist {
    /// The mist amount in `[0, 1]` at camera distance `dist` (Cycles' formula).
    pub fn amount(&self, dist: f32) -> f32 {
        let inv_depth = if self.depth > 0.0 {
            1.0 / self.depth
        } else {
            0.0
        };
        let m = ((dist - self.start) * inv_depth).clamp(0.0, 1.0);
        if self.falloff == 1.0 {
            m
        } else if self.falloff == 2.0 {
            m * m
        } else if self.falloff == 0.5 {
            m.sqrt()
        } else {
            m.powf(self.falloff)
        }
    }
}

/// A complete scene.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Meshes no instance refers to are in world space; the others in object space.
    pub meshes: Vec<Mesh>,
    /// Placements of object-space meshes (a mesh may be placed many times).
    pub instances: Vec<Instance>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    pub images: Vec<Image>,
    pub lights: Vec<Light>,
    /// The light and shadow linking of each of `lights` (missing entries: none).
    pub light_links: Vec<LightLinks>,
    pub camera: Option<Camera>,
    /// The camera's camera-to-world over the shutter (motion blur; rigid keys), or `None`
    /// for a camera that stays at `camera.to_world`.
    pub camera_motion: Option<crate::motion::TransformMotion>,
    /// Constant background radiance seen by rays that leave the scene, W/(m² sr).
    pub background: Vec3,
    /// The world's node graph and settings (the constant `background` is its fallback).
    pub world: World,
    pub settings: RenderSettings,
    /// Non-fatal problems found while loading (unknown optional extensions, skipped primitives...).
    pub warnings: Vec<String>,
}

impl Scene {
    /// Whether anything moves over the shutter (then each camera path draws a time).
    pub fn has_motion(&self) -> bool {
        self.camera_motion.is_some() || self.instances.iter().any(|i| i.motion.is_some())
    }

    /// Axis-aligned world-space bounds of all geometry (instances by their transformed mesh
    /// bounds), or `None` for a scene without geometry.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let placed = self.placed_meshes();
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        let mut any = false;
        for (m, _) in self.meshes.iter().zip(&placed).filter(|(_, p)| !**p) {
            for p in &m.positions {
                lo = lo.min(*p);
                hi = hi.max(*p);
                any = true;
            }
        }
        let mesh_bounds: Vec<Option<(Vec3, Vec3)>> = (self.meshes.iter().zip(&placed))
            .map(|(m, p)| if *p { m.bounds() } else { None })
            .collect();
        for inst in &self.instances {
            if let Some(Some((l, h))) = mesh_bounds.get(inst.mesh) {
                let (l, h) = match &inst.motion {
                    Some(m) => m.bounds(*l, *h),
                    None => instance::transform_bounds(&inst.to_world, *l, *h),
                };
                lo = lo.min(l);
                hi = hi.max(h);
                any = true;
            }
        }
        any.then_some((lo, hi))
    }

    /// For each mesh, whether instances place it (then it is in object space and not drawn
    /// by itself).
    pub fn placed_meshes(&self) -> Vec<bool> {
        let mut placed = vec![false; self.meshes.len()];
        for i in &self.instances {
            if let Some(p) = placed.get_mut(i.mesh) {
                *p = true;
            }
        }
        placed
    }

    /// Triangles stored: each mesh once, however many instances place it.
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.indices.len()).sum()
    }

    /// Triangles rendered: world-space meshes once, placed meshes once per instance.
    pub fn instanced_triangle_count(&self) -> u64 {
        let placed = self.placed_meshes();
        let own: u64 = (self.meshes.iter().zip(&placed))
            .filter(|(_, p)| !**p)
            .map(|(m, _)| m.indices.len() as u64)
            .sum();
        let inst: u64 = (self.instances.iter())
            .filter_map(|i| self.meshes.get(i.mesh))
            .map(|m| m.indices.len() as u64)
            .sum();
        own + inst
    }
}
