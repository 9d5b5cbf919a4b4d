//! A world that varies with direction (an HDRI, a gradient sky, a camera-only backdrop): its
//! node program evaluated per escaped ray direction, and importance-sampled as Cycles samples
//! its background light.
//!
//! The sampling map is the world's luminance on an equirectangular grid (Blender's Z-up
//! orientation, Cycles' `direction_to_equirectangular`): `w x h` cells, row 0 at the zenith,
//! each cell's value its luminance at the cell's centre (the mean of `ss x ss` points when the
//! environment image is finer than the map) times `sin θ` of the centre. A piecewise-constant
//! 2D distribution over `(u, t) ∈ [0, 1]²` (`t = θ / π`) is sampled by inverting its marginal
//! (rows) and conditional (columns) CDFs; its density per solid angle is
//! `p(u, t) / (2π² sin θ)` with `sin θ` of the direction itself, exactly the Jacobian of the
//! map, so `sample` and `pdf` agree everywhere. The map is evaluated as Cycles evaluates it:
//! with no Light Path bits set (neither camera nor any bounce type).
//!
//! A Sky Texture's sun disc is far smaller than a map cell: as Cycles' sun guiding, a world
//! with one such sun leaves it out of the map (evaluated with `ray::IMPORTANCE_BAKE`) and
//! draws [`SUN_FRACTION`] of its samples uniformly in the sun's cone; the density of every
//! direction is the mixture `f p_cone + (1 - f) p_map`, whichever strategy drew it.

use super::{Emitter, EmitterQueryRecord, luminance};
use crate::sampling::{
    square_to_uniform_cone, square_to_uniform_cone_pdf, square_to_uniform_sphere,
    square_to_uniform_sphere_pdf,
};
use crate::scene::{Image, Scene, World, WorldSampling};
use crate::shading::Program;
use crate::shading::globals::ray;
use crate::shading::globals::{ShadeEnv, from_blender, to_blender};
use crate::shading::graph::Graph;
use crate::shading::nodes::environment::{
    ImageWorld, background_globals, direction_to_equirectangular, equirectangular_to_direction,
};
use crate::shading::nodes::sky::{self, GuidedSun, Suns};
use glam::{Mat4, Vec2, Vec3};
use rayon::prelude::*;
use std::f32::consts::PI;
use std::sync::Arc;

/// Largest map edge (cells) chosen automatically from an environment image; finer images are
/// averaged over up to `MAX_SUPERSAMPLE²` points per cell.
pub const MAX_AUTO_WIDTH: usize = 2048;
/// Largest map edge accepted from `sample_map_resolution`.
pub const MAX_MANUAL_WIDTH: usize = 4096;
const MAX_SUPERSAMPLE: usize = 4;
/// The automatic map of a sky whose sun is sampled apart (Cycles' 512 x 256).
const SKY_WIDTH: usize = 512;
/// The share of samples drawn from a guided sun's cone (Cycles' weights: 4 for the sun, 1
/// for the map).
const SUN_FRACTION: f32 = 0.8;
/// Smallest map (cells): procedural worlds over a tiny image still get a useful map.
const MIN_WIDTH: usize = 64;
const MIN_HEIGHT: usize = 32;

/// Ray depth the world is evaluated at for light sampling (a bounce, not the camera).
const LIGHT_DEPTH: u32 = 2;

/// The sampling map's size: `(width, height, supersampling per axis)`, or `None` when the
/// world is not sampled as a light. Automatic: the largest environment image the graph uses
/// (capped at [`MAX_AUTO_WIDTH`] wide, averaging finer texels), else 1024 x 512, as Cycles.
pub fn map_resolution(world: &World, graph: &Graph, images: &[Image]) -> Option<[usize; 3]> {
    let (w, h, ss) = match world.sampling {
        WorldSampling::None => return None,
        WorldSampling::Manual(n) => {
            let w = (n as usize).clamp(2, MAX_MANUAL_WIDTH);
            (w, (w / 2).max(1), 1)
        }
        WorldSampling::Automatic => {
            let (mut w, mut h) = (0usize, 0usize);
            // As Cycles: a sun sampled apart needs only a coarse map of the sky; suns the map
            // must resolve get the finest automatic one.
            match sky::suns(graph) {
                Suns::None => {}
                Suns::Guided(_) => (w, h) = (SKY_WIDTH, SKY_WIDTH / 2),
                Suns::Unguided => (w, h) = (MAX_AUTO_WIDTH, MAX_AUTO_WIDTH / 2),
            }
            for n in &graph.nodes {
                if n.kind == "ShaderNodeTexEnvironment"
                    && let Some(img) = n.image.and_then(|i| images.get(i))
                {
                    w = w.max(img.width as usize);
                    h = h.max(img.height as usize);
                }
            }
            if w == 0 || h == 0 {
                (1024, 512, 1)
            } else if w > MAX_AUTO_WIDTH || h > MAX_AUTO_WIDTH / 2 {
                let s =
                    (w as f64 / MAX_AUTO_WIDTH as f64).max(h as f64 / (MAX_AUTO_WIDTH / 2) as f64);
                let ss = (s.ceil() as usize).clamp(1, MAX_SUPERSAMPLE);
                (
                    ((w as f64 / s) as usize).clamp(1, MAX_AUTO_WIDTH),
                    ((h as f64 / s) as usize).clamp(1, MAX_AUTO_WIDTH / 2),
                    ss,
                )
            } else {
                (w, h, 1)
            }
        }
    };
    Some([w.max(MIN_WIDTH), h.max(MIN_HEIGHT), ss])
}

/// A piecewise-constant distribution over `[0, 1]²` on a `w x h` grid (row-major, row 0 at
/// `t = 0`).
#[derive(Clone, Debug)]
pub struct Distribution2D {
    w: usize,
    h: usize,
    /// Cell values (non-negative).
    func: Vec<f32>,
    /// Per row, the normalised CDF over its columns (`w + 1` entries; all zero for an empty row).
    conditional: Vec<f32>,
    /// Per row, the guide table of its CDF ([`guide_into`], `w + 1` entries).
    conditional_guide: Vec<u32>,
    /// The normalised CDF over rows (`h + 1` entries).
    marginal: Vec<f32>,
    /// The guide table of `marginal` (`h + 1` entries).
    marginal_guide: Vec<u32>,
    /// `w h / Σ func`: a cell's value times this is the density on `[0, 1]²`.
    norm: f32,
}

/// The normalised CDF of `f` into `out` (`f.len() + 1` entries); returns the sum.
fn cdf_into(f: impl Iterator<Item = f64>, out: &mut Vec<f32>) -> f64 {
    let start = out.len();
    let mut acc = 0.0f64;
    let mut raw = vec![0.0f64];
    for v in f {
        acc += v;
        raw.push(acc);
    }
    if acc > 0.0 {
        out.extend(raw.iter().map(|c| (c / acc) as f32));
        *out.last_mut().unwrap() = 1.0;
    } else {
        out.extend(std::iter::repeat_n(0.0, raw.len()));
    }
    debug_assert_eq!(out.len() - start, raw.len());
    acc
}

/// The guide bucket of a value in `[0, 1]` among `g` equal buckets; non-decreasing in `x`.
#[inline]
fn bucket(x: f32, g: usize) -> usize {
    ((x * g as f32) as usize).min(g - 1)
}

/// Appends the guide table of `cdf` with `g` buckets: entry `b` (of `g + 1`) is the first index
/// whose value falls in bucket `b` or later (`cdf.len()` if none). Since [`bucket`] is
/// monotone, the first entry above any `u` lies between the guides of `u`'s bucket and the
/// next one, so a search confined there finds exactly what a search of the whole CDF finds.
fn guide_into(cdf: &[f32], g: usize, out: &mut Vec<u32>) {
    let mut i = 0;
    for b in 0..=g {
        while i < cdf.len() && bucket(cdf[i], g) < b {
            i += 1;
        }
        out.push(i as u32);
    }
}

/// Samples cell and position within a CDF with its guide table: `(cell, continuous
/// coordinate in [0, 1))`.
#[inline]
fn sample_cdf(cdf: &[f32], guide: &[u32], u: f32) -> (usize, f32) {
    let n = cdf.len() - 1;
    let b = bucket(u, guide.len() - 1);
    let (lo, hi) = (guide[b] as usize, guide[b + 1] as usize);
    // The first entry above u, minus one: a cell of positive width containing u.
    let i = (lo + cdf[lo..hi].partition_point(|&c| c <= u)).clamp(1, n) - 1;
    let (a, b) = (cdf[i], cdf[i + 1]);
    let du = if b > a {
        ((u - a) / (b - a)).clamp(0.0, 1.0)
    } else {
        0.5
    };
    let x = ((i as f32 + du) / n as f32).min(1.0 - f32::EPSILON / 2.0);
    (i, x)
}

impl Distribution2D {
    /// Builds the distribution; `None` when every value is zero (or not finite).
    pub fn new(w: usize, h: usize, func: Vec<f32>) -> Option<Distribution2D> {
        assert_eq!(func.len(), w * h);
        let clean = |v: f32| {
            if v.is_finite() && v > 0.0 {
                v as f64
            } else {
                0.0
            }
        };
        let func: Vec<f32> = func.iter().map(|&v| clean(v) as f32).collect();
        let mut conditional = Vec::with_capacity((w + 1) * h);
        let mut rows = Vec::with_capacity(h);
        for r in func.chunks_exact(w) {
            rows.push(cdf_into(r.iter().map(|&v| v as f64), &mut conditional));
        }
        let mut marginal = Vec::with_capacity(h + 1);
        let total = cdf_into(rows.iter().copied(), &mut marginal);
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let mut conditional_guide = Vec::with_capacity((w + 1) * h);
        for row in conditional.chunks_exact(w + 1) {
            guide_into(row, w, &mut conditional_guide);
        }
        let mut marginal_guide = Vec::with_capacity(h + 1);
        guide_into(&marginal, h, &mut marginal_guide);
        Some(Distribution2D {
            w,
            h,
            func,
            conditional,
            conditional_guide,
            marginal,
            marginal_guide,
            norm: ((w * h) as f64 / total) as f32,
        })
    }

    /// A point of `[0, 1)²` and its density.
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (j, t) = sample_cdf(&self.marginal, &self.marginal_guide, u.y);
        let rows = j * (self.w + 1)..(j + 1) * (self.w + 1);
        let (i, x) = sample_cdf(
            &self.conditional[rows.clone()],
            &self.conditional_guide[rows],
            u.x,
        );
        (Vec2::new(x, t), self.func[j * self.w + i] * self.norm)
    }

    /// The density at a point of `[0, 1]²`.
    #[inline]
    pub fn pdf(&self, p: Vec2) -> f32 {
        let i = ((p.x * self.w as f32) as usize).min(self.w - 1);
        let j = ((p.y * self.h as f32) as usize).min(self.h - 1);
        self.func[j * self.w + i] * self.norm
    }
}

/// A direction-dependent world.
#[derive(Clone, Debug)]
pub struct Environment {
    program: Arc<Program>,
    /// The program, when it is only an image times a constant, in the form that evaluates
    /// it directly (to the same values).
    image_world: Option<ImageWorld>,
    /// The camera in Blender's coordinates (Texture Coordinate's Camera output).
    camera_to_world: Mat4,
    /// The importance map; `None`: uniform over the sphere (a world whose luminance does not
    /// vary, e.g. a constant colour behind a camera-only backdrop).
    dist: Option<Box<Distribution2D>>,
    /// `∫ luminance dω` of the sky over the sphere, a guided sun left out, for light
    /// selection (0 with `sun_irradiance`: not a light).
    sky_integral: f32,
    /// A guided sun's luminance-weighted irradiance (0: none).
    sun_irradiance: f32,
    /// A sky's sun sampled apart (Cycles' sun guiding): the map leaves its disc out and
    /// [`SUN_FRACTION`] of the samples are drawn uniformly in its cone.
    sun: Option<SunCone>,
}

/// A guided sun's cone in the renderer's world.
#[derive(Clone, Copy, Debug)]
struct SunCone {
    /// Unit direction towards the centre.
    dir: Vec3,
    /// Frame with `dir` as its third axis.
    t: Vec3,
    b: Vec3,
    cos_max: f32,
}

impl SunCone {
    fn new(s: &GuidedSun) -> SunCone {
        let dir = from_blender(s.dir).normalize();
        let (t, b) = dir.any_orthonormal_pair();
        SunCone {
            dir,
            t,
            b,
            cos_max: s.half_angle.cos(),
        }
    }

    #[inline]
    fn sample(&self, u: Vec2) -> Vec3 {
        let l = square_to_uniform_cone(u, self.cos_max);
        (self.t * l.x + self.b * l.y + self.dir * l.z).normalize()
    }

    #[inline]
    fn pdf(&self, d: Vec3) -> f32 {
        square_to_uniform_cone_pdf(Vec3::new(0.0, 0.0, d.dot(self.dir)), self.cos_max)
    }
}

/// Cycles' equirectangular `(u, v)` of a cell-space point `(u, t)` (`t = θ / π` from the top).
#[inline]
fn cell_direction(u: f32, t: f32) -> Vec3 {
    from_blender(equirectangular_to_direction(u, 1.0 - t))
}

impl Environment {
    /// The world `program` (a compiled world graph) with an importance map of `res`
    /// ([`map_resolution`]; `None`: not a light).
    pub fn new(
        scene: &Scene,
        program: Arc<Program>,
        camera_to_world: Mat4,
        res: Option<[usize; 3]>,
    ) -> Environment {
        let mut env = Environment {
            image_world: program.image_world(),
            program,
            camera_to_world,
            dist: None,
            sky_integral: 0.0,
            sun_irradiance: 0.0,
            sun: None,
        };
        let Some([w, h, ss]) = res else {
            return env;
        };
        let guided = match scene.world.graph.as_ref().map(sky::suns) {
            Some(Suns::Guided(s)) => Some(s),
            _ => None,
        };
        let bake = if guided.is_some() {
            ray::IMPORTANCE_BAKE
        } else {
            0
        };
        // Per cell: the sampling weight, and the radiance at its centre (for the power).
        let mut cells = vec![(0.0f32, 0.0f32); w * h];
        cells.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
            for (i, out) in row.iter_mut().enumerate() {
                let lum_at = |u: f32, t: f32| {
                    let d = cell_direction(u, t);
                    let l = luminance(env.radiance(scene, d, LIGHT_DEPTH, bake));
                    if l.is_finite() && l > 0.0 { l } else { 0.0 }
                };
                if ss == 1 {
                    // A map cell is one texel, but a filtered lookup spreads a bright texel
                    // half a texel into its neighbours: the cell takes the largest radiance
                    // it holds (bilinear is monotone between texel centres, so the corners,
                    // edge midpoints and centre find it), or a small sun's rim would be
                    // sampled at the sky's density.
                    let mut m = 0.0f32;
                    for a in 0..3 {
                        for b in 0..3 {
                            let u = (i as f32 + b as f32 * 0.5) / w as f32;
                            let t = (j as f32 + a as f32 * 0.5) / h as f32;
                            m = m.max(lum_at(u.min(1.0), t.min(1.0)));
                        }
                    }
                    let centre = lum_at((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32);
                    *out = (m, centre);
                    continue;
                }
                let mut sum = 0.0f64;
                for a in 0..ss {
                    for b in 0..ss {
                        let u = (i as f32 + (b as f32 + 0.5) / ss as f32) / w as f32;
                        let t = (j as f32 + (a as f32 + 0.5) / ss as f32) / h as f32;
                        sum += lum_at(u, t) as f64;
                    }
                }
                let mean = (sum / (ss * ss) as f64) as f32;
                *out = (mean, mean);
            }
        });
        let lum: Vec<f32> = cells.iter().map(|c| c.0).collect();
        let first = lum[0];
        if let Some(s) = &guided {
            env.sun = Some(SunCone::new(s));
            env.sun_irradiance = luminance(s.power);
        }
        if lum.iter().all(|&l| l == first) && env.sun.is_none() {
            env.sky_integral = if first.is_finite() {
                first * 4.0 * PI
            } else {
                0.0
            };
            return env;
        }
        let mut integral = 0.0f64;
        let func: Vec<f32> = lum
            .iter()
            .zip(&cells)
            .enumerate()
            .map(|(k, (&l, &(_, centre)))| {
                let sin_t = (PI * ((k / w) as f32 + 0.5) / h as f32).sin();
                integral += (centre * sin_t) as f64;
                l * sin_t
            })
            .collect();
        env.sky_integral =
            (integral * 2.0 * std::f64::consts::PI * std::f64::consts::PI / (w * h) as f64) as f32;
        env.dist = Distribution2D::new(w, h, func).map(Box::new);
        if env.dist.is_none() && env.sun.is_none() {
            env.sky_integral = 0.0;
        }
        env
    }

    fn shade_env<'a>(&self, scene: &'a Scene) -> ShadeEnv<'a> {
        ShadeEnv {
            images: &scene.images,
            textures: &scene.textures,
            camera_to_world: self.camera_to_world,
            window: &crate::camera::NO_WINDOW,
            tracer: None,
        }
    }

    /// The radiance arriving along `-d` from the world, for a ray along the unit direction
    /// `d` (renderer world) leaving path vertex `depth - 1` with Light Path bits `flags`.
    #[inline]
    pub fn radiance(&self, scene: &Scene, d: Vec3, depth: u32, flags: u32) -> Vec3 {
        if let Some(w) = &self.image_world {
            return w.emission(to_blender(d), &scene.images);
        }
        let g = background_globals(d, depth, flags);
        // The world gives light only: its importance map and sun need radiance >= 0 (a
        // negative Background strength is black; the constant world is clamped alike).
        self.program
            .emission(&g, &self.shade_env(scene))
            .max(Vec3::ZERO)
    }

    /// The radiance light sampling sees (no Light Path bits, as Cycles' light evaluation).
    #[inline]
    fn light_radiance(&self, scene: &Scene, d: Vec3) -> Vec3 {
        self.radiance(scene, d, LIGHT_DEPTH, 0)
    }

    /// Solid-angle density of direction `d` (renderer world, unit).
    #[inline]
    pub fn pdf_dir(&self, d: Vec3) -> f32 {
        match &self.sun {
            None => self.map_pdf(d),
            Some(sun) => SUN_FRACTION * sun.pdf(d) + (1.0 - SUN_FRACTION) * self.map_pdf(d),
        }
    }

    /// Solid-angle density of the map's sampling (uniform without a map).
    #[inline]
    fn map_pdf(&self, d: Vec3) -> f32 {
        let Some(dist) = &self.dist else {
            return square_to_uniform_sphere_pdf();
        };
        let b = to_blender(d);
        let sin_theta = (b.x * b.x + b.y * b.y).sqrt();
        if sin_theta.is_nan() || sin_theta <= 0.0 {
            return 0.0;
        }
        let uv = direction_to_equirectangular(b);
        let p = dist.pdf(Vec2::new(uv.x, 1.0 - uv.y));
        p / (2.0 * PI * PI * sin_theta)
    }

    /// The importance map, if the world has one.
    pub fn distribution(&self) -> Option<&Distribution2D> {
        self.dist.as_deref()
    }
}

impl Emitter for Environment {
    fn sample(&self, scene: &Scene, rec: &mut EmitterQueryRecord, mut u: Vec2) -> Vec3 {
        rec.dist = f32::INFINITY;
        if let Some(sun) = &self.sun {
            // One strategy by u.x, which is then stretched back over [0, 1); the density is
            // the mixture's, so MIS with BSDF sampling sees one light.
            if u.x < SUN_FRACTION {
                u.x /= SUN_FRACTION;
                rec.wi = sun.sample(u);
            } else {
                u.x = ((u.x - SUN_FRACTION) / (1.0 - SUN_FRACTION)).min(1.0 - f32::EPSILON);
                rec.wi = self.sample_map(u).0;
            }
            rec.pdf = self.pdf_dir(rec.wi);
            if !(rec.pdf > 0.0 && rec.pdf.is_finite()) {
                rec.pdf = 0.0;
                return Vec3::ZERO;
            }
            return self.light_radiance(scene, rec.wi) / rec.pdf;
        }
        (rec.wi, rec.pdf) = self.sample_map(u);
        if !(rec.pdf > 0.0 && rec.pdf.is_finite()) {
            rec.pdf = 0.0;
            return Vec3::ZERO;
        }
        self.light_radiance(scene, rec.wi) / rec.pdf
    }

    fn eval(&self, scene: &Scene, rec: &EmitterQueryRecord) -> Vec3 {
        self.light_radiance(scene, rec.wi)
    }

    fn pdf(&self, _scene: &Scene, rec: &EmitterQueryRecord) -> f32 {
        self.pdf_dir(rec.wi)
    }

    /// What the world delivers to the scene's cross-section `π r²` as a surface facing it
    /// receives it: the irradiance `∫ L cos θ dω` over a hemisphere, which is `∫ L dω / 4` for
    /// a sky of no preferred direction (Cycles' `π · average radiance`), plus a guided sun's
    /// irradiance in full. Against the suns' `E π r²`, the flux through the sphere `∫ L dω π r²`
    /// would choose a world four times as often as its light is worth where it arrives.
    fn power(&self, _scene: &Scene, r: f32) -> f32 {
        (0.25 * self.sky_integral + self.sun_irradiance) * PI * r * r
    }

    fn is_delta(&self) -> bool {
        false
    }
}

impl Environment {
    /// A direction from the map (uniform without one) and the map's density for it.
    #[inline]
    fn sample_map(&self, u: Vec2) -> (Vec3, f32) {
        match &self.dist {
            Some(dist) => {
                // The density the point was drawn with, over the map's Jacobian `2π² sin θ`
                // `pdf_dir` of the direction without going back through atan2 to find its cell.
                let (p, density) = dist.sample(u);
                let wi = cell_direction(p.x, p.y);
                let b = to_blender(wi);
                let sin_theta = (b.x * b.x + b.y * b.y).sqrt();
                let pdf = if sin_theta > 0.0 {
                    density / (2.0 * PI * PI * sin_theta)
                } else {
                    0.0
                };
                (wi, pdf)
            }
            None => (square_to_uniform_sphere(u), square_to_uniform_sphere_pdf()),
        }
    }
}

/// The emitter of `scene`'s world, if it is not black: the constant [`super::Background`] for
/// a constant colour (no graph, or a graph that does not depend on the direction or the ray),
/// else an [`Environment`]. A world graph that cannot be compiled falls back to the constant
/// colour, with a warning; the compiler's fallbacks are reported naming the world.
pub fn world_emitter(
    scene: &Scene,
    camera_to_world: Mat4,
    warnings: &mut Vec<String>,
) -> Option<super::EmitterInstance> {
    // Clamped at 0 as the world's varying radiance is (see `Environment::radiance`).
    let constant = |c: Vec3| {
        (c.max_element() > 0.0 && c.is_finite()).then_some(super::EmitterInstance::Background(
            super::Background {
                radiance: c.max(Vec3::ZERO),
            },
        ))
    };
    let world = &scene.world;
    let Some(graph) = &world.graph else {
        return constant(scene.background);
    };
    let name = &world.name;
    let ours = |w: String| w.replacen(&format!("material '{name}'"), &format!("world '{name}'"), 1);
    let compiled = match crate::shading::compile(graph, name) {
        Ok(c) => c,
        Err(e) => {
            warnings.push(format!(
                "{}; the world renders as its colour {:?}",
                ours(e.0),
                scene.background.to_array()
            ));
            return constant(scene.background);
        }
    };
    for w in compiled.warnings {
        let w = ours(w);
        if !warnings.contains(&w) {
            warnings.push(w);
        }
    }
    if let Some(n) = graph.node_with_linked_output("ShaderNodeTexCoord", "Window") {
        warnings.push(format!(
            "world '{name}': node '{}': Window coordinates are not rendered in the world; they read as (0, 0, 0)",
            n.name
        ));
    }
    let program = compiled.program;
    if let Some(set) = &program.constant {
        return constant(set.emission);
    }
    if !program.may_emit() {
        return None;
    }
    let res = map_resolution(world, graph, &scene.images);
    let env = Environment::new(scene, Arc::new(program), camera_to_world, res);
    Some(super::EmitterInstance::Environment(env))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distribution_samples_where_its_density_says() {
        // One bright cell among dim ones: samples land in it in proportion.
        let (w, h) = (8, 4);
        let mut f = vec![1.0f32; w * h];
        f[2 * w + 5] = 29.0;
        let d = Distribution2D::new(w, h, f).unwrap();
        let total = (w * h - 1) as f32 + 29.0;
        let n = 64_000;
        let mut hits = 0;
        for k in 0..n {
            // A stratified sweep of the unit square.
            let u = Vec2::new(
                ((k % 256) as f32 + 0.5) / 256.0,
                ((k / 256) as f32 + 0.5) / 250.0,
            );
            let (p, pdf) = d.sample(u);
            assert!(p.x >= 0.0 && p.x < 1.0 && p.y >= 0.0 && p.y < 1.0, "{p}");
            assert!(
                (pdf - d.pdf(p)).abs() <= 1e-6 * pdf.max(1.0),
                "{pdf} vs {}",
                d.pdf(p)
            );
            if (p.x * w as f32) as usize == 5 && (p.y * h as f32) as usize == 2 {
                hits += 1;
            }
        }
        let want = 29.0 / total;
        let got = hits as f32 / n as f32;
        assert!((got - want).abs() < 0.01, "{got} vs {want}");
        // Density integrates to one.
        let int: f32 = (0..w * h)
            .map(|k| {
                d.pdf(Vec2::new(
                    ((k % w) as f32 + 0.5) / w as f32,
                    ((k / w) as f32 + 0.5) / h as f32,
                ))
            })
            .sum::<f32>()
            / (w * h) as f32;
        assert!((int - 1.0).abs() < 1e-5, "{int}");
        // All-zero and non-finite maps have no distribution; empty cells are never sampled.
        assert!(Distribution2D::new(2, 2, vec![0.0, f32::NAN, -1.0, 0.0]).is_none());
        let d = Distribution2D::new(4, 1, vec![0.0, 1.0, 0.0, 1.0]).unwrap();
        for k in 0..100 {
            let (p, pdf) = d.sample(Vec2::new(k as f32 / 100.0, 0.5));
            let cell = (p.x * 4.0) as usize;
            assert!(cell == 1 || cell == 3, "{p}");
            assert_eq!(pdf, 2.0);
        }
    }

    #[test]
    fn guided_search_finds_what_the_whole_search_finds() {
        // CDFs with empty cells, runs of equal values, a spike and a dense tail; queries on a
        // fine sweep plus every CDF value and its float neighbours (bucket edges included).
        let mut state = 0x2545_f491_u32;
        let mut rnd = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as f32 / u32::MAX as f32
        };
        for (n, g) in [(1usize, 1usize), (7, 7), (64, 64), (300, 64), (33, 100)] {
            let f: Vec<f64> = (0..n)
                .map(|i| match i % 5 {
                    0 => 0.0,
                    1 => 1e3 * rnd() as f64,
                    _ => rnd() as f64,
                })
                .collect();
            let mut cdf = Vec::new();
            if cdf_into(f.iter().copied(), &mut cdf) == 0.0 {
                continue;
            }
            let mut guide = Vec::new();
            guide_into(&cdf, g, &mut guide);
            let mut queries: Vec<f32> = (0..4096).map(|k| k as f32 / 4096.0).collect();
            for &c in &cdf {
                queries.extend([
                    c,
                    f32::from_bits(c.to_bits().saturating_sub(1)),
                    c.next_up(),
                ]);
            }
            for b in 0..=g {
                queries.push(b as f32 / g as f32);
            }
            for u in queries.into_iter().filter(|u| (0.0..1.0).contains(u)) {
                let whole = cdf.partition_point(|&c| c <= u).clamp(1, n) - 1;
                assert_eq!(sample_cdf(&cdf, &guide, u).0, whole, "n {n} g {g} u {u}");
            }
        }
    }

    /// A scene whose world is a Sky Texture into a Background.
    fn sky_scene(sky_type: &str, elevation_deg: f32) -> Scene {
        let mut g = Graph::default();
        g.add(
            crate::shading::Node::new("ShaderNodeTexSky")
                .prop("sky_type", serde_json::json!(sky_type))
                .prop(
                    "sun_elevation",
                    serde_json::json!(elevation_deg.to_radians()),
                )
                .prop("sun_rotation", serde_json::json!(0.7)),
        );
        g.add(crate::shading::Node::new("ShaderNodeBackground").link("Color", 0, "Color"));
        g.surface = Some((1, "Background".into()));
        let mut scene = Scene::default();
        scene.world.graph = Some(g);
        scene
    }

    #[test]
    fn a_guided_sun_is_sampled_in_its_cone_and_the_mixture_density_is_consistent() {
        let scene = sky_scene("MULTIPLE_SCATTERING", 30.0);
        let graph = scene.world.graph.as_ref().unwrap();
        let Suns::Guided(sun) = sky::suns(graph) else {
            panic!("one plain sun is guided");
        };
        let res = map_resolution(&scene.world, graph, &scene.images);
        assert_eq!(res, Some([512, 256, 1]));
        let program = crate::shading::compile(graph, "w").unwrap().program;
        let env = Environment::new(&scene, Arc::new(program), Mat4::IDENTITY, res);
        let cone = env.sun.expect("sun cone");
        // The map left the disc out: its density at the sun is the sky's, not the sun's.
        let d = from_blender(sun.dir);
        assert!(env.map_pdf(d) < 50.0, "{}", env.map_pdf(d));
        // E[1/pdf] = 4π (the density is positive everywhere: the ground's sky is lit too), and
        // E[1_cone/pdf] = the cone's solid angle; a density that is not the mixture's fails.
        let omega = 2.0 * PI * (1.0 - cone.cos_max);
        let n = 256;
        let (mut all, mut inside, mut hits) = (0.0f64, 0.0f64, 0usize);
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let mut rec = EmitterQueryRecord::default();
                let l = env.sample(&scene, &mut rec, u);
                assert!(rec.pdf > 0.0 && l.is_finite(), "{u} {}", rec.pdf);
                assert!((rec.pdf - env.pdf_dir(rec.wi)).abs() <= 1e-3 * rec.pdf);
                all += 1.0 / rec.pdf as f64;
                if cone.pdf(rec.wi) > 0.0 {
                    inside += 1.0 / rec.pdf as f64;
                    hits += 1;
                }
            }
        }
        let m = (n * n) as f64;
        assert!(
            (all / m / (4.0 * std::f64::consts::PI) - 1.0).abs() < 0.02,
            "{}",
            all / m
        );
        assert!(
            (inside / m / omega as f64 - 1.0).abs() < 0.02,
            "{} {omega}",
            inside / m
        );
        assert!(hits as f64 > 0.79 * m, "{hits}");
        // The light's power counts the sun, and the sky besides.
        assert_eq!(env.sun_irradiance, luminance(sun.power));
        assert!(env.power(&scene, 1.0) > luminance(sun.power) * PI);
    }

    /// The image world's direct evaluation gives the program's emission to the bit, for
    /// filtered, closest, sRGB and mirror-ball lookups, odd texels (negative, huge, NaN) and
    /// strengths; a world with anything more is left to the program.
    #[test]
    fn an_image_world_evaluates_as_its_program() {
        let (w, h) = (7u32, 5u32);
        let mut float = Vec::new();
        for k in 0..w * h {
            let x = k as f32;
            float.push(match k % 9 {
                0 => [-0.5, 2.0, 0.25, 1.0],
                4 => [f32::NAN, 1.0, 3e38, 0.5],
                _ => [x * 0.37 % 1.3, x * 0.11 % 0.9, 40.0 / (1.0 + x), 1.0],
            });
        }
        let image = Image {
            width: w,
            height: h,
            rgba8: Vec::new(),
            float,
        };
        let world = |interp: &str, colorspace: &str, projection: &str, strength: f32| {
            let mut g = Graph::default();
            let mut n = crate::shading::Node::new("ShaderNodeTexEnvironment")
                .prop("interpolation", serde_json::json!(interp))
                .prop("colorspace", serde_json::json!(colorspace))
                .prop("projection", serde_json::json!(projection));
            n.image = Some(0);
            let env = g.add(n);
            let bg = g.add(
                crate::shading::Node::new("ShaderNodeBackground")
                    .link("Color", env, "Color")
                    .with("Strength", &[strength]),
            );
            g.surface = Some((bg, "Background".into()));
            g
        };
        let mut checked = 0;
        for (interp, cs, proj, strength) in [
            ("Linear", "Non-Color", "EQUIRECTANGULAR", 1.0),
            ("Closest", "Non-Color", "EQUIRECTANGULAR", 2.5),
            ("Linear", "sRGB", "EQUIRECTANGULAR", 0.7),
            ("Linear", "Non-Color", "MIRROR_BALL", 1.3),
            ("Linear", "Non-Color", "EQUIRECTANGULAR", 0.0),
            ("Linear", "Non-Color", "EQUIRECTANGULAR", -1.0),
        ] {
            let mut scene = Scene::default();
            scene.images.push(image.clone());
            scene.world.graph = Some(world(interp, cs, proj, strength));
            let program = crate::shading::compile(scene.world.graph.as_ref().unwrap(), "w")
                .unwrap()
                .program;
            assert!(program.image_world().is_some(), "{interp} {cs} {proj}");
            let env = Environment::new(&scene, Arc::new(program), Mat4::IDENTITY, None);
            for k in 0..4000 {
                let u = Vec2::new((k % 80) as f32 / 79.0, (k / 80) as f32 / 49.0);
                let d = crate::sampling::square_to_uniform_sphere(u);
                // Clamped as the world clamps its program's emission.
                let by_program = env
                    .program
                    .emission(&background_globals(d, 2, 0), &env.shade_env(&scene))
                    .max(Vec3::ZERO);
                let direct = env.radiance(&scene, d, 2, 0);
                assert_eq!(
                    direct.to_array().map(f32::to_bits),
                    by_program.to_array().map(f32::to_bits),
                    "{interp} {cs} {proj} {strength}: {d}"
                );
                checked += (direct != Vec3::ZERO) as usize;
            }
        }
        assert!(checked > 10_000, "{checked}");
        // A linked Vector is more than an image world.
        let mut g = world("Linear", "Non-Color", "EQUIRECTANGULAR", 1.0);
        let tc = g.add(crate::shading::Node::new("ShaderNodeTexCoord"));
        g.nodes[0] = g.nodes[0].clone().link("Vector", tc, "Generated");
        let program = crate::shading::compile(&g, "w").unwrap().program;
        assert!(program.image_world().is_none());
    }

    #[test]
    fn map_resolution_follows_the_image_capped() {
        let img = |w: u32, h: u32| Image {
            width: w,
            height: h,
            rgba8: Vec::new(),
            float: vec![[0.0; 4]; 1],
        };
        let mut g = Graph::default();
        let mut n = crate::shading::Node::new("ShaderNodeTexEnvironment");
        n.image = Some(0);
        g.add(n);
        let world = World::default();
        assert_eq!(
            map_resolution(&world, &g, &[img(512, 256)]),
            Some([512, 256, 1])
        );
        assert_eq!(
            map_resolution(&world, &g, &[img(8192, 4096)]),
            Some([2048, 1024, 4])
        );
        assert_eq!(map_resolution(&world, &g, &[img(1, 1)]), Some([64, 32, 1]));
        assert_eq!(
            map_resolution(&world, &g, &[img(100_000, 2)]),
            Some([2048, 32, 4])
        );
        assert_eq!(
            map_resolution(&world, &Graph::default(), &[]),
            Some([1024, 512, 1])
        );
        let manual = World {
            sampling: WorldSampling::Manual(256),
            ..Default::default()
        };
        assert_eq!(
            map_resolution(&manual, &g, &[img(512, 256)]),
            Some([256, 128, 1])
        );
        let none = World {
            sampling: WorldSampling::None,
            ..Default::default()
        };
        assert_eq!(map_resolution(&none, &g, &[]), None);
    }
}
