//! The rod of He et al. (2024), Section 3: a segment `[0, π̃]` of homogeneous
//! medium (scattering `κs`, extinction `κe`, absorption `κa = κe − κs`) where
//! particles travel only along the axis, `ω ∈ {+1, −1}`, and scatter
//! isotropically between the two directions. Intensity `I0` enters at `x = 0`
//! going right; nothing enters at `x = π̃`. The shape parameter is the length
//! `π̃`; the sensitivity is `s(x, ω) = ∂I/∂π̃` at fixed `x`.
//!
//! A rod needs a float and a sign, so positions are `f64` and directions are
//! [`Direction`]. The estimators live in one module each, the exact solution in
//! [`exact`], the shared random walk in [`walk`]. Book: chapter "The rod and its
//! exact solution".
use crate::error::{Error, check};
use crate::estimator::Estimator;
use crate::fd::{CentralDifference, DEFAULT_STEP, Pair, check_step, invalid_displacement};
use crate::method::Problem;

pub mod exact;
pub mod expectation;
#[cfg(feature = "figures")]
pub mod figures;
pub mod intensity;
pub mod rendering;
pub mod transport;
pub mod walk;

/// A direction of travel along the rod.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Direction {
    /// `ω = +1`, towards increasing `x`.
    Right,
    /// `ω = −1`, towards decreasing `x`.
    Left,
}

impl Direction {
    /// `ω` as a number, `+1` or `−1`.
    #[inline]
    pub fn sign(self) -> f64 {
        match self {
            Direction::Right => 1.0,
            Direction::Left => -1.0,
        }
    }

    /// The opposite direction: a backward path from a probe looking along `ω`
    /// travels along `−ω`.
    #[inline]
    pub fn reverse(self) -> Direction {
        match self {
            Direction::Right => Direction::Left,
            Direction::Left => Direction::Right,
        }
    }

    /// The rod end that a particle travelling this way reaches.
    #[inline]
    pub fn end(self) -> Side {
        match self {
            Direction::Right => Side::End,
            Direction::Left => Side::Start,
        }
    }

    /// Parses `ω` from a number: `+1` or `−1`, anything else is an error.
    pub fn from_sign(omega: f64) -> Result<Direction, Error> {
        if omega == 1.0 {
            Ok(Direction::Right)
        } else if omega == -1.0 {
            Ok(Direction::Left)
        } else {
            Err(Error::InvalidParameter {
                name: "omega",
                value: omega,
                expected: "+1 or -1",
            })
        }
    }
}

/// An end of the rod.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Side {
    /// `x = 0`, the fixed end where `I0` enters.
    Start,
    /// `x = π̃`, the moving end.
    End,
}

/// The rod: its coefficients, its length and the intensity entering at `x = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rod {
    /// Scattering coefficient `κs ≥ 0`.
    pub ks: f64,
    /// Extinction coefficient `κe ≥ κs`.
    pub ke: f64,
    /// Length `π̃ > 0`, the shape parameter.
    pub length: f64,
    /// Intensity `I0` entering at `x = 0` going right.
    pub incoming: f64,
}

impl Rod {
    /// Largest optical thickness `κe π̃` a rod may have.
    pub const MAX_OPTICAL_THICKNESS: f64 = 1e4;

    /// A rod with `I0 = 1`; errors name any value out of its domain.
    pub fn new(ks: f64, ke: f64, length: f64) -> Result<Rod, Error> {
        let ks = check("ks", ks, ks >= 0.0, "a finite number >= 0")?;
        let ke = check("ke", ke, ke >= ks, "a finite number >= ks")?;
        let length = check("length", length, length > 0.0, "a finite number > 0")?;
        // A conservative rod's paths take ~(κe π̃)² collisions: 10⁸ at the
        // bound, beyond which a run would not end in any useful time.
        check(
            "optical thickness ke*length",
            ke * length,
            ke * length <= Self::MAX_OPTICAL_THICKNESS,
            "at most 1e4",
        )?;
        Ok(Rod {
            ks,
            ke,
            length,
            incoming: 1.0,
        })
    }

    /// The same rod with entering intensity `i0` (finite, ≥ 0).
    pub fn with_incoming(self, i0: f64) -> Result<Rod, Error> {
        let incoming = check("incoming", i0, i0 >= 0.0, "a finite number >= 0")?;
        Ok(Rod { incoming, ..self })
    }

    /// Absorption coefficient `κa = κe − κs`.
    #[inline]
    pub fn ka(&self) -> f64 {
        self.ke - self.ks
    }

    /// Single-scattering albedo `λ = κs/κe` (0 for an empty rod).
    pub fn albedo(&self) -> f64 {
        if self.ke > 0.0 {
            self.ks / self.ke
        } else {
            0.0
        }
    }

    /// The intensity entering the rod at `side`: what a backward path that
    /// leaves through `side` collects (`I0` at the start, 0 at the end).
    #[inline]
    pub fn incoming_at(&self, side: Side) -> f64 {
        match side {
            Side::Start => self.incoming,
            Side::End => 0.0,
        }
    }

    /// Distance from `x` to the end reached travelling along `dir` (Eq. 27).
    #[inline]
    pub fn distance_to_boundary(&self, x: f64, dir: Direction) -> f64 {
        match dir {
            Direction::Right => self.length - x,
            Direction::Left => x,
        }
    }
}

/// Where the intensity is observed: a position on the rod and a direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Probe {
    /// Position `0 ≤ x ≤ π̃`.
    pub x: f64,
    /// Direction `ω` of the observed intensity.
    pub omega: Direction,
}

impl Probe {
    /// A probe on `rod`; errors if `x` is outside `[0, π̃]` or not finite.
    pub fn new(rod: &Rod, x: f64, omega: Direction) -> Result<Probe, Error> {
        let x = check("x", x, (0.0..=rod.length).contains(&x), "0 <= x <= length")?;
        Ok(Probe { x, omega })
    }
}

/// The methods: every [`Method`] runs on a rod (`method.estimator((rod,
/// probe))`): intensity (Algorithm 3), expectation (Algorithm 4), rendering
/// (Algorithm 5), transport (the coupled models `{I, s, ∂xI}` of Eqs. 41–43)
/// and central finite differences in the length.
pub use crate::method::Method;

impl Problem for (Rod, Probe) {
    /// For [`Method::Fd`] the half step is `fd_step` times the rod's length.
    fn estimator(&self, method: Method, fd_step: Option<f64>) -> Result<Box<dyn Estimator>, Error> {
        let (rod, probe) = *self;
        check_collisions(&rod)?;
        Ok(match method {
            Method::Intensity => Box::new(intensity::IntensityEstimator { rod, probe }),
            Method::Expectation => Box::new(expectation::ExpectationEstimator { rod, probe }),
            Method::Rendering => Box::new(rendering::RenderingEstimator { rod, probe }),
            Method::Transport => Box::new(transport::TransportEstimator { rod, probe }),
            Method::Fd => Box::new(finite_difference(
                rod,
                probe,
                fd_step.map_or(Ok(DEFAULT_STEP), check_step)?,
            )?),
        })
    }
}

/// Most collisions a rod's path is expected to need: beyond, a Monte Carlo
/// run would not end in any useful time (the exact solution still serves).
pub const MAX_COLLISIONS: f64 = 1e6;

/// Refuses Monte Carlo on a rod whose paths would need more than
/// [`MAX_COLLISIONS`] collisions: about `(κs π̃)²` in a conservative rod
/// (a random walk leaves a slab of optical thickness τ after ~τ² steps), and
/// at most `746 κs/κa` where absorption ends a path (its weight `e^{−κa L}`
/// is exactly 0 from `κa L = 746` on, and the walk stops there).
fn check_collisions(rod: &Rod) -> Result<(), Error> {
    let tau = rod.ks * rod.length;
    let ka = rod.ka();
    let walk = tau * tau;
    let collisions = if ka > 0.0 {
        walk.min(746.0 * rod.ks / ka)
    } else {
        walk
    };
    if collisions > MAX_COLLISIONS {
        return Err(Error::Config(format!(
            "a path in this rod (κs × length = {}, albedo {}) would collide ~{} times: \
             Monte Carlo is refused beyond {MAX_COLLISIONS:e} (use --method exact, or \
             a thinner or more absorbing rod)",
            crate::error::Num(tau),
            crate::error::Num(rod.albedo()),
            crate::error::Num(collisions.round())
        )));
    }
    Ok(())
}

/// Central differences in the length with common random numbers: `I` at
/// `probe`, then `[I(π̃ + h) − I(π̃ − h)]/2h` with `h = step × π̃`; errors if
/// the probe is at the moving end (`x = π̃`) or a displaced rod is invalid
/// (the probe beyond the shortened rod's end, the lengthened rod too thick).
/// An optically thin rod's difference carries a caveat
/// ([`thin_medium_caveat`](crate::fd::thin_medium_caveat)).
pub fn finite_difference(rod: Rod, probe: Probe, step: f64) -> Result<CentralDifference, Error> {
    if probe.x >= rod.length {
        return Err(Error::InvalidParameter {
            name: "x",
            value: probe.x,
            expected: "x < length for fd: finite differences in the length shorten the rod, \
                       and no shortened rod contains its end (the other methods take x = length)",
        });
    }
    let h = step * rod.length;
    let displaced = |delta: f64| -> Result<Box<dyn Estimator>, Error> {
        let moved = Rod::new(rod.ks, rod.ke, rod.length + delta)
            .and_then(|r| r.with_incoming(rod.incoming))
            .and_then(|r| Ok((r, Probe::new(&r, probe.x, probe.omega)?)))
            .map_err(|e| {
                let note = format!(" (half step {step} × length {})", rod.length);
                invalid_displacement("rod", PARAMETER, delta, &note, e)
            })?;
        Method::Intensity.estimator(moved)
    };
    let pair = Pair {
        parameter: PARAMETER.to_owned(),
        plus: displaced(h)?,
        minus: displaced(-h)?,
        half_step: h,
    };
    let fd = CentralDifference::new(Some(Method::Intensity.estimator((rod, probe))?), vec![pair])?;
    // A thin rod's collisions are drawn at a raised rate: its pairs jump.
    Ok(
        match crate::fd::thin_medium_caveat([("rod", rod.ks, rod.length)]) {
            Some(why) => fd.with_caveat(PARAMETER, why),
            None => fd,
        },
    )
}

/// The name of the rod's shape parameter in estimator outputs.
pub const PARAMETER: &str = "length";
