//! Per-sample deterministic random numbers.
//!
//! Each camera sample owns a sampler seeded from `(seed, pixel index, sample index)` only,
//! never from a thread or a tile, so an image is bit-identical for any thread count.
//! [`Sampler`] is a plain PCG32 stream; [`SobolSampler`], used by the renderer, draws each
//! dimension slot (a number, a pair, or a pair with a number) from the first Sobol dimensions
//! of one index, Owen-scrambled, whose sample order is shuffled per pixel and slot (Burley
//! 2020, "Practical Hash-based Owen Scrambling"), so the samples of one pixel are stratified
//! within every slot it uses. Lights and lobes are chosen with the number of their point's
//! slot, as Cycles does, and the pixel filter's slot also carries the path's first BSDF
//! sample ([`SobolSampler::next_2d_reserving`]).

use glam::Vec2;

/// SplitMix64 finaliser: a bijective 64-bit mixer.
#[inline]
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A PCG32 generator (O'Neill 2014, XSH-RR output) seeded per camera sample.
#[derive(Clone, Debug)]
pub struct Sampler {
    state: u64,
    inc: u64,
}

impl Sampler {
    /// The stream for sample `sample` of pixel `pixel` in a render with seed `seed`.
    #[inline]
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Sampler {
        let a = mix64(seed ^ 0x9e37_79b9_7f4a_7c15);
        let b = mix64(a ^ pixel.wrapping_mul(0xd1b5_4a32_d192_ed03));
        let c = mix64(b ^ sample.wrapping_mul(0x8cb9_2ba7_2f3d_8dd7));
        let mut s = Sampler {
            state: 0,
            inc: (mix64(c ^ 0x5851_f42d_4c95_7f2d) << 1) | 1,
        };
        s.next_u32();
        s.state = s.state.wrapping_add(c);
        s.next_u32();
        s
    }

    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// A uniform number in `[0, 1)`.
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// A uniform point in `[0, 1)²`.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let x = self.next_1d();
        Vec2::new(x, self.next_1d())
    }
}

/// 32-bit hash of a 64-bit value.
#[inline]
pub(crate) fn hash32(x: u64) -> u32 {
    (mix64(x) >> 32) as u32
}

/// Laine–Karras style permutation: each output bit depends only on the input bits below it,
/// so applied to bit-reversed values it is a nested uniform (Owen) scramble.
#[inline]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x ^= x.wrapping_mul(0x3d20_adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x0552_6c56);
    x ^= x.wrapping_mul(0x53a2_2864);
    x
}

/// Owen scrambling of a 32-bit fixed-point value in [0, 1) (or a shuffle of an index): the
/// definition [`SobolSampler`] computes with the cancelling reversals taken out.
#[cfg(test)]
fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// Direction numbers `v[k] = m_k 2^(31-k)` of the Sobol dimension whose primitive polynomial
/// has degree `s` and inner coefficients `a` (Joe and Kuo's notation; `a`'s high bit is the
/// coefficient of `x^(s-1)`), extended by `v[k] = v[k-s] ^ (v[k-s] >> s) ^ XOR a_j v[k-j]`.
const fn sobol_directions(s: usize, a: u32, m: [u32; 3]) -> [u32; 32] {
    let mut v = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        v[k] = if k < s {
            m[k] << (31 - k)
        } else {
            let mut x = v[k - s] ^ (v[k - s] >> s);
            let mut j = 1;
            while j < s {
                if (a >> (s - 1 - j)) & 1 == 1 {
                    x ^= v[k - j];
                }
                j += 1;
            }
            x
        };
        k += 1;
    }
    v
}

/// Sobol's dimensions 1 to 4 (dimension 0 is van der Corput's): the polynomials `x + 1`,
/// `x² + x + 1`, `x³ + x + 1` and `x³ + x² + 1` with Joe and Kuo's initial numbers.
const SOBOL_DIRECTIONS: [[u32; 32]; 4] = [
    sobol_directions(1, 0, [1, 0, 0]),
    sobol_directions(2, 1, [1, 3, 0]),
    sobol_directions(3, 1, [1, 3, 1]),
    sobol_directions(3, 2, [1, 1, 1]),
];

/// `SOBOL_REV_BYTES[d][b][x]`: XOR of the bit-reversed direction numbers of dimension `d + 1`
/// selected by byte `b` of an index equal to `x` (reversal commutes with XOR: the tables give
/// the dimension bit-reversed, which is what the sampler scrambles).
const fn sobol_rev_byte_tables() -> [[[u32; 256]; 4]; 4] {
    let mut t = [[[0u32; 256]; 4]; 4];
    let mut d = 0;
    while d < 4 {
        let v = SOBOL_DIRECTIONS[d];
        let mut b = 0;
        while b < 4 {
            let mut x = 0;
            while x < 256 {
                let mut r = 0u32;
                let mut bit = 0;
                while bit < 8 {
                    if x & (1 << bit) != 0 {
                        r ^= v[8 * b + bit].reverse_bits();
                    }
                    bit += 1;
                }
                t[d][b][x] = r;
                x += 1;
            }
            b += 1;
        }
        d += 1;
    }
    t
}

static SOBOL_REV_BYTES: [[[u32; 256]; 4]; 4] = sobol_rev_byte_tables();

/// Sobol dimension `d + 1` at index `i`, bit-reversed; four table lookups.
#[inline]
fn sobol_rev(d: usize, i: u32) -> u32 {
    let t = &SOBOL_REV_BYTES[d];
    let b = i.to_le_bytes();
    t[0][b[0] as usize] ^ t[1][b[1] as usize] ^ t[2][b[2] as usize] ^ t[3][b[3] as usize]
}

#[inline]
fn to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// A low-discrepancy sampler for sample `index` of one pixel: every call draws the next
/// dimension (a 1D value or a 2D point) from a differently scrambled and shuffled
/// (0,2)-sequence, so over a pixel's samples each dimension is well stratified, and pixels
/// are decorrelated by their seeds.
#[derive(Clone, Debug)]
pub struct SobolSampler {
    seed: u64,
    /// The sample index, bit-reversed (what the index shuffle starts from).
    index_rev: u32,
    dim: u32,
    /// Sobol dimensions 0-2 of the point [`Self::next_2d_reserving`] drew, until
    /// [`Self::reserved_3d`] takes them.
    reserved: Option<(Vec2, f32)>,
}

impl SobolSampler {
    #[inline]
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        SobolSampler {
            seed: mix64(
                mix64(seed ^ 0x2545_f491_4f6c_dd1d) ^ pixel.wrapping_mul(0x9e37_79b9_7f4a_7c15),
            ),
            index_rev: (sample as u32).reverse_bits(),
            dim: 0,
            reserved: None,
        }
    }

    #[inline]
    fn next_seed(&mut self) -> u64 {
        self.dim += 1;
        self.seed ^ (self.dim as u64).wrapping_mul(0xd1b5_4a32_d192_ed03)
    }

    /// The shuffled index of this dimension, bit-reversed: `t.reverse_bits()` is
    /// `nested_uniform_scramble(index, h)`.
    #[inline]
    fn shuffled_rev(&self, h: u32) -> u32 {
        laine_karras(self.index_rev, h)
    }

    /// Sobol's dimensions `0..N` of the shuffled index `i` of the next dimension slot, each
    /// Owen-scrambled with its own seed: dimension 0 (van der Corput's) is
    /// `nested_uniform_scramble(i.reverse_bits(), h0)` and dimension `d` is
    /// `nested_uniform_scramble(sobol_d(i), hd)`, written with the reversals that cancel taken
    /// out (`reverse_bits` is a dozen instructions on x86-64).
    #[inline]
    fn point<const N: usize>(&mut self) -> [f32; N] {
        const SCRAMBLE: [u64; 5] = [0x51, 0xa3, 0x1b7, 0x2c9, 0x3e5];
        let s = self.next_seed();
        let i = self.shuffled_rev(hash32(s)).reverse_bits();
        std::array::from_fn(|d| {
            let v = if d == 0 { i } else { sobol_rev(d - 1, i) };
            to_unit(laine_karras(v, hash32(s ^ SCRAMBLE[d])).reverse_bits())
        })
    }

    /// A uniform number in `[0, 1)`: Sobol's dimension 0 of the slot's shuffled index.
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        self.point::<1>()[0]
    }

    /// A uniform point in `[0, 1)²`: Sobol's dimensions 0 and 1 of the slot's shuffled index,
    /// a (0,2)-sequence.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let [x, y] = self.point::<2>();
        Vec2::new(x, y)
    }

    /// A uniform point in `[0, 1)³` as a pair and a number: Sobol's dimensions 0-2 of one
    /// shuffled index, so the number is stratified jointly with the pair (a choice made with
    /// it, of a light or a lobe, leaves each choice's pairs spread), as Cycles draws its
    /// light and BSDF samples. One dimension slot.
    #[inline]
    pub fn next_3d(&mut self) -> (Vec2, f32) {
        let [x, y, z] = self.point::<3>();
        (Vec2::new(x, y), z)
    }

    /// A 2D sample drawn as part of a 5D Sobol point: it returns Sobol's dimensions 3 and 4
    /// and keeps dimensions 0-2 for [`Self::reserved_3d`], so the two samples are stratified
    /// jointly, not only each in its own space. The renderer draws the pixel filter's offset
    /// this way and the path's first BSDF sample takes the rest: where the surface changes
    /// across a pixel (normal maps, edges) the directions and lobes sampled stay spread over
    /// the pixel's area, which independent samples leave to chance.
    #[inline]
    pub fn next_2d_reserving(&mut self) -> Vec2 {
        let [x, y, z, a, b] = self.point::<5>();
        self.reserved = Some((Vec2::new(x, y), z));
        Vec2::new(a, b)
    }

    /// The sample [`Self::next_2d_reserving`] kept, the first time it is asked for; then (or
    /// without one) [`Self::next_3d`]. It takes one dimension slot either way, so the
    /// dimensions after it are the same whichever it returned.
    #[inline]
    pub fn reserved_3d(&mut self) -> (Vec2, f32) {
        match self.reserved.take() {
            Some(p) => {
                self.dim += 1;
                p
            }
            None => self.next_3d(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deterministic_and_distinct_streams() {
        let mut a = Sampler::new(1, 2, 3);
        let mut b = Sampler::new(1, 2, 3);
        let mut c = Sampler::new(1, 2, 4);
        let va: Vec<u32> = (0..8).map(|_| a.next_u32()).collect();
        let vb: Vec<u32> = (0..8).map(|_| b.next_u32()).collect();
        let vc: Vec<u32> = (0..8).map(|_| c.next_u32()).collect();
        assert_eq!(va, vb);
        assert_ne!(va, vc);
    }

    #[test]
    fn sobol_points_are_stratified_per_pixel() {
        // 64 samples of one pixel: every one of the 8x8 strata holds exactly one point in
        // each dimension pair (a (0,2)-sequence keeps this under Owen scrambling).
        for dim in 0..4 {
            let mut cells = [0u32; 64];
            for i in 0..64 {
                let mut s = SobolSampler::new(5, 77, i);
                let mut p = s.next_2d();
                for _ in 0..dim {
                    p = s.next_2d();
                }
                assert!((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y));
                let c = (p.x * 8.0) as usize + 8 * (p.y * 8.0) as usize;
                cells[c] += 1;
            }
            assert!(cells.iter().all(|&c| c == 1), "dimension {dim}: {cells:?}");
        }
        // Different pixels get different points.
        let a = SobolSampler::new(5, 1, 0).next_2d();
        let b = SobolSampler::new(5, 2, 0).next_2d();
        assert_ne!(a, b);
    }

    /// The definition the sampler's arithmetic is a rewrite of.
    fn reference_2d(seed: u64, pixel: u64, sample: u64, dims: usize) -> Vec<(u32, u32, u32)> {
        let seed =
            mix64(mix64(seed ^ 0x2545_f491_4f6c_dd1d) ^ pixel.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        (1..=dims as u64)
            .map(|dim| {
                let s = seed ^ dim.wrapping_mul(0xd1b5_4a32_d192_ed03);
                let i = nested_uniform_scramble(sample as u32, hash32(s));
                let x = nested_uniform_scramble(i.reverse_bits(), hash32(s ^ 0x51));
                let y = nested_uniform_scramble(sobol_dim(0, i), hash32(s ^ 0xa3));
                (x, y, x)
            })
            .collect()
    }

    #[test]
    fn sobol_sampler_equals_its_definition() {
        for (seed, pixel, sample) in [
            (0, 0, 0),
            (1, 2, 3),
            (7, 123_456, 1023),
            (u64::MAX, 5, 77_777),
        ] {
            let r = reference_2d(seed, pixel, sample, 6);
            let mut a = SobolSampler::new(seed, pixel, sample);
            let mut b = SobolSampler::new(seed, pixel, sample);
            for (k, &(x, y, x1)) in r.iter().enumerate() {
                let p = a.next_2d();
                assert_eq!(p, Vec2::new(to_unit(x), to_unit(y)), "2D dimension {k}");
                assert_eq!(b.next_1d(), to_unit(x1), "1D dimension {k}");
            }
        }
    }

    /// Sobol dimension `d + 1` by its definition: the XOR of the direction numbers the
    /// index's bits select.
    fn sobol_dim(d: usize, i: u32) -> u32 {
        let v = SOBOL_DIRECTIONS[d];
        (0..32)
            .filter(|k| i & (1 << k) != 0)
            .fold(0, |r, k| r ^ v[k])
    }

    #[test]
    fn sobol_tables_match_definition() {
        for d in 0..4 {
            for i in [0u32, 1, 2, 3, 5, 255, 256, 0xdead_beef, u32::MAX] {
                assert_eq!(
                    sobol_rev(d, i),
                    sobol_dim(d, i).reverse_bits(),
                    "dim {d} index {i}"
                );
            }
        }
        // Dimension 1: v[k] = v[k-1] ^ (v[k-1] >> 1).
        assert_eq!(sobol_dim(0, 1), 1 << 31);
        assert_eq!(sobol_dim(0, 2), 3 << 30);
        // The first m_k of each dimension: Joe and Kuo's initial numbers, continued by
        // m_k = 2 a_1 m_(k-1) ^ ... ^ 2^s m_(k-s) ^ m_(k-s) (worked by hand).
        let m = |d: usize| {
            (0..4)
                .map(|k| SOBOL_DIRECTIONS[d][k] >> (31 - k))
                .collect::<Vec<_>>()
        };
        assert_eq!(m(0), [1, 3, 5, 15]);
        assert_eq!(m(1), [1, 3, 3, 9]);
        assert_eq!(m(2), [1, 3, 1, 5]);
        assert_eq!(m(3), [1, 1, 1, 11]);
    }

    /// The least `t` for which `pts` (n = 2^k points in [0,1)^2) is a (t, k, 2)-net: every
    /// elementary interval of volume 2^t / n holds 2^t points.
    fn net_t(pts: &[Vec2]) -> u32 {
        let n = pts.len();
        let k = n.trailing_zeros();
        (0..=k)
            .find(|&t| {
                (0..=k - t).all(|a| {
                    let (cx, cy) = (1usize << a, 1usize << (k - t - a));
                    let mut cells = vec![0u32; cx * cy];
                    for p in pts {
                        cells[(p.x * cx as f32) as usize + cx * (p.y * cy as f32) as usize] += 1;
                    }
                    cells.iter().all(|&c| c == 1 << t)
                })
            })
            .unwrap_or(k)
    }

    #[test]
    fn reserved_sample_is_stratified_with_the_pixel_sample() {
        // 64 samples of one pixel: the five numbers are one point of a scrambled Sobol
        // sequence, so every plane of two of them is a (t, 6, 2)-net with t <= 3 (the kept
        // pair, Sobol's dimensions 0 and 1: t = 0; the pixel's pair t = 1). Drawn
        // independently (next_2d, next_3d), a plane across the two is stratified only by
        // chance (t = 5 here).
        let mut v: Vec<[f32; 5]> = vec![];
        let mut ind = vec![];
        for i in 0..64 {
            let mut s = SobolSampler::new(3, 41, i);
            let p = s.next_2d_reserving();
            let (q, c) = s.reserved_3d();
            v.push([q.x, q.y, c, p.x, p.y]);
            let mut t = SobolSampler::new(3, 41, i);
            let p = t.next_2d();
            ind.push(Vec2::new(p.x, t.next_3d().0.x));
        }
        let plane =
            |a: usize, b: usize| v.iter().map(|p| Vec2::new(p[a], p[b])).collect::<Vec<_>>();
        let mut worst = 0;
        for a in 0..5 {
            for b in a + 1..5 {
                worst = worst.max(net_t(&plane(a, b)));
            }
        }
        assert_eq!(net_t(&plane(0, 1)), 0);
        assert!(net_t(&plane(3, 4)) <= 1);
        assert!(worst <= 3, "a plane with t = {worst}");
        assert!(net_t(&ind) >= 5, "independent samples: t = {}", net_t(&ind));
    }

    #[test]
    fn reserved_sample_keeps_later_dimensions() {
        // Whether or not the reserved sample is taken, the dimensions after it are the same;
        // it is handed out once.
        let mut a = SobolSampler::new(9, 5, 17);
        let mut b = SobolSampler::new(9, 5, 17);
        a.next_2d_reserving();
        b.next_2d_reserving();
        let q = a.reserved_3d();
        b.next_2d();
        assert_eq!(a.next_2d(), b.next_2d());
        assert_ne!(a.reserved_3d(), q);
        // The kept pair is what next_2d would have drawn in that dimension slot.
        let mut c = SobolSampler::new(2, 3, 4);
        c.next_2d_reserving();
        assert_eq!(c.reserved_3d().0, SobolSampler::new(2, 3, 4).next_2d());
        assert_eq!(
            SobolSampler::new(7, 1, 2).next_3d().0,
            SobolSampler::new(7, 1, 2).next_2d()
        );
    }

    #[test]
    fn sobol_1d_mean() {
        let mut sum = 0.0f64;
        let n = 4096;
        for p in 0..n {
            sum += SobolSampler::new(1, p, 3).next_1d() as f64;
        }
        assert!((sum / n as f64 - 0.5).abs() < 0.03);
    }

    #[test]
    fn uniform_mean_and_range() {
        let mut s = Sampler::new(7, 0, 0);
        let n = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let x = s.next_1d();
            assert!((0.0..1.0).contains(&x));
            sum += x as f64;
        }
        // Standard error of the mean is 1/sqrt(12 n) ≈ 0.0009; allow 5 sigma.
        assert!((sum / n as f64 - 0.5).abs() < 0.0045);
    }
}
