//! Are the 3D error bars honest? As `flat_coverage.rs`: over many
//! independent runs, the fraction whose estimate lies within ±2 and ±3
//! standard errors of the closed form must match the normal law (95.45 %,
//! 99.73 %), for intensity and for rendering, expectation and transport on
//! every parameter kind (translations along x, y, z, rotation, scale).
//!
//! Scenes with a closed form (`mesh::exact`): the square occluder under the
//! square lamp, off-centre and rotated, and a closed box. Every (method,
//! scene, parameter) gets [`RUNS`] runs of [`PATHS`] paths with seeds used
//! nowhere else; each count of runs within `k` standard errors is then
//! Binomial(runs, P(|Z| ≤ k)) for an honest error bar, and the test
//! accepts its central `1 − 2·10⁻⁴`, per parameter and pooled per kind.
//! With 2 × (3 + 1 + 3 · (3 · 5 + 5)) = 128 ranges checked, a correct
//! estimator fails one with probability below 2.6 %; the seeds are fixed,
//! so a pass is reproducible. About 7 × 10⁷ paths, a minute on 2 cores.
//!
//! Observed (pooled per kind): 0.93–0.97 within 2σ, 0.993–1 within 3σ. At
//! 4000 paths per run two cases covered too little: expectation's `ty` on
//! the square (0.86 within 2σ) before the warp aligned its fibres with
//! translations (a silhouette's vertex made knots with different slide
//! rates meet: a log-divergent variance), and transport's scale
//! (591/600 within 3σ, accepted from 592), which at 16 000 paths per run
//! covers normally (0.955, 0.995): its weights' skew needs more paths than
//! rendering's before the normal law holds. Hence 10 000 paths per run.
use geosens::mesh::cases::{box_shape, lamp, up};
use geosens::mesh::exact::{BoxScene, OccluderScene};
use geosens::mesh::{Motion, Parameter, Scene, Shape, Surface};
use geosens::{Estimate, Method, Quantity, RunConfig, run};
use glam::DVec3;
use rayon::prelude::*;
use statrs::distribution::{Binomial, ContinuousCDF, DiscreteCDF, Normal};
use std::sync::Arc;

/// Runs per (method, scene, parameter).
const RUNS: u64 = 150;
/// Paths per run.
const PATHS: u64 = 10_000;
/// Each tail of the binomial law left out of the acceptance range.
const TAIL: f64 = 1e-4;

const NAMES: [&str; 5] = ["tx", "ty", "tz", "rot", "scale"];

/// Runs within 2σ and 3σ, out of `runs`.
#[derive(Debug, Default, Clone, Copy)]
struct Count {
    runs: u64,
    within2: u64,
    within3: u64,
    /// Runs flagged unreliable, and misses beyond 2σ that were flagged.
    flagged: u64,
    missed2_flagged: u64,
}

impl Count {
    fn of(estimates: &[Estimate], exact: f64) -> Count {
        let mut c = Count::default();
        for e in estimates {
            let z = e.z_score(exact);
            c.runs += 1;
            c.within2 += u64::from(z <= 2.0);
            c.within3 += u64::from(z <= 3.0);
            c.flagged += u64::from(!e.is_reliable());
            c.missed2_flagged += u64::from(z > 2.0 && !e.is_reliable());
        }
        c
    }

    fn add(&mut self, o: Count) {
        self.runs += o.runs;
        self.within2 += o.within2;
        self.within3 += o.within3;
        self.flagged += o.flagged;
        self.missed2_flagged += o.missed2_flagged;
    }
}

fn check(c: &Count) -> Result<(), String> {
    let mut why = Vec::new();
    for (k, n) in [(2.0, c.within2), (3.0, c.within3)] {
        let p = 2.0 * Normal::standard().cdf(k) - 1.0;
        let b = Binomial::new(p, c.runs).unwrap();
        let (lo, hi) = (b.inverse_cdf(TAIL), b.inverse_cdf(1.0 - TAIL));
        if !(lo..=hi).contains(&n) {
            why.push(format!("{n}/{} within {k}σ, accepted {lo}..={hi}", c.runs));
        }
    }
    if why.is_empty() {
        Ok(())
    } else {
        Err(why.join("; "))
    }
}

/// The scenes: name, scene, closed-form E and sensitivities.
fn scenes() -> Vec<(&'static str, Arc<Scene>, f64, [f64; 5])> {
    let (lamp, sensor) = (lamp(), up());
    let build = |occ: Shape, motions: [Motion; 5]| {
        let parameters = NAMES
            .iter()
            .zip(motions)
            .map(|(n, m)| Parameter {
                name: (*n).into(),
                shape: "occ".into(),
                motion: m,
                bounds: None,
            })
            .collect();
        Arc::new(Scene::new(vec![lamp.clone(), occ], parameters, sensor).unwrap())
    };
    let mut out = Vec::new();
    for (name, cx, cy, angle) in [("square", 0.3, 0.1, 0.0), ("rotated", -0.2, 0.25, 0.4)] {
        let mut o = OccluderScene::shipped(cx, cy);
        o.occ_angle = angle;
        let occ = o.occluder_shape();
        out.push((
            name,
            build(occ, o.motions()),
            o.irradiance().unwrap(),
            o.sensitivities().unwrap(),
        ));
    }
    let b = BoxScene::shipped(DVec3::new(0.2, -0.1, 1.0), 0.3);
    let occ = box_shape("occ", b.corners(), Surface::Absorber, None);
    out.push((
        "box",
        build(occ, b.motions()),
        b.irradiance().unwrap(),
        b.sensitivities().unwrap(),
    ));
    out
}

fn runs(method: Method, scene: &Arc<Scene>, q: &Quantity, base: u64) -> Vec<Estimate> {
    let estimator = method.estimator(scene.clone()).unwrap();
    (0..RUNS)
        .into_par_iter()
        .map(|i| {
            let cfg = RunConfig::new(PATHS, base + i).unwrap().threads(1);
            run(estimator.as_ref(), &cfg).unwrap().get(q).unwrap()
        })
        .collect()
}

#[test]
fn error_bars_cover_the_closed_forms() {
    let scenes = scenes();
    let mut failures = Vec::new();
    let mut report = |what: String, c: &Count| {
        eprintln!(
            "{what:<34} {:.4} within 2σ, {:.4} within 3σ ({} runs; {} flagged, {} of the {} misses beyond 2σ)",
            c.within2 as f64 / c.runs as f64,
            c.within3 as f64 / c.runs as f64,
            c.runs,
            c.flagged,
            c.missed2_flagged,
            c.runs - c.within2
        );
        if let Err(why) = check(c) {
            failures.push(format!("{what}: {why}"));
        }
    };
    let mut intensity = Count::default();
    for (s, (name, scene, e, _)) in scenes.iter().enumerate() {
        let c = Count::of(
            &runs(
                Method::Intensity,
                scene,
                &Quantity::Intensity,
                1_000_000 * (s as u64 + 1),
            ),
            *e,
        );
        report(format!("intensity {name} I"), &c);
        intensity.add(c);
    }
    report("intensity pooled I".into(), &intensity);
    let methods = [Method::Rendering, Method::Expectation, Method::Transport];
    for (m, method) in methods.into_iter().enumerate() {
        let mut kinds = [Count::default(); 5];
        for (s, (name, scene, _, exact)) in scenes.iter().enumerate() {
            for (j, param) in NAMES.iter().enumerate() {
                let base = 10_000_000 * (m as u64 + 1) + 100_000 * (s as u64 * 8 + j as u64);
                let c = Count::of(
                    &runs(method, scene, &Quantity::sensitivity(param), base),
                    exact[j],
                );
                report(format!("{method} {name} {param}"), &c);
                kinds[j].add(c);
            }
        }
        for (j, param) in NAMES.iter().enumerate() {
            report(format!("{method} pooled {param}"), &kinds[j]);
        }
    }
    assert!(
        failures.is_empty(),
        "coverage fails:\n{}",
        failures.join("\n")
    );
}
