//! The assignment's claims, each decided by the study's numbers, and `study.md`: the claims,
//! the settings, per-scene tables and the figures.

use super::run::{MIRROR_REGION, SWEEP_SCENE};
use super::{Claim, Study, Summary};
use std::fmt::Write;

/// The scene the diffuse claims are measured on.
pub const DIFFUSE_SCENE: &str = "cornell-box";
/// The scene with a mirror, for the first-hit claim.
pub const MIRROR_SCENE: &str = "cornell-spheres";
/// The scene with glass before emitters.
pub const GLASS_SCENE: &str = "glass-pane";
/// How far from −1 an error slope may be and still be Monte Carlo's 1/N.
pub const SLOPE_TOLERANCE: f64 = 0.15;
/// MIS is "as good as the better strategy" within this factor of its relMSE.
pub const MIS_TOLERANCE: f64 = 1.10;
/// Rungs at and above this spp take part in the comparisons (below it, both strategies'
/// errors are dominated by a few samples).
pub const COMPARE_FROM_SPP: u32 = 4;

/// Integrators that are meant to be biased where they are measured (they are reported, not
/// held to the unbiasedness claim).
fn expected_biased(integrator: &str) -> bool {
    integrator == "direct_ems_first_hit" || integrator.starts_with("test_")
}

fn rungs<'a>(a: &'a Summary, b: &'a Summary) -> impl Iterator<Item = (u32, f64, f64)> + 'a {
    a.per_spp.iter().filter_map(|p| {
        (p.spp >= COMPARE_FROM_SPP)
            .then(|| b.rel_mse_at(p.spp).map(|e| (p.spp, p.rel_mse, e)))
            .flatten()
    })
}

fn ems_beats_mats(study: &Study) -> Claim {
    let statement = "On diffuse surfaces emitter sampling converges faster than BSDF sampling: \
        direct_ems has a lower relMSE than direct_mats at every spp >= 4 (cornell-box)."
        .to_string();
    let (Some(ems), Some(mats)) = (
        study.summary(DIFFUSE_SCENE, "direct_ems"),
        study.summary(DIFFUSE_SCENE, "direct_mats"),
    ) else {
        return unmeasured("ems-beats-mats", statement);
    };
    let r: Vec<(u32, f64, f64)> = rungs(ems, mats).collect();
    let holds = !r.is_empty() && r.iter().all(|(_, e, m)| e < m);
    let evidence = r
        .iter()
        .map(|(n, e, m)| format!("{n} spp: mats/ems = {:.2}", m / e))
        .collect::<Vec<_>>()
        .join("; ");
    Claim {
        id: "ems-beats-mats".into(),
        statement,
        holds: Some(holds),
        evidence,
    }
}

fn mis_near_best(study: &Study) -> Claim {
    let statement = "MIS is as good as the better of the two strategies: direct_mis's relMSE \
        is within 10% of min(direct_ems, direct_mats) at every spp >= 4 (cornell-box)."
        .to_string();
    let (Some(ems), Some(mats), Some(mis)) = (
        study.summary(DIFFUSE_SCENE, "direct_ems"),
        study.summary(DIFFUSE_SCENE, "direct_mats"),
        study.summary(DIFFUSE_SCENE, "direct_mis"),
    ) else {
        return unmeasured("mis-near-best", statement);
    };
    let mut parts = Vec::new();
    let mut holds = true;
    for (n, e, m) in rungs(ems, mats) {
        let Some(x) = mis.rel_mse_at(n) else { continue };
        let r = x / e.min(m);
        holds &= r <= MIS_TOLERANCE;
        parts.push(format!("{n} spp: mis/best = {r:.3}"));
    }
    Claim {
        id: "mis-near-best".into(),
        statement,
        holds: Some(holds && !parts.is_empty()),
        evidence: parts.join("; "),
    }
}

fn slopes(study: &Study) -> Claim {
    let statement = format!(
        "Every unbiased estimator's relMSE falls as 1/N: its fitted log-log slope against spp is \
         within {SLOPE_TOLERANCE} of -1 (all scenes)."
    );
    let mut parts = Vec::new();
    let mut holds = true;
    for s in study
        .summaries
        .iter()
        .filter(|s| !expected_biased(&s.integrator))
    {
        match s.slope_spp {
            Some(k) => {
                holds &= (k + 1.0).abs() <= SLOPE_TOLERANCE;
                parts.push(format!("{} {}: {k:.3}", s.scene, s.integrator));
            }
            None => holds = false,
        }
    }
    Claim {
        id: "slopes".into(),
        statement,
        holds: Some(holds && !parts.is_empty()),
        evidence: parts.join("; "),
    }
}

fn unbiased(study: &Study) -> Claim {
    let statement = "Tesela's estimators are unbiased: each one's mean, pooled over every render, \
        is within 3 standard errors of its reference's (all scenes)."
        .to_string();
    let mut parts = Vec::new();
    let mut holds = true;
    for s in study
        .summaries
        .iter()
        .filter(|s| !expected_biased(&s.integrator))
    {
        holds &= s.unbiased;
        parts.push(format!(
            "{} {}: {:.4} ± {:.4} (z = {:.1})",
            s.scene, s.integrator, s.mean_ratio.value, s.mean_ratio.se, s.bias_z
        ));
    }
    // Without a standard error (one seed per rung) there is no verdict.
    let measured = study
        .summaries
        .iter()
        .filter(|s| !expected_biased(&s.integrator))
        .all(|s| !s.bias_z.is_nan());
    Claim {
        id: "unbiased".into(),
        statement,
        holds: (measured && !parts.is_empty()).then_some(holds),
        evidence: parts.join("; "),
    }
}

fn larger_light(study: &Study) -> Claim {
    let statement = "BSDF sampling works better the larger the light: with the same power, \
        relMSE(direct_mats) / relMSE(direct_ems) falls as the light's area grows (cornell-box, \
        1/16 to 4 times its light's area)."
        .to_string();
    let pts: Vec<(f64, f64)> = study
        .settings
        .sweep_area_scales
        .iter()
        .filter_map(|&a| {
            Some((
                a,
                study.sweep_rel_mse(a, "direct_mats")? / study.sweep_rel_mse(a, "direct_ems")?,
            ))
        })
        .collect();
    let Some((slope, _)) = super::metrics::log_log_fit(&pts) else {
        return unmeasured("larger-light", statement);
    };
    let first = pts[0].1;
    let last = pts[pts.len() - 1].1;
    Claim {
        id: "larger-light".into(),
        statement,
        holds: Some(slope < 0.0 && last < first),
        evidence: format!(
            "{}; log-log slope of the ratio against area {slope:.2} ({SWEEP_SCENE}, {} spp)",
            pts.iter()
                .map(|(a, r)| format!("area x{a}: {r:.2}"))
                .collect::<Vec<_>>()
                .join(", "),
            study.settings.sweep_spp
        ),
    }
}

fn first_hit_mirror(study: &Study) -> Claim {
    let statement = format!(
        "Emitter sampling at the first hit only (the assignment's direct_ems) cannot see \
         mirrors: in the pixels where the mirror sphere shows the light ({MIRROR_SCENE}), \
         direct_ems_first_hit keeps under 10% of the reference's light, while direct_mats and \
         Tesela's direct_ems (which follows delta bounces) keep it within 10%."
    );
    let get = |i: &str| {
        study
            .summary(MIRROR_SCENE, i)
            .and_then(|s| s.region_ratios.get(MIRROR_REGION).copied())
    };
    let (Some(first), Some(ems), Some(mats)) = (
        get("direct_ems_first_hit"),
        get("direct_ems"),
        get("direct_mats"),
    ) else {
        return unmeasured("first-hit-misses-mirror", statement);
    };
    let pixels = study
        .references
        .iter()
        .find(|r| r.scene == MIRROR_SCENE)
        .and_then(|r| r.regions.get(MIRROR_REGION).copied())
        .unwrap_or(0);
    Claim {
        id: "first-hit-misses-mirror".into(),
        statement,
        holds: Some(
            first.value < 0.1 && (ems.value - 1.0).abs() < 0.1 && (mats.value - 1.0).abs() < 0.1,
        ),
        evidence: format!(
            "mean over reference in the region ({pixels} pixels): direct_ems_first_hit {:.3}, \
             direct_ems {:.3} ± {:.3}, direct_mats {:.3} ± {:.3}",
            first.value, ems.value, ems.se, mats.value, mats.se
        ),
    }
}

fn one_bounce_glass(study: &Study) -> Claim {
    let statement = format!(
        "A one-bounce estimator shows what is seen through glass but not what glass lights: in \
         {GLASS_SCENE}, the direct-illumination reference holds measurably less light than the \
         path-traced one (the floor lit through the pane, and the second bounces)."
    );
    let find = |i: &str| {
        study
            .references
            .iter()
            .find(|r| r.scene == GLASS_SCENE && r.integrator == i)
    };
    let (Some(d), Some(p)) = (find("direct_mis"), find("path_mis")) else {
        return unmeasured("one-bounce-glass", statement);
    };
    let r = super::metrics::ratio(d.mean, p.mean);
    Claim {
        id: "one-bounce-glass".into(),
        statement,
        holds: Some(r.value + 3.0 * r.se < 1.0),
        evidence: format!(
            "direct_mis / path_mis reference mean = {:.4} ± {:.4}",
            r.value, r.se
        ),
    }
}

fn unmeasured(id: &str, statement: String) -> Claim {
    Claim {
        id: id.into(),
        statement,
        holds: None,
        evidence: "not measured by this study (scene or integrator missing)".into(),
    }
}

/// The claims, decided by the study's measurements.
pub fn claims(study: &Study) -> Vec<Claim> {
    vec![
        ems_beats_mats(study),
        mis_near_best(study),
        slopes(study),
        unbiased(study),
        larger_light(study),
        first_hit_mirror(study),
        one_bounce_glass(study),
    ]
}

fn verdict(h: Option<bool>) -> &'static str {
    match h {
        Some(true) => "supported",
        Some(false) => "contradicted",
        None => "not measured",
    }
}

/// `study.md`: figures are linked as `{figures}{file}` (`figures` is a folder prefix such as
/// `"study/"`, or empty when they sit beside the report).
pub fn markdown(study: &Study, figures: &str, files: &[String]) -> String {
    let st = &study.settings;
    let mut md = String::new();
    let _ = writeln!(md, "# What the integrators do, measured\n");
    let _ = writeln!(
        md,
        "Written by `tesela study`. Settings: {}x{} pixels, spp {:?}, {} seeds per rung, \
         {} samples, references of {} x {} spp, max depth {}, light-size sweep at {} spp over area scales \
         {:?}, strips at {} spp; relMSE = mean of (x - r)^2 / (r^2 + {}) over pixels and RGB. \
         The whole study took {:.1} s.\n",
        st.width,
        st.height,
        st.spp,
        st.seeds,
        st.sampler,
        st.reference_seeds,
        st.reference_spp,
        st.max_depth,
        st.sweep_spp,
        st.sweep_area_scales,
        st.strip_spp,
        st.rel_mse_epsilon,
        st.seconds
    );
    let _ = writeln!(md, "## Claims\n");
    for c in &study.claims {
        let _ = writeln!(
            md,
            "- **{}** ({}): {}\n  Measured: {}\n",
            c.id,
            verdict(c.holds),
            c.statement,
            c.evidence
        );
    }
    let mut scenes: Vec<&str> = study.summaries.iter().map(|s| s.scene.as_str()).collect();
    scenes.dedup();
    for scene in scenes {
        let _ = writeln!(md, "## {scene}\n");
        let _ = writeln!(
            md,
            "| integrator | reference | slope (spp) | slope (time) | relMSE at {} spp | mean / reference | z |",
            st.spp.last().copied().unwrap_or(0)
        );
        let _ = writeln!(md, "|---|---|---|---|---|---|---|");
        for s in study.summaries.iter().filter(|s| s.scene == scene) {
            let f = |v: Option<f64>| v.map_or("-".into(), |k| format!("{k:.2}"));
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {:.3e} | {:.4} ± {:.4} | {:.1} |",
                s.integrator,
                s.reference,
                f(s.slope_spp),
                f(s.slope_time),
                s.per_spp.last().map_or(f64::NAN, |p| p.rel_mse),
                s.mean_ratio.value,
                s.mean_ratio.se,
                s.bias_z
            );
        }
        let _ = writeln!(md);
        for stem in ["error-spp", "error-time", "strip"] {
            let ext = if stem == "strip" { "png" } else { "svg" };
            let name = format!("{scene}-{stem}.{ext}");
            if files.contains(&name) {
                let _ = writeln!(md, "![{scene} {stem}]({figures}{name})\n");
            }
        }
        if files.contains(&format!("{scene}-strip.png")) {
            let _ = writeln!(
                md,
                "Top: each integrator at {} spp (first seed); bottom: its per-pixel relative \
                 squared error against its reference, log scale from 1e-4 (black) to 1 (white).\n",
                st.strip_spp
            );
        }
    }
    if !study.sweep.is_empty() {
        let _ = writeln!(md, "## Light-size sweep ({SWEEP_SCENE}, same power)\n");
        let _ = writeln!(
            md,
            "| area scale | relMSE direct_ems | relMSE direct_mats | ratio |"
        );
        let _ = writeln!(md, "|---|---|---|---|");
        for &a in &st.sweep_area_scales {
            if let (Some(e), Some(m)) = (
                study.sweep_rel_mse(a, "direct_ems"),
                study.sweep_rel_mse(a, "direct_mats"),
            ) {
                let _ = writeln!(md, "| {a} | {e:.3e} | {m:.3e} | {:.2} |", m / e);
            }
        }
        let _ = writeln!(md);
        if files.iter().any(|f| f == "light-size.svg") {
            let _ = writeln!(md, "![light-size sweep]({figures}light-size.svg)\n");
        }
    }
    md
}
