//! Central finite differences with common random numbers: the reference
//! (and the foil) for every derivative estimator, on every scene kind. One
//! sample runs the estimator of the nominal problem (`I`) and, per parameter
//! `π_j`, the estimators of the problem displaced to `π_j + h_j` and
//! `π_j − h_j`, all from the same generator state, and scores
//! `(w₊ − w₋)/(2h_j)`. Its bias is `O(h²)`; its variance falls with `h` only
//! while the two paths keep the same structure, and where a path's structure
//! changes with `π` (a collision that moves past the rod's moving end, a ray
//! that grazes a moving corner) it grows like `1/h`. The book's introduction
//! shows both.
use crate::error::{Error, check};
use crate::estimator::{Estimator, Quantity};
use crate::path::PixelSample;
use crate::rng::PathRng;
use crate::stats::{ChunkSums, StratumSums};

/// Default half step of [`Method::Fd`](crate::Method::Fd): relative to the
/// scene's size for a translation (the rod's length, flatland's bounding box),
/// absolute for a rotation (radians) or a scale (relative change).
pub const DEFAULT_STEP: f64 = 1e-3;

/// Smallest half step [`check_step`] takes: below about 10⁻¹⁶ a displaced
/// vertex rounds back to where it was, and every derivative read exactly 0
/// (marked unreliable, with no word why); at 10⁻¹² the displacement still
/// keeps four digits.
pub const MIN_STEP: f64 = 1e-12;

/// Checks a half step relative to the scene's size (or in radians, or a
/// relative scale change), as `--fd-step` takes it: finite and in
/// `[MIN_STEP, 1)`.
pub fn check_step(h: f64) -> Result<f64, Error> {
    check(
        "fd-step",
        h,
        (MIN_STEP..1.0).contains(&h),
        "a finite number from 1e-12 (smaller steps round away) up to 1",
    )
}

/// The error for a problem displaced by `delta` along `parameter` that is
/// invalid: the step is too large ([`Error::FdStep`]), and the message says
/// that finite differences displaced the problem, by how much and along
/// what. `what` names the problem (`"scene"`, `"rod"`), `note` may add how
/// the displacement was derived from the step.
pub fn invalid_displacement(
    what: &str,
    parameter: &str,
    delta: f64,
    note: &str,
    cause: Error,
) -> Error {
    let cause = match cause {
        Error::Scene(msg) => msg,
        other => other.to_string(),
    };
    // Seven significant digits: 0.1 × 3 reads 0.3, not 0.30000000000000004.
    let delta: f64 = format!("{delta:.6e}").parse().unwrap_or(delta);
    Error::FdStep(format!(
        "finite differences displace the {what} by {delta:+} along parameter \
         {parameter:?}{note}, and the displaced {what} is invalid: {cause}"
    ))
}

/// Why the central difference along a parameter may not be trusted when it
/// moves the boundary of a free-path domain in an optically thin medium:
/// the parameter's own shape holds the medium, or lies in it. `media`
/// lists those media as `(name, κs, chord)` (`chord` the medium's
/// [`chord_bound`](crate::path::thin_media::chord_bound)).
///
/// The walk draws collisions in such a medium at a raised rate
/// ([`THIN_DEPTH`](crate::path::thin_media::THIN_DEPTH)), so the pass weight
/// varies at that rate with the boundary and a pair that collides on one
/// side and passes on the other jumps by `O(1)`: `O(h)` of the pairs carry
/// a share `O(1/h)` each, a tail that a run sees only in part (a thin fog's
/// rotation read −2.5·10⁻⁴ ± 4·10⁻⁶ against 1.7·10⁻⁸). The other methods
/// have no such jumps.
pub fn thin_medium_caveat<'a>(
    media: impl IntoIterator<Item = (&'a str, f64, f64)>,
) -> Option<String> {
    media.into_iter().find_map(|(name, ks, chord)| {
        crate::path::thin_media::is_thin(ks, chord).then(|| {
            format!(
                "the step moves the boundary of the optically thin medium {name:?} \
                 (κs × size {:.1e}), whose collisions are drawn at a raised rate: a pair \
                 colliding on one side of the boundary only jumps, and the differences' \
                 tail is too heavy for their error bar; expectation, rendering and \
                 transport do not jump there",
                ks * chord
            )
        })
    })
}

/// The problem displaced along one parameter, both ways.
pub struct Pair {
    /// The parameter's name: the pair's quantity is `∂I/∂parameter`.
    pub parameter: String,
    /// The estimator of `I` at `π + h`.
    pub plus: Box<dyn Estimator>,
    /// The estimator of `I` at `π − h`.
    pub minus: Box<dyn Estimator>,
    /// The half step `h > 0`, in the parameter's units.
    pub half_step: f64,
}

/// `I` from the nominal problem, then `[I(π_j + h_j) − I(π_j − h_j)] / 2h_j`
/// per parameter, all with common random numbers.
///
/// The first run of a sample (the nominal one, or the first pair's `+` run
/// without a nominal) draws from the chunk's generator itself and so
/// advances it; every other run draws from a copy of the sample's starting
/// state. Every run writes one weight into a one-slot buffer on the stack:
/// no cap on the number of parameters, no allocation per path.
pub struct CentralDifference {
    nominal: Option<Box<dyn Estimator>>,
    pairs: Vec<Pair>,
    caveats: Vec<(Quantity, String)>,
}

/// The only quantity a run of a [`CentralDifference`] may estimate.
fn intensity_only(e: &dyn Estimator) -> bool {
    e.quantities() == [Quantity::Intensity]
}

impl CentralDifference {
    /// The central differences of `pairs`, with `I` from `nominal` if given.
    /// Errors if a half step is not finite and positive, an estimator
    /// estimates anything but `I` alone, two pairs share a parameter, or
    /// there is nothing to estimate.
    pub fn new(nominal: Option<Box<dyn Estimator>>, pairs: Vec<Pair>) -> Result<Self, Error> {
        if nominal.is_none() && pairs.is_empty() {
            return Err(Error::Config(
                "finite differences of nothing: no nominal estimator and no parameter".into(),
            ));
        }
        if let Some(n) = &nominal
            && !intensity_only(n.as_ref())
        {
            return Err(Error::Config(format!(
                "finite differences: the nominal estimator ({}) must estimate I alone",
                n.method()
            )));
        }
        for (j, p) in pairs.iter().enumerate() {
            check("h", p.half_step, p.half_step > 0.0, "a finite number > 0")?;
            if !(intensity_only(p.plus.as_ref()) && intensity_only(p.minus.as_ref())) {
                return Err(Error::Config(format!(
                    "finite differences along {:?}: the displaced estimators must estimate I alone",
                    p.parameter
                )));
            }
            if pairs[..j].iter().any(|q| q.parameter == p.parameter) {
                return Err(Error::Config(format!(
                    "finite differences: parameter {:?} appears twice",
                    p.parameter
                )));
            }
        }
        Ok(CentralDifference {
            nominal,
            pairs,
            caveats: Vec::new(),
        })
    }

    /// The same with a warning on `parameter`'s quantity (see
    /// [`Estimator::caveats`]).
    pub fn with_caveat(mut self, parameter: &str, why: String) -> Self {
        self.caveats.push((Quantity::sensitivity(parameter), why));
        self
    }
}

/// One run's weight of `I`: from `own` (the chunk's generator) if no run of
/// this sample has used it yet, else from a copy of `start`.
#[inline]
fn intensity(
    e: &dyn Estimator,
    own: &mut Option<&mut PathRng>,
    start: &PathRng,
    pixel: PixelSample,
) -> f64 {
    let mut w = [0.0];
    match own.take() {
        Some(rng) => e.sample_pixel(rng, pixel, &mut w),
        None => e.sample_pixel(&mut start.clone(), pixel, &mut w),
    }
    w[0]
}

impl Estimator for CentralDifference {
    fn method(&self) -> &'static str {
        "fd"
    }

    /// `I` (with a nominal estimator), then `∂I/∂π_j` per pair.
    fn quantities(&self) -> Vec<Quantity> {
        self.nominal
            .iter()
            .map(|_| Quantity::Intensity)
            .chain(
                self.pairs
                    .iter()
                    .map(|p| Quantity::sensitivity(&p.parameter)),
            )
            .collect()
    }

    fn caveats(&self) -> Vec<(Quantity, String)> {
        self.caveats.clone()
    }

    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        self.sample_pixel(rng, PixelSample::default(), weights);
    }

    /// The nominal problem's image (the displaced ones share its camera).
    fn image(&self) -> Option<(u32, u32)> {
        match &self.nominal {
            Some(n) => n.image(),
            None => self.pairs.first().and_then(|p| p.plus.image()),
        }
    }

    fn sample_pixel(&self, rng: &mut PathRng, pixel: PixelSample, weights: &mut [f64]) {
        self.differences(rng, pixel, weights, |_| ());
    }

    /// The provided pixel loop, counting jumps as [`Self::accumulate`]
    /// does, per pixel (and so over the image, for its mean).
    fn accumulate_pixel(&self, rng: &mut PathRng, pixel: u32, spp: u64, sums: &mut [StratumSums]) {
        let first = usize::from(self.nominal.is_some());
        let mut w = vec![0.0; sums.len()];
        let mut jumped = vec![false; if first == 1 { sums.len() } else { 0 }];
        if first == 1 {
            sums[1..].iter_mut().for_each(StratumSums::track_jumps);
        }
        crate::estimator::stratified_marked(pixel, spp, sums, &mut w, &mut jumped, |s, w, j| {
            self.differences(rng, s, w, |k| j[first + k] = true)
        });
    }

    /// The provided loop, besides counting per parameter, where `I` is
    /// estimated too, the pairs that jumped ([`jumped`]): the boundary part
    /// of a derivative rests on them alone, and a run that drew few of them
    /// has an error bar that cannot see the part it missed
    /// ([`crate::stats::Estimate::jumps`]).
    fn accumulate(&self, rng: &mut PathRng, paths: u64, sums: &mut [ChunkSums]) {
        let first = usize::from(self.nominal.is_some());
        if first == 1 {
            sums[1..].iter_mut().for_each(ChunkSums::track_jumps);
        }
        let mut w = vec![0.0; sums.len()];
        for _ in 0..paths {
            let pairs = &mut sums[first..];
            self.differences(rng, PixelSample::default(), &mut w, |j| {
                pairs[j].push_jump()
            });
            for (s, &x) in sums.iter_mut().zip(&w) {
                s.push(x);
            }
        }
    }
}

/// Whether one path's weights `plus` and `minus` in the two displaced
/// scenes, and `nominal` in the scene itself, differ by a jump: a smooth
/// weight passes the nominal scene halfway between the other two (to
/// `O(h²)` against a difference of `O(h)`), a jump (a shadow ray blocked on
/// one side only, a collision inside a medium on one side and outside on
/// the other) leaves the nominal weight at one side, a quarter of the
/// difference or nearer. Nearer one side, not merely away from the
/// midpoint: a smooth weight at its extremum has `plus ≈ minus` with the
/// nominal a curvature away from both. And a difference of at least
/// [`JUMP_FLOOR`] of the weights: weights that differ by the rounding of
/// the displaced geometry (a rotating lamp's length, hence every path's
/// light-selection weight, 10⁵ sizes from the origin) sit at random about
/// one another and once made 81 000 "jumps" of a run whose real jumps were
/// never drawn: its estimate, the smooth part alone, was marked reliable
/// (seen in random scenes, `tests/flat_failures.rs`).
#[inline]
pub fn jumped(nominal: f64, plus: f64, minus: f64) -> bool {
    let d = (plus - minus).abs();
    d > JUMP_FLOOR * (plus.abs() + minus.abs())
        && (nominal - plus).abs().min((nominal - minus).abs()) <= 0.25 * d
}

/// The smallest relative difference [`jumped`] takes for a jump: far above
/// the displaced geometry's rounding (64 ulps at 10⁶ sizes from the origin
/// is 1.4·10⁻⁸ of a weight), far below what a boundary crossed moves (a
/// blocked shadow ray, a collision on the other side of an interface).
pub const JUMP_FLOOR: f64 = 1e-6;

impl CentralDifference {
    /// One sample's weights; `jump(j)` is called for each pair `j` whose
    /// paths [`jumped`] (never without a nominal estimator).
    #[inline]
    fn differences(
        &self,
        rng: &mut PathRng,
        pixel: PixelSample,
        weights: &mut [f64],
        mut jump: impl FnMut(usize),
    ) {
        let start = rng.clone();
        let mut own = Some(rng);
        let mut slots = weights.iter_mut();
        let mut at_nominal = None;
        if let Some(nominal) = &self.nominal
            && let Some(w) = slots.next()
        {
            *w = intensity(nominal.as_ref(), &mut own, &start, pixel);
            at_nominal = Some(*w);
        }
        for (j, (pair, w)) in self.pairs.iter().zip(slots).enumerate() {
            let plus = intensity(pair.plus.as_ref(), &mut own, &start, pixel);
            let minus = intensity(pair.minus.as_ref(), &mut own, &start, pixel);
            let diff = plus - minus;
            // Two paths that differ only by the rounding of the displaced
            // geometry give a difference of roundoff, not a derivative.
            *w = if crate::estimator::within_rounding(diff, plus.abs() + minus.abs()) {
                0.0
            } else {
                if at_nominal.is_some_and(|w| jumped(w, plus, minus)) {
                    jump(j);
                }
                diff / (2.0 * pair.half_step)
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Method;
    use crate::rod::{Direction, PARAMETER, Probe, Rod, exact};
    use crate::runner::{RunConfig, run};

    fn intensity(length: f64) -> Box<dyn Estimator> {
        let rod = Rod::new(2.1, 3.0, length).unwrap();
        let probe = Probe::new(&rod, 1.0, Direction::Left).unwrap();
        Method::Intensity.estimator((rod, probe)).unwrap()
    }

    fn pair(name: &str, h: f64) -> Pair {
        Pair {
            parameter: name.into(),
            plus: intensity(2.0 + h),
            minus: intensity(2.0 - h),
            half_step: h,
        }
    }

    #[test]
    fn common_random_numbers_recover_the_exact_sensitivity() {
        // h = 3e-3: the O(h²) bias is ~1e-6, far under σ ≈ 2e-4 at 10⁶ paths.
        let h = 3e-3;
        let fd = CentralDifference::new(None, vec![pair(PARAMETER, h)]).unwrap();
        assert_eq!(fd.quantities(), [Quantity::sensitivity(PARAMETER)]);
        let e = run(&fd, &RunConfig::new(1_000_000, 5).unwrap())
            .unwrap()
            .estimates[0]
            .1;
        let rod = Rod::new(2.1, 3.0, 2.0).unwrap();
        let s = exact::solve(&rod, 1.0, Direction::Left).sensitivity;
        assert!(e.stderr > 0.0 && e.z_score(s) < 4.0, "{e:?} vs {s}");
    }

    #[test]
    fn many_parameters_share_one_path_each_way() {
        // Twelve copies of one pair: more than the old cap of 8 quantities,
        // and every copy, from the same generator state, gives the same
        // weight; with the nominal first, `I` matches a plain run.
        let h = 1e-2;
        let names: Vec<String> = (0..12).map(|j| format!("p{j}")).collect();
        let pairs = names.iter().map(|n| pair(n, h)).collect();
        let fd = CentralDifference::new(Some(intensity(2.0)), pairs).unwrap();
        assert_eq!(fd.quantities().len(), 13);
        let cfg = RunConfig::new(20_000, 9).unwrap();
        let r = run(&fd, &cfg).unwrap();
        let plain = run(intensity(2.0).as_ref(), &cfg).unwrap();
        assert_eq!(r.estimates[0].1.mean, plain.estimates[0].1.mean);
        let s = r.estimates[1].1;
        assert!(s.stderr > 0.0);
        for (_, e) in &r.estimates[1..] {
            assert_eq!(e.mean, s.mean);
        }
    }

    #[test]
    fn a_jump_leaves_the_nominal_weight_on_one_side() {
        // Smooth: w(π) = 1 + 3π + 40π² at π = 0, ±h, for any h up to 0.01.
        for h in [1e-6, 1e-3, 1e-2] {
            let w = |p: f64| 1.0 + 3.0 * p + 40.0 * p * p;
            assert!(!jumped(w(0.0), w(h), w(-h)), "h = {h}");
        }
        // A shadow edge crossed between the two scenes, whatever the size
        // of the blocked part beside the rest of the path's weight.
        for part in [1.0, 1e-3] {
            assert!(jumped(5.0 + part, 5.0 + part, 5.0), "{part}");
            assert!(jumped(5.0, 5.0 + part, 5.0), "{part}");
        }
        assert!(!jumped(0.0, 0.0, 0.0));
        // A smooth weight at its extremum: plus ≈ minus, the nominal a
        // curvature away from both.
        for h in [1e-6, 1e-3, 1e-2] {
            let w = |p: f64| 1.0 + 1e-9 * p - 40.0 * p * p;
            assert!(!jumped(w(0.0), w(h), w(-h)), "h = {h}");
        }
        // The rounding of the displaced geometry: three weights a few
        // ulps of 10⁵ apart, in any order.
        let ulps = |k: f64| 0.3 * (1.0 + k * 64.0 * f64::EPSILON * 1e5);
        for (n, p, m) in [(0.0, 1.0, -1.0), (1.0, 1.0, 0.0), (0.0, 1.0, 0.0)] {
            assert!(!jumped(ulps(n), ulps(p), ulps(m)), "{n} {p} {m}");
        }
        // A jump against a smooth change of the other sign.
        assert!(jumped(5.0, 5.0 + 1e-4 - 0.5, 5.0 - 1e-4));
    }

    #[test]
    fn bad_steps_and_estimators_are_rejected() {
        for h in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let p = Pair {
                half_step: h,
                ..pair("length", 0.1)
            };
            assert!(CentralDifference::new(None, vec![p]).is_err());
        }
        let rod = Rod::new(2.1, 3.0, 2.0).unwrap();
        let probe = Probe::new(&rod, 1.0, Direction::Left).unwrap();
        let other = Method::Expectation.estimator((rod, probe)).unwrap();
        let p = Pair {
            minus: other,
            ..pair("length", 0.1)
        };
        assert!(CentralDifference::new(None, vec![p]).is_err());
        let twice = vec![pair("length", 0.1), pair("length", 0.2)];
        assert!(CentralDifference::new(None, twice).is_err());
        assert!(CentralDifference::new(None, vec![]).is_err());
        for h in [0.0, -1e-3, 1.0, f64::NAN, f64::INFINITY, 1e-17, 5e-324] {
            let e = check_step(h).unwrap_err().to_string();
            assert!(e.contains("fd-step"), "{e}");
        }
        assert_eq!(check_step(1e-3), Ok(1e-3));
        assert_eq!(check_step(MIN_STEP), Ok(MIN_STEP));
    }
}
