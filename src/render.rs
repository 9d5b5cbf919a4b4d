//! The render loop: square tiles in parallel on a `rayon` pool, a box pixel filter, and one
//! deterministic random stream per (seed, pixel, sample) so the image does not depend on the
//! thread count. Non-finite samples are rejected (counted, never written to the film).

use crate::camera::RayCamera;
use crate::integrator::{self, Integrator};
use crate::render_scene::{Ctx, RayQuery, RenderScene};
use crate::sampler::SobolSampler;
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
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
        }
    }
}

/// A finished tile: `w × h` RGBA pixels, rows top to bottom, at `(x, y)` in the output image.
pub struct Tile {
    pub x: u32,
    pub y: u32,
    pub w: u32,
    pub h: u32,
    pub pixels: Vec<[f32; 4]>,
}

/// Linear RGBA image, rows top to bottom.
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
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
    if integrator::by_name(&opts.integrator, 1).is_none() {
        return Err(RenderError::Invalid(format!(
            "unknown integrator `{}` (choose one of {})",
            opts.integrator,
            integrator::NAMES.join(", ")
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

/// Renders one pixel's samples with the thread's context `ctx` (its ray count and log carry
/// on); returns the mean radiance of the accepted samples.
#[inline]
#[allow(clippy::too_many_arguments)]
fn render_pixel(
    scene: &RenderScene,
    camera: &RayCamera,
    integrator: &dyn Integrator,
    opts: &RenderOptions,
    px: u32,
    py: u32,
    ctx: &mut Ctx,
    rejected: &mut u64,
    sampling: Sampling,
) -> [f32; 4] {
    let pixel_index = py as u64 * opts.width as u64 + px as u64;
    let mut sum = Vec3::ZERO;
    let mut accepted = 0u32;
    // Samples where the camera sees nothing (outside a fisheye's circle): black.
    let mut empty = 0u32;
    // With a transparent film: the summed coverage of the accepted samples (their alpha).
    let mut coverage = 0.0f32;
    let transparent = scene.scene.settings.film_transparent;
    let lens = camera.has_lens();
    for s in 0..opts.spp {
        ctx.sampler = match sampling {
            Sampling::Sobol => SobolSampler::new(opts.seed, pixel_index, s as u64),
            Sampling::Independent => {
                SobolSampler::new(independent_seed(opts.seed, s), pixel_index, 0)
            }
        };
        // Dimension 0: the pixel filter; 1: the lens, only for cameras with depth of field.
        let film = Vec2::new(px as f32, py as f32) + ctx.sampler.next_2d();
        let u_lens = if lens {
            ctx.sampler.next_2d()
        } else {
            Vec2::ZERO
        };
        let Some(ray) = camera.ray(film, u_lens) else {
            empty += 1;
            continue;
        };
        // The integrators trace camera rays without an end yet: `ray.tmax` (the far clip
        // distance) is not applied.
        let l = integrator.li(scene, ctx, ray.o, ray.d);
        if l.is_finite() && l.min_element() >= 0.0 {
            sum += l;
            accepted += 1;
            if transparent {
                coverage += scene.camera_coverage(ctx, ray.o, ray.d);
            }
        } else {
            *rejected += 1;
        }
    }
    let n = accepted + empty;
    let c = if n > 0 { sum / n as f32 } else { Vec3::ZERO };
    // An opaque film, as Cycles' without "Transparent": alpha 1 everywhere. A transparent
    // one (`render.film_transparent`): the mean coverage (`RenderScene::camera_coverage`).
    let alpha = if transparent && n > 0 {
        coverage / n as f32
    } else {
        1.0
    };
    [c.x, c.y, c.z, alpha]
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
    Ok(Prepared {
        integrator: integrator::by_name(&opts.integrator, opts.max_depth.max(1))
            .ok_or_else(|| RenderError::Invalid("unknown integrator".into()))?,
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
            render_pixel(
                scene,
                &camera,
                integrator.as_ref(),
                opts,
                x,
                y,
                &mut ctx,
                &mut rejected,
                Sampling::Sobol,
            );
        }
    }
    Ok(ctx.log.unwrap_or_default())
}

/// Renders the image. `on_tile(tile, tiles_done, tiles_total)` runs on a worker thread as each
/// tile finishes. `cancel` is polled between rows.
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
    let Prepared {
        integrator,
        camera,
        region: [rx, ry, rw, rh],
    } = prepare(scene, opts)?;
    let ts = opts.tile_size.max(1);
    let mut tiles = Vec::new();
    for ty in (0..rh).step_by(ts as usize) {
        for tx in (0..rw).step_by(ts as usize) {
            tiles.push((tx, ty, ts.min(rw - tx), ts.min(rh - ty)));
        }
    }
    let total = tiles.len();
    let done = AtomicUsize::new(0);
    let rays = AtomicU64::new(0);
    let rejected = AtomicU64::new(0);
    let start = Instant::now();

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .map_err(|e| RenderError::Invalid(format!("cannot start worker threads: {e}")))?;
    let results: Result<Vec<Tile>, RenderError> = pool.install(|| {
        tiles
            .par_iter()
            .map(|&(tx, ty, tw, th)| {
                let mut pixels = Vec::with_capacity((tw * th) as usize);
                let mut ctx = Ctx::new(SobolSampler::new(0, 0, 0));
                let mut rej = 0u64;
                for y in 0..th {
                    if cancel.load(Ordering::Relaxed) {
                        return Err(RenderError::Cancelled);
                    }
                    for x in 0..tw {
                        pixels.push(render_pixel(
                            scene,
                            &camera,
                            integrator.as_ref(),
                            opts,
                            rx + tx + x,
                            ry + ty + y,
                            &mut ctx,
                            &mut rej,
                            sampling,
                        ));
                    }
                }
                rays.fetch_add(ctx.rays, Ordering::Relaxed);
                rejected.fetch_add(rej, Ordering::Relaxed);
                let tile = Tile {
                    x: tx,
                    y: ty,
                    w: tw,
                    h: th,
                    pixels,
                };
                let n = done.fetch_add(1, Ordering::Relaxed) + 1;
                on_tile(&tile, n, total);
                Ok(tile)
            })
            .collect()
    });
    let tiles = results?;
    let mut image = Image {
        width: rw,
        height: rh,
        pixels: vec![[0.0; 4]; rw as usize * rh as usize],
    };
    for t in &tiles {
        for y in 0..t.h {
            let src = &t.pixels[(y * t.w) as usize..((y + 1) * t.w) as usize];
            let row = (t.y + y) as usize * rw as usize + t.x as usize;
            image.pixels[row..row + t.w as usize].copy_from_slice(src);
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    let samples = rw as u64 * rh as u64 * opts.spp as u64;
    let rays = rays.into_inner();
    Ok((
        image,
        RenderStats {
            seconds,
            samples,
            rays,
            samples_per_second: samples as f64 / seconds.max(1e-9),
            rays_per_second: rays as f64 / seconds.max(1e-9),
            rejected_samples: rejected.into_inner(),
        },
    ))
}
