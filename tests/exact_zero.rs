//! A derivative that is exactly 0 reads 0, not a rounding residue with a
//! false error bar. An absorbing slab wider than everything the sensor sees,
//! moved along its normal or along itself, changes no chord: every sensor
//! ray crosses the same thickness, so ∂E/∂t = 0 exactly, while its terms
//! (the entry and exit faces' speeds) are of order 1 and cancel. Before the
//! rounding floor (`estimator::ROUNDING`) every method printed about
//! −4e-18 ± 3e-20, "reliable": 150 standard errors from the truth. The
//! slab's scale (its thickness grows) is the control: a derivative that is
//! not 0 must stay as it was, within its error bar of the reference.
use geosens::{Method, Quantity, RunConfig, run};
use std::sync::Arc;

const FLAT: &str = r#"
[sensor]
kind = "irradiance"
point = [0.0, 0.0]
normal = [0.0, 1.0]

[[shapes]]
name = "lamp"
vertices = [[-1.0, 2.0], [1.0, 2.0]]
surface = { kind = "emitter", radiance = 1.0 }

[[shapes]]
name = "slab"
closed = true
vertices = [[-5.0, 0.8], [5.0, 0.8], [5.0, 1.3], [-5.0, 1.3]]
surface = { kind = "transparent" }
medium = { ks = 0.0, ke = 1.5 }

[[parameters]]
name = "slab_tx"
shape = "slab"
motion = { kind = "translate_x" }

[[parameters]]
name = "slab_ty"
shape = "slab"
motion = { kind = "translate_y" }

[[parameters]]
name = "slab_scale"
shape = "slab"
motion = { kind = "scale", pivot = [0.0, 1.05] }
"#;

const MESH: &str = r#"
[sensor]
kind = "irradiance"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[shapes]]
name = "lamp"
vertices = [[-0.5, -0.5, 2.0], [0.5, -0.5, 2.0], [0.5, 0.5, 2.0], [-0.5, 0.5, 2.0]]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = { kind = "emitter", radiance = 1.0 }

[[shapes]]
name = "slab"
vertices = [
    [-5.0, -5.0, 0.8], [5.0, -5.0, 0.8], [-5.0, 5.0, 0.8], [5.0, 5.0, 0.8],
    [-5.0, -5.0, 1.3], [5.0, -5.0, 1.3], [-5.0, 5.0, 1.3], [5.0, 5.0, 1.3],
]
triangles = [
    [0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
    [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5],
]
surface = { kind = "transparent" }
medium = { ks = 0.0, ke = 1.5 }

[[parameters]]
name = "slab_tx"
shape = "slab"
motion = { kind = "translate_x" }

[[parameters]]
name = "slab_tz"
shape = "slab"
motion = { kind = "translate_z" }

[[parameters]]
name = "slab_scale"
shape = "slab"
motion = { kind = "scale", pivot = [0.0, 0.0, 1.05] }
"#;

/// `dE/dscale` of a slab of thickness `d` (scaled about its mid-plane):
/// the thickness grows as `d (1 + s)`, every chord as `d / cos θ`, so
/// `dE/ds = −κe d ∫ Le e^{−κe d / cos θ} dθ` over the lamp's angles in the
/// plane, by the midpoint rule.
fn flat_scale_reference() -> f64 {
    let (ke, d) = (1.5, 0.5);
    let half = (1.0f64 / 2.0).atan();
    let n = 200_000;
    let h = 2.0 * half / n as f64;
    (0..n)
        .map(|i| {
            let th = -half + (i as f64 + 0.5) * h;
            // Irradiance in the plane: E = ∫ L cos θ dθ; the chord's
            // derivative brings −κe d / cos θ.
            -ke * d / th.cos() * (-ke * d / th.cos()).exp() * th.cos() * h
        })
        .sum()
}

fn check(problem_name: &str, result: &geosens::RunResult, zeros: &[&str]) {
    for name in zeros {
        let e = result.get(&Quantity::sensitivity(name)).unwrap();
        assert_eq!(
            (e.mean, e.stderr, e.nonzero),
            (0.0, 0.0, 0),
            "{problem_name} {}: ∂E/∂{name} = {} ± {} from {} non-zero weights",
            result.method,
            e.mean,
            e.stderr,
            e.nonzero
        );
        assert!(!e.is_reliable(), "0 ± 0 rests on no weight: not reliable");
    }
}

/// The slab's scale changes every chord smoothly and no path's fate: a
/// central difference draws no jump, and cannot tell that from jumps it
/// never drew (`tests/reliability.rs`), so it says "not reliable" however
/// right its value; the other methods' error bars are reliable.
fn smooth_or_reliable(m: Method, s: &geosens::Estimate) -> bool {
    if m == Method::Fd {
        s.jumps == Some(0) && !s.is_reliable()
    } else {
        s.is_reliable()
    }
}

#[test]
fn an_exactly_zero_derivative_reads_zero_in_flatland() {
    let scene = Arc::new(geosens::flat::file::from_toml(FLAT).unwrap());
    let cfg = RunConfig::new(100_000, 3).unwrap();
    let reference = flat_scale_reference();
    for m in Method::ALL.into_iter().filter(|m| *m != Method::Intensity) {
        let r = run(m.estimator(Arc::clone(&scene)).unwrap().as_ref(), &cfg).unwrap();
        check("flatland", &r, &["slab_tx", "slab_ty"]);
        let s = r.get(&Quantity::sensitivity("slab_scale")).unwrap();
        // fd's bias at its default step is far below this run's error bar.
        assert!(
            s.z_score(reference) < 4.0 && smooth_or_reliable(m, &s),
            "{m}: ∂E/∂scale = {} ± {} against {reference}",
            s.mean,
            s.stderr
        );
    }
}

#[test]
fn an_exactly_zero_derivative_reads_zero_in_3d() {
    let scene = Arc::new(geosens::mesh::file::from_toml(MESH).unwrap());
    let cfg = RunConfig::new(50_000, 4).unwrap();
    let mut scale = Vec::new();
    for m in Method::ALL.into_iter().filter(|m| *m != Method::Intensity) {
        let r = run(m.estimator(Arc::clone(&scene)).unwrap().as_ref(), &cfg).unwrap();
        check("3D", &r, &["slab_tx", "slab_tz"]);
        let s = r.get(&Quantity::sensitivity("slab_scale")).unwrap();
        assert!(smooth_or_reliable(m, &s) && s.mean < 0.0, "{m}: {s:?}");
        scale.push(s);
    }
    // The methods agree on the non-zero one (no closed form written here:
    // the control is that they still estimate it, and alike).
    for a in &scale {
        for b in &scale {
            let z = (a.mean - b.mean).abs() / (a.stderr.powi(2) + b.stderr.powi(2)).sqrt();
            assert!(z < 4.0, "{a:?} against {b:?}");
        }
    }
}

/// A radiance probe whose ray ends on the dark face of a reflector segment
/// (the lamp lights only its other face): `I` and its derivatives are 0 for
/// every path. The vertex on the segment sees the segment's own corners
/// exactly edge-on; evaluated at their rounding cosine, rendering and
/// transport reported about 9·10⁻³² ± 2·10⁻³⁴, "reliable" (found by a
/// random-scene campaign); skipped as edge-on, every method reads 0 ± 0.
#[test]
fn a_vertex_does_not_see_its_own_faces_corners() {
    let scene = Arc::new(
        geosens::flat::file::from_toml(
            r#"
[sensor]
kind = "radiance"
point = [0.0, 0.0]
direction = [0.8225718698159828, -0.5686611636004676]

[[shapes]]
name = "lamp"
vertices = [[1.0470999869898725, -1.2828387163266006], [1.4723076600629754, -0.7491477670702488]]
surface = { kind = "emitter", radiance = 0.852 }

[[shapes]]
name = "refl0"
vertices = [[1.025173151684059, -0.6119710900462777], [0.8846162046873112, -0.8280547122050302]]
surface = { kind = "reflector", albedo = 0.33 }

[[parameters]]
name = "refl0_translate_x"
shape = "refl0"
motion = { kind = "translate_x" }
"#,
        )
        .unwrap(),
    );
    let cfg = RunConfig::new(100_000, 1).unwrap();
    for m in Method::ALL.into_iter().filter(|m| *m != Method::Intensity) {
        let r = run(m.estimator(Arc::clone(&scene)).unwrap().as_ref(), &cfg).unwrap();
        check("dark face", &r, &["refl0_translate_x"]);
    }
}
