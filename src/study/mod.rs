//! `tesela study`: measures what the direct-illumination assignment argues from pictures.
//!
//! For each scene it renders a converged reference, then each integrator at a ladder of
//! sample counts with several independent seeds, and measures the relative MSE, the mean
//! against the reference (bias) and the time ([`run`]). A light-size sweep on the diffuse
//! Cornell box compares BSDF and emitter sampling as the same power leaves through smaller
//! and larger lights. [`report`] states the assignment's claims with the numbers that
//! support or contradict them, [`plot`] draws the curves and image strips, and the whole
//! measurement is written as `study.json` (schema: `docs/study-schema.json`, checked by
//! [`schema`]).

pub mod metrics;
pub mod plot;
pub mod report;
pub mod run;
pub mod schema;

pub use run::{StudyConfig, StudyScene, run};

use metrics::Estimate;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Version of the `study.json` layout.
pub const SCHEMA_VERSION: u32 = 1;

/// Everything a study measured (what `study.json` holds).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Study {
    pub schema_version: u32,
    pub settings: Settings,
    pub references: Vec<Reference>,
    pub measurements: Vec<Measurement>,
    pub summaries: Vec<Summary>,
    pub sweep: Vec<SweepPoint>,
    pub claims: Vec<Claim>,
}

/// The settings the study ran with.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Settings {
    pub width: u32,
    pub height: u32,
    pub spp: Vec<u32>,
    pub seeds: u32,
    pub reference_spp: u32,
    pub reference_seeds: u32,
    pub max_depth: u32,
    pub threads: usize,
    pub sweep_spp: u32,
    pub sweep_area_scales: Vec<f64>,
    pub strip_spp: u32,
    /// "independent" (plain Monte Carlo) or "sobol" (Tesela's stratified samples).
    pub sampler: String,
    pub rel_mse_epsilon: f64,
    /// Wall time of the whole study (seconds).
    pub seconds: f64,
}

/// A reference render: the mean of `seeds` renders of `spp` samples.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Reference {
    pub scene: String,
    pub integrator: String,
    pub spp: u32,
    pub seeds: u32,
    /// Mean pixel value (sum of RGB) with its standard error.
    pub mean: Estimate,
    pub seconds: f64,
    /// Named pixel regions measured separately, with their pixel counts.
    pub regions: BTreeMap<String, usize>,
}

/// One render of one integrator at one sample count and seed.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Measurement {
    pub scene: String,
    pub integrator: String,
    pub spp: u32,
    pub seed: u64,
    pub rel_mse: f64,
    /// Mean pixel value over the reference's.
    pub mean_ratio: f64,
    /// The same ratio inside each of the reference's named regions.
    pub region_ratios: BTreeMap<String, f64>,
    pub seconds: f64,
}

/// What one integrator's measurements on one scene add up to.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Summary {
    pub scene: String,
    pub integrator: String,
    /// The integrator the reference was rendered with.
    pub reference: String,
    /// Per rung of the spp ladder: spp, mean relMSE and mean seconds over the seeds.
    pub per_spp: Vec<SppSummary>,
    /// Fitted exponent of relMSE against spp (Monte Carlo: −1).
    pub slope_spp: Option<f64>,
    /// Fitted exponent of relMSE against render time.
    pub slope_time: Option<f64>,
    /// Mean over the reference's mean, pooled over every render (inverse-variance weights),
    /// with its standard error (that of the reference included).
    pub mean_ratio: Estimate,
    /// `(mean_ratio − 1) / se`; NaN (`null` in JSON) when the standard error is unknown
    /// (one seed per rung).
    pub bias_z: f64,
    /// `|bias_z| <= 3` (false when `bias_z` is unknown).
    pub unbiased: bool,
    /// Pooled mean ratios inside the named regions.
    pub region_ratios: BTreeMap<String, Estimate>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SppSummary {
    pub spp: u32,
    pub rel_mse: f64,
    pub seconds: f64,
}

/// One point of the light-size sweep: the diffuse box with its light's area scaled by
/// `area_scale` (same power), one integrator, the mean relMSE over the seeds.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SweepPoint {
    pub area_scale: f64,
    pub integrator: String,
    pub spp: u32,
    pub rel_mse: f64,
    pub rel_mse_per_seed: Vec<f64>,
}

/// One of the assignment's claims, with the measured number that supports or contradicts it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Claim {
    pub id: String,
    pub statement: String,
    /// `None` when the study did not measure what the claim needs.
    pub holds: Option<bool>,
    pub evidence: String,
}

impl Study {
    /// The summary of `integrator` on `scene`.
    pub fn summary(&self, scene: &str, integrator: &str) -> Option<&Summary> {
        self.summaries
            .iter()
            .find(|s| s.scene == scene && s.integrator == integrator)
    }

    /// The mean relMSE of `integrator` at `area_scale` in the light-size sweep.
    pub fn sweep_rel_mse(&self, area_scale: f64, integrator: &str) -> Option<f64> {
        self.sweep
            .iter()
            .find(|p| p.area_scale == area_scale && p.integrator == integrator)
            .map(|p| p.rel_mse)
    }
}

impl Summary {
    /// Mean relMSE at `spp`.
    pub fn rel_mse_at(&self, spp: u32) -> Option<f64> {
        self.per_spp
            .iter()
            .find(|p| p.spp == spp)
            .map(|p| p.rel_mse)
    }
}

/// Writes `study.json`, the figures and `study.md` into `dir` (created if missing); returns
/// the names of the files written.
pub fn write(dir: &std::path::Path, outcome: &run::Outcome) -> Result<Vec<String>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    let json_path = dir.join("study.json");
    let json = serde_json::to_string_pretty(&outcome.study)
        .map_err(|e| format!("{}: {e}", json_path.display()))?;
    std::fs::write(&json_path, json)
        .map_err(|e| format!("{}: cannot write: {e}", json_path.display()))?;
    let mut files = vec!["study.json".to_string()];
    files.extend(plot::write_all(dir, outcome)?);
    let md_path = dir.join("study.md");
    std::fs::write(&md_path, report::markdown(&outcome.study, "", &files))
        .map_err(|e| format!("{}: cannot write: {e}", md_path.display()))?;
    files.push("study.md".into());
    Ok(files)
}
