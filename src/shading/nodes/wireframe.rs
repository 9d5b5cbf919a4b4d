//! The Wireframe node (Cycles' `svm_node_wireframe`): 1 within half of `Size` (world units) of
//! an edge of the point's triangle, else 0. Every triangle edge counts, the diagonals of
//! triangulated quads included, as in Cycles.

use crate::shading::compile::{CompileError, NodeCx, SocketType};
use crate::shading::globals::ShaderGlobals;
use crate::shading::program::{Op, Slot, Slots};
use glam::Vec3;

#[derive(Clone, Copy, Debug)]
pub struct WireframeOp {
    size: Slot,
    out: Slot,
}

/// 1 when `p` lies within `size / 2` of an edge (the infinite line through it) of triangle
/// `tri`; the neighbour across the edge draws the other half.
pub fn wireframe(p: Vec3, tri: [Vec3; 3], size: f32) -> f32 {
    let half = 0.5 * size;
    let w2 = half * half;
    for i in 0..3 {
        let j = if i == 0 { 2 } else { i - 1 };
        let edge = tri[i] - tri[j];
        // |edge × (p - a)|² / |edge|² is the squared distance from p to the edge's line.
        let c = edge.cross(p - tri[i]);
        if c.length_squared() < edge.length_squared() * w2 {
            return 1.0;
        }
    }
    0.0
}

impl WireframeOp {
    #[inline]
    pub fn eval(&self, s: &mut Slots, g: &ShaderGlobals) {
        let f = g
            .triangle()
            .map_or(0.0, |tri| wireframe(g.p, tri, s.f(self.size)));
        s.set_f(self.out, f);
    }
}

pub fn compile(kind: &str, cx: &mut NodeCx) -> Result<bool, CompileError> {
    if kind != "ShaderNodeWireframe" {
        return Ok(false);
    }
    if cx.prop_bool("use_pixel_size", false) {
        // Needs the pixel footprint (ray differentials), which shading points do not carry.
        cx.warn("Pixel Size is not supported; the node renders as muted");
        return Ok(false);
    }
    let size = cx.float("Size", 0.01)?;
    let out = cx.output("Fac", SocketType::Float)?;
    cx.emit(Op::Wireframe(WireframeOp { size, out }), true);
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn within_half_the_size_of_any_edge() {
        let tri = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        // 0.04 from the x axis edge: inside a 0.1 wire, outside a 0.07 one.
        let p = Vec3::new(0.5, 0.04, 0.0);
        assert_eq!(wireframe(p, tri, 0.1), 1.0);
        assert_eq!(wireframe(p, tri, 0.07), 0.0);
        // Near the hypotenuse x + y = 2: distance (2 - 1.9) / √2 ≈ 0.0707.
        let q = Vec3::new(0.95, 0.95, 0.0);
        assert_eq!(wireframe(q, tri, 0.15), 1.0);
        assert_eq!(wireframe(q, tri, 0.14), 0.0);
        // The centroid is far from every edge.
        assert_eq!(wireframe(Vec3::splat(2.0 / 3.0).with_z(0.0), tri, 0.5), 0.0);
    }
}
