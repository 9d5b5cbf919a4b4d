//! RGB Curves, Vector Curves and Float Curve nodes, read from tables baked by the add-on
//! exactly as Cycles' Blender sync bakes them (`intern/cycles/blender/util.h`), and looked
//! up like `svm_node_curves` / `svm_node_curve` (`kernel/svm/ramp.h`).
//!
//! Baking (Blender 5.0): `size = CURVE_TABLE_SIZE` (256), `size + 1` samples at
//! `t_i = min_x + (i / size) * (max_x - min_x)`, `i = 0..=size`, each evaluated with
//! `CurveMapping.evaluate` after `CurveMapping.initialize()`:
//! * RGB Curves: entry `(R(C(t)), G(C(t)), B(C(t)))` where `C` is the combined curve
//!   (`curves[3]`); `min_x`/`max_x` = smallest first-point x / largest last-point x over
//!   all 4 curves.
//! * Vector Curves: entry `(X(t), Y(t), Z(t))`; range over the 3 curves.
//! * Float Curve: entry `curve(t)` of `curves[0]`; range from that curve alone.
//!
//! `extrapolate` is `mapping.extend == 'EXTRAPOLATED'`.

use super::ramp::table_lookup;
use glam::Vec3;

/// `RAMP_TABLE_SIZE`: the tables hold `CURVE_TABLE_SIZE + 1` samples.
pub const CURVE_TABLE_SIZE: usize = 256;

/// Positions `t_i = min_x + (i / size) * (max_x - min_x)`, `i = 0..=size`, at which the
/// add-on must evaluate the curves (computed in f32 like Cycles).
pub fn sample_positions(min_x: f32, max_x: f32, size: usize) -> impl Iterator<Item = f32> {
    let size = size.max(1);
    let range = max_x - min_x;
    (0..=size).map(move |i| min_x + i as f32 / size as f32 * range)
}

/// A baked 3-channel curve table (RGB Curves or Vector Curves).
#[derive(Clone, Debug, PartialEq)]
pub struct CurveTable {
    /// Samples at [`sample_positions`]`(min_x, max_x, len - 1)`.
    pub table: Vec<Vec3>,
    pub min_x: f32,
    pub max_x: f32,
    /// Extend mode EXTRAPOLATED (otherwise EXTENDED: constant past the ends).
    pub extrapolate: bool,
}

impl CurveTable {
    pub fn new(table: Vec<Vec3>, min_x: f32, max_x: f32, extrapolate: bool) -> Self {
        CurveTable {
            table,
            min_x,
            max_x,
            extrapolate,
        }
    }

    /// RGB Curves / Vector Curves node: each channel `c` is looked up at
    /// `(c - min_x) / (max_x - min_x)` in its own table channel (linear interpolation,
    /// extrapolated from the two end samples when enabled, else clamped), then mixed with
    /// the input: `(1 - fac) * c + fac * curve(c)`.
    pub fn evaluate(&self, fac: f32, color: Vec3) -> Vec3 {
        let range = self.max_x - self.min_x;
        let rel = (color - Vec3::splat(self.min_x)) / range;
        let r = table_lookup(&self.table, rel.x, true, self.extrapolate).x;
        let g = table_lookup(&self.table, rel.y, true, self.extrapolate).y;
        let b = table_lookup(&self.table, rel.z, true, self.extrapolate).z;
        color * (1.0 - fac) + Vec3::new(r, g, b) * fac
    }

    /// RGB Curves node (`ShaderNodeRGBCurve`), see [`CurveTable::evaluate`].
    pub fn rgb_curves(&self, fac: f32, color: Vec3) -> Vec3 {
        self.evaluate(fac, color)
    }

    /// Vector Curves node (`ShaderNodeVectorCurve`), see [`CurveTable::evaluate`].
    pub fn vector_curves(&self, fac: f32, vector: Vec3) -> Vec3 {
        self.evaluate(fac, vector)
    }
}

/// A baked Float Curve table.
#[derive(Clone, Debug, PartialEq)]
pub struct FloatCurveTable {
    pub table: Vec<f32>,
    pub min_x: f32,
    pub max_x: f32,
    pub extrapolate: bool,
}

impl FloatCurveTable {
    pub fn new(table: Vec<f32>, min_x: f32, max_x: f32, extrapolate: bool) -> Self {
        FloatCurveTable {
            table,
            min_x,
            max_x,
            extrapolate,
        }
    }

    /// Float Curve node: `(1 - fac) * v + fac * curve((v - min_x) / (max_x - min_x))`.
    pub fn float_curve(&self, fac: f32, value: f32) -> f32 {
        let rel = (value - self.min_x) / (self.max_x - self.min_x);
        let v = table_lookup(&self.table, rel, true, self.extrapolate);
        (1.0 - fac) * value + fac * v
    }
}

#[cfg(test)]
#[allow(
    clippy::approx_constant,
    clippy::excessive_precision,
    clippy::type_complexity
)]
mod tests {
    use super::*;

    #[test]
    fn sample_positions_cover_range() {
        let p: Vec<f32> = sample_positions(-0.5, 1.5, CURVE_TABLE_SIZE).collect();
        assert_eq!(p.len(), 257);
        assert_eq!(p[0], -0.5);
        assert_eq!(p[128], 0.5);
        assert_eq!(p[256], 1.5);
    }

    #[test]
    fn lookup_semantics() {
        // Identity-like curve table over [-1, 1]: entry i = t_i * (1, 2, -1).
        let table: Vec<Vec3> = sample_positions(-1.0, 1.0, 4)
            .map(|t| Vec3::new(t, 2.0 * t, -t))
            .collect();
        let ext = CurveTable::new(table.clone(), -1.0, 1.0, true);
        let hor = CurveTable::new(table, -1.0, 1.0, false);
        let c = Vec3::new(0.25, -0.5, 3.0);
        assert_eq!(ext.evaluate(1.0, c), Vec3::new(0.25, -1.0, -3.0));
        assert_eq!(hor.evaluate(1.0, c), Vec3::new(0.25, -1.0, -1.0));
        // fac blends with the input (unclamped).
        assert_eq!(hor.evaluate(0.0, c), c);
        assert_eq!(
            hor.evaluate(0.5, Vec3::splat(0.5)),
            Vec3::new(0.5, 0.75, 0.0)
        );
        let f = FloatCurveTable::new(vec![1.0, 0.0, 1.0], 0.0, 2.0, true);
        assert_eq!(f.float_curve(1.0, 1.0), 0.0);
        assert_eq!(f.float_curve(1.0, 3.0), 2.0);
        assert_eq!(f.float_curve(1.0, -1.0), 2.0);
        // Degenerate range / empty tables / non-finite input never panic.
        let z = FloatCurveTable::new(vec![], 1.0, 1.0, true);
        for v in [f32::NAN, f32::INFINITY, 0.0, 1.0] {
            let _ = z.float_curve(1.0, v);
            let _ = f.float_curve(v, v);
            let _ = ext.evaluate(v, Vec3::splat(v));
            let _ = CurveTable::new(vec![], 0.0, 0.0, true).evaluate(1.0, Vec3::splat(v));
        }
    }

    /// Float Curve measured from Cycles 5.0: curve points (-0.5, 0.2), (0.25, 0.9),
    /// (0.6, -0.3), (1.5, 0.7) (auto handles, no clipping), table baked by Blender's
    /// `CurveMapping.evaluate` at `sample_positions(-0.5, 1.5, 256)`.
    #[test]
    fn measured_from_cycles() {
        assert_eq!(FLOAT_CURVE_TABLE.len(), 257);
        for &(extrapolate, fac, value, want) in MEASURED {
            let c = FloatCurveTable::new(FLOAT_CURVE_TABLE.to_vec(), -0.5, 1.5, extrapolate);
            let got = c.float_curve(fac, value);
            assert!(
                (got - want).abs() <= 1e-6,
                "({fac}, {value}): {got} vs Cycles {want}"
            );
        }
    }

    /// (extrapolate, factor, value, result): measured from Cycles 5.0.
    #[rustfmt::skip]
    const MEASURED: &[(bool, f32, f32, f32)] = &[
        (true, -0.1388878, 0.29455566, 0.21605249),
        (true, 0.38454875, 1.9397354, 1.9493104),
        (true, 0.22514457, 0.9500246, 0.67920464),
        (true, 0.8594795, -0.3139106, 0.4494441),
        (false, -0.1388878, 0.29455566, 0.21605249),
        (false, 0.38454875, 1.9397354, 1.4629966),
        (false, 0.22514457, 0.9500246, 0.67920464),
        (false, 0.8594795, -0.3139106, 0.4494441),
    ];

    #[rustfmt::skip]
    const FLOAT_CURVE_TABLE: [f32; 257] = [
        0.2, 0.21729583, 0.23459165, 0.2518, 0.2690032, 0.2860512, 0.30307356, 0.31990173, 0.3366604, 0.35322297, 0.36964092, 0.38590595, 0.40191233, 0.41786146, 0.43339187, 0.44892225, 0.46401608, 0.47901267, 0.49373987, 0.50815153, 0.52253515, 0.53631705, 0.5500989, 0.5635029, 0.5766164, 0.5897162, 0.60212886, 0.6145415, 0.6266608, 0.6383456, 0.6500304, 0.6611818, 0.6721171, 0.6830524, 0.6932662, 0.7034353, 0.71353495, 0.72292566, 0.7323162, 0.7415888, 0.75019276, 0.7587968, 0.7673054, 0.77511835, 0.78293127, 0.7907441, 0.79776746, 0.8047881, 0.81180876, 0.8182173, 0.8244474, 0.83067745, 0.83655405, 0.841998, 0.8474419, 0.85287106, 0.85753536, 0.86219954, 0.86686385, 0.87115955, 0.8750527, 0.8789458, 0.88283885, 0.88610584, 0.8892379, 0.89237, 0.8954649, 0.8978475, 0.90023005, 0.9026126, 0.9048815, 0.90652716, 0.90817297, 0.9098186, 0.9113681, 0.9122906, 0.91321313, 0.9141357, 0.91505814, 0.9152846, 0.91549826, 0.91571194, 0.9159256, 0.9156557, 0.91517556, 0.9146954, 0.91421527, 0.9135488, 0.91239023, 0.9112317, 0.91007316, 0.9089145, 0.9072854, 0.90546405, 0.9036428, 0.9018215, 0.9, 0.8962275, 0.89245504, 0.8855586, 0.8783614, 0.86770606, 0.85643756, 0.84181, 0.8256242, 0.8070316, 0.7852884, 0.7615999, 0.7347709, 0.70462024, 0.6718822, 0.6363292, 0.5974287, 0.55535686, 0.5107177, 0.46373487, 0.41477588, 0.36434188, 0.31303954, 0.26153663, 0.21050885, 0.16067302, 0.11275597, 0.06712669, 0.024085836, -0.016213614, -0.053753525, -0.08824854, -0.119053535, -0.14729208, -0.17327861, -0.195423, -0.21542162, -0.23350394, -0.24808419, -0.26167682, -0.27204844, -0.28137934, -0.28816217, -0.29389164, -0.29728508, -0.3002905, -0.30174294, -0.3031954, -0.3046478, -0.30610028, -0.3075527, -0.30900514, -0.30979162, -0.31056058, -0.31132957, -0.31209856, -0.31286752, -0.31363648, -0.31371215, -0.3137731, -0.313834, -0.31389493, -0.31395587, -0.31386447, -0.3131923, -0.31252015, -0.31184798, -0.31117582, -0.3105037, -0.3093356, -0.3079049, -0.30647427, -0.30504358, -0.30361295, -0.30193865, -0.29972383, -0.297509, -0.29529417, -0.29307935, -0.2907254, -0.2877007, -0.28467602, -0.28165126, -0.27862656, -0.2754092, -0.271549, -0.26768875, -0.26382855, -0.2599683, -0.25569436, -0.2509734, -0.24625243, -0.24153146, -0.2368105, -0.23127908, -0.22567277, -0.22006649, -0.21446018, -0.20837364, -0.2018584, -0.1953432, -0.18882799, -0.18202135, -0.17457503, -0.16712871, -0.1596824, -0.15198612, -0.14358833, -0.13519058, -0.1267928, -0.11803533, -0.108668156, -0.09930098, -0.08993381, -0.079945095, -0.06959359, -0.059242092, -0.048853386, -0.037506275, -0.02615916, -0.0148120485, -0.0028812182, 0.009468291, 0.021817802, 0.03442807, 0.0477814, 0.061134737, 0.07455118, 0.08890374, 0.10325631, 0.11760886, 0.13293487, 0.14827469, 0.16363554, 0.17994264, 0.19624974, 0.21271053, 0.22995567, 0.24720079, 0.2648106, 0.2829543, 0.30109802, 0.31987032, 0.33886218, 0.35798228, 0.37775975, 0.39753717, 0.41778767, 0.4382758, 0.45891446, 0.4800254, 0.50113636, 0.5227091, 0.5443418, 0.5662149, 0.5882557, 0.6103946, 0.63271767, 0.6550631, 0.6775317, 0.6999997
    ];
}
