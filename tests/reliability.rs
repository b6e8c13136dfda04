//! Error bars that never claim more than the sample shows (issue 11, items 2
//! and 3): an overflowed variance is not a zero one, and a quantity no path
//! contributed to is not known to ±0.
mod common;
use common::*;
use geosens::Quantity;
use geosens::rod::{Direction, Method, Rod};

#[test]
fn overflowed_variance_is_not_a_reliable_zero() {
    // Optical thickness 1 at a scale of 1e-300: the sensitivity weights are
    // ~1e300 and their squares overflow.
    let rod = Rod::new(1e300, 1e300, 1e-300).unwrap();
    let s = Quantity::sensitivity("length");
    for paths in [2000, 4097] {
        let r = estimate(Method::Expectation, rod, 1e-300, Direction::Right, paths, 1);
        let e = r.get(&s).unwrap();
        assert!(
            !e.stderr.is_finite() && !e.is_reliable(),
            "{paths} paths: {e:?} claims a finite error bar"
        );
        // The intensity's weights are ≤ 1: its error bar is sound.
        let i = r.get(&Quantity::Intensity).unwrap();
        assert!(
            i.stderr.is_finite() && i.stderr > 0.0 && i.is_reliable(),
            "{i:?}"
        );
    }
}

#[test]
fn nothing_sampled_is_not_a_reliable_zero() {
    // 10⁻⁴ from the moving end, looking left: the expectation method's
    // weights are non-zero only for paths that collide within 10⁻⁴ of the
    // start (one in ~20 000); at 20 000 paths none did here.
    let rod = thick();
    let r = estimate(Method::Expectation, rod, 1.9999, Direction::Left, 20_000, 1);
    for (q, e) in &r.estimates {
        assert_eq!((e.mean, e.stderr), (0.0, 0.0), "{q}");
        assert!(!e.is_reliable(), "{q}: 0 ± 0 from no contribution: {e:?}");
        assert_eq!(e.nonzero, 0, "{q}");
        let exact = exact_value(&rod, 1.9999, Direction::Left, q);
        assert!(exact > 0.0, "{q}: exact {exact}");
    }
}

#[test]
fn an_exactly_zero_quantity_is_flagged_too() {
    // s(0, +1) = 0 exactly: the transport model's backward path leaves at
    // once through x = 0, where the sensitivity has no source. The sample
    // cannot tell this zero from an unsampled one; the flag says so.
    let rod = thick();
    let s = Quantity::sensitivity("length");
    assert_eq!(exact_value(&rod, 0.0, Direction::Right, &s), 0.0);
    let r = estimate(Method::Transport, rod, 0.0, Direction::Right, 5000, 1);
    let e = r.get(&s).unwrap();
    assert_eq!((e.mean, e.nonzero), (0.0, 0));
    assert!(!e.is_reliable());
    // The intensity there is sampled by every path: reliable.
    let i = r.get(&Quantity::Intensity).unwrap();
    assert_eq!(i.nonzero, 5000);
    assert!(i.is_reliable());
}

#[test]
fn nonzero_counts_the_contributing_paths() {
    // Rendering's sensitivity weight is non-zero only for paths that leave
    // through the moving end and whose nested path leaves through x = 0;
    // its intensity weight only for those that leave through x = 0: the two
    // counts are disjoint and at most the path count.
    let r = estimate(Method::Rendering, thick(), 1.0, Direction::Left, 40_000, 2);
    let i = r.get(&Quantity::Intensity).unwrap();
    let s = r.get(&Quantity::sensitivity("length")).unwrap();
    assert!(i.nonzero > 1000 && s.nonzero > 1000, "{i:?} {s:?}");
    assert!(i.nonzero + s.nonzero <= 40_000);
    assert!(i.is_reliable() && s.is_reliable());
    let json = serde_json::to_value(s).unwrap();
    assert_eq!(json["nonzero"].as_u64(), Some(s.nonzero));
    assert_eq!(json["reliable"].as_bool(), Some(true));
}
