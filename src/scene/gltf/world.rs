//! `TESELA_world` (root): the world's constant colour (the fallback), its node graph, camera
//! visibility and importance-sampling settings (docs/extensions.md). Problems with the graph
//! are reported and fall back, never fail the load: a graph that does not parse renders as the
//! constant colour, an image that cannot be read as Cycles renders a missing one (magenta), a
//! Sky Texture of the Hosek-Wilkie model (not rendered) as the world's colour.

use super::{Loader, member, num, rgb};
use crate::scene::WorldSampling;
use glam::Vec3;
use serde_json::{Value, json};

impl Loader<'_> {
    pub(super) fn world(&mut self, w: &Value) {
        let name = member(w, "name")
            .and_then(Value::as_str)
            .unwrap_or("World")
            .to_string();
        self.scene.world.name = name.clone();
        let color = rgb(w, "color").unwrap_or(Vec3::ZERO);
        let strength = num(w, "strength").unwrap_or(1.0) as f32;
        let bg = color * strength;
        if bg.is_finite() && bg.min_element() >= 0.0 {
            self.scene.background = bg;
        } else {
            self.scene
                .warnings
                .push("TESELA_world: invalid color or strength, ignored".into());
        }
        let world = &mut self.scene.world;
        for (key, flag) in [
            ("visible_camera", &mut world.visible_camera),
            ("visible_diffuse", &mut world.visible_diffuse),
            ("visible_glossy", &mut world.visible_glossy),
            ("visible_transmission", &mut world.visible_transmission),
        ] {
            if let Some(v) = member(w, key).and_then(Value::as_bool) {
                *flag = v;
            }
        }
        let resolution = member(w, "map_resolution")
            .and_then(Value::as_u64)
            .unwrap_or(1024)
            .min(u32::MAX as u64) as u32;
        self.scene.world.sampling = match member(w, "sampling").and_then(Value::as_str) {
            None | Some("AUTOMATIC") => WorldSampling::Automatic,
            Some("MANUAL") => WorldSampling::Manual(resolution),
            Some("NONE") => WorldSampling::None,
            Some(other) => {
                self.warn_once(format!(
                    "world '{name}': sampling method `{other}` is unknown; AUTOMATIC is used"
                ));
                WorldSampling::Automatic
            }
        };
        let Some(g) = member(w, "graph").filter(|g| !g.is_null()) else {
            return;
        };
        let mut graph = match crate::shading::Graph::from_json(g) {
            Ok(g) => g,
            Err(e) => {
                self.warn_once(format!(
                    "world '{name}': TESELA_world graph: {e}; the world renders as its colour {:?}",
                    self.scene.background.to_array()
                ));
                return;
            }
        };
        let fallback = color.max(Vec3::ZERO);
        for i in 0..graph.nodes.len() {
            let node = &graph.nodes[i];
            let sky = node
                .props
                .get("sky_type")
                .and_then(Value::as_str)
                .unwrap_or("MULTIPLE_SCATTERING");
            if node.kind == "ShaderNodeTexSky" && !crate::shading::nodes::sky::is_rendered(sky) {
                let msg = format!(
                    "world '{name}': node '{}' (ShaderNodeTexSky): the {sky} sky model is not \
                     rendered; it reads as the world's colour {:?}",
                    node.name,
                    fallback.to_array()
                );
                self.warn_once(msg);
                let node = &mut graph.nodes[i];
                node.kind = "ShaderNodeRGB".into();
                node.props = serde_json::Map::new();
                node.props
                    .insert("value".into(), json!(fallback.to_array()));
                node.inputs.clear();
                node.internal_links.clear();
                continue;
            }
            let Some(ii) = node.props.get("image").and_then(Value::as_u64) else {
                continue;
            };
            match self.graph_image(ii as usize) {
                Ok(image) => graph.nodes[i].image = Some(image),
                Err(e) => {
                    let msg = format!(
                        "world '{name}': node '{}': {}; it renders as a missing image",
                        graph.nodes[i].name, e.message
                    );
                    self.warn_once(msg);
                }
            }
        }
        self.scene.world.graph = Some(graph);
    }
}
