//! `geosens._geosens`: the Rust side of the `geosens` Python package, a thin
//! layer over the library's jobs ([`geosens::job`]), printing
//! ([`geosens::report`]), shards ([`geosens::shard`]) and optimisation
//! ([`geosens::optimize`]), and the closed forms ([`Target::exact`]).
//! Every estimating function returns the same JSON text as
//! the command line's `--json` line (`optimize`: lines; or a shard's
//! state), which `geosens/__init__.py` turns into Python objects;
//! every bad input raises `ValueError` with the library's message, the one
//! the command line prints after `error: `. The GIL is released while
//! sampling, and Ctrl-C stops a run (`KeyboardInterrupt`), as does the
//! caller's `stop` (a run on another thread than Python's main one, which
//! alone sees signals).
use geosens::image::ImageResult;
use geosens::job::{ImageReport, Job, RenderJob, SceneSource, Target};
use geosens::optimize::{Optimizer, Product, Record, Sampling, Settings};
use geosens::report::Report;
use geosens::runner::Progress;
use geosens::shard::{Merged, Shard, State, merge as merge_states};
use geosens::{Error, Method, Quantity, RunConfig};
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

/// One image of a rendering as Python gets it: its key (`I`, or the
/// parameter's name), height, width, and the bytes of its means and standard
/// errors (native-endian `f64`, row-major).
type Image = (String, u32, u32, Py<PyBytes>, Py<PyBytes>);

/// What every function returns: the kind (`"report"`: the JSON line of
/// `rod`, `flat` or `mesh`; `"image"`: the JSON line of `render`; `"state"`:
/// a shard's state), the JSON text, the warnings the command line prints on
/// stderr, and a rendering's images (empty otherwise).
type Outcome = (&'static str, String, Vec<String>, Vec<Image>);

/// What a run gives before it becomes Python objects (built without the
/// GIL).
enum Output {
    Report(Report),
    Image(ImageReport),
    State(State),
}

/// `e` as the `ValueError` Python raises, with the command line's message.
fn value_error(e: Error) -> PyErr {
    PyValueError::new_err(e.to_string())
}

impl Output {
    /// The JSON text, warnings and images, as [`Outcome`].
    fn into_py(self, py: Python<'_>) -> Result<Outcome, Error> {
        Ok(match self {
            Output::Report(r) => ("report", r.json()?, r.warnings(), Vec::new()),
            Output::Image(r) => ("image", r.json()?, r.warnings(), images(py, &r.result)),
            Output::State(s) => ("state", s.to_json()?, Vec::new(), Vec::new()),
        })
    }
}

/// The images of `r` as [`Image`]s, in the estimator's order.
fn images(py: Python<'_>, r: &ImageResult) -> Vec<Image> {
    let bytes = |f: &dyn Fn(&geosens::Estimate) -> f64, img: &[geosens::Estimate]| {
        let b: Vec<u8> = img.iter().flat_map(|e| f(e).to_ne_bytes()).collect();
        PyBytes::new(py, &b).unbind()
    };
    r.images
        .iter()
        .map(|(q, img)| {
            let key = match q {
                Quantity::Intensity => "I".to_owned(),
                Quantity::Sensitivity(p) => p.clone(),
                Quantity::Gradient(_) => q.to_string(),
            };
            (
                key,
                r.height,
                r.width,
                bytes(&|e| e.mean, img),
                bytes(&|e| e.stderr, img),
            )
        })
        .collect()
}

/// The scene: a file, or the file's schema as JSON text.
fn source(path: Option<PathBuf>, json: Option<String>) -> PyResult<SceneSource> {
    match (path, json) {
        (Some(p), None) => Ok(SceneSource::File(p)),
        (None, Some(text)) => Ok(SceneSource::Json(text)),
        _ => Err(PyValueError::new_err(
            "the scene is either a file or JSON text",
        )),
    }
}

/// Runs `work` on a thread of its own while the calling thread, the GIL
/// released, looks every 50 ms for signals and calls `stop` (a callable,
/// true to stop). Python runs its signal handlers on its main thread only,
/// between bytecodes, so Ctrl-C reaches a run called from there; a run
/// called from another thread is stopped through `stop`, which the caller
/// sets when its main thread gets the `KeyboardInterrupt`. Either way the
/// run stops at its next chunk (a rendering's: pixel) through its progress
/// hook, and the exception (the signal handler's, `stop`'s own if calling
/// it raised, else `KeyboardInterrupt`) is raised here once the chunks
/// under way have ended.
fn interruptible<T: Send>(
    py: Python<'_>,
    stop: Option<&Py<PyAny>>,
    work: impl FnOnce(Progress) -> Result<T, Error> + Send,
) -> PyResult<Result<T, Error>> {
    interruptible_with(py, stop, |()| Ok(true), |progress, _| work(progress))
}

/// [`interruptible`] for a run that hands the calling thread messages as it
/// goes (an optimisation's records): `work` gets, beside the progress hook,
/// a function that passes a message to `receive`, called with the GIL on
/// the calling thread, and returns what `receive` returned (true to go on)
/// once it has: the run waits. A message is not received (false) once the
/// run is being stopped; an exception raised by `receive` stops the run
/// and is raised here, as a signal's.
fn interruptible_with<T: Send, M: Send>(
    py: Python<'_>,
    stop: Option<&Py<PyAny>>,
    mut receive: impl FnMut(M) -> PyResult<bool>,
    work: impl FnOnce(Progress, &dyn Fn(M) -> bool) -> Result<T, Error> + Send,
) -> PyResult<Result<T, Error>> {
    let stopping = AtomicBool::new(false);
    let hook = |_done: u64| {
        if stopping.load(Ordering::Relaxed) {
            Err(Error::Stopped("interrupted".into()))
        } else {
            Ok(())
        }
    };
    let hook = &hook;
    std::thread::scope(|s| {
        // Messages (`None`: the run has ended), and the answers to them.
        let (tx, rx) = mpsc::channel::<Option<M>>();
        let (answer_tx, answer_rx) = mpsc::channel::<bool>();
        // The stack of a main thread: a run on one thread runs here.
        let worker = std::thread::Builder::new()
            .stack_size(8 << 20)
            .spawn_scoped(s, move || {
                // No answer (the calling thread is gone): stop.
                let send = |m: M| tx.send(Some(m)).is_ok() && answer_rx.recv().unwrap_or(false);
                let out = work(hook, &send);
                let _ = tx.send(None);
                out
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start the run's thread: {e}")))?;
        let (mut signal, mut rx) = (None, rx);
        loop {
            // The receiver goes to the GIL-free side and back (it is Send,
            // not Sync).
            let (waited, back) =
                py.detach(move || (rx.recv_timeout(Duration::from_millis(50)), rx));
            rx = back;
            match waited {
                Ok(Some(m)) => {
                    let go_on = signal.is_none()
                        && receive(m).unwrap_or_else(|e| {
                            signal = Some(e);
                            stopping.store(true, Ordering::Relaxed);
                            false
                        });
                    let _ = answer_tx.send(go_on);
                }
                Ok(None) | Err(mpsc::RecvTimeoutError::Disconnected) => break,
                Err(mpsc::RecvTimeoutError::Timeout) => {}
            }
            if signal.is_none() {
                signal = py.check_signals().err().or_else(|| stopped(py, stop));
                if signal.is_some() {
                    stopping.store(true, Ordering::Relaxed);
                }
            }
        }
        let out = py
            .detach(|| worker.join())
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        signal.map_or(Ok(out), Err)
    })
}

/// The exception that stops a run if the caller's `stop` says so (true,
/// or raising): see [`interruptible`].
fn stopped(py: Python<'_>, stop: Option<&Py<PyAny>>) -> Option<PyErr> {
    match stop?.bind(py).call0().and_then(|v| v.is_truthy()) {
        Ok(false) => None,
        Ok(true) => Some(PyKeyboardInterrupt::new_err(
            "the run was stopped: its stop was set",
        )),
        Err(e) => Some(e),
    }
}

/// Runs `job` on `paths` paths, or its shard `shard = (i, n)`, without the
/// GIL, stopping at Ctrl-C or at `stop` ([`interruptible`]).
#[allow(clippy::too_many_arguments)]
fn estimate(
    py: Python<'_>,
    job: Job,
    paths: u64,
    seed: u64,
    threads: usize,
    shard: Option<(u64, u64)>,
    stop: Option<Py<PyAny>>,
) -> PyResult<Outcome> {
    let out = interruptible(py, stop.as_ref(), |progress| -> Result<Output, Error> {
        let cfg = RunConfig::new(paths, seed)?.threads(threads);
        match shard {
            None => job.run(&cfg, progress).map(Output::Report),
            Some((i, n)) => job
                .run_shard(&cfg, Shard::new(i, n)?, progress)
                .map(Output::State),
        }
    })?;
    out.and_then(|o| o.into_py(py)).map_err(value_error)
}

/// `geosens rod`: `method` is a method's name or `exact`.
#[pyfunction]
#[pyo3(signature = (method, ks, ke, length, x, omega, paths, seed, threads, fd_step, shard, stop))]
#[allow(clippy::too_many_arguments)]
fn rod(
    py: Python<'_>,
    method: &str,
    ks: f64,
    ke: f64,
    length: f64,
    x: f64,
    omega: f64,
    paths: u64,
    seed: u64,
    threads: usize,
    fd_step: Option<f64>,
    shard: Option<(u64, u64)>,
    stop: Option<Py<PyAny>>,
) -> PyResult<Outcome> {
    // `exact` beside the methods, as the command line's `--method` lists
    // them.
    let method = geosens::job::parse_method(method, true).map_err(value_error)?;
    let job = Job {
        target: Target::Rod(geosens::report::RodProbe {
            ks,
            ke,
            length,
            x,
            omega,
        }),
        method,
        fd_step,
    };
    estimate(py, job, paths, seed, threads, shard, stop)
}

/// `geosens flat` (`mesh = false`) or `geosens mesh` on a scene file
/// (`path`) or JSON text (`json`).
#[pyfunction]
#[pyo3(signature = (mesh, path, json, method, paths, seed, threads, fd_step, shard, stop))]
#[allow(clippy::too_many_arguments)]
fn scene(
    py: Python<'_>,
    mesh: bool,
    path: Option<PathBuf>,
    json: Option<String>,
    method: &str,
    paths: u64,
    seed: u64,
    threads: usize,
    fd_step: Option<f64>,
    shard: Option<(u64, u64)>,
    stop: Option<Py<PyAny>>,
) -> PyResult<Outcome> {
    let method = method.parse::<Method>().map_err(value_error)?;
    let source = source(path, json)?;
    let job = Job {
        target: if mesh {
            Target::Mesh(source)
        } else {
            Target::Flat(source)
        },
        method: Some(method),
        fd_step,
    };
    estimate(py, job, paths, seed, threads, shard, stop)
}

/// `geosens render` on a scene file (`path`) or JSON text (`json`), or its
/// shard `shard = (i, n)`.
#[pyfunction]
#[pyo3(signature = (path, json, method, spp, seed, threads, fd_step, shard, stop))]
#[allow(clippy::too_many_arguments)]
fn render(
    py: Python<'_>,
    path: Option<PathBuf>,
    json: Option<String>,
    method: &str,
    spp: u64,
    seed: u64,
    threads: usize,
    fd_step: Option<f64>,
    shard: Option<(u64, u64)>,
    stop: Option<Py<PyAny>>,
) -> PyResult<Outcome> {
    let method = method.parse::<Method>().map_err(value_error)?;
    let job = RenderJob {
        scene: source(path, json)?,
        method,
        fd_step,
    };
    let out = interruptible(py, stop.as_ref(), |progress| -> Result<Output, Error> {
        geosens::runner::check_threads(threads)?;
        match shard {
            None => job.run(spp, seed, threads, progress).map(Output::Image),
            Some((i, n)) => job
                .run_shard(spp, seed, threads, Shard::new(i, n)?, progress)
                .map(Output::State),
        }
    })?;
    out.and_then(|o| o.into_py(py)).map_err(value_error)
}

/// `geosens optimize --json` on a scene file (`path`) or JSON text (`json`),
/// flatland or 3D by its points: the records' JSON lines. `each`, if given,
/// is called with each record's line as it is made, on the calling thread;
/// a false answer ends the run after that record (it is the last returned).
/// Ctrl-C and `stop` end it after the iteration under way
/// (`KeyboardInterrupt`, [`interruptible_with`]).
#[pyfunction]
#[pyo3(signature = (path, json, method, optimizer, iterations, paths_per_step, step, batches, fd_step, tolerance, seed, threads, each, stop))]
#[allow(clippy::too_many_arguments)]
fn optimize(
    py: Python<'_>,
    path: Option<PathBuf>,
    json: Option<String>,
    method: &str,
    optimizer: &str,
    iterations: u64,
    paths_per_step: u64,
    step: f64,
    batches: u64,
    fd_step: Option<f64>,
    tolerance: f64,
    seed: u64,
    threads: usize,
    each: Option<Py<PyAny>>,
    stop: Option<Py<PyAny>>,
) -> PyResult<Vec<String>> {
    let config = |m: String| value_error(Error::Config(m));
    let method = method.parse::<Method>().map_err(value_error)?;
    let optimizer = match optimizer {
        "adam" => Optimizer::Adam,
        "sgd" => Optimizer::Sgd,
        other => {
            return Err(config(format!(
                "unknown optimizer {other:?}: expected one of adam, sgd"
            )));
        }
    };
    // The command line's checks (clap's types and its own), named as
    // Python names them.
    if !(step.is_finite() && step > 0.0) {
        return Err(config(format!("step {step} is not a positive number")));
    }
    let iterations = match u32::try_from(iterations) {
        Ok(0) => return Err(config("iterations must be at least 1".into())),
        Ok(n) => n,
        Err(_) => return Err(config(format!("iterations {iterations} is over 2^32 - 1"))),
    };
    let batches = u32::try_from(batches)
        .map_err(|_| config(format!("batches {batches} is over 2^32 - 1")))?;
    let settings = Settings {
        method,
        optimizer,
        iterations,
        step,
        sampling: Sampling {
            paths: paths_per_step,
            batches,
            seed,
            threads,
            fd_step,
            product: Product::Independent,
        },
        tolerance,
    };
    let source = source(path, json)?;
    let receive = |line: String| -> PyResult<bool> {
        match &each {
            Some(f) => f.bind(py).call1((line,))?.is_truthy(),
            None => Ok(true),
        }
    };
    let out = interruptible_with(py, stop.as_ref(), receive, |_progress, send| {
        let mut lines = Vec::new();
        let mut failed = None;
        let each = |r: &Record| match serde_json::to_string(r) {
            Ok(line) => {
                lines.push(line.clone());
                send(line)
            }
            Err(e) => {
                failed = Some(Error::Output(e.to_string()));
                false
            }
        };
        match source.dimension()? {
            Some(3) => geosens::optimize::optimize(&source.mesh_study()?, &settings, each)?,
            _ => geosens::optimize::optimize(&source.flat_study()?, &settings, each)?,
        };
        failed.map_or(Ok(lines), Err)
    })?;
    out.map_err(value_error)
}

/// The closed form as Python gets it: `I`, `∂I/∂π` by parameter, the
/// sensor's gradient by axis (`None` in 3D).
type Closed = (f64, Vec<(String, f64)>, Option<Vec<(String, f64)>>);

/// The rod's Bellman–Wing solution at every probe position of `xs`
/// (direction `omega`): `I`, `∂I/∂length` and `∂I/∂x`, one list each.
#[pyfunction]
fn rod_exact(
    ks: f64,
    ke: f64,
    length: f64,
    xs: Vec<f64>,
    omega: f64,
) -> PyResult<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    let mut out = (
        Vec::with_capacity(xs.len()),
        Vec::with_capacity(xs.len()),
        Vec::with_capacity(xs.len()),
    );
    for x in xs {
        let probe = geosens::report::RodProbe {
            ks,
            ke,
            length,
            x,
            omega,
        };
        let (rod, probe) = probe.build().map_err(value_error)?;
        let [i, s, g] = geosens::report::rod_exact(&rod, &probe);
        out.0.push(i);
        out.1.push(s);
        out.2.push(g);
    }
    Ok(out)
}

/// The closed form of a flatland (`mesh = false`) or 3D scene, a file
/// (`path`) or JSON text (`json`), as [`Closed`]; `ValueError` saying why
/// when it has none ([`Target::exact`]).
#[pyfunction]
#[pyo3(signature = (mesh, path, json))]
fn scene_exact(
    py: Python<'_>,
    mesh: bool,
    path: Option<PathBuf>,
    json: Option<String>,
) -> PyResult<Closed> {
    let source = source(path, json)?;
    let target = if mesh {
        Target::Mesh(source)
    } else {
        Target::Flat(source)
    };
    // A medium's quadrature, a large mesh's loading: without the GIL.
    let e = py.detach(|| target.exact()).map_err(value_error)?;
    Ok((e.intensity, e.sensitivity, e.gradient))
}

/// `geosens merge`: `states` holds, per state, its name in messages and
/// either its file or its JSON text.
#[pyfunction]
fn merge(
    py: Python<'_>,
    states: Vec<(String, Option<PathBuf>, Option<String>)>,
) -> PyResult<Outcome> {
    let out = py.detach(|| -> Result<Output, Error> {
        let mut labelled = Vec::with_capacity(states.len());
        for (name, path, text) in states {
            // The command line's messages: a file that cannot be read, and
            // a text that is not a state, named.
            let state = match (path, text) {
                (Some(p), _) => State::read(&p)?,
                (None, Some(t)) => State::named(&name, &t)?,
                (None, None) => return Err(Error::Merge(format!("{name}: no state"))),
            };
            labelled.push((name, state));
        }
        Ok(match merge_states(&labelled)? {
            Merged::Probe(r) => Output::Report(r),
            Merged::Image(r) => Output::Image(r),
        })
    });
    out.and_then(|o| o.into_py(py)).map_err(value_error)
}

/// The module `geosens._geosens`.
#[pymodule]
fn _geosens(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(rod, m)?)?;
    m.add_function(wrap_pyfunction!(scene, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(optimize, m)?)?;
    m.add_function(wrap_pyfunction!(rod_exact, m)?)?;
    m.add_function(wrap_pyfunction!(scene_exact, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
