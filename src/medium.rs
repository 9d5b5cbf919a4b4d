//! Homogeneous absorbing interiors: a closed mesh whose material has a volume (Blender's
//! Volume Absorption, glTF's `KHR_materials_volume` attenuation) attenuates the light that
//! travels inside it by Beer's law. Like Cycles' volume stack, a ray enters the interior when it
//! crosses such a surface from its front (outer) side and leaves it when it crosses back;
//! surfaces without a volume leave the current medium as it is. One level: an absorbing mesh
//! inside another is left into the clear medium.

use crate::render_scene::{Intersection, RenderScene};
use glam::Vec3;

/// Beer–Lambert transmittance `exp(-σ t)` per channel over distance `t` (which may be
/// infinite); a channel with `σ = 0` transmits everything.
#[inline]
pub fn transmittance(sigma: Vec3, t: f32) -> Vec3 {
    let f = |s: f32| if s > 0.0 { (-s * t).exp() } else { 1.0 };
    Vec3::new(f(sigma.x), f(sigma.y), f(sigma.z))
}

/// The absorption coefficient (1/m) of the medium a ray is in after it meets `its` travelling
/// along `d` and leaves along `wo`, when it was in `current` before: a crossing into an
/// absorbing mesh (from the side its normal points to) enters its interior, a crossing out of
/// one leaves into the clear medium, and reflections and surfaces without a volume change
/// nothing.
#[inline]
pub fn after(scene: &RenderScene, its: &Intersection, d: Vec3, wo: Vec3, current: Vec3) -> Vec3 {
    let (into, out) = (d.dot(its.ng), wo.dot(its.ng));
    if into * out <= 0.0 {
        return current;
    }
    let sigma = scene.programs[its.material as usize].absorption();
    if sigma == Vec3::ZERO {
        current
    } else if into < 0.0 {
        sigma
    } else {
        Vec3::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transmittance_is_beers_law_and_clear_channels_pass_any_distance() {
        let t = transmittance(Vec3::new(0.0, 1.0, 2.0), 0.5);
        assert_eq!(t.x, 1.0);
        assert!((t.y - (-0.5f32).exp()).abs() < 1e-7);
        assert!((t.z - (-1.0f32).exp()).abs() < 1e-7);
        assert_eq!(
            transmittance(Vec3::new(0.0, 1.0, 0.0), f32::INFINITY),
            Vec3::new(1.0, 0.0, 1.0)
        );
    }
}
