//! What an estimation prints: the table and the one JSON line of `geosens
//! rod`, `geosens flat` and `geosens mesh`, built here once so that the
//! command line, the Python package (`geosens.rod`, `geosens.flat`, …) and a
//! merge of shards ([`crate::shard`]) print the same bytes for the same run.
//!
//! A [`Report`] is a [`RunResult`] with what the printing needs beside it:
//! the rod and probe or the scene's name and size ([`Header`]), the seed, and
//! the estimator's caveats. Its JSON line carries, per quantity, the mean,
//! standard error, count of non-zero weights and whether the error bar can
//! be trusted ([`MeanErr`]).
use crate::error::{Error, Num};
use crate::estimator::Quantity;
use crate::rod::{Direction, Probe, Rod, exact};
use crate::runner::RunResult;
use crate::stats::Estimate;
use serde::{Deserialize, Serialize};
use std::fmt::Write;

/// A probe on a rod as a user gives it (unchecked): what `geosens rod`
/// takes and its table's first line says.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RodProbe {
    /// Scattering coefficient κs.
    pub ks: f64,
    /// Extinction coefficient κe.
    pub ke: f64,
    /// Length π̃.
    pub length: f64,
    /// Probe position.
    pub x: f64,
    /// Probe direction, ±1.
    pub omega: f64,
}

impl RodProbe {
    /// The rod and probe, validated (errors name the bad value).
    pub fn build(&self) -> Result<(Rod, Probe), Error> {
        let rod = Rod::new(self.ks, self.ke, self.length)?;
        let probe = Probe::new(&rod, self.x, Direction::from_sign(self.omega)?)?;
        Ok((rod, probe))
    }

    /// The user-facing form of a validated rod and probe.
    pub fn of(rod: &Rod, probe: &Probe) -> RodProbe {
        RodProbe {
            ks: rod.ks,
            ke: rod.ke,
            length: rod.length,
            x: probe.x,
            omega: probe.omega.sign(),
        }
    }
}

/// What was estimated on, as the table's first line says it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Header {
    /// A probe on a rod.
    Rod(RodProbe),
    /// A flatland or 3D scene.
    Scene {
        /// The scene as the table names it (its file, or `<dict>`).
        scene: String,
        /// Number of shapes.
        shapes: usize,
        /// Number of parameters.
        parameters: usize,
    },
}

impl Header {
    /// The rod and probe of a rod header (validated again: a header read
    /// from a state file is user data).
    fn rod(&self) -> Result<Option<(Rod, Probe)>, Error> {
        match self {
            Header::Rod(r) => r.build().map(Some),
            Header::Scene { .. } => Ok(None),
        }
    }
}

/// One estimation's result with what its printing needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// What was estimated on.
    pub header: Header,
    /// The estimates.
    pub result: RunResult,
    /// The seed of the run.
    pub seed: u64,
    /// Why a quantity may be far off whatever its error bar, as the
    /// estimator said when it was built.
    pub caveats: Vec<(Quantity, String)>,
}

/// Mean and standard error, as the JSON line prints them, with the count
/// of non-zero weights and whether the error bar can be trusted.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeanErr {
    /// Estimated value.
    pub mean: f64,
    /// Its standard error (0 for `exact`).
    pub stderr: f64,
    /// Paths whose weight was not zero (0 for `exact`).
    pub nonzero: u64,
    /// Whether the error bar can be trusted ([`Estimate::is_reliable`] and
    /// no caveat).
    pub reliable: bool,
    /// Why the estimate may be far off whatever its error bar, if the
    /// estimator said so when it was built.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub caveat: Option<String>,
    /// Pairs of paths that jumped, for a central difference
    /// ([`Estimate::jumps`]); absent for the other methods.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jumps: Option<u64>,
}

impl MeanErr {
    /// The JSON form of `e`, with the caveat on its quantity if any.
    pub fn of(e: &Estimate, caveat: Option<&String>) -> MeanErr {
        MeanErr {
            mean: e.mean,
            stderr: e.stderr,
            nonzero: e.nonzero,
            reliable: e.is_reliable() && caveat.is_none(),
            caveat: caveat.cloned(),
            jumps: e.jumps,
        }
    }
}

/// A table's `reliable` column: `caveat` where the estimator gave one.
fn reliable_text(e: &Estimate, caveat: Option<&String>) -> &'static str {
    match (e.is_reliable(), caveat) {
        (true, None) => "yes",
        (_, Some(_)) => "caveat",
        (false, None) => "no",
    }
}

/// The caveat on quantity `q` among `caveats`, if any.
pub fn caveat_of<'a>(caveats: &'a [(Quantity, String)], q: &Quantity) -> Option<&'a String> {
    caveats.iter().find(|(k, _)| k == q).map(|(_, why)| why)
}

/// `z` as the tables print it: `-` where the error bar is 0 and the
/// estimate is off (no finite z; `reliable` says why).
pub fn z_text(e: &Estimate, exact: f64) -> String {
    let z = e.z_score(exact);
    if z.is_finite() {
        format!("{z:.1}")
    } else {
        "-".to_owned()
    }
}

/// The one JSON line of `geosens rod --json`; `None` prints `null` for a
/// quantity the method does not estimate.
#[derive(Serialize)]
struct RodJsonLine<'a> {
    method: &'a str,
    intensity: Option<MeanErr>,
    sensitivity: Option<MeanErr>,
    gradient_x: Option<MeanErr>,
    paths: u64,
    seconds: f64,
}

/// The one JSON line of `geosens flat --json` and `geosens mesh --json`.
#[derive(Serialize)]
struct SceneJsonLine<'a> {
    method: &'a str,
    intensity: MeanErr,
    sensitivity: serde_json::Map<String, serde_json::Value>,
    gradient: Option<serde_json::Map<String, serde_json::Value>>,
    paths: u64,
    seconds: f64,
}

/// The three quantities a rod run can report, in table and JSON order.
pub fn rod_quantities() -> [Quantity; 3] {
    [
        Quantity::Intensity,
        Quantity::sensitivity(crate::rod::PARAMETER),
        Quantity::gradient("x"),
    ]
}

/// The exact values of [`rod_quantities`] at a probe.
pub fn rod_exact(rod: &Rod, probe: &Probe) -> [f64; 3] {
    let e = exact::solve(rod, probe.x, probe.omega);
    [e.intensity, e.sensitivity, e.gradient_x]
}

/// `e` as JSON.
fn to_json<T: Serialize>(value: &T) -> Result<String, Error> {
    serde_json::to_string(value).map_err(|e| Error::Output(e.to_string()))
}

impl Report {
    /// Errors if an estimate is not finite: serde_json would print a NaN as
    /// `null`, indistinguishable from "not estimated".
    pub fn check_finite(&self) -> Result<(), Error> {
        match self
            .result
            .estimates
            .iter()
            .find(|(_, e)| !(e.mean.is_finite() && e.stderr.is_finite()))
        {
            Some((q, e)) => Err(Error::Output(format!(
                "method {} gives {q} = {} ± {} at these inputs ({})",
                self.result.method,
                Num(e.mean),
                Num(e.stderr),
                // `Moments::lost_to_underflow`: the mean is fine, its error
                // bar is not.
                if e.mean.is_finite() && e.mean.abs() < 1e-100 {
                    "floating-point underflow: the weights' squared deviations fall below the \
                     smallest double, so the error bar cannot be computed in double precision \
                     (a scene: scale the emitters' radiance up; the answers scale with it)"
                } else {
                    "floating-point overflow"
                }
            ))),
            None => Ok(()),
        }
    }

    /// The warnings the command prints on stderr, one per caveat.
    pub fn warnings(&self) -> Vec<String> {
        self.caveats
            .iter()
            .map(|(q, why)| format!("warning: {q}: {why}"))
            .collect()
    }

    /// The JSON line (without its newline) of `--json`.
    pub fn json(&self) -> Result<String, Error> {
        self.check_finite()?;
        let r = &self.result;
        let mean_err = |q: &Quantity, e: &Estimate| MeanErr::of(e, caveat_of(&self.caveats, q));
        if matches!(self.header, Header::Rod(_)) {
            let [i, s, g] = rod_quantities().map(|q| r.get(&q).map(|e| mean_err(&q, &e)));
            return to_json(&RodJsonLine {
                method: r.method,
                intensity: i,
                sensitivity: s,
                gradient_x: g,
                paths: r.paths,
                seconds: r.seconds,
            });
        }
        let value = |q: &Quantity, e: &Estimate| {
            serde_json::to_value(mean_err(q, e)).map_err(|e| Error::Output(e.to_string()))
        };
        let mut intensity = None;
        let mut sensitivity = serde_json::Map::new();
        let mut gradient = serde_json::Map::new();
        for (q, e) in &r.estimates {
            match q {
                Quantity::Intensity => intensity = Some(mean_err(q, e)),
                Quantity::Sensitivity(p) => {
                    sensitivity.insert(p.clone(), value(q, e)?);
                }
                Quantity::Gradient(a) => {
                    gradient.insert(a.clone(), value(q, e)?);
                }
            }
        }
        to_json(&SceneJsonLine {
            method: r.method,
            intensity: intensity.ok_or_else(|| Error::Output("no intensity estimate".into()))?,
            sensitivity,
            gradient: (!gradient.is_empty()).then_some(gradient),
            paths: r.paths,
            seconds: r.seconds,
        })
    }

    /// The table the command prints without `--json`, every line ended by
    /// a newline.
    pub fn table(&self) -> Result<String, Error> {
        self.check_finite()?;
        match &self.header {
            Header::Rod(_) => self.rod_table(),
            Header::Scene {
                scene,
                shapes,
                parameters,
            } => Ok(self.scene_table(scene, *shapes, *parameters)),
        }
    }

    fn rod_table(&self) -> Result<String, Error> {
        let Some((rod, probe)) = self.header.rod()? else {
            unreachable!("called on a rod header")
        };
        let r = &self.result;
        let mut t = String::new();
        // Writing to a String cannot fail.
        let _ = writeln!(
            t,
            "rod κs = {:?}, κe = {:?}, length {:?}; probe x = {:?}, ω = {:+}",
            rod.ks,
            rod.ke,
            rod.length,
            probe.x,
            probe.omega.sign()
        );
        let _ = writeln!(
            t,
            "method {}: {} paths, seed {}, {:.3} s",
            r.method, r.paths, self.seed, r.seconds
        );
        // No `n` column: every quantity of a run has the run's paths, which
        // the line above gives, and the table keeps within 100 characters.
        let jumps = self.counts_jumps();
        let _ = writeln!(
            t,
            "{:<10} {:>13} {:>8} {:>9} {:>7} {:>9} {:>8} {:>13} {:>5}{}",
            "quantity",
            "mean",
            "stderr",
            "nonzero",
            "vov",
            "max_share",
            "reliable",
            "exact",
            "z",
            jumps_cell(jumps, || "jumps".to_owned())
        );
        let exact = rod_exact(&rod, &probe);
        let qs = rod_quantities();
        for (q, e) in &r.estimates {
            let ex = qs
                .iter()
                .position(|k| k == q)
                .map_or(f64::NAN, |i| exact[i]);
            let mc = e.n > 0;
            let _ = writeln!(
                t,
                "{:<10} {:>13.6e} {:>8.2e} {:>9} {:>7} {:>9} {:>8} {:>13} {:>5}{}",
                q.to_string(),
                e.mean,
                e.stderr,
                dash(mc, || e.nonzero.to_string()),
                dash(mc, || format!("{:.1e}", e.vov)),
                dash(mc, || format!("{:.1e}", e.max_share)),
                dash(mc, || reliable_text(e, caveat_of(&self.caveats, q))
                    .to_owned()),
                dash(mc, || format!("{ex:.6e}")),
                dash(mc, || z_text(e, ex)),
                jumps_cell(jumps, || jumps_text(e)),
            );
        }
        Ok(t)
    }

    /// Whether an estimate of the run counts its jumps (a central
    /// difference's derivatives): its table then has a `jumps` column.
    fn counts_jumps(&self) -> bool {
        self.result.estimates.iter().any(|(_, e)| e.jumps.is_some())
    }

    fn scene_table(&self, scene: &str, shapes: usize, parameters: usize) -> String {
        let r = &self.result;
        let mut t = String::new();
        let _ = writeln!(t, "scene {scene}: {shapes} shapes, {parameters} parameters");
        let _ = writeln!(
            t,
            "method {}: {} paths, seed {}, {:.3} s",
            r.method, r.paths, self.seed, r.seconds
        );
        let jumps = self.counts_jumps();
        let _ = writeln!(
            t,
            "{:<20} {:>14} {:>11} {:>9} {:>9} {:>9} {:>8}{}",
            "quantity",
            "mean",
            "stderr",
            "nonzero",
            "vov",
            "max_share",
            "reliable",
            jumps_cell(jumps, || "jumps".to_owned())
        );
        for (q, e) in &r.estimates {
            let caveat = caveat_of(&self.caveats, q);
            let _ = writeln!(
                t,
                "{:<20} {:>14.6e} {:>11.2e} {:>9} {:>9.1e} {:>9.1e} {:>8}{}",
                q.to_string(),
                e.mean,
                e.stderr,
                e.nonzero,
                e.vov,
                e.max_share,
                reliable_text(e, caveat),
                jumps_cell(jumps, || jumps_text(e))
            );
        }
        t
    }
}

/// The `jumps` cell, with its leading space, where the table has the
/// column (`shown`), else nothing.
fn jumps_cell(shown: bool, text: impl FnOnce() -> String) -> String {
    if shown {
        format!(" {:>7}", text())
    } else {
        String::new()
    }
}

/// An estimate's jumps ([`Estimate::jumps`]), `-` where not counted (a
/// central difference's `I`, which is no difference).
fn jumps_text(e: &Estimate) -> String {
    e.jumps.map_or("-".to_owned(), |k| k.to_string())
}

/// `text()` if `show`, else `-`.
fn dash(show: bool, text: impl FnOnce() -> String) -> String {
    if show { text() } else { "-".to_owned() }
}

/// `yes` or `no`.
pub fn yes_no(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}
