//! The seeded generator every case is drawn with ([`Rng`]) and the ranges it draws from
//! ([`Span`]).

/// A small seeded generator (SplitMix64): the same seed draws the same cases everywhere.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `span`.
    pub fn uniform(&mut self, span: Span) -> f64 {
        span.0 + (span.1 - span.0) * self.unit()
    }

    /// Log-uniform in `span` (both ends > 0), rounded to 3 significant digits so repros
    /// read well.
    pub fn log_uniform(&mut self, span: Span) -> f64 {
        let (a, b) = (span.0.ln(), span.1.ln());
        round3((a + (b - a) * self.unit()).exp()).clamp(span.0, span.1)
    }

    /// An integer in `lo..=hi`, log-uniform (small values as likely per octave as large).
    pub fn int_log(&mut self, lo: u32, hi: u32) -> u32 {
        let v = (lo as f64 - 0.5).max(0.5).ln()
            + ((hi as f64 + 0.5).ln() - (lo as f64 - 0.5).max(0.5).ln()) * self.unit();
        (v.exp().round() as u32).clamp(lo, hi)
    }

    /// An integer in `lo..=hi`, uniform.
    pub fn int(&mut self, lo: u32, hi: u32) -> u32 {
        lo + (self.next_u64() % (hi - lo + 1) as u64) as u32
    }

    pub fn pick<T: Copy>(&mut self, from: &[T]) -> T {
        from[(self.next_u64() % from.len() as u64) as usize]
    }
}

/// A closed range of a parameter `(lo, hi)`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Span(pub f64, pub f64);

impl Span {
    pub const fn at(v: f64) -> Span {
        Span(v, v)
    }
}

/// `v` rounded to 3 significant digits (the nearest f64 to the decimal, so it prints as
/// one).
pub fn round3(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    format!("{v:.2e}").parse().unwrap_or(v)
}
