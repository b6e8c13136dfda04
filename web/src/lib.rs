//! The estimators in a browser: WebAssembly bindings of geosens for the live
//! book's widgets (`book/src/live/`), built by `web/build.sh`.
//!
//! A [`Run`] is a `geosens rod --json` or `geosens flat --json` run sampled a
//! few blocks at a time, so that a Web Worker can post its estimates as they
//! grow. It samples blocks with [`geosens::runner::sample_blocks`] and merges
//! them in block order, which is the runner's own reduction: after `k`
//! blocks of 65 536 paths its JSON line is, bit for bit where the platform's
//! floating point agrees, what the command line prints for `--paths
//! k·65536` with the same seed (and for the whole run, what it prints for
//! `--paths N`). Nothing here estimates anything itself.
use geosens::Error;
use geosens::estimator::Quantity;
use geosens::job::{Job, Prepared, SceneSource, Target, parse_method};
use geosens::report::{Report, RodProbe};
use geosens::runner::{self, BLOCK, CHUNK, RunConfig, RunResult};
use geosens::stats::Moments;
use glam::DVec2;
use serde_json::{Value, json};
use std::sync::Arc;
use wasm_bindgen::prelude::*;

/// Paths per block: the unit a [`Run`] advances by.
const BLOCK_PATHS: u64 = BLOCK * CHUNK;

fn js(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}

/// The job a JSON request describes: `{"rod": {ks, ke, length, x, omega}}`
/// or `{"flat": <the scene file's schema>}`, with `"method"` (a method's
/// name, or `exact` on the rod).
fn job_of(request: &Value) -> Result<Job, Error> {
    let method = request
        .get("method")
        .and_then(Value::as_str)
        .ok_or_else(|| Error::Config("the request needs a \"method\"".into()))?;
    let target = if let Some(rod) = request.get("rod") {
        let probe: RodProbe =
            serde_json::from_value(rod.clone()).map_err(|e| Error::Config(format!("rod: {e}")))?;
        Target::Rod(probe)
    } else if let Some(scene) = request.get("flat") {
        Target::Flat(SceneSource::Json(scene.to_string()))
    } else {
        return Err(Error::Config(
            "the request needs \"rod\" or \"flat\"".into(),
        ));
    };
    let rod = matches!(target, Target::Rod(_));
    Ok(Job {
        target,
        method: parse_method(method, rod)?,
        fd_step: request.get("fd_step").and_then(Value::as_f64),
    })
}

/// A run sampled block by block.
#[wasm_bindgen]
pub struct Run {
    prepared: Prepared,
    method: &'static str,
    cfg: RunConfig,
    total: Vec<Moments>,
    blocks_done: u64,
}

#[wasm_bindgen]
impl Run {
    /// A run of the request `{"rod"|"flat": …, "method", "paths", "seed"}`
    /// (JSON text); errors name the bad input as the command line does.
    #[wasm_bindgen(constructor)]
    pub fn new(request: &str) -> Result<Run, JsError> {
        let request: Value = serde_json::from_str(request).map_err(js)?;
        let job = job_of(&request).map_err(js)?;
        let paths = request
            .get("paths")
            .and_then(Value::as_u64)
            .unwrap_or(1_000_000);
        let seed = request.get("seed").and_then(Value::as_u64).unwrap_or(0);
        let mut cfg = RunConfig::new(paths, seed).map_err(js)?;
        cfg.threads = 1;
        let prepared = job.prepare().map_err(js)?;
        let method = job.method.map_or("exact", |m| m.name());
        let nq = prepared
            .estimator
            .as_ref()
            .map_or(0, |e| e.quantities().len());
        Ok(Run {
            prepared,
            method,
            cfg,
            total: vec![Moments::default(); nq],
            blocks_done: 0,
        })
    }

    /// Samples up to `blocks` more blocks (65 536 paths each); returns
    /// whether the run is complete.
    pub fn step(&mut self, blocks: u32) -> Result<bool, JsError> {
        let Some(est) = &self.prepared.estimator else {
            return Ok(true);
        };
        let end = runner::blocks(self.cfg.paths);
        let upto = end.min(self.blocks_done + u64::from(blocks));
        let range = self.blocks_done..upto;
        let (sampled, _) =
            runner::sample_blocks(est.as_ref(), &self.cfg, range, &runner::quiet).map_err(js)?;
        for block in &sampled {
            for (t, m) in self.total.iter_mut().zip(block) {
                *t = t.merge(m);
            }
        }
        self.blocks_done = upto;
        Ok(upto == end)
    }

    /// Paths sampled so far.
    pub fn paths(&self) -> f64 {
        (self.blocks_done * BLOCK_PATHS).min(self.cfg.paths) as f64
    }

    /// The command line's JSON line for the paths sampled so far (its
    /// `seconds` is 0: the page times the run). The rod's exact solution is
    /// complete at once.
    pub fn json(&self) -> Result<String, JsError> {
        let result = match &self.prepared.estimator {
            None => geosens::job::exact_result(&self.prepared.header).map_err(js)?,
            Some(est) => RunResult {
                method: self.method,
                estimates: est
                    .quantities()
                    .into_iter()
                    .zip(self.total.iter().map(Moments::estimate))
                    .collect(),
                paths: self.paths() as u64,
                seconds: 0.0,
            },
        };
        Report {
            header: self.prepared.header.clone(),
            result,
            seed: self.cfg.seed,
            caveats: self.prepared.caveats.clone(),
        }
        .json()
        .map_err(js)
    }
}

/// The rod's exact values (Bellman–Wing) at a probe, `{"ks", "ke",
/// "length", "x", "omega"}`: `[I, ∂I/∂π̃, ∂I/∂x]`.
#[wasm_bindgen]
pub fn rod_exact(probe: &str) -> Result<Vec<f64>, JsError> {
    let given: RodProbe = serde_json::from_str(probe).map_err(js)?;
    let (rod, probe) = given.build().map_err(js)?;
    Ok(geosens::report::rod_exact(&rod, &probe).to_vec())
}

/// The rod's exact curves along `x` for both directions at `n` points:
/// `{"x": […], "right": {"intensity", "sensitivity"}, "left": {…}}`.
#[wasm_bindgen]
pub fn rod_curves(ks: f64, ke: f64, length: f64, n: u32) -> Result<String, JsError> {
    let n = n.max(2) as usize;
    let xs: Vec<f64> = (0..n).map(|i| length * i as f64 / (n - 1) as f64).collect();
    let mut out = json!({ "x": xs });
    for (name, omega) in [("right", 1.0), ("left", -1.0)] {
        let mut i = Vec::with_capacity(n);
        let mut s = Vec::with_capacity(n);
        for &x in &xs {
            let (rod, probe) = RodProbe {
                ks,
                ke,
                length,
                x,
                omega,
            }
            .build()
            .map_err(js)?;
            let [vi, vs, _] = geosens::report::rod_exact(&rod, &probe);
            i.push(vi);
            s.push(vs);
        }
        out[name] = json!({ "intensity": i, "sensitivity": s });
    }
    Ok(out.to_string())
}

/// A flatland scene (the file's schema as JSON text), checked.
fn flat_scene(scene: &str) -> Result<Arc<geosens::flat::Scene>, JsError> {
    Ok(Arc::new(geosens::flat::file::from_json(scene).map_err(js)?))
}

/// The closed form of a flatland scene that has one (an irradiance sensor,
/// one emitter segment, black absorbers, at most one absorbing medium):
/// `{"intensity": E, "sensitivity": {parameter: ∂E/∂π}}`; an error says why
/// a scene has none.
#[wasm_bindgen]
pub fn flat_exact(scene: &str) -> Result<String, JsError> {
    let scene = flat_scene(scene)?;
    let r = geosens::flat::exact::Reference::for_scene(&scene).map_err(js)?;
    let sensitivity: serde_json::Map<String, Value> = scene
        .parameters()
        .iter()
        .enumerate()
        .map(|(j, p)| (p.name.clone(), json!(r.derivative(j))))
        .collect();
    Ok(json!({ "intensity": r.value(), "sensitivity": sensitivity }).to_string())
}

/// The expectation method's warp field on a fan of `rays` directions over
/// the sensor's half circle: per ray its end (the first hit, or `null`) and
/// per parameter `t V_j(φ) η⊥`, the velocity of that end
/// ([`geosens::flat::methods::sensor_warp`], what `flat_warp` draws):
/// `{"origin", "rays": [{"phi", "end", "arrows": {parameter: [dx, dy]}}]}`.
#[wasm_bindgen]
pub fn flat_warp(scene: &str, rays: u32) -> Result<String, JsError> {
    use geosens::flat::geometry::{NO_SEGMENT, direction, perp};
    let scene = flat_scene(scene)?;
    let (x, phi_n) = match scene.sensor() {
        geosens::flat::Sensor::Irradiance { point, normal } => (point, normal.y.atan2(normal.x)),
        _ => return Err(js("the warp field is drawn for an irradiance sensor")),
    };
    let plane = geosens::flat::space::Plane::new(Arc::clone(&scene));
    let names: Vec<&str> = scene.parameters().iter().map(|p| p.name.as_str()).collect();
    let mut out = Vec::new();
    for i in 0..rays {
        let phi = phi_n - std::f64::consts::FRAC_PI_2
            + std::f64::consts::PI * (f64::from(i) + 0.5) / f64::from(rays);
        let w = direction(phi);
        let ray = match scene.cast(x, w, NO_SEGMENT) {
            Some(h) => {
                let v = geosens::flat::methods::sensor_warp(&plane, phi);
                let end = x + h.t * w;
                let arrows: serde_json::Map<String, Value> = names
                    .iter()
                    .zip(v)
                    .map(|(n, vj)| {
                        let a: DVec2 = h.t * vj * perp(w);
                        ((*n).to_owned(), json!([a.x, a.y]))
                    })
                    .collect();
                json!({ "phi": phi, "end": [end.x, end.y], "arrows": arrows })
            }
            None => json!({ "phi": phi, "end": null, "arrows": {} }),
        };
        out.push(ray);
    }
    Ok(json!({ "origin": [x.x, x.y], "rays": out }).to_string())
}

/// Quantities' names as the JSON line spells them, for a page's labels.
#[wasm_bindgen]
pub fn quantity_names(request: &str) -> Result<Vec<String>, JsError> {
    let request: Value = serde_json::from_str(request).map_err(js)?;
    let prepared = job_of(&request).and_then(|j| j.prepare()).map_err(js)?;
    Ok(prepared.estimator.map_or(Vec::new(), |e| {
        e.quantities().iter().map(Quantity::to_string).collect()
    }))
}

/// Most vertices [`sampled_paths`] keeps.
const MOST_VERTICES: usize = 20_000;

/// The first `n` paths a run of `request` (`{"flat": …, "method", "seed"}`,
/// as for [`Run`]) samples, as the estimator walked them: they draw from
/// the stream of the run's first chunk, so they are its paths 0 to `n − 1`
/// ([`geosens::path::record`] writes their vertices down). `{"vertices":
/// [path, walk, x, y, z, …], "weights": [[w per quantity] per path]}`,
/// `walk` 0 the path from the sensor, higher the walks it nested (or a
/// finite difference's displaced twins).
#[wasm_bindgen]
pub fn sampled_paths(request: &str, n: u32) -> Result<String, JsError> {
    let request: Value = serde_json::from_str(request).map_err(js)?;
    let seed = request.get("seed").and_then(Value::as_u64).unwrap_or(0);
    let prepared = job_of(&request).and_then(|j| j.prepare()).map_err(js)?;
    let est = prepared
        .estimator
        .ok_or_else(|| js("the exact solution samples no path"))?;
    let mut rng = geosens::rng::stream(seed, 0);
    let mut weights = vec![vec![0.0; est.quantities().len()]; n as usize];
    let vertices = geosens::path::record::recorded(n, MOST_VERTICES, |i| {
        est.sample(&mut rng, &mut weights[i as usize]);
    });
    let flat: Vec<f64> = vertices.into_iter().flatten().collect();
    Ok(json!({ "vertices": flat, "weights": weights }).to_string())
}
