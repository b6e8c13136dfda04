//! What an optimisation asks of a scene, written once for both dimensions:
//! its measurements (each a sensor, with a target and a weight), the
//! objective over them, and the parameters' bounds. Book: chapter
//! "Sensitivities at work", section "Objectives".
//!
//! A file gives them as
//! ```toml
//! [objective]
//! kind = "least_squares"        # or "maximize", "minimize"
//!
//! [[measurements]]
//! kind = "irradiance"           # any sensor of the dimension
//! point = [0.3, 0.0]
//! normal = [0.0, 1.0]
//! target = 0.1234               # a camera's: one value per pixel
//! weight = 1.0                  # or sigma = 0.01 (weight 1/σ²)
//! ```
//! and `bounds = [lo, hi]` on a parameter (offsets from the file's pose).
use super::config;
use crate::error::Error;
use serde::de::{DeserializeOwned, Error as _};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// What the optimiser does with the measurements `I_k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectiveKind {
    /// An inverse problem: minimise `Σ_k w_k (I_k − T_k)²` (every
    /// measurement has a target `T_k`).
    LeastSquares,
    /// Design: maximise `Σ_k w_k I_k`.
    Maximize,
    /// Design: minimise `Σ_k w_k I_k`.
    Minimize,
}

impl ObjectiveKind {
    /// The name a file gives it.
    pub fn name(self) -> &'static str {
        match self {
            ObjectiveKind::LeastSquares => "least_squares",
            ObjectiveKind::Maximize => "maximize",
            ObjectiveKind::Minimize => "minimize",
        }
    }
}

/// The `[objective]` table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Objective {
    /// Least squares or design.
    pub kind: ObjectiveKind,
}

/// One measurement: a sensor of the scene's dimension, what it should read
/// (least squares) and how much it counts.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement<S> {
    /// Where and what is measured.
    pub sensor: S,
    /// The target: one value, or one per pixel (row-major) for a camera.
    pub target: Option<Vec<f64>>,
    /// The weight `w_k` in the objective (`1/σ²` when the file gives
    /// `sigma`); 1 by default.
    pub weight: f64,
}

/// The keys a measurement adds to its sensor's.
const OWN_KEYS: [&str; 3] = ["target", "weight", "sigma"];

impl<'de, S: DeserializeOwned> Deserialize<'de> for Measurement<S> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let mut table = serde_json::Map::<String, serde_json::Value>::deserialize(d)?;
        let mut own = OWN_KEYS.map(|k| table.remove(k));
        let sensor = serde_json::from_value(serde_json::Value::Object(table))
            .map_err(|e| D::Error::custom(format_args!("measurement: {e}")))?;
        let number = |key: &str, v: serde_json::Value| {
            v.as_f64()
                .ok_or_else(|| D::Error::custom(format_args!("field `{key}`: expected a number")))
        };
        let target = match own[0].take() {
            None => None,
            Some(serde_json::Value::Array(values)) => Some(
                values
                    .into_iter()
                    .map(|v| number("target", v))
                    .collect::<Result<Vec<_>, _>>()?,
            ),
            Some(v) => Some(vec![number("target", v)?]),
        };
        let weight = match (own[1].take(), own[2].take()) {
            (Some(_), Some(_)) => {
                return Err(D::Error::custom(
                    "a measurement takes `weight` or `sigma`, not both",
                ));
            }
            (Some(w), None) => number("weight", w)?,
            (None, Some(s)) => {
                let s = number("sigma", s)?;
                if !(s.is_finite() && s > 0.0) {
                    return Err(D::Error::custom(format_args!(
                        "field `sigma`: {s} is not a positive finite number"
                    )));
                }
                1.0 / (s * s)
            }
            (None, None) => 1.0,
        };
        Ok(Measurement {
            sensor,
            target,
            weight,
        })
    }
}

impl<S: Serialize> Serialize for Measurement<S> {
    fn serialize<Z: Serializer>(&self, z: Z) -> Result<Z::Ok, Z::Error> {
        use serde::ser::Error as _;
        let mut v = serde_json::to_value(&self.sensor).map_err(Z::Error::custom)?;
        if let Some(table) = v.as_object_mut() {
            match self.target.as_deref() {
                Some([one]) => {
                    table.insert("target".into(), (*one).into());
                }
                Some(many) => {
                    table.insert("target".into(), many.to_vec().into());
                }
                None => {}
            }
            if self.weight != 1.0 {
                table.insert("weight".into(), self.weight.into());
            }
        }
        v.serialize(z)
    }
}

/// Checks a parameter's bounds (offsets from the file's pose, which must
/// lie within them).
pub fn check_bounds(name: &str, bounds: [f64; 2]) -> Result<(), Error> {
    let [lo, hi] = bounds;
    if !(lo.is_finite() && hi.is_finite()) {
        return config(format!(
            "parameter {name:?}: field `bounds`: [{lo}, {hi}] is not finite"
        ));
    }
    if lo > hi {
        return config(format!(
            "parameter {name:?}: field `bounds`: [{lo}, {hi}] is reversed (low > high)"
        ));
    }
    if lo > 0.0 || hi < 0.0 {
        return config(format!(
            "parameter {name:?}: field `bounds`: [{lo}, {hi}] excludes 0, the file's pose \
             (bounds are offsets from it)"
        ));
    }
    Ok(())
}

/// Checks the measurements against the objective: a least-squares
/// objective needs a target on every measurement, weights are finite and
/// positive, targets finite.
pub fn check_measurements<S>(
    kind: ObjectiveKind,
    measurements: &[Measurement<S>],
) -> Result<(), Error> {
    if measurements.is_empty() {
        return config("an objective needs at least one entry in [[measurements]]".into());
    }
    for (i, m) in measurements.iter().enumerate() {
        if !(m.weight.is_finite() && m.weight > 0.0) {
            return config(format!(
                "measurements[{i}]: field `weight`: {} is not a positive finite number",
                m.weight
            ));
        }
        match &m.target {
            None if kind == ObjectiveKind::LeastSquares => {
                return config(format!(
                    "measurements[{i}]: field `target` is missing: a least_squares objective \
                     needs a target on every measurement"
                ));
            }
            Some(t) if t.iter().any(|v| !v.is_finite()) => {
                return config(format!(
                    "measurements[{i}]: field `target` holds a value that is not finite"
                ));
            }
            _ => {}
        }
    }
    Ok(())
}
