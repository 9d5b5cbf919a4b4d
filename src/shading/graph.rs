//! A material's node graph as the scene describes it (the `TESELA_material_graph` glTF
//! extension, or a preset such as glTF metallic-roughness): Blender's node types and socket
//! identifiers, with unlinked inputs as constants. [`super::compile`] turns it into a program.

use serde_json::{Map, Value};

/// One input socket's value.
#[derive(Clone, Debug, PartialEq)]
pub enum Input {
    /// The unlinked value: one number, or the components of a vector or colour.
    Const(Vec<f32>),
    /// Linked to output `output` (an identifier) of node `node`.
    Link { node: usize, output: String },
}

/// A node: Blender's `bl_idname`, its properties and its inputs by socket identifier.
#[derive(Clone, Debug, Default)]
pub struct Node {
    /// Blender's node name (for messages).
    pub name: String,
    /// Blender's `bl_idname`, e.g. `ShaderNodeBsdfPrincipled`.
    pub kind: String,
    pub props: Map<String, Value>,
    pub inputs: Vec<(String, Input)>,
    /// Output identifier → input identifier: how Blender passes values through a muted node.
    pub internal_links: Vec<(String, String)>,
    /// For image nodes: the index into the scene's images (resolved by the loader).
    pub image: Option<usize>,
    /// For UDIM image nodes: `(tile number, scene image)` of each tile (`tiles` prop).
    pub tiles: Vec<(u32, usize)>,
}

impl Node {
    pub fn new(kind: &str) -> Node {
        Node {
            name: kind.trim_start_matches("ShaderNode").to_string(),
            kind: kind.to_string(),
            ..Default::default()
        }
    }

    /// Builder: sets an unlinked input.
    pub fn with(mut self, id: &str, value: &[f32]) -> Node {
        self.set(id, Input::Const(value.to_vec()));
        self
    }

    /// Builder: links input `id` to `output` of node `node`.
    pub fn link(mut self, id: &str, node: usize, output: &str) -> Node {
        self.set(
            id,
            Input::Link {
                node,
                output: output.to_string(),
            },
        );
        self
    }

    /// Builder: sets a property.
    pub fn prop(mut self, key: &str, value: Value) -> Node {
        self.props.insert(key.to_string(), value);
        self
    }

    pub fn set(&mut self, id: &str, input: Input) {
        match self.inputs.iter_mut().find(|(k, _)| k == id) {
            Some(slot) => slot.1 = input,
            None => self.inputs.push((id.to_string(), input)),
        }
    }

    pub fn input(&self, id: &str) -> Option<&Input> {
        self.inputs.iter().find(|(k, _)| k == id).map(|(_, v)| v)
    }
}

/// A whole material graph.
#[derive(Clone, Debug, Default)]
pub struct Graph {
    pub nodes: Vec<Node>,
    /// What reaches the material output's Surface: `(node, output identifier)`.
    pub surface: Option<(usize, String)>,
    /// What reaches the material output's Displacement.
    pub displacement: Option<(usize, String)>,
    /// What reaches the material output's Volume: the closed mesh's interior.
    pub volume: Option<(usize, String)>,
    /// The material's displacement method: `"BUMP"` (Blender's default, also when absent),
    /// `"DISPLACEMENT"` or `"BOTH"`.
    pub displacement_method: String,
}

impl Graph {
    /// The first node of `kind` whose output `output` some node reads (for reports).
    pub fn node_with_linked_output(&self, kind: &str, output: &str) -> Option<&Node> {
        self.nodes.iter().enumerate().find_map(|(i, n)| {
            let read = self.nodes.iter().any(|m| {
                m.inputs.iter().any(|(_, inp)| {
                    matches!(inp, Input::Link { node, output: o } if *node == i && o == output)
                })
            }) || [&self.surface, &self.displacement, &self.volume]
                .into_iter()
                .any(|r| matches!(r, Some((node, o)) if *node == i && o == output));
            (n.kind == kind && read).then_some(n)
        })
    }

    /// Appends a node and returns its index.
    pub fn add(&mut self, node: Node) -> usize {
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    /// Parses a `TESELA_material_graph` object. Errors name the node and what is wrong; links
    /// to missing nodes are errors here, cycles are found by the compiler.
    pub fn from_json(v: &Value) -> Result<Graph, String> {
        let obj = v.as_object().ok_or("the graph is not a JSON object")?;
        if let Some(ver) = obj.get("version")
            && ver.as_u64() != Some(1)
        {
            return Err(format!("graph version {ver} is not supported (1 is)"));
        }
        let raw_nodes = match obj.get("nodes") {
            Some(Value::Array(a)) => a.as_slice(),
            None => &[],
            Some(_) => return Err("`nodes` is not an array".into()),
        };
        let n = raw_nodes.len();
        let mut nodes = Vec::with_capacity(n);
        for (i, rn) in raw_nodes.iter().enumerate() {
            let o = rn
                .as_object()
                .ok_or_else(|| format!("node {i} is not an object"))?;
            let kind = o
                .get("type")
                .and_then(Value::as_str)
                .ok_or_else(|| format!("node {i} has no `type`"))?
                .to_string();
            let name = o
                .get("name")
                .and_then(Value::as_str)
                .map(str::to_string)
                .unwrap_or_else(|| format!("{kind} {i}"));
            let props = match o.get("props") {
                Some(Value::Object(m)) => m.clone(),
                None | Some(Value::Null) => Map::new(),
                Some(_) => return Err(format!("node `{name}`: `props` is not an object")),
            };
            let mut inputs = Vec::new();
            if let Some(ins) = o.get("inputs") {
                let ins = ins
                    .as_object()
                    .ok_or_else(|| format!("node `{name}`: `inputs` is not an object"))?;
                for (id, val) in ins {
                    let input = parse_input(val, n)
                        .map_err(|e| format!("node `{name}`, input `{id}`: {e}"))?;
                    inputs.push((id.clone(), input));
                }
            }
            let mut internal_links = Vec::new();
            if let Some(Value::Object(m)) = o.get("internal_links") {
                for (out, inp) in m {
                    if let Some(s) = inp.as_str() {
                        internal_links.push((out.clone(), s.to_string()));
                    }
                }
            }
            nodes.push(Node {
                name,
                kind,
                props,
                inputs,
                internal_links,
                image: None,
                tiles: Vec::new(),
            });
        }
        let output = |key: &str| -> Result<Option<(usize, String)>, String> {
            match obj.get(key) {
                None | Some(Value::Null) => Ok(None),
                Some(v) => parse_link(v, n)
                    .map(Some)
                    .map_err(|e| format!("`{key}`: {e}")),
            }
        };
        Ok(Graph {
            surface: output("surface")?,
            displacement: output("displacement")?,
            volume: output("volume")?,
            displacement_method: match obj.get("displacement_method") {
                None | Some(Value::Null) => "BUMP".to_string(),
                Some(Value::String(m)) => m.clone(),
                Some(v) => return Err(format!("`displacement_method` is not a string: {v}")),
            },
            nodes,
        })
    }
}

fn parse_link(v: &Value, n: usize) -> Result<(usize, String), String> {
    let a = v
        .as_array()
        .filter(|a| a.len() == 2)
        .ok_or("a link is `[node index, output identifier]`")?;
    let node = a[0]
        .as_u64()
        .ok_or("a link's node index is not a non-negative integer")? as usize;
    if node >= n {
        return Err(format!("links to node {node}, but the graph has {n} nodes"));
    }
    let out = a[1].as_str().ok_or("a link's output is not a string")?;
    Ok((node, out.to_string()))
}

fn parse_input(v: &Value, n: usize) -> Result<Input, String> {
    match v {
        Value::Number(x) => Ok(Input::Const(vec![finite(x.as_f64())?])),
        Value::Bool(b) => Ok(Input::Const(vec![if *b { 1.0 } else { 0.0 }])),
        Value::Array(a) => {
            if a.is_empty() || a.len() > 16 {
                return Err(format!("a constant has {} components", a.len()));
            }
            a.iter()
                .map(|c| finite(c.as_f64()))
                .collect::<Result<Vec<_>, _>>()
                .map(Input::Const)
        }
        Value::Object(o) => {
            let l = o.get("link").ok_or("an object input needs `link`")?;
            let (node, output) = parse_link(l, n)?;
            Ok(Input::Link { node, output })
        }
        _ => Err("an input is a number, an array or {\"link\": [node, output]}".into()),
    }
}

fn finite(x: Option<f64>) -> Result<f32, String> {
    match x {
        Some(x) if x.is_finite() && x.abs() <= f32::MAX as f64 => Ok(x as f32),
        Some(x) => Err(format!("the constant {x} is not a finite number")),
        None => Err("a constant component is not a number".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn parses_nodes_links_and_constants() {
        let g = Graph::from_json(&json!({
            "version": 1,
            "nodes": [
                {"type": "ShaderNodeTexCoord", "name": "tc"},
                {"type": "ShaderNodeBsdfDiffuse", "inputs": {
                    "Color": [0.5, 0.25, 1.0, 1.0], "Roughness": 0.0,
                    "Normal": {"link": [0, "Normal"]}}}
            ],
            "surface": [1, "BSDF"]
        }))
        .unwrap();
        assert_eq!(g.nodes.len(), 2);
        assert_eq!(g.surface, Some((1, "BSDF".to_string())));
        assert_eq!(
            g.nodes[1].input("Normal"),
            Some(&Input::Link {
                node: 0,
                output: "Normal".into()
            })
        );
        assert_eq!(
            g.nodes[1].input("Color"),
            Some(&Input::Const(vec![0.5, 0.25, 1.0, 1.0]))
        );
    }

    #[test]
    fn bad_graphs_are_errors_that_say_where() {
        for (doc, needle) in [
            (
                json!({"nodes": [{"type": "X", "inputs": {"A": {"link": [5, "B"]}}}]}),
                "5",
            ),
            (
                json!({"nodes": [{"name": "n", "type": "X", "inputs": {"A": "s"}}]}),
                "`n`",
            ),
            (json!({"nodes": [{"inputs": {}}]}), "type"),
            (json!({"nodes": [], "surface": [0, "BSDF"]}), "surface"),
            (json!({"version": 7}), "version"),
            (json!([1, 2]), "object"),
        ] {
            let e = Graph::from_json(&doc).unwrap_err();
            assert!(e.contains(needle), "{e} should mention {needle}");
        }
    }
}
