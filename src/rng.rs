//! Random streams. Every chunk of paths draws from its own generator, a pure
//! function of `(seed, chunk)`, so a run is reproducible bit for bit whatever
//! the number of threads that process the chunks.
//!
//! The generator is a named, portable one (xoshiro256++), not `StdRng`, whose
//! algorithm may change between rand releases. The chunk seed is mixed by
//! SplitMix64 so neighbouring `(seed, chunk)` pairs give unrelated states.
use rand::SeedableRng;
use rand::distr::Distribution;
use rand_distr::Exp1;

/// The generator every path draws from.
pub type PathRng = rand_xoshiro::Xoshiro256PlusPlus;

/// SplitMix64 finaliser: a bijective 64-bit mixer.
fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The generator of chunk `chunk` of a run seeded with `seed`.
pub fn stream(seed: u64, chunk: u64) -> PathRng {
    PathRng::seed_from_u64(mix64(
        mix64(seed) ^ chunk.wrapping_mul(0xD2B7_4407_B1CE_6E93),
    ))
}

/// A free path `ξ ~ κs e^{−κs ξ}` (the distance to the next scattering in
/// a medium of scattering coefficient `ks`); infinite without scattering.
/// Every scene's walk draws its free paths here.
#[inline]
pub fn free_path(ks: f64, rng: &mut PathRng) -> f64 {
    if ks > 0.0 {
        let e: f64 = Exp1.sample(rng);
        e / ks
    } else {
        f64::INFINITY
    }
}

/// A seed for one independent run inside a larger one (an optimiser's
/// iteration, measurement and batch): distinct `parts` give unrelated
/// streams, the same parts the same stream.
pub fn derive_seed(seed: u64, parts: &[u64]) -> u64 {
    parts
        .iter()
        .fold(mix64(seed ^ 0x6F70_7469_6D69_7365), |h, &p| {
            mix64(h ^ mix64(p))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;

    #[test]
    fn streams_are_pure_and_distinct() {
        let a: Vec<u64> = (0..4).map(|c| stream(1, c).next_u64()).collect();
        let b: Vec<u64> = (0..4).map(|c| stream(1, c).next_u64()).collect();
        assert_eq!(a, b);
        let mut sorted = a.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), 4);
        assert_ne!(stream(1, 0).next_u64(), stream(2, 0).next_u64());
    }
}
