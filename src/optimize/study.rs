//! An optimisation problem over one scene and its estimates: the objective
//! and its gradient at any offsets of the parameters, each with a standard
//! error, by any method. Book: chapter "Sensitivities at work", sections
//! "Objectives" and "The bias of products".
//!
//! A least-squares gradient multiplies two estimates,
//! `∂L/∂π = 2 Σ_k w_k (I_k − T_k) ∂I_k/∂π`. From the same paths their
//! product is biased by their covariance, `E[(Î − T) ∂̂I] = (I − T) ∂I +
//! Cov(Î, ∂̂I)/N`, and the loss by the variance, `E[(Î − T)²] = (I − T)² +
//! Var(Î)/N`. So the paths are split into `B` independent batches and the
//! products taken between different batches only: with `x_b = Î_b − T`
//! and `y_b = ∂̂I_b`, `(Σ_b x_b Σ_b y_b − Σ_b x_b y_b) / (B(B − 1))` is
//! unbiased for `(I − T) ∂I` (a U-statistic of order 2). Its standard
//! error is the delete-one-batch jackknife's. [`Product::Naive`] keeps the
//! biased product, to show the bias.
use crate::error::Error;
use crate::estimator::Quantity;
use crate::method::model::Model;
use crate::method::{Method, Problem};
use crate::runner::{RunConfig, run};
use crate::scene::config;
use crate::scene::objective::{Measurement, ObjectiveKind, check_measurements};
use std::sync::Arc;
use std::time::Instant;

/// How the objective's products of estimates are formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Product {
    /// Between independent batches: unbiased.
    Independent,
    /// From the same paths: biased by the covariance (for comparison).
    Naive,
}

/// One evaluation's settings.
#[derive(Debug, Clone, Copy)]
pub struct Sampling {
    /// Paths per measurement (a camera's: per pixel), split over the batches.
    pub paths: u64,
    /// Independent batches (at least 2).
    pub batches: u32,
    /// Seed of this evaluation (each batch and measurement derives its own).
    pub seed: u64,
    /// Worker threads (0: all cores); the results do not depend on it.
    pub threads: usize,
    /// The finite-difference half step ([`Method::Fd`] only).
    pub fd_step: Option<f64>,
    /// Unbiased or naive products.
    pub product: Product,
}

/// A value with its standard error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Value {
    /// The estimate.
    pub mean: f64,
    /// Its standard error (jackknife over the batches).
    pub stderr: f64,
}

/// The objective and its gradient at one point.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// The loss the optimiser minimises: `Σ w (I − T)²` for least
    /// squares, `−Σ w I` to maximise, `Σ w I` to minimise.
    pub loss: Value,
    /// `∂loss/∂π_j`, per parameter.
    pub gradient: Vec<Value>,
    /// Paths sampled.
    pub paths: u64,
    /// Wall time of the sampling, in seconds.
    pub sampling_seconds: f64,
    /// Wall time of building the scenes and estimators, in seconds.
    pub setup_seconds: f64,
}

/// An optimisation problem: a scene at its start pose, what is measured,
/// and the objective.
#[derive(Debug)]
pub struct Study<S: Model> {
    scene: S,
    measurements: Vec<Measurement<S::Sensor>>,
    objective: ObjectiveKind,
}

impl<S: Model> Study<S> {
    /// Checks the parts: a target on every measurement for least squares
    /// (a camera's, one per pixel), each measurement's sensor valid in the
    /// scene, each shape moved by translations and at most one rotation or
    /// scale. Errors name the measurement and the field.
    pub fn new(
        scene: S,
        measurements: Vec<Measurement<S::Sensor>>,
        objective: ObjectiveKind,
    ) -> Result<Study<S>, Error> {
        check_measurements(objective, &measurements)?;
        if scene.parameter_names().next().is_none() {
            return config("an optimisation needs at least one entry in [[parameters]]".into());
        }
        // Posing at the start checks the shapes' motions.
        let zero = vec![0.0; scene.parameter_names().count()];
        scene.posed(&zero)?;
        for (i, m) in measurements.iter().enumerate() {
            scene
                .with_sensor(m.sensor)
                .map_err(|e| Error::Scene(format!("measurements[{i}]: {}", message(&e))))?;
            let pixels = S::pixels(&m.sensor);
            if let Some(t) = &m.target
                && t.len() as u64 != pixels
            {
                return config(format!(
                    "measurements[{i}]: field `target` holds {} values for {pixels} pixel{}",
                    t.len(),
                    if pixels == 1 { "" } else { "s" }
                ));
            }
        }
        Ok(Study {
            scene,
            measurements,
            objective,
        })
    }

    /// The scene at the start.
    pub fn scene(&self) -> &S {
        &self.scene
    }
    /// The measurements.
    pub fn measurements(&self) -> &[Measurement<S::Sensor>] {
        &self.measurements
    }
    /// The objective.
    pub fn objective(&self) -> ObjectiveKind {
        self.objective
    }
    /// The parameters' names.
    pub fn parameter_names(&self) -> Vec<String> {
        self.scene.parameter_names().map(str::to_string).collect()
    }
    /// Each parameter's bounds (unbounded: infinite).
    pub fn bounds(&self) -> Vec<[f64; 2]> {
        (0..self.parameter_names().len())
            .map(|j| {
                self.scene
                    .bounds(j)
                    .unwrap_or([f64::NEG_INFINITY, f64::INFINITY])
            })
            .collect()
    }

    /// The scene at `offsets` (validated), or why it is not valid.
    pub fn posed(&self, offsets: &[f64]) -> Result<S, Error> {
        self.scene.posed(offsets)
    }

    /// The loss and its gradient at `offsets` by `method` ([`Method::Intensity`]
    /// gives the loss only: a zero gradient).
    pub fn evaluate(
        &self,
        offsets: &[f64],
        method: Method,
        sampling: &Sampling,
    ) -> Result<Evaluation, Error> {
        let start = Instant::now();
        let posed = self.posed(offsets)?;
        let posing = start.elapsed().as_secs_f64();
        let mut e = self.evaluate_posed(&posed, offsets, method, sampling)?;
        e.setup_seconds += posing;
        Ok(e)
    }

    /// [`Study::evaluate`] on the scene already posed at `offsets`.
    pub fn evaluate_posed(
        &self,
        posed: &S,
        offsets: &[f64],
        method: Method,
        sampling: &Sampling,
    ) -> Result<Evaluation, Error> {
        let b = sampling.batches as usize;
        if b < 3 {
            return config(format!(
                "{b} batches: the unbiased products need 2 and their jackknife error 3"
            ));
        }
        let names = self.parameter_names();
        let np = names.len();
        let quantities: Vec<Quantity> = names.iter().map(|n| Quantity::sensitivity(n)).collect();
        // Per batch: the loss's and the gradient's sums of products within
        // the batch (diagonal) are kept apart from the batch's sums.
        let mut terms = Terms::new(b, np);
        let mut paths = 0;
        let mut sampling_seconds = 0.0;
        let mut setup_seconds = 0.0;
        for (k, m) in self.measurements.iter().enumerate() {
            let built = Instant::now();
            let scene = Arc::new(posed.with_sensor(m.sensor)?);
            let est = scene.estimator(method, sampling.fd_step)?;
            setup_seconds += built.elapsed().as_secs_f64();
            let pixels = S::pixels(&m.sensor);
            let per_batch = (sampling.paths / b as u64).max(2);
            for batch in 0..b {
                let seed = crate::rng::derive_seed(sampling.seed, &[k as u64, batch as u64]);
                // Per pixel: I and ∂I/∂π_j of this batch.
                let (values, secs) = if est.image().is_some() {
                    let r = crate::image::render(
                        &*est,
                        per_batch,
                        seed,
                        sampling.threads,
                        &crate::runner::quiet,
                    )?;
                    let mut values = vec![vec![0.0; 1 + np]; pixels as usize];
                    for (q, image) in &r.images {
                        let slot = slot_of(q, &quantities);
                        if let Some(s) = slot {
                            for (p, e) in image.iter().enumerate() {
                                values[p][s] = e.mean;
                            }
                        }
                    }
                    paths += r.paths();
                    (values, r.seconds)
                } else {
                    let cfg = RunConfig::new(per_batch, seed)?.threads(sampling.threads);
                    let r = run(&*est, &cfg)?;
                    let mut v = vec![0.0; 1 + np];
                    for (q, e) in &r.estimates {
                        if let Some(s) = slot_of(q, &quantities) {
                            v[s] = e.mean;
                        }
                    }
                    paths += r.paths;
                    (vec![v], r.seconds)
                };
                sampling_seconds += secs;
                for (p, v) in values.iter().enumerate() {
                    terms.add(batch, self.term(m, p, v));
                }
            }
        }
        let (loss, mut gradient) = terms.finish(sampling.product);
        // The estimators differentiate the posed scene's own motions; the
        // chain rule to the offsets (a scale's: 1/(1 + θ)).
        for (j, g) in gradient.iter_mut().enumerate() {
            let rate = posed.offset_rate(j, offsets[j]);
            g.mean *= rate;
            g.stderr *= rate;
        }
        Ok(Evaluation {
            loss,
            gradient,
            paths,
            sampling_seconds,
            setup_seconds,
        })
    }

    /// One pixel's factors: `x = √w (I − T)` and `y_j = √w ∂I/∂π_j` for
    /// least squares (loss `Σ x²`, gradient `2 Σ x y_j`), or the linear
    /// objective's `±w I`, `±w ∂I/∂π_j`.
    fn term(&self, m: &Measurement<S::Sensor>, pixel: usize, v: &[f64]) -> Term {
        match self.objective {
            ObjectiveKind::LeastSquares => {
                let target = m.target.as_ref().map_or(0.0, |t| t[pixel]);
                let r = m.weight.sqrt();
                Term::Square {
                    x: r * (v[0] - target),
                    y: v[1..].iter().map(|d| r * d).collect(),
                }
            }
            ObjectiveKind::Maximize | ObjectiveKind::Minimize => {
                let sign = if self.objective == ObjectiveKind::Maximize {
                    -1.0
                } else {
                    1.0
                };
                let w = sign * m.weight;
                Term::Linear {
                    x: w * v[0],
                    y: v[1..].iter().map(|d| w * d).collect(),
                }
            }
        }
    }
}

/// Slot of quantity `q` in a pixel's values: 0 for `I`, `1 + j` for
/// `∂I/∂π_j`.
fn slot_of(q: &Quantity, sensitivities: &[Quantity]) -> Option<usize> {
    if *q == Quantity::Intensity {
        return Some(0);
    }
    sensitivities.iter().position(|s| s == q).map(|j| j + 1)
}

/// The message of a scene error without its kind.
fn message(e: &Error) -> String {
    match e {
        Error::Scene(m) => m.clone(),
        other => other.to_string(),
    }
}

/// One pixel's contribution from one batch.
enum Term {
    /// A squared residual and its gradient factor.
    Square { x: f64, y: Vec<f64> },
    /// A linear objective's value and gradient.
    Linear { x: f64, y: Vec<f64> },
}

/// Per batch, sums over measurements and pixels of the loss's and the
/// gradient's parts, from which the U-statistic and its jackknife follow.
struct Terms {
    /// Per batch: the linear part `Σ x` (squares: `x` summed per pixel is
    /// not enough, so the products are kept per pixel below).
    pixels: Vec<Vec<(f64, Vec<f64>)>>,
    /// Per batch: the linear objective's sums.
    linear: Vec<(f64, Vec<f64>)>,
    square: bool,
    np: usize,
}

impl Terms {
    fn new(batches: usize, np: usize) -> Terms {
        Terms {
            pixels: vec![Vec::new(); batches],
            linear: vec![(0.0, vec![0.0; np]); batches],
            square: false,
            np,
        }
    }

    fn add(&mut self, batch: usize, t: Term) {
        match t {
            Term::Square { x, y } => {
                self.square = true;
                self.pixels[batch].push((x, y));
            }
            Term::Linear { x, y } => {
                let s = &mut self.linear[batch];
                s.0 += x;
                for (a, b) in s.1.iter_mut().zip(y) {
                    *a += b;
                }
            }
        }
    }

    /// The loss and gradient from all batches but `skip` (none: all).
    fn estimate(&self, skip: Option<usize>, product: Product) -> (f64, Vec<f64>) {
        let used: Vec<usize> = (0..self.pixels.len())
            .filter(|&b| Some(b) != skip)
            .collect();
        let n = used.len() as f64;
        let mut loss = 0.0;
        let mut grad = vec![0.0; self.np];
        if self.square {
            let count = self.pixels[used[0]].len();
            for p in 0..count {
                let (mut sx, mut sxx) = (0.0, 0.0);
                let mut sy = vec![0.0; self.np];
                let mut sxy = vec![0.0; self.np];
                for &b in &used {
                    let (x, y) = &self.pixels[b][p];
                    sx += x;
                    sxx += x * x;
                    for j in 0..self.np {
                        sy[j] += y[j];
                        sxy[j] += x * y[j];
                    }
                }
                match product {
                    Product::Independent => {
                        let pairs = n * (n - 1.0);
                        loss += (sx * sx - sxx) / pairs;
                        for j in 0..self.np {
                            grad[j] += 2.0 * (sx * sy[j] - sxy[j]) / pairs;
                        }
                    }
                    Product::Naive => {
                        loss += (sx / n) * (sx / n);
                        for j in 0..self.np {
                            grad[j] += 2.0 * (sx / n) * (sy[j] / n);
                        }
                    }
                }
            }
        } else {
            for &b in &used {
                loss += self.linear[b].0 / n;
                for (g, y) in grad.iter_mut().zip(&self.linear[b].1) {
                    *g += y / n;
                }
            }
        }
        (loss, grad)
    }

    /// The estimates with their delete-one-batch jackknife errors.
    fn finish(&self, product: Product) -> (Value, Vec<Value>) {
        let (loss, grad) = self.estimate(None, product);
        let b = self.pixels.len();
        let mut var_loss = 0.0;
        let mut var_grad = vec![0.0; self.np];
        let leave: Vec<(f64, Vec<f64>)> = (0..b).map(|i| self.estimate(Some(i), product)).collect();
        let mean_loss = leave.iter().map(|l| l.0).sum::<f64>() / b as f64;
        for (l, g) in &leave {
            var_loss += (l - mean_loss).powi(2);
            for j in 0..self.np {
                let m = leave.iter().map(|x| x.1[j]).sum::<f64>() / b as f64;
                var_grad[j] += (g[j] - m).powi(2);
            }
        }
        let scale = (b as f64 - 1.0) / b as f64;
        (
            Value {
                mean: loss,
                stderr: (scale * var_loss).sqrt(),
            },
            grad.iter()
                .zip(&var_grad)
                .map(|(&mean, &v)| Value {
                    mean,
                    stderr: (scale * v).sqrt(),
                })
                .collect(),
        )
    }
}
