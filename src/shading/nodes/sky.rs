//! The Sky Texture node (`ShaderNodeTexSky`) as Cycles' `svm_node_tex_sky` renders the
//! `PREETHAM` type ([`PreethamSky`]) and the `SINGLE_SCATTERING` and `MULTIPLE_SCATTERING` types: the precomputed sky table
//! ([`crate::shading::sky`]) looked up by direction, plus the sun disc (its radiance
//! interpolated between the disc's lowest and highest point, with limb darkening), XYZ to
//! scene linear, negatives clamped.
//!
//! Directions are Blender world space (Z up). The sun sits at elevation `e` and Cycles'
//! rotation `r` (after [`sun_position`]) in direction `(-cos e sin r, cos e cos r, sin e)`.

use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::{ShaderGlobals, ray};
use crate::shading::graph::{Graph, Input, Node};
use crate::shading::program::{Op, Slot, Slots};
use crate::shading::sky::{Atmosphere, Model, SkyTable, earth_intersection_angle, sun_radiance};
use glam::Vec3;
use std::f32::consts::{FRAC_2_PI, FRAC_PI_2, PI, TAU};
use std::sync::Arc;

/// The sun disc as the node draws it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunDisc {
    /// XYZ radiance at the disc's lowest and highest point (times the sun intensity).
    pub bottom: Vec3,
    pub top: Vec3,
    /// Angular diameter (radians).
    pub diameter: f32,
}

/// A Sky Texture's parameters, read from the node's properties as Cycles reads them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyParams {
    pub atmosphere: Atmosphere,
    /// Cycles' sun rotation (after [`sun_position`]), radians.
    pub sun_rotation: f32,
    /// `None`: no sun disc.
    pub sun_disc: Option<f32>,
    pub sun_intensity: f32,
    pub altitude: f32,
}

/// Cycles' `simplify_settings`: the sun's elevation wrapped into `[-π/2, π/2]` (going over the
/// zenith turns it half around) and its rotation into the kernel's `2π - r`, `r ∈ [0, 2π)`.
pub fn sun_position(elevation: f32, rotation: f32) -> (f32, f32) {
    let mut e = elevation % TAU;
    let mut r = rotation;
    if e.abs() >= PI {
        e -= (2.0f32).copysign(e) * PI;
    }
    if e >= FRAC_PI_2 || e <= -FRAC_PI_2 {
        e = PI.copysign(e) - e;
        r += PI;
    }
    r %= TAU;
    if r < 0.0 {
        r += TAU;
    }
    (e, TAU - r)
}

/// The unit direction (Blender world) towards the sun of elevation `e`, rotation `r` (both
/// after [`sun_position`]).
pub fn sun_direction(e: f32, r: f32) -> Vec3 {
    let (se, ce) = e.sin_cos();
    let (sr, cr) = r.sin_cos();
    Vec3::new(-ce * sr, ce * cr, se)
}

fn finite(v: Option<&serde_json::Value>, default: f32) -> f32 {
    v.and_then(serde_json::Value::as_f64)
        .map(|x| x as f32)
        .filter(|x| x.is_finite())
        .unwrap_or(default)
}

/// The model of a `sky_type` (Blender ≤ 4.x's `NISHITA` is single scattering); `None` for
/// the analytic models.
pub fn model_of(sky_type: &str) -> Option<Model> {
    match sky_type {
        "MULTIPLE_SCATTERING" => Some(Model::Multiple),
        "SINGLE_SCATTERING" | "NISHITA" => Some(Model::Single),
        _ => None,
    }
}

impl SkyParams {
    /// The parameters of `node` (defaults as Blender's); `None` for the analytic models.
    pub fn of(node: &Node) -> Option<SkyParams> {
        let p = |k: &str, d: f32| finite(node.props.get(k), d);
        let ty = node
            .props
            .get("sky_type")
            .and_then(serde_json::Value::as_str)
            .unwrap_or("MULTIPLE_SCATTERING");
        let model = model_of(ty)?;
        let (e, r) = sun_position(
            p("sun_elevation", 15f32.to_radians()),
            p("sun_rotation", 0.0),
        );
        let disc = node
            .props
            .get("sun_disc")
            .and_then(serde_json::Value::as_bool)
            .unwrap_or(true);
        let altitude = p("altitude", 100.0);
        // Older Blender calls the aerosols "dust".
        let aerosol = node
            .props
            .get("aerosol_density")
            .or_else(|| node.props.get("dust_density"));
        Some(SkyParams {
            atmosphere: Atmosphere {
                model,
                sun_elevation: e,
                altitude,
                // Blender's range starts at 0; a negative density would amplify the light.
                air: p("air_density", 1.0).max(0.0),
                aerosol: finite(aerosol, 1.0).max(0.0),
                ozone: p("ozone_density", 1.0).max(0.0),
            },
            sun_rotation: r,
            // Clamped for numerical precision, as Cycles.
            sun_disc: disc.then(|| p("sun_size", 0.009_512).max(0.0005)),
            sun_intensity: p("sun_intensity", 1.0),
            altitude,
        })
    }

    /// The disc as drawn (`None` without one).
    pub fn disc(&self) -> Option<SunDisc> {
        let d = self.sun_disc?;
        let (bottom, top) = sun_radiance(&self.atmosphere, d);
        Some(SunDisc {
            bottom: bottom * self.sun_intensity,
            top: top * self.sun_intensity,
            diameter: d,
        })
    }

    /// Unit direction towards the sun, Blender world.
    pub fn sun_dir(&self) -> Vec3 {
        sun_direction(self.atmosphere.sun_elevation, self.sun_rotation)
    }
}

/// The sun a world can sample directly (Cycles' "sun guiding").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuidedSun {
    /// Unit direction towards the sun's centre, Blender world.
    pub dir: Vec3,
    /// Half the angular diameter (radians).
    pub half_angle: f32,
    /// `∫ L dω` over the disc, scene linear RGB.
    pub power: Vec3,
}

/// The world's sun discs, as Cycles' background light sees them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Suns {
    None,
    /// Exactly one sun disc, on a sky node reading the plain view direction: sampled apart
    /// and left out of the importance map.
    Guided(GuidedSun),
    /// More than one, or a sky node whose direction is transformed: the map must resolve them.
    Unguided,
}

/// The sun discs of the Sky Textures in `graph`.
pub fn suns(graph: &Graph) -> Suns {
    let mut found = Suns::None;
    for node in graph.nodes.iter().filter(|n| n.kind == "ShaderNodeTexSky") {
        let Some(params) = SkyParams::of(node) else {
            continue;
        };
        let Some(disc) = params.disc() else {
            continue;
        };
        let plain = match node.input("Vector") {
            Some(Input::Link { node: from, output }) => graph
                .nodes
                .get(*from)
                .is_some_and(|n| n.kind == "ShaderNodeTexCoord" && output == "Generated"),
            _ => true,
        };
        let transformed = node
            .props
            .get("texture_mapping")
            .is_some_and(|v| !v.is_null());
        if !plain || transformed || !matches!(found, Suns::None) {
            return Suns::Unguided;
        }
        let half_angle = disc.diameter * 0.5;
        let visible = params.atmosphere.sun_elevation + half_angle
            > -earth_intersection_angle(params.altitude);
        if !visible || disc.top.max_element() <= 0.0 && disc.bottom.max_element() <= 0.0 {
            continue;
        }
        // Limb darkening 1 - 0.6 (1 - √(1 - ρ²)) averages 0.8 over the disc's area.
        let solid_angle = TAU * (1.0 - half_angle.cos());
        let centre = xyz_to_rgb(disc.bottom.lerp(disc.top, 0.5));
        found = Suns::Guided(GuidedSun {
            dir: params.sun_dir(),
            half_angle,
            power: centre * (0.8 * solid_angle),
        });
    }
    found
}

/// XYZ to scene linear Rec.709, negatives clamped (Cycles' `xyz_to_rgb_clamped`).
#[inline]
pub fn xyz_to_rgb(xyz: Vec3) -> Vec3 {
    let m = &super::color::XYZ_TO_RGB;
    Vec3::new(m[0].dot(xyz), m[1].dot(xyz), m[2].dot(xyz)).max(Vec3::ZERO)
}

/// The Sky Texture's operation, one per kind of model.
#[derive(Clone, Debug)]
pub enum SkyOp {
    Table(TableSky),
    Preetham(PreethamSky),
}

impl SkyOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals) {
        match self {
            SkyOp::Table(t) => t.eval(s, g),
            SkyOp::Preetham(p) => p.eval(s),
        }
    }
}

/// Single and multiple scattering: the precomputed table and the sun disc.
#[derive(Clone, Debug)]
pub struct TableSky {
    table: Arc<SkyTable>,
    disc: Option<SunDisc>,
    sun_elevation: f32,
    sun_rotation: f32,
    /// Lowest elevation (radians, negative) at which the sun is not behind the ground.
    min_sun_elevation: f32,
    vector: Slot,
    color: Slot,
}

impl TableSky {
    /// The op of `params` (precomputes the table unless one for the same atmosphere is live).
    pub fn new(params: &SkyParams, vector: Slot, color: Slot) -> TableSky {
        TableSky {
            table: SkyTable::shared(&params.atmosphere),
            disc: params.disc(),
            sun_elevation: params.atmosphere.sun_elevation,
            sun_rotation: params.sun_rotation,
            min_sun_elevation: -earth_intersection_angle(params.altitude),
            vector,
            color,
        }
    }

    /// Scene-linear radiance towards direction `v` (Blender world, any length); the sun disc
    /// is left out when `bake` (the importance map of a world whose sun is sampled apart).
    pub fn radiance(&self, v: Vec3, bake: bool) -> Vec3 {
        let len = v.length();
        let dir = if len > 0.0 && len.is_finite() {
            v / len
        } else {
            Vec3::ZERO
        };
        let theta = dir.z.clamp(-1.0, 1.0).acos();
        let phi = dir.y.atan2(dir.x);
        let elevation = FRAC_PI_2 - theta;
        let mut xyz = Vec3::ZERO;
        if let Some(disc) = &self.disc
            && !bake
        {
            let sun = sun_direction(self.sun_elevation, self.sun_rotation);
            // The angle between unit vectors, accurate near zero.
            let angle = 2.0 * (dir - sun).length().atan2((dir + sun).length());
            let half = disc.diameter * 0.5;
            if angle < half && elevation > self.min_sun_elevation {
                let y = (elevation - self.sun_elevation) / disc.diameter + 0.5;
                let rho = angle / half;
                let limb = 1.0 - 0.6 * (1.0 - (1.0 - rho * rho).max(0.0).sqrt());
                xyz = disc.bottom.lerp(disc.top, y) * limb;
            }
        }
        let x = (-phi - FRAC_PI_2 + self.sun_rotation) / TAU;
        let x = x - x.floor();
        // The inverse of the table's elevation mapping.
        let y = (elevation.abs() * FRAC_2_PI).sqrt().copysign(elevation) * 0.5 + 0.5;
        xyz += self.table.lookup(x, y);
        xyz_to_rgb(xyz)
    }

    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals) {
        let c = self.radiance(s.v(self.vector), g.ray_flags & ray::IMPORTANCE_BAKE != 0);
        s.set_v(self.color, c);
    }
}

/// Preetham, Shirley and Smits' analytic daylight (Cycles' `PREETHAM`): Perez functions of
/// the view's zenith angle `θ` and its angle `γ` to the sun for the CIE xyY of the sky, each
/// normalised by its value at the zenith and scaled to the model's zenith value.
#[derive(Clone, Debug)]
pub struct PreethamSky {
    /// The sun's zenith angle and Cycles' azimuth (`atan2(x, y)` of its direction).
    theta: f32,
    phi: f32,
    /// Zenith values of Y, x, y over their Perez functions at the zenith.
    radiance: [f32; 3],
    /// Perez coefficients of Y, x, y.
    config: [[f32; 5]; 3],
    vector: Slot,
    color: Slot,
}

fn perez(lam: &[f32; 5], theta: f32, gamma: f32) -> f32 {
    let cg = gamma.cos();
    (1.0 + lam[0] * (lam[1] / theta.cos()).exp())
        * (1.0 + lam[2] * (lam[3] * gamma).exp() + lam[4] * cg * cg)
}

impl PreethamSky {
    /// The model for a sun towards `sun` (Blender world) and `turbidity`.
    pub fn new(sun: Vec3, turbidity: f32, vector: Slot, color: Slot) -> PreethamSky {
        let sun = sun.try_normalize().unwrap_or(Vec3::Z);
        let theta = sun.z.clamp(-1.0, 1.0).acos();
        let phi = sun.x.atan2(sun.y);
        let (t, t2) = (turbidity, turbidity * turbidity);
        let (th, th2, th3) = (theta, theta * theta, theta * theta * theta);
        let chi = (4.0 / 9.0 - t / 120.0) * (PI - 2.0 * theta);
        let zenith_y = ((4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192) * 0.06;
        let zenith_x = (0.00166 * th3 - 0.00375 * th2 + 0.00209 * th) * t2
            + (-0.02903 * th3 + 0.06377 * th2 - 0.03202 * th + 0.00394) * t
            + (0.11693 * th3 - 0.21196 * th2 + 0.06052 * th + 0.25886);
        let zenith_yy = (0.00275 * th3 - 0.00610 * th2 + 0.00317 * th) * t2
            + (-0.04214 * th3 + 0.08970 * th2 - 0.04153 * th + 0.00516) * t
            + (0.15346 * th3 - 0.26756 * th2 + 0.06670 * th + 0.26688);
        let config = [
            [
                0.1787 * t - 1.4630,
                -0.3554 * t + 0.4275,
                -0.0227 * t + 5.3251,
                0.1206 * t - 2.5771,
                -0.0670 * t + 0.3703,
            ],
            [
                -0.0193 * t - 0.2592,
                -0.0665 * t + 0.0008,
                -0.0004 * t + 0.2125,
                -0.0641 * t - 0.8989,
                -0.0033 * t + 0.0452,
            ],
            [
                -0.0167 * t - 0.2608,
                -0.0950 * t + 0.0092,
                -0.0079 * t + 0.2102,
                -0.0441 * t - 1.6537,
                -0.0109 * t + 0.0529,
            ],
        ];
        let radiance = [zenith_y, zenith_x, zenith_yy]
            .iter()
            .zip(&config)
            .map(|(z, c)| z / perez(c, 0.0, theta))
            .collect::<Vec<_>>();
        PreethamSky {
            theta,
            phi,
            radiance: [radiance[0], radiance[1], radiance[2]],
            config,
            vector,
            color,
        }
    }

    /// Scene-linear radiance towards `v` (Blender world, any length).
    pub fn radiance(&self, v: Vec3) -> Vec3 {
        let d = v.try_normalize().unwrap_or(Vec3::ZERO);
        let theta = d.z.clamp(-1.0, 1.0).acos();
        let phi = FRAC_PI_2 - d.y.atan2(d.x);
        let cos_psi = theta.sin() * self.theta.sin() * (self.phi - phi).cos()
            + theta.cos() * self.theta.cos();
        let gamma = cos_psi.clamp(-1.0, 1.0).acos();
        // Below the horizon the sky is the horizon's.
        let theta = theta.min(FRAC_PI_2 - 0.001);
        let yy = self.radiance[0] * perez(&self.config[0], theta, gamma);
        let x = self.radiance[1] * perez(&self.config[1], theta, gamma);
        let y = self.radiance[2] * perez(&self.config[2], theta, gamma);
        // xyY to XYZ, as Cycles (zero for a zero y).
        let big_x = if y != 0.0 { x / y * yy } else { 0.0 };
        let big_z = if y != 0.0 && yy != 0.0 {
            (1.0 - x - y) / y * yy
        } else {
            0.0
        };
        let c = xyz_to_rgb(Vec3::new(big_x, yy, big_z));
        if c.is_finite() { c } else { Vec3::ZERO }
    }

    #[inline]
    pub fn eval(&self, s: &mut Slots) {
        let c = self.radiance(s.v(self.vector));
        s.set_v(self.color, c);
    }
}

/// Compiles the Sky Texture; `Ok(false)` for other kinds.
pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    if kind != "ShaderNodeTexSky" {
        return Ok(false);
    }
    let ty = cx.prop_str("sky_type").unwrap_or("MULTIPLE_SCATTERING");
    let params = SkyParams::of(cx.node());
    if params.is_none() && ty != "PREETHAM" {
        cx.warn(&format!(
            "the {ty} sky model is not rendered; it reads as black"
        ));
        let black = cx.constant(&[0.0; 3])?;
        cx.alias("Color", black, SocketType::Color);
        return Ok(true);
    }
    if cx.prop("texture_mapping").is_some_and(|v| !v.is_null()) {
        cx.warn("the node's texture mapping is ignored");
    }
    let vector = super::environment::direction_input(cx)?;
    let color = cx.output("Color", SocketType::Color)?;
    let op = match params {
        Some(p) => SkyOp::Table(TableSky::new(&p, vector, color)),
        None => {
            let sun = cx
                .prop("sun_direction")
                .and_then(serde_json::Value::as_array)
                .and_then(|a| {
                    let v: Vec<f32> = a
                        .iter()
                        .filter_map(|x| x.as_f64())
                        .map(|x| x as f32)
                        .collect();
                    (v.len() == 3).then(|| Vec3::new(v[0], v[1], v[2]))
                })
                .filter(|v| v.is_finite())
                .unwrap_or(Vec3::Z);
            let turbidity = cx.prop_f32("turbidity", 2.2);
            SkyOp::Preetham(PreethamSky::new(sun, turbidity, vector, color))
        }
    };
    cx.emit(Op::Sky(op), true);
    Ok(true)
}

/// Whether `sky_type` renders (the Hosek-Wilkie model does not).
pub fn is_rendered(sky_type: &str) -> bool {
    model_of(sky_type).is_some() || sky_type == "PREETHAM"
}
