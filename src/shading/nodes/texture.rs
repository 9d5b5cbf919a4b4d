//! Procedural texture nodes (Noise, White Noise, Voronoi, Checker, Gradient, Wave, Magic,
//! Brick, Gabor): the compile glue around the algorithms in [`crate::shading::tex`]. An unlinked
//! Vector input reads Generated coordinates, as in Cycles (White Noise's reads its zero default).

use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::program::{Op, Slot, Slots};
use crate::shading::tex::{
    brick, checker, gabor, gradient, magic, noise, voronoi, wave, white_noise,
};
use glam::Vec3;

/// A texture's settings: menus and flags from the node's properties.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    Noise {
        dimensions: u8,
        kind: noise::NoiseType,
        normalize: bool,
        want_color: bool,
    },
    WhiteNoise {
        dimensions: u8,
    },
    Voronoi {
        dimensions: voronoi::VoronoiDimensions,
        feature: voronoi::VoronoiFeature,
        metric: voronoi::VoronoiMetric,
        normalize: bool,
    },
    Checker,
    Gradient(gradient::GradientType),
    Wave {
        wave_type: wave::WaveType,
        direction: wave::WaveDirection,
        profile: wave::WaveProfile,
    },
    Magic {
        depth: i32,
    },
    Gabor {
        three_d: bool,
    },
    Brick {
        offset: f32,
        offset_frequency: i32,
        squash: f32,
        squash_frequency: i32,
    },
}

/// Most inputs / outputs of one texture node.
const MAX_IN: usize = 10;
const MAX_OUT: usize = 5;

#[derive(Clone, Copy, Debug)]
pub struct TextureOp {
    kind: Kind,
    vector: Slot,
    /// The other inputs in the node's socket order (see [`inputs_of`]).
    inputs: [Slot; MAX_IN],
    /// Outputs in the node's socket order (see [`outputs_of`]).
    outputs: [Slot; MAX_OUT],
}

/// The non-vector inputs a texture reads, with Blender's defaults and whether each is a colour.
fn inputs_of(kind: &Kind) -> &'static [(&'static str, f32, bool)] {
    match kind {
        Kind::Noise { .. } => &[
            ("W", 0.0, false),
            ("Scale", 5.0, false),
            ("Detail", 2.0, false),
            ("Roughness", 0.5, false),
            ("Lacunarity", 2.0, false),
            ("Offset", 0.0, false),
            ("Gain", 1.0, false),
            ("Distortion", 0.0, false),
        ],
        Kind::WhiteNoise { .. } => &[("W", 0.0, false)],
        Kind::Voronoi { .. } => &[
            ("W", 0.0, false),
            ("Scale", 5.0, false),
            ("Detail", 0.0, false),
            ("Roughness", 0.5, false),
            ("Lacunarity", 2.0, false),
            ("Smoothness", 1.0, false),
            ("Exponent", 0.5, false),
            ("Randomness", 1.0, false),
        ],
        Kind::Checker => &[
            ("Color1", 0.8, true),
            ("Color2", 0.2, true),
            ("Scale", 5.0, false),
        ],
        Kind::Gradient(_) => &[],
        Kind::Wave { .. } => &[
            ("Scale", 5.0, false),
            ("Distortion", 0.0, false),
            ("Detail", 2.0, false),
            ("Detail Scale", 1.0, false),
            ("Detail Roughness", 0.5, false),
            ("Phase Offset", 0.0, false),
        ],
        Kind::Magic { .. } => &[("Scale", 5.0, false), ("Distortion", 1.0, false)],
        // Orientation 3D, a vector, follows these (see `compile`).
        Kind::Gabor { .. } => &[
            ("Scale", 5.0, false),
            ("Frequency", 2.0, false),
            ("Anisotropy", 1.0, false),
            ("Orientation 2D", std::f32::consts::FRAC_PI_4, false),
        ],
        Kind::Brick { .. } => &[
            ("Color1", 0.8, true),
            ("Color2", 0.2, true),
            ("Mortar", 0.0, true),
            ("Scale", 5.0, false),
            ("Mortar Size", 0.02, false),
            ("Mortar Smooth", 0.1, false),
            ("Bias", 0.0, false),
            ("Brick Width", 0.5, false),
            ("Row Height", 0.25, false),
        ],
    }
}

/// The outputs a texture writes, with their types.
fn outputs_of(kind: &Kind) -> &'static [(&'static str, SocketType)] {
    use SocketType::{Color, Float, Vector};
    match kind {
        Kind::Noise { .. } => &[("Fac", Float), ("Color", Color)],
        Kind::WhiteNoise { .. } => &[("Value", Float), ("Color", Color)],
        Kind::Voronoi { .. } => &[
            ("Distance", Float),
            ("Color", Color),
            ("Position", Vector),
            ("W", Float),
            ("Radius", Float),
        ],
        Kind::Gabor { .. } => &[("Value", Float), ("Phase", Float), ("Intensity", Float)],
        _ => &[("Color", Color), ("Fac", Float)],
    }
}

impl TextureOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots) {
        let p = s.v(self.vector);
        let f = |i: usize| s.f(self.inputs[i]);
        let v = |i: usize| s.v(self.inputs[i]);
        let (a, b, c, d, e): (f32, Vec3, Vec3, f32, f32) = match self.kind {
            Kind::Noise {
                dimensions,
                kind,
                normalize,
                want_color,
            } => {
                let params = noise::NoiseParams {
                    dimensions,
                    kind,
                    normalize,
                    scale: f(1),
                    detail: f(2),
                    roughness: f(3),
                    lacunarity: f(4),
                    offset: f(5),
                    gain: f(6),
                    distortion: f(7),
                };
                let (fac, color) = noise::noise_texture(p, f(0), &params, want_color);
                (fac, color, Vec3::ZERO, 0.0, 0.0)
            }
            Kind::WhiteNoise { dimensions } => {
                let (val, color) = white_noise::white_noise(dimensions, p, f(0));
                (val, color, Vec3::ZERO, 0.0, 0.0)
            }
            Kind::Voronoi {
                dimensions,
                feature,
                metric,
                normalize,
            } => {
                let params = voronoi::VoronoiParams {
                    dimensions,
                    feature,
                    metric,
                    scale: f(1),
                    detail: f(2),
                    roughness: f(3),
                    lacunarity: f(4),
                    smoothness: f(5),
                    exponent: f(6),
                    randomness: f(7),
                    normalize,
                };
                let o = voronoi::voronoi_texture(p, f(0), &params);
                (o.distance, o.color, o.position, o.w, o.radius)
            }
            Kind::Checker => {
                let (col, fac) = checker::checker(p, v(0), v(1), f(2));
                (fac, col, Vec3::ZERO, 0.0, 0.0)
            }
            Kind::Gradient(kind) => {
                let (col, fac) = gradient::gradient(p, kind);
                (fac, col, Vec3::ZERO, 0.0, 0.0)
            }
            Kind::Wave {
                wave_type,
                direction,
                profile,
            } => {
                let params = wave::WaveParams {
                    wave_type,
                    direction,
                    profile,
                    scale: f(0),
                    distortion: f(1),
                    detail: f(2),
                    detail_scale: f(3),
                    detail_roughness: f(4),
                    phase_offset: f(5),
                };
                let (col, fac) = wave::wave(p, &params);
                (fac, col, Vec3::ZERO, 0.0, 0.0)
            }
            Kind::Magic { depth } => {
                let (col, fac) = magic::magic(p, depth, f(0), f(1));
                (fac, col, Vec3::ZERO, 0.0, 0.0)
            }
            Kind::Gabor { three_d } => {
                let (value, phase, intensity) =
                    gabor::gabor(p, f(0), f(1), f(2), three_d, f(3), v(4));
                (value, Vec3::ZERO, Vec3::ZERO, phase, intensity)
            }
            Kind::Brick {
                offset,
                offset_frequency,
                squash,
                squash_frequency,
            } => {
                let params = brick::BrickParams {
                    offset,
                    offset_frequency,
                    squash,
                    squash_frequency,
                    color1: v(0),
                    color2: v(1),
                    mortar: v(2),
                    scale: f(3),
                    mortar_size: f(4),
                    mortar_smooth: f(5),
                    bias: f(6),
                    brick_width: f(7),
                    row_height: f(8),
                };
                let (col, fac) = brick::brick(p, &params);
                (fac, col, Vec3::ZERO, 0.0, 0.0)
            }
        };
        match self.kind {
            Kind::Noise { .. } | Kind::WhiteNoise { .. } => {
                s.set_f(self.outputs[0], a);
                s.set_v(self.outputs[1], b);
            }
            Kind::Gabor { .. } => {
                s.set_f(self.outputs[0], a);
                s.set_f(self.outputs[1], d);
                s.set_f(self.outputs[2], e);
            }
            Kind::Voronoi { .. } => {
                s.set_f(self.outputs[0], a);
                s.set_v(self.outputs[1], b);
                s.set_v(self.outputs[2], c);
                s.set_f(self.outputs[3], d);
                s.set_f(self.outputs[4], e);
            }
            _ => {
                s.set_v(self.outputs[0], b);
                s.set_f(self.outputs[1], a);
            }
        }
    }
}

fn dims(cx: &NodeCx, key: &str) -> u8 {
    match cx.prop_str(key).unwrap_or("3D") {
        "1D" => 1,
        "2D" => 2,
        "4D" => 4,
        _ => 3,
    }
}

fn kind_of(kind: &str, cx: &mut NodeCx) -> Option<Kind> {
    Some(match kind {
        "ShaderNodeTexNoise" | "ShaderNodeTexMusgrave" => {
            let t = match cx
                .prop_str("noise_type")
                .or(cx.prop_str("musgrave_type"))
                .unwrap_or("FBM")
            {
                "MULTIFRACTAL" => noise::NoiseType::Multifractal,
                "HYBRID_MULTIFRACTAL" => noise::NoiseType::HybridMultifractal,
                "RIDGED_MULTIFRACTAL" => noise::NoiseType::RidgedMultifractal,
                "HETERO_TERRAIN" => noise::NoiseType::HeteroTerrain,
                _ => noise::NoiseType::Fbm,
            };
            let d = if cx.prop("noise_dimensions").is_some() {
                dims(cx, "noise_dimensions")
            } else {
                dims(cx, "musgrave_dimensions")
            };
            Kind::Noise {
                dimensions: d,
                kind: t,
                normalize: cx.prop_bool("normalize", true),
                want_color: true,
            }
        }
        "ShaderNodeTexWhiteNoise" => Kind::WhiteNoise {
            dimensions: dims(cx, "noise_dimensions"),
        },
        "ShaderNodeTexVoronoi" => {
            use voronoi::{VoronoiDimensions as D, VoronoiFeature as F, VoronoiMetric as M};
            Kind::Voronoi {
                dimensions: match dims(cx, "voronoi_dimensions") {
                    1 => D::D1,
                    2 => D::D2,
                    4 => D::D4,
                    _ => D::D3,
                },
                feature: match cx.prop_str("feature").unwrap_or("F1") {
                    "F2" => F::F2,
                    "SMOOTH_F1" => F::SmoothF1,
                    "DISTANCE_TO_EDGE" => F::DistanceToEdge,
                    "N_SPHERE_RADIUS" => F::NSphereRadius,
                    _ => F::F1,
                },
                metric: match cx.prop_str("distance").unwrap_or("EUCLIDEAN") {
                    "MANHATTAN" => M::Manhattan,
                    "CHEBYCHEV" => M::Chebychev,
                    "MINKOWSKI" => M::Minkowski,
                    _ => M::Euclidean,
                },
                normalize: cx.prop_bool("normalize", false),
            }
        }
        "ShaderNodeTexChecker" => Kind::Checker,
        "ShaderNodeTexGradient" => {
            use gradient::GradientType as G;
            Kind::Gradient(match cx.prop_str("gradient_type").unwrap_or("LINEAR") {
                "QUADRATIC" => G::Quadratic,
                "EASING" => G::Easing,
                "DIAGONAL" => G::Diagonal,
                "SPHERICAL" => G::Spherical,
                "QUADRATIC_SPHERE" => G::QuadraticSphere,
                "RADIAL" => G::Radial,
                _ => G::Linear,
            })
        }
        "ShaderNodeTexWave" => {
            let wave_type = match cx.prop_str("wave_type").unwrap_or("BANDS") {
                "RINGS" => wave::WaveType::Rings,
                _ => wave::WaveType::Bands,
            };
            let key = if wave_type == wave::WaveType::Rings {
                "rings_direction"
            } else {
                "bands_direction"
            };
            Kind::Wave {
                wave_type,
                direction: match cx.prop_str(key).unwrap_or("X") {
                    "Y" => wave::WaveDirection::Y,
                    "Z" => wave::WaveDirection::Z,
                    "DIAGONAL" => wave::WaveDirection::Diagonal,
                    "SPHERICAL" => wave::WaveDirection::Spherical,
                    _ => wave::WaveDirection::X,
                },
                profile: match cx.prop_str("wave_profile").unwrap_or("SIN") {
                    "SAW" => wave::WaveProfile::Saw,
                    "TRI" => wave::WaveProfile::Triangle,
                    _ => wave::WaveProfile::Sine,
                },
            }
        }
        "ShaderNodeTexGabor" => Kind::Gabor {
            three_d: cx.prop_str("gabor_type") == Some("3D"),
        },
        "ShaderNodeTexMagic" => Kind::Magic {
            depth: cx.prop_f32("turbulence_depth", 2.0) as i32,
        },
        "ShaderNodeTexBrick" => Kind::Brick {
            offset: cx.prop_f32("offset", 0.5),
            offset_frequency: cx.prop_f32("offset_frequency", 2.0) as i32,
            squash: cx.prop_f32("squash", 1.0),
            squash_frequency: cx.prop_f32("squash_frequency", 2.0) as i32,
        },
        _ => return None,
    })
}

pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    let Some(mut k) = kind_of(kind, cx) else {
        return Ok(false);
    };
    if let Kind::Noise { want_color, .. } = &mut k {
        // Three more noise evaluations: only when something reads the colour.
        *want_color = cx.wanted() != Some("Fac");
    }
    // White Noise is the one texture whose unlinked Vector is its zero default rather than
    // the Generated coordinates (Cycles gives its socket no texture-coordinate link).
    let vector = if cx.is_linked("Vector") || matches!(k, Kind::WhiteNoise { .. }) {
        cx.vector("Vector", Vec3::ZERO)?
    } else {
        let out = cx.alloc(3)?;
        cx.emit(
            Op::Input(super::input::InputOp {
                src: super::input::Source::Generated,
                out,
            }),
            true,
        );
        out
    };
    let mut inputs = [0; MAX_IN];
    for (i, &(id, default, color)) in inputs_of(&k).iter().enumerate() {
        inputs[i] = if color {
            cx.color(id, Vec3::splat(default))?
        } else {
            cx.float(id, default)?
        };
    }
    if let Kind::Gabor { .. } = k {
        let n = inputs_of(&k).len();
        let diagonal = Vec3::new(1.0, 1.0, 0.0) * std::f32::consts::FRAC_1_SQRT_2;
        inputs[n] = cx.vector("Orientation 3D", diagonal)?;
    }
    let mut outputs = [0; MAX_OUT];
    let partial = matches!(
        k,
        Kind::Noise {
            want_color: false,
            ..
        }
    );
    for (i, &(id, ty)) in outputs_of(&k).iter().enumerate() {
        if partial && id != "Fac" {
            outputs[i] = cx.alloc(ty.width())?;
        } else {
            outputs[i] = cx.output(id, ty)?;
        }
    }
    if partial {
        cx.partial();
    }
    cx.emit(
        Op::Texture(TextureOp {
            kind: k,
            vector,
            inputs,
            outputs,
        }),
        true,
    );
    Ok(true)
}
