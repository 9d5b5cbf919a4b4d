//! The Bump node: the height input evaluated at the point and at two nearby points on the
//! surface, turned into a perturbed normal with Cycles' surface-gradient formula.

use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::ShaderGlobals;
use crate::shading::program::{Op, Slot, Slots};
use glam::Vec3;

#[derive(Clone, Copy, Debug)]
pub enum BumpOp {
    /// Operations up to `Leave` run at the point moved along bump axis `axis` (1 or 2).
    Enter {
        axis: u8,
    },
    Leave,
    /// From here on the shading normal `N` is the unit vector in slot `n` (Cycles' Set Normal,
    /// after a displacement rendered as bump).
    SetNormal {
        n: Slot,
    },
    Normal {
        strength: Slot,
        distance: Slot,
        invert: bool,
        /// Height at the point and at its two offsets.
        h: [Slot; 3],
        normal: Option<Slot>,
        out: Slot,
    },
}

/// `v / |v|`, or zero for a zero, infinite or NaN `v`.
pub(super) fn safe_normalize(v: Vec3) -> Vec3 {
    let l = v.length();
    if l > 0.0 && l.is_finite() {
        v / l
    } else {
        Vec3::ZERO
    }
}

impl BumpOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals) {
        let BumpOp::Normal {
            strength,
            distance,
            invert,
            h,
            normal,
            out,
        } = *self
        else {
            return;
        };
        let n_in = normal.map_or(g.n, |n| {
            let v = safe_normalize(s.v(n));
            if v == Vec3::ZERO { g.n } else { v }
        });
        let mut dist = s.f(distance);
        if invert {
            dist = -dist;
        }
        let h = [s.f(h[0]), s.f(h[1]), s.f(h[2])];
        s.set_v(out, bumped_normal(g, n_in, h, dist, s.f(strength)));
    }
}

/// Cycles' bump formula: the unit normal `n_in` tilted by the surface gradient of the heights
/// `h` at the point and at its two offsets along [`ShaderGlobals::bump_axes`], scaled by
/// `distance`, blended with `n_in` by `strength` (clamped below at 0); `n_in` where it fails.
#[inline]
pub fn bumped_normal(
    g: &ShaderGlobals,
    n_in: Vec3,
    h: [f32; 3],
    distance: f32,
    strength: f32,
) -> Vec3 {
    let (dpdx, dpdy) = g.bump_axes();
    let rx = dpdy.cross(n_in);
    let ry = n_in.cross(dpdx);
    let [hc, hx, hy] = h;
    let det = dpdx.dot(rx);
    let surfgrad = (hx - hc) * rx + (hy - hc) * ry;
    let k = strength.max(0.0);
    let n = safe_normalize(det.abs() * n_in - distance * det.signum() * surfgrad);
    let n = if n == Vec3::ZERO || !n.is_finite() {
        n_in
    } else {
        safe_normalize(k * n + (1.0 - k) * n_in)
    };
    if n == Vec3::ZERO { n_in } else { n }
}

pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    if kind != "ShaderNodeBump" {
        return Ok(false);
    }
    let strength = cx.float("Strength", 1.0)?;
    let distance = cx.float("Distance", 1.0)?;
    let invert = cx.prop_bool("invert", false);
    let normal = cx.linked_vector("Normal")?;
    let out = cx.output("Normal", SocketType::Vector)?;
    if !cx.is_linked("Height") {
        // A constant height bumps nothing.
        let n = cx.alloc(3)?;
        cx.emit(
            Op::Input(super::input::InputOp {
                src: super::input::Source::Normal,
                out: n,
            }),
            true,
        );
        let src = normal.unwrap_or(n);
        cx.emit(
            Op::Convert(super::convert::ConvertOp::Copy3 { a: src, out }),
            true,
        );
        return Ok(true);
    }
    let hc = cx.float("Height", 1.0)?;
    let [hx, hy] = cx.float_at_offsets("Height", 1.0)?;
    cx.emit(
        Op::Bump(BumpOp::Normal {
            strength,
            distance,
            invert,
            h: [hc, hx, hy],
            normal,
            out,
        }),
        true,
    );
    Ok(true)
}
