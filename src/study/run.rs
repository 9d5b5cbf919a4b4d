//! Running a study: references, the spp ladder of every integrator with independent seeds,
//! the light-size sweep, and the summaries of what was measured.

use super::metrics::{self, Estimate, SeedMoments};
use super::{Measurement, Reference, Settings, SppSummary, Study, Summary, SweepPoint};
use crate::camera::RayCamera;
use crate::emitter::LightChoice;
use crate::render::{self, RenderOptions, Sampling};
use crate::render_scene::{Ctx, RenderScene};
use crate::sampler::SobolSampler;
use crate::scene::{Scene, builtin};
use glam::Vec2;
use std::collections::BTreeMap;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// The scenes a default study measures: the seed's figures.
pub const DEFAULT_SCENES: [&str; 3] = ["cornell-box", "cornell-spheres", "glass-pane"];

/// The scene the light-size sweep varies.
pub const SWEEP_SCENE: &str = "cornell-box";

/// The region of a mirror's pixels that show an emitter (see [`mirror_emitter_region`]).
pub const MIRROR_REGION: &str = "emitter seen in a mirror";

/// A reference pixel brighter than this (sum of RGB) inside a mirror shows an emitter: far
/// above any lit diffuse surface of the shipped scenes (below 2), far below their lights
/// (above 10).
pub const MIRROR_REGION_THRESHOLD: f64 = 4.0;

/// One scene of a study and the integrators measured on it.
#[derive(Clone)]
pub struct StudyScene {
    pub name: String,
    pub scene: Scene,
    pub integrators: Vec<String>,
}

impl StudyScene {
    /// A built-in scene with [`default_integrators`].
    pub fn builtin(name: &str) -> Option<StudyScene> {
        builtin::by_name(name).map(|scene| StudyScene::new(name, scene))
    }

    /// `scene` with [`default_integrators`].
    pub fn new(name: &str, scene: Scene) -> StudyScene {
        StudyScene {
            name: name.into(),
            integrators: default_integrators(&scene),
            scene,
        }
    }
}

/// Does the scene have a delta (perfectly smooth mirror or glass) material?
fn has_delta_material(scene: &Scene) -> bool {
    scene
        .materials
        .iter()
        .any(|m| m.roughness == 0.0 && (m.metallic >= 1.0 || m.transmission > 0.0))
}

/// The three direct-illumination estimators everywhere; where the scene has mirrors or glass
/// (light reaches the eye through more than one bounce) also the first-hit-only emitter
/// sampling and the two path tracers.
pub fn default_integrators(scene: &Scene) -> Vec<String> {
    let mut v: Vec<String> = ["direct_ems", "direct_mats", "direct_mis"]
        .map(String::from)
        .to_vec();
    if has_delta_material(scene) {
        v.extend(["direct_ems_first_hit", "path_mats", "path_mis"].map(String::from));
    }
    v
}

/// The integrator whose converged render an integrator is compared with: path tracers
/// against `path_mis`, the direct-illumination estimators against `direct_mis`.
pub fn reference_for(integrator: &str) -> &'static str {
    if integrator.starts_with("path") {
        "path_mis"
    } else {
        "direct_mis"
    }
}

/// The light-size sweep: the diffuse box's light scaled by each of `area_scales` (same
/// power), `direct_ems` and `direct_mats` at `spp`.
#[derive(Clone, Debug)]
pub struct Sweep {
    pub area_scales: Vec<f64>,
    pub spp: u32,
}

/// What a study renders.
#[derive(Clone)]
pub struct StudyConfig {
    pub scenes: Vec<StudyScene>,
    /// Image width; the height follows the camera's aspect ratio (square without one).
    pub width: u32,
    /// The spp ladder.
    pub spp: Vec<u32>,
    /// Independent seeds per rung.
    pub seeds: u32,
    pub reference_spp: u32,
    /// Independent renders averaged into each reference (at least 2: their spread gives the
    /// reference's standard error).
    pub reference_seeds: u32,
    pub max_depth: u32,
    /// Worker threads per render (0 = one per core).
    pub threads: usize,
    pub sweep: Option<Sweep>,
    /// The rung whose first-seed images make the image strips (the largest rung at or below
    /// it when it is not on the ladder).
    pub strip_spp: u32,
    /// Independent samples (plain Monte Carlo, as the assignment's sampler) or Tesela's
    /// stratified Sobol samples.
    pub sampling: Sampling,
}

/// `1, 2, 4, …` up to `max` (inclusive when a power of two).
pub fn spp_ladder(max: u32) -> Vec<u32> {
    let mut v = vec![1];
    while v[v.len() - 1] * 2 <= max.max(1) {
        v.push(v[v.len() - 1] * 2);
    }
    v
}

impl StudyConfig {
    /// The default study: the seed's figure scenes at 64 pixels wide, spp 1…`spp_max`,
    /// `seeds` seeds, references of 4 × 1024 spp, the light-size sweep from 1/16 to 4 times
    /// the area at 16 spp, strips at 16 spp, independent samples.
    pub fn default_with(spp_max: u32, seeds: u32) -> StudyConfig {
        StudyConfig {
            scenes: DEFAULT_SCENES
                .iter()
                .filter_map(|n| StudyScene::builtin(n))
                .collect(),
            width: 64,
            spp: spp_ladder(spp_max),
            seeds,
            reference_spp: 1024,
            reference_seeds: 4,
            max_depth: 16,
            threads: 0,
            sweep: Some(Sweep {
                area_scales: vec![1.0 / 16.0, 1.0 / 8.0, 0.25, 0.5, 1.0, 2.0, 4.0],
                spp: 16,
            }),
            strip_spp: 16,
            sampling: Sampling::Independent,
        }
    }

    /// Refuses settings that cannot be measured (empty ladder, unknown integrator, ...).
    pub fn check(&self) -> Result<(), String> {
        if self.scenes.is_empty() {
            return Err("the study has no scenes".into());
        }
        if self.spp.is_empty() || self.spp.contains(&0) {
            return Err("the spp ladder must be non-empty and every rung at least 1".into());
        }
        if self.seeds == 0 {
            return Err("--seeds must be at least 1".into());
        }
        if self.reference_seeds < 2 || self.reference_spp == 0 {
            return Err("the reference needs at least 2 seeds of at least 1 spp".into());
        }
        for s in &self.scenes {
            if s.integrators.is_empty() {
                return Err(format!("scene {}: no integrators to measure", s.name));
            }
            for i in &s.integrators {
                if crate::integrator::by_name(i, 1).is_none() {
                    return Err(format!(
                        "unknown integrator `{i}` (choose among {})",
                        crate::integrator::NAMES.join(", ")
                    ));
                }
            }
        }
        if let Some(sw) = &self.sweep
            && sw
                .area_scales
                .iter()
                .any(|a| !(a.is_finite() && *a > 0.0 && *a <= 16.0))
        {
            return Err("sweep area scales must lie in (0, 16]".into());
        }
        Ok(())
    }

    fn height_of(&self, scene: &Scene) -> u32 {
        match scene.camera.and_then(|c| c.aspect) {
            Some(a) if a.is_finite() && a > 0.0 => ((self.width as f32 / a).round() as u32).max(1),
            _ => self.width,
        }
    }
}

/// The images a study keeps for its strips: per scene, each integrator's render at the strip
/// rung (first seed) and the reference it is compared with.
pub struct SceneImages {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub renders: Vec<StripRender>,
}

/// One image of a strip and the reference it is compared with.
pub struct StripRender {
    pub integrator: String,
    pub image: Vec<[f32; 4]>,
    pub reference: Vec<[f32; 4]>,
}

/// A study's measurements and the images of its strips.
pub struct Outcome {
    pub study: Study,
    pub images: Vec<SceneImages>,
}

/// Renders one image: `(pixels, seconds)`.
#[allow(clippy::too_many_arguments)]
fn render_once(
    rs: &RenderScene,
    integrator: &str,
    (width, height): (u32, u32),
    spp: u32,
    seed: u64,
    config: &StudyConfig,
    cancel: &AtomicBool,
    bar: &indicatif::ProgressBar,
) -> Result<(Vec<[f32; 4]>, f64), String> {
    let opts = RenderOptions {
        width,
        height,
        spp,
        max_depth: config.max_depth,
        seed,
        integrator: integrator.into(),
        threads: config.threads,
        tile_size: 16,
        region: None,
        ..Default::default()
    };
    let (img, stats) = render::render_sampled(rs, &opts, config.sampling, cancel, &|_, _, _| {})
        .map_err(|e| format!("{integrator} at {spp} spp: {e}"))?;
    bar.inc(width as u64 * height as u64 * spp as u64);
    Ok((img.pixels, stats.seconds))
}

/// Pixels whose camera ray (through the pixel's centre) first hits a perfect mirror and whose
/// reference is brighter than [`MIRROR_REGION_THRESHOLD`]: where a mirror shows an emitter.
/// `None` when there are none.
pub fn mirror_emitter_region(
    rs: &RenderScene,
    (width, height): (u32, u32),
    reference: &[[f32; 4]],
) -> Option<Vec<bool>> {
    let camera = RayCamera::new(&rs.scene, width, height);
    let mut ctx = Ctx::new(SobolSampler::new(0, 0, 0));
    let mut mask = vec![false; (width * height) as usize];
    for y in 0..height {
        for x in 0..width {
            let i = (y * width + x) as usize;
            let Some(ray) = camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), Vec2::ZERO)
            else {
                continue;
            };
            let Some(its) = rs.trace(&mut ctx, ray.o, ray.d, 1) else {
                continue;
            };
            let m = &rs.scene.materials[its.material as usize];
            let mirror = m.metallic >= 1.0 && m.roughness == 0.0 && m.transmission == 0.0;
            mask[i] = mirror && metrics::pixel_value(&reference[i]) > MIRROR_REGION_THRESHOLD;
        }
    }
    mask.iter().any(|&m| m).then_some(mask)
}

/// A converged reference: its mean image, mean estimate and named regions.
struct RefImage {
    image: Vec<[f32; 4]>,
    mean: Estimate,
    seconds: f64,
}

#[allow(clippy::too_many_arguments)]
fn render_reference(
    rs: &RenderScene,
    integrator: &str,
    size: (u32, u32),
    config: &StudyConfig,
    cancel: &AtomicBool,
    bar: &indicatif::ProgressBar,
) -> Result<RefImage, String> {
    let mut m = SeedMoments::new((size.0 * size.1) as usize);
    let mut seconds = 0.0;
    for k in 0..config.reference_seeds {
        let (img, s) = render_once(
            rs,
            integrator,
            size,
            config.reference_spp,
            reference_seed(k),
            config,
            cancel,
            bar,
        )?;
        m.add(&img);
        seconds += s;
    }
    Ok(RefImage {
        image: m.mean_image(),
        mean: Estimate {
            value: m.mean(),
            se: m.mean_variance().sqrt(),
        },
        seconds,
    })
}

/// Seeds: each (rung, seed index) and each reference or sweep render has its own, so one
/// integrator's renders are independent of each other and of the references. Integrators
/// share the seed of a (rung, seed index): common random numbers (the same camera samples),
/// which sharpen their comparison.
fn measurement_seed(spp: u32, k: u32) -> u64 {
    ((spp as u64) << 20) | k as u64
}
fn reference_seed(k: u32) -> u64 {
    (1 << 50) | k as u64
}
fn sweep_seed(k: u32) -> u64 {
    (1 << 51) | k as u64
}

/// The name of a sampling in `study.json` and on the command line.
pub fn sampler_name(s: Sampling) -> &'static str {
    match s {
        Sampling::Independent => "independent",
        Sampling::Sobol => "sobol",
    }
}

/// Samples (pixels × spp) the study will render, for the progress bar.
pub fn total_samples(config: &StudyConfig) -> u64 {
    let ladder: u64 = config.spp.iter().map(|&n| n as u64).sum();
    let mut total = 0;
    for s in &config.scenes {
        let px = config.width as u64 * config.height_of(&s.scene) as u64;
        let refs = {
            let mut r: Vec<&str> = s.integrators.iter().map(|i| reference_for(i)).collect();
            r.sort();
            r.dedup();
            r.len() as u64
        };
        total += px * refs * (config.reference_spp * config.reference_seeds) as u64;
        total += px * s.integrators.len() as u64 * ladder * config.seeds as u64;
    }
    if let Some(sw) = &config.sweep {
        let scene = builtin::cornell_box();
        let px = config.width as u64 * config.height_of(&scene) as u64;
        let per = (config.reference_spp * config.reference_seeds) as u64
            + 2 * (sw.spp * config.seeds) as u64;
        total += px * per * sw.area_scales.len() as u64;
    }
    total
}

/// Pooled mean ratio of an estimate in a region: the spp-weighted mean of the per-render
/// ratios (their variance falls as 1/spp), its standard error from their scatter.
fn pooled_region(ratios: &[(u32, f64)]) -> Estimate {
    let w: f64 = ratios.iter().map(|r| r.0 as f64).sum();
    let v = ratios.iter().map(|r| r.0 as f64 * r.1).sum::<f64>() / w;
    let var: f64 = ratios
        .iter()
        .map(|r| (r.0 as f64 / w).powi(2) * (r.1 - v).powi(2))
        .sum();
    let n = ratios.len() as f64;
    Estimate {
        value: v,
        se: if n > 1.0 {
            (var * n / (n - 1.0)).sqrt()
        } else {
            f64::INFINITY
        },
    }
}

/// Runs the study. The bar counts samples ([`total_samples`]); `cancel` stops it between
/// rows of a render.
pub fn run(
    config: &StudyConfig,
    bar: &indicatif::ProgressBar,
    cancel: &AtomicBool,
) -> Result<Outcome, String> {
    config.check()?;
    let start = Instant::now();
    // The strips show the largest rung at or below the one asked for (the first rung if none).
    let strip_spp = config
        .spp
        .iter()
        .copied()
        .filter(|&n| n <= config.strip_spp)
        .max()
        .unwrap_or(config.spp[0]);
    bar.set_length(total_samples(config));
    let mut references = Vec::new();
    let mut measurements = Vec::new();
    let mut summaries = Vec::new();
    let mut images = Vec::new();
    for s in &config.scenes {
        bar.set_message(s.name.clone());
        let size = (config.width, config.height_of(&s.scene));
        let rs = RenderScene::new(s.scene.clone(), LightChoice::Power);
        let mut refs: BTreeMap<&str, RefImage> = BTreeMap::new();
        for i in &s.integrators {
            let r = reference_for(i);
            if !refs.contains_key(r) {
                refs.insert(r, render_reference(&rs, r, size, config, cancel, bar)?);
            }
        }
        // Regions are found on the direct-illumination reference when there is one: what a
        // one-bounce estimator should show.
        let region_source = refs
            .get("direct_mis")
            .or_else(|| refs.values().next())
            .map(|r| &r.image);
        let mut regions: BTreeMap<String, Vec<bool>> = BTreeMap::new();
        if let Some(src) = region_source
            && let Some(mask) = mirror_emitter_region(&rs, size, src)
        {
            regions.insert(MIRROR_REGION.into(), mask);
        }
        let region_count: BTreeMap<String, usize> = regions
            .iter()
            .map(|(k, m)| (k.clone(), m.iter().filter(|&&b| b).count()))
            .collect();
        for (name, r) in &refs {
            references.push(Reference {
                scene: s.name.clone(),
                integrator: name.to_string(),
                spp: config.reference_spp,
                seeds: config.reference_seeds,
                mean: r.mean,
                seconds: r.seconds,
                regions: region_count.clone(),
            });
        }
        let mut renders = Vec::new();
        for integrator in &s.integrators {
            let ref_name = reference_for(integrator);
            let reference = &refs[ref_name];
            let ref_region_means: BTreeMap<&str, f64> = regions
                .iter()
                .map(|(k, m)| (k.as_str(), metrics::masked_mean(&reference.image, Some(m))))
                .collect();
            let mut per_spp = Vec::new();
            let mut pooled_parts = Vec::new();
            let mut region_parts: BTreeMap<&str, Vec<(u32, f64)>> = BTreeMap::new();
            for &spp in &config.spp {
                let mut moments = SeedMoments::new((size.0 * size.1) as usize);
                let (mut err_sum, mut sec_sum) = (0.0, 0.0);
                for k in 0..config.seeds {
                    let seed = measurement_seed(spp, k);
                    let (img, seconds) =
                        render_once(&rs, integrator, size, spp, seed, config, cancel, bar)?;
                    let rel_mse = metrics::rel_mse(&img, &reference.image);
                    let mut region_ratios = BTreeMap::new();
                    for (name, mask) in &regions {
                        let r = metrics::masked_mean(&img, Some(mask))
                            / ref_region_means[name.as_str()];
                        region_ratios.insert(name.clone(), r);
                        region_parts
                            .entry(name.as_str())
                            .or_default()
                            .push((spp, r));
                    }
                    moments.add(&img);
                    measurements.push(Measurement {
                        scene: s.name.clone(),
                        integrator: integrator.clone(),
                        spp,
                        seed,
                        rel_mse,
                        mean_ratio: metrics::masked_mean(&img, None) / reference.mean.value,
                        region_ratios,
                        seconds,
                    });
                    err_sum += rel_mse;
                    sec_sum += seconds;
                    if spp == strip_spp && k == 0 {
                        renders.push(StripRender {
                            integrator: integrator.clone(),
                            image: img,
                            reference: reference.image.clone(),
                        });
                    }
                }
                pooled_parts.push((moments.mean(), moments.mean_variance()));
                per_spp.push(SppSummary {
                    spp,
                    rel_mse: err_sum / config.seeds as f64,
                    seconds: sec_sum / config.seeds as f64,
                });
            }
            let mean_ratio = metrics::ratio(metrics::pooled_mean(&pooled_parts), reference.mean);
            // One seed per rung gives no spread, hence no standard error: no verdict on bias.
            let bias_z = if mean_ratio.se.is_finite() {
                (mean_ratio.value - 1.0) / mean_ratio.se
            } else {
                f64::NAN
            };
            let fit = |x: fn(&SppSummary) -> f64| {
                metrics::log_log_fit(
                    &per_spp
                        .iter()
                        .map(|p| (x(p), p.rel_mse))
                        .collect::<Vec<_>>(),
                )
                .map(|f| f.0)
            };
            summaries.push(Summary {
                scene: s.name.clone(),
                integrator: integrator.clone(),
                reference: ref_name.into(),
                slope_spp: fit(|p| p.spp as f64),
                slope_time: fit(|p| p.seconds),
                per_spp,
                mean_ratio,
                bias_z,
                unbiased: bias_z.abs() <= 3.0,
                region_ratios: region_parts
                    .into_iter()
                    .map(|(k, v)| (k.to_string(), pooled_region(&v)))
                    .collect(),
            });
        }
        images.push(SceneImages {
            scene: s.name.clone(),
            width: size.0,
            height: size.1,
            spp: strip_spp,
            renders,
        });
    }
    let mut sweep = Vec::new();
    if let Some(sw) = &config.sweep {
        bar.set_message("light-size sweep");
        for &a in &sw.area_scales {
            let scene = builtin::cornell_box_light_area(a as f32);
            let size = (config.width, config.height_of(&scene));
            let rs = RenderScene::new(scene, LightChoice::Power);
            let reference = render_reference(&rs, "direct_mis", size, config, cancel, bar)?;
            for integrator in ["direct_ems", "direct_mats"] {
                let mut errs = Vec::new();
                for k in 0..config.seeds {
                    let (img, _) = render_once(
                        &rs,
                        integrator,
                        size,
                        sw.spp,
                        sweep_seed(k),
                        config,
                        cancel,
                        bar,
                    )?;
                    errs.push(metrics::rel_mse(&img, &reference.image));
                }
                sweep.push(SweepPoint {
                    area_scale: a,
                    integrator: integrator.into(),
                    spp: sw.spp,
                    rel_mse: errs.iter().sum::<f64>() / errs.len() as f64,
                    rel_mse_per_seed: errs,
                });
            }
        }
    }
    let height = config
        .scenes
        .first()
        .map_or(config.width, |s| config.height_of(&s.scene));
    let mut study = Study {
        schema_version: super::SCHEMA_VERSION,
        settings: Settings {
            width: config.width,
            height,
            spp: config.spp.clone(),
            seeds: config.seeds,
            reference_spp: config.reference_spp,
            reference_seeds: config.reference_seeds,
            max_depth: config.max_depth,
            threads: config.threads,
            sweep_spp: config.sweep.as_ref().map_or(0, |s| s.spp),
            sweep_area_scales: config
                .sweep
                .as_ref()
                .map_or(Vec::new(), |s| s.area_scales.clone()),
            strip_spp,
            sampler: sampler_name(config.sampling).into(),
            rel_mse_epsilon: metrics::REL_MSE_EPSILON,
            seconds: 0.0,
        },
        references,
        measurements,
        summaries,
        sweep,
        claims: Vec::new(),
    };
    study.claims = super::report::claims(&study);
    study.settings.seconds = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    Ok(Outcome { study, images })
}
