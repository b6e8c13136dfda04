//! `geosens._geosens`: the Rust side of the `geosens` Python package, a thin
//! layer over the library's jobs ([`geosens::job`]), printing
//! ([`geosens::report`]) and shards ([`geosens::shard`]). Every function
//! returns the same JSON text as the command line's `--json` line (or a
//! shard's state), which `geosens/__init__.py` turns into Python objects;
//! every bad input raises `ValueError` with the library's message, the one
//! the command line prints after `error: `. The GIL is released while
//! sampling, and Ctrl-C stops a run (`KeyboardInterrupt`), as does the
//! caller's `stop` (a run on another thread than Python's main one, which
//! alone sees signals).
use geosens::image::ImageResult;
use geosens::job::{ImageReport, Job, RenderJob, SceneSource, Target};
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
        let (tx, rx) = mpsc::channel();
        // The stack of a main thread: a run on one thread runs here.
        let worker = std::thread::Builder::new()
            .stack_size(8 << 20)
            .spawn_scoped(s, move || {
                let out = work(hook);
                let _ = tx.send(());
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
            if waited != Err(mpsc::RecvTimeoutError::Timeout) {
                break;
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
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
