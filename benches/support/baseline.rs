//! The baseline every rod method is timed against: Algorithm 3 of He et al.
//! (2024, Appendix F), backward path tracing of the intensity, written as
//! one plain loop with no runner, no trait, no observer and no statistics
//! beyond the sum and the sum of squares. It draws from the same generator
//! as the library (`PathRng`, seeded by `rng::stream(seed, 0)`), so the gap
//! between it and `run(IntensityEstimator)` is what the generic interface
//! costs.
//!
//! Shared by `benches/rod.rs` and `examples/perf_table.rs` through `#[path]`.
use geosens::rng::{self, PathRng};
use rand::Rng;
use rand::distr::Distribution;
use rand_distr::Exp1;

/// `(Σw, Σw²)` over `n` backward paths from `x` for the intensity observed
/// along `omega` (`+1` or `−1`) on a rod `[0, length]` with `I0 = 1`.
pub fn algorithm3(
    ks: f64,
    ke: f64,
    length: f64,
    x: f64,
    omega: f64,
    n: u64,
    seed: u64,
) -> (f64, f64) {
    let ka = ke - ks;
    let mut rng: PathRng = rng::stream(seed, 0);
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        // The backward path travels along −ω.
        let mut left = omega > 0.0;
        let mut pos = x;
        let mut l_tot = 0.0;
        let w = loop {
            let e: f64 = Exp1.sample(&mut rng);
            let xi = e / ks;
            let d = if left { pos } else { length - pos };
            if xi >= d {
                // Leaving at x = 0 collects I0 = 1; at x = π̃ nothing enters.
                break if left { (-ka * (l_tot + d)).exp() } else { 0.0 };
            }
            l_tot += xi;
            pos += if left { -xi } else { xi };
            // Isotropic scattering: one bit, the same one the library reads.
            left = rng.next_u64() >> 63 == 1;
        };
        sum += w;
        sum2 += w * w;
    }
    (sum, sum2)
}
