//! Errors for bad user input. Nothing a user passes in panics: every
//! constructor validates and names the offending value.
use thiserror::Error;

/// What went wrong, with the name and value of the bad input.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// A numeric parameter is out of its domain (or not finite).
    #[error("invalid {name} = {value}: expected {expected}")]
    InvalidParameter {
        /// Name of the parameter, as the CLI and the docs spell it.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// The domain the value must lie in.
        expected: &'static str,
    },
    /// The run configuration cannot be honoured (thread pool, sample count).
    #[error("invalid run configuration: {0}")]
    Config(String),
    /// A scene is invalid (geometry, coefficients, parameters, sensor) or
    /// its file cannot be read.
    #[error("invalid scene: {0}")]
    Scene(String),
    /// Writing a result (figure, table) failed.
    #[error("{0}")]
    Output(String),
}

/// Checks that `value` is finite and satisfies `ok`, or names it in an error.
pub(crate) fn check(
    name: &'static str,
    value: f64,
    ok: bool,
    expected: &'static str,
) -> Result<f64, Error> {
    if value.is_finite() && ok {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name,
            value,
            expected,
        })
    }
}
