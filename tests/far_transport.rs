//! Transport's in-scattering walks start half a nudge (`Geometry::nudge`)
//! off the moving surface they leave. Far from the origin the nudge grows
//! with the coordinates' rounding; a fixed `0.5e-9 × size` start fell
//! inside the 3D casters' rounding floor there, the nested walk missed the
//! mirror it started next to: with that start this test reads
//! ∂I/∂mirror_tz = +1.28e-2 ± 0.74e-3 at 4·10⁵ sizes from the origin
//! against −2.88e-3 ± 0.66e-3 at it (both "reliable"). Book: chapter "When not to trust a number", section
//! "Scale".
use geosens::{Method, Quantity, RunConfig, run};
use std::sync::Arc;

/// A lamp over a mirror moving in z and x inside a box of fog, with an
/// irradiance sensor under them, translated by `offset`.
fn mirror_in_fog(offset: [f64; 3]) -> Arc<geosens::mesh::Scene> {
    let p = |x: f64, y: f64, z: f64| {
        format!(
            "[{:?}, {:?}, {:?}]",
            x + offset[0],
            y + offset[1],
            z + offset[2]
        )
    };
    let (a, b) = ((-1.5, -1.5, 0.3), (1.5, 1.5, 1.8));
    let mut fog = Vec::new();
    for z in [a.2, b.2] {
        for y in [a.1, b.1] {
            for x in [a.0, b.0] {
                fog.push(p(x, y, z));
            }
        }
    }
    let text = format!(
        r#"
[sensor]
kind = "irradiance"
point = {sensor}
normal = [0.0, 0.0, 1.0]

[[shapes]]
name = "lamp"
vertices = [{l0}, {l1}, {l2}, {l3}]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = {{ kind = "emitter", radiance = 1.0 }}

[[shapes]]
name = "mirror"
vertices = [{m0}, {m1}, {m2}, {m3}]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = {{ kind = "reflector", albedo = 0.9 }}

[[shapes]]
name = "fog"
vertices = [{fog}]
triangles = [[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4], [2, 6, 7],
             [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]]
surface = {{ kind = "transparent" }}
medium = {{ ks = 1.2, ke = 1.5, g = 0.3 }}

[[parameters]]
name = "mirror_tz"
shape = "mirror"
motion = {{ kind = "translate_z" }}
"#,
        sensor = p(0.0, 0.0, 0.0),
        l0 = p(-0.5, -0.5, 2.0),
        l1 = p(0.5, -0.5, 2.0),
        l2 = p(0.5, 0.5, 2.0),
        l3 = p(-0.5, 0.5, 2.0),
        m0 = p(0.3, -0.5, 1.0),
        m1 = p(1.2, -0.5, 1.0),
        m2 = p(1.2, 0.5, 1.0),
        m3 = p(0.3, 0.5, 1.0),
        fog = fog.join(", "),
    );
    Arc::new(geosens::mesh::file::from_toml(&text).unwrap())
}

/// Transport's ∂I/∂mirror_tz: mean and standard error.
fn mirror_tz(scene: Arc<geosens::mesh::Scene>) -> (f64, f64) {
    let e = Method::Transport.estimator(scene).unwrap();
    let r = run(e.as_ref(), &RunConfig::new(200_000, 3).unwrap()).unwrap();
    let (_, est) = r
        .estimates
        .iter()
        .find(|(q, _)| *q == Quantity::sensitivity("mirror_tz"))
        .unwrap();
    (est.mean, est.stderr)
}

#[test]
fn a_scene_far_from_the_origin_reads_the_derivative_it_reads_at_the_origin() {
    let (near, near_se) = mirror_tz(mirror_in_fog([0.0; 3]));
    let (far, far_se) = mirror_tz(mirror_in_fog([1.2e6, -8e5, 5e5]));
    // The two runs share their seed, so their difference is smaller than
    // the combined error bar; the bug moved it by 18 of them.
    let sigma = near_se.hypot(far_se);
    assert!(
        near_se < 0.5 * near.abs(),
        "{near} ± {near_se}: too wide to tell"
    );
    assert!(
        (far - near).abs() < 4.0 * sigma,
        "at 4e5 sizes {far} ± {far_se}, at the origin {near} ± {near_se}"
    );
}
