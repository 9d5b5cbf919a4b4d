//! The `tesela` command line: render a glTF scene (or a built-in one) to EXR/PNG, or stream
//! tiles to the Blender add-on over a pipe (`--pipe`, see docs/protocol.md).

use clap::{Parser, Subcommand};
use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;
use tesela::emitter::LightChoice;
use tesela::protocol::{self, Message};
use tesela::render::{self, RenderError, RenderOptions};
use tesela::render_scene::RenderScene;
use tesela::scene::{self, Scene};

/// Exit status: the render failed.
const EXIT_RENDER: u8 = 1;
/// Exit status: the scene could not be loaded.
const EXIT_LOAD: u8 = 3;
/// Exit status: cancelled (stdin closed in pipe mode, or SIGTERM/SIGINT).
const EXIT_CANCELLED: u8 = 130;

/// Set by SIGTERM/SIGINT or by stdin reaching EOF in pipe mode; polled by the render loop.
static CANCEL: AtomicBool = AtomicBool::new(false);

#[derive(Parser)]
#[command(
    name = "tesela",
    version,
    about = "Tesela: a physically based renderer for glTF 2.0 scenes and Blender",
    after_help = "Exit status: 0 success, 1 render failed, 2 bad usage, 3 scene could not be loaded, 130 cancelled."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
#[allow(clippy::large_enum_variant)] // parsed once
enum Command {
    /// Render a scene to an image (or to the Blender add-on with --pipe).
    Render(RenderArgs),
    /// Print what a scene contains (meshes, triangles, materials, lights, camera, warnings).
    Info {
        /// A .gltf or .glb file.
        scene: PathBuf,
    },
    /// Measure the integrators: relMSE, bias and time against converged references, a
    /// light-size sweep, plots and a report (docs/study.md shows a run).
    Study(StudyArgs),
    /// A long-lived renderer for Blender's interactive viewport: commands on stdin, progressive
    /// images on stdout (docs/session.md). Exits 0 when stdin ends.
    Session {
        /// Worker threads (0 = one per core).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// The Open Image Denoise library (libOpenImageDenoise.so or its folder), for the
        /// viewport denoiser.
        #[arg(long, value_name = "PATH")]
        oidn_lib: Option<PathBuf>,
    },
    /// Merge the accumulators of sample-range parts (`render --sample-range A:B
    /// --accumulators PART.exr`) into the image of the whole render.
    Merge(MergeArgs),
    /// Write a built-in scene as a .gltf file (how scenes/*.gltf are made).
    ExportBuiltin {
        /// One of: cornell-box, cornell-spheres, glass-pane.
        name: String,
        /// Output .gltf path (buffers are embedded as data URIs).
        out: PathBuf,
    },
}

#[derive(clap::Args)]
struct RenderArgs {
    /// The scene: a .gltf or .glb file. Without it, the built-in Cornell box is rendered.
    scene: Option<PathBuf>,
    /// Render a built-in scene instead of a file: cornell-box, cornell-spheres, glass-pane.
    #[arg(long, conflicts_with = "scene")]
    builtin: Option<String>,
    /// Output image; the extension picks the format: .exr (linear float RGBA) or .png (sRGB).
    /// Default: tesela.png (no file in --pipe mode unless given).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Integrator: direct_ems, direct_mats, direct_mis, path_mats, path_mis, normals, albedo,
    /// or direct_ems_first_hit (emitter sampling at the first hit only: mirrors and glass show
    /// black, as in the assignment's own direct_ems; direct_ems follows their delta chains).
    /// Default: the scene's TESELA_render setting, else path_mis.
    #[arg(long)]
    integrator: Option<String>,
    /// Samples per pixel. Default: the scene's setting, else 64.
    #[arg(long)]
    spp: Option<u32>,
    /// Maximum path depth in vertices (Mitsuba's convention): 1 = emitters seen directly,
    /// 2 = direct illumination; Cycles' max_bounces b is depth b + 2. Default 16.
    #[arg(long)]
    max_depth: Option<u32>,
    /// Image width in pixels. Default: the scene's setting, else 512.
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels. Default: the scene's setting, else from the camera's aspect ratio.
    #[arg(long)]
    height: Option<u32>,
    /// Seed of the per-pixel random streams (same seed, same image, any thread count).
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads (0 = one per core).
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// How a light is chosen for each shadow ray: power (proportional to emitted power; with 8
    /// or more lights at finite positions through a light tree that also weighs their distance
    /// and orientation), flat (proportional to power, no tree) or uniform (the seed's choice).
    #[arg(long, default_value = "power", value_parser = ["power", "flat", "uniform"])]
    light_choice: String,
    /// Render only the window X Y W H of the full frame (pixels, top-left origin).
    #[arg(long, num_args = 4, value_names = ["X", "Y", "W", "H"])]
    region: Option<Vec<u32>>,
    /// Tile edge in pixels.
    #[arg(long, default_value_t = 32)]
    tile_size: u32,
    /// A mesh placed several times is baked into world space while its copies together have at
    /// most this many triangles, else instanced (0: instance every repeated mesh). A tuning
    /// knob (bench/bake_limit.py measures it); the default is the measured break-even.
    #[arg(long, default_value_t = scene::gltf::LoadOptions::default().bake_triangles)]
    bake_triangles: usize,
    /// Stream binary frames on stdout for the Blender add-on (docs/protocol.md); stops when
    /// stdin closes.
    #[arg(long)]
    pipe: bool,
    /// No progress bar or summary.
    #[arg(short, long)]
    quiet: bool,
    /// Light the scene with an equirectangular environment image (.exr or .hdr), replacing
    /// its world. Oriented as Cycles orients it in Blender's Z-up world: the image's centre
    /// column looks along +X, its left quarter along +Y, its top row straight up.
    #[arg(long, value_name = "FILE", conflicts_with = "background")]
    env: Option<PathBuf>,
    /// Multiplies the environment's radiance (the Background node's strength). Default 1.
    #[arg(long, value_name = "S", requires = "env", allow_hyphen_values = true)]
    env_strength: Option<f32>,
    /// Turns the environment about the vertical axis by DEG degrees (the Z rotation of a
    /// Mapping node between Texture Coordinate and the Environment Texture, as in Blender).
    #[arg(long, value_name = "DEG", requires = "env", allow_hyphen_values = true)]
    env_rotation: Option<f32>,
    /// Auxiliary passes, comma-separated: depth, mist, normal, position, uv, object_index,
    /// material_index, emission, environment, denoising_normal, denoising_albedo,
    /// diffuse_direct, diffuse_indirect, diffuse_color, glossy_direct, glossy_indirect,
    /// glossy_color, transmission_direct, transmission_indirect, transmission_color (direct
    /// and indirect divided by colour, as Cycles shows them; not with the normals and albedo
    /// views), noisy_image (Combined before --denoise) (Cycles' passes of those names).
    /// An .exr output becomes multi-layer with Blender's layer and
    /// channel names (ViewLayer.Depth.Z, ...); with --pipe they travel in the tiles
    /// (protocol version 2).
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    passes: Vec<String>,
    /// Adaptive sampling with noise threshold T (Cycles' "Noise Threshold"; 0 = automatic):
    /// each pixel stops once its noise estimate falls below T, up to --spp samples.
    #[arg(long, value_name = "T", allow_hyphen_values = true)]
    adaptive_threshold: Option<f32>,
    /// Samples every pixel takes before adaptive sampling may stop it (0 = automatic).
    #[arg(long, value_name = "N", requires = "adaptive_threshold")]
    adaptive_min_samples: Option<u32>,
    /// Stop after the sample round that passes S seconds of rendering (0 = no limit).
    #[arg(long, value_name = "S", allow_hyphen_values = true)]
    time_limit: Option<f64>,
    /// Denoise the final image with Intel Open Image Denoise, guided by the albedo and normal
    /// of the first surfaces (rendered for it). Without the library: a warning, and the image
    /// stays as rendered.
    #[arg(long)]
    denoise: bool,
    /// How the denoiser treats its albedo and normal guides: accurate (denoises them first,
    /// Cycles' default) or fast / none (uses them as rendered).
    #[arg(long, default_value = "accurate", value_parser = ["accurate", "fast", "none"])]
    denoise_prefilter: String,
    /// The Open Image Denoise library (libOpenImageDenoise.so or its folder). Default: the
    /// environment variable TESELA_OIDN_LIB, then beside the executable (and ../lib), then a
    /// Python environment with pyoidn, then the system's library path.
    #[arg(long, value_name = "PATH")]
    oidn_lib: Option<PathBuf>,
    /// Most diffuse bounces (Cycles' diffuse_bounces); default: no limit besides --max-depth.
    #[arg(long, value_name = "N")]
    diffuse_bounces: Option<u32>,
    /// Most glossy bounces (Cycles' glossy_bounces).
    #[arg(long, value_name = "N")]
    glossy_bounces: Option<u32>,
    /// Most transmission bounces (Cycles' transmission_bounces).
    #[arg(long, value_name = "N")]
    transmission_bounces: Option<u32>,
    /// Most volume scatter bounces (Cycles' volume_bounces; the add-on passes Blender's
    /// setting, whose default is 0: single scattering).
    #[arg(long, value_name = "N")]
    volume_bounces: Option<u32>,
    /// Most transparent surfaces a path passes straight through (Cycles'
    /// transparent_max_bounces): the next surface ends it; shadow rays get what it has left.
    #[arg(long, default_value_t = 8, value_name = "N")]
    transparent_bounces: u32,
    /// Clamp direct light: a sample's |R|+|G|+|B| above this is scaled down to it (Cycles'
    /// sample_clamp_direct; 0 = off). Path integrators.
    #[arg(long, default_value_t = 0.0, value_name = "C")]
    clamp_direct: f32,
    /// Clamp indirect light (Cycles' sample_clamp_indirect; 0 = off). Path integrators.
    #[arg(long, default_value_t = 0.0, value_name = "C")]
    clamp_indirect: f32,
    /// No reflective caustics (Cycles' caustics_reflective off): rays leaving a diffuse
    /// bounce meet no glossy reflection. Path integrators.
    #[arg(long)]
    no_caustics_reflective: bool,
    /// No refractive caustics (Cycles' caustics_refractive off): rays leaving a diffuse
    /// bounce meet no refraction. Path integrators.
    #[arg(long)]
    no_caustics_refractive: bool,
    /// Filter Glossy (Cycles' blur_glossy; 0 = off): after bounces sampled with a density
    /// below B per steradian, glossy lobes are blurred. Path integrators.
    #[arg(long, default_value_t = 0.0, value_name = "B")]
    blur_glossy: f32,
    /// Pixel filter (Cycles' pixel_filter_type): box, gaussian or blackman-harris.
    #[arg(long, default_value = "box", value_parser = ["box", "gaussian", "blackman-harris"])]
    filter: String,
    /// Pixel filter width in pixels (Cycles' filter_width; Cycles' default is Blackman-Harris
    /// 1.5, which spans 3 pixels).
    #[arg(long, default_value_t = 1.0, value_name = "W")]
    filter_width: f32,
    /// The pipe protocol version to speak with --pipe (1 or 2; docs/protocol.md).
    #[arg(long, default_value_t = 1, value_name = "N")]
    pipe_version: u32,
    /// A constant world of linear RGB radiance R G B, replacing the scene's world.
    #[arg(long, num_args = 3, value_names = ["R", "G", "B"])]
    background: Option<Vec<f32>>,
    /// Render only samples [A, B) of every pixel (of the --spp of the whole render), with the
    /// random streams the whole render gives them, so parts rendered on several machines
    /// merge exactly (`tesela merge`). Not with adaptive sampling, a time limit or --denoise.
    #[arg(long, value_name = "A:B", value_parser = parse_sample_range, conflicts_with = "pipe")]
    sample_range: Option<std::ops::Range<u32>>,
    /// Write the film's unnormalised sums (radiance, coverage, sample counts, raw pass
    /// records) to this OpenEXR file for `tesela merge` (docs/farm.md describes it). An
    /// image is then written only if --output is given.
    #[arg(long, value_name = "FILE", conflicts_with = "pipe")]
    accumulators: Option<PathBuf>,
}

/// `A:B` with `A < B`: a range of sample indices.
fn parse_sample_range(s: &str) -> Result<std::ops::Range<u32>, String> {
    let bad = || format!("`{s}` is not a sample range A:B (0 <= A < B, e.g. 0:64)");
    let (a, b) = s.split_once(':').ok_or_else(bad)?;
    let (a, b): (u32, u32) = (
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    );
    if a >= b {
        return Err(bad());
    }
    Ok(a..b)
}

#[derive(clap::Args)]
struct MergeArgs {
    /// Accumulator files of one render (any order); their sample ranges must cover [0, spp).
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// Output image: .exr (multi-layer with the parts' passes) or .png.
    #[arg(short, long)]
    output: PathBuf,
    /// Passes to write, comma-separated (default: every pass the parts hold).
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    passes: Option<Vec<String>>,
    /// Denoise the merged image with Open Image Denoise (guided by the parts'
    /// denoising_albedo and denoising_normal passes, if they have them).
    #[arg(long)]
    denoise: bool,
    /// As `render --denoise-prefilter`.
    #[arg(long, default_value = "accurate", value_parser = ["accurate", "fast", "none"])]
    denoise_prefilter: String,
    /// As `render --oidn-lib`.
    #[arg(long, value_name = "PATH")]
    oidn_lib: Option<PathBuf>,
    /// No summary.
    #[arg(short, long)]
    quiet: bool,
}

#[derive(clap::Args)]
struct StudyArgs {
    /// Scenes: built-in names (cornell-box, cornell-spheres, glass-pane) or .gltf/.glb files.
    /// Default: the three built-in figure scenes.
    scenes: Vec<String>,
    /// Folder for study.json, study.md and the figures (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// The spp ladder is 1, 2, 4, ... up to N.
    #[arg(long, default_value_t = 64)]
    spp_max: u32,
    /// Independent seeds per rung of the ladder.
    #[arg(long, default_value_t = 4)]
    seeds: u32,
    /// Comma-separated integrators measured on every scene. Default: direct_ems,
    /// direct_mats, direct_mis, and where a scene has mirrors or glass also
    /// direct_ems_first_hit, path_mats, path_mis.
    #[arg(long, value_delimiter = ',')]
    integrators: Option<Vec<String>>,
    /// Image width in pixels (the height follows the camera's aspect ratio).
    #[arg(long, default_value_t = 64)]
    width: u32,
    /// Samples per pixel of each of the reference's renders.
    #[arg(long, default_value_t = 1024)]
    reference_spp: u32,
    /// Independent renders averaged into each reference (at least 2).
    #[arg(long, default_value_t = 4)]
    reference_seeds: u32,
    /// Samples per pixel of the light-size sweep's renders.
    #[arg(long, default_value_t = 16)]
    sweep_spp: u32,
    /// Skip the light-size sweep.
    #[arg(long)]
    no_sweep: bool,
    /// The rung of the ladder shown in the image strips (else the largest rung below it).
    #[arg(long, default_value_t = 16)]
    strip_spp: u32,
    /// Random numbers: independent (plain Monte Carlo, whose error falls as 1/N; the
    /// assignment's) or sobol (Tesela's stratified samples, as `tesela render` uses).
    #[arg(long, default_value = "independent", value_parser = ["independent", "sobol"])]
    sampler: String,
    /// Worker threads per render (0 = one per core).
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// No progress bar.
    #[arg(short, long)]
    quiet: bool,
}

fn run_study(args: &StudyArgs) -> ExitCode {
    use tesela::study::{self, StudyConfig, StudyScene};
    let mut config = StudyConfig::default_with(args.spp_max, args.seeds);
    if !args.scenes.is_empty() {
        let mut scenes = Vec::new();
        for s in &args.scenes {
            let found = match StudyScene::builtin(s) {
                Some(b) => Ok(b),
                None => scene::gltf::load(Path::new(s))
                    .map(|sc| {
                        let name = Path::new(s)
                            .file_stem()
                            .map_or(s.clone(), |n| n.to_string_lossy().into_owned());
                        StudyScene::new(&name, sc)
                    })
                    .map_err(|e| e.to_string()),
            };
            match found {
                Ok(sc) => scenes.push(sc),
                Err(e) => {
                    eprintln!("tesela: error: {e}");
                    return ExitCode::from(EXIT_LOAD);
                }
            }
        }
        config.scenes = scenes;
    }
    if let Some(list) = &args.integrators {
        for s in &mut config.scenes {
            s.integrators = list.clone();
        }
    }
    config.width = args.width;
    config.reference_spp = args.reference_spp;
    config.reference_seeds = args.reference_seeds;
    config.threads = args.threads;
    config.strip_spp = args.strip_spp;
    if args.sampler == "sobol" {
        config.sampling = render::Sampling::Sobol;
    }
    if args.no_sweep {
        config.sweep = None;
    } else if let Some(sw) = &mut config.sweep {
        sw.spp = args.sweep_spp;
    }
    if config.width == 0 || config.width > 4096 {
        eprintln!(
            "tesela: error: --width {} must be in 1..=4096",
            config.width
        );
        return ExitCode::from(EXIT_USAGE);
    }
    if let Err(e) = config.check() {
        eprintln!("tesela: error: {e}");
        return ExitCode::from(EXIT_USAGE);
    }
    // Before minutes of rendering: a folder that cannot be made fails now.
    if let Err(e) = std::fs::create_dir_all(&args.out) {
        eprintln!("tesela: error: {}: cannot create: {e}", args.out.display());
        return ExitCode::from(EXIT_USAGE);
    }
    let bar = if args.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        let b = indicatif::ProgressBar::new(1);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:40} {percent}% {msg} ({eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    };
    let outcome = match study::run(&config, &bar, &CANCEL) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("tesela: error: {e}");
            return ExitCode::from(EXIT_RENDER);
        }
    };
    match study::write(&args.out, &outcome) {
        Ok(files) => {
            if !args.quiet {
                eprintln!(
                    "tesela: study of {} renders in {:.1} s -> {} ({} files)",
                    outcome.study.measurements.len(),
                    outcome.study.settings.seconds,
                    args.out.display(),
                    files.len()
                );
                for c in &outcome.study.claims {
                    let v = match c.holds {
                        Some(true) => "supported",
                        Some(false) => "CONTRADICTED",
                        None => "not measured",
                    };
                    eprintln!("  {v}: {}", c.id);
                }
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("tesela: error: {e}");
            ExitCode::from(EXIT_RENDER)
        }
    }
}

extern "C" fn on_signal(_: libc::c_int) {
    CANCEL.store(true, Ordering::SeqCst);
}

fn install_signal_handlers() {
    let handler = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
    // SAFETY: the handler only stores to an atomic, which is async-signal-safe.
    unsafe {
        libc::signal(libc::SIGTERM, handler);
        libc::signal(libc::SIGINT, handler);
    }
}

/// After a cancel, give the workers a moment to stop cleanly, then exit regardless.
fn spawn_cancel_watchdog() {
    std::thread::spawn(|| {
        while !CANCEL.load(Ordering::SeqCst) {
            std::thread::sleep(Duration::from_millis(10));
        }
        std::thread::sleep(Duration::from_millis(250));
        // Not eprintln!: it panics when stderr's reader is gone (a killed Blender), and this
        // thread must reach the exit.
        let _ = writeln!(std::io::stderr(), "tesela: CANCELLED");
        std::process::exit(EXIT_CANCELLED as i32);
    });
}

/// Exit status: bad usage.
const EXIT_USAGE: u8 = 2;

/// Checks the world options' numbers (clap accepts NaN and negative values).
fn check_world_args(args: &RenderArgs) -> Result<(), String> {
    if let Some(s) = args.env_strength
        && !(s.is_finite() && s >= 0.0)
    {
        return Err(format!(
            "--env-strength {s}: the strength must be a finite number >= 0"
        ));
    }
    if let Some(r) = args.env_rotation
        && !r.is_finite()
    {
        return Err(format!(
            "--env-rotation {r}: the angle must be a finite number"
        ));
    }
    if let Some(c) = &args.background
        && c.iter().any(|v| !(v.is_finite() && *v >= 0.0))
    {
        return Err(format!(
            "--background {c:?}: the colour's components must be finite numbers >= 0"
        ));
    }
    Ok(())
}

/// Replaces the scene's world with `--env` / `--background`, if given.
fn apply_world_args(args: &RenderArgs, scene: &mut Scene) -> Result<(), String> {
    if let Some(c) = &args.background {
        scene.background = glam::Vec3::new(c[0], c[1], c[2]);
        scene.world = scene::World {
            name: "--background".into(),
            ..Default::default()
        };
    }
    if let Some(path) = &args.env {
        let (img, bad) = scene::world::read_environment_image(path)?;
        if bad > 0 {
            scene.warnings.push(format!(
                "{}: {bad} texel values are negative or not finite and read as 0",
                path.display()
            ));
        }
        scene.images.push(img);
        let image = scene.images.len() - 1;
        scene.background = glam::Vec3::ZERO;
        scene.world = scene::World {
            name: path.display().to_string(),
            graph: Some(scene::world::environment_graph(
                image,
                args.env_strength.unwrap_or(1.0),
                args.env_rotation.unwrap_or(0.0),
            )),
            ..Default::default()
        };
    }
    Ok(())
}

fn load_scene(args: &RenderArgs) -> Result<Scene, String> {
    let mut scene = load_scene_file(args)?;
    apply_world_args(args, &mut scene)?;
    Ok(scene)
}

fn load_scene_file(args: &RenderArgs) -> Result<Scene, String> {
    if let Some(name) = &args.builtin {
        return scene::builtin::by_name(name).ok_or_else(|| {
            format!(
                "unknown built-in scene `{name}` (choose one of {})",
                scene::builtin::NAMES.join(", ")
            )
        });
    }
    match &args.scene {
        Some(path) => {
            let options = scene::gltf::LoadOptions {
                bake_triangles: args.bake_triangles,
            };
            scene::gltf::load_with(path, &options).map_err(|e| e.to_string())
        }
        None => Ok(scene::builtin::cornell_box()),
    }
}

fn options(args: &RenderArgs, scene: &Scene) -> RenderOptions {
    let s = &scene.settings;
    let aspect = scene
        .camera
        .and_then(|c| c.aspect)
        .filter(|a| a.is_finite() && *a > 0.0);
    let width = args.width.or(s.width).unwrap_or(512);
    let height =
        args.height
            .or(s.height)
            .unwrap_or_else(|| match (args.width.or(s.width), aspect) {
                (_, Some(a)) => ((width as f32 / a).round() as u32).max(1),
                _ => width,
            });
    RenderOptions {
        width,
        height,
        spp: args.spp.or(s.spp).unwrap_or(64),
        max_depth: args.max_depth.or(s.max_depth).unwrap_or(16),
        seed: args.seed.or(s.seed).unwrap_or(0),
        integrator: args
            .integrator
            .clone()
            .or_else(|| s.integrator.clone())
            .unwrap_or_else(|| "path_mis".into()),
        threads: args.threads,
        tile_size: args.tile_size,
        region: args.region.as_ref().map(|r| [r[0], r[1], r[2], r[3]]),
        passes: tesela::film::PassSet::parse(args.passes.iter().map(String::as_str))
            .unwrap_or_default(),
        adaptive: args
            .adaptive_threshold
            .map(|threshold| tesela::film::Adaptive {
                threshold,
                min_samples: args.adaptive_min_samples.unwrap_or(0),
            }),
        time_limit: args.time_limit,
        light_paths: tesela::integrator::light_paths::LightPaths {
            diffuse: args.diffuse_bounces.unwrap_or(u32::MAX),
            glossy: args.glossy_bounces.unwrap_or(u32::MAX),
            transmission: args.transmission_bounces.unwrap_or(u32::MAX),
            volume: args.volume_bounces.unwrap_or(u32::MAX),
            transparent: args.transparent_bounces,
            clamp_direct: args.clamp_direct,
            clamp_indirect: args.clamp_indirect,
            caustics_reflective: !args.no_caustics_reflective,
            caustics_refractive: !args.no_caustics_refractive,
            filter_glossy: tesela::integrator::filter_glossy::FilterGlossy::new(args.blur_glossy),
        },
        filter: tesela::film::PixelFilter::new(
            match args.filter.as_str() {
                "gaussian" => tesela::film::FilterType::Gaussian,
                "blackman-harris" => tesela::film::FilterType::BlackmanHarris,
                _ => tesela::film::FilterType::Box,
            },
            args.filter_width,
        ),
    }
}

/// Loads the denoiser when `--denoise` asks for it and adds the guide passes it needs to
/// `opts`. A library that cannot be used is a warning (returned), not an error: the render
/// goes on without denoising.
fn setup_denoiser(
    args: &RenderArgs,
    opts: &mut RenderOptions,
) -> (Option<tesela::denoise::Denoiser>, Option<String>) {
    if !args.denoise {
        return (None, None);
    }
    match tesela::denoise::Denoiser::load(args.oidn_lib.as_deref(), opts.threads) {
        Ok(d) => {
            use tesela::film::{Pass, PassSet};
            let old = opts.passes.clone();
            opts.passes = PassSet::new(Pass::ALL.into_iter().filter(|&p| {
                old.contains(p) || p == Pass::DenoisingAlbedo || p == Pass::DenoisingNormal
            }));
            (Some(d), None)
        }
        Err(e) => (None, Some(format!("{e}; rendering without denoising"))),
    }
}

/// Denoises the finished image and drops the guide passes nobody asked for. Returns what to
/// tell the user: the denoiser used, or why the image stays noisy.
fn finish_denoise(
    args: &RenderArgs,
    image: &mut render::Image,
    denoiser: Option<&tesela::denoise::Denoiser>,
) -> Option<Result<String, String>> {
    let d = denoiser?;
    let result = image
        .denoise(d, args.denoise_prefilter == "accurate")
        .map(|_| format!("denoised with {}", d.describe()))
        .map_err(|e| format!("{e}; the image is not denoised"));
    let asked =
        tesela::film::PassSet::parse(args.passes.iter().map(String::as_str)).unwrap_or_default();
    image.retain_passes(&asked);
    Some(result)
}

/// Checks the film options clap cannot (pass names).
fn check_film_args(args: &RenderArgs) -> Result<(), String> {
    for (name, v) in [
        ("--clamp-direct", args.clamp_direct),
        ("--clamp-indirect", args.clamp_indirect),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(format!(
                "{name} {v}: the clamp must be a number >= 0 (0 = off)"
            ));
        }
    }
    if !(args.blur_glossy.is_finite() && args.blur_glossy >= 0.0) {
        return Err(format!(
            "--blur-glossy {}: Filter Glossy must be a number >= 0 (0 = off)",
            args.blur_glossy
        ));
    }
    if !(args.filter_width.is_finite() && (0.01..=10.0).contains(&args.filter_width)) {
        return Err(format!(
            "--filter-width {}: the width must be between 0.01 and 10 pixels",
            args.filter_width
        ));
    }
    tesela::film::PassSet::parse(args.passes.iter().map(String::as_str))
        .map(|_| ())
        .map_err(|e| format!("--passes: {e}"))
}

/// One tile as protocol frames carry it: RGBA only (version 1), or RGBA and then each pass
/// in turn (version 2).
/// `layout` is how the tile's records are laid out, `send` the passes to send.
fn tile_data(
    t: &render::Tile,
    layout: &tesela::film::PassSet,
    send: &tesela::film::PassSet,
    version: u32,
) -> Vec<f32> {
    let mut data: Vec<f32> = t.pixels.iter().flatten().copied().collect();
    if version >= 2 {
        let stride = layout.stride();
        for (pass, _) in send.iter() {
            let (Some(at), k) = (layout.offset(pass), pass.channels()) else {
                continue;
            };
            for r in t.aovs.chunks_exact(stride.max(1)) {
                data.extend_from_slice(&r[at..at + k]);
            }
        }
    }
    data
}

/// Pipe mode: frames on stdout, stop when stdin closes.
fn run_pipe(args: &RenderArgs) -> ExitCode {
    std::thread::spawn(|| {
        let mut buf = [0u8; 256];
        let mut stdin = std::io::stdin();
        loop {
            match stdin.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(_) => {}
            }
        }
        CANCEL.store(true, Ordering::SeqCst);
    });
    let out = Mutex::new(BufWriter::with_capacity(1 << 20, std::io::stdout()));
    let send = |m: &Message| {
        let mut o = out.lock().unwrap_or_else(|e| e.into_inner());
        // A closed stdout means the reader is gone: stop.
        if protocol::write(&mut *o, m).and_then(|_| o.flush()).is_err() {
            CANCEL.store(true, Ordering::SeqCst);
        }
    };
    let version = args.pipe_version;
    if version != protocol::VERSION && version != protocol::VERSION_1 {
        let e = format!(
            "protocol version mismatch: the add-on asks for version {version}, this renderer speaks {} and {}",
            protocol::VERSION_1,
            protocol::VERSION
        );
        eprintln!("tesela: error: {e}");
        send(&Message::Error(e));
        return ExitCode::from(EXIT_USAGE);
    }
    if let Err(e) = check_world_args(args).and_then(|_| check_film_args(args)) {
        eprintln!("tesela: error: {e}");
        send(&Message::Error(e));
        return ExitCode::from(EXIT_USAGE);
    }
    if version < 2 && !args.passes.is_empty() {
        let e = "--passes needs --pipe-version 2 (version 1 tiles carry RGBA only)".to_string();
        eprintln!("tesela: error: {e}");
        send(&Message::Error(e));
        return ExitCode::from(EXIT_USAGE);
    }
    let load_start = std::time::Instant::now();
    let scene = match load_scene(args) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("tesela: {e}");
            send(&Message::Error(e));
            return ExitCode::from(EXIT_LOAD);
        }
    };
    let load_seconds = load_start.elapsed().as_secs_f64();
    let mut opts = options(args, &scene);
    if let Err(e) = render::validate(&opts) {
        send(&Message::Error(e.to_string()));
        return ExitCode::from(EXIT_RENDER);
    }
    let (denoiser, denoise_warning) = setup_denoiser(args, &mut opts);
    // What the tiles carry: the passes asked for (the denoiser's guides stay internal).
    let tile_passes =
        tesela::film::PassSet::parse(args.passes.iter().map(String::as_str)).unwrap_or_default();
    let bvh_start = std::time::Instant::now();
    let rscene = prepare(scene, light_choice(args), opts.threads);
    let bvh_seconds = bvh_start.elapsed().as_secs_f64();
    let [_, _, rw, rh] = opts.region.unwrap_or([0, 0, opts.width, opts.height]);
    let ts = opts.tile_size.max(1);
    let mut passes = Vec::new();
    if version >= 2 {
        passes.push(("Combined".to_string(), "RGBA".to_string()));
        for (p, _) in tile_passes.iter() {
            passes.push((p.blender_name().to_string(), p.channel_ids().to_string()));
        }
    }
    send(&Message::Hello {
        version,
        width: rw,
        height: rh,
        spp: opts.spp,
        tile_count: rw.div_ceil(ts) * rh.div_ceil(ts),
        passes,
    });
    let subsurface = tesela::integrator::limitations(&opts.integrator, &rscene);
    for w in (rscene.scene.warnings.iter())
        .chain(&denoise_warning)
        .chain(&subsurface)
    {
        send(&Message::Log {
            level: 2,
            message: w.clone(),
        });
    }
    if rscene.triangle_count() == 0 {
        send(&Message::Log {
            level: 2,
            message: "the scene has no triangles: the image shows only the background".into(),
        });
    }
    let start = std::time::Instant::now();
    // Nanoseconds spent packing tiles and writing them into the pipe (waiting for the reader
    // included), summed over the worker threads.
    let stream_nanos = AtomicU64::new(0);
    let send_tile = |t: &render::Tile, passes: &tesela::film::PassSet| {
        let t0 = std::time::Instant::now();
        send(&Message::Tile {
            x: t.x,
            y: t.y,
            w: t.w,
            h: t.h,
            data: tile_data(t, passes, &tile_passes, version),
        });
        let nanos = u64::try_from(t0.elapsed().as_nanos()).unwrap_or(u64::MAX);
        stream_nanos.fetch_add(nanos, Ordering::Relaxed);
    };
    let on_tile = |t: &render::Tile, done: usize, total: usize| {
        send_tile(t, &opts.passes);
        send(&Message::Progress {
            tiles_done: done as u32,
            tiles_total: total as u32,
            spp: t.spp,
            elapsed: start.elapsed().as_secs_f64(),
        });
    };
    match render::render(&rscene, &opts, &CANCEL, &on_tile) {
        Ok((mut image, stats)) => {
            match finish_denoise(args, &mut image, denoiser.as_ref()) {
                Some(Ok(m)) => {
                    send(&Message::Log {
                        level: 1,
                        message: m,
                    });
                    for t in image.tiles(ts) {
                        send_tile(&t, &image.passes);
                    }
                }
                Some(Err(m)) => send(&Message::Log {
                    level: 2,
                    message: m,
                }),
                None => {}
            }
            if let Some(path) = &args.output
                && let Err(e) = tesela::output::write(&image, path)
            {
                send(&Message::Error(e));
                return ExitCode::from(EXIT_RENDER);
            }
            let mut done = serde_json::to_value(&stats).unwrap_or_default();
            if let Some(fields) = done.as_object_mut() {
                // Where the time went besides the render itself (`seconds`).
                let stream = stream_nanos.load(Ordering::Relaxed) as f64 * 1e-9;
                fields.insert("load_seconds".into(), load_seconds.into());
                fields.insert("bvh_seconds".into(), bvh_seconds.into());
                fields.insert("stream_seconds".into(), stream.into());
            }
            send(&Message::Done(done.to_string()));
            ExitCode::SUCCESS
        }
        Err(RenderError::Cancelled) => {
            let _ = writeln!(std::io::stderr(), "tesela: CANCELLED");
            ExitCode::from(EXIT_CANCELLED)
        }
        Err(e) => {
            send(&Message::Error(e.to_string()));
            ExitCode::from(EXIT_RENDER)
        }
    }
}

/// Builds the BVH and the emitters on `threads` worker threads (0 = one per core), the count
/// the render itself is given.
fn prepare(scene: tesela::scene::Scene, choice: LightChoice, threads: usize) -> RenderScene {
    match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(pool) => pool.install(|| RenderScene::new(scene, choice)),
        Err(_) => RenderScene::new(scene, choice),
    }
}

fn light_choice(args: &RenderArgs) -> LightChoice {
    match args.light_choice.as_str() {
        "uniform" => LightChoice::Uniform,
        "flat" => LightChoice::Flat,
        _ => LightChoice::Power,
    }
}

fn run_render(args: &RenderArgs) -> ExitCode {
    if let Err(e) = check_world_args(args)
        .and_then(|_| check_film_args(args))
        .and_then(|_| check_split_args(args))
    {
        eprintln!("tesela: error: {e}");
        return ExitCode::from(EXIT_USAGE);
    }
    let scene = match load_scene(args) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("tesela: error: {e}");
            return ExitCode::from(EXIT_LOAD);
        }
    };
    let mut opts = options(args, &scene);
    if let Err(e) = render::validate(&opts) {
        eprintln!("tesela: error: {e}");
        return ExitCode::from(EXIT_RENDER);
    }
    let split = split_range(args, &opts);
    if let Some(r) = &split {
        let why = render::unsplittable(&opts).map(|w| format!("{w} cannot be split exactly"));
        if let Some(e) = why.or_else(|| {
            (r.end > opts.spp).then(|| {
                format!(
                    "sample range {}:{} is outside the render's {} samples",
                    r.start, r.end, opts.spp
                )
            })
        }) {
            eprintln!("tesela: error: --sample-range/--accumulators: {e}");
            return ExitCode::from(EXIT_USAGE);
        }
    }
    let (denoiser, denoise_warning) = setup_denoiser(args, &mut opts);
    if let Some(w) = &denoise_warning {
        eprintln!("tesela: warning: {w}");
    }
    // With --accumulators the sums are the result: an image only if asked for.
    let output = match (&args.output, &args.accumulators) {
        (Some(o), _) => Some(o.clone()),
        (None, None) => Some(PathBuf::from("tesela.png")),
        (None, Some(_)) => None,
    };
    for path in output.iter().chain(&args.accumulators) {
        if let Err(e) = check_output(path) {
            eprintln!("tesela: error: {e}");
            return ExitCode::from(EXIT_RENDER);
        }
    }
    if let Some(a) = &args.accumulators
        && !a.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        eprintln!(
            "tesela: error: {}: accumulators are written as OpenEXR (use a .exr file name)",
            a.display()
        );
        return ExitCode::from(EXIT_USAGE);
    }
    let key = split.as_ref().map(|_| render_key(args, &opts));
    let build = std::time::Instant::now();
    let rscene = prepare(scene, light_choice(args), opts.threads);
    let subsurface = tesela::integrator::limitations(&opts.integrator, &rscene);
    for w in rscene.scene.warnings.iter().chain(&subsurface) {
        eprintln!("tesela: warning: {w}");
    }
    if rscene.triangle_count() == 0 {
        // Not an error: the image shows the background, as Blender shows an empty scene.
        eprintln!(
            "tesela: warning: the scene has no triangles: the image shows only the background"
        );
    }
    if rscene.emitters.is_empty() && rscene.triangle_count() > 0 {
        // Files made for real-time viewers often carry no light: their viewers add one.
        eprintln!(
            "tesela: warning: the scene has no light (no lights, emissive surfaces or world): it renders black; --background R G B or --env FILE gives it a world"
        );
    }
    let build_s = build.elapsed().as_secs_f64();
    let bar = if args.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        let b = indicatif::ProgressBar::new(1);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} tiles ({eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    };
    let on_tile = |_: &render::Tile, done: usize, total: usize| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    };
    let result = match &split {
        None => render::render(&rscene, &opts, &CANCEL, &on_tile).map(|(i, s)| (i, s, None)),
        Some(r) => render::render_range(&rscene, &opts, r.clone(), &CANCEL, &on_tile).map(
            |(mut film, s)| {
                film.key = key.clone().unwrap_or_default();
                let mut image = film.resolve();
                // The film also summed the Color passes its light passes are divided by.
                image.retain_passes(&opts.passes);
                (image, s, Some(film))
            },
        ),
    };
    bar.finish_and_clear();
    match result {
        Ok((mut image, stats, film)) => {
            match finish_denoise(args, &mut image, denoiser.as_ref()) {
                Some(Ok(m)) if !args.quiet => eprintln!("tesela: {m}"),
                Some(Err(m)) => eprintln!("tesela: warning: {m}"),
                _ => {}
            }
            if let (Some(film), Some(path)) = (&film, &args.accumulators)
                && let Err(e) = tesela::film::accumulators::write(film, path)
            {
                eprintln!("tesela: error: {e}");
                return ExitCode::from(EXIT_RENDER);
            }
            if let Some(output) = &output
                && let Err(e) = tesela::output::write(&image, output)
            {
                eprintln!("tesela: error: {e}");
                return ExitCode::from(EXIT_RENDER);
            }
            let output = output
                .as_ref()
                .or(args.accumulators.as_ref())
                .map_or(String::new(), |p| p.display().to_string());
            if !args.quiet {
                eprintln!(
                    "tesela: {}x{} {} spp {} -> {} in {:.2} s (+{:.2} s BVH): {:.2} M samples/s, {:.2} M rays/s, {} triangles{}",
                    image.width,
                    image.height,
                    split.as_ref().map_or(opts.spp.to_string(), |r| format!(
                        "samples {}:{} of {}",
                        r.start, r.end, opts.spp
                    )),
                    opts.integrator,
                    output,
                    stats.seconds,
                    build_s,
                    stats.samples_per_second / 1e6,
                    stats.rays_per_second / 1e6,
                    rscene.triangle_count(),
                    if stats.rejected_samples > 0 {
                        format!(", {} non-finite samples rejected", stats.rejected_samples)
                    } else {
                        String::new()
                    }
                );
                if opts.adaptive.is_some() || opts.time_limit.is_some_and(|t| t > 0.0) {
                    eprintln!(
                        "tesela: samples per pixel reached: {} to {} (mean {:.1}) in {} rounds; noise level {:.4}",
                        stats.spp_min, stats.spp_max, stats.spp_mean, stats.rounds, stats.noise
                    );
                }
            }
            ExitCode::SUCCESS
        }
        Err(RenderError::Cancelled) => {
            eprintln!("tesela: cancelled");
            ExitCode::from(EXIT_CANCELLED)
        }
        Err(e) => {
            eprintln!("tesela: error: {e}");
            ExitCode::from(EXIT_RENDER)
        }
    }
}

/// Refuses an output path whose format is unknown, or whose folder does not exist, before
/// spending time on the render.
fn check_output(path: &Path) -> Result<(), String> {
    if let Some(dir) = path.parent()
        && !dir.as_os_str().is_empty()
        && !dir.is_dir()
    {
        return Err(format!(
            "{}: the output folder {} does not exist",
            path.display(),
            dir.display()
        ));
    }
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
    {
        Some(e) if e == "png" || e == "exr" => Ok(()),
        _ => Err(format!(
            "{}: unknown output format (use a .exr or .png file name)",
            path.display()
        )),
    }
}

fn run_info(path: &Path) -> ExitCode {
    match scene::gltf::load(path) {
        Ok(s) => {
            println!("{}", path.display());
            println!(
                "  meshes: {}, triangles: {}, instances: {}, triangles placed: {}",
                s.meshes.len(),
                s.triangle_count(),
                s.instances.len(),
                s.instanced_triangle_count()
            );
            println!("  materials: {}", s.materials.len());
            for m in &s.materials {
                println!(
                    "    {}: base {:?} metallic {} roughness {} emission {:?} transmission {} ior {} specular {}",
                    m.name,
                    m.base_color,
                    m.metallic,
                    m.roughness,
                    m.emission,
                    m.transmission,
                    m.ior,
                    m.specular
                );
            }
            println!("  lights: {}", s.lights.len());
            for l in &s.lights {
                println!("    {l:?}");
            }
            match &s.camera {
                Some(c) => println!("  camera: {:?}", c.projection),
                None => println!("  camera: none (a default camera frames the scene)"),
            }
            if let Some((lo, hi)) = s.bounds() {
                println!("  bounds: {lo:?} .. {hi:?}");
            }
            println!("  background: {:?}", s.background);
            let w = &s.world;
            if w.graph.is_some() || !w.visible_camera {
                println!(
                    "  world '{}': {}, sampling {:?}{}",
                    w.name,
                    match &w.graph {
                        Some(g) => format!("node graph of {} nodes", g.nodes.len()),
                        None => "constant colour".into(),
                    },
                    w.sampling,
                    if w.visible_camera {
                        ""
                    } else {
                        ", hidden from the camera"
                    }
                );
            }
            if s.settings.film_transparent {
                match s.settings.film_transparent_glass {
                    Some(t) => {
                        println!("  film: transparent, transparent glass (roughness <= {t})")
                    }
                    None => println!("  film: transparent"),
                }
            }
            for w in &s.warnings {
                println!("  warning: {w}");
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("tesela: error: {e}");
            ExitCode::from(EXIT_LOAD)
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    install_signal_handlers();
    if let Command::Session { threads, oidn_lib } = &cli.command {
        if *threads > render::MAX_THREADS {
            eprintln!(
                "tesela: error: --threads {threads} is too many (at most {})",
                render::MAX_THREADS
            );
            return ExitCode::from(EXIT_USAGE);
        }
        let opts = tesela::session::SessionOptions {
            threads: *threads,
            oidn_lib: oidn_lib.clone(),
        };
        let code = tesela::session::run(&opts, std::io::stdin(), std::io::stdout(), &CANCEL);
        return ExitCode::from(code as u8);
    }
    spawn_cancel_watchdog();
    match cli.command {
        Command::Render(args) => {
            if args.pipe {
                run_pipe(&args)
            } else {
                run_render(&args)
            }
        }
        Command::Info { scene } => run_info(&scene),
        Command::Session { .. } => ExitCode::SUCCESS,
        Command::Study(args) => run_study(&args),
        Command::Merge(args) => run_merge(&args),
        Command::ExportBuiltin { name, out } => match scene::builtin::by_name(&name) {
            Some(s) => match scene::gltf_write::write(&s, &out) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("tesela: error: {e}");
                    ExitCode::from(EXIT_RENDER)
                }
            },
            None => {
                eprintln!("tesela: error: unknown built-in scene `{name}`");
                ExitCode::from(EXIT_USAGE)
            }
        },
    }
}

/// The sample range a split render renders: `--sample-range`, or all samples when only
/// `--accumulators` is given; `None` for an ordinary render.
fn split_range(args: &RenderArgs, opts: &RenderOptions) -> Option<std::ops::Range<u32>> {
    match (&args.sample_range, &args.accumulators) {
        (Some(r), _) => Some(r.clone()),
        (None, Some(_)) => Some(0..opts.spp),
        (None, None) => None,
    }
}

/// Refuses the options a sample-range part cannot have before the scene is loaded.
fn check_split_args(args: &RenderArgs) -> Result<(), String> {
    if (args.sample_range.is_some() || args.accumulators.is_some()) && args.denoise {
        return Err(
            "--denoise on a sample-range part would denoise a noisier image than the \
             whole render's (and denoised images do not add up): render the parts without \
             it and denoise after merging (`tesela merge --denoise`)"
                .into(),
        );
    }
    Ok(())
}

/// FNV-1a, 64 bits: a stable fingerprint (the same on every machine and build).
fn fnv1a(bytes: &[u8], mut h: u64) -> u64 {
    for b in bytes {
        h ^= *b as u64;
        h = h.wrapping_mul(0x100_0000_01b3);
    }
    h
}

/// Names the render a part belongs to: the scene's bytes, the world options and every
/// render option but the sample range, thread count and tile size, hashed. Parts with
/// different keys do not merge.
fn render_key(args: &RenderArgs, opts: &RenderOptions) -> String {
    let scene = match (&args.builtin, &args.scene) {
        (Some(b), _) => fnv1a(b.as_bytes(), 0xcbf2_9ce4_8422_2325),
        (None, Some(p)) => fnv1a(&std::fs::read(p).unwrap_or_default(), 0xcbf2_9ce4_8422_2325),
        (None, None) => 0,
    };
    let env = args
        .env
        .as_ref()
        .map_or(0, |p| fnv1a(&std::fs::read(p).unwrap_or_default(), scene));
    let mut o = opts.clone();
    (o.threads, o.tile_size) = (0, 0);
    let settings = format!(
        "{o:?} {:?} {:?} {:?} {:?} {}",
        args.env_strength, args.env_rotation, args.background, args.light_choice, env
    );
    format!(
        "scene {scene:016x} options {:016x}",
        fnv1a(settings.as_bytes(), 0xcbf2_9ce4_8422_2325)
    )
}

/// `tesela merge`: adds the parts' sums, resolves, optionally denoises, writes the image.
fn run_merge(args: &MergeArgs) -> ExitCode {
    use tesela::film::accumulators;
    if let Err(e) = check_output(&args.output) {
        eprintln!("tesela: error: {e}");
        return ExitCode::from(EXIT_USAGE);
    }
    let keep = match &args.passes {
        Some(list) => match tesela::film::PassSet::parse(list.iter().map(String::as_str)) {
            Ok(p) => Some(p),
            Err(e) => {
                eprintln!("tesela: error: --passes: {e}");
                return ExitCode::from(EXIT_USAGE);
            }
        },
        None => None,
    };
    let mut parts = Vec::with_capacity(args.parts.len());
    for p in &args.parts {
        match accumulators::read(p) {
            Ok(a) => parts.push((p.display().to_string(), a)),
            Err(e) => {
                eprintln!("tesela: error: {e}");
                return ExitCode::from(EXIT_LOAD);
            }
        }
    }
    let film = match accumulators::Accumulators::merge(parts) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("tesela: error: cannot merge: {e}");
            return ExitCode::from(EXIT_USAGE);
        }
    };
    let mut image = film.resolve();
    if args.denoise {
        let done = tesela::denoise::Denoiser::load(args.oidn_lib.as_deref(), 0)
            .map_err(|e| e.to_string())
            .and_then(|d| {
                image
                    .denoise(&d, args.denoise_prefilter == "accurate")
                    .map(|_| d.describe())
                    .map_err(|e| e.to_string())
            });
        match done {
            Ok(d) if !args.quiet => eprintln!("tesela: denoised with {d}"),
            Ok(_) => {}
            Err(e) => eprintln!("tesela: warning: {e}; the image is not denoised"),
        }
    }
    if let Some(keep) = &keep {
        image.retain_passes(keep);
    }
    if let Err(e) = tesela::output::write(&image, &args.output) {
        eprintln!("tesela: error: {e}");
        return ExitCode::from(EXIT_RENDER);
    }
    if !args.quiet {
        eprintln!(
            "tesela: merged {} parts ({}x{}, {} spp) -> {}",
            args.parts.len(),
            image.width,
            image.height,
            film.spp,
            args.output.display()
        );
    }
    ExitCode::SUCCESS
}
