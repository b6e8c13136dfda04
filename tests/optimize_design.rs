//! The design problem `scenes/design_reflector.toml` (issue 32 point 5):
//! the optimiser's answer against a scan of the objective, whose peak a
//! quadratic fit locates. The answer has no closed form; the scan is an
//! independent reference (the intensity estimator alone, no derivative).
use geosens::Method;
use geosens::flat::file::load_study;
use geosens::optimize::scan::{fit_quadratic, scan};
use geosens::optimize::{Optimizer, Product, Sampling, Settings, optimize};
use std::path::Path;

fn sampling(paths: u64, seed: u64) -> Sampling {
    Sampling {
        paths,
        batches: 8,
        seed,
        threads: 0,
        fd_step: None,
        product: Product::Independent,
    }
}

/// The scan's fitted peak and the tail average of expectation's and
/// rendering's runs agree within 0.02 in the shift (1 % of the scene's
/// size) and 0.02 rad in the tilt: the maximum is flat (J falls by
/// about 0.3 % 0.05 away), so the scan's own peak wanders by ~0.005 with
/// its seed, and the runs' averages by as much (seeds 1–3 gave under
/// 0.005 from the peak; the bound leaves room for both). The runs' J is
/// also within 0.3 % of the peak's.
#[test]
fn the_optimiser_finds_the_scanned_maximum() {
    let study = load_study(Path::new("scenes/design_reflector.toml")).unwrap();
    let axis = |lo: f64, hi: f64| -> Vec<f64> {
        (0..11)
            .map(|i| lo + (hi - lo) * f64::from(i) / 10.0)
            .collect()
    };
    let points = scan(
        &study,
        &[0.0, 0.0],
        (0, &axis(-0.2, 0.1)),
        (1, &axis(-0.7, -0.4)),
        &sampling(1 << 16, 7),
    )
    .unwrap();
    assert_eq!(points.len(), 121);
    let fit = fit_quadratic(
        &points
            .iter()
            .map(|p| ([p.offsets[0], p.offsets[1]], -p.loss))
            .collect::<Vec<_>>(),
    )
    .unwrap();
    // A maximum: the fitted Hessian is negative definite.
    let [[a, b], [_, d]] = fit.h;
    assert!(a < 0.0 && a * d - b * b > 0.0, "{:?}", fit.h);
    let peak = fit.stationary().unwrap();
    for method in [Method::Expectation, Method::Rendering] {
        let settings = Settings {
            method,
            optimizer: Optimizer::Adam,
            iterations: 250,
            step: 0.02,
            sampling: sampling(16384, 2),
            tolerance: 0.0,
        };
        let records = optimize(&study, &settings, |_| true).unwrap();
        let last = records.last().unwrap();
        let answer = [
            last.average["reflector_tx"],
            last.average["reflector_rotate"],
        ];
        assert!(
            (answer[0] - peak[0]).abs() < 0.02 && (answer[1] - peak[1]).abs() < 0.02,
            "{method:?}: {answer:?} vs the scan's peak {peak:?}"
        );
        assert!(fit.at(answer) > fit.at(peak) * (1.0 - 3e-3), "{method:?}");
        // The design improved on the start by far more than the noise.
        assert!(last.loss.mean < 1.4 * records[0].loss.mean, "{method:?}");
    }
}

/// The intensity method estimates no gradient and cannot drive the
/// optimiser: a clear error, not a run that never moves.
#[test]
fn the_intensity_method_cannot_optimise() {
    let study = load_study(Path::new("scenes/design_reflector.toml")).unwrap();
    let settings = Settings {
        method: Method::Intensity,
        optimizer: Optimizer::Adam,
        iterations: 5,
        step: 0.02,
        sampling: sampling(1024, 2),
        tolerance: 0.0,
    };
    let e = optimize(&study, &settings, |_| true)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no gradient"), "{e}");
}
