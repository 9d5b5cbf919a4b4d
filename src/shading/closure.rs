//! What a material's program produces at a shading point: weighted BSDF closures, emission and
//! transparency (Cycles' closure list). Vectors here are in the renderer's world space.

use glam::Vec3;

/// Most BSDF closures one shading point keeps (further ones are dropped with their weight
/// added to the strongest, as a documented limit).
pub const MAX_CLOSURES: usize = 8;

/// Blender's Principled BSDF parameters at a point (4.x/5.x meaning).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Principled {
    pub base_color: Vec3,
    pub metallic: f32,
    pub roughness: f32,
    pub ior: f32,
    /// Specular IOR Level (0.5 = the IOR's own reflectance; 0 = no specular layer).
    pub specular_level: f32,
    pub specular_tint: Vec3,
    pub transmission: f32,
    pub anisotropic: f32,
    pub anisotropic_rotation: f32,
    pub coat_weight: f32,
    pub coat_roughness: f32,
    pub coat_ior: f32,
    pub coat_tint: Vec3,
    /// Unit coat normal, world space.
    pub coat_normal: Vec3,
    pub sheen_weight: f32,
    pub sheen_roughness: f32,
    pub sheen_tint: Vec3,
    /// Share of the dielectric base that scatters below the surface (the rest is diffuse).
    pub subsurface_weight: f32,
    /// Mean free path per channel, in units of `subsurface_scale`.
    pub subsurface_radius: Vec3,
    pub subsurface_scale: f32,
    /// Henyey–Greenstein `g` inside.
    pub subsurface_anisotropy: f32,
    /// Oren–Nayar σ of the diffuse base (0: Lambert).
    pub diffuse_roughness: f32,
    /// Thin Film Thickness (nm) and IOR, where there is a film: it colours the specular and
    /// transmission lobes' reflectance.
    pub thin_film: Option<crate::bsdf::thin_film::ThinFilm>,
    /// Blender's Principled (F82 metals, multiple-scattering GGX, coat and sheen layers);
    /// false for glTF materials, which keep their Schlick metal and single-scattering GGX.
    pub cycles: bool,
    /// The Multiscatter GGX distribution (Blender's default), whose energy compensation the
    /// metal, specular and transmission lobes get; false for plain GGX.
    pub multiscatter: bool,
}

impl Principled {
    /// Every layer off (no base colour, specular, coat or sheen): a base for closures that
    /// are one of Principled's lobes on its own (Metallic BSDF, Sheen BSDF).
    pub fn lobe_only() -> Principled {
        Principled {
            base_color: Vec3::ZERO,
            metallic: 0.0,
            roughness: 0.5,
            ior: 1.5,
            specular_level: 0.0,
            specular_tint: Vec3::ONE,
            transmission: 0.0,
            anisotropic: 0.0,
            anisotropic_rotation: 0.0,
            coat_weight: 0.0,
            coat_roughness: 0.03,
            coat_ior: 1.5,
            coat_tint: Vec3::ONE,
            coat_normal: Vec3::ZERO,
            sheen_weight: 0.0,
            sheen_roughness: 0.5,
            sheen_tint: Vec3::ONE,
            subsurface_weight: 0.0,
            subsurface_radius: Vec3::ONE,
            subsurface_scale: 0.0,
            subsurface_anisotropy: 0.0,
            diffuse_roughness: 0.0,
            thin_film: None,
            cycles: true,
            multiscatter: true,
        }
    }
}

/// One BSDF closure's kind and parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ClosureKind {
    Principled(Principled),
    /// Lambert, or Oren–Nayar where `roughness` (σ) is above zero.
    Diffuse {
        color: Vec3,
        roughness: f32,
        /// The clamped colour Oren–Nayar's multiple-scattering term takes (Cycles passes it
        /// beside the weight, which carries the colour too).
        albedo: Vec3,
    },
    /// Microfacet reflection without Fresnel (Blender's Glossy/Anisotropic BSDF).
    Glossy {
        color: Vec3,
        roughness: f32,
        anisotropy: f32,
        rotation: f32,
        /// Multiple-scattering GGX (energy compensation), Blender's default distribution.
        multiscatter: bool,
        /// The Beckmann distribution (else GGX).
        beckmann: bool,
        /// The node's colour, which is in the closure's weight; the energy compensation takes
        /// it as the average reflectance `F_ss`, as Cycles' constant-Fresnel setup does.
        tint: Vec3,
    },
    /// Dielectric reflection and refraction (Blender's Glass BSDF).
    Glass {
        color: Vec3,
        roughness: f32,
        ior: f32,
        multiscatter: bool,
        /// The Beckmann distribution (else GGX).
        beckmann: bool,
        /// The node's colour, in the closure's weight: `F_ss` of the energy compensation (Cycles
        /// takes the transmission tint).
        tint: Vec3,
    },
    /// Dielectric refraction only (Blender's Refraction BSDF).
    Refraction {
        color: Vec3,
        roughness: f32,
        ior: f32,
        /// The Beckmann distribution (else GGX).
        beckmann: bool,
    },
    /// Lambertian transmission.
    Translucent {
        color: Vec3,
    },
    /// Blender's Toon BSDF: Size and Smooth as the node gives them (fractions of a right
    /// angle), about the normal or (Glossy) the mirror direction.
    Toon {
        color: Vec3,
        size: f32,
        smooth: f32,
        glossy: bool,
    },
    /// Blender's Principled Hair BSDF (Chiang model) on a strand: the closure's tangent is the
    /// curve's direction (world space); the offset `h` across the fibre is found where the
    /// shading point is set up, from the tangent, the normal and the viewer. Its Random input
    /// is already resolved (the linked socket, else the strand's random number).
    Hair(crate::bsdf::hair::PrincipledHair),
    /// Subsurface scattering (Blender's Subsurface Scattering node): a random walk below the
    /// surface; its colour is in the closure's weight, and also its albedo here.
    Subsurface {
        albedo: Vec3,
        /// Mean free path per channel, world units (Radius × Scale).
        radius: Vec3,
        ior: f32,
        roughness: f32,
        anisotropy: f32,
    },
    /// Straight pass-through.
    Transparent {
        color: Vec3,
    },
}

impl ClosureKind {
    /// A Lambertian diffuse closure of `color`.
    pub const fn lambert(color: Vec3) -> ClosureKind {
        ClosureKind::Diffuse {
            color,
            roughness: 0.0,
            albedo: Vec3::ZERO,
        }
    }
}

/// A closure with its weight (the product of the mix factors above it and the node's own
/// weight) and its shading normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closure {
    pub weight: Vec3,
    /// Unit shading normal, world space, on the side the ray came from (as Cycles' `N`).
    pub normal: Vec3,
    /// Unit tangent (world space) for anisotropic lobes; zero when the mesh has none.
    pub tangent: Vec3,
    /// The surface normal Cycles' bump corrections compare `normal` with (its `sd->N`), world
    /// space: zero for the interpolated normal, else the normal a displacement made.
    pub surface_normal: Vec3,
    pub kind: ClosureKind,
}

/// Everything a shading point's program produced.
#[derive(Clone, Debug)]
pub struct ClosureSet {
    pub closures: [Closure; MAX_CLOSURES],
    pub len: usize,
    /// Emitted radiance, W/(m² sr) (sum of emission closures times their weights).
    pub emission: Vec3,
    /// Absorption coefficient σ_a per channel, 1/m (a volume's absorption closures times
    /// their weights; zero for surfaces).
    pub absorption: Vec3,
    /// Scattering coefficient σ_s per channel, 1/m (a volume's scatter closures).
    pub scatter: Vec3,
    /// Sum of the scatter closures' anisotropies weighted by the mean of their σ_s.
    pub scatter_g: f32,
    /// Whether scatter closures of different anisotropy were added (they render as one
    /// Henyey–Greenstein lobe of the weighted mean anisotropy).
    pub mixed_phase: bool,
    /// Holdout weight (Holdout closures): the share of the pixel a transparent film leaves
    /// transparent where the camera sees the surface.
    pub holdout: Vec3,
}

const EMPTY: Closure = Closure {
    weight: Vec3::ZERO,
    normal: Vec3::Z,
    tangent: Vec3::ZERO,
    surface_normal: Vec3::ZERO,
    kind: ClosureKind::lambert(Vec3::ZERO),
};

impl Default for ClosureSet {
    fn default() -> Self {
        ClosureSet {
            closures: [EMPTY; MAX_CLOSURES],
            len: 0,
            emission: Vec3::ZERO,
            absorption: Vec3::ZERO,
            scatter: Vec3::ZERO,
            scatter_g: 0.0,
            mixed_phase: false,
            holdout: Vec3::ZERO,
        }
    }
}

impl ClosureSet {
    pub fn clear(&mut self) {
        self.len = 0;
        self.emission = Vec3::ZERO;
        self.absorption = Vec3::ZERO;
        self.scatter = Vec3::ZERO;
        self.scatter_g = 0.0;
        self.mixed_phase = false;
        self.holdout = Vec3::ZERO;
    }

    /// The closures present.
    pub fn closures(&self) -> &[Closure] {
        &self.closures[..self.len]
    }

    /// Adds a BSDF closure; zero or non-finite weights are dropped. Past [`MAX_CLOSURES`], the
    /// closure's weight goes to the strongest kept one (energy kept, lobe shape lost).
    pub fn push(&mut self, c: Closure) {
        if c.weight.max_element() <= 0.0 || !c.weight.is_finite() {
            return;
        }
        if self.len < MAX_CLOSURES {
            self.closures[self.len] = c;
            self.len += 1;
        } else if let Some(s) = self
            .closures
            .iter_mut()
            .max_by(|a, b| a.weight.element_sum().total_cmp(&b.weight.element_sum()))
        {
            s.weight += c.weight;
        }
    }

    /// Adds a straight pass-through of weight `w`.
    pub fn push_transparent(&mut self, w: Vec3) {
        self.push(Closure {
            weight: w,
            normal: Vec3::ZERO,
            tangent: Vec3::ZERO,
            surface_normal: Vec3::ZERO,
            kind: ClosureKind::Transparent { color: Vec3::ONE },
        });
    }

    /// Adds emitted radiance; a negative one takes light away, as Cycles' emission closures
    /// with a negative colour or strength do.
    pub fn add_emission(&mut self, e: Vec3) {
        if e.is_finite() {
            self.emission += e;
        }
    }

    pub fn add_absorption(&mut self, sigma: Vec3) {
        if sigma.is_finite() {
            self.absorption += sigma.max(Vec3::ZERO);
        }
    }

    /// The straight-through transmittance: the sum of the transparent closures' weights.
    pub fn transparency(&self) -> Vec3 {
        self.closures()
            .iter()
            .filter(|c| matches!(c.kind, ClosureKind::Transparent { .. }))
            .map(|c| c.weight)
            .sum()
    }

    pub fn add_holdout(&mut self, w: Vec3) {
        if w.is_finite() {
            self.holdout += w.max(Vec3::ZERO);
        }
    }

    /// Adds a volume scatter closure of coefficient `sigma` (1/m) and Henyey–Greenstein
    /// anisotropy `g`.
    pub fn add_scatter(&mut self, sigma: Vec3, g: f32) {
        let sigma = sigma.max(Vec3::ZERO);
        let w = sigma.element_sum() / 3.0;
        if !(w > 0.0 && w.is_finite() && g.is_finite()) {
            return;
        }
        let before = self.scatter.element_sum() / 3.0;
        if before > 0.0 && (self.scatter_g / before - g).abs() > 1e-4 {
            self.mixed_phase = true;
        }
        self.scatter += sigma;
        self.scatter_g += w * g;
    }

    /// The homogeneous medium of a volume's closures (emission: the emission closures, which
    /// in a volume are radiance per metre).
    pub fn medium(&self) -> crate::medium::Medium {
        let w = self.scatter.element_sum() / 3.0;
        crate::medium::Medium {
            sigma_a: self.absorption,
            sigma_s: self.scatter,
            g: if w > 0.0 { self.scatter_g / w } else { 0.0 },
            emission: self.emission,
        }
        .sanitized()
    }

    /// Chooses closure `i` with probability proportional to the mean of its weight, reusing
    /// `u` (returned rescaled to `[0, 1)` for the closure's own choices). `None` when there is
    /// no closure. With one closure, `u` is returned unchanged.
    #[inline]
    pub fn choose(&self, u: f32) -> Option<(usize, f32, f32)> {
        match self.len {
            0 => None,
            1 => Some((0, 1.0, u)),
            n => {
                let total: f32 = self.closures[..n]
                    .iter()
                    .map(|c| c.weight.element_sum())
                    .sum();
                let mut acc = 0.0;
                for (i, c) in self.closures[..n].iter().enumerate() {
                    let w = c.weight.element_sum();
                    if u * total < acc + w || i == n - 1 {
                        let p = w / total;
                        let r = ((u * total - acc) / w).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
                        return Some((i, p, r));
                    }
                    acc += w;
                }
                None
            }
        }
    }
}
