//! Graph → [`Program`]: nodes are compiled depth-first from the material output, each once
//! (its outputs get slots), with Cycles' implicit conversions between socket types. Shader
//! sockets are compiled with a weight: a Mix Shader splits its weight between its inputs, so
//! every closure node becomes one closure operation carrying the product of the factors above
//! it (Cycles' closure weights).
//!
//! Nothing is dropped silently: a node the renderer does not implement is evaluated as Blender
//! evaluates a muted node (its internal links, else zero) and reported once in `warnings`,
//! naming the material and the node.

use super::globals::{ShadeEnv, ShaderGlobals};
use super::graph::{Graph, Input};
use super::nodes;
use super::program::{Op, Program, Scratch, Slot, Slots};
use glam::Vec3;
use serde_json::Value;
use std::collections::HashMap;

/// Most slots one program may use.
pub const MAX_SLOTS: usize = 4096;

/// The type of a socket's value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SocketType {
    Float,
    Vector,
    Color,
    Shader,
}

impl SocketType {
    pub fn width(self) -> usize {
        match self {
            SocketType::Float => 1,
            SocketType::Vector | SocketType::Color => 3,
            SocketType::Shader => 0,
        }
    }
}

/// A compile error: the graph cannot be turned into a program at all (a cycle, too many slots).
#[derive(Clone, Debug, PartialEq)]
pub struct CompileError(pub String);

type Result<T> = std::result::Result<T, CompileError>;

/// A compiled output: its slot and type.
#[derive(Clone, Copy, Debug)]
struct Out {
    slot: Slot,
    ty: SocketType,
}

enum State {
    Compiling,
    /// Compiled, with its outputs; `partial` when only the outputs asked for so far were
    /// computed (another output compiles the node again).
    Done(Vec<(String, Out)>, bool),
}

/// The compiler's state for one graph.
pub struct Compiler<'g> {
    graph: &'g Graph,
    material: &'g str,
    ops: Vec<Op>,
    init: Vec<f32>,
    /// Per (node, bump context): compiled outputs.
    state: HashMap<(usize, u8), State>,
    /// The bump context being compiled: 0 at the point, 1 and 2 at its offsets along the
    /// two surface directions (a Bump node evaluates its height three times).
    bump: u8,
    consts: HashMap<Vec<u32>, Slot>,
    warnings: Vec<String>,
    may_emit: bool,
    may_pass: bool,
    may_scatter_below: bool,
    /// Whether any operation depends on the shading point (else the closures are constant).
    varying: bool,
    /// A displacement replaced `N`: closures without a Normal input take the displaced one.
    displaced: bool,
    /// Compiling what reaches the Volume input (volume closures), not the Surface.
    volume: bool,
}

/// The result of compiling a material.
pub struct Compiled {
    pub program: Program,
    /// Fallbacks taken, one line each, naming the material and the node.
    pub warnings: Vec<String>,
}

/// Compiles `graph` of material `material`.
pub fn compile(graph: &Graph, material: &str) -> std::result::Result<Compiled, CompileError> {
    let mut c = Compiler::new(graph, material, false);
    if let Some((node, output)) = &graph.displacement {
        // True displacement alone moves the vertices (see [`compile_displacement`]) and leaves
        // the normal to the displaced geometry; "Displacement and Bump" adds the bump.
        if graph.displacement_method != "DISPLACEMENT" {
            c.displacement_as_bump(*node, output)?;
        }
    }
    if let Some((node, output)) = &graph.surface {
        let one = c.constant(&[1.0])?;
        c.shader_link(*node, output, one)?;
    } else if graph.volume.is_some() {
        // Only a volume: the surface lets rays into it (Cycles' SD_HAS_ONLY_VOLUME).
        let one = c.constant(&[1.0])?;
        let white = c.constant(&[1.0; 3])?;
        c.may_pass = true;
        c.push(
            Op::Closure(nodes::bsdf::ClosureOp::transparent(one, white)),
            false,
        );
    }
    let (medium, volume_warnings) = match &graph.volume {
        Some((node, output)) => compile_volume(graph, material, *node, output)?,
        None => (Default::default(), Vec::new()),
    };
    let mut program = Program {
        ops: c.ops,
        init: c.init,
        constant: None,
        may_emit: c.may_emit,
        may_pass: c.may_pass,
        may_scatter_below: c.may_scatter_below,
        medium,
    };
    if !c.varying {
        // Closure operations read only constant slots: run once now.
        let set = program.run_at_origin();
        program.may_emit = set.emission != Vec3::ZERO;
        program.may_pass = set.holdout != Vec3::ZERO
            || set
                .closures()
                .iter()
                .any(|c| matches!(c.kind, super::ClosureKind::Transparent { .. }));
        program.constant = Some(set);
    }
    let mut warnings = c.warnings;
    warnings.extend(volume_warnings);
    Ok(Compiled { program, warnings })
}

/// A material's true displacement (Cycles' methods "Displacement Only" and "Displacement and
/// Bump"): run at a mesh vertex, `program` leaves the displacement vector of the material
/// output's Displacement (Blender world space, metres) in slot `out`.
pub struct Displacer {
    pub program: Program,
    pub out: Slot,
    /// "Displacement Only": the normals come from the moved geometry (else the bump of the
    /// surface program perturbs the interpolated ones).
    pub renormal: bool,
}

impl Displacer {
    /// The displacement at `g` (Blender world space); zero where it is not finite.
    pub fn at(&self, g: &ShaderGlobals, env: &ShadeEnv, scratch: &mut Scratch) -> Vec3 {
        self.program.run(g, env, scratch);
        let d = Slots(&mut scratch.slots).v(self.out);
        if d.is_finite() { d } else { Vec3::ZERO }
    }
}

/// The program that moves the vertices of meshes with `graph`'s material, when its
/// displacement method displaces them (`None` for "Bump Only" and without a Displacement).
pub fn compile_displacement(
    graph: &Graph,
    material: &str,
) -> std::result::Result<Option<Displacer>, CompileError> {
    let Some((node, output)) = &graph.displacement else {
        return Ok(None);
    };
    let renormal = match graph.displacement_method.as_str() {
        "DISPLACEMENT" => true,
        "BOTH" => false,
        _ => return Ok(None),
    };
    let mut c = Compiler::new(graph, material, false);
    let out = c.link(*node, output, SocketType::Vector)?;
    let program = Program {
        ops: c.ops,
        init: c.init,
        ..Program::default()
    };
    Ok(Some(Displacer {
        program,
        out,
        renormal,
    }))
}

/// The medium of the volume `(node, output)` feeds into the material output's Volume, and what
/// was reported. The interior is homogeneous: a volume whose inputs vary through space is
/// evaluated once, at the origin, and reported.
fn compile_volume(
    graph: &Graph,
    material: &str,
    node: usize,
    output: &str,
) -> std::result::Result<(crate::medium::Medium, Vec<String>), CompileError> {
    let mut c = Compiler::new(graph, material, true);
    let one = c.constant(&[1.0])?;
    c.shader_link(node, output, one)?;
    if c.varying {
        let n = &graph.nodes[node];
        c.warn(format!(
            "material '{material}': the volume from node '{}' ({}) varies through space; it renders \
             homogeneous, with its value at the origin",
            n.name, n.kind
        ));
    }
    let program = Program {
        ops: c.ops,
        init: c.init,
        ..Program::default()
    };
    let set = program.run_at_origin();
    let mut warnings = c.warnings;
    if set.mixed_phase {
        warnings.push(format!(
            "material '{material}': volume scatter closures of different anisotropy render as \
             one lobe of their weighted mean anisotropy"
        ));
    }
    Ok((set.medium(), warnings))
}

impl<'g> Compiler<'g> {
    fn new(graph: &'g Graph, material: &'g str, volume: bool) -> Self {
        Compiler {
            graph,
            material,
            ops: Vec::new(),
            init: Vec::new(),
            state: HashMap::new(),
            bump: 0,
            consts: HashMap::new(),
            warnings: Vec::new(),
            may_emit: false,
            may_pass: false,
            may_scatter_below: false,
            varying: false,
            displaced: false,
            volume,
        }
    }

    /// The material output's Displacement as Cycles' "Bump Only": the displacement vector at
    /// the point and its two offsets, the displaced normal from them, and a Set Normal that
    /// the surface graph (compiled afterwards, from scratch) sees as `N`. With "Displacement
    /// and Bump" the vertices are displaced as well ([`compile_displacement`]).
    fn displacement_as_bump(&mut self, node: usize, output: &str) -> Result<()> {
        let center = self.link(node, output, SocketType::Vector)?;
        let mut d = [center; 3];
        for axis in [1u8, 2] {
            self.push(Op::Bump(nodes::bump::BumpOp::Enter { axis }), true);
            self.bump = axis;
            let r = self.link(node, output, SocketType::Vector);
            self.bump = 0;
            self.push(Op::Bump(nodes::bump::BumpOp::Leave), true);
            d[axis as usize] = r?;
        }
        let n = self.alloc(3)?;
        self.push(
            Op::Displacement(nodes::displacement::DisplacementOp::Normal { d, out: n }),
            true,
        );
        self.push(Op::Bump(nodes::bump::BumpOp::SetNormal { n }), true);
        // The surface reads N after the Set Normal: its nodes are compiled anew.
        self.state.clear();
        self.displaced = true;
        Ok(())
    }

    fn warn(&mut self, msg: String) {
        if !self.warnings.contains(&msg) {
            self.warnings.push(msg);
        }
    }

    fn alloc(&mut self, width: usize) -> Result<Slot> {
        let s = self.init.len();
        if s + width > MAX_SLOTS {
            return Err(CompileError(format!(
                "material '{}': the graph needs more than {MAX_SLOTS} values",
                self.material
            )));
        }
        self.init.resize(s + width, 0.0);
        Ok(s as Slot)
    }

    /// A slot holding `v` (shared between equal constants).
    pub fn constant(&mut self, v: &[f32]) -> Result<Slot> {
        let key: Vec<u32> = v.iter().map(|x| x.to_bits()).collect();
        if let Some(&s) = self.consts.get(&key) {
            return Ok(s);
        }
        let s = self.alloc(v.len())?;
        self.init[s as usize..s as usize + v.len()].copy_from_slice(v);
        self.consts.insert(key, s);
        Ok(s)
    }

    fn push(&mut self, op: Op, varying: bool) {
        self.varying |= varying;
        self.ops.push(op);
    }

    /// Compiles node `n` (once, or again for an output a partial compile left out) and
    /// returns its outputs; `wanted` is the output being asked for.
    fn node_outputs(&mut self, n: usize, wanted: &str) -> Result<Vec<(String, Out)>> {
        let mut before = Vec::new();
        let key = (n, self.bump);
        match self.state.get(&key) {
            Some(State::Done(outs, partial)) => {
                if !*partial || outs.iter().any(|(id, _)| id == wanted) {
                    return Ok(outs.clone());
                }
                before = outs.clone();
            }
            Some(State::Compiling) => {
                return Err(CompileError(format!(
                    "material '{}': the node graph has a cycle through node '{}'",
                    self.material, self.graph.nodes[n].name
                )));
            }
            None => {}
        }
        self.state.insert(key, State::Compiling);
        let mut cx = NodeCx {
            c: self,
            node: n,
            outs: Vec::new(),
            wanted: Some(wanted.to_string()),
            partial: false,
        };
        let kind = cx.c.graph.nodes[n].kind.clone();
        let known = nodes::compile(&kind, &mut cx)?;
        if !known {
            cx.mute()?;
        }
        let partial = cx.partial;
        let mut outs = before;
        outs.extend(cx.outs);
        self.state.insert(key, State::Done(outs.clone(), partial));
        Ok(outs)
    }

    /// The slot of `output` of node `n`, converted to `want`.
    fn link(&mut self, n: usize, output: &str, want: SocketType) -> Result<Slot> {
        let outs = self.node_outputs(n, output)?;
        let found = outs.iter().find(|(id, _)| id == output).map(|(_, o)| *o);
        let Some(o) = found else {
            let node = &self.graph.nodes[n];
            let msg = format!(
                "material '{}': node '{}' ({}) has no output '{}' the renderer computes; it reads as zero",
                self.material, node.name, node.kind, output
            );
            self.warn(msg);
            return self.constant(&vec![0.0; want.width().max(1)]);
        };
        self.convert(o, want)
    }

    /// Cycles' implicit conversions between socket types.
    fn convert(&mut self, o: Out, want: SocketType) -> Result<Slot> {
        use SocketType::*;
        Ok(match (o.ty, want) {
            (a, b) if a == b => o.slot,
            (Vector, Color) | (Color, Vector) => o.slot,
            (Float, Vector | Color) => {
                let out = self.alloc(3)?;
                self.push(
                    Op::Convert(nodes::convert::ConvertOp::FloatToVec { a: o.slot, out }),
                    false,
                );
                out
            }
            (Color, Float) => {
                let out = self.alloc(1)?;
                self.push(
                    Op::Convert(nodes::convert::ConvertOp::ColorToFloat { a: o.slot, out }),
                    false,
                );
                out
            }
            (Vector, Float) => {
                let out = self.alloc(1)?;
                self.push(
                    Op::Convert(nodes::convert::ConvertOp::VectorToFloat { a: o.slot, out }),
                    false,
                );
                out
            }
            (Shader, _) | (_, Shader) => self.constant(&vec![0.0; want.width().max(1)])?,
            _ => o.slot,
        })
    }

    /// Compiles what feeds a shader socket with weight slot `w`: a closure node, or a colour
    /// (which Cycles turns into an emission closure).
    fn shader_link(&mut self, n: usize, output: &str, w: Slot) -> Result<()> {
        let kind = self.graph.nodes[n].kind.clone();
        if nodes::bsdf::is_shader_node(&kind) {
            let key = (n, self.bump);
            if matches!(self.state.get(&key), Some(State::Compiling)) {
                return Err(CompileError(format!(
                    "material '{}': the node graph has a cycle through node '{}'",
                    self.material, self.graph.nodes[n].name
                )));
            }
            self.state.insert(key, State::Compiling);
            let mut cx = NodeCx {
                c: self,
                node: n,
                outs: Vec::new(),
                wanted: None,
                partial: false,
            };
            let known = nodes::bsdf::compile_closure(&kind, &mut cx, w)?;
            if !known {
                // A muted shader node passes its first linked shader input through.
                let node = &cx.c.graph.nodes[n];
                let through = node
                    .internal_links
                    .iter()
                    .find(|(o, _)| o == output)
                    .map(|(_, i)| i.clone());
                let msg = format!(
                    "material '{}': shader node '{}' ({}) is not supported; it renders as muted",
                    cx.c.material, node.name, node.kind
                );
                cx.c.warn(msg);
                if let Some(i) = through {
                    cx.shader(&i, w)?;
                }
            }
            self.state.remove(&key);
            return Ok(());
        }
        // A value linked into a shader socket: emission of that colour.
        let color = self.link(n, output, SocketType::Color)?;
        let one = self.constant(&[1.0])?;
        let op = nodes::bsdf::ClosureOp::emission(w, color, one);
        self.may_emit = true;
        self.push(Op::Closure(op), false);
        Ok(())
    }
}

/// What a node family's compile function sees: the node, its inputs as slots, its outputs.
pub struct NodeCx<'c, 'g> {
    c: &'c mut Compiler<'g>,
    node: usize,
    outs: Vec<(String, Out)>,
    wanted: Option<String>,
    partial: bool,
}

impl<'g> NodeCx<'_, 'g> {
    pub fn material(&self) -> &'g str {
        self.c.material
    }

    pub fn node(&self) -> &'g super::graph::Node {
        &self.c.graph.nodes[self.node]
    }

    /// The output being asked for (`None` for shader nodes).
    pub fn wanted(&self) -> Option<&str> {
        self.wanted.as_deref()
    }

    /// Declares that only some outputs were compiled: asking for another one compiles the
    /// node again for it.
    pub fn partial(&mut self) {
        self.partial = true;
    }

    /// Whether the node is reached from the Volume input.
    pub fn in_volume(&self) -> bool {
        self.c.volume
    }

    /// The material's displacement replaced the shading normal `N`.
    pub fn displaced(&self) -> bool {
        self.c.displaced
    }

    pub fn is_linked(&self, id: &str) -> bool {
        matches!(self.node().input(id), Some(Input::Link { .. }))
    }

    /// The first component of input `id`'s constant, when it has one (not linked, given).
    pub fn input_f32(&self, id: &str) -> Option<f32> {
        match self.node().input(id) {
            Some(Input::Const(v)) => v.first().copied(),
            _ => None,
        }
    }

    /// Vector input `id` when it is linked (inputs such as Normal whose unlinked value is the
    /// shading point's own, not the socket's constant); `None` when unlinked.
    pub fn linked_vector(&mut self, id: &str) -> Result<Option<Slot>> {
        if self.is_linked(id) {
            self.vector(id, Vec3::ZERO).map(Some)
        } else {
            Ok(None)
        }
    }

    /// Input `id` as a slot of type `ty`: its link, its constant, or `default`.
    pub fn input(&mut self, id: &str, ty: SocketType, default: &[f32]) -> Result<Slot> {
        match self.node().input(id) {
            Some(Input::Link { node, output }) => self.c.link(*node, output, ty),
            Some(Input::Const(v)) => {
                let w = ty.width();
                let mut val = vec![0.0; w];
                if v.len() == 1 {
                    val.iter_mut().for_each(|x| *x = v[0]);
                } else if w == 1 {
                    // A vector/colour constant in a float socket: Cycles' conversions.
                    val[0] = match ty {
                        _ if v.len() >= 3 => {
                            if self.is_color_default(v) {
                                luminance(Vec3::new(v[0], v[1], v[2]))
                            } else {
                                (v[0] + v[1] + v[2]) / 3.0
                            }
                        }
                        _ => v[0],
                    };
                } else {
                    for (i, x) in val.iter_mut().enumerate() {
                        *x = v.get(i).copied().unwrap_or(0.0);
                    }
                }
                self.c.constant(&val)
            }
            None => {
                let w = ty.width();
                let mut val = vec![0.0; w];
                for (i, x) in val.iter_mut().enumerate() {
                    *x = default.get(i).or(default.first()).copied().unwrap_or(0.0);
                }
                self.c.constant(&val)
            }
        }
    }

    fn is_color_default(&self, v: &[f32]) -> bool {
        v.len() == 4
    }

    pub fn float(&mut self, id: &str, default: f32) -> Result<Slot> {
        self.input(id, SocketType::Float, &[default])
    }

    pub fn vector(&mut self, id: &str, default: Vec3) -> Result<Slot> {
        self.input(id, SocketType::Vector, &default.to_array())
    }

    pub fn color(&mut self, id: &str, default: Vec3) -> Result<Slot> {
        self.input(id, SocketType::Color, &default.to_array())
    }

    /// The constant value of input `id` when it is not linked.
    pub fn const_value(&self, id: &str) -> Option<&'g [f32]> {
        match self.node().input(id) {
            Some(Input::Const(v)) => Some(v),
            _ => None,
        }
    }

    /// Declares output `id` of type `ty` and returns its slot.
    pub fn output(&mut self, id: &str, ty: SocketType) -> Result<Slot> {
        let slot = self.c.alloc(ty.width().max(1))?;
        self.outs.push((id.to_string(), Out { slot, ty }));
        Ok(slot)
    }

    /// Declares output `id` as an alias of an existing slot.
    pub fn alias(&mut self, id: &str, slot: Slot, ty: SocketType) {
        self.outs.push((id.to_string(), Out { slot, ty }));
    }

    pub fn constant(&mut self, v: &[f32]) -> Result<Slot> {
        self.c.constant(v)
    }

    pub fn alloc(&mut self, width: usize) -> Result<Slot> {
        self.c.alloc(width)
    }

    /// Emits an operation; `varying` when its result depends on the shading point.
    pub fn emit(&mut self, op: Op, varying: bool) {
        self.c.push(op, varying);
    }

    /// Marks the program as possibly emitting.
    pub fn emits(&mut self) {
        self.c.may_emit = true;
    }

    /// Marks the program as possibly scattering below the surface (a subsurface closure).
    pub fn scatters_below(&mut self) {
        self.c.may_scatter_below = true;
    }

    /// Marks the program as possibly letting light straight through (a transparent closure).
    pub fn passes(&mut self) {
        self.c.may_pass = true;
    }

    /// Compiles what feeds shader input `id` with weight slot `w` (nothing when unlinked).
    pub fn shader(&mut self, id: &str, w: Slot) -> Result<()> {
        if let Some(Input::Link { node, output }) = self.node().input(id) {
            self.c.shader_link(*node, output, w)?;
        }
        Ok(())
    }

    pub fn prop(&self, key: &str) -> Option<&'g Value> {
        self.node().props.get(key)
    }

    pub fn prop_str(&self, key: &str) -> Option<&'g str> {
        self.prop(key).and_then(Value::as_str)
    }

    pub fn prop_bool(&self, key: &str, default: bool) -> bool {
        self.prop(key).and_then(Value::as_bool).unwrap_or(default)
    }

    pub fn prop_f32(&self, key: &str, default: f32) -> f32 {
        self.prop(key)
            .and_then(Value::as_f64)
            .map(|x| x as f32)
            .filter(|x| x.is_finite())
            .unwrap_or(default)
    }

    /// Compiles input `id` as a float at the two offset points of a Bump node: the slots of
    /// its value at `P + dPdx` and `P + dPdy` (the operations in between run with the
    /// shading point moved).
    pub fn float_at_offsets(&mut self, id: &str, default: f32) -> Result<[Slot; 2]> {
        let saved = self.c.bump;
        let mut out = [0; 2];
        for (i, axis) in [1u8, 2].into_iter().enumerate() {
            self.c
                .push(Op::Bump(nodes::bump::BumpOp::Enter { axis }), true);
            self.c.bump = axis;
            let r = self.float(id, default);
            self.c.bump = saved;
            self.c.push(Op::Bump(nodes::bump::BumpOp::Leave), true);
            out[i] = r?;
        }
        Ok(out)
    }

    /// Reports a fallback once, naming the material and the node.
    pub fn warn(&mut self, what: &str) {
        let node = self.node();
        let msg = format!(
            "material '{}': node '{}' ({}): {}",
            self.c.material, node.name, node.kind, what
        );
        self.c.warn(msg);
    }

    /// Evaluates the node as Blender evaluates a muted node (internal links, else zero), and
    /// reports it.
    pub fn mute(&mut self) -> Result<()> {
        let node = self.node();
        let msg = format!(
            "material '{}': node '{}' ({}) is not supported; it renders as muted",
            self.c.material, node.name, node.kind
        );
        self.c.warn(msg);
        for (out, inp) in &node.internal_links {
            let ty = match node.input(inp) {
                Some(Input::Const(v)) if v.len() == 1 => SocketType::Float,
                _ => SocketType::Color,
            };
            let s = self.input(inp, ty, &[0.0])?;
            self.alias(out, s, ty);
        }
        Ok(())
    }
}

/// Cycles' colour → float conversion: luminance with the scene's (OCIO) Rec. 709 weights.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    super::nodes::color::rgb_to_bw(c)
}
