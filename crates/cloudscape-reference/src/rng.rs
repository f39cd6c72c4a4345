//! Random numbers: PCG32 (O'Neill 2014, "PCG: A Family of Simple Fast Space-Efficient Statistically
//! Good Algorithms for Random Number Generation"), one stream per pixel and one starting state per
//! sample, so an image depends only on its seed, never on thread scheduling or pass sizes.

use glam::{Vec2, Vec3};

/// PCG32's multiplier (O'Neill 2014).
const PCG_MULTIPLIER: u64 = 6_364_136_223_846_793_005;

/// A PCG32 generator: 64-bit state, one of 2^63 streams.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    increment: u64,
}

/// SplitMix64's finaliser (Steele, Lea & Flood 2014, "Fast Splittable Pseudorandom Number
/// Generators"): spreads nearby seeds over the whole state space.
fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Rng {
    /// The generator of sample `sample` of pixel `pixel` (row-major index) under image seed `seed`:
    /// the pixel picks the stream, the seed and the sample index the starting state.
    pub fn for_sample(seed: u64, pixel: u64, sample: u64) -> Rng {
        let mut rng = Rng {
            state: 0,
            increment: (splitmix64(pixel ^ seed.rotate_left(32)) << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng
            .state
            .wrapping_add(splitmix64(seed ^ splitmix64(sample)));
        rng.next_u32();
        rng
    }

    /// The next 32 random bits (PCG-XSH-RR).
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(PCG_MULTIPLIER)
            .wrapping_add(self.increment);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32)
    }

    /// A uniform number in [0, 1) with 24 random bits (every value exactly representable).
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// Two uniform numbers in [0, 1).
    pub fn next_vec2(&mut self) -> Vec2 {
        Vec2::new(self.next_f32(), self.next_f32())
    }

    /// Three uniform numbers in [0, 1).
    pub fn next_vec3(&mut self) -> Vec3 {
        Vec3::new(self.next_f32(), self.next_f32(), self.next_f32())
    }

    /// An optical depth drawn from the unit exponential distribution, `-ln(1 - u)`.
    pub fn next_optical_depth(&mut self) -> f32 {
        -(1.0 - self.next_f32()).ln()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let draw = |seed, pixel, sample| {
            let mut r = Rng::for_sample(seed, pixel, sample);
            [r.next_u32(), r.next_u32(), r.next_u32()]
        };
        assert_eq!(draw(1, 2, 3), draw(1, 2, 3));
        assert_ne!(draw(1, 2, 3), draw(1, 2, 4));
        assert_ne!(draw(1, 2, 3), draw(1, 3, 3));
        assert_ne!(draw(1, 2, 3), draw(2, 2, 3));
    }

    #[test]
    fn uniforms_have_the_right_mean_and_range() {
        let mut r = Rng::for_sample(7, 0, 0);
        let n = 100_000;
        let values: Vec<f32> = (0..n).map(|_| r.next_f32()).collect();
        assert!(values.iter().all(|v| (0.0..1.0).contains(v)));
        let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / n as f64;
        // The standard error of the mean of U(0, 1) is 1 / sqrt(12 n) = 0.0009.
        assert!((mean - 0.5).abs() < 0.004, "{mean}");
        let depth = (0..n)
            .map(|_| f64::from(r.next_optical_depth()))
            .sum::<f64>()
            / n as f64;
        assert!((depth - 1.0).abs() < 0.02, "{depth}");
    }
}
