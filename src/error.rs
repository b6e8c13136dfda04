//! Errors for bad user input. Nothing a user passes in panics: every
//! constructor validates and names the offending value.
use thiserror::Error;

/// What went wrong, with the name and value of the bad input.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// A numeric parameter is out of its domain (or not finite).
    #[error("invalid {name} = {}: expected {expected}", Num(*value))]
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
    /// The half step of central finite differences (`--method fd`) is too
    /// large for the problem: the problem displaced by it is invalid
    /// (shapes that touch, a probe beyond the shortened rod's end). A
    /// smaller step helps; the scene itself is valid.
    #[error("fd step too large: {0}")]
    FdStep(String),
    /// States of shards that do not make one whole run, or a file that is
    /// not a state.
    #[error("cannot merge: {0}")]
    Merge(String),
    /// Writing a result (figure, table) failed.
    #[error("{0}")]
    Output(String),
    /// A run was stopped before its end by its progress hook
    /// ([`crate::runner::Progress`]): an interrupt, a time budget.
    #[error("stopped before the end: {0}")]
    Stopped(String),
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

/// A number as a person reads it: plain between 10⁻⁴ and 10¹⁵, in
/// scientific notation beyond (Rust's `{}` writes `1e300` with 301 digits),
/// always the shortest form that reads back to the same `f64`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-4..1e15).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_print_short() {
        assert_eq!(Num(1e300).to_string(), "1e300");
        assert_eq!(Num(-2.5e-200).to_string(), "-2.5e-200");
        assert_eq!(Num(0.1).to_string(), "0.1");
        assert_eq!(Num(123456.5).to_string(), "123456.5");
        assert_eq!(Num(f64::NAN).to_string(), "NaN");
        let e = Error::InvalidParameter {
            name: "ke",
            value: 1e300,
            expected: "x",
        };
        assert!(e.to_string().len() < 40, "{e}");
    }
}
