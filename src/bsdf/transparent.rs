//! A delta pass-through (Blender's Transparent BSDF): `wo = -wi`, weight = colour, relative
//! index 1. Cycles folds transparency into the same closure (Principled's Alpha < 1 adds a
//! transparent closure of weight `1 - alpha`).

use super::{Bsdf, BsdfQueryRecord, Measure};
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct Transparent {
    pub color: Vec3,
}

impl Transparent {
    /// `color` = the node's Color input (or `1 - alpha` for Principled's Alpha).
    pub fn new(color: Vec3) -> Self {
        Transparent { color }
    }
}

impl Bsdf for Transparent {
    fn sample(&self, rec: &mut BsdfQueryRecord, _u: Vec2, _u1: f32) -> Vec3 {
        if rec.wi.z == 0.0 {
            return Vec3::ZERO;
        }
        rec.wo = -rec.wi;
        rec.eta = 1.0;
        rec.measure = Measure::Discrete;
        rec.pdf = 0.0;
        self.color
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
