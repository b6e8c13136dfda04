//! The nested walks of rendering and transport (double randomisation) cost
//! a path a bounded share of work ([`geosens::path::nested`]), and the
//! roulette that bounds it keeps the estimators unbiased.
//!
//! In a closed room of reflectors of albedo 1, which only the lamp ends, a
//! path makes about (wall area)/(lamp area) events and a few nested walks
//! at each, each as long: rendering and transport took 4.5–9.4 s and
//! 6–14 s of CPU per path in the 3D room below (runs of 2 to 8 paths),
//! against 0.8 ms for the intensity estimator. The work is counted here in
//! events, not timed.
use geosens::path::Boundaries;
use geosens::path::estimator::{DerivativeEstimator, Scheme};
use geosens::path::nested::{Budget, FREE_NESTED_EVENTS, NESTED_EVENTS_PER_ESTIMATE, Work};
use geosens::{Estimator, Quantity, RunConfig, RunResult, run};
use std::path::Path;
use std::sync::Arc;

/// A closed flatland room of reflectors of albedo `albedo`, 4 × 3: three
/// walls in one polyline and a fourth that translates along x (`wall_tx`),
/// 10⁻⁶ from the others at its ends (shapes must be disjoint), a lamp
/// segment of length `2 half_lamp` near the ceiling, the sensor on the
/// floor's side looking up.
fn flat_room(albedo: f64, half_lamp: f64) -> Arc<geosens::flat::Scene> {
    let text = format!(
        r#"
[sensor]
kind = "irradiance"
point = [0.0, 0.0]
normal = [0.0, 1.0]

[[shapes]]
name = "walls"
vertices = [[2.0, -1.0], [-2.0, -1.0], [-2.0, 2.0], [2.0, 2.0]]
surface = {{ kind = "reflector", albedo = {albedo} }}

[[shapes]]
name = "wall"
vertices = [[2.0, 1.999999], [2.0, -0.999999]]
surface = {{ kind = "reflector", albedo = {albedo} }}

[[shapes]]
name = "lamp"
vertices = [[{a}, 1.5], [{half_lamp}, 1.5]]
surface = {{ kind = "emitter", radiance = 1.0 }}

[[parameters]]
name = "wall_tx"
shape = "wall"
motion = {{ kind = "translate_x" }}
"#,
        a = -half_lamp
    );
    Arc::new(geosens::flat::file::from_toml(&text).unwrap())
}

/// The 3D room: a box 3 × 3 × 2.02 of reflectors of albedo `albedo` open
/// at x = 1.5, closed there by a wall 10⁻⁶ inside its rim that translates
/// along x (`wall_tx`), a square lamp of half-side `half_lamp` under the
/// ceiling, the sensor on the floor looking up.
fn mesh_room(albedo: f64, half_lamp: f64) -> Arc<geosens::mesh::Scene> {
    let (g, h) = (1e-6, half_lamp);
    let text = format!(
        r#"
[sensor]
kind = "irradiance"
point = [0.0, 0.0, 0.01]
normal = [0.0, 0.0, 1.0]

[[shapes]]
name = "room"
vertices = [[-1.5, -1.5, -0.01], [1.5, -1.5, -0.01], [-1.5, 1.5, -0.01], [1.5, 1.5, -0.01],
            [-1.5, -1.5, 2.01], [1.5, -1.5, 2.01], [-1.5, 1.5, 2.01], [1.5, 1.5, 2.01]]
triangles = [[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4], [2, 6, 7],
             [2, 7, 3], [0, 4, 6], [0, 6, 2]]
surface = {{ kind = "reflector", albedo = {albedo} }}

[[shapes]]
name = "wall"
vertices = [[1.5, {y0}, {z0}], [1.5, {y1}, {z0}], [1.5, {y1}, {z1}], [1.5, {y0}, {z1}]]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = {{ kind = "reflector", albedo = {albedo} }}

[[shapes]]
name = "lamp"
vertices = [[-{h}, -{h}, 1.9], [{h}, -{h}, 1.9], [{h}, {h}, 1.9], [-{h}, {h}, 1.9]]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = {{ kind = "emitter", radiance = 1.0 }}

[[parameters]]
name = "wall_tx"
shape = "wall"
motion = {{ kind = "translate_x" }}
"#,
        y0 = -1.5 + g,
        y1 = 1.5 - g,
        z0 = -0.01 + g,
        z1 = 2.01 - g,
    );
    Arc::new(geosens::mesh::file::from_toml(&text).unwrap())
}

/// The work of `paths` paths of `e` from seed `seed`, summed.
fn work<G: Boundaries>(e: &DerivativeEstimator<G>, paths: u64, seed: u64) -> Work {
    let mut rng = geosens::rng::stream(seed, 0);
    let mut weights = vec![0.0; e.quantities().len()];
    let mut sum = Work::new(e.budget);
    for _ in 0..paths {
        let w = e.sample_with_work(&mut rng, &mut weights);
        sum.main += w.main;
        sum.nested += w.nested;
        sum.replayed += w.replayed;
        sum.estimates += w.estimates;
        sum.skipped += w.skipped;
    }
    sum
}

/// The bound the budget keeps, with room for chance: the free work twice
/// over (the near sides of jumps and their far sides, counted apart), a
/// nested walk or two past it (each about as long as the main walk, in a
/// room), and about [`NESTED_EVENTS_PER_ESTIMATE`] per opportunity (an
/// estimate made or skipped) after, here up to 4 times that (an estimate
/// in a room costs thousands of events, and a path makes only tens).
fn check_bounded(what: &str, w: &Work, paths: u64) {
    let opportunities = (w.estimates + w.skipped) as f64;
    let bound = (2 * paths * FREE_NESTED_EVENTS + 4 * w.main) as f64
        + 4.0 * NESTED_EVENTS_PER_ESTIMATE * opportunities;
    let per_path = |n: u64| n as f64 / paths as f64;
    eprintln!(
        "{what}: per path {:.0} main events, {:.0} nested and {:.0} replayed, {:.1} estimates \
         made, {:.1} skipped; nested work {} against the bound {bound:.0}",
        per_path(w.main),
        per_path(w.nested),
        per_path(w.replayed),
        per_path(w.estimates),
        per_path(w.skipped),
        w.nested + w.replayed,
    );
    assert!(
        ((w.nested + w.replayed) as f64) < bound,
        "{what}: {w:?}, bound {bound}"
    );
    // The paths are long (the regime where the nested work was the square
    // of their length), and the roulette acted.
    assert!(w.main > 1000 * paths, "{what}: {w:?}");
    assert!(w.skipped > w.estimates, "{what}: {w:?}");
}

/// A closed room of albedo 1 with a moving wall and a small lamp, flatland
/// and 3D, rendering and transport: the nested walks' events stay within
/// the budget (here 1–4·10⁵ per path, where they were 4–7·10⁷ without
/// it, and the test ran for minutes).
#[test]
fn a_closed_room_of_albedo_one_costs_in_proportion_to_its_paths() {
    let flat = flat_room(1.0, 5e-4);
    let mesh = mesh_room(1.0, 0.05);
    for scheme in [Scheme::Rendering, Scheme::Transport] {
        let e = geosens::flat::methods::derivative(flat.clone(), scheme);
        check_bounded(&format!("flatland {scheme:?}"), &work(&e, 16, 1), 16);
        let e = geosens::mesh::methods::derivative(mesh.clone(), scheme);
        check_bounded(&format!("3D {scheme:?}"), &work(&e, 4, 1), 4);
    }
}

/// Within the free work every weight is the one a run without a budget
/// draws, bit for bit, and nothing is skipped: the shipped scenes' paths
/// stay far inside it (at most 640 nested events and 144 estimates in
/// 2·10⁴ paths).
#[test]
fn within_the_free_work_every_weight_is_unchanged() {
    fn same<G: Boundaries>(name: &str, mut e: DerivativeEstimator<G>, paths: u64) {
        let n = e.quantities().len();
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        let (mut ra, mut rb) = (geosens::rng::stream(5, 0), geosens::rng::stream(5, 0));
        let mut most = 0;
        for _ in 0..paths {
            e.budget = Budget::default();
            let w = e.sample_with_work(&mut ra, &mut a);
            e.budget = Budget::UNLIMITED;
            e.sample_with_work(&mut rb, &mut b);
            assert_eq!(a, b, "{name}");
            assert_eq!(w.skipped, 0, "{name}");
            most = most.max(w.nested);
        }
        eprintln!("{name}: at most {most} nested events per path");
    }
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for name in ["submerged.toml", "fog.toml", "three_shapes.toml"] {
        let s = Arc::new(geosens::flat::file::load(&scenes.join(name)).unwrap());
        for scheme in [Scheme::Rendering, Scheme::Transport] {
            same(
                name,
                geosens::flat::methods::derivative(s.clone(), scheme),
                5000,
            );
        }
    }
    for name in ["room.toml", "fog_cube.toml"] {
        let s = Arc::new(geosens::mesh::file::load(&scenes.join("mesh").join(name)).unwrap());
        for scheme in [Scheme::Rendering, Scheme::Transport] {
            same(
                name,
                geosens::mesh::methods::derivative(s.clone(), scheme),
                2000,
            );
        }
    }
}

/// Budgets under which the roulette acts on many nested estimates: none
/// free (about one event per opportunity: most are skipped where nested
/// walks are long),
/// and a little free work, so that paths cross from free to rouletted on
/// the way.
const HARSH: [Budget; 2] = [
    Budget {
        free_events: 0,
        free_estimates: 0,
        per_estimate: 1.0,
    },
    Budget {
        free_events: 8,
        free_estimates: 2,
        per_estimate: 0.5,
    },
];

/// Under each of [`HARSH`] budgets, rendering's and transport's
/// derivatives of the parameters `names` (by `estimator`, `paths` paths)
/// within 4 standard errors of the finite differences `fd`, the roulette
/// seen to act.
fn rouletted_against<G: Boundaries>(
    what: &str,
    estimator: impl Fn(Scheme) -> DerivativeEstimator<G>,
    schemes: &[Scheme],
    names: &[String],
    fd: &RunResult,
    paths: u64,
) {
    for (k, budget) in HARSH.into_iter().enumerate() {
        for (l, &scheme) in schemes.iter().enumerate() {
            let mut e = estimator(scheme);
            e.budget = budget;
            let what = format!("{what} {scheme:?} {budget:?}");
            let w = work(&e, 1000, 7);
            assert!(4 * w.skipped > w.estimates, "{what}: {w:?}");
            let seed = 31 + (2 * k + l) as u64;
            let r = run(&e, &RunConfig::new(paths, seed).unwrap()).unwrap();
            for name in names {
                agree(&what, name, &r, fd);
            }
        }
    }
}

/// Nested estimates rouletted leave every derivative of rendering and
/// transport within 4 standard errors of central finite differences with
/// common random numbers (step 10⁻² of the scene's size, more paths):
/// Leibniz terms, corner jumps, transport's frozen walks at opaque moving
/// boundaries and at a moving reflector in a medium (the twins'
/// in-scattering; walked for 130 parameters, past the twins), and the
/// in-scattered radiances at a moving fog's boundary.
#[test]
fn rouletted_nested_estimates_stay_unbiased_in_flatland() {
    use geosens::flat::methods::{derivative, finite_difference};
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let both = [Scheme::Rendering, Scheme::Transport];
    for name in ["submerged.toml", "fog.toml"] {
        let s = Arc::new(geosens::flat::file::load(&scenes.join(name)).unwrap());
        let fd = run(
            &finite_difference(&s, 1e-2).unwrap(),
            &RunConfig::new(2_000_000, 99).unwrap(),
        )
        .unwrap();
        let names: Vec<String> = s.parameters().iter().map(|p| p.name.clone()).collect();
        rouletted_against(
            name,
            |m| derivative(s.clone(), m),
            &both,
            &names,
            &fd,
            400_000,
        );
        if name == "submerged.toml" {
            // 130 more copies of the wedge's translation: no twins, the
            // moving reflector's frozen walks walked.
            let mut parameters = s.parameters().to_vec();
            let wedge = parameters
                .iter()
                .find(|p| p.name == "wedge_tx")
                .unwrap()
                .clone();
            parameters.extend((0..130).map(|k| geosens::flat::Parameter {
                name: format!("wedge_tx_{k}"),
                ..wedge.clone()
            }));
            let many = Arc::new(
                geosens::flat::Scene::new(s.shapes().to_vec(), parameters, s.sensor()).unwrap(),
            );
            assert_eq!(derivative(many.clone(), Scheme::Transport).slots.twins, 0);
            let transport = [Scheme::Transport];
            rouletted_against(
                "130 parameters",
                |m| derivative(many.clone(), m),
                &transport,
                &names,
                &fd,
                200_000,
            );
        }
    }
}

/// The 3D counterpart: a closed reflecting room (albedo 0.6, its creases
/// seen from inside) with a lamp panel, a black cube that moves, a
/// reflecting panel that turns and a fog cube that moves, nested estimates
/// rouletted, against finite differences. (Letting the roulette's
/// decisions count the far sides of jumps, which read ahead in the path's
/// stream, read transport's `occ_tx` 0.782 ± 0.003 against 0.740 ± 0.002.)
#[test]
fn rouletted_nested_estimates_stay_unbiased_in_3d() {
    let s = Arc::new(
        geosens::mesh::file::from_toml(
            r#"
[sensor]
kind = "irradiance"
point = [0.1, 0.0, 0.2]
normal = [0.2, 0.1, 1.0]

[[shapes]]
name = "room"
vertices = [[-1.5, -1.5, -0.5], [1.5, -1.5, -0.5], [-1.5, 1.5, -0.5], [1.5, 1.5, -0.5],
            [-1.5, -1.5, 2.5], [1.5, -1.5, 2.5], [-1.5, 1.5, 2.5], [1.5, 1.5, 2.5]]
triangles = [[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4], [2, 6, 7],
             [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]]
surface = { kind = "reflector", albedo = 0.6 }

[[shapes]]
name = "lamp"
vertices = [[-0.1, -0.2, 2.3], [0.5, -0.2, 2.3], [0.5, 0.4, 2.3], [-0.1, 0.4, 2.3]]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = { kind = "emitter", radiance = 3.0 }

[[shapes]]
name = "panel"
vertices = [[-0.9, -0.4, 0.6], [-0.5, -0.4, 1.3], [-0.5, 0.4, 1.3], [-0.9, 0.4, 0.6]]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = { kind = "reflector", albedo = 0.9 }

[[shapes]]
name = "occ"
vertices = [[0.15, -0.2, 1.0], [0.55, -0.2, 1.0], [0.15, 0.2, 1.0], [0.55, 0.2, 1.0],
            [0.15, -0.2, 1.4], [0.55, -0.2, 1.4], [0.15, 0.2, 1.4], [0.55, 0.2, 1.4]]
triangles = [[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4], [2, 6, 7],
             [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]]
surface = { kind = "absorber" }

[[shapes]]
name = "fog"
vertices = [[0.6, -1.0, 0.2], [1.2, -1.0, 0.2], [0.6, -0.4, 0.2], [1.2, -0.4, 0.2],
            [0.6, -1.0, 0.8], [1.2, -1.0, 0.8], [0.6, -0.4, 0.8], [1.2, -0.4, 0.8]]
triangles = [[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4], [2, 6, 7],
             [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]]
surface = { kind = "transparent" }
medium = { ks = 1.5, ke = 2.0 }

[[parameters]]
name = "occ_tx"
shape = "occ"
motion = { kind = "translate_x" }

[[parameters]]
name = "panel_rot"
shape = "panel"
motion = { kind = "rotate", axis = [0.0, 1.0, 0.0], pivot = [-0.9, 0.0, 0.6] }

[[parameters]]
name = "fog_ty"
shape = "fog"
motion = { kind = "translate_y" }
"#,
        )
        .unwrap(),
    );
    let fd = geosens::mesh::methods::finite_difference(&s, 1e-2).unwrap();
    let fd = run(&fd, &RunConfig::new(2_000_000, 60).unwrap()).unwrap();
    let names: Vec<String> = s.parameters().iter().map(|p| p.name.clone()).collect();
    let both = [Scheme::Rendering, Scheme::Transport];
    let estimator = |m| geosens::mesh::methods::derivative(s.clone(), m);
    rouletted_against("3D", estimator, &both, &names, &fd, 150_000);
}

/// `r`'s `∂I/∂name` within 4 combined standard errors of `fd`'s.
fn agree(what: &str, name: &str, r: &RunResult, fd: &RunResult) {
    let q = Quantity::sensitivity(name);
    let (a, b) = (r.get(&q).unwrap(), fd.get(&q).unwrap());
    let z = (a.mean - b.mean) / a.stderr.hypot(b.stderr);
    eprintln!(
        "{what} {name}: {:.6} ± {:.2e} vs fd {:.6} ± {:.2e} (z {z:.2})",
        a.mean, a.stderr, b.mean, b.stderr
    );
    assert!(
        a.stderr > 0.0 && z.abs() < 4.0,
        "{what} {name}: {a:?} vs fd {b:?}"
    );
}
