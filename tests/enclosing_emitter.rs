//! A sensor inside a closed emitter sees the emitter's inner faces, which
//! emit as the outer ones (surfaces are two-sided): a furnace. It was
//! refused in 3D ("inside the opaque shape "box", which holds no emitter")
//! and in flatland ("inside the opaque shape "box""). Inside a closed
//! emitter of radiance `L` with nothing else, the irradiance is `π L` (3D)
//! and `2 L` (flatland: `∫ L cos θ dθ` over the half circle); a black
//! square (3D) or segment (flatland) in front of the sensor hides the
//! emitter's light over its solid angle, in closed form with its
//! derivative along the normal. The box's own motions change nothing the
//! sensor sees (every ray still ends on the box, of radiance `L`): their
//! derivatives are 0. Every method, against those.
use geosens::{Method, Quantity, RunConfig, run};
use std::sync::Arc;

/// Radiance of the box.
const L: f64 = 1.5;
/// The occluder's half-width and its height above the sensor.
const A: f64 = 0.5;
const H: f64 = 1.0;

/// An L-shaped emitter polygon around the sensor at the origin (its notch,
/// top right, puts a reflex corner in the sensor's view), a black segment
/// at height `H` of half-width `A`.
const FLAT: &str = r#"
[sensor]
kind = "irradiance"
point = [0.0, 0.0]
normal = [0.0, 1.0]

[[shapes]]
name = "box"
closed = true
vertices = [[-2.0, -1.0], [2.0, -1.0], [2.0, 1.5], [1.0, 1.5], [1.0, 3.0], [-2.0, 3.0]]
surface = { kind = "emitter", radiance = 1.5 }

[[shapes]]
name = "bar"
vertices = [[-0.5, 1.0], [0.5, 1.0]]
surface = { kind = "absorber" }

[[parameters]]
name = "box_tx"
shape = "box"
motion = { kind = "translate_x" }

[[parameters]]
name = "box_scale"
shape = "box"
motion = { kind = "scale", pivot = [0.0, 0.5] }

[[parameters]]
name = "bar_ty"
shape = "bar"
motion = { kind = "translate_y" }
"#;

/// A closed emitter cube around the sensor at the origin, a black square
/// at height `H` of half-side `A`.
const MESH: &str = r#"
[sensor]
kind = "irradiance"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[shapes]]
name = "box"
vertices = [
    [-2.0, -2.0, -1.0], [2.0, -2.0, -1.0], [-2.0, 2.0, -1.0], [2.0, 2.0, -1.0],
    [-2.0, -2.0, 3.0], [2.0, -2.0, 3.0], [-2.0, 2.0, 3.0], [2.0, 2.0, 3.0],
]
triangles = [
    [0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
    [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5],
]
surface = { kind = "emitter", radiance = 1.5 }

[[shapes]]
name = "square"
vertices = [[-0.5, -0.5, 1.0], [0.5, -0.5, 1.0], [0.5, 0.5, 1.0], [-0.5, 0.5, 1.0]]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = { kind = "absorber" }

[[parameters]]
name = "box_tx"
shape = "box"
motion = { kind = "translate_x" }

[[parameters]]
name = "box_scale"
shape = "box"
motion = { kind = "scale", pivot = [0.0, 0.0, 1.0] }

[[parameters]]
name = "square_tz"
shape = "square"
motion = { kind = "translate_z" }
"#;

/// Flatland: `E = L (2 − 2 sin φ)`, `tan φ = A / H` the half-angle of the
/// segment from the normal, and `dE/dH = 2 L A H / (A² + H²)^{3/2}`.
fn flat_exact() -> (f64, f64) {
    let r2 = A * A + H * H;
    (
        L * (2.0 - 2.0 * A / r2.sqrt()),
        2.0 * L * A * H / r2.powf(1.5),
    )
}

/// 3D: the square hides `4 L u atan u`, `u = X / √(1 + X²)`, `X = A / H`
/// (four rectangles with a corner above the sensor: the form factor of a
/// parallel rectangle, `(1/2π) Σ X/√(1+X²) atan(Y/√(1+X²))` over its two
/// sides, times `π L`); `dE/dH = −L d/dH (4 u atan u) = 4 L (atan u + u /
/// (1 + u²)) (1 + X²)^{-3/2} A / H²`.
fn mesh_exact() -> (f64, f64) {
    let x = A / H;
    let u = x / (1.0 + x * x).sqrt();
    let hidden = 4.0 * L * u * u.atan();
    let d = 4.0 * L * (u.atan() + u / (1.0 + u * u)) * (1.0 + x * x).powf(-1.5) * A / (H * H);
    (std::f64::consts::PI * L - hidden, d)
}

fn check(dimension: &str, r: &geosens::RunResult, m: Method, exact: (f64, f64), moving: &str) {
    let i = r.get(&Quantity::Intensity).unwrap();
    assert!(
        i.z_score(exact.0) < 4.0,
        "{dimension} {m}: I = {i:?} vs {}",
        exact.0
    );
    if m == Method::Intensity {
        return;
    }
    let d = r.get(&Quantity::sensitivity(moving)).unwrap();
    assert!(
        d.z_score(exact.1) < 4.0 && d.stderr < 0.1 * exact.1,
        "{dimension} {m}: ∂I/∂{moving} = {d:?} vs {}",
        exact.1
    );
    for box_param in ["box_tx", "box_scale"] {
        let b = r.get(&Quantity::sensitivity(box_param)).unwrap();
        assert!(
            b.z_score(0.0) < 4.0 && b.mean.abs() < 0.05 * exact.1,
            "{dimension} {m}: ∂I/∂{box_param} = {b:?} vs 0"
        );
    }
}

#[test]
fn a_sensor_inside_a_flatland_emitter_sees_it_all_around() {
    let scene = Arc::new(geosens::flat::file::from_toml(FLAT).unwrap());
    let cfg = RunConfig::new(100_000, 5).unwrap();
    for m in Method::ALL {
        let r = run(m.estimator(Arc::clone(&scene)).unwrap().as_ref(), &cfg).unwrap();
        check("flatland", &r, m, flat_exact(), "bar_ty");
    }
}

#[test]
fn a_sensor_inside_a_3d_emitter_sees_it_all_around() {
    let scene = Arc::new(geosens::mesh::file::from_toml(MESH).unwrap());
    let cfg = RunConfig::new(100_000, 6).unwrap();
    for m in Method::ALL {
        let r = run(m.estimator(Arc::clone(&scene)).unwrap().as_ref(), &cfg).unwrap();
        check("3D", &r, m, mesh_exact(), "square_tz");
    }
}

/// What stays refused: a closed box that is not an emitter of positive
/// radiance around the sensor (it would see nothing in 3D; flatland takes
/// every other closed opaque polygon for a solid), and, in flatland, a
/// closed emitter around a reflecting box around the sensor.
#[test]
fn a_dark_box_around_the_sensor_is_still_refused() {
    for surface in [
        "{ kind = \"emitter\", radiance = 0.0 }",
        "{ kind = \"absorber\" }",
        "{ kind = \"reflector\", albedo = 0.5 }",
    ] {
        let text = MESH.replace("{ kind = \"emitter\", radiance = 1.5 }", surface);
        let err = geosens::mesh::file::from_toml(&text)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("inside the opaque shape \"box\", which holds no emitter"),
            "{err}"
        );
        let text = FLAT.replace("{ kind = \"emitter\", radiance = 1.5 }", surface);
        let err = geosens::flat::file::from_toml(&text)
            .unwrap_err()
            .to_string();
        assert!(err.contains("inside the opaque shape \"box\""), "{err}");
    }
    let nested = FLAT.replace(
        "[[shapes]]\nname = \"bar\"",
        "[[shapes]]\nname = \"inner\"\nclosed = true\n\
         vertices = [[-1.5, -0.5], [0.8, -0.5], [0.8, 2.5], [-1.5, 2.5]]\n\
         surface = { kind = \"reflector\", albedo = 0.5 }\n\n[[shapes]]\nname = \"bar\"",
    );
    let err = geosens::flat::file::from_toml(&nested)
        .unwrap_err()
        .to_string();
    assert!(err.contains("inside the opaque shape \"inner\""), "{err}");
}
