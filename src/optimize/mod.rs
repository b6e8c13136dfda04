//! Sensitivities at work: inverse problems and design by stochastic
//! gradient descent on a scene's parameters. Book: chapter "Sensitivities
//! at work".
//!
//! A [`Study`] is a scene with measurements and an objective (least
//! squares to targets, or the maximum or minimum of a weighted sum); its
//! [`Study::evaluate`] estimates the loss and its gradient by any method,
//! unbiased ([`study`]'s products between independent batches). The loop
//! [`optimize`] steps with [`Adam`](Optimizer::Adam) or plain gradient
//! descent with a decreasing step ([`Optimizer::Sgd`]), keeps the
//! parameters in their bounds, and shortens a step that would make the
//! scene invalid until it is valid, saying so in the record. Every
//! iteration's randomness derives from the seed and the iteration, so a run
//! is reproducible bit for bit whatever the thread count.
pub mod compare;
pub mod scan;
pub mod study;

pub use study::{Evaluation, Product, Sampling, Study, Value};

use crate::error::Error;
use crate::method::Method;
use crate::method::model::Model;
use serde::Serialize;
use std::collections::BTreeMap;

/// The step rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Optimizer {
    /// Adam (Kingma & Ba 2015): per-parameter steps normalised by the
    /// gradient's running scale, `step / (1 + t/τ)` with τ = 50 (its noise
    /// floor is proportional to the step, so the step must fall).
    Adam,
    /// Gradient descent, `step / (1 + t/τ)^0.75` with τ = 50 (the
    /// Robbins–Monro conditions: Σ αₜ = ∞, Σ αₜ² < ∞).
    Sgd,
}

/// Settings of a run.
#[derive(Debug, Clone, Copy)]
pub struct Settings {
    /// The method that estimates the gradient.
    pub method: Method,
    /// The step rule.
    pub optimizer: Optimizer,
    /// Iterations at most.
    pub iterations: u32,
    /// The first step: Adam's in parameter units, gradient descent's
    /// multiplier of the gradient.
    pub step: f64,
    /// Each evaluation's sampling (its seed is the run's; each iteration
    /// derives its own).
    pub sampling: Sampling,
    /// Stop once every parameter's last step is below this (0: never).
    pub tolerance: f64,
}

/// One iteration's record: the iterate, the loss and gradient estimated
/// there, and what the step did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// Iteration (0: the start).
    pub iteration: u32,
    /// The parameters' offsets from the file's pose, by name.
    pub parameters: BTreeMap<String, f64>,
    /// The mean of the iterates over the last half of the run so far
    /// (iterations ⌈t/2⌉ to t; Polyak–Ruppert tail averaging): the answer
    /// to report, its noise √(t/2) times smaller than the iterate's once
    /// the iterates hover about the optimum.
    pub average: BTreeMap<String, f64>,
    /// The loss at this iterate.
    pub loss: MeanErr,
    /// Its gradient, by parameter name.
    pub gradient: BTreeMap<String, MeanErr>,
    /// Paths sampled for this iteration.
    pub paths: u64,
    /// Wall time of this iteration (sampling, set-up and step), seconds.
    pub seconds: f64,
    /// Of which the sampling.
    pub sampling_seconds: f64,
    /// What the step that led to this iterate did beyond the rule
    /// (clamped to a bound, shortened to keep the scene valid).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// A mean and its standard error, as the records print them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MeanErr {
    /// The estimate.
    pub mean: f64,
    /// Its standard error.
    pub stderr: f64,
}

impl From<Value> for MeanErr {
    fn from(v: Value) -> MeanErr {
        MeanErr {
            mean: v.mean,
            stderr: v.stderr,
        }
    }
}

/// Adam's and gradient descent's state.
#[derive(Debug, Clone)]
pub struct Stepper {
    optimizer: Optimizer,
    step: f64,
    m: Vec<f64>,
    v: Vec<f64>,
    t: u32,
}

/// Adam's decay rates and guard.
const BETA1: f64 = 0.9;
const BETA2: f64 = 0.999;
const EPSILON: f64 = 1e-12;
/// Iterations over which the step halves (Adam: `1/(1 + t/τ)`) or falls by
/// 2^0.75 (gradient descent).
const TAU: f64 = 50.0;

impl Stepper {
    /// A stepper for `n` parameters.
    pub fn new(optimizer: Optimizer, step: f64, n: usize) -> Stepper {
        Stepper {
            optimizer,
            step,
            m: vec![0.0; n],
            v: vec![0.0; n],
            t: 0,
        }
    }

    /// The proposed change of the parameters for gradient `g`.
    pub fn delta(&mut self, g: &[f64]) -> Vec<f64> {
        self.t += 1;
        let t = f64::from(self.t);
        match self.optimizer {
            Optimizer::Adam => {
                let alpha = self.step / (1.0 + (t - 1.0) / TAU);
                (0..g.len())
                    .map(|j| {
                        self.m[j] = BETA1 * self.m[j] + (1.0 - BETA1) * g[j];
                        self.v[j] = BETA2 * self.v[j] + (1.0 - BETA2) * g[j] * g[j];
                        let m = self.m[j] / (1.0 - BETA1.powf(t));
                        let v = self.v[j] / (1.0 - BETA2.powf(t));
                        -alpha * m / (v.sqrt() + EPSILON)
                    })
                    .collect()
            }
            Optimizer::Sgd => {
                let alpha = self.step / (1.0 + (t - 1.0) / TAU).powf(0.75);
                g.iter().map(|gj| -alpha * gj).collect()
            }
        }
    }
}

/// Halvings tried before a step that keeps the scene invalid is dropped.
pub const MAX_HALVINGS: u32 = 30;

/// Runs the optimisation from the file's pose; `each` gets every record as
/// it is made (iteration 0 is the start) and may stop the run by returning
/// `false` (a Ctrl-C, say). Returns the records.
pub fn optimize<S: Model>(
    study: &Study<S>,
    settings: &Settings,
    mut each: impl FnMut(&Record) -> bool,
) -> Result<Vec<Record>, Error> {
    if settings.method == Method::Intensity {
        return Err(Error::Config(
            "the intensity method estimates no gradient: optimise with expectation, \
             rendering, transport or fd"
                .into(),
        ));
    }
    let names = study.parameter_names();
    let bounds = study.bounds();
    let mut theta = vec![0.0; names.len()];
    let mut stepper = Stepper::new(settings.optimizer, settings.step, names.len());
    let mut records = Vec::new();
    let mut posed = study.posed(&theta)?;
    let mut notes = Vec::new();
    let mut history: Vec<Vec<f64>> = Vec::new();
    for iteration in 0..=settings.iterations {
        history.push(theta.clone());
        let start = std::time::Instant::now();
        let sampling = Sampling {
            seed: crate::rng::derive_seed(settings.sampling.seed, &[u64::from(iteration)]),
            ..settings.sampling
        };
        let e = study.evaluate_posed(&posed, &theta, settings.method, &sampling)?;
        let g: Vec<f64> = e.gradient.iter().map(|v| v.mean).collect();
        let mut record = Record {
            iteration,
            parameters: names.iter().cloned().zip(theta.iter().copied()).collect(),
            average: names.iter().cloned().zip(tail_average(&history)).collect(),
            loss: e.loss.into(),
            gradient: names
                .iter()
                .cloned()
                .zip(e.gradient.iter().map(|&v| MeanErr::from(v)))
                .collect(),
            paths: e.paths,
            seconds: 0.0,
            sampling_seconds: e.sampling_seconds,
            notes: std::mem::take(&mut notes),
        };
        let mut moved = f64::INFINITY;
        if iteration < settings.iterations {
            let delta = stepper.delta(&g);
            let (next, scene, step_notes) = take_step(study, &theta, &delta, &bounds, &names);
            notes = step_notes;
            moved = next
                .iter()
                .zip(&theta)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            if let Some(scene) = scene {
                theta = next;
                posed = scene;
            }
        }
        record.seconds = start.elapsed().as_secs_f64();
        let go_on = each(&record);
        records.push(record);
        if !go_on || moved < settings.tolerance {
            break;
        }
    }
    Ok(records)
}

/// The mean of the last half of `history` (its last ⌈n/2⌉ entries).
fn tail_average(history: &[Vec<f64>]) -> Vec<f64> {
    let tail = &history[history.len() / 2..];
    let n = tail.len() as f64;
    (0..tail[0].len())
        .map(|j| tail.iter().map(|t| t[j]).sum::<f64>() / n)
        .collect()
}

/// `theta + delta` clamped to the bounds and shortened (halved) until the
/// scene is valid there: the new point and its scene (`None`: no valid
/// step found, stay), with notes on what was done.
fn take_step<S: Model>(
    study: &Study<S>,
    theta: &[f64],
    delta: &[f64],
    bounds: &[[f64; 2]],
    names: &[String],
) -> (Vec<f64>, Option<S>, Vec<String>) {
    let mut notes = Vec::new();
    let mut clamped = Vec::new();
    let target: Vec<f64> = theta
        .iter()
        .zip(delta)
        .zip(bounds)
        .enumerate()
        .map(|(j, ((t, d), [lo, hi]))| {
            let x = t + d;
            if x < *lo || x > *hi {
                clamped.push(names[j].as_str());
            }
            x.clamp(*lo, *hi)
        })
        .collect();
    if !clamped.is_empty() {
        notes.push(format!("clamped to bounds: {}", clamped.join(", ")));
    }
    let mut fraction = 1.0;
    let mut first_error = None;
    for halvings in 0..=MAX_HALVINGS {
        let point: Vec<f64> = theta
            .iter()
            .zip(&target)
            .map(|(t, x)| t + fraction * (x - t))
            .collect();
        match study.posed(&point) {
            Ok(scene) => {
                if halvings > 0 {
                    notes.push(format!(
                        "step shortened to 2^-{halvings} of its length: {}",
                        first_error.unwrap_or_default()
                    ));
                }
                return (point, Some(scene), notes);
            }
            Err(e) => {
                first_error.get_or_insert_with(|| e.to_string());
                fraction *= 0.5;
            }
        }
    }
    notes.push(format!(
        "no valid step after {MAX_HALVINGS} halvings, stayed: {}",
        first_error.unwrap_or_default()
    ));
    (theta.to_vec(), None, notes)
}
