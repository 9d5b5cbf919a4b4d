//! What a session keeps between commands: the loaded scene (as the file said, with every edit
//! since), the scene prepared for rendering, the view and the settings, and what each
//! command changes. A command that fails changes nothing.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use glam::Mat4;
use serde_json::{Map, Value};

use super::pieces;
use super::protocol::{Command, View};
use crate::emitter::LightChoice;
use crate::film::{FilterType, PixelFilter};
use crate::render::RenderOptions;
use crate::render_scene::RenderScene;
use crate::scene::gltf::{Document, Origins};
use crate::scene::{Instance, Scene};

/// The viewport's render settings (`settings` command; docs/session.md).
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Samples per pixel to reach; 0 = refine until stopped.
    pub samples: u32,
    /// Cycles' "Start Pixels": the first pass has at most this many pixels squared.
    pub start_resolution: u32,
    /// Cycles' viewport "Pixel Size".
    pub pixel_size: u32,
    pub denoise: bool,
    pub seed: Option<u64>,
    pub max_depth: Option<u32>,
    pub integrator: Option<String>,
    pub diffuse_bounces: Option<u32>,
    pub glossy_bounces: Option<u32>,
    pub transmission_bounces: Option<u32>,
    pub volume_bounces: Option<u32>,
    pub transparent_bounces: u32,
    pub clamp_direct: f32,
    pub clamp_indirect: f32,
    pub caustics_reflective: bool,
    pub caustics_refractive: bool,
    /// Cycles' `blur_glossy` (0 = off).
    pub blur_glossy: f32,
    pub filter: FilterType,
    pub filter_width: f32,
    pub film_transparent: Option<bool>,
}

impl Default for Settings {
    /// `tesela render`'s defaults; samples until stopped, Cycles' start resolution 64.
    fn default() -> Self {
        Settings {
            samples: 0,
            start_resolution: 64,
            pixel_size: 1,
            denoise: false,
            seed: None,
            max_depth: None,
            integrator: None,
            diffuse_bounces: None,
            glossy_bounces: None,
            transmission_bounces: None,
            volume_bounces: None,
            transparent_bounces: 8,
            clamp_direct: 0.0,
            clamp_indirect: 0.0,
            caustics_reflective: true,
            caustics_refractive: true,
            blur_glossy: 0.0,
            filter: FilterType::Box,
            filter_width: 1.0,
            film_transparent: None,
        }
    }
}

impl Settings {
    /// These settings with `fields` changed (each checked); the names of fields not known.
    pub fn patched(&self, fields: &Map<String, Value>) -> Result<(Settings, Vec<String>), String> {
        let mut s = self.clone();
        let mut unknown = Vec::new();
        for (k, v) in fields {
            let uint = || {
                v.as_u64()
                    .and_then(|x| u32::try_from(x).ok())
                    .ok_or_else(|| format!("`{k}` must be a whole number >= 0, not {v}"))
            };
            let clamp = || {
                v.as_f64()
                    .map(|x| x as f32)
                    .filter(|x| x.is_finite() && *x >= 0.0)
                    .ok_or_else(|| format!("`{k}` must be a number >= 0 (0 = off), not {v}"))
            };
            let boolean = || {
                v.as_bool()
                    .ok_or_else(|| format!("`{k}` must be true or false, not {v}"))
            };
            match k.as_str() {
                "samples" => s.samples = uint()?,
                "start_resolution" => s.start_resolution = uint()?,
                "pixel_size" => {
                    let p = uint()?;
                    if ![1, 2, 4, 8].contains(&p) {
                        return Err(format!("`pixel_size` must be 1, 2, 4 or 8, not {v}"));
                    }
                    s.pixel_size = p;
                }
                "denoise" => s.denoise = boolean()?,
                "seed" => {
                    s.seed =
                        Some(v.as_u64().ok_or_else(|| {
                            format!("`seed` must be a whole number >= 0, not {v}")
                        })?)
                }
                "max_depth" => s.max_depth = Some(uint()?),
                "max_bounces" => s.max_depth = Some(uint()?.saturating_add(2)),
                "integrator" => {
                    let name = v
                        .as_str()
                        .ok_or_else(|| format!("`integrator` must be a string, not {v}"))?;
                    if crate::integrator::by_name(name, 1).is_none() {
                        return Err(format!(
                            "unknown integrator `{name}` (choose one of {})",
                            crate::integrator::NAMES.join(", ")
                        ));
                    }
                    s.integrator = Some(name.to_string());
                }
                "diffuse_bounces" => s.diffuse_bounces = Some(uint()?),
                "glossy_bounces" => s.glossy_bounces = Some(uint()?),
                "transmission_bounces" => s.transmission_bounces = Some(uint()?),
                "volume_bounces" => s.volume_bounces = Some(uint()?),
                "transparent_bounces" => s.transparent_bounces = uint()?,
                "clamp_direct" => s.clamp_direct = clamp()?,
                "clamp_indirect" => s.clamp_indirect = clamp()?,
                "filter" => {
                    s.filter = match v.as_str() {
                        Some("box") => FilterType::Box,
                        Some("gaussian") => FilterType::Gaussian,
                        Some("blackman-harris") => FilterType::BlackmanHarris,
                        _ => {
                            return Err(format!(
                                "`filter` must be box, gaussian or blackman-harris, not {v}"
                            ));
                        }
                    }
                }
                "filter_width" => {
                    let w = clamp()?;
                    if !(0.01..=10.0).contains(&w) {
                        return Err(format!(
                            "`filter_width` must be between 0.01 and 10 pixels, not {v}"
                        ));
                    }
                    s.filter_width = w;
                }
                "film_transparent" => s.film_transparent = Some(boolean()?),
                "caustics_reflective" => s.caustics_reflective = boolean()?,
                "caustics_refractive" => s.caustics_refractive = boolean()?,
                "blur_glossy" => s.blur_glossy = clamp()?,
                _ => unknown.push(k.clone()),
            }
        }
        Ok((s, unknown))
    }
}

/// A loaded scene and what the session needs to edit it.
pub struct Loaded {
    doc: Document,
    /// The scene as the file said, with every edit since; nothing hidden.
    source: Scene,
    origins: Origins,
    /// Node name -> glTF node index (the first node of that name).
    nodes: HashMap<String, usize>,
    hidden: HashSet<usize>,
    /// The scene as rendered (hidden objects left out).
    pub render: RenderScene,
}

impl Loaded {
    /// Reads and prepares file `path`.
    pub fn read(path: &Path) -> Result<Loaded, String> {
        let doc = Document::read(path).map_err(|e| e.to_string())?;
        let (source, origins) = doc.load().map_err(|e| e.to_string())?;
        let mut nodes = HashMap::new();
        if let Some(a) = doc.raw.get("nodes").and_then(Value::as_array) {
            for (i, n) in a.iter().enumerate() {
                if let Some(name) = n.get("name").and_then(Value::as_str) {
                    nodes.entry(name.to_string()).or_insert(i);
                }
            }
        }
        Ok(Loaded {
            doc,
            render: RenderScene::new(source.clone(), LightChoice::Power),
            source,
            origins,
            nodes,
            hidden: HashSet::new(),
        })
    }

    /// The load's and the preparation's warnings.
    pub fn warnings(&self) -> &[String] {
        &self.render.scene.warnings
    }

    /// The scene as rendered, less what is hidden.
    fn visible(&self) -> Scene {
        let mut s = self.source.clone();
        if self.hidden.is_empty() {
            return s;
        }
        for (m, node) in s.meshes.iter_mut().zip(&self.origins.mesh_node) {
            if node.is_some_and(|n| self.hidden.contains(&n)) {
                m.indices = Vec::new();
                m.positions = Vec::new();
            }
        }
        let keep = |node: &usize| !self.hidden.contains(node);
        s.instances = (s.instances.into_iter())
            .zip(&self.origins.instance_node)
            .filter(|(_, n)| keep(n))
            .map(|(i, _)| i)
            .collect();
        s.lights = self.visible_lights();
        s
    }

    fn visible_lights(&self) -> Vec<crate::scene::Light> {
        (self.source.lights.iter())
            .zip(&self.origins.light_node)
            .filter(|(_, n)| !self.hidden.contains(n))
            .map(|(l, _)| l.clone())
            .collect()
    }

    /// Prepares the scene again from scratch (BVH included), keeping the camera and settings.
    fn rebuild(&mut self) {
        let mut scene = self.visible();
        scene.camera = self.render.scene.camera;
        scene.settings = self.render.scene.settings.clone();
        self.render = RenderScene::new(scene, LightChoice::Power);
    }

    fn node(&self, name: &str) -> Result<usize, String> {
        self.nodes
            .get(name)
            .copied()
            .ok_or_else(|| format!("no node named `{name}` in {}", self.doc.name()))
    }

    /// `node`'s world matrix: the new `matrix` for it, in the document and everything made
    /// from the node (its baked meshes, its instances, its lights).
    fn transform(&mut self, ni: usize, matrix: Mat4) -> Result<Vec<String>, String> {
        if let Some(p) = Instance::check(&matrix) {
            return Err(format!("the matrix cannot place an object: {p}"));
        }
        let old = self
            .origins
            .node_world
            .get(ni)
            .copied()
            .unwrap_or(Mat4::IDENTITY);
        let delta = matrix * old.inverse();
        if !delta.is_finite() {
            return Err("the node's old matrix cannot be undone (singular)".into());
        }
        let location = matrix.transform_point3(glam::Vec3::ZERO);
        let mut moved = false;
        for (k, inst) in self.source.instances.iter_mut().enumerate() {
            if self.origins.instance_node[k] == ni {
                // A plain placement is the node's matrix itself: take the new one exactly
                // (as a file with it would); one of several instances of a node moves along.
                inst.to_world = if inst.to_world == old {
                    matrix
                } else {
                    delta * inst.to_world
                };
                inst.object.location = location;
                moved = true;
            }
        }
        // A baked mesh becomes an instance of itself: its triangles are made unhittable in
        // the world's BVH (no rebuild) and its own bottom level is built once; later moves
        // only place the instance.
        let unbaked = self.unbake(ni, delta, location);
        if let Some(n) = self.origins.node_world.get_mut(ni) {
            *n = matrix;
        }
        self.set_raw_matrix(ni, matrix);
        let mut warnings = Vec::new();
        let light = (self.doc.raw.get("nodes"))
            .and_then(|n| n.get(ni))
            .and_then(|n| n.get("extensions"))
            .and_then(|e| e.get("TESELA_light"))
            .cloned();
        if let Some(light) = light {
            warnings = self.set_lights(ni, matrix, &light)?;
        }
        if !unbaked.is_empty() {
            warnings.extend(self.out_of_world(&unbaked, &unbaked));
        } else if moved {
            warnings.extend(self.instances_changed(&[]));
        } else {
            warnings.extend(self.render.refresh_lights());
        }
        Ok(warnings)
    }

    /// Turns node `ni`'s baked meshes into instances of themselves placed by `delta`, with
    /// Object Info at `location`; the meshes that had triangles (to take out of the
    /// world-space BVH).
    fn unbake(&mut self, ni: usize, delta: Mat4, location: glam::Vec3) -> Vec<usize> {
        let mut moved = Vec::new();
        for mi in 0..self.source.meshes.len() {
            if self.origins.mesh_node[mi] != Some(ni) {
                continue;
            }
            self.origins.mesh_node[mi] = None;
            let m = &self.source.meshes[mi];
            if m.indices.is_empty() {
                continue;
            }
            let mut object = m.attrs.object.clone();
            object.location = location;
            self.source.instances.push(Instance {
                motion: None,
                mesh: mi,
                to_world: delta,
                material: None,
                object,
            });
            self.origins.instance_node.push(ni);
            moved.push(mi);
        }
        moved
    }

    /// World-space meshes `removed` leave the world's BVH in place (no rebuild) and the
    /// instances now placing meshes `changed` are built (their bottom levels and the top).
    fn out_of_world(&mut self, removed: &[usize], changed: &[usize]) -> Vec<String> {
        if self.render.instances_emit() {
            self.rebuild();
            return Vec::new();
        }
        self.render.remove_world_meshes(removed);
        let mut both = removed.to_vec();
        both.extend(changed.iter().filter(|m| !removed.contains(m)));
        self.instances_changed(&both)
    }

    /// After instances moved or meshes `changed` (or appended) got new triangles: builds
    /// only the instances' BVH when no instance emits (emitting instances are baked into
    /// world space), else everything.
    fn instances_changed(&mut self, changed: &[usize]) -> Vec<String> {
        let r = &self.render.scene;
        let aligned = !self.render.instances_emit()
            && r.meshes.len() <= self.source.meshes.len()
            && r.materials.len() == self.source.materials.len();
        if !aligned {
            self.rebuild();
            return Vec::new();
        }
        let visible: Vec<Instance> = (self.source.instances.iter())
            .zip(&self.origins.instance_node)
            .filter(|(_, n)| !self.hidden.contains(n))
            .map(|(i, _)| i.clone())
            .collect();
        let r = &mut self.render.scene;
        for &m in changed {
            if m < r.meshes.len() {
                r.meshes[m] = self.source.meshes[m].clone();
            }
        }
        let have = r.meshes.len();
        r.meshes.extend(self.source.meshes[have..].iter().cloned());
        r.instances = visible;
        if self.render.instances_emit() {
            self.rebuild();
            return Vec::new();
        }
        self.render.refresh_instances(changed)
    }

    /// Writes world matrix `m` as node `ni`'s matrix in the document (relative to its parent).
    fn set_raw_matrix(&mut self, ni: usize, m: Mat4) {
        let parent = (self.doc.raw.get("nodes").and_then(Value::as_array))
            .and_then(|a| {
                a.iter().position(|n| {
                    (n.get("children").and_then(Value::as_array))
                        .is_some_and(|c| c.iter().any(|c| c.as_u64() == Some(ni as u64)))
                })
            })
            .and_then(|p| self.origins.node_world.get(p).copied())
            .unwrap_or(Mat4::IDENTITY);
        let local = parent.inverse() * m;
        if let Some(node) = (self.doc.raw.get_mut("nodes"))
            .and_then(|n| n.get_mut(ni))
            .and_then(Value::as_object_mut)
        {
            for k in ["translation", "rotation", "scale"] {
                node.remove(k);
            }
            node.insert(
                "matrix".into(),
                Value::from(local.to_cols_array().map(f64::from).to_vec()),
            );
        }
    }

    /// Replaces node `ni`'s lights by those of `TESELA_light` object `light` at `matrix`.
    fn set_lights(
        &mut self,
        ni: usize,
        matrix: Mat4,
        light: &Value,
    ) -> Result<Vec<String>, String> {
        let (new, warnings) = pieces::lights(&matrix, light)?;
        let at = (self.origins.light_node.iter())
            .position(|&n| n == ni)
            .unwrap_or(self.source.lights.len());
        let mut lights = Vec::new();
        let mut nodes = Vec::new();
        for (k, (l, &n)) in self
            .source
            .lights
            .iter()
            .zip(&self.origins.light_node)
            .enumerate()
        {
            if k == at {
                lights.extend(new.iter().cloned());
                nodes.extend(std::iter::repeat_n(ni, new.len()));
            }
            if n != ni {
                lights.push(l.clone());
                nodes.push(n);
            }
        }
        if at == self.source.lights.len() {
            lights.extend(new.iter().cloned());
            nodes.extend(std::iter::repeat_n(ni, new.len()));
        }
        self.source.lights = lights;
        self.origins.light_node = nodes;
        self.render.scene.lights = self.visible_lights();
        Ok(warnings)
    }

    /// The `light` command.
    fn light(
        &mut self,
        node: &str,
        light: &Value,
        matrix: Option<Mat4>,
    ) -> Result<Vec<String>, String> {
        let ni = match self.nodes.get(node) {
            Some(&ni) => ni,
            None => {
                // A light the file did not have: a new node.
                let m = matrix.ok_or_else(|| {
                    format!("no node named `{node}`: a new light needs its `matrix`")
                })?;
                let nodes = (self.doc.raw.as_object_mut())
                    .map(|o| o.entry("nodes").or_insert_with(|| Value::Array(Vec::new())))
                    .and_then(Value::as_array_mut)
                    .ok_or("the document's `nodes` is not an array")?;
                nodes.push(serde_json::json!({"name": node}));
                let ni = nodes.len() - 1;
                self.origins.node_world.resize(ni + 1, Mat4::IDENTITY);
                self.origins.node_world[ni] = m;
                self.nodes.insert(node.to_string(), ni);
                ni
            }
        };
        let matrix = matrix.unwrap_or(self.origins.node_world.get(ni).copied().unwrap_or_default());
        if let Some(p) = Instance::check(&matrix) {
            return Err(format!("the matrix cannot place a light: {p}"));
        }
        let warnings = self.set_lights(ni, matrix, light)?;
        if let Some(n) = (self.doc.raw.get_mut("nodes"))
            .and_then(|n| n.get_mut(ni))
            .and_then(Value::as_object_mut)
        {
            let ext = n
                .entry("extensions")
                .or_insert_with(|| Value::Object(Map::new()));
            if let Some(e) = ext.as_object_mut() {
                e.insert("TESELA_light".into(), light.clone());
            }
        }
        if self.origins.node_world.len() <= ni {
            // A node the walk never reached (not in the scene's tree).
            self.origins.node_world.resize(ni + 1, Mat4::IDENTITY);
        }
        self.origins.node_world[ni] = matrix;
        self.set_raw_matrix(ni, matrix);
        let mut w = warnings;
        w.extend(self.render.refresh_lights());
        Ok(w)
    }

    /// The `material` command.
    fn material(&mut self, name: &str, json: &Value) -> Result<Vec<String>, String> {
        let targets: Vec<usize> = (0..self.source.materials.len())
            .filter(|&i| self.source.materials[i].name == name)
            .collect();
        if targets.is_empty() {
            return Err(format!("no material named `{name}` in {}", self.doc.name()));
        }
        let (piece, mut warnings) = pieces::material(&self.doc, json)?;
        for &i in &targets {
            let mut m = pieces::merge_material(&mut self.source, &piece, 0);
            m.vertex_color = self.source.materials[i].vertex_color && m.graph.is_none();
            m.name = name.to_string();
            self.source.materials[i] = m;
        }
        if let Some(gis) = self
            .doc
            .raw
            .get_mut("materials")
            .and_then(Value::as_array_mut)
        {
            for &i in &targets {
                if let Some(gi) = self.origins.material_gltf.get(i).copied().flatten()
                    && let Some(slot) = gis.get_mut(gi)
                {
                    *slot = json.clone();
                }
            }
        }
        let r = &mut self.render.scene;
        r.textures = self.source.textures.clone();
        r.images = self.source.images.clone();
        for &i in &targets {
            r.materials[i] = self.source.materials[i].clone();
        }
        if self.render.shading_keeps_geometry() {
            warnings.extend(self.render.refresh_shading());
        } else {
            self.rebuild();
        }
        Ok(warnings)
    }

    /// The `world` command.
    fn world(&mut self, json: &Value) -> Result<Vec<String>, String> {
        let (piece, mut warnings) = pieces::world(&self.doc, json)?;
        let (world, background) = pieces::merge_world(&mut self.source, &piece);
        self.source.world = world.clone();
        self.source.background = background;
        if let Some(ext) = (self.doc.raw.as_object_mut())
            .map(|o| {
                o.entry("extensions")
                    .or_insert_with(|| Value::Object(Map::new()))
            })
            .and_then(Value::as_object_mut)
        {
            ext.insert("TESELA_world".into(), json.clone());
        }
        let r = &mut self.render.scene;
        r.images = self.source.images.clone();
        r.world = world;
        r.background = background;
        warnings.extend(self.render.refresh_lights());
        Ok(warnings)
    }

    /// The `visibility` command.
    fn visibility(&mut self, node: &str, visible: bool) -> Result<(), String> {
        let ni = self.node(node)?;
        let changed = if visible {
            self.hidden.remove(&ni)
        } else {
            self.hidden.insert(ni)
        };
        if !changed {
            return Ok(());
        }
        self.render.scene.lights = self.visible_lights();
        // A baked object becomes an instance of itself where it is (identity placement), so
        // hiding and showing it only builds the top level.
        let location = (self.origins.node_world.get(ni))
            .map_or(glam::Vec3::ZERO, |m| m.transform_point3(glam::Vec3::ZERO));
        let unbaked = self.unbake(ni, Mat4::IDENTITY, location);
        if !unbaked.is_empty() {
            self.out_of_world(&unbaked, &unbaked);
        } else if self.origins.instance_node.contains(&ni) {
            self.instances_changed(&[]);
        } else {
            self.render.refresh_lights();
        }
        Ok(())
    }

    /// The `mesh` command: the meshes of every node that uses mesh `name` become those of
    /// file `path` (in object space), placed as the node places them.
    fn mesh(&mut self, name: &str, path: &Path) -> Result<Vec<String>, String> {
        let meshes = self.doc.raw.get("meshes").and_then(Value::as_array);
        let gltf_mesh = meshes
            .and_then(|a| {
                a.iter()
                    .position(|m| m.get("name").and_then(Value::as_str) == Some(name))
            })
            .ok_or_else(|| format!("no mesh named `{name}` in {}", self.doc.name()))?;
        let users: Vec<usize> = (self.doc.raw.get("nodes").and_then(Value::as_array))
            .map(|a| {
                (a.iter().enumerate())
                    .filter(|(_, n)| {
                        n.get("mesh").and_then(Value::as_u64) == Some(gltf_mesh as u64)
                    })
                    .map(|(i, _)| i)
                    .collect()
            })
            .unwrap_or_default();
        let piece_doc = Document::read(path).map_err(|e| e.to_string())?;
        let (piece, _) = piece_doc.load().map_err(|e| e.to_string())?;
        if piece.meshes.iter().all(|m| m.indices.is_empty()) {
            return Err(format!("{} holds no triangles", path.display()));
        }
        let warnings = piece.warnings.clone();
        // The piece's materials: the session's of the same name, else added.
        let mut material_of = Vec::new();
        for k in 0..piece.materials.len() {
            let found =
                (self.source.materials.iter()).position(|m| m.name == piece.materials[k].name);
            material_of.push(match found {
                Some(i) => i,
                None => {
                    let m = pieces::merge_material(&mut self.source, &piece, k);
                    self.source.materials.push(m);
                    self.origins.material_gltf.push(None);
                    self.source.materials.len() - 1
                }
            });
        }
        let new_meshes: Vec<crate::scene::Mesh> = (piece.meshes.iter())
            .filter(|m| !m.indices.is_empty())
            .map(|m| crate::scene::Mesh {
                material: material_of[m.material],
                ..m.clone()
            })
            .collect();
        // Baked meshes leave the world-space BVH (made unhittable in place); the node then
        // places the new meshes as instances: no replacement builds the world BVH again.
        let mut placements: Vec<(usize, Instance)> = Vec::new();
        let mut removed = Vec::new();
        for &ni in &users {
            let world = self.origins.node_world.get(ni).copied().unwrap_or_default();
            let mut object = None;
            for mi in 0..self.source.meshes.len() {
                if self.origins.mesh_node[mi] == Some(ni) {
                    self.origins.mesh_node[mi] = None;
                    let m = &mut self.source.meshes[mi];
                    object.get_or_insert(m.attrs.object.clone());
                    if !m.indices.is_empty() {
                        removed.push(mi);
                    }
                    m.indices = Vec::new();
                    m.positions = Vec::new();
                }
            }
            if let Some(object) = object {
                let inst = Instance {
                    motion: None,
                    mesh: 0,
                    to_world: world,
                    material: None,
                    object,
                };
                placements.push((ni, inst));
            }
        }
        // Instanced meshes: each placement of a user node places the new meshes instead.
        let mut old_meshes = HashSet::new();
        let mut kept = Vec::new();
        let mut kept_nodes = Vec::new();
        for (inst, &n) in self
            .source
            .instances
            .iter()
            .zip(&self.origins.instance_node)
        {
            if users.contains(&n) {
                old_meshes.insert(inst.mesh);
                if !placements.iter().any(|(pn, p)| {
                    *pn == n && p.to_world == inst.to_world && p.object == inst.object
                }) {
                    placements.push((n, inst.clone()));
                }
            } else {
                kept.push(inst.clone());
                kept_nodes.push(n);
            }
        }
        let first = self.source.meshes.len();
        if !placements.is_empty() {
            for m in &new_meshes {
                self.source.meshes.push(m.clone());
                self.origins.mesh_node.push(None);
            }
            for (n, p) in placements {
                for k in 0..new_meshes.len() {
                    kept.push(Instance {
                        motion: None,
                        mesh: first + k,
                        material: None,
                        ..p.clone()
                    });
                    kept_nodes.push(n);
                }
            }
            for mi in old_meshes {
                let m = &mut self.source.meshes[mi];
                m.indices = Vec::new();
                m.positions = Vec::new();
            }
            self.source.instances = kept;
            self.origins.instance_node = kept_nodes;
        }
        let mut warnings = warnings;
        let changed: Vec<usize> = (first..self.source.meshes.len()).collect();
        warnings.extend(self.out_of_world(&removed, &changed));
        Ok(warnings)
    }
}

/// Everything the session knows.
#[derive(Default)]
pub struct State {
    pub loaded: Option<Loaded>,
    pub view: Option<View>,
    pub settings: Settings,
    /// Grows with every accepted change.
    pub generation: u64,
}

/// What an accepted command asks of the render loop.
#[derive(Clone, Debug, PartialEq)]
pub enum Effect {
    /// The image changes: start again.
    Restart,
    Pause,
    Resume,
    Stop,
}

impl State {
    /// Applies `command`; on success what the loop must do and what to report.
    pub fn apply(&mut self, command: Command) -> Result<(Effect, Vec<String>), String> {
        let mut warnings = Vec::new();
        match command {
            Command::Pause => return Ok((Effect::Pause, warnings)),
            Command::Resume => return Ok((Effect::Resume, warnings)),
            Command::Stop => return Ok((Effect::Stop, warnings)),
            Command::Load { path } => {
                let mut loaded = Loaded::read(&path)?;
                warnings.extend(loaded.warnings().iter().cloned());
                if let Some(v) = &self.view {
                    let (cam, w) = pieces::camera(&v.camera.matrix, &v.camera.camera)?;
                    warnings.extend(w);
                    loaded.render.set_camera(Some(cam));
                }
                self.apply_scene_settings(&mut loaded);
                self.loaded = Some(loaded);
            }
            Command::View(v) => {
                let (cam, w) = pieces::camera(&v.camera.matrix, &v.camera.camera)?;
                warnings.extend(w);
                if let Some(l) = &mut self.loaded {
                    l.render.set_camera(Some(cam));
                }
                self.view = Some(v);
            }
            Command::Settings(fields) => {
                let (s, unknown) = self.settings.patched(&fields)?;
                if !unknown.is_empty() {
                    warnings.push(format!(
                        "settings: unknown fields ignored: {}",
                        unknown.join(", ")
                    ));
                }
                self.settings = s;
                if let Some(mut l) = self.loaded.take() {
                    self.apply_scene_settings(&mut l);
                    self.loaded = Some(l);
                }
            }
            other => {
                let l = self
                    .loaded
                    .as_mut()
                    .ok_or("no scene is loaded (send `load` first)")?;
                match other {
                    Command::Transform { node, matrix } => {
                        let ni = l.node(&node)?;
                        warnings = l.transform(ni, matrix)?;
                    }
                    Command::Material { name, material } => {
                        warnings = l.material(&name, &material)?;
                    }
                    Command::Light {
                        node,
                        light,
                        matrix,
                    } => warnings = l.light(&node, &light, matrix)?,
                    Command::World { world } => warnings = l.world(&world)?,
                    Command::Visibility { node, visible } => l.visibility(&node, visible)?,
                    Command::Mesh { name, path } => warnings = l.mesh(&name, &path)?,
                    _ => unreachable!("handled above"),
                }
            }
        }
        self.generation += 1;
        Ok((Effect::Restart, warnings))
    }

    /// The settings that live in the prepared scene (film transparency).
    fn apply_scene_settings(&self, l: &mut Loaded) {
        let t = self
            .settings
            .film_transparent
            .unwrap_or(l.source.settings.film_transparent);
        l.render.scene.settings.film_transparent = t;
    }

    /// The options of a render of the view at `divider` times fewer pixels per side (1: the
    /// full view), `spp` samples; `None` without a scene and a view.
    pub fn render_options(
        &self,
        divider: u32,
        threads: usize,
    ) -> Option<(RenderOptions, [u32; 4])> {
        let (l, v) = (self.loaded.as_ref()?, self.view.as_ref()?);
        let s = &self.settings;
        let file = &l.source.settings;
        let d = divider.max(1);
        let (w, h) = (v.width.div_ceil(d), v.height.div_ceil(d));
        let window = v.border.unwrap_or([0, 0, v.width, v.height]);
        let [bx, by, bw, bh] = window;
        let region = v.border.map(|_| {
            let (x, y) = ((bx / d).min(w - 1), (by / d).min(h - 1));
            [x, y, bw.div_ceil(d).min(w - x), bh.div_ceil(d).min(h - y)]
        });
        let opts = RenderOptions {
            width: w,
            height: h,
            spp: 1,
            max_depth: s.max_depth.or(file.max_depth).unwrap_or(16),
            seed: s.seed.or(file.seed).unwrap_or(0),
            integrator: (s.integrator.clone())
                .or_else(|| file.integrator.clone())
                .unwrap_or_else(|| "path_mis".into()),
            threads,
            tile_size: 32,
            region,
            passes: Default::default(),
            adaptive: None,
            time_limit: None,
            filter: PixelFilter::new(s.filter, s.filter_width),
            light_paths: crate::integrator::light_paths::LightPaths {
                diffuse: s.diffuse_bounces.unwrap_or(u32::MAX),
                glossy: s.glossy_bounces.unwrap_or(u32::MAX),
                transmission: s.transmission_bounces.unwrap_or(u32::MAX),
                volume: s.volume_bounces.unwrap_or(u32::MAX),
                transparent: s.transparent_bounces,
                clamp_direct: s.clamp_direct,
                clamp_indirect: s.clamp_indirect,
                caustics_reflective: s.caustics_reflective,
                caustics_refractive: s.caustics_refractive,
                filter_glossy: crate::integrator::filter_glossy::FilterGlossy::new(s.blur_glossy),
            },
        };
        Some((opts, window))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blur_glossy_is_a_number_of_at_least_zero() {
        let base = Settings::default();
        assert_eq!(base.blur_glossy, 0.0, "off unless sent");
        let patch = |v: Value| {
            let mut m = Map::new();
            m.insert("blur_glossy".into(), v);
            base.patched(&m)
        };
        let (s, unknown) = patch(serde_json::json!(1.5)).unwrap();
        assert!(unknown.is_empty());
        assert_eq!(s.blur_glossy, 1.5);
        for bad in [serde_json::json!(-1.0), serde_json::json!("soft")] {
            let e = patch(bad.clone()).unwrap_err();
            assert!(e.contains("blur_glossy"), "{bad}: {e}");
        }
    }
}
