//! The estimation methods, one enum for every scene kind, and [`Problem`]:
//! what a method is asked to estimate on (a probe on a rod, a flatland scene).
//!
//! `Method::Expectation.estimator((rod, probe))` and
//! `Method::Fd.estimator(scene)` build the same method on two scene kinds; a
//! method a scene kind does not support is an error, never a panic.
use crate::error::Error;
use crate::estimator::Estimator;
use std::fmt;
use std::str::FromStr;

pub mod model;

/// A Monte Carlo estimation method. The CLI's `--method` takes these names
/// (`clap::ValueEnum`); the variants' one-line doc comments are its help.
///
/// On the rod ([`crate::rod`]) the methods are the paper's Algorithms 3
/// (intensity), 4 (expectation) and 5 (rendering) and its coupled transport
/// models `{I, s, ∂xI}` (Eqs. 41–43), which also return `∂I/∂x`. In flatland
/// ([`crate::flat`]) expectation carries the warp field and stretched free
/// paths, rendering joins the corner and medium-boundary terms by double
/// randomisation, and transport keeps the path still, with sources where it
/// meets moving boundaries coupled to the radiance gradient there (nested
/// walks), and also returns `∂I/∂x`, `∂I/∂y` at the sensor. On both,
/// [`Method::Fd`] is [`crate::fd::CentralDifference`]: `I` on the nominal
/// scene and, per parameter, the scene displaced both ways, all with common
/// random numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Method {
    /// Backward path tracing of I only.
    Intensity,
    /// Expectation differentiation: I and s from the same paths.
    Expectation,
    /// Differentiable rendering: boundary terms by double randomization.
    Rendering,
    /// Sensitivity transport: s transported with I and ∂I/∂x.
    Transport,
    /// Central finite differences with common random numbers.
    Fd,
}

impl Method {
    /// Every method, in the order the CLI lists them.
    pub const ALL: [Method; 5] = [
        Method::Intensity,
        Method::Expectation,
        Method::Rendering,
        Method::Transport,
        Method::Fd,
    ];

    /// The four unbiased methods (all but [`Method::Fd`]), in the order the
    /// comparison tables print them.
    pub const UNBIASED: [Method; 4] = [
        Method::Intensity,
        Method::Expectation,
        Method::Rendering,
        Method::Transport,
    ];

    /// The method's name, as the CLI spells it.
    pub fn name(self) -> &'static str {
        match self {
            Method::Intensity => "intensity",
            Method::Expectation => "expectation",
            Method::Rendering => "rendering",
            Method::Transport => "transport",
            Method::Fd => "fd",
        }
    }

    /// The estimator of this method on `problem` (finite differences with
    /// the problem's default half step); errors if the problem does not
    /// support the method or a displaced problem is invalid.
    pub fn estimator(self, problem: impl Problem) -> Result<Box<dyn Estimator>, Error> {
        problem.estimator(self, None)
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = Error;

    /// Parses a method from its [`name`](Method::name).
    fn from_str(s: &str) -> Result<Method, Error> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
                Error::Config(format!(
                    "unknown method {s:?}: expected one of {}",
                    names.join(", ")
                ))
            })
    }
}

/// What the methods estimate on: a probe on a rod (`(Rod, Probe)`), a
/// flatland scene (`Arc<Scene>`).
pub trait Problem {
    /// The estimator of `method`. For [`Method::Fd`], `fd_step` is the half
    /// step ([`fd::DEFAULT_STEP`](crate::fd::DEFAULT_STEP) if `None`),
    /// relative to the scene's size for a translation and absolute for a
    /// rotation (radians) or a scale. Errors if the problem does not support
    /// `method`, the step is not in `(0, 1)`, or a displaced problem is
    /// invalid (the error then names the parameter and the displacement).
    fn estimator(&self, method: Method, fd_step: Option<f64>) -> Result<Box<dyn Estimator>, Error>;
}

/// A borrowed problem is a problem: `method.estimator(&scene)`.
impl<P: Problem + ?Sized> Problem for &P {
    fn estimator(&self, method: Method, fd_step: Option<f64>) -> Result<Box<dyn Estimator>, Error> {
        (**self).estimator(method, fd_step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_are_errors() {
        for m in Method::ALL {
            assert_eq!(m.name().parse::<Method>(), Ok(m));
            assert_eq!(m.to_string(), m.name());
            let clap = clap::ValueEnum::to_possible_value(&m).unwrap();
            assert_eq!(clap.get_name(), m.name());
        }
        let e = "magic".parse::<Method>().unwrap_err().to_string();
        assert!(e.contains("magic") && e.contains("fd"), "{e}");
        assert!(!Method::UNBIASED.contains(&Method::Fd));
    }
}
