//! Central finite differences with common random numbers: the reference
//! (and the foil) for every derivative estimator. One sample runs the
//! estimator of the scene at `π + h` and, from a copy of the same generator
//! state, the estimator at `π − h`, and scores `(w₊ − w₋)/(2h)` per
//! quantity. Its bias is `O(h²)`; its variance falls with `h` only while the
//! two paths keep the same structure, and where a path's structure changes
//! with `π` (here: a collision that moves past the moving end) it grows like
//! `1/h`. The book's introduction shows both.
use crate::error::{Error, check};
use crate::estimator::{Estimator, Quantity};
use crate::rng::PathRng;

/// Most quantities a [`CentralDifference`] differentiates (its per-sample
/// buffer lives on the stack).
pub const MAX_QUANTITIES: usize = 8;

/// `[E(π + h) − E(π − h)] / 2h` with common random numbers.
pub struct CentralDifference {
    plus: Box<dyn Estimator>,
    minus: Box<dyn Estimator>,
    half_step: f64,
}

impl CentralDifference {
    /// The difference quotient of two estimators of the same quantities, at
    /// parameters `π ± half_step`; errors if `half_step` is not finite and
    /// positive or the estimators' quantities differ.
    pub fn new(
        plus: Box<dyn Estimator>,
        minus: Box<dyn Estimator>,
        half_step: f64,
    ) -> Result<Self, Error> {
        let half_step = check("h", half_step, half_step > 0.0, "a finite number > 0")?;
        if plus.quantities() != minus.quantities() {
            return Err(Error::Config(
                "the two estimators estimate different quantities".into(),
            ));
        }
        if plus.quantities().len() > MAX_QUANTITIES {
            return Err(Error::Config(format!(
                "finite differences take at most {MAX_QUANTITIES} quantities"
            )));
        }
        Ok(CentralDifference {
            plus,
            minus,
            half_step,
        })
    }
}

impl Estimator for CentralDifference {
    fn method(&self) -> &'static str {
        "fd"
    }

    /// The same quantities as the wrapped estimators, differentiated.
    fn quantities(&self) -> Vec<Quantity> {
        self.plus.quantities()
    }

    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        // Few quantities: a fixed buffer keeps the hot loop allocation-free.
        let mut minus = [0.0; MAX_QUANTITIES];
        let n = weights.len();
        let mut common = rng.clone();
        self.plus.sample(rng, weights);
        self.minus.sample(&mut common, &mut minus[..n]);
        let scale = 0.5 / self.half_step;
        for (w, m) in weights.iter_mut().zip(&minus[..n]) {
            *w = (*w - m) * scale;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rod::{Direction, Method, Probe, Rod, exact};
    use crate::runner::{RunConfig, run};

    fn intensity(length: f64) -> Box<dyn Estimator> {
        let rod = Rod::new(2.1, 3.0, length).unwrap();
        Method::Intensity.estimator(rod, Probe::new(&rod, 1.0, Direction::Left).unwrap())
    }

    #[test]
    fn common_random_numbers_recover_the_exact_sensitivity() {
        // h = 3e-3: the O(h²) bias is ~1e-6, far under σ ≈ 2e-4 at 10⁶ paths.
        let h = 3e-3;
        let fd = CentralDifference::new(intensity(2.0 + h), intensity(2.0 - h), h).unwrap();
        let e = run(&fd, &RunConfig::new(1_000_000, 5).unwrap())
            .unwrap()
            .estimates[0]
            .1;
        let rod = Rod::new(2.1, 3.0, 2.0).unwrap();
        let s = exact::solve(&rod, 1.0, Direction::Left).sensitivity;
        assert!(e.stderr > 0.0 && e.z_score(s) < 4.0, "{e:?} vs {s}");
    }

    #[test]
    fn bad_steps_and_mismatched_estimators_are_rejected() {
        for h in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(CentralDifference::new(intensity(2.0), intensity(2.0), h).is_err());
        }
        let rod = Rod::new(2.1, 3.0, 2.0).unwrap();
        let probe = Probe::new(&rod, 1.0, Direction::Left).unwrap();
        let other = Method::Expectation.estimator(rod, probe);
        assert!(CentralDifference::new(intensity(2.0), other, 0.1).is_err());
    }
}
