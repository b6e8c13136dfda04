//! What `geosens` prints: the JSON lines (every estimate with its mean,
//! standard error, count of non-zero weights and reliability) and the
//! checks before printing.
use super::*;

/// Mean and standard error, as the JSON line prints them, with the count
/// of non-zero weights and whether the error bar can be trusted.
#[derive(Serialize)]
pub(super) struct MeanErr {
    /// Estimated value.
    mean: f64,
    /// Its standard error (0 for `exact`).
    stderr: f64,
    /// Paths whose weight was not zero (0 for `exact`).
    nonzero: u64,
    /// Whether the error bar can be trusted ([`Estimate::is_reliable`] and
    /// no caveat).
    reliable: bool,
    /// Why the estimate may be far off whatever its error bar, if the
    /// estimator said so when it was built.
    #[serde(skip_serializing_if = "Option::is_none")]
    caveat: Option<String>,
}

impl MeanErr {
    /// The JSON form of `e`, with the caveat on its quantity if any.
    pub(super) fn of(e: &Estimate, caveat: Option<&String>) -> MeanErr {
        MeanErr {
            mean: e.mean,
            stderr: e.stderr,
            nonzero: e.nonzero,
            reliable: e.is_reliable() && caveat.is_none(),
            caveat: caveat.cloned(),
        }
    }
}

/// The caveat the estimator raised on quantity `q`, if any.
pub(super) fn caveat_of<'a>(caveats: &'a [(Quantity, String)], q: &Quantity) -> Option<&'a String> {
    caveats.iter().find(|(k, _)| k == q).map(|(_, why)| why)
}

/// `z` as the tables print it: `-` where the error bar is 0 and the
/// estimate is off (no finite z; `reliable` says why).
pub(super) fn z_text(e: &Estimate, exact: f64) -> String {
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
pub(super) struct JsonLine<'a> {
    /// Method name.
    pub(super) method: &'a str,
    /// `I`.
    pub(super) intensity: Option<MeanErr>,
    /// `∂I/∂length`.
    pub(super) sensitivity: Option<MeanErr>,
    /// `∂I/∂x`.
    pub(super) gradient_x: Option<MeanErr>,
    /// Paths sampled (0 for `exact`).
    pub(super) paths: u64,
    /// Wall time of the sampling (or evaluation), in seconds.
    pub(super) seconds: f64,
}

/// Refuses a result with a non-finite estimate: serde_json would print a
/// NaN as `null`, indistinguishable from "not estimated".
pub(super) fn all_finite(result: &RunResult) -> Result<(), String> {
    match result
        .estimates
        .iter()
        .find(|(_, e)| !(e.mean.is_finite() && e.stderr.is_finite()))
    {
        Some((q, e)) => Err(format!(
            "method {} gives {q} = {} ± {} at these inputs (floating-point overflow)",
            result.method,
            Num(e.mean),
            Num(e.stderr)
        )),
        None => Ok(()),
    }
}

/// The one JSON line of `geosens flat --json`: the rod's shape, with one
/// sensitivity per parameter.
#[derive(Serialize)]
pub(super) struct FlatJsonLine<'a> {
    /// Method name.
    pub(super) method: &'a str,
    /// The sensor's reading.
    pub(super) intensity: MeanErr,
    /// `∂I/∂π` keyed by parameter name (declaration order).
    pub(super) sensitivity: serde_json::Map<String, serde_json::Value>,
    /// `∂I/∂x`, `∂I/∂y` at the sensor (`transport` only).
    pub(super) gradient: Option<serde_json::Map<String, serde_json::Value>>,
    /// Paths sampled.
    pub(super) paths: u64,
    /// Wall time of the sampling, in seconds.
    pub(super) seconds: f64,
}
