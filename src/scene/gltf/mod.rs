//! glTF 2.0 loader (`.gltf` with external or data-URI buffers, and `.glb`).
//!
//! The `gltf` crate parses the JSON into its typed document; everything else is done here
//! with explicit checks, so that no input can make the loader panic, hang or allocate
//! without bound: buffers and images are resolved by [`uri`] (data URIs, the GLB BIN
//! chunk, bufferViews and files inside the scene's folder only), accessors are read by
//! [`accessor`], and the node tree is walked iteratively with a visited set.
//!
//! Extensions read from the raw JSON: `KHR_lights_punctual`, `KHR_materials_*`
//! (emissive_strength, ior, transmission, specular, clearcoat, sheen, volume, anisotropy),
//! `KHR_texture_transform`, `KHR_mesh_quantization` (accessor types), and Tesela's own `TESELA_light`, `TESELA_world`, `TESELA_emission`,
//! `TESELA_render`, `TESELA_camera` (see `docs/extensions.md`).

mod accessor;
mod camera;
mod container;
mod curves;
mod document;
mod draco;
mod image_file;
mod instances;
mod lights;
mod linking;
mod material;
mod mesh;
mod meshopt;
mod motion;
mod points;
mod skin;
mod tangents;
mod uri;
mod world;

#[cfg(test)]
mod tests_load;

#[cfg(test)]
mod tests_attributes;

use std::borrow::Cow;
use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::rc::Rc;

use ::gltf::json;
use glam::{Mat3, Mat4, Quat, Vec3, Vec4};
use serde_json::Value;

use crate::scene::error::{LoadError, LoadErrorKind};
use crate::scene::{RenderSettings, Scene};

pub use document::{Document, Origins};

/// Output limits: a scene beyond them is refused rather than exhausting memory.
const MAX_TRIANGLES: usize = 1 << 25;
const MAX_VERTICES: usize = 1 << 25;

/// Extensions that may appear in `extensionsRequired`.
const SUPPORTED_REQUIRED: &[&str] = &[
    "KHR_mesh_quantization",
    "TESELA_curves",
    "TESELA_points",
    "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    "EXT_mesh_gpu_instancing",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_materials_specular",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_volume",
    "KHR_materials_anisotropy",
    "KHR_lights_punctual",
    "KHR_texture_transform",
    "KHR_materials_unlit",
    "KHR_materials_pbrSpecularGlossiness",
    "EXT_texture_webp",
    "TESELA_light",
    "TESELA_world",
    "TESELA_emission",
    "TESELA_render",
    "TESELA_material_graph",
    "TESELA_images",
    "TESELA_camera",
    "TESELA_light_linking",
    "TESELA_motion",
];

/// Extensions that are used without a warning. Clearcoat, sheen and anisotropy reach the
/// Principled BSDF's inputs; where the BSDF cannot draw a lobe yet, the material compiler
/// reports it. Volume attenuation, which is not rendered yet, is reported by the loader.
const UNDERSTOOD: &[&str] = &[
    "KHR_mesh_quantization",
    "TESELA_curves",
    "TESELA_points",
    "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    "EXT_mesh_gpu_instancing",
    "KHR_texture_transform",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_materials_specular",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_volume",
    "KHR_materials_anisotropy",
    "KHR_lights_punctual",
    "KHR_materials_unlit",
    "KHR_materials_pbrSpecularGlossiness",
    "EXT_texture_webp",
    "TESELA_light",
    "TESELA_world",
    "TESELA_emission",
    "TESELA_render",
    "TESELA_material_graph",
    "TESELA_images",
    "TESELA_camera",
    "TESELA_light_linking",
    "TESELA_motion",
];

/// Loads a `.gltf` or `.glb` file. External files are resolved relative to its folder
/// and must lie inside it.
pub fn load(path: &Path) -> Result<Scene, LoadError> {
    load_with(path, &LoadOptions::default())
}

/// [`load`] with explicit [`LoadOptions`].
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Scene, LoadError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| {
        LoadError::new(LoadErrorKind::Io, format!("cannot read the file: {e}")).in_file(&name)
    })?;
    let base = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    load_from_slice_with(&bytes, Some(base), &name, options)
}

/// How a load turns the file into a scene.
#[derive(Clone, Copy, Debug)]
pub struct LoadOptions {
    /// A mesh placed several times is still baked into world space while all its copies
    /// together have at most this many triangles: one flat BVH traces faster than instances
    /// (a two-level traversal transforms every ray), and so few copies cost little memory.
    /// 0: every mesh placed more than once is instanced. The default, 2^18, is where
    /// `bench/bake_limit.py` finds the two even: baked renders 5-19% more samples/s up to
    /// 2^16 triangles, about the same at 2^18 (+0.2 s BVH, +65 MB), and instancing is as fast
    /// or faster from 2^20 on, where baking costs ~0.8 s and ~290 MB per million.
    pub bake_triangles: usize,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            bake_triangles: 1 << 18,
        }
    }
}

/// Loads glTF JSON or GLB bytes. `base_dir` is the folder external URIs are resolved in
/// (`None` refuses every external file); `name` names the input in messages.
pub fn load_from_slice(
    bytes: &[u8],
    base_dir: Option<&Path>,
    name: &str,
) -> Result<Scene, LoadError> {
    load_from_slice_with(bytes, base_dir, name, &LoadOptions::default())
}

/// [`load_from_slice`] with explicit [`LoadOptions`].
pub fn load_from_slice_with(
    bytes: &[u8],
    base_dir: Option<&Path>,
    name: &str,
    options: &LoadOptions,
) -> Result<Scene, LoadError> {
    load_inner(bytes, base_dir, options).map_err(|e| e.in_file(name))
}

fn invalid(msg: String) -> LoadError {
    LoadError::new(LoadErrorKind::Invalid, msg)
}

fn load_inner(
    bytes: &[u8],
    base_dir: Option<&Path>,
    options: &LoadOptions,
) -> Result<Scene, LoadError> {
    let c = container::split(bytes)?;
    let raw = parse_json(c.json)?;
    let root = typed_document(&raw)?;
    let buffers = resolve_buffers(&raw, &root, c.bin, base_dir)?;
    let buffer_refs: Vec<&[u8]> = buffers.iter().map(|b| &b[..]).collect();
    load_parsed(&raw, &root, &buffer_refs, base_dir, options).map(|(scene, _)| scene)
}

/// The document's JSON, which must be an object.
fn parse_json(json: &[u8]) -> Result<Value, LoadError> {
    let raw: Value = serde_json::from_slice(json)
        .map_err(|e| LoadError::new(LoadErrorKind::Format, format!("invalid JSON: {e}")))?;
    if !raw.is_object() {
        return Err(LoadError::new(
            LoadErrorKind::Format,
            "not a glTF file: the JSON is not an object",
        ));
    }
    Ok(raw)
}

/// Loads a parsed document whose buffers are resolved (`buffers[i]` is buffer `i`).
fn load_parsed(
    raw: &Value,
    root: &json::Root,
    buffers: &[&[u8]],
    base_dir: Option<&Path>,
    options: &LoadOptions,
) -> Result<(Scene, Origins), LoadError> {
    let version = root.asset.version.trim();
    if !version.starts_with("2.") && version != "2" {
        return Err(LoadError::new(
            LoadErrorKind::Unsupported,
            format!("unsupported glTF version `{version}` (asset.version); only 2.x is supported"),
        ));
    }
    if let Some(unsupported) = root
        .extensions_required
        .iter()
        .find(|e| !SUPPORTED_REQUIRED.contains(&e.as_str()))
    {
        return Err(LoadError::new(
            LoadErrorKind::Unsupported,
            format!("unsupported required extension `{unsupported}` (extensionsRequired)"),
        ));
    }
    let mut warnings = Vec::new();
    let mut seen = HashSet::new();
    for ext in root.extensions_used.iter() {
        if !UNDERSTOOD.contains(&ext.as_str()) && seen.insert(ext.clone()) {
            warnings.push(format!(
                "extension `{ext}` is not supported and is ignored (extensionsUsed)"
            ));
        }
    }
    let views = meshopt::decode_views(raw, buffers)?;
    let mut loader = Loader {
        root,
        raw,
        base_dir,
        reader: accessor::Reader {
            root,
            buffers,
            views: &views,
            decoded: HashMap::new(),
        },
        scene: Scene {
            warnings,
            ..Default::default()
        },
        materials: HashMap::new(),
        textures: HashMap::new(),
        images: HashMap::new(),
        raw_images: HashMap::new(),
        prim_cache: HashMap::new(),
        warned: HashSet::new(),
        tri_total: 0,
        vert_total: 0,
        origins: Origins::default(),
        options: *options,
        links: HashMap::new(),
    };
    loader.root_extensions()?;
    loader.light_linking();
    loader.walk()?;
    let mut origins = loader.origins;
    origins.mesh_node.resize(loader.scene.meshes.len(), None);
    origins.material_gltf = vec![None; loader.scene.materials.len()];
    for (&(gi, _), &m) in &loader.materials {
        origins.material_gltf[m] = gi;
    }
    Ok((loader.scene, origins))
}

/// The typed document, deserialized by the `gltf` crate from a copy of the JSON that
/// keeps only what the crate must check: extension and extras objects and skins (read from
/// the raw JSON instead) and animations (not used) are left out, and properties that glTF
/// makes optional but the crate requires get neutral values (`scene.nodes`, a texture's
/// `source`, which [`Loader::texture`] checks in the raw JSON).
fn typed_document(raw: &Value) -> Result<json::Root, LoadError> {
    fn strip(v: &mut Value) {
        match v {
            Value::Object(o) => {
                o.remove("extensions");
                o.remove("extras");
                o.values_mut().for_each(strip);
            }
            Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v = raw.clone();
    if let Some(o) = v.as_object_mut() {
        o.remove("animations");
        o.remove("skins");
    }
    strip(&mut v);
    for key in ["scenes", "textures"] {
        let Some(items) = v.get_mut(key).and_then(Value::as_array_mut) else {
            continue;
        };
        for item in items.iter_mut().filter_map(Value::as_object_mut) {
            match key {
                "scenes" => {
                    item.entry("nodes")
                        .or_insert_with(|| Value::Array(Vec::new()));
                }
                _ => {
                    item.entry("source").or_insert(Value::from(u32::MAX));
                }
            }
        }
    }
    use serde::Deserialize;
    json::Root::deserialize(&v).map_err(|e| {
        let at = locate_error(&v).unwrap_or_else(|| e.to_string());
        LoadError::new(
            LoadErrorKind::Format,
            format!("not a valid glTF 2.0 document: {at}"),
        )
    })
}

/// Finds the first top-level array element the `gltf` crate refuses, for a message with
/// a JSON path (`accessors[3]: missing field `count``).
fn locate_error(v: &Value) -> Option<String> {
    use serde::Deserialize;
    fn first_bad<T: for<'de> Deserialize<'de>>(v: &Value, key: &str) -> Option<String> {
        let items = member(v, key)?;
        let Some(items) = items.as_array() else {
            return Some(format!("`{key}` is not an array"));
        };
        items.iter().enumerate().find_map(|(i, item)| {
            T::deserialize(item)
                .err()
                .map(|e| format!("{key}[{i}]: {e}"))
        })
    }
    if member(v, "asset").is_none() {
        return Some("missing field `asset` (not a glTF document?)".into());
    }
    json::Asset::deserialize(&v["asset"])
        .err()
        .map(|e| format!("asset: {e}"))
        .or_else(|| first_bad::<json::Accessor>(v, "accessors"))
        .or_else(|| first_bad::<json::Buffer>(v, "buffers"))
        .or_else(|| first_bad::<json::buffer::View>(v, "bufferViews"))
        .or_else(|| first_bad::<json::Camera>(v, "cameras"))
        .or_else(|| first_bad::<json::Image>(v, "images"))
        .or_else(|| first_bad::<json::Material>(v, "materials"))
        .or_else(|| first_bad::<json::Mesh>(v, "meshes"))
        .or_else(|| first_bad::<json::Node>(v, "nodes"))
        .or_else(|| first_bad::<json::texture::Sampler>(v, "samplers"))
        .or_else(|| first_bad::<json::Scene>(v, "scenes"))
        .or_else(|| first_bad::<json::Texture>(v, "textures"))
}

/// Fetches every buffer, trimmed to its `byteLength`.
fn resolve_buffers<'a>(
    raw: &Value,
    root: &json::Root,
    bin: Option<&'a [u8]>,
    base_dir: Option<&Path>,
) -> Result<Vec<Cow<'a, [u8]>>, LoadError> {
    let mut out = Vec::with_capacity(root.buffers.len());
    for (i, b) in root.buffers.iter().enumerate() {
        let want = b.byte_length.0;
        let data: Cow<'a, [u8]> = match &b.uri {
            // Every view on a meshopt fallback buffer is decoded from another buffer.
            None if meshopt::is_fallback_buffer(raw, i) => {
                out.push(Cow::Borrowed(&[][..]));
                continue;
            }
            None => {
                if i != 0 {
                    return Err(invalid(format!(
                        "buffer {i} has no uri (only buffer 0 may refer to the GLB BIN chunk)"
                    )));
                }
                let bin = bin.ok_or_else(|| {
                    invalid("buffer 0 has no uri and there is no GLB BIN chunk".to_string())
                })?;
                if (bin.len() as u64) < want {
                    return Err(invalid(format!(
                        "buffer 0: the GLB BIN chunk is {} bytes, shorter than byteLength {want}",
                        bin.len()
                    )));
                }
                Cow::Borrowed(bin)
            }
            Some(u) => {
                let shown = short_uri(u);
                let ctx = |e: LoadError| {
                    LoadError::new(e.kind, format!("buffer {i} (`{shown}`): {}", e.message))
                };
                match uri::resolve(u, base_dir).map_err(ctx)? {
                    uri::Target::Data { bytes, .. } => {
                        if (bytes.len() as u64) < want {
                            return Err(invalid(format!(
                                "buffer {i}: data URI holds {} bytes, fewer than byteLength {want}",
                                bytes.len()
                            )));
                        }
                        Cow::Owned(bytes)
                    }
                    uri::Target::File(path) => {
                        // resolve() returned File only with a base directory.
                        let base = base_dir.unwrap_or(Path::new("."));
                        Cow::Owned(uri::read_file(&path, base, u, Some(want)).map_err(ctx)?)
                    }
                }
            }
        };
        // `want <= data.len()` was checked above.
        let data = match data {
            Cow::Borrowed(s) => Cow::Borrowed(&s[..want as usize]),
            Cow::Owned(mut v) => {
                v.truncate(want as usize);
                Cow::Owned(v)
            }
        };
        out.push(data);
    }
    Ok(out)
}

/// A URI shortened for messages (data URIs can be megabytes long).
fn short_uri(u: &str) -> String {
    if u.len() > 64 {
        let mut end = 48;
        while !u.is_char_boundary(end) {
            end -= 1;
        }
        format!("{}...", &u[..end])
    } else {
        u.to_string()
    }
}

/// Triangulated primitive data in the mesh's local space.
#[derive(Clone, Debug, Default)]
pub(crate) struct LocalPrim {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<glam::Vec2>,
    pub tris: Vec<[u32; 3]>,
    /// TEXCOORD_1.. (empty where absent or not needed).
    pub extra_uvs: Vec<Vec<glam::Vec2>>,
    /// Names of the TEXCOORD sets (`uv_names[k]` names set k).
    pub uv_names: Vec<String>,
    /// COLOR_n, linear RGBA, with their names.
    pub colors: Vec<(String, Vec<Vec4>)>,
    /// Local-space tangents (TANGENT or MikkTSpace), w = bitangent sign; may be empty.
    pub tangents: Vec<Vec4>,
}

pub(crate) struct Loader<'a> {
    pub root: &'a json::Root,
    pub raw: &'a Value,
    pub base_dir: Option<&'a Path>,
    pub reader: accessor::Reader<'a>,
    pub scene: Scene,
    /// (glTF material index or `None` for the default, multiplied by COLOR_0) -> scene
    /// material index.
    pub materials: HashMap<(Option<usize>, bool), usize>,
    /// glTF texture index -> scene texture index.
    pub textures: HashMap<usize, usize>,
    /// glTF image index -> scene image index.
    pub images: HashMap<usize, usize>,
    /// `TESELA_images` index -> scene image index.
    pub raw_images: HashMap<usize, usize>,
    /// (mesh, primitive) -> local data, for meshes instanced with their default weights.
    pub prim_cache: HashMap<(usize, usize), Option<Rc<LocalPrim>>>,
    pub warned: HashSet<String>,
    /// Triangles and vertices emitted so far (checked against the limits).
    pub tri_total: usize,
    pub vert_total: usize,
    /// Which node made each mesh, instance and light.
    pub origins: Origins,
    pub options: LoadOptions,
    /// Node → its light and shadow linking (`TESELA_light_linking`), for linked nodes.
    pub links: HashMap<usize, crate::scene::LightLinks>,
}

/// `raw[key]` as an object member, if present.
pub(crate) fn member<'v>(v: &'v Value, key: &str) -> Option<&'v Value> {
    v.as_object().and_then(|o| o.get(key))
}

/// The raw JSON of extension `ext` on `v`.
pub(crate) fn extension<'v>(v: &'v Value, ext: &str) -> Option<&'v Value> {
    member(v, "extensions").and_then(|e| member(e, ext))
}

/// `v[key]` as a number.
pub(crate) fn num(v: &Value, key: &str) -> Option<f64> {
    member(v, key).and_then(Value::as_f64)
}

/// `v[key]` as `[r, g, b]`.
pub(crate) fn rgb(v: &Value, key: &str) -> Option<Vec3> {
    let a = member(v, key)?.as_array()?;
    if a.len() < 3 {
        return None;
    }
    let c = |i: usize| a[i].as_f64().map(|x| x as f32);
    Some(Vec3::new(c(0)?, c(1)?, c(2)?))
}

impl<'a> Loader<'a> {
    pub(crate) fn warn_once(&mut self, msg: String) {
        if self.warned.insert(msg.clone()) {
            self.scene.warnings.push(msg);
        }
    }

    /// `nodes[i]` in the raw JSON.
    pub(crate) fn raw_item(&self, array: &str, i: usize) -> &'a Value {
        static NULL: Value = Value::Null;
        member(self.raw, array)
            .and_then(|a| a.as_array())
            .and_then(|a| a.get(i))
            .unwrap_or(&NULL)
    }

    /// A root-level extension object of the raw document.
    pub(crate) fn raw_root_extension(&self, ext: &str) -> Option<&'a Value> {
        extension(self.raw, ext)
    }

    fn root_extensions(&mut self) -> Result<(), LoadError> {
        if let Some(w) = extension(self.raw, "TESELA_world") {
            self.world(w);
        }
        if let Some(r) = extension(self.raw, "TESELA_render") {
            let mut s = RenderSettings::default();
            let u32_of = |k: &str| {
                member(r, k)
                    .and_then(Value::as_u64)
                    .and_then(|v| u32::try_from(v).ok())
            };
            s.width = u32_of("width").filter(|&v| v > 0);
            s.height = u32_of("height").filter(|&v| v > 0);
            s.spp = u32_of("spp").filter(|&v| v > 0);
            s.max_depth = u32_of("max_depth");
            s.seed = member(r, "seed").and_then(Value::as_u64);
            s.integrator = member(r, "integrator")
                .and_then(Value::as_str)
                .map(str::to_string);
            s.film_transparent = member(r, "film_transparent")
                .and_then(Value::as_bool)
                .unwrap_or(false);
            if member(r, "film_transparent_glass").and_then(Value::as_bool) == Some(true) {
                let t = member(r, "film_transparent_roughness")
                    .and_then(Value::as_f64)
                    .map(|v| v as f32)
                    .filter(|v| v.is_finite())
                    .unwrap_or(0.1);
                s.film_transparent_glass = Some(t.clamp(0.0, 1.0));
            }
            if let Some(m) = member(r, "mist") {
                let f = |k: &str, d: f32| {
                    member(m, k)
                        .and_then(Value::as_f64)
                        .map(|v| v as f32)
                        .filter(|v| v.is_finite())
                        .unwrap_or(d)
                };
                let d = crate::scene::Mist::default();
                s.mist = crate::scene::Mist {
                    start: f("start", d.start),
                    depth: f("depth", d.depth).max(0.0),
                    falloff: f("falloff", d.falloff).max(0.0),
                };
            }
            self.scene.settings = s;
        }
        Ok(())
    }

    /// The root nodes of the scene to render.
    fn roots(&self) -> Result<Vec<usize>, LoadError> {
        let root = self.root;
        let scene = match root.scene {
            Some(s) => Some(root.scenes.get(s.value()).ok_or_else(|| {
                invalid(format!(
                    "scene {} (the default `scene`) does not exist (the file has {})",
                    s.value(),
                    root.scenes.len()
                ))
            })?),
            None => root.scenes.first(),
        };
        if let Some(scene) = scene {
            return Ok(scene.nodes.iter().map(|n| n.value()).collect());
        }
        // No scenes: every node that is nobody's child.
        let mut is_child = vec![false; root.nodes.len()];
        for n in &root.nodes {
            for c in n.children.iter().flatten() {
                if let Some(f) = is_child.get_mut(c.value()) {
                    *f = true;
                }
            }
        }
        Ok((0..root.nodes.len()).filter(|&i| !is_child[i]).collect())
    }

    /// Walks the node tree depth first (pre-order, children in order), iteratively.
    fn walk(&mut self) -> Result<(), LoadError> {
        let roots = self.roots()?;
        let n = self.root.nodes.len();
        let mut visited = vec![false; n];
        let mut stack: Vec<(usize, Mat4)> =
            roots.iter().rev().map(|&r| (r, Mat4::IDENTITY)).collect();
        let mut uses = Vec::new();
        while let Some((ni, parent)) = stack.pop() {
            let node =
                self.root.nodes.get(ni).ok_or_else(|| {
                    invalid(format!("node {ni} does not exist (the file has {n})"))
                })?;
            if visited[ni] {
                return Err(invalid(format!(
                    "node {ni} is reached twice (a cycle, or a node with two parents)"
                )));
            }
            visited[ni] = true;
            let world = parent * local_transform(node, ni)?;
            if !world.is_finite() {
                return Err(invalid(format!(
                    "node {ni}: its world transform is not finite"
                )));
            }
            let motion = self.node_motion(ni, parent)?;
            let mut moved = false;
            if let Some(ci) = node.camera
                && self.scene.camera.is_none()
            {
                self.scene.camera = Some(self.camera(ci.value(), ni, world)?);
                if let Some(keys) = &motion {
                    self.scene.camera_motion = Some(self.camera_motion(ni, keys)?);
                    moved = true;
                }
            }
            if let Some(mi) = node.mesh {
                let mi = mi.value();
                if mi >= self.root.meshes.len() {
                    return Err(invalid(format!(
                        "node {ni}: mesh {mi} does not exist (the file has {})",
                        self.root.meshes.len()
                    )));
                }
                let (gpu, gpu_random) = self.gpu_instances(ni)?;
                moved |= motion.is_some();
                uses.push(instances::MeshUse {
                    node: ni,
                    mesh: mi,
                    world,
                    gpu,
                    gpu_random,
                    motion: motion.clone(),
                });
            }
            if motion.is_some() && !moved {
                self.warn_once(format!(
                    "node {ni}: its motion (TESELA_motion) is rendered for meshes and cameras \
                     only; it renders at its node transform"
                ));
            }
            self.node_curves(ni, world)?;
            self.node_points(ni, world)?;
            self.origins.node_world.resize(n, Mat4::IDENTITY);
            self.origins.node_world[ni] = world;
            let lights = self.scene.lights.len();
            self.node_lights(ni, world)?;
            (self.origins.light_node).resize(self.scene.lights.len().max(lights), ni);
            let links = self.links_of(ni);
            (self.scene.light_links).resize(self.scene.lights.len(), links);
            for c in node.children.iter().flatten().rev() {
                stack.push((c.value(), world));
            }
        }
        self.place_meshes(uses)
    }
}

/// The node's local transform (matrix, or T * R * S).
fn local_transform(node: &json::Node, ni: usize) -> Result<Mat4, LoadError> {
    let m = if let Some(m) = node.matrix {
        Mat4::from_cols_array(&m)
    } else {
        let t = node.translation.map(Vec3::from_array).unwrap_or(Vec3::ZERO);
        let s = node.scale.map(Vec3::from_array).unwrap_or(Vec3::ONE);
        let r = match &node.rotation {
            Some(q) => {
                let q = Quat::from_array(q.0);
                let len = q.length();
                if !(len.is_finite() && len > 1e-12) {
                    return Err(invalid(format!(
                        "node {ni}: rotation {:?} is not a valid quaternion",
                        q.to_array()
                    )));
                }
                q / len
            }
            None => Quat::IDENTITY,
        };
        Mat4::from_scale_rotation_translation(s, r, t)
    };
    if !m.is_finite() {
        return Err(invalid(format!("node {ni}: transform is not finite")));
    }
    Ok(m)
}

/// Removes scale (and shear) from a transform, keeping position and orientation: the
/// result is rigid and right-handed, looking down the original -Z with +Y up.
pub(crate) fn orthonormalize(m: Mat4) -> Option<Mat4> {
    let y0 = m.y_axis.truncate();
    let z = m.z_axis.truncate().try_normalize()?;
    let x = y0.cross(z).try_normalize()?;
    let y = z.cross(x);
    Some(Mat4::from_cols(
        x.extend(0.0),
        y.extend(0.0),
        z.extend(0.0),
        Vec4::new(m.w_axis.x, m.w_axis.y, m.w_axis.z, 1.0),
    ))
}

/// The matrix that transforms normals (inverse transpose of the linear part).
pub(crate) fn normal_matrix(m: Mat4) -> Option<Mat3> {
    let l = Mat3::from_mat4(m);
    let det = l.determinant();
    (det.is_finite() && det != 0.0).then(|| l.inverse().transpose())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orthonormalize_removes_scale_keeps_orientation() {
        let m = Mat4::from_scale_rotation_translation(
            Vec3::new(2.0, 3.0, 0.5),
            Quat::from_rotation_y(0.7),
            Vec3::new(1.0, 2.0, 3.0),
        );
        let o = orthonormalize(m).unwrap();
        let r =
            Mat4::from_rotation_translation(Quat::from_rotation_y(0.7), Vec3::new(1.0, 2.0, 3.0));
        assert!(o.abs_diff_eq(r, 1e-5), "{o:?}");
        assert!(orthonormalize(Mat4::from_scale(Vec3::new(1.0, 1.0, 0.0))).is_none());
    }
}
