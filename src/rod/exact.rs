//! The exact rod solution (Bellman and Wing 1992; He et al. 2024, Appendix A,
//! with the argument `κe√(1−λ)` the extraction garbled).
//!
//! With `a = κe − κs/2`, `b = κs/2` and `k = √(a² − b²) = √(κe κa)`, the
//! two-stream system `±∂x I± = −a I± + b I∓`, `I+(0) = I0`, `I−(π̃) = 0`, is
//! solved in the distance `y = π̃ − x` from the moving end:
//!
//! `I+ = I0 f(π̃−x)/f(π̃)`, `I− = I0 b S(π̃−x)/f(π̃)`, with
//! `S(y) = sinh(ky)/k`, `C(y) = cosh(ky)`, `f = C + aS`, `f' = k²S + aC`.
//!
//! Then `∂xI = −∂y`, and `s = ∂π̃I` follows by the quotient rule. Every
//! function is evaluated scaled by `e^{−ky}`, with `S(y)e^{−ky} =
//! y·(1 − e^{−2ky})/(2ky)` through `expm1`: no overflow for thick rods, no
//! `0/0` at `κa = 0` (`k = 0`), exact at `κs = 0`. The book's chapter "The
//! rod and its exact solution" has the derivation.
use super::{Direction, Rod};
use crate::estimator::Quantity;

/// `I`, `∂I/∂π̃` and `∂I/∂x` at one point and direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solution {
    /// The intensity `I(x, ω)`.
    pub intensity: f64,
    /// The sensitivity `s = ∂I/∂π̃` at fixed `x`.
    pub sensitivity: f64,
    /// The spatial derivative `∂I/∂x`.
    pub gradient_x: f64,
}

impl Solution {
    /// The exact value of `q`: `I`, `s` for any sensitivity, `∂xI` for any
    /// gradient (the rod has one parameter and one axis).
    pub fn get(&self, q: &Quantity) -> f64 {
        match q {
            Quantity::Intensity => self.intensity,
            Quantity::Sensitivity(_) => self.sensitivity,
            Quantity::Gradient(_) => self.gradient_x,
        }
    }
}

// ANCHOR: solve
/// `(1 − e^{−t})/t`, 1 at `t = 0`, accurate for small `t`.
fn one_minus_exp_over(t: f64) -> f64 {
    if t == 0.0 { 1.0 } else { -(-t).exp_m1() / t }
}

/// The scaled hyperbolic functions at `y`: `(C, S)·e^{−ky}`.
fn scaled(k: f64, y: f64) -> (f64, f64) {
    let e = (-2.0 * k * y).exp();
    (0.5 * (1.0 + e), y * one_minus_exp_over(2.0 * k * y))
}

/// The exact `I`, `s` and `∂xI` at `x ∈ [0, π̃]` in direction `omega`.
pub fn solve(rod: &Rod, x: f64, omega: Direction) -> Solution {
    let (a, b) = (rod.ke - 0.5 * rod.ks, 0.5 * rod.ks);
    let k = (rod.ke * rod.ka()).max(0.0).sqrt();
    let y = rod.length - x;
    let (c, s) = scaled(k, y);
    let (cp, sp) = scaled(k, rod.length);
    let f = |c: f64, s: f64| c + a * s;
    let df = |c: f64, s: f64| k * k * s + a * c;
    let g = f(cp, sp);
    let dlog_g = df(cp, sp) / g;
    // e^{−kx} relates the two scalings, e^{−ky}/e^{−kπ̃}.
    let scale = rod.incoming * (-k * x).exp() / g;
    match omega {
        Direction::Right => Solution {
            intensity: scale * f(c, s),
            sensitivity: scale * (df(c, s) - f(c, s) * dlog_g),
            gradient_x: -scale * df(c, s),
        },
        Direction::Left => Solution {
            intensity: scale * b * s,
            sensitivity: scale * b * (c - s * dlog_g),
            gradient_x: -scale * b * c,
        },
    }
}
// ANCHOR_END: solve
