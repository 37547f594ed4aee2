//! A small deterministic pseudo-random generator (Knuth's MMIX linear
//! congruential generator) for the tests, examples and benchmarks that need
//! a few reproducible numbers without a dependency. Not for anything that
//! needs good randomness.

/// The generator's state; the same seed gives the same numbers everywhere.
#[derive(Clone, Debug)]
pub struct Lcg(pub u64);

impl Lcg {
    fn step(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0
    }

    /// The next 31 bits (the state's high bits).
    pub fn next_u32(&mut self) -> u32 {
        (self.step() >> 33) as u32
    }

    /// The next number in `0..n` (`n` > 0; slightly uneven for large `n`).
    pub fn below(&mut self, n: u32) -> u32 {
        self.next_u32() % n
    }

    /// The next number in `[0, 1)`, 53 bits.
    pub fn next_f64(&mut self) -> f64 {
        (self.step() >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_seed_repeats_its_numbers() {
        let (mut a, mut b) = (Lcg(7), Lcg(7));
        let xs: Vec<u32> = (0..4).map(|_| a.below(100)).collect();
        let ys: Vec<u32> = (0..4).map(|_| b.below(100)).collect();
        assert_eq!(xs, ys);
        assert!(xs.iter().all(|&x| x < 100));
        let f = Lcg(1).next_f64();
        assert!((0.0..1.0).contains(&f));
        // The first state after seed 0 is the increment.
        assert_eq!(Lcg(0).next_u32(), (1442695040888963407u64 >> 33) as u32);
    }
}
