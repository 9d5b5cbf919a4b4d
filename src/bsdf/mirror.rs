//! Perfect specular reflection off a conductor: `wo = (-wi.x, -wi.y, wi.z)`, weight = the
//! conductor's Fresnel at `cos θi`: Schlick with `F0 = base colour` (glTF metals; white stays
//! white at every angle), Cycles' F82-tint (the Principled BSDF's smooth metal), or a constant
//! colour (Blender's Glossy BSDF, which has no Fresnel).

use super::microfacet::ConductorFresnel;
use super::{Bsdf, BsdfQueryRecord, Measure};
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct Mirror {
    pub fresnel: ConductorFresnel,
}

impl Mirror {
    /// Schlick's Fresnel with `F0 = f0`.
    pub fn new(f0: Vec3) -> Self {
        Mirror {
            fresnel: ConductorFresnel::Schlick(f0),
        }
    }

    pub fn with_fresnel(fresnel: ConductorFresnel) -> Self {
        Mirror { fresnel }
    }
}

impl Bsdf for Mirror {
    fn sample(&self, rec: &mut BsdfQueryRecord, _u: Vec2, _u1: f32) -> Vec3 {
        if rec.wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        rec.wo = Vec3::new(-rec.wi.x, -rec.wi.y, rec.wi.z);
        rec.eta = 1.0;
        rec.measure = Measure::Discrete;
        rec.pdf = 0.0;
        self.fresnel.eval(rec.wi.z)
    }

    fn eval(&self, _rec: &BsdfQueryRecord) -> Vec3 {
        Vec3::ZERO
    }

    fn pdf(&self, _rec: &BsdfQueryRecord) -> f32 {
        0.0
    }

    fn is_delta(&self) -> bool {
        true
    }
}
