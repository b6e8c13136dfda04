//! The exact rod solution against an independent numerical solution of the
//! two-stream ODE: RK4 shooting from the moving end, `s` by a central finite
//! difference of the numerical solution in the length, `∂xI` from the ODE's
//! right-hand side. Also against the paper's Eqs. 44–45 (argument corrected).
use geosens::rod::{Direction, Rod, exact};

/// `(I+, I−)` at `x` from RK4 integration of `±∂x I± = −a I± + b I∓` from
/// `x = length` (`I− = 0`) down to 0, normalised so that `I+(0) = I0`.
fn rk4(rod: &Rod, length: f64, x: f64) -> (f64, f64) {
    let (a, b) = (rod.ke - 0.5 * rod.ks, 0.5 * rod.ks);
    let rhs = |p: f64, m: f64| (-a * p + b * m, a * m - b * p);
    let step = |(p, m): (f64, f64), h: f64| {
        let k1 = rhs(p, m);
        let k2 = rhs(p + 0.5 * h * k1.0, m + 0.5 * h * k1.1);
        let k3 = rhs(p + 0.5 * h * k2.0, m + 0.5 * h * k2.1);
        let k4 = rhs(p + h * k3.0, m + h * k3.1);
        (
            p + h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0),
            m + h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1),
        )
    };
    // A fixed step count per leg keeps the RK4 error smooth in the length,
    // which the finite difference below needs.
    let integrate = |mut s: (f64, f64), from: f64, to: f64| {
        let n = 20_000;
        let h = (to - from) / n as f64;
        for _ in 0..n {
            s = step(s, h);
        }
        s
    };
    let at_x = integrate((1.0, 0.0), length, x);
    let at_0 = integrate(at_x, x, 0.0);
    let scale = rod.incoming / at_0.0;
    (at_x.0 * scale, at_x.1 * scale)
}

fn numerical(rod: &Rod, x: f64, omega: Direction) -> exact::Solution {
    let pick = |(p, m): (f64, f64)| if omega == Direction::Right { p } else { m };
    let (p, m) = rk4(rod, rod.length, x);
    let (a, b) = (rod.ke - 0.5 * rod.ks, 0.5 * rod.ks);
    // Fourth-order central difference in the length.
    let delta = 1e-3;
    let at = |d: f64| pick(rk4(rod, rod.length + d, x));
    let sensitivity =
        (8.0 * (at(delta) - at(-delta)) - (at(2.0 * delta) - at(-2.0 * delta))) / (12.0 * delta);
    exact::Solution {
        intensity: pick((p, m)),
        sensitivity,
        gradient_x: pick((-a * p + b * m, a * m - b * p)),
    }
}

fn close(a: f64, b: f64, rel: f64, scale: f64) -> bool {
    (a - b).abs() <= rel * scale.max(f64::MIN_POSITIVE)
}

fn rods() -> Vec<(&'static str, Rod)> {
    vec![
        ("thin", Rod::new(0.07, 0.1, 2.0).unwrap()),
        ("thick", Rod::new(2.1, 3.0, 2.0).unwrap()),
        ("no absorption", Rod::new(1.5, 1.5, 2.0).unwrap()),
        (
            "almost no absorption",
            Rod::new(1.5, 1.5 * (1.0 + 1e-12), 2.0).unwrap(),
        ),
        ("no scattering", Rod::new(0.0, 1.2, 2.0).unwrap()),
        ("thick, scattering", Rod::new(24.0, 25.0, 2.0).unwrap()),
        ("thick, absorbing", Rod::new(0.0, 25.0, 2.0).unwrap()),
        ("thick, conservative", Rod::new(25.0, 25.0, 2.0).unwrap()),
        ("empty", Rod::new(0.0, 0.0, 1.0).unwrap()),
        (
            "I0 = 3",
            Rod::new(0.5, 0.8, 1.0).unwrap().with_incoming(3.0).unwrap(),
        ),
    ]
}

#[test]
fn exact_matches_numerical_ode_solution() {
    for (name, rod) in rods() {
        for i in 0..=8 {
            let x = rod.length * i as f64 / 8.0;
            for omega in [Direction::Right, Direction::Left] {
                let e = exact::solve(&rod, x, omega);
                let n = numerical(&rod, x, omega);
                // Scale of each field: the intensity entering, times the rate.
                let rate = rod.ke.max(1.0 / rod.length);
                for (what, a, b, scale) in [
                    ("I", e.intensity, n.intensity, n.intensity.abs()),
                    ("s", e.sensitivity, n.sensitivity, n.sensitivity.abs()),
                    ("dI/dx", e.gradient_x, n.gradient_x, n.gradient_x.abs()),
                ] {
                    // Relative 1e-6 of the value, or 1e-9 of I0·rate for values near 0.
                    let ok = close(a, b, 1e-6, scale) || close(a, b, 1e-9, rod.incoming * rate);
                    assert!(
                        ok,
                        "{name}: {what} at x={x} {omega:?}: exact {a} vs ODE {b}"
                    );
                    assert!(a.is_finite());
                }
            }
        }
    }
}

/// The paper's Eqs. 44–45 with the hyperbolic argument `κe√(1−λ)`, for
/// `λ < 1`, `I0 = 1`.
fn bellman_wing(rod: &Rod, x: f64, omega: Direction) -> f64 {
    let l = rod.ks / rod.ke;
    let q = (1.0 - l).sqrt();
    let arg = |y: f64| y * rod.ke * q;
    let den = 2.0 * (l - 1.0) * arg(rod.length).cosh() + q * (l - 2.0) * arg(rod.length).sinh();
    let y = rod.length - x;
    match omega {
        Direction::Right => (2.0 * (l - 1.0) * arg(y).cosh() + q * (l - 2.0) * arg(y).sinh()) / den,
        Direction::Left => -l * q * arg(y).sinh() / den,
    }
}

#[test]
fn exact_matches_paper_formula() {
    for (ks, ke) in [(0.07, 0.1), (2.1, 3.0), (0.0, 1.0), (0.9, 1.0)] {
        let rod = Rod::new(ks, ke, 2.0).unwrap();
        for x in [0.0, 0.3, 1.0, 1.7, 2.0] {
            for omega in [Direction::Right, Direction::Left] {
                let a = exact::solve(&rod, x, omega).intensity;
                let b = bellman_wing(&rod, x, omega);
                assert!(
                    (a - b).abs() <= 1e-13 * b.abs().max(1e-3),
                    "{ks} {ke} {x} {omega:?}: {a} vs {b}"
                );
            }
        }
    }
}

#[test]
fn boundary_identities() {
    // I(π̃, −1) = 0 for every π̃, so s = −∂xI there; and s(π̃,−1) = (κs/2) I(π̃,+1).
    for (_, rod) in rods() {
        let end_left = exact::solve(&rod, rod.length, Direction::Left);
        let end_right = exact::solve(&rod, rod.length, Direction::Right);
        let tol = 1e-12 * rod.ke.max(1.0);
        assert_eq!(end_left.intensity, 0.0);
        assert!((end_left.sensitivity + end_left.gradient_x).abs() <= tol);
        assert!((end_left.sensitivity - 0.5 * rod.ks * end_right.intensity).abs() <= tol);
        // Nothing at x = 0 going right depends on the length.
        let start = exact::solve(&rod, 0.0, Direction::Right);
        assert!((start.intensity - rod.incoming).abs() <= 1e-14 * rod.incoming);
        assert!(start.sensitivity.abs() <= tol);
    }
}

#[test]
fn sensitivities_are_positive_deep_in_thick_rods() {
    // s(x,+1) = I0 b² S(x)/f(π̃)² and s(x,−1) = I0 b f(x)/f(π̃)²: positive for
    // κs > 0 (x > 0 looking right), however small. A quotient-rule evaluation
    // cancels to 0 or to the wrong sign here.
    for (ks, ke, length) in [
        (25.0, 50.0, 1.0),
        (2.1, 3.0, 20.0),
        (49.0, 50.0, 1.0),
        (50.0, 50.0, 1.0),
    ] {
        let rod = Rod::new(ks, ke, length).unwrap();
        for i in 0..=10 {
            let x = length * i as f64 / 10.0;
            let left = exact::solve(&rod, x, Direction::Left).sensitivity;
            assert!(left > 0.0, "s({x}, -1) = {left} on {rod:?}");
            if x > 0.0 {
                let right = exact::solve(&rod, x, Direction::Right).sensitivity;
                assert!(right > 0.0, "s({x}, +1) = {right} on {rod:?}");
            }
        }
    }
}

#[test]
fn very_thick_rods_do_not_overflow() {
    // Up to the largest optical thickness a rod may have, kπ̃ far past the
    // ≈ 710 where unscaled cosh overflows.
    for (ks, ke, length) in [
        (49.0, 50.0, 1.0),
        (50.0, 50.0, 1.0),
        (0.0, 50.0, 1.0),
        (25.0, 50.0, 1.0),
        (0.0, 1e4, 1.0),
        (5e3, 1e4, 1.0),
    ] {
        let rod = Rod::new(ks, ke, length).unwrap();
        for x in [0.0, 0.5, 1.0] {
            for omega in [Direction::Right, Direction::Left] {
                let e = exact::solve(&rod, x, omega);
                assert!(
                    e.intensity.is_finite()
                        && e.sensitivity.is_finite()
                        && e.gradient_x.is_finite()
                );
                assert!(e.intensity >= 0.0 && e.intensity <= 1.0);
            }
        }
    }
}

/// Asserts `scaled == unit / c`: exactly where that is a normal number (the
/// scaling by a power of two commutes with rounding), within two of the
/// smallest subnormals where it underflows.
fn assert_scaled(what: &str, scaled: f64, unit: f64, c: f64) {
    let want = unit / c;
    let ok = if want.abs() >= f64::MIN_POSITIVE {
        scaled == want
    } else {
        (scaled - want).abs() <= 2.0 * f64::from_bits(1)
    };
    assert!(ok, "{what}: {scaled:e} at scale {c:e}, want {want:e}");
}

#[test]
fn only_optical_variables_matter_at_every_scale() {
    // Lengths times c = 2^k, coefficients over c: κ·length, the albedo and
    // x/length are the same bits, so I must be too, and s and ∂xI (per unit
    // length) exactly 1/c times the unit-scale values. With k = ±664 the
    // product κe·κa of the old `k = √(κe κa)` underflowed or overflowed.
    for (name, rod) in rods() {
        for k in [-1000, -664, -300, 300, 664, 1000] {
            let c = 2f64.powi(k);
            let scaled = Rod::new(rod.ks / c, rod.ke / c, rod.length * c)
                .unwrap()
                .with_incoming(rod.incoming)
                .unwrap();
            for i in 0..=8 {
                let x = rod.length * i as f64 / 8.0;
                for omega in [Direction::Right, Direction::Left] {
                    let what = format!("{name} at x = {x}·2^{k}, {omega:?}");
                    let unit = exact::solve(&rod, x, omega);
                    let e = exact::solve(&scaled, x * c, omega);
                    assert_eq!(e.intensity, unit.intensity, "I: {what}");
                    assert_scaled(&format!("s: {what}"), e.sensitivity, unit.sensitivity, c);
                    assert_scaled(&format!("∂xI: {what}"), e.gradient_x, unit.gradient_x, c);
                }
            }
        }
    }
}

#[test]
fn extreme_unit_scales_of_the_issue() {
    // `--ks 2.1e-200 --ke 3e-200 --length 2e200 --x 1e200 --omega 1` is the
    // thick rod at x = 1 (I = 0.1928), not I = 0.602.
    let unit = exact::solve(&Rod::new(2.1, 3.0, 2.0).unwrap(), 1.0, Direction::Right);
    let rod = Rod::new(2.1e-200, 3e-200, 2e200).unwrap();
    let e = exact::solve(&rod, 1e200, Direction::Right);
    assert!(close(e.intensity, unit.intensity, 1e-13, unit.intensity));
    assert!(close(
        e.sensitivity * 1e200,
        unit.sensitivity,
        1e-13,
        unit.sensitivity
    ));
    assert!(close(
        e.gradient_x * 1e200,
        unit.gradient_x,
        1e-13,
        unit.gradient_x.abs()
    ));
    // An empty rod of length 1e308: I = I0 looking right, 0 looking left, no
    // sensitivity (the old evaluation gave NaN: e^{−0·2π̃} with 2π̃ = ∞).
    let empty = Rod::new(0.0, 0.0, 1e308).unwrap();
    for x in [0.0, 1.0, 5e307, 1e308] {
        let right = exact::solve(&empty, x, Direction::Right);
        let left = exact::solve(&empty, x, Direction::Left);
        assert_eq!(
            (right.intensity, right.sensitivity, right.gradient_x),
            (1.0, 0.0, 0.0)
        );
        assert_eq!(
            (left.intensity, left.sensitivity, left.gradient_x),
            (0.0, 0.0, 0.0)
        );
    }
    // Optical thickness 1 at the scale 1e-300: s ≈ 1e299, finite (was ∞).
    let tiny = Rod::new(1e300, 1e300, 1e-300).unwrap();
    let unit = exact::solve(&Rod::new(1.0, 1.0, 1.0).unwrap(), 1.0, Direction::Right);
    let e = exact::solve(&tiny, 1e-300, Direction::Right);
    assert!(close(e.intensity, unit.intensity, 1e-14, 1.0));
    assert!(close(
        e.sensitivity * 1e-300,
        unit.sensitivity,
        1e-13,
        unit.sensitivity
    ));
}
