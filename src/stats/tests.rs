use super::*;

/// Weights whose squared deviations underflow give a NaN error bar,
/// not 0 ± 0 marked reliable; equal tiny weights (a deterministic
/// estimate) keep their exact 0, and the same weights scaled into
/// range keep their error bar.
#[test]
fn an_underflowed_spread_is_not_an_error_bar_of_zero() {
    let spread: Vec<f64> = (0..1000)
        .map(|i| 1.0 + 0.03 * ((i % 7) as f64 - 3.0))
        .collect();
    let tiny: Vec<f64> = spread.iter().map(|w| w * 1e-184).collect();
    let e = Moments::of(&tiny).estimate();
    assert!(e.stderr.is_nan() && !e.is_reliable(), "{e:?}");
    let mut with_zeros = tiny.clone();
    with_zeros.extend([0.0; 10]);
    assert!(Moments::of(&with_zeros).estimate().stderr.is_nan());
    let equal = Moments::of(&[1e-184; 100]).estimate();
    assert!(equal.stderr == 0.0 && equal.mean == 1e-184, "{equal:?}");
    let fine = Moments::of(&spread).estimate();
    assert!(fine.stderr > 0.0 && fine.is_reliable(), "{fine:?}");
    // Merged chunks (the runner's path) say the same.
    let (a, b) = tiny.split_at(500);
    let merged = Moments::of(a).merge(&Moments::of(b)).estimate();
    assert!(merged.stderr.is_nan(), "{merged:?}");
    // And a pixel's strata.
    let mut pixel = StratumSums::default();
    for stratum in tiny.chunks(100) {
        stratum.iter().for_each(|&w| pixel.push(w));
        pixel.end_stratum();
    }
    let e = pixel.estimate();
    assert!(e.stderr.is_nan() && !e.is_reliable(), "{e:?}");
}

/// Two-pass central moments: the independent reference.
fn two_pass(w: &[f64]) -> (f64, f64, f64, f64) {
    let n = w.len() as f64;
    let mean = w.iter().sum::<f64>() / n;
    let m = |k: i32| w.iter().map(|x| (x - mean).powi(k)).sum::<f64>();
    (mean, m(2), m(3), m(4))
}

#[test]
fn merge_matches_two_pass() {
    let w: Vec<f64> = (0..1000)
        .map(|i| ((i * 7919) % 1013) as f64 * 0.01 + 100.0)
        .collect();
    let (mean, m2, m3, m4) = two_pass(&w);
    let merged = w
        .chunks(77)
        .map(Moments::of)
        .fold(Moments::default(), |a, b| a.merge(&b));
    assert_eq!(merged.n, 1000);
    approx::assert_relative_eq!(merged.mean, mean, max_relative = 1e-12);
    approx::assert_relative_eq!(merged.m2, m2, max_relative = 1e-9);
    assert!((merged.m3 - m3).abs() < 1e-7 * m4.sqrt() * m2.sqrt());
    approx::assert_relative_eq!(merged.m4, m4, max_relative = 1e-9);
}

#[test]
fn estimate_and_diagnostics() {
    let e = Moments::of(&[1.0, 2.0, 3.0, 4.0]).estimate();
    assert_eq!(e.mean, 2.5);
    // var = 5/3, stderr = sqrt(5/12)
    assert!((e.stderr - (5.0f64 / 12.0).sqrt()).abs() < 1e-15);
    assert!((e.max_share - 0.4).abs() < 1e-15);
    // one big weight among zeros: VOV ≈ 1, share = 1
    let mut w = vec![0.0; 999];
    w.push(1.0);
    let e = Moments::of(&w).estimate();
    assert!(e.vov > 0.9 && e.max_share == 1.0 && !e.is_reliable());
    // constant weights: zero variance, reliable
    assert!(Moments::of(&[3.0; 10]).estimate().is_reliable());
}

#[test]
fn overflowed_moments_give_no_error_bar() {
    // d² overflows: the variance is not 0 but unknown.
    let w: Vec<f64> = (0..100).map(|i| [1e200, -1e200, 3e200][i % 3]).collect();
    let one = Moments::of(&w);
    assert!(one.m2.is_nan() || one.m2 == f64::INFINITY, "{one:?}");
    let merged = Moments::of(&w[..50]).merge(&Moments::of(&w[50..]));
    for m in [one, merged] {
        let e = m.estimate();
        assert!(!e.stderr.is_finite() && !e.vov.is_finite(), "{e:?}");
        assert!(!e.is_reliable());
    }
}

#[test]
fn vov_survives_a_squared_variance_that_overflows() {
    // M2² overflows while M4 does not: the VOV is scale-free, so it must
    // equal the VOV of the same weights scaled down.
    // The first weight (the accumulator's shift) is 1, near the mean:
    // the shifted power sums stay finite.
    let w: Vec<f64> = (0..2000)
        .map(|i| {
            if i % 97 == 2 {
                5.0
            } else {
                ((i + 4) % 7) as f64 - 3.0
            }
        })
        .collect();
    let small = Moments::of(&w).estimate();
    let big_w: Vec<f64> = w.iter().map(|x| x * 4e75).collect();
    let big = Moments::of(&big_w);
    assert!(!(big.m2 * big.m2).is_finite() && big.m4.is_finite());
    let big = big.estimate();
    approx::assert_relative_eq!(big.vov, small.vov, max_relative = 1e-12);
    assert!(small.vov > 0.0 && big.is_reliable());
}

#[test]
fn nonzero_weights_are_counted_and_required() {
    let mut w = vec![0.0; 990];
    w.extend([0.5; 10]);
    let m = Moments::of(&w[..500]).merge(&Moments::of(&w[500..]));
    assert_eq!((m.n, m.nonzero), (1000, 10));
    // Nothing sampled: 0 ± 0, and unreliable although the VOV is 0.
    let zero = Moments::of(&[0.0; 1000]).estimate();
    assert_eq!((zero.mean, zero.stderr, zero.vov), (0.0, 0.0, 0.0));
    assert_eq!(zero.nonzero, 0);
    assert!(!zero.is_reliable());
    // Few weights, all alike: the VOV is 0, the count flags them.
    assert!(!Moments::of(&[3.0; 9]).estimate().is_reliable());
    assert!(Moments::of(&[3.0; 10]).estimate().is_reliable());
    // An exact value needs no samples.
    assert!(Estimate::exact(0.0).is_reliable());
    assert!(!Estimate::exact(f64::NAN).is_reliable());
}

#[test]
fn json_carries_nonzero_and_reliable_beside_mean_and_stderr() {
    let e = Moments::of(&[0.0, 1.0, 2.0]).estimate();
    let json = serde_json::to_value(e).unwrap();
    let keys: Vec<&str> = json
        .as_object()
        .unwrap()
        .keys()
        .map(|k| k.as_str())
        .collect();
    assert_eq!(
        keys,
        [
            "mean",
            "stderr",
            "nonzero",
            "reliable",
            "n",
            "vov",
            "max_share"
        ]
    );
    assert_eq!(json["nonzero"], 2);
    assert_eq!(json["reliable"], false);
}
