//! A compiled material: a flat list of operations over a slot array (Cycles' SVM is the model:
//! each operation reads slots and writes slots), run once per shading point without allocating.

use super::closure::ClosureSet;
use super::globals::{ShadeEnv, ShaderGlobals};
use super::nodes;
use glam::Vec3;

/// Index of one `f32` in the slot array; a vector or colour takes three consecutive slots.
pub type Slot = u16;

/// The slot array and the closures one evaluation fills. One per thread, reused.
#[derive(Default)]
pub struct Scratch {
    pub slots: Vec<f32>,
    pub set: ClosureSet,
}

/// Slot access for operations.
pub struct Slots<'a>(pub &'a mut [f32]);

impl Slots<'_> {
    #[inline(always)]
    pub fn f(&self, s: Slot) -> f32 {
        self.0[s as usize]
    }
    #[inline(always)]
    pub fn v(&self, s: Slot) -> Vec3 {
        let i = s as usize;
        Vec3::new(self.0[i], self.0[i + 1], self.0[i + 2])
    }
    #[inline(always)]
    pub fn set_f(&mut self, s: Slot, x: f32) {
        self.0[s as usize] = x;
    }
    #[inline(always)]
    pub fn set_v(&mut self, s: Slot, x: Vec3) {
        let i = s as usize;
        self.0[i] = x.x;
        self.0[i + 1] = x.y;
        self.0[i + 2] = x.z;
    }
}

/// One operation. Each node family owns its payload type and its evaluation.
#[derive(Clone, Debug)]
pub enum Op {
    Closure(nodes::bsdf::ClosureOp),
    Input(nodes::input::InputOp),
    Image(nodes::image::ImageOp),
    Vector(nodes::vector::VectorOp),
    Transform(nodes::transform::TransformOp),
    Wireframe(nodes::wireframe::WireframeOp),
    LightFalloff(nodes::light_falloff::LightFalloffOp),
    Ao(nodes::ao::AoOp),
    Bevel(nodes::bevel::BevelOp),
    Convert(nodes::convert::ConvertOp),
    Texture(nodes::texture::TextureOp),
    Utility(nodes::utility::UtilityOp),
    Bump(nodes::bump::BumpOp),
    Displacement(nodes::displacement::DisplacementOp),
    Environment(nodes::environment::EnvironmentOp),
    Sky(nodes::sky::SkyOp),
}

impl Op {
    #[inline]
    fn eval(&self, s: &mut Slots, g: &ShaderGlobals, env: &ShadeEnv, out: &mut ClosureSet) {
        match self {
            Op::Closure(op) => op.eval(s, g, out),
            Op::Input(op) => op.eval(s, g, env),
            Op::Image(op) => op.eval(s, g, env),
            Op::Vector(op) => op.eval(s, g),
            Op::Transform(op) => op.eval(s, g, env),
            Op::Wireframe(op) => op.eval(s, g),
            Op::LightFalloff(op) => op.eval(s, g),
            Op::Ao(op) => op.eval(s, g, env),
            Op::Bevel(op) => op.eval(s, g, env),
            Op::Convert(op) => op.eval(s),
            Op::Texture(op) => op.eval(s),
            Op::Utility(op) => op.eval(s),
            Op::Bump(op) => op.eval(s, g),
            Op::Displacement(op) => op.eval(s, g),
            Op::Environment(op) => op.eval(s, g, env),
            Op::Sky(op) => op.eval(s, g),
        }
    }
}

/// A compiled material graph.
#[derive(Clone, Debug, Default)]
pub struct Program {
    pub(crate) ops: Vec<Op>,
    /// Initial slot values (constants; outputs start at 0).
    pub(crate) init: Vec<f32>,
    /// The closures, when they do not depend on the shading point (then `ops` is not run).
    pub(crate) constant: Option<ClosureSet>,
    /// Whether any emission can come out of the program.
    pub(crate) may_emit: bool,
    /// Whether a transparent closure can come out of the program (shadow rays must then
    /// look through the surface).
    pub(crate) may_pass: bool,
    /// Whether a subsurface closure can come out of the program.
    pub(crate) may_scatter_below: bool,
    /// The medium inside meshes with this material (the material's volume); clear by
    /// default.
    pub(crate) medium: crate::medium::Medium,
}

impl Program {
    /// Runs the program at `g`; the result lives in `scratch` or, for constant programs, in
    /// the program itself.
    #[inline]
    pub fn eval<'a>(
        &'a self,
        g: &ShaderGlobals,
        env: &ShadeEnv,
        scratch: &'a mut Scratch,
    ) -> &'a ClosureSet {
        if let Some(c) = &self.constant {
            return c;
        }
        self.run(g, env, scratch);
        &scratch.set
    }

    /// The closures at a default shading point (at the origin, facing +Z): for programs
    /// whose closures do not depend on the point.
    pub(crate) fn run_at_origin(&self) -> ClosureSet {
        let globals = ShaderGlobals::at(Vec3::ZERO, Vec3::Z, glam::Vec2::ZERO);
        let env = ShadeEnv {
            images: &[],
            textures: &[],
            camera_to_world: glam::Mat4::IDENTITY,
            window: &crate::camera::NO_WINDOW,
            tracer: None,
        };
        let mut scratch = Scratch::default();
        self.run(&globals, &env, &mut scratch);
        scratch.set
    }

    /// The homogeneous medium inside meshes with this material ([`crate::medium`]).
    #[inline(always)]
    pub fn medium(&self) -> &crate::medium::Medium {
        &self.medium
    }

    /// The closures of a program that does not depend on the shading point.
    #[inline(always)]
    pub fn constant_set(&self) -> Option<&ClosureSet> {
        self.constant.as_ref()
    }

    /// Runs the operations into `scratch` (even for a constant program).
    pub(crate) fn run(&self, g: &ShaderGlobals, env: &ShadeEnv, scratch: &mut Scratch) {
        scratch.slots.clear();
        scratch.slots.extend_from_slice(&self.init);
        scratch.set.clear();
        let mut s = Slots(&mut scratch.slots);
        // Bump nodes evaluate their height at offset points: operations between Enter and
        // Leave see the moved point.
        let mut moved: Option<ShaderGlobals> = None;
        // A displacement rendered as bump replaces the normal the rest of the graph sees
        // (copied only then: most graphs read `g` as it is).
        let mut displaced: Option<ShaderGlobals> = None;
        for op in &self.ops {
            match op {
                Op::Bump(nodes::bump::BumpOp::Enter { axis }) => {
                    moved = Some(displaced.as_ref().unwrap_or(g).offset(*axis))
                }
                Op::Bump(nodes::bump::BumpOp::Leave) => moved = None,
                Op::Bump(nodes::bump::BumpOp::SetNormal { n }) => {
                    let v = s.v(*n);
                    if v.is_finite() && v != Vec3::ZERO {
                        let base = displaced.get_or_insert(*g);
                        base.n = v;
                        base.n_displaced = true;
                    }
                }
                _ => op.eval(
                    &mut s,
                    moved.as_ref().or(displaced.as_ref()).unwrap_or(g),
                    env,
                    &mut scratch.set,
                ),
            }
        }
    }

    /// Emission at a point (for emitters, which shade without a per-thread context).
    pub fn emission(&self, g: &ShaderGlobals, env: &ShadeEnv) -> Vec3 {
        if let Some(c) = &self.constant {
            return c.emission;
        }
        if !self.may_emit {
            return Vec3::ZERO;
        }
        SCRATCH.with(|s| {
            let mut s = s.borrow_mut();
            self.run(g, env, &mut s);
            s.set.emission
        })
    }

    /// The program as an [`nodes::environment::ImageWorld`], if that is all it computes.
    pub fn image_world(&self) -> Option<nodes::environment::ImageWorld> {
        if self.constant.is_some() || !self.may_emit {
            return None;
        }
        nodes::environment::ImageWorld::recognise(&self.ops, &self.init)
    }

    /// True when the program may emit light somewhere.
    pub fn may_emit(&self) -> bool {
        self.may_emit
    }

    /// True when the surface may scatter light below itself somewhere (subsurface).
    pub fn may_scatter_below(&self) -> bool {
        self.may_scatter_below
    }

    /// True when the surface may be partly transparent somewhere.
    pub fn may_pass(&self) -> bool {
        self.may_pass
    }

    /// The straight-through transmittance at a point (the summed weight of the transparent
    /// closures), for shadow rays.
    pub fn transparency(&self, g: &ShaderGlobals, env: &ShadeEnv, scratch: &mut Scratch) -> Vec3 {
        if !self.may_pass {
            return Vec3::ZERO;
        }
        self.eval(g, env, scratch).transparency()
    }

    /// Number of operations run per shading point (0 for constant programs).
    pub fn len(&self) -> usize {
        if self.constant.is_some() {
            0
        } else {
            self.ops.len()
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// Runs `f` with this thread's scratch space.
pub fn with_scratch<R>(f: impl FnOnce(&mut Scratch) -> R) -> R {
    SCRATCH.with(|s| f(&mut s.borrow_mut()))
}
