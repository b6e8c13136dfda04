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

/// The fog of `scenes/fog.toml` made sparse (κe = 0.2, κs = 0.16): a
/// collision near its moving edge is rare. Just thick enough (κs × its
/// chord bound ≥ `THIN_DEPTH`) that the walk draws its collisions at κs
/// itself: a thinner fog's raised collision rate makes jumps frequent (and
/// its finite differences carry a caveat, `tests/thin_media.rs`).
fn sparse_fog() -> geosens::flat::Scene {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/fog.toml"))
        .unwrap()
        .replace("ks = 1.2, ke = 1.5", "ks = 0.16, ke = 0.2");
    let scene = geosens::flat::file::from_toml(&text).unwrap();
    let fog = &scene.shapes()[1];
    let chord = geosens::path::thin_media::chord_bound(&fog.vertices);
    assert!(!geosens::path::thin_media::is_thin(0.16, chord));
    scene
}

#[test]
fn a_central_difference_that_drew_no_jump_is_not_reliable() {
    // Central differences with common random numbers: the two displaced
    // fogs change a path smoothly (its transmittance) unless a collision
    // falls in the sliver between their edges (probability ∝ the step),
    // which changes it by O(1): the boundary part of the derivative rests
    // on those jumps alone. At 5·10³ paths none fell there: the smooth part
    // alone (about twice the derivative) with every weight non-zero and a
    // small VOV, which looked reliable; the count of jumps flags it.
    use geosens::flat::Method as Flat;
    let scene = std::sync::Arc::new(sparse_fog());
    let q = Quantity::sensitivity("fog_scale");
    let run = |m: Flat, paths: u64| {
        let e = m.estimator(scene.clone()).unwrap();
        let cfg = geosens::RunConfig::new(paths, 3).unwrap().threads(2);
        geosens::run(e.as_ref(), &cfg).unwrap().get(&q).unwrap()
    };
    let few = run(Flat::Fd, 5_000);
    assert!(few.nonzero >= 10 && few.vov < 0.1, "{few:?}");
    assert_eq!(few.jumps, Some(0), "{few:?}");
    assert!(!few.is_reliable(), "{few:?}");
    // The reference: rendering, whose boundary term is sampled, not waited for.
    let reference = run(Flat::Rendering, 400_000);
    assert!(reference.is_reliable(), "{reference:?}");
    assert!(
        few.z_score(reference.mean) > 20.0,
        "the flagged estimate was far off ({few:?} against {reference:?}): \
         otherwise this test shows nothing"
    );
    // Enough paths to draw the jumps: flagged reliable, and right.
    let many = run(Flat::Fd, 2_000_000);
    assert!(many.jumps.unwrap() >= 100 && many.is_reliable(), "{many:?}");
    let z = (many.mean - reference.mean) / many.stderr.hypot(reference.stderr);
    assert!(z.abs() < 4.0, "z = {z}: {many:?} against {reference:?}");
    // Other methods count no jumps; their JSON has no such key.
    assert_eq!(reference.jumps, None);
    let json = serde_json::to_value(reference).unwrap();
    assert!(json.get("jumps").is_none());
    assert_eq!(
        serde_json::to_value(many).unwrap()["jumps"],
        many.jumps.unwrap()
    );
}

/// A radiance sensor aimed exactly at a lamp's end through an absorbing
/// polygon (campaign): whether the ray meets the lamp comes down to the
/// rounding of the medium's crossings, so every pair of displaced scenes
/// jumped, every weight was alike, and fd read 1762 ± 0 at `--fd-step
/// 1e-4`, "reliable": `I` itself jumps there. Most pairs jumping is now
/// what a jump of `I` looks like, and not reliable.
#[test]
fn a_central_difference_whose_pairs_mostly_jumped_is_not_reliable() {
    let text = r#"{"sensor": {"kind": "radiance", "point": [-4.04037273864387, 9.14742521876093], "direction": [0.04733331367156574, -2.9236337601383005]}, "shapes": [{"name": "lamp0", "vertices": [[-3.992939936196319, 6.223781359936925], [-3.9930394249723045, 6.223791458622629]], "surface": {"kind": "emitter", "radiance": 1.037}}, {"name": "o0", "vertices": [[-3.64469535152883, 8.7525761763066], [-3.4677185531462555, 8.965809986686407], [-3.6809523635260635, 9.142786785068983], [-4.034905960291212, 8.716319164309366], [-3.9496124361392893, 8.645528444956337], [-3.7726356377567147, 8.858762255336146]], "closed": true, "surface": {"kind": "transparent"}, "medium": {"ks": 0.0, "ke": 3.336}}], "parameters": [{"name": "o0_translate_x", "shape": "o0", "motion": {"kind": "translate_x"}}]}"#;
    let scene = std::sync::Arc::new(geosens::flat::file::from_json(text).unwrap());
    let q = Quantity::sensitivity("o0_translate_x");
    for step in [1e-4, 1e-5] {
        let fd = geosens::flat::methods::finite_difference(&scene, step).unwrap();
        let r = geosens::run(&fd, &geosens::RunConfig::new(1000, 1).unwrap()).unwrap();
        let s = r.get(&q).unwrap();
        assert!(!s.is_reliable(), "step {step}: {s:?}");
    }
    // A boundary's share of the pairs is small: the thin fog's 2·10⁶-path
    // run above jumped on 144 pairs and stays reliable.
}
