//! The film's unnormalised sums for a range of samples, so that a render can be split over
//! machines by sample index and merged exactly.
//!
//! A part renders samples `[start, end)` of every pixel with the same (seed, pixel, sample)
//! streams as the whole render, and keeps what the film accumulates: the radiance sum, the
//! coverage sum, the accepted and empty sample counts, and each auxiliary pass's record.
//! Merging adds the sums of parts (in sample order) and resolves them as the renderer
//! resolves its own film, so the merged image equals the single-machine render up to the
//! order of float additions. Passes that the first sample alone writes (depth, position,
//! indices) come from the earliest part in which the pixel accepted a sample.
//!
//! On disk the sums are a single-layer OpenEXR file (see [`write`]): 32-bit float channels
//! for the sums, 32-bit unsigned integer channels for the counts, and header attributes for
//! the sample range and what render the part belongs to.

use super::PixelAcc;
use super::pass::{Pass, PassSet};
use crate::render::Image;
use std::ops::Range;
use std::path::Path;

/// The `tesela.format` attribute of an accumulator file.
pub const FORMAT: &str = "tesela-accumulators 1";

/// The film of one part: `width × height` pixels (the rendered window), rows top to bottom.
#[derive(Clone, Debug)]
pub struct Accumulators {
    pub width: u32,
    pub height: u32,
    /// The samples `[start, end)` of every pixel that these sums hold.
    pub samples: Range<u32>,
    /// Samples per pixel of the whole render the part belongs to.
    pub spp: u32,
    pub passes: PassSet,
    /// Alpha is the mean coverage (a transparent film) rather than 1.
    pub transparent: bool,
    /// Identifies the render (scene and every option but the sample range): only parts with
    /// equal keys merge.
    pub key: String,
    /// Per pixel: `sum`, `coverage`, `accepted` and `empty` (the other fields are unused).
    pub pixels: Vec<PixelAcc>,
    /// Per pixel, the passes' raw record ([`PassSet::stride`] values, as the film adds them).
    pub aovs: Vec<f32>,
}

impl Accumulators {
    /// The image these sums stand for: the means the renderer's film would show.
    pub fn resolve(&self) -> Image {
        let stride = self.passes.stride();
        let mut aovs = vec![0.0; self.aovs.len()];
        let pixels = (self.pixels.iter().enumerate())
            .map(|(i, p)| {
                let r = i * stride..(i + 1) * stride;
                let (rec, out) = (&self.aovs[r.clone()], &mut aovs[r]);
                super::resolve_pixel(p, &self.passes, rec, &self.passes, self.transparent, out)
            })
            .collect();
        Image {
            width: self.width,
            height: self.height,
            pixels,
            passes: self.passes.clone(),
            aovs,
        }
    }

    /// Adds the parts' sums into one film. The parts must belong to one render (same key,
    /// size, passes and total spp) and their sample ranges must tile `[0, spp)` without gaps
    /// or overlaps (in any order: they are sorted by range). `names` label the parts in
    /// errors (file names), in the order of `parts`.
    pub fn merge(mut parts: Vec<(String, Accumulators)>) -> Result<Accumulators, String> {
        if parts.is_empty() {
            return Err("no parts to merge".into());
        }
        parts.sort_by_key(|(_, p)| (p.samples.start, p.samples.end));
        let (first_name, first) = &parts[0];
        for (name, p) in &parts[1..] {
            let differs = if p.key != first.key {
                Some("comes from another render (scene or render options differ)")
            } else if (p.width, p.height) != (first.width, first.height) {
                Some("has another image size")
            } else if p.passes != first.passes {
                Some("has other passes")
            } else if p.spp != first.spp {
                Some("belongs to a render of another sample count")
            } else if p.transparent != first.transparent {
                Some("has another film transparency")
            } else {
                None
            };
            if let Some(why) = differs {
                return Err(format!("{name}: {why} than {first_name}"));
            }
        }
        let mut next = 0;
        for (name, p) in &parts {
            let (a, b) = (p.samples.start, p.samples.end);
            if a > next {
                return Err(format!(
                    "samples {next}:{a} of the {} are in no part (next part: {name}, samples {a}:{b})",
                    first.spp
                ));
            }
            if a < next {
                return Err(format!(
                    "{name}: samples {a}:{b} overlap samples a previous part holds (up to {next})"
                ));
            }
            next = b;
        }
        if next != first.spp {
            return Err(format!(
                "samples {next}:{} of the {} are in no part",
                first.spp, first.spp
            ));
        }
        let mut parts = parts.into_iter().map(|(_, p)| p);
        let mut merged = parts.next().ok_or("no parts to merge")?;
        let stride = merged.passes.stride();
        // Per channel of a pass record: written by the pixel's first sample alone.
        let mut first_only = vec![false; stride];
        for (pass, at) in merged.passes.iter() {
            first_only[at..at + pass.channels()].fill(pass.first_sample_only());
        }
        for p in parts {
            for (i, (m, q)) in merged.pixels.iter_mut().zip(&p.pixels).enumerate() {
                let r = i * stride..(i + 1) * stride;
                let (ma, qa) = (&mut merged.aovs[r.clone()], &p.aovs[r]);
                let take_first = m.accepted == 0 && q.accepted > 0;
                for ((x, y), first) in ma.iter_mut().zip(qa).zip(&first_only) {
                    if !first {
                        *x += *y;
                    } else if take_first {
                        *x = *y;
                    }
                }
                m.sum += q.sum;
                m.coverage += q.coverage;
                m.accepted += q.accepted;
                m.empty += q.empty;
            }
            merged.samples.end = p.samples.end;
        }
        Ok(merged)
    }
}

/// The channels of an accumulator file besides the passes: radiance sums, coverage sum,
/// and the sample counts.
const SUM: [&str; 3] = ["sum.R", "sum.G", "sum.B"];
const COVERAGE: &str = "sum.coverage";
const ACCEPTED: &str = "count.accepted";
const EMPTY: &str = "count.empty";

/// The channel of `pass`'s component `id`: `pass.Depth.Z`, `pass.Denoising Normal.X`.
fn pass_channel(pass: Pass, id: char) -> String {
    format!("pass.{}.{id}", pass.blender_name())
}

fn text(s: &str, path: &Path) -> Result<exr::prelude::Text, String> {
    exr::prelude::Text::new_or_none(s)
        .ok_or_else(|| format!("{}: `{s}` cannot be an EXR attribute", path.display()))
}

/// Writes `acc` as a single-layer OpenEXR file: float channels `sum.R/G/B` (radiance summed
/// over the accepted samples), `sum.coverage`, each pass's raw record as `pass.<Blender
/// name>.<channel>`, and unsigned integer channels `count.accepted` and `count.empty`; text
/// attributes `tesela.format`, `tesela.samples` (`start end spp`), `tesela.passes`
/// (command-line names), `tesela.transparent` (`0`/`1`) and `tesela.key`.
pub fn write(acc: &Accumulators, path: &Path) -> Result<(), String> {
    use exr::prelude::*;
    let stride = acc.passes.stride();
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = Default::default();
    for (c, name) in SUM.iter().enumerate() {
        let v = acc.pixels.iter().map(|p| p.sum[c]).collect();
        channels.push(AnyChannel::new(*name, FlatSamples::F32(v)));
    }
    let v = acc.pixels.iter().map(|p| p.coverage).collect();
    channels.push(AnyChannel::new(COVERAGE, FlatSamples::F32(v)));
    let v = acc.pixels.iter().map(|p| p.accepted).collect();
    channels.push(AnyChannel::new(ACCEPTED, FlatSamples::U32(v)));
    let v = acc.pixels.iter().map(|p| p.empty).collect();
    channels.push(AnyChannel::new(EMPTY, FlatSamples::U32(v)));
    for (pass, at) in acc.passes.iter() {
        for (c, id) in pass.channel_ids().chars().enumerate() {
            let v = acc.aovs.chunks_exact(stride).map(|r| r[at + c]).collect();
            channels.push(AnyChannel::new(
                pass_channel(pass, id).as_str(),
                FlatSamples::F32(v),
            ));
        }
    }
    let mut attrs = LayerAttributes::default();
    let passes: Vec<&str> = acc.passes.iter().map(|(p, _)| p.name()).collect();
    for (k, v) in [
        ("tesela.format", FORMAT.to_string()),
        (
            "tesela.samples",
            format!("{} {} {}", acc.samples.start, acc.samples.end, acc.spp),
        ),
        ("tesela.passes", passes.join(",")),
        ("tesela.transparent", u8::from(acc.transparent).to_string()),
        ("tesela.key", acc.key.clone()),
    ] {
        attrs
            .other
            .insert(text(k, path)?, AttributeValue::Text(text(&v, path)?));
    }
    let layer = Layer::new(
        (acc.width as usize, acc.height as usize),
        attrs,
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(channels),
    );
    exr::image::Image::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|e| format!("{}: cannot write EXR: {e}", path.display()))
}

/// Reads an accumulator file that [`write`] wrote.
pub fn read(path: &Path) -> Result<Accumulators, String> {
    use exr::prelude::{AttributeValue, FlatSamples, ReadChannels, ReadLayers};
    let shown = path.display();
    let bad = |what: &str| format!("{shown}: not a Tesela accumulator file ({what})");
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| format!("{shown}: cannot read EXR: {e}"))?;
    let layer = &image.layer_data;
    let attr = |k: &str| -> Result<String, String> {
        layer
            .attributes
            .other
            .iter()
            .find(|(name, _)| **name == *k)
            .and_then(|(_, v)| match v {
                AttributeValue::Text(t) => Some(t.to_string()),
                _ => None,
            })
            .ok_or_else(|| bad(&format!("no {k} attribute")))
    };
    let format = attr("tesela.format")?;
    if format != FORMAT {
        return Err(bad(&format!(
            "format `{format}`, this renderer reads `{FORMAT}`"
        )));
    }
    let nums: Vec<u32> = attr("tesela.samples")?
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|_| bad("tesela.samples is not three numbers"))?;
    let [start, end, spp] = nums[..] else {
        return Err(bad("tesela.samples is not three numbers"));
    };
    if !(start < end && end <= spp) {
        return Err(bad(&format!("samples {start}:{end} of {spp}")));
    }
    // In the file's order: the layout of the records the part accumulated.
    let passes = attr("tesela.passes")?
        .split(',')
        .filter(|n| !n.is_empty())
        .map(|n| Pass::from_record_name(n).ok_or_else(|| bad(&format!("unknown pass `{n}`"))))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let passes = PassSet::new(passes);
    let (w, h) = (layer.size.width(), layer.size.height());
    let n = w * h;
    let channel = |name: &str| -> Result<&FlatSamples, String> {
        let c = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name == *name)
            .ok_or_else(|| bad(&format!("no channel {name}")))?;
        if c.sample_data.len() != n {
            return Err(bad(&format!("channel {name} has the wrong size")));
        }
        Ok(&c.sample_data)
    };
    let floats = |name: &str| -> Result<&[f32], String> {
        match channel(name)? {
            FlatSamples::F32(v) => Ok(v),
            _ => Err(bad(&format!("channel {name} is not 32-bit float"))),
        }
    };
    let counts = |name: &str| -> Result<&[u32], String> {
        match channel(name)? {
            FlatSamples::U32(v) => Ok(v),
            _ => Err(bad(&format!("channel {name} is not 32-bit unsigned"))),
        }
    };
    let sums = [floats(SUM[0])?, floats(SUM[1])?, floats(SUM[2])?];
    let (coverage, accepted, empty) = (floats(COVERAGE)?, counts(ACCEPTED)?, counts(EMPTY)?);
    let mut pixels = Vec::with_capacity(n);
    for i in 0..n {
        let p = PixelAcc {
            sum: glam::Vec3::new(sums[0][i], sums[1][i], sums[2][i]),
            coverage: coverage[i],
            accepted: accepted[i],
            empty: empty[i],
            next: end,
            ..Default::default()
        };
        if !(p.sum.is_finite() && p.coverage.is_finite())
            || p.accepted as u64 + p.empty as u64 > (end - start) as u64
        {
            return Err(bad(&format!(
                "pixel {} {} holds impossible sums",
                i % w,
                i / w
            )));
        }
        pixels.push(p);
    }
    let stride = passes.stride();
    let mut aovs = vec![0.0; n * stride];
    for (pass, at) in passes.iter() {
        for (c, id) in pass.channel_ids().chars().enumerate() {
            let v = floats(&pass_channel(pass, id))?;
            for (i, x) in v.iter().enumerate() {
                aovs[i * stride + at + c] = *x;
            }
        }
    }
    Ok(Accumulators {
        width: w as u32,
        height: h as u32,
        samples: start..end,
        spp,
        passes,
        transparent: attr("tesela.transparent")? == "1",
        key: attr("tesela.key")?,
        pixels,
        aovs,
    })
}
