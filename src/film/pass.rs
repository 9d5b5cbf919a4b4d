//! The render passes besides Combined, with Cycles' names and meanings.

/// One auxiliary pass of the film. Names and channel layouts are Blender's (what Cycles
/// registers in a view layer), so the add-on can fill the render result directly.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Pass {
    /// Camera-space depth of the first surface (distance along the view axis; ray length for
    /// panoramic cameras), from the pixel's first sample; 1e10 where the ray escapes.
    Depth,
    /// `1 - (1 - mist) · alpha` averaged, with Blender's mist start, depth and falloff.
    Mist,
    /// Average closure normal at the first surface, Blender world space (Z up).
    Normal,
    /// First surface position, Blender world space, from the pixel's first sample.
    Position,
    /// First UV map at the first surface: `(u, v, 1)`, Blender's convention (v up).
    Uv,
    /// The object's pass index (Object > Relations), from the pixel's first sample.
    ObjectIndex,
    /// The material's pass index (Material > Settings), from the pixel's first sample.
    MaterialIndex,
    /// Emission seen directly by the camera (surfaces and lights), through transparency.
    Emission,
    /// The world seen directly by the camera, even with a transparent film.
    Environment,
    /// The denoiser's normal feature: albedo-weighted closure normal, Blender world space.
    DenoisingNormal,
    /// The denoiser's albedo feature: the summed closure albedo at the first surface.
    DenoisingAlbedo,
    /// Cycles' light passes: the radiance that reached the camera through a first bounce of
    /// that class (diffuse, glossy, transmission: the sampled closure's class, see
    /// [`crate::bsdf::Bsdf::eval_split`]), *divided by the pass's colour* as Cycles shows it.
    /// Direct is light sampled at the first bounce and emission met by the ray leaving it;
    /// Indirect all that comes later. So `(Direct + Indirect) · Color` of the three classes,
    /// plus Emission and Environment, is Combined: per pixel where the camera sees opaque
    /// surfaces, in expectation through partly transparent ones (Emission and Environment
    /// weight what lies behind by the transparency, a path picks it at random) or with
    /// clamping (which Emission and Environment do not apply).
    DiffuseDirect,
    DiffuseIndirect,
    /// The summed albedo of the diffuse closures (Cycles' `bsdf_albedo`) where the camera
    /// path first scatters, weighted by the transparency in front.
    DiffuseColor,
    GlossyDirect,
    GlossyIndirect,
    /// The glossy closures' albedo (reflection part of glass lobes included).
    GlossyColor,
    TransmissionDirect,
    TransmissionIndirect,
    /// The transmission closures' albedo (refraction part of glass lobes included).
    TransmissionColor,
    /// Combined before denoising (Cycles registers it when the view layer is denoised).
    NoisyImage,
    /// Cycles' Shadow Catcher pass: per channel, the light the shadow catchers receive with
    /// the other objects over the light they receive without them (1 where no catcher is
    /// seen), over white by the alpha of the film ([`crate::film::catcher`]).
    ShadowCatcher,
    /// The film's own sums for shadow catchers, never shown ([`crate::film::catcher`]): the
    /// matte (RGB, transparency), the catchers' light without the other objects (RGB, the
    /// samples that met a catcher) and the world behind them (RGB).
    CatcherSums,
}

/// The light-pass classes of a camera path's first bounce, in Cycles' order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightClass {
    Diffuse = 0,
    Glossy = 1,
    Transmission = 2,
}

impl LightClass {
    pub const ALL: [LightClass; 3] = [
        LightClass::Diffuse,
        LightClass::Glossy,
        LightClass::Transmission,
    ];

    /// `(direct, indirect, color)` passes of the class.
    pub fn passes(self) -> (Pass, Pass, Pass) {
        match self {
            LightClass::Diffuse => (
                Pass::DiffuseDirect,
                Pass::DiffuseIndirect,
                Pass::DiffuseColor,
            ),
            LightClass::Glossy => (Pass::GlossyDirect, Pass::GlossyIndirect, Pass::GlossyColor),
            LightClass::Transmission => (
                Pass::TransmissionDirect,
                Pass::TransmissionIndirect,
                Pass::TransmissionColor,
            ),
        }
    }
}

impl Pass {
    pub const ALL: [Pass; 22] = [
        Pass::Depth,
        Pass::Mist,
        Pass::Normal,
        Pass::Position,
        Pass::Uv,
        Pass::ObjectIndex,
        Pass::MaterialIndex,
        Pass::Emission,
        Pass::Environment,
        Pass::DenoisingNormal,
        Pass::DenoisingAlbedo,
        Pass::DiffuseDirect,
        Pass::DiffuseIndirect,
        Pass::DiffuseColor,
        Pass::GlossyDirect,
        Pass::GlossyIndirect,
        Pass::GlossyColor,
        Pass::TransmissionDirect,
        Pass::TransmissionIndirect,
        Pass::TransmissionColor,
        Pass::NoisyImage,
        Pass::ShadowCatcher,
    ];

    /// The command line's name (`--passes depth,normal,...`).
    pub fn name(self) -> &'static str {
        match self {
            Pass::Depth => "depth",
            Pass::Mist => "mist",
            Pass::Normal => "normal",
            Pass::Position => "position",
            Pass::Uv => "uv",
            Pass::ObjectIndex => "object_index",
            Pass::MaterialIndex => "material_index",
            Pass::Emission => "emission",
            Pass::Environment => "environment",
            Pass::DenoisingNormal => "denoising_normal",
            Pass::DenoisingAlbedo => "denoising_albedo",
            Pass::DiffuseDirect => "diffuse_direct",
            Pass::DiffuseIndirect => "diffuse_indirect",
            Pass::DiffuseColor => "diffuse_color",
            Pass::GlossyDirect => "glossy_direct",
            Pass::GlossyIndirect => "glossy_indirect",
            Pass::GlossyColor => "glossy_color",
            Pass::TransmissionDirect => "transmission_direct",
            Pass::TransmissionIndirect => "transmission_indirect",
            Pass::TransmissionColor => "transmission_color",
            Pass::NoisyImage => "noisy_image",
            Pass::ShadowCatcher => "shadow_catcher",
            Pass::CatcherSums => "catcher_sums",
        }
    }

    /// Blender's render pass name (3.x's; the add-on maps it to later Blenders' names).
    pub fn blender_name(self) -> &'static str {
        match self {
            Pass::Depth => "Depth",
            Pass::Mist => "Mist",
            Pass::Normal => "Normal",
            Pass::Position => "Position",
            Pass::Uv => "UV",
            Pass::ObjectIndex => "IndexOB",
            Pass::MaterialIndex => "IndexMA",
            Pass::Emission => "Emit",
            Pass::Environment => "Env",
            Pass::DenoisingNormal => "Denoising Normal",
            Pass::DenoisingAlbedo => "Denoising Albedo",
            Pass::DiffuseDirect => "DiffDir",
            Pass::DiffuseIndirect => "DiffInd",
            Pass::DiffuseColor => "DiffCol",
            Pass::GlossyDirect => "GlossDir",
            Pass::GlossyIndirect => "GlossInd",
            Pass::GlossyColor => "GlossCol",
            Pass::TransmissionDirect => "TransDir",
            Pass::TransmissionIndirect => "TransInd",
            Pass::TransmissionColor => "TransCol",
            Pass::NoisyImage => "Noisy Image",
            Pass::ShadowCatcher => "Shadow Catcher",
            Pass::CatcherSums => "Catcher Sums",
        }
    }

    /// Blender's channel ids, one letter per channel.
    pub fn channel_ids(self) -> &'static str {
        match self {
            Pass::Depth | Pass::Mist => "Z",
            Pass::ObjectIndex | Pass::MaterialIndex => "X",
            Pass::Normal | Pass::Position | Pass::DenoisingNormal => "XYZ",
            Pass::Uv => "UVA",
            Pass::NoisyImage => "RGBA",
            // Unique letters for the accumulator files' channel names.
            Pass::CatcherSums => "RGBTKLMNXYZ",
            _ => "RGB",
        }
    }

    pub fn channels(self) -> usize {
        self.channel_ids().len()
    }

    pub fn from_name(name: &str) -> Option<Pass> {
        Pass::ALL.into_iter().find(|p| p.name() == name)
    }

    /// [`Pass::from_name`], also for the film's own records (which no one asks to render).
    pub fn from_record_name(name: &str) -> Option<Pass> {
        Pass::from_name(name).or((name == Pass::CatcherSums.name()).then_some(Pass::CatcherSums))
    }

    /// The light class of a Direct or Indirect pass, and whether it is the direct one.
    pub fn light(self) -> Option<(LightClass, bool)> {
        LightClass::ALL.into_iter().find_map(|c| {
            let (d, i, _) = c.passes();
            (self == d || self == i).then_some((c, self == d))
        })
    }

    /// Written by the pixel's first sample only, as Cycles writes it (an average of depths or
    /// indices across an edge means nothing).
    pub fn first_sample_only(self) -> bool {
        matches!(
            self,
            Pass::Depth | Pass::Position | Pass::ObjectIndex | Pass::MaterialIndex
        )
    }
}

/// The enabled passes in a fixed order, with each one's offset in a pixel's channel record.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PassSet {
    passes: Vec<Pass>,
    offsets: Vec<usize>,
    stride: usize,
}

impl PassSet {
    /// The passes named in `names` (command-line names, or Blender's), in [`Pass::ALL`]'s
    /// order, each once. An unknown name is an error listing the known ones.
    pub fn parse<'a>(names: impl IntoIterator<Item = &'a str>) -> Result<PassSet, String> {
        let mut want = Vec::new();
        for n in names {
            let n = n.trim();
            if n.is_empty() {
                continue;
            }
            let p = Pass::from_name(n)
                .or_else(|| Pass::ALL.into_iter().find(|p| p.blender_name() == n))
                .ok_or_else(|| {
                    format!(
                        "unknown pass `{n}` (known passes: {})",
                        Pass::ALL.map(Pass::name).join(", ")
                    )
                })?;
            want.push(p);
        }
        Ok(PassSet::new(
            Pass::ALL.into_iter().filter(|p| want.contains(p)),
        ))
    }

    pub fn new(passes: impl IntoIterator<Item = Pass>) -> PassSet {
        let mut set = PassSet::default();
        for p in passes {
            if set.passes.contains(&p) {
                continue;
            }
            set.offsets.push(set.stride);
            set.stride += p.channels();
            set.passes.push(p);
        }
        set
    }

    /// This set plus what its passes are computed from: the Color pass of every Direct or
    /// Indirect pass (Cycles divides those by it when they are read).
    pub fn with_dividers(&self) -> PassSet {
        let need = |p: Pass| {
            self.contains(p)
                || LightClass::ALL.into_iter().any(|c| {
                    let (d, i, col) = c.passes();
                    p == col && (self.contains(d) || self.contains(i))
                })
        };
        PassSet::new(Pass::ALL.into_iter().filter(|&p| need(p)))
    }

    /// This set plus the shadow catchers' sums ([`Pass::CatcherSums`]), last.
    pub fn with_catcher(&self) -> PassSet {
        PassSet::new(self.passes.iter().copied().chain([Pass::CatcherSums]))
    }

    /// True when any Direct or Indirect light pass is enabled.
    pub fn has_light(&self) -> bool {
        self.passes.iter().any(|p| p.light().is_some())
    }

    pub fn is_empty(&self) -> bool {
        self.passes.is_empty()
    }

    pub fn contains(&self, p: Pass) -> bool {
        self.passes.contains(&p)
    }

    /// The offset of pass `p` in a pixel's record, if enabled.
    #[inline]
    pub fn offset(&self, p: Pass) -> Option<usize> {
        self.passes
            .iter()
            .position(|&q| q == p)
            .map(|i| self.offsets[i])
    }

    /// Channels per pixel, all passes together.
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// `(pass, offset)` in order.
    pub fn iter(&self) -> impl Iterator<Item = (Pass, usize)> + '_ {
        self.passes
            .iter()
            .copied()
            .zip(self.offsets.iter().copied())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_in_canonical_order_with_offsets() {
        let s = PassSet::parse(["normal", "Depth", "uv", "depth"]).unwrap();
        let got: Vec<_> = s.iter().collect();
        assert_eq!(
            got,
            vec![(Pass::Depth, 0), (Pass::Normal, 1), (Pass::Uv, 4)]
        );
        assert_eq!(s.stride(), 7);
        let s = PassSet::parse(["glossy_indirect", "DiffDir", "depth"]).unwrap();
        let full = s.with_dividers();
        let names: Vec<_> = full.iter().map(|(p, _)| p.name()).collect();
        assert_eq!(
            names,
            [
                "depth",
                "diffuse_direct",
                "diffuse_color",
                "glossy_indirect",
                "glossy_color"
            ]
        );
        assert_eq!(full.with_dividers(), full);
        assert!(s.has_light() && !PassSet::parse(["diffuse_color"]).unwrap().has_light());
        let e = PassSet::parse(["depth", "shiny"]).unwrap_err();
        assert!(e.contains("`shiny`") && e.contains("object_index"), "{e}");
    }

    #[test]
    fn every_pass_has_distinct_names() {
        for (i, a) in Pass::ALL.iter().enumerate() {
            assert_eq!(Pass::from_name(a.name()), Some(*a));
            for b in &Pass::ALL[i + 1..] {
                assert_ne!(a.name(), b.name());
                assert_ne!(a.blender_name(), b.blender_name());
            }
        }
    }
}
