//! The render loop: square tiles in parallel on a `rayon` pool, a box pixel filter, and one
//! deterministic random stream per (seed, pixel, sample) so the image does not depend on the
//! thread count. Non-finite samples are rejected (counted, never written to the film).

use crate::camera::RayCamera;
use crate::film::accumulators::Accumulators;
use crate::film::data::DataContext;
use crate::film::{Adaptive, Pass, PassSet, PixelAcc, catcher};
use crate::integrator::light_split::LightSplit;
use crate::integrator::{self, Integrator};
use crate::render_scene::{Ctx, RayQuery, RenderScene};
use crate::sampler::SobolSampler;
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

/// How a pixel's samples draw their random numbers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Sampling {
    /// One Owen-scrambled Sobol sequence per pixel ([`SobolSampler`]): the samples of a pixel
    /// are stratified, and error falls faster than 1/N where the integrand is smooth.
    #[default]
    Sobol,
    /// Every sample its own scramble (the first point of a sequence seeded by the sample):
    /// independent uniform numbers, plain Monte Carlo whose variance falls as exactly 1/N.
    Independent,
}

/// What to render.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    pub seed: u64,
    pub integrator: String,
    /// Worker threads; 0 = one per core.
    pub threads: usize,
    pub tile_size: u32,
    /// Window `(x, y, w, h)` of the full frame to render (top-left origin); `None` = all.
    pub region: Option<[u32; 4]>,
    /// Auxiliary passes to render besides Combined.
    pub passes: PassSet,
    /// Cycles' adaptive sampling; `None` renders `spp` samples in every pixel.
    pub adaptive: Option<Adaptive>,
    /// Stop after the sample round that crosses this many seconds (Cycles' time limit).
    pub time_limit: Option<f64>,
    /// How sample positions spread over and around each pixel.
    pub filter: crate::film::PixelFilter,
    /// Per-kind bounce limits, transparent pass-throughs and clamping (path integrators).
    pub light_paths: crate::integrator::light_paths::LightPaths,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 512,
            height: 512,
            spp: 64,
            max_depth: 16,
            seed: 0,
            integrator: "path_mis".into(),
            threads: 0,
            tile_size: 32,
            region: None,
            passes: PassSet::default(),
            adaptive: None,
            time_limit: None,
            filter: Default::default(),
            light_paths: Default::default(),
        }
    }
}

/// A tile of the film as it stands: `w × h` RGBA pixels, rows top to bottom, at `(x, y)` in
/// the output image, with the auxiliary passes of each pixel.
pub struct Tile {
    pub x: u32,
    pub y: u32,
    pub w: u32,
    pub h: u32,
    pub pixels: Vec<[f32; 4]>,
    /// `w × h` records of [`RenderOptions::passes`]' channels (`PassSet::stride` each).
    pub aovs: Vec<f32>,
    /// Samples per pixel reached by the round the tile comes from (adaptive sampling may
    /// have stopped some pixels earlier).
    pub spp: u32,
}

/// Linear RGBA image, rows top to bottom, with its auxiliary passes.
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
    pub passes: PassSet,
    /// One record of `passes`' channels per pixel, in pixel order.
    pub aovs: Vec<f32>,
}

impl Image {
    /// Denoises Combined's colour in place (alpha kept) with Open Image Denoise, guided by
    /// the Denoising Albedo and Denoising Normal passes when the image has them.
    pub fn denoise(
        &mut self,
        denoiser: &crate::denoise::Denoiser,
        prefilter: bool,
    ) -> Result<(), crate::denoise::DenoiseError> {
        use crate::film::Pass;
        let color: Vec<f32> = self
            .pixels
            .iter()
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        let albedo = self.pass(Pass::DenoisingAlbedo);
        let normal = self.pass(Pass::DenoisingNormal);
        let out = denoiser.denoise(
            &crate::denoise::Input {
                width: self.width as usize,
                height: self.height as usize,
                color: &color,
                albedo: albedo.as_deref(),
                normal: albedo.as_ref().and(normal.as_deref()),
            },
            prefilter,
        )?;
        for (p, c) in self.pixels.iter_mut().zip(out.chunks_exact(3)) {
            p[..3].copy_from_slice(c);
        }
        Ok(())
    }

    /// Keeps only the passes of `keep` (those it lists that the image has).
    pub fn retain_passes(&mut self, keep: &PassSet) {
        let kept = PassSet::new(
            self.passes
                .iter()
                .map(|(p, _)| p)
                .filter(|p| keep.contains(*p)),
        );
        if kept == self.passes {
            return;
        }
        let stride = self.passes.stride();
        let mut aovs = Vec::with_capacity(self.pixels.len() * kept.stride());
        for r in self.aovs.chunks_exact(stride.max(1)) {
            for (p, _) in kept.iter() {
                let at = self.passes.offset(p).unwrap_or(0);
                aovs.extend_from_slice(&r[at..at + p.channels()]);
            }
        }
        self.aovs = if kept.is_empty() { Vec::new() } else { aovs };
        self.passes = kept;
    }

    /// The image cut into `size`-pixel tiles, as the render streamed them.
    pub fn tiles(&self, size: u32) -> Vec<Tile> {
        let (w, stride) = (self.width as usize, self.passes.stride());
        let mut tiles = Vec::new();
        let size = size.max(1);
        for ty in (0..self.height).step_by(size as usize) {
            for tx in (0..self.width).step_by(size as usize) {
                let (tw, th) = (size.min(self.width - tx), size.min(self.height - ty));
                let mut pixels = Vec::with_capacity((tw * th) as usize);
                let mut aovs = Vec::with_capacity((tw * th) as usize * stride);
                for y in ty..ty + th {
                    let row = y as usize * w;
                    let (a, b) = (row + tx as usize, row + (tx + tw) as usize);
                    pixels.extend_from_slice(&self.pixels[a..b]);
                    aovs.extend_from_slice(&self.aovs[a * stride..b * stride]);
                }
                tiles.push(Tile {
                    x: tx,
                    y: ty,
                    w: tw,
                    h: th,
                    pixels,
                    aovs,
                    spp: 0,
                });
            }
        }
        tiles
    }

    /// Pass `p` as its own image: `width × height` records of `p.channels()` values.
    pub fn pass(&self, p: crate::film::Pass) -> Option<Vec<f32>> {
        let at = self.passes.offset(p)?;
        let (k, stride) = (p.channels(), self.passes.stride());
        Some(
            self.aovs
                .chunks_exact(stride)
                .flat_map(|r| r[at..at + k].iter().copied())
                .collect(),
        )
    }
}

/// Figures about a finished render.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct RenderStats {
    pub seconds: f64,
    pub samples: u64,
    /// Rays cast (see [`Ctx::rays`]).
    pub rays: u64,
    pub samples_per_second: f64,
    pub rays_per_second: f64,
    pub rejected_samples: u64,
    /// Samples per pixel reached: fewest, most, mean (they differ with adaptive sampling).
    pub spp_min: u32,
    pub spp_max: u32,
    pub spp_mean: f64,
    /// Mean per-pixel error estimate (adaptive sampling's, in units of its noise threshold).
    pub noise: f64,
    /// Sample rounds rendered.
    pub rounds: u32,
}

/// Why a render did not finish.
#[derive(Debug)]
pub enum RenderError {
    Cancelled,
    Invalid(String),
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RenderError::Cancelled => write!(f, "render cancelled"),
            RenderError::Invalid(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for RenderError {}

/// Largest image accepted (pixels): refuse what cannot reasonably be allocated.
pub const MAX_PIXELS: u64 = 1 << 28;

/// Most worker threads accepted: starting 100,000 threads takes minutes (it looked like a hang).
pub const MAX_THREADS: usize = 1024;

/// Checks the options before any allocation.
pub fn validate(opts: &RenderOptions) -> Result<(), RenderError> {
    if opts.width == 0 || opts.height == 0 {
        return Err(RenderError::Invalid(
            "resolution must be at least 1x1".into(),
        ));
    }
    if opts.width as u64 * opts.height as u64 > MAX_PIXELS {
        return Err(RenderError::Invalid(format!(
            "resolution {}x{} is too large (at most {} pixels)",
            opts.width, opts.height, MAX_PIXELS
        )));
    }
    if opts.threads > MAX_THREADS {
        return Err(RenderError::Invalid(format!(
            "{} worker threads is too many (at most {MAX_THREADS}; 0 = one per core)",
            opts.threads
        )));
    }
    if opts.spp == 0 {
        return Err(RenderError::Invalid(
            "samples per pixel must be at least 1".into(),
        ));
    }
    let Some(chosen) = integrator::by_name(&opts.integrator, 1) else {
        return Err(RenderError::Invalid(format!(
            "unknown integrator `{}` (choose one of {})",
            opts.integrator,
            integrator::NAMES.join(", ")
        )));
    };
    if opts.passes.has_light() && !chosen.splits_light() {
        return Err(RenderError::Invalid(format!(
            "the light passes (diffuse/glossy/transmission direct and indirect) need a \
             shading integrator (path_mis, path_mats, direct_mis, direct_ems, direct_mats), \
             not `{}`",
            opts.integrator
        )));
    }
    if let Some(t) = opts.time_limit
        && !(t.is_finite() && t >= 0.0)
    {
        return Err(RenderError::Invalid(format!(
            "time limit {t} is not a number of seconds >= 0 (0 = no limit)"
        )));
    }
    if let Some(a) = &opts.adaptive
        && !(a.threshold.is_finite() && a.threshold >= 0.0)
    {
        return Err(RenderError::Invalid(format!(
            "adaptive threshold {} is not a number >= 0 (0 = automatic)",
            a.threshold
        )));
    }
    if let Some([x, y, w, h]) = opts.region
        && (w == 0
            || h == 0
            || x as u64 + w as u64 > opts.width as u64
            || y as u64 + h as u64 > opts.height as u64)
    {
        return Err(RenderError::Invalid(format!(
            "region {x} {y} {w} {h} is empty or outside the {}x{} frame",
            opts.width, opts.height
        )));
    }
    Ok(())
}

/// Renders the samples `acc.next..end` of pixel `(px, py)` into its sums, with the thread's
/// context `ctx` (its ray count and log carry on).
#[inline]
#[allow(clippy::too_many_arguments)]
fn render_samples(
    scene: &RenderScene,
    camera: &RayCamera,
    integrator: &dyn Integrator,
    opts: &RenderOptions,
    data: Option<&DataContext>,
    (px, py): (u32, u32),
    end: u32,
    ctx: &mut Ctx,
    rejected: &mut u64,
    acc: &mut PixelAcc,
    aov: &mut [f32],
    sampling: Sampling,
) {
    let pixel_index = py as u64 * opts.width as u64 + px as u64;
    let transparent = scene.scene.settings.film_transparent;
    let lens = camera.has_lens();
    let timed = camera.needs_time();
    let adaptive = opts.adaptive.is_some();
    let light = data.is_some_and(|d| d.passes.has_light());
    let catcher = data.and_then(|d| d.passes.offset(Pass::CatcherSums));
    let data = data.filter(|d| d.passes.iter().any(|(p, _)| p != Pass::CatcherSums));
    // The film's data passes, coverage and catcher split follow the integrator's camera ray.
    ctx.camera_memo = data.is_some() || transparent || catcher.is_some();
    let sampler = |s: u32| match sampling {
        Sampling::Sobol => SobolSampler::new(opts.seed, pixel_index, s as u64),
        Sampling::Independent => SobolSampler::new(independent_seed(opts.seed, s), pixel_index, 0),
    };
    for s in acc.next..end {
        ctx.sampler = sampler(s);
        // Dimension 0: the pixel filter (with the first BSDF sample reserved, see
        // `next_2d_reserving`); then the lens, only for cameras with depth of field; then the
        // shutter time, only in scenes where something moves.
        let u = ctx.sampler.next_2d_reserving();
        let film = Vec2::new(
            px as f32 + opts.filter.offset(u.x),
            py as f32 + opts.filter.offset(u.y),
        );
        let u_lens = if lens {
            ctx.sampler.next_2d()
        } else {
            Vec2::ZERO
        };
        let ray = if timed {
            ctx.time = ctx.sampler.next_1d();
            camera.ray_at(film, u_lens, ctx.time)
        } else {
            camera.ray(film, u_lens)
        };
        let Some(ray) = ray else {
            acc.empty += 1;
            continue;
        };
        ctx.camera_end = ray.tmax.is_finite().then(|| ray.o + ray.d * ray.tmax);
        ctx.camera_hit = None;
        let mut split = LightSplit::default();
        let l = if light {
            integrator.li_split(scene, ctx, ray.o, ray.d, &mut split)
        } else {
            integrator.li(scene, ctx, ray.o, ray.d)
        };
        if l.is_finite() {
            acc.sum += l;
            acc.accepted += 1;
            // Film > Transparent Glass: less the share the path found the world with through
            // transmission (not clamped: the mean over samples is).
            let coverage = if transparent {
                scene.camera_coverage(ctx, ray.o, ray.d) - ctx.see_through
            } else {
                1.0
            };
            if transparent {
                acc.coverage += coverage;
            }
            if adaptive && crate::film::in_half_buffer(s) {
                acc.half += 2.0 * l;
            }
            if let Some(data) = data {
                data.add_sample(ctx, ray.o, ray.d, acc.accepted == 1, aov);
                if light {
                    data.add_light(&split, aov);
                }
            }
            if let Some(at) = catcher {
                let rec = &mut aov[at..at + Pass::CatcherSums.channels()];
                match scene.trace(ctx, ray.o, ray.d, 1) {
                    Some(its) if scene.catcher_at(&its) => {
                        // The second path takes the first one's random numbers (Cycles copies
                        // the path's state), so the two differ only where other objects are.
                        ctx.sampler = sampler(s);
                        ctx.sampler.next_2d_reserving();
                        if lens {
                            ctx.sampler.next_2d();
                        }
                        if timed {
                            ctx.sampler.next_1d();
                        }
                        (ctx.catchers_only, ctx.camera_hit) = (true, None);
                        let k = integrator.li(scene, ctx, ray.o, ray.d);
                        (ctx.catchers_only, ctx.camera_hit) = (false, None);
                        let k = if k.is_finite() { k } else { Vec3::ZERO };
                        let world = if transparent {
                            Vec3::ZERO
                        } else {
                            scene.world_radiance(ray.d, ray.o)
                        };
                        catcher::add_split(rec, k, world);
                    }
                    hit => {
                        let world = if transparent || hit.is_some() {
                            Vec3::ZERO
                        } else {
                            scene.world_radiance(ray.d, ray.o)
                        };
                        catcher::add_matte(rec, l, 1.0 - coverage, world);
                    }
                }
            }
        } else {
            *rejected += 1;
        }
    }
    (ctx.camera_memo, ctx.camera_hit) = (false, None);
    acc.next = acc.next.max(end);
}

/// The seed of sample `s` under [`Sampling::Independent`] (a bijective mix, so no two samples
/// of a render share a scramble).
#[inline]
fn independent_seed(seed: u64, s: u32) -> u64 {
    let mut z = seed ^ ((s as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15));
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// What every render with `opts` starts from.
struct Prepared {
    integrator: Box<dyn Integrator>,
    camera: RayCamera,
    /// The pixel window `[x, y, w, h]`.
    region: [u32; 4],
}

/// Checks `opts` and sets up the integrator, the camera and the pixel window.
fn prepare(scene: &RenderScene, opts: &RenderOptions) -> Result<Prepared, RenderError> {
    validate(opts)?;
    let integrator =
        integrator::by_name_with(&opts.integrator, opts.max_depth.max(1), opts.light_paths)
            .ok_or_else(|| RenderError::Invalid("unknown integrator".into()))?;
    scene.set_window_resolution(opts.width, opts.height);
    Ok(Prepared {
        integrator,
        camera: RayCamera::new(&scene.scene, opts.width, opts.height),
        region: opts.region.unwrap_or([0, 0, opts.width, opts.height]),
    })
}

/// Every ray a render with `opts` casts, in pixel order on one thread (for the traversal
/// benchmark: `benches/traversal.rs`).
pub fn record_rays(
    scene: &RenderScene,
    opts: &RenderOptions,
) -> Result<Vec<RayQuery>, RenderError> {
    let Prepared {
        integrator,
        camera,
        region: [rx, ry, rw, rh],
    } = prepare(scene, opts)?;
    let mut ctx = Ctx::new(SobolSampler::new(0, 0, 0));
    ctx.log = Some(Vec::new());
    let mut rejected = 0;
    for y in ry..ry + rh {
        for x in rx..rx + rw {
            let mut acc = PixelAcc::default();
            render_samples(
                scene,
                &camera,
                integrator.as_ref(),
                opts,
                None,
                (x, y),
                opts.spp,
                &mut ctx,
                &mut rejected,
                &mut acc,
                &mut [],
                Sampling::Sobol,
            );
        }
    }
    Ok(ctx.log.unwrap_or_default())
}

/// What the workers on one row of a tile did in a round.
#[derive(Default)]
struct RowWork {
    rays: u64,
    rejected: u64,
    /// Some pixel rendered samples.
    worked: bool,
    cancelled: bool,
}

impl RowWork {
    fn merge(a: RowWork, b: RowWork) -> RowWork {
        RowWork {
            rays: a.rays + b.rays,
            rejected: a.rejected + b.rejected,
            worked: a.worked || b.worked,
            cancelled: a.cancelled || b.cancelled,
        }
    }
}

/// One tile's pixels and their sums, owned by whichever worker renders it in a round.
struct TileState {
    x: u32,
    y: u32,
    w: u32,
    h: u32,
    px: Vec<PixelAcc>,
    aov: Vec<f32>,
    rays: u64,
    rejected: u64,
}

impl TileState {
    /// The tile as it stands now.
    /// The tile as it stands now, with the passes of `passes` from the sums laid out by
    /// `acc` (`passes` and what they are computed from).
    fn snapshot(&self, passes: &PassSet, acc: &PassSet, transparent: bool, spp: u32) -> Tile {
        let (stride, acc_stride) = (passes.stride(), acc.stride());
        let mut aovs = vec![0.0; self.px.len() * stride];
        let pixels = (self.px.iter().enumerate())
            .map(|(i, p)| {
                let out = &mut aovs[i * stride..(i + 1) * stride];
                let rec = &self.aov[i * acc_stride..(i + 1) * acc_stride];
                crate::film::resolve_pixel(p, acc, rec, passes, transparent, out)
            })
            .collect();
        Tile {
            x: self.x,
            y: self.y,
            w: self.w,
            h: self.h,
            pixels,
            aovs,
            spp,
        }
    }
}

/// Renders the image. `on_tile(tile, tiles_done, tiles_total)` runs on a worker thread as each
/// tile finishes a sample round (at most about once a second per tile when there are several
/// rounds, and always for the last). `cancel` is polled between pixels.
pub fn render(
    scene: &RenderScene,
    opts: &RenderOptions,
    cancel: &AtomicBool,
    on_tile: &(dyn Fn(&Tile, usize, usize) + Sync),
) -> Result<(Image, RenderStats), RenderError> {
    render_sampled(scene, opts, Sampling::Sobol, cancel, on_tile)
}

/// [`render`] with the random numbers drawn as `sampling` says.
pub fn render_sampled(
    scene: &RenderScene,
    opts: &RenderOptions,
    sampling: Sampling,
    cancel: &AtomicBool,
    on_tile: &(dyn Fn(&Tile, usize, usize) + Sync),
) -> Result<(Image, RenderStats), RenderError> {
    let (film, stats) = render_film(scene, opts, sampling, 0..opts.spp, cancel, on_tile)?;
    let mut image = film.resolve();
    // The film also summed the Color passes its light passes are divided by.
    image.retain_passes(&opts.passes);
    Ok((image, stats))
}

/// Renders samples `samples` (`[start, end)`, within `[0, opts.spp)`) of every pixel with the
/// streams a whole render gives them, and returns the film's sums: the parts of a render
/// split by sample range merge into it exactly ([`Accumulators::merge`]). Adaptive sampling
/// and a time limit decide which samples exist from the whole film, so a part cannot have
/// them. The returned key is empty: the caller names the render.
pub fn render_range(
    scene: &RenderScene,
    opts: &RenderOptions,
    samples: Range<u32>,
    cancel: &AtomicBool,
    on_tile: &(dyn Fn(&Tile, usize, usize) + Sync),
) -> Result<(Accumulators, RenderStats), RenderError> {
    if samples.start >= samples.end || samples.end > opts.spp {
        return Err(RenderError::Invalid(format!(
            "sample range {}:{} is empty or outside the render's {} samples",
            samples.start, samples.end, opts.spp
        )));
    }
    if let Some(why) = unsplittable(opts) {
        return Err(RenderError::Invalid(format!(
            "{why} cannot be split into sample ranges exactly"
        )));
    }
    render_film(scene, opts, Sampling::Sobol, samples, cancel, on_tile)
}

/// What in `opts` makes a render's samples depend on the whole film (so a sample range
/// cannot be rendered alone).
pub fn unsplittable(opts: &RenderOptions) -> Option<&'static str> {
    if opts.adaptive.is_some() {
        Some("adaptive sampling (each pixel's sample count depends on the whole film)")
    } else if opts.time_limit.is_some_and(|t| t > 0.0) {
        Some("a time limit (the sample count depends on the machine's speed)")
    } else {
        None
    }
}

/// A film whose per-pixel sums persist between sample rounds. [`render_film`] runs its
/// rounds through one; the interactive session adds rounds as it goes. A pixel sums its
/// samples in sample order whatever the split into rounds, so the image at `N` samples is
/// the same bits however the rounds (and the threads) divided the work.
pub struct Progressive {
    prepared: Prepared,
    opts: RenderOptions,
    sampling: Sampling,
    /// The film's sums: the passes asked for and the Color passes their light passes need.
    acc_passes: PassSet,
    tiles: Vec<TileState>,
    /// The first sample of every pixel.
    first: u32,
    rounds: u32,
    /// Blender's film_transparent: alpha is the coverage.
    transparent: bool,
}

impl Progressive {
    /// An empty film for `opts` (its `spp` is only checked, never used: rounds say how far).
    pub fn new(
        scene: &RenderScene,
        opts: &RenderOptions,
        sampling: Sampling,
    ) -> Result<Progressive, RenderError> {
        Self::starting_at(scene, opts, sampling, 0)
    }

    /// [`Progressive::new`] whose pixels start at sample `first`.
    fn starting_at(
        scene: &RenderScene,
        opts: &RenderOptions,
        sampling: Sampling,
        first: u32,
    ) -> Result<Progressive, RenderError> {
        let prepared = prepare(scene, opts)?;
        let [_, _, rw, rh] = prepared.region;
        let ts = opts.tile_size.max(1);
        let mut acc_passes = opts.passes.with_dividers();
        if scene.has_catchers() {
            acc_passes = acc_passes.with_catcher();
        }
        let acc_stride = acc_passes.stride();
        let mut tiles = Vec::new();
        for ty in (0..rh).step_by(ts as usize) {
            for tx in (0..rw).step_by(ts as usize) {
                let (tw, th) = (ts.min(rw - tx), ts.min(rh - ty));
                let n = (tw * th) as usize;
                tiles.push(TileState {
                    x: tx,
                    y: ty,
                    w: tw,
                    h: th,
                    px: vec![
                        PixelAcc {
                            next: first,
                            ..Default::default()
                        };
                        n
                    ],
                    aov: vec![0.0; n * acc_stride],
                    rays: 0,
                    rejected: 0,
                });
            }
        }
        Ok(Progressive {
            prepared,
            opts: opts.clone(),
            sampling,
            acc_passes,
            tiles,
            first,
            rounds: 0,
            transparent: scene.scene.settings.film_transparent,
        })
    }

    /// Renders every pixel's samples up to `end` (those not yet rendered, of pixels adaptive
    /// sampling has not stopped) on `pool`. `cancel` is polled before each pixel; a cancelled
    /// round leaves each pixel with whole samples only, so a later round resumes it.
    pub fn round(
        &mut self,
        scene: &RenderScene,
        end: u32,
        pool: &rayon::ThreadPool,
        cancel: &AtomicBool,
    ) -> Result<(), RenderError> {
        self.round_with(scene, end, pool, cancel, &|_, _| {})
    }

    /// [`Progressive::round`], calling `after(tile, worked)` on the worker as each tile is done
    /// (`worked`: the tile rendered samples in this round).
    fn round_with(
        &mut self,
        scene: &RenderScene,
        end: u32,
        pool: &rayon::ThreadPool,
        cancel: &AtomicBool,
        after: &(dyn Fn(&TileState, bool) + Sync),
    ) -> Result<(), RenderError> {
        let Prepared {
            integrator,
            camera,
            region: [rx, ry, _, _],
        } = &self.prepared;
        let (opts, sampling) = (&self.opts, self.sampling);
        let acc_stride = self.acc_passes.stride();
        let data_ctx = (!self.acc_passes.is_empty()).then_some(DataContext {
            scene,
            camera,
            passes: &self.acc_passes,
            mist: scene.scene.settings.mist,
        });
        // Rows are the unit of work, tiles the unit of streaming: late adaptive rounds leave
        // the unconverged pixels in a few tiles, which whole-tile work would give one thread.
        let result: Result<(), RenderError> = pool.install(|| {
            self.tiles.par_iter_mut().try_for_each(|t| {
                let (tx, ty, tw) = (t.x, t.y, t.w as usize);
                let mut aov_rows = t.aov.chunks_mut((tw * acc_stride).max(1));
                let rows: Vec<(&mut [PixelAcc], &mut [f32])> = (t.px.chunks_mut(tw))
                    .map(|px| (px, aov_rows.next().unwrap_or(&mut [])))
                    .collect();
                let row = |(y, (px, aov)): (usize, (&mut [PixelAcc], &mut [f32]))| {
                    let mut ctx = Ctx::new(SobolSampler::new(0, 0, 0));
                    let mut w = RowWork::default();
                    for (x, acc) in px.iter_mut().enumerate() {
                        if acc.converged || acc.next >= end {
                            continue;
                        }
                        // Polled per pixel: a pixel's samples are the longest wait (a row of
                        // a tile at 16 samples in a million-triangle scene is ~20 ms).
                        if cancel.load(Ordering::Relaxed) {
                            w.cancelled = true;
                            break;
                        }
                        w.worked = true;
                        render_samples(
                            scene,
                            camera,
                            integrator.as_ref(),
                            opts,
                            data_ctx.as_ref(),
                            (rx + tx + x as u32, ry + ty + y as u32),
                            end,
                            &mut ctx,
                            &mut w.rejected,
                            acc,
                            &mut aov[x * acc_stride..(x + 1) * acc_stride],
                            sampling,
                        );
                    }
                    w.rays = ctx.rays;
                    w
                };
                let w = rows
                    .into_par_iter()
                    .enumerate()
                    .map(row)
                    .reduce(RowWork::default, RowWork::merge);
                t.rays += w.rays;
                t.rejected += w.rejected;
                if w.cancelled {
                    return Err(RenderError::Cancelled);
                }
                after(t, w.worked);
                Ok(())
            })
        });
        result?;
        self.rounds += 1;
        Ok(())
    }

    /// Samples per pixel every pixel has reached.
    pub fn samples(&self) -> u32 {
        (self.tiles.iter())
            .flat_map(|t| t.px.iter().map(|p| p.next))
            .min()
            .unwrap_or(0)
    }

    /// The film's sums as they stand, for samples `first..end` of a render of `spp`.
    fn accumulators(&self, end: u32) -> Accumulators {
        let [_, _, rw, rh] = self.prepared.region;
        let acc_stride = self.acc_passes.stride();
        let mut film = Accumulators {
            width: rw,
            height: rh,
            samples: self.first..end,
            spp: self.opts.spp,
            passes: self.acc_passes.clone(),
            transparent: self.transparent,
            key: String::new(),
            pixels: vec![PixelAcc::default(); rw as usize * rh as usize],
            aovs: vec![0.0; rw as usize * rh as usize * acc_stride],
        };
        for t in &self.tiles {
            for y in 0..t.h {
                let src = (y * t.w) as usize..((y + 1) * t.w) as usize;
                let row = (t.y + y) as usize * rw as usize + t.x as usize;
                film.pixels[row..row + t.w as usize].copy_from_slice(&t.px[src.clone()]);
                film.aovs[row * acc_stride..(row + t.w as usize) * acc_stride]
                    .copy_from_slice(&t.aov[src.start * acc_stride..src.end * acc_stride]);
            }
        }
        film
    }

    /// The film as it stands: the window's pixels and the passes asked for.
    pub fn image(&self) -> Image {
        let mut image = self.accumulators(self.samples()).resolve();
        image.retain_passes(&self.opts.passes);
        image
    }

    /// The film's figures, `seconds` after the render started.
    pub fn stats(&self, seconds: f64) -> RenderStats {
        let [_, _, rw, rh] = self.prepared.region;
        let (mut rays, mut rejected, mut samples) = (0u64, 0u64, 0u64);
        let (mut spp_min, mut spp_max, mut noise) = (u32::MAX, 0u32, 0.0f64);
        for t in &self.tiles {
            for p in &t.px {
                let n = p.next - self.first;
                samples += n as u64;
                spp_min = spp_min.min(n);
                spp_max = spp_max.max(n);
                let e = p.error() as f64;
                if e.is_finite() {
                    noise += e;
                }
            }
            rays += t.rays;
            rejected += t.rejected;
        }
        let pixels = (rw as u64 * rh as u64).max(1);
        RenderStats {
            seconds,
            samples,
            rays,
            samples_per_second: samples as f64 / seconds.max(1e-9),
            rays_per_second: rays as f64 / seconds.max(1e-9),
            rejected_samples: rejected,
            spp_min: spp_min.min(spp_max),
            spp_max,
            spp_mean: samples as f64 / pixels as f64,
            // In units of the noise threshold the user sets (Cycles' internal one is 5x).
            noise: noise / pixels as f64 / 5.0,
            rounds: self.rounds,
        }
    }
}

/// Renders samples `range` of every pixel into the film's sums (rounds, adaptive sampling
/// and the time limit only for a whole render, `0..opts.spp`).
fn render_film(
    scene: &RenderScene,
    opts: &RenderOptions,
    sampling: Sampling,
    range: Range<u32>,
    cancel: &AtomicBool,
    on_tile: &(dyn Fn(&Tile, usize, usize) + Sync),
) -> Result<(Accumulators, RenderStats), RenderError> {
    let mut film = Progressive::starting_at(scene, opts, sampling, range.start)?;
    let [_, _, rw, rh] = film.prepared.region;
    let acc_passes = film.acc_passes.clone();
    let transparent = film.transparent;
    let time_limit = opts.time_limit.filter(|t| *t > 0.0);
    let whole = range == (0..opts.spp);
    let ends = if whole {
        crate::film::round_ends(opts.spp, opts.adaptive.as_ref(), time_limit.is_some())
    } else {
        vec![range.end]
    };
    let threshold = opts.adaptive.map(|a| a.resolved(opts.spp).0);
    let total = film.tiles.len() * ends.len();
    let done = AtomicUsize::new(0);
    let start = Instant::now();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .map_err(|e| RenderError::Invalid(format!("cannot start worker threads: {e}")))?;

    let mut last_stream: Option<Instant> = None;
    let mut streamed_last = false;
    for (ri, &end) in ends.iter().enumerate() {
        let last = ri + 1 == ends.len();
        let stream = last || last_stream.is_none_or(|t| t.elapsed().as_secs_f64() >= 1.0);
        let after = |t: &TileState, worked: bool| {
            let n = done.fetch_add(1, Ordering::Relaxed) + 1;
            if stream && (worked || last) {
                on_tile(
                    &t.snapshot(&opts.passes, &acc_passes, transparent, end),
                    n,
                    total,
                );
            }
        };
        film.round_with(scene, end, &pool, cancel, &after)?;
        if stream {
            last_stream = Some(Instant::now());
        }
        streamed_last = stream;
        if last {
            break;
        }
        let mut all_converged = false;
        if let Some(threshold) = threshold {
            all_converged = check_convergence(&mut film.tiles, rw, rh, threshold);
        }
        let out_of_time = time_limit.is_some_and(|t| start.elapsed().as_secs_f64() >= t);
        if all_converged || out_of_time {
            break;
        }
    }
    if !streamed_last {
        // The render stopped early after a round that was not streamed: send the final film.
        let n = film.tiles.len();
        for (i, t) in film.tiles.iter().enumerate() {
            let spp = t.px.iter().map(|p| p.next).max().unwrap_or(0);
            on_tile(
                &t.snapshot(&opts.passes, &acc_passes, transparent, spp),
                total - n + i + 1,
                total,
            );
        }
    }
    let stats = film.stats(start.elapsed().as_secs_f64());
    Ok((film.accumulators(range.end), stats))
}

/// Adaptive sampling's check after a round: marks the pixels whose error is below
/// `threshold` converged, then un-marks the neighbours of unconverged pixels. True when
/// every pixel has converged.
fn check_convergence(tiles: &mut [TileState], rw: u32, rh: u32, threshold: f32) -> bool {
    let (w, h) = (rw as usize, rh as usize);
    let mut mask = vec![false; w * h];
    for t in tiles.iter() {
        for (i, p) in t.px.iter().enumerate() {
            let (x, y) = (
                t.x as usize + i % t.w as usize,
                t.y as usize + i / t.w as usize,
            );
            mask[y * w + x] = p.converged || p.error() < threshold;
        }
    }
    crate::film::dilate_unconverged(&mut mask, w, h);
    let mut all = true;
    for t in tiles.iter_mut() {
        let tw = t.w as usize;
        for (i, p) in t.px.iter_mut().enumerate() {
            let (x, y) = (t.x as usize + i % tw, t.y as usize + i / tw);
            p.converged = mask[y * w + x];
            all &= p.converged;
        }
    }
    all
}
