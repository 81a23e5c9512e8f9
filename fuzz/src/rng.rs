//! The fuzzer's randomness: a small seeded generator (SplitMix64, so a seed gives the same
//! stream on every platform and every build) and the pools of values it draws from.

use shm_layout::{Handle, Pose, Vec3};

/// Floats that have broken numeric code before: NaN, infinities, zeros of both signs, the
/// smallest subnormal, the extremes of f32 and values just past common bounds.
pub const SPECIAL_F32: [f32; 22] = [
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    0.0,
    -0.0,
    1e-45,
    -1e-45,
    f32::MIN_POSITIVE,
    1e-30,
    1e-7,
    -1.0,
    -1e-3,
    1e38,
    -1e38,
    f32::MAX,
    f32::MIN,
    1e20,
    -1e20,
    1.000_000_1,
    10_000.001,
    65.0,
    33.0,
];

/// Integers at and around the bounds of counts, indices and generations.
pub const SPECIAL_U32: [u32; 12] = [
    0,
    1,
    2,
    31,
    32,
    33,
    63,
    64,
    65,
    65_536,
    u32::MAX - 1,
    u32::MAX,
];

/// A seeded SplitMix64 generator.
#[derive(Debug, Clone)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// The stream of `seed`.
    pub fn new(seed: u64) -> Rng {
        Rng { state: seed }
    }

    /// The next 64 random bits.
    pub fn u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// 32 random bits.
    pub fn u32(&mut self) -> u32 {
        (self.u64() >> 32) as u32
    }

    /// A byte.
    pub fn byte(&mut self) -> u8 {
        (self.u64() >> 56) as u8
    }

    /// Uniform in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            ((self.u64() >> 11) % n as u64) as usize
        }
    }

    /// Uniform in `lo..=hi`.
    pub fn range(&mut self, lo: usize, hi: usize) -> usize {
        lo + self.below(hi - lo + 1)
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn f32_in(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit() as f32
    }

    /// Log-uniform in [lo, hi] (both > 0): every order of magnitude equally likely.
    pub fn log_f32(&mut self, lo: f32, hi: f32) -> f32 {
        let (a, b) = ((lo as f64).ln(), (hi as f64).ln());
        (a + (b - a) * self.unit())
            .exp()
            .clamp(lo as f64, hi as f64) as f32
    }

    /// One of `items`.
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    /// A special float.
    pub fn special_f32(&mut self) -> f32 {
        *self.pick(&SPECIAL_F32)
    }

    /// Any bit pattern as a float (NaN payloads, subnormals and all).
    pub fn bits_f32(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }

    /// A float that is, in `wild` mode, often special: the value `sane` otherwise.
    pub fn maybe_wild(&mut self, wild: bool, sane: f32) -> f32 {
        if !wild || self.chance(0.5) {
            sane
        } else if self.chance(0.85) {
            self.special_f32()
        } else {
            self.bits_f32()
        }
    }

    /// A vector in the cube `[-r, r]³`, components made wild in `wild` mode.
    pub fn vec3(&mut self, wild: bool, r: f32) -> Vec3 {
        [0; 3].map(|_| {
            let v = self.f32_in(-r, r);
            self.maybe_wild(wild, v)
        })
    }

    /// A unit quaternion `[x, y, z, w]`; in `wild` mode sometimes zero, unnormalised or
    /// with special components.
    pub fn quat(&mut self, wild: bool) -> [f32; 4] {
        if wild && self.chance(0.3) {
            return match self.below(4) {
                0 => [0.0; 4],
                1 => [1e-7, 0.0, 0.0, 0.0],
                2 => [self.f32_in(-100.0, 100.0), 0.0, 0.0, 3.0],
                _ => [0; 4].map(|_| self.special_f32()),
            };
        }
        if self.chance(0.3) {
            return [0.0, 0.0, 0.0, 1.0];
        }
        let q: [f32; 4] = [0; 4].map(|_| self.f32_in(-1.0, 1.0));
        let n = q.iter().map(|c| c * c).sum::<f32>().sqrt().max(1e-3);
        q.map(|c| c / n)
    }

    /// A pose within `r` of the origin.
    pub fn pose(&mut self, wild: bool, r: f32) -> Pose {
        Pose {
            position: self.vec3(wild, r),
            rotation: self.quat(wild),
        }
    }

    /// A count or index near a bound.
    pub fn special_u32(&mut self) -> u32 {
        *self.pick(&SPECIAL_U32)
    }

    /// A handle nobody handed out: out of range, generation 0, or random.
    pub fn bogus_handle(&mut self) -> Handle {
        match self.below(4) {
            0 => Handle {
                slot: self.special_u32(),
                generation: self.special_u32(),
            },
            1 => Handle {
                slot: self.below(64) as u32,
                generation: 0,
            },
            2 => Handle {
                slot: u32::MAX,
                generation: u32::MAX,
            },
            _ => Handle {
                slot: self.u32(),
                generation: self.u32(),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_seed_gives_one_stream() {
        let a: Vec<u64> = {
            let mut r = Rng::new(7);
            (0..8).map(|_| r.u64()).collect()
        };
        let mut r = Rng::new(7);
        assert!(a.iter().all(|&v| v == r.u64()));
        assert_ne!(Rng::new(8).u64(), a[0]);
    }

    #[test]
    fn ranges_hold() {
        let mut r = Rng::new(1);
        for _ in 0..10_000 {
            assert!(r.below(5) < 5);
            let v = r.range(3, 6);
            assert!((3..=6).contains(&v));
            let x = r.log_f32(1e-6, 1.0);
            assert!((1e-6..=1.0).contains(&x), "{x}");
            let u = r.unit();
            assert!((0.0..1.0).contains(&u));
        }
    }
}
