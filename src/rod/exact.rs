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
//! Then `∂xI = −∂y`, and `s = ∂π̃I` follows by the quotient rule, whose
//! numerator hyperbolic identities turn into products (no cancellation deep
//! in thick rods): `s(x,+1) = I0 b² S(x)/f(π̃)²`, `s(x,−1) = I0 b f(x)/f(π̃)²`.
//! Every
//! function is evaluated scaled by `e^{−ky}`, with `S(y)e^{−ky} =
//! y·(1 − e^{−2ky})/(2ky)` through `expm1`: no overflow for thick rods, no
//! `0/0` at `κa = 0` (`k = 0`), exact at `κs = 0`. The book's chapter "The
//! rod and its exact solution" has the derivation.
//!
//! Only optical quantities matter: `I` depends on `κe π̃`, `κs π̃` and
//! `x/π̃` alone, and `s`, `∂xI` are `1/π̃` times functions of them. So the
//! solution is evaluated in optical units (lengths over `π̃`, coefficients
//! times `π̃`), where every number is at most the optical thickness (≤ 10⁴),
//! and `s`, `∂xI` are divided by `π̃` last. In physical units `κe κa`
//! underflows from `κ ≈ 1e-162` and `2π̃` overflows from `π̃ ≈ 9e307`, while
//! the rod's validation accepts both.
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
    // Optical units: the rod is [0, 1], coefficients are optical depths
    // (each ≤ κe π̃ ≤ 10⁴: no overflow, and κa π̃ from κe − κs directly).
    let l = rod.length;
    let (tau_e, tau_s, tau_a) = (rod.ke * l, rod.ks * l, rod.ka() * l);
    let (a, b) = (tau_e - 0.5 * tau_s, 0.5 * tau_s);
    let k = (tau_e * tau_a).sqrt();
    // The probe, and its distance to the moving end (exact near that end).
    let (x, y) = (x / l, (l - x) / l);
    let f = |(c, s): (f64, f64)| c + a * s;
    let df = |(c, s): (f64, f64)| k * k * s + a * c;
    let at_y = scaled(k, y);
    let at_x = scaled(k, x);
    let g = f(scaled(k, 1.0));
    // e^{−kx} relates the scalings of y = 1 − x and 1; e^{−k(1 + y)} those of
    // x and 1² in the sensitivity's product form.
    let scale = rod.incoming * (-k * x).exp() / g;
    let scale_s = rod.incoming * b * (-k * (1.0 + y)).exp() / (g * g);
    // s and ∂xI are rates per unit length: back to physical units by 1/π̃.
    match omega {
        Direction::Right => Solution {
            intensity: scale * f(at_y),
            // f'(y) f(1) − f(y) f'(1) = b² S(x): no cancellation.
            sensitivity: scale_s * b * at_x.1 / l,
            gradient_x: -scale * df(at_y) / l,
        },
        Direction::Left => Solution {
            intensity: scale * b * at_y.1,
            // C(y) f(1) − S(y) f'(1) = f(x).
            sensitivity: scale_s * f(at_x) / l,
            gradient_x: -scale * b * at_y.0 / l,
        },
    }
}
// ANCHOR_END: solve
