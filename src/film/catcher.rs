//! Shadow catchers (Blender's Object > Visibility > Shadow Catcher), as Cycles forms them.
//!
//! Where a camera ray first meets a catcher, the sample's path is split: one path goes on as
//! usual (the catcher an ordinary object: Combined `C`), a second one with the same random
//! numbers sees the catchers alone (`K`: the catcher's light without the other objects'
//! shadows and reflections). Samples whose camera ray meets something else form the *matte*
//! `M`, their Combined; a catcher sample adds nothing to it but its full transparency. Per
//! pixel, over the samples' sums:
//!
//! * shadow `S = (ΣC − ΣM) / ΣK` per channel (1 where `ΣK = 0`, or where no sample met a
//!   catcher), over white by Combined's alpha `a_C`: `S' = (1 − a_C) + a_C S`; this is the
//!   Shadow Catcher pass;
//! * the matte's alpha `a_M = 1 − Σ transparency / n` and the shadow's alpha
//!   `a = (1 − a_M) (1 − clamp(mean_rgb S', 0, 1)) + a_M`;
//! * Combined is `(ΣM / n, a)` with a transparent film; with an opaque one the matte over the
//!   world `B` seen behind the catchers (and directly): `(ΣM / n + (1 − a) ΣB / n, 1)`.
//!   When the Shadow Catcher pass is rendered (for compositing the shadows apart, Cycles'
//!   exact mode), Combined is the matte alone, `(ΣM / n, a_M)`, with either film.
//!
//! So a transparent film shows the other objects over black shadows whose alpha is how much
//! light they take from the catcher (light the objects add, brighter than without them, shows
//! as no shadow).

use super::PixelAcc;
use glam::Vec3;

/// Offsets in the [`super::Pass::CatcherSums`] record.
const MATTE: usize = 0;
const MATTE_TRANSPARENCY: usize = 3;
const LIGHT: usize = 4;
const SAMPLES: usize = 7;
const BACKGROUND: usize = 8;

#[inline]
fn add(rec: &mut [f32], at: usize, v: Vec3) {
    rec[at] += v.x;
    rec[at + 1] += v.y;
    rec[at + 2] += v.z;
}

#[inline]
fn rgb(rec: &[f32], at: usize) -> Vec3 {
    Vec3::new(rec[at], rec[at + 1], rec[at + 2])
}

/// Adds a sample whose camera ray met a catcher: `light` is the catchers-only path's radiance,
/// `world` the world's radiance along the camera ray (zero with a transparent film).
pub fn add_split(rec: &mut [f32], light: Vec3, world: Vec3) {
    rec[MATTE_TRANSPARENCY] += 1.0;
    add(rec, LIGHT, light);
    rec[SAMPLES] += 1.0;
    add(rec, BACKGROUND, world);
}

/// Adds a sample whose camera ray met no catcher first: its Combined radiance `l` and
/// transparency, and the world it sees directly (zero otherwise, or with a transparent film).
pub fn add_matte(rec: &mut [f32], l: Vec3, transparency: f32, world: Vec3) {
    add(rec, MATTE, l);
    rec[MATTE_TRANSPARENCY] += transparency;
    add(rec, BACKGROUND, world);
}

/// Combined (RGBA) and the Shadow Catcher pass of pixel `p` with the catcher sums `rec`
/// (see the module's formulas); `with_shadow`: Combined carries the shadows (no Shadow
/// Catcher pass is rendered).
pub fn resolve(
    p: &PixelAcc,
    rec: &[f32],
    transparent: bool,
    with_shadow: bool,
) -> ([f32; 4], Vec3) {
    let n = p.n();
    if n == 0 {
        return ([0.0; 4], Vec3::ONE);
    }
    let inv = 1.0 / n as f32;
    let matte = rgb(rec, MATTE);
    let alpha_c = if transparent {
        (p.coverage * inv).clamp(0.0, 1.0)
    } else {
        1.0
    };
    let shadow = if rec[SAMPLES] == 0.0 {
        Vec3::ONE
    } else {
        let (num, den) = (p.sum - matte, rgb(rec, LIGHT));
        let q = |a: f32, b: f32| if b != 0.0 { a / b } else { 1.0 };
        Vec3::new(q(num.x, den.x), q(num.y, den.y), q(num.z, den.z))
    };
    let shadow = Vec3::splat(1.0 - alpha_c) + alpha_c * shadow;
    let alpha_m = (1.0 - rec[MATTE_TRANSPARENCY] * inv).clamp(0.0, 1.0);
    let alpha = (1.0 - alpha_m) * (1.0 - (shadow.element_sum() / 3.0).clamp(0.0, 1.0)) + alpha_m;
    let m = matte * inv;
    let rgba = if !with_shadow {
        [m.x, m.y, m.z, alpha_m]
    } else if transparent {
        [m.x, m.y, m.z, alpha]
    } else {
        let c = m + rgb(rec, BACKGROUND) * inv * (1.0 - alpha);
        [c.x, c.y, c.z, 1.0]
    };
    (rgba, shadow)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixel(sum: Vec3, coverage: f32, n: u32) -> PixelAcc {
        PixelAcc {
            sum,
            coverage,
            accepted: n,
            ..Default::default()
        }
    }

    #[test]
    fn a_catcher_in_half_shadow_is_a_black_matte_of_half_alpha() {
        // Four samples on the catcher: lit 0.4 with the objects, 0.8 without.
        let mut rec = [0.0; 11];
        for _ in 0..4 {
            add_split(&mut rec, Vec3::splat(0.8), Vec3::ZERO);
        }
        let p = pixel(Vec3::splat(1.6), 4.0, 4);
        let (rgba, shadow) = resolve(&p, &rec, true, true);
        assert_eq!(rgba, [0.0, 0.0, 0.0, 0.5]);
        assert_eq!(shadow, Vec3::splat(0.5));
        // An opaque film shows the world behind, darkened by the shadow.
        let mut rec = [0.0; 11];
        for _ in 0..4 {
            add_split(&mut rec, Vec3::splat(0.8), Vec3::new(0.2, 0.4, 0.6));
        }
        let (rgba, _) = resolve(&p, &rec, false, true);
        let want = [0.1, 0.2, 0.3, 1.0];
        for (a, b) in rgba.iter().zip(want) {
            assert!((a - b).abs() < 1e-6, "{rgba:?}");
        }
        // With the Shadow Catcher pass apart, Combined is the matte: a hole.
        assert_eq!(resolve(&p, &rec, false, false).0, [0.0; 4]);
    }

    #[test]
    fn objects_and_the_world_keep_their_matte_and_light_added_shows_no_shadow() {
        // Two samples see an object (0.3, opaque), two the world through a transparent film.
        let mut rec = [0.0; 11];
        add_matte(&mut rec, Vec3::splat(0.3), 0.0, Vec3::ZERO);
        add_matte(&mut rec, Vec3::splat(0.3), 0.0, Vec3::ZERO);
        add_matte(&mut rec, Vec3::ZERO, 1.0, Vec3::ZERO);
        add_matte(&mut rec, Vec3::ZERO, 1.0, Vec3::ZERO);
        let p = pixel(Vec3::splat(0.6), 2.0, 4);
        let (rgba, shadow) = resolve(&p, &rec, true, true);
        assert_eq!(rgba, [0.15, 0.15, 0.15, 0.5]);
        assert_eq!(shadow, Vec3::ONE);
        // A catcher brighter with the objects than without: no shadow, alpha 0.
        let mut rec = [0.0; 11];
        add_split(&mut rec, Vec3::splat(0.5), Vec3::ZERO);
        let p = pixel(Vec3::splat(0.7), 1.0, 1);
        let (rgba, shadow) = resolve(&p, &rec, true, true);
        assert_eq!(rgba, [0.0; 4]);
        assert!((shadow - Vec3::splat(1.4)).abs().max_element() < 1e-6);
    }
}
