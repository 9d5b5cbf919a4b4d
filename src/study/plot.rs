//! The study's figures, drawn with `plotters`: log-log error curves (against spp and against
//! time) with their fitted slopes, the light-size sweep, and image strips (renders at equal
//! spp over their per-pixel error images). Curves are written as PNG and SVG.
//!
//! Text needs a TrueType font: the first of `$TESELA_FONT` and a few usual system paths
//! (DejaVu Sans, Liberation Sans, Arial) that can be read. Without one the figures are drawn
//! without text (axes, curves and images only).

use super::metrics;
use super::run::{Outcome, SceneImages};
use super::{Study, Summary};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

const FONT_PATHS: [&str; 6] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/Library/Fonts/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

/// Registers a font as plotters' "sans-serif" once; whether text can be drawn.
fn text_available() -> bool {
    static READY: OnceLock<bool> = OnceLock::new();
    *READY.get_or_init(|| {
        let env = std::env::var("TESELA_FONT").ok();
        for p in env.iter().map(String::as_str).chain(FONT_PATHS) {
            if let Ok(bytes) = std::fs::read(p) {
                // plotters keeps fonts for the life of the program.
                let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
                if plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok() {
                    return true;
                }
            }
        }
        false
    })
}

/// A curve's colour, fixed per integrator so every figure agrees.
fn color_of(integrator: &str) -> RGBColor {
    match integrator {
        "direct_ems" => RGBColor(31, 119, 180),
        "direct_mats" => RGBColor(214, 39, 40),
        "direct_mis" => RGBColor(44, 160, 44),
        "direct_ems_first_hit" => RGBColor(255, 127, 14),
        "path_mats" => RGBColor(148, 103, 189),
        "path_mis" => RGBColor(23, 190, 207),
        _ => RGBColor(127, 127, 127),
    }
}

/// One labelled curve.
pub struct Series {
    pub label: String,
    pub color: RGBColor,
    pub points: Vec<(f64, f64)>,
}

/// A log-log chart of labelled curves and an optional dashed guide line.
pub struct LineChart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub guide: Option<(String, Vec<(f64, f64)>)>,
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.1, 10.0);
    }
    if hi <= lo * 1.01 {
        (lo / 2.0, hi * 2.0)
    } else {
        (lo / 1.25, hi * 1.25)
    }
}

fn draw_chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    c: &LineChart,
    text: bool,
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let pts = || c.series.iter().flat_map(|s| s.points.iter());
    let (x0, x1) = range(pts().map(|p| p.0));
    let (y0, y1) = range(pts().map(|p| p.1));
    let mut b = ChartBuilder::on(root);
    b.margin(12);
    if text {
        b.caption(&c.title, ("sans-serif", 20))
            .x_label_area_size(40)
            .y_label_area_size(64);
    } else {
        b.x_label_area_size(8).y_label_area_size(8);
    }
    let mut chart = b
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(err)?;
    let mut mesh = chart.configure_mesh();
    if text {
        mesh.x_desc(&c.x_label).y_desc(&c.y_label);
        mesh.y_label_formatter(&|v| format!("{v:.1e}"));
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw().map_err(err)?;
    if let Some((label, g)) = &c.guide {
        let s = chart
            .draw_series(DashedLineSeries::new(
                g.iter().copied(),
                6,
                4,
                BLACK.mix(0.6).stroke_width(1),
            ))
            .map_err(err)?;
        if text {
            s.label(label.clone())
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.6)));
        }
    }
    for Series {
        label,
        color,
        points: p,
    } in &c.series
    {
        let color = *color;
        let s = chart
            .draw_series(LineSeries::new(p.iter().copied(), color.stroke_width(2)))
            .map_err(err)?;
        if text {
            s.label(label.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
        }
        chart
            .draw_series(p.iter().map(|&q| Circle::new(q, 3, color.filled())))
            .map_err(err)?;
    }
    if text {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(err)?;
    }
    root.present().map_err(err)?;
    Ok(())
}

/// Writes `chart` as `stem.png` and `stem.svg` in `dir`; returns the two file names.
pub fn write_chart(dir: &Path, stem: &str, chart: &LineChart) -> Result<Vec<String>, String> {
    let (w, h) = (720u32, 480u32);
    let text = text_available();
    let png = dir.join(format!("{stem}.png"));
    let svg = dir.join(format!("{stem}.svg"));
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        draw_chart(&root, chart, text).map_err(|e| format!("{}: {e}", png.display()))?;
    }
    image::save_buffer(&png, &buf, w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| format!("{}: cannot write PNG: {e}", png.display()))?;
    {
        let root = SVGBackend::new(&svg, (w, h)).into_drawing_area();
        draw_chart(&root, chart, text).map_err(|e| format!("{}: {e}", svg.display()))?;
    }
    Ok(vec![format!("{stem}.png"), format!("{stem}.svg")])
}

/// `relMSE` against spp (or mean seconds) of every integrator measured on `scene`.
pub fn error_chart(study: &Study, scene: &str, against_time: bool) -> LineChart {
    let summaries: Vec<&Summary> = study
        .summaries
        .iter()
        .filter(|s| s.scene == scene)
        .collect();
    let series: Vec<_> = summaries
        .iter()
        .map(|s| {
            let slope = if against_time {
                s.slope_time
            } else {
                s.slope_spp
            };
            let label = match slope {
                Some(k) => format!("{} (slope {k:.2})", s.integrator),
                None => s.integrator.clone(),
            };
            let pts = s
                .per_spp
                .iter()
                .map(|p| {
                    let x = if against_time {
                        p.seconds
                    } else {
                        p.spp as f64
                    };
                    (x, p.rel_mse)
                })
                .collect();
            Series {
                label,
                color: color_of(&s.integrator),
                points: pts,
            }
        })
        .collect();
    // The 1/N line through the first point of the first curve.
    let guide = series.first().and_then(|s| {
        let p = &s.points;
        let (&first, &last) = (p.first()?, p.last()?);
        (last.0 > first.0).then(|| {
            (
                "1/N".to_string(),
                vec![first, (last.0, first.1 * first.0 / last.0)],
            )
        })
    });
    LineChart {
        title: format!(
            "{scene}: relMSE against {}",
            if against_time { "time" } else { "spp" }
        ),
        x_label: if against_time {
            "seconds per image".into()
        } else {
            "samples per pixel".into()
        },
        y_label: "relMSE".into(),
        series,
        guide,
    }
}

/// The light-size sweep: BSDF-sampling over emitter-sampling relMSE against light area.
pub fn sweep_chart(study: &Study) -> LineChart {
    let pts: Vec<(f64, f64)> = study
        .settings
        .sweep_area_scales
        .iter()
        .filter_map(|&a| {
            let ems = study.sweep_rel_mse(a, "direct_ems")?;
            let mats = study.sweep_rel_mse(a, "direct_mats")?;
            Some((a, mats / ems))
        })
        .collect();
    LineChart {
        title: format!(
            "cornell-box, same power: relMSE(direct_mats) / relMSE(direct_ems) at {} spp",
            study.settings.sweep_spp
        ),
        x_label: "light area / the box's light area".into(),
        y_label: "relMSE ratio".into(),
        series: vec![Series {
            label: "direct_mats / direct_ems".into(),
            color: color_of("direct_mats"),
            points: pts,
        }],
        guide: None,
    }
}

/// A heat colour ramp (black, red, yellow, white) of `t` in [0, 1].
fn heat(t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0) * 3.0;
    let r = t.min(1.0);
    let g = (t - 1.0).clamp(0.0, 1.0);
    let b = (t - 2.0).clamp(0.0, 1.0);
    [r, g, b].map(|c| (c * 255.0 + 0.5) as u8)
}

/// Decades of relative squared error the error images span: 1e-4 is black, 1 white.
const ERROR_DECADES: f64 = 4.0;

/// Integer magnification of the strips' images (small renders are hard to see).
fn zoom(width: u32) -> u32 {
    (256 / width.max(1)).clamp(1, 4)
}

/// The strip of one scene: its renders at equal spp in a row, their per-pixel relative
/// squared error under them, labels above when text can be drawn. Written as `stem.png`.
pub fn write_strip(dir: &Path, stem: &str, s: &SceneImages) -> Result<String, String> {
    let z = zoom(s.width);
    let (cw, ch) = (s.width * z, s.height * z);
    let gap = 6u32;
    let label_h = if text_available() { 22 } else { 0 };
    let n = s.renders.len() as u32;
    let w = n * cw + (n + 1) * gap;
    let h = label_h + 2 * ch + 3 * gap;
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let mut put = |x: u32, y: u32, c: [u8; 3]| {
        let i = ((y * w + x) * 3) as usize;
        buf[i..i + 3].copy_from_slice(&c);
    };
    for (k, r) in s.renders.iter().enumerate() {
        let (img, reference) = (&r.image, &r.reference);
        let x0 = gap + k as u32 * (cw + gap);
        let err = metrics::rel_se_image(img, reference);
        for y in 0..ch {
            for x in 0..cw {
                let i = ((y / z) * s.width + x / z) as usize;
                let p = img[i];
                let c = [0, 1, 2].map(|c| (crate::output::srgb_encode(p[c]) * 255.0 + 0.5) as u8);
                put(x0 + x, label_h + gap + y, c);
                let t = (err[i].max(1e-30).log10() + ERROR_DECADES) / ERROR_DECADES;
                put(x0 + x, label_h + 2 * gap + ch + y, heat(t));
            }
        }
    }
    if label_h > 0 {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        for (k, r) in s.renders.iter().enumerate() {
            let name = &r.integrator;
            let x0 = (gap + k as u32 * (cw + gap)) as i32;
            root.draw(&Text::new(
                name.clone(),
                (x0, 4),
                ("sans-serif", 12).into_font(),
            ))
            .map_err(|e| format!("{stem}: {e}"))?;
        }
        root.present().map_err(|e| format!("{stem}: {e}"))?;
    }
    let path = dir.join(format!("{stem}.png"));
    image::save_buffer(&path, &buf, w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| format!("{}: cannot write PNG: {e}", path.display()))?;
    Ok(format!("{stem}.png"))
}

/// Every figure of a study: per scene the two error charts and the strip, and the sweep.
/// Returns the file names written (relative to `dir`).
pub fn write_all(dir: &Path, outcome: &Outcome) -> Result<Vec<String>, String> {
    let mut files = Vec::new();
    for s in &outcome.images {
        let study = &outcome.study;
        files.extend(write_chart(
            dir,
            &format!("{}-error-spp", s.scene),
            &error_chart(study, &s.scene, false),
        )?);
        files.extend(write_chart(
            dir,
            &format!("{}-error-time", s.scene),
            &error_chart(study, &s.scene, true),
        )?);
        if !s.renders.is_empty() {
            files.push(write_strip(dir, &format!("{}-strip", s.scene), s)?);
        }
    }
    if !outcome.study.sweep.is_empty() {
        files.extend(write_chart(
            dir,
            "light-size",
            &sweep_chart(&outcome.study),
        )?);
    }
    Ok(files)
}
