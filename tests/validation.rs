//! Every invalid input is a clear error naming the bad value, never a panic
//! or a NaN.
use geosens::rod::{Direction, Method, Probe, Rod};
use geosens::{Error, RunConfig, run};

fn names(err: Error, name: &str) {
    match &err {
        Error::InvalidParameter { name: n, .. } => assert_eq!(*n, name, "{err}"),
        other => panic!("expected InvalidParameter({name}), got {other:?}"),
    }
    assert!(err.to_string().contains(name), "{err}");
}

#[test]
fn rod_coefficients_are_validated() {
    for (ks, ke, length, bad) in [
        (-0.1, 1.0, 1.0, "ks"),
        (f64::NAN, 1.0, 1.0, "ks"),
        (f64::INFINITY, f64::INFINITY, 1.0, "ks"),
        (0.5, 0.4, 1.0, "ke"),
        (0.5, f64::NAN, 1.0, "ke"),
        (0.5, f64::INFINITY, 1.0, "ke"),
        (0.5, 1.0, 0.0, "length"),
        (0.5, 1.0, -2.0, "length"),
        (0.5, 1.0, f64::NAN, "length"),
        (0.5, 1.0, f64::INFINITY, "length"),
    ] {
        names(Rod::new(ks, ke, length).unwrap_err(), bad);
    }
    // Optical thickness beyond the supported range (overflow, endless paths).
    names(
        Rod::new(1e308, 1e308, 1e308).unwrap_err(),
        "optical thickness ke*length",
    );
    names(
        Rod::new(0.0, 1e3, 11.0).unwrap_err(),
        "optical thickness ke*length",
    );
    assert!(Rod::new(50.0, 50.0, 200.0).is_ok());
    let rod = Rod::new(0.5, 1.0, 1.0).unwrap();
    names(rod.with_incoming(-1.0).unwrap_err(), "incoming");
    names(rod.with_incoming(f64::NAN).unwrap_err(), "incoming");
    assert!(Rod::new(0.0, 0.0, 1e-9).is_ok());
}

#[test]
fn probes_are_validated() {
    let rod = Rod::new(0.5, 1.0, 2.0).unwrap();
    for x in [
        -1e-12,
        2.0 + 1e-12,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ] {
        names(Probe::new(&rod, x, Direction::Left).unwrap_err(), "x");
    }
    assert!(Probe::new(&rod, 0.0, Direction::Left).is_ok());
    assert!(Probe::new(&rod, 2.0, Direction::Left).is_ok());
    for omega in [0.0, 2.0, -0.5, f64::NAN, f64::INFINITY] {
        names(Direction::from_sign(omega).unwrap_err(), "omega");
    }
    assert_eq!(Direction::from_sign(-1.0), Ok(Direction::Left));
    assert_eq!(Direction::from_sign(1.0), Ok(Direction::Right));
}

#[test]
fn run_configurations_are_validated() {
    for paths in [0, 1] {
        names(RunConfig::new(paths, 1).unwrap_err(), "paths");
    }
    // A hand-built configuration is checked by the runner too.
    let rod = Rod::new(0.5, 1.0, 2.0).unwrap();
    let probe = Probe::new(&rod, 1.0, Direction::Left).unwrap();
    let cfg = RunConfig {
        paths: 1,
        seed: 0,
        threads: 1,
    };
    names(
        run(
            Method::Intensity.estimator((rod, probe)).unwrap().as_ref(),
            &cfg,
        )
        .unwrap_err(),
        "paths",
    );
    // Two paths are enough for an error bar, and every estimate is finite.
    for method in Method::UNBIASED {
        let r = run(
            method.estimator((rod, probe)).unwrap().as_ref(),
            &RunConfig::new(2, 3).unwrap(),
        )
        .unwrap();
        assert!(
            r.estimates
                .iter()
                .all(|(_, e)| e.mean.is_finite() && e.stderr.is_finite())
        );
    }
}
