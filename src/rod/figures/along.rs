//! Intensity and sensitivity along the rod, over the exact curves (the
//! paper's Figs. 5 and 6a–d).
use super::{FigureOptions, exact_value, positions, thick, thin};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::plot::{Figure, Mark, Panel, Series};
use crate::rod::{Direction, Method, PARAMETER, Rod};
use serde::Serialize;
use std::path::PathBuf;

/// Paths per point of the along-the-rod figures (times the effort).
pub const PATHS: u64 = 100_000;

/// The directions, their labels and palette indices, in the panels' order.
const DIRECTIONS: [(Direction, &str, usize); 2] = [
    (Direction::Right, "ω = +1", 0),
    (Direction::Left, "ω = −1", 1),
];

/// The rods, in the panels' order.
fn rods() -> [(Rod, &'static str); 2] {
    [(thin(), "thin"), (thick(), "thick")]
}

/// The legend entries of every panel (one legend for the figure): the exact
/// curve and the estimates of each direction.
fn legend() -> Vec<Series> {
    DIRECTIONS
        .iter()
        .flat_map(|&(_, label, color)| {
            [
                Series::line(&format!("exact, {label}"), color, vec![]),
                Series::points(&format!("estimate ± σ, {label}"), color, vec![]),
            ]
        })
        .collect()
}

/// One panel: `method`'s estimates of `q` at 21 positions in direction `k`
/// of [`DIRECTIONS`] (one direction a panel, each on its own y axis: the
/// two differ by a factor 15 on the thin rod), over the exact curve.
fn panel(
    opts: &FigureOptions,
    (rod, name): (Rod, &str),
    method: Method,
    q: &Quantity,
    k: usize,
    salt: u64,
) -> Result<Panel, Error> {
    let (omega, label, color) = DIRECTIONS[k];
    let xs = positions(&rod, 21);
    let fine = positions(&rod, 201);
    let exact = fine
        .iter()
        .map(|&x| (x, exact_value(&rod, x, omega, q)))
        .collect();
    let mut points = Vec::with_capacity(xs.len());
    for (i, &x) in xs.iter().enumerate() {
        let r = opts.run(
            method,
            rod,
            x,
            omega,
            PATHS,
            salt + 1000 * k as u64 + i as u64,
        )?;
        let e = r
            .get(q)
            .ok_or_else(|| Error::Output(format!("{} does not estimate {q}", method.name())))?;
        points.push((x, e.mean, e.stderr));
    }
    Ok(Panel {
        title: format!("{name} rod (κs = {}, κe = {}), {label}", rod.ks, rod.ke),
        x_label: "x".into(),
        y_label: format!("{q} by {}", method.name()),
        series: vec![
            Series::line("", color, exact),
            Series::points(&format!("{}, {label}", method.name()), color, points),
        ],
        ..Panel::default()
    })
}

/// The panels of one row: `method`'s `q` on both rods, both directions,
/// seeds from `salt` on per rod (`salt_of(i)` for rod `i`).
fn row(
    opts: &FigureOptions,
    method: Method,
    q: &Quantity,
    salt_of: impl Fn(usize) -> u64,
) -> Result<Vec<Panel>, Error> {
    let mut panels = Vec::new();
    for (i, rod) in rods().into_iter().enumerate() {
        for k in 0..DIRECTIONS.len() {
            panels.push(panel(opts, rod, method, q, k, salt_of(i))?);
        }
    }
    Ok(panels)
}

/// `(x, mean, σ)` of one point.
type Estimated = (f64, f64, f64);

/// The estimates behind one panel: its title and `(x, mean, σ)` per series.
#[derive(Debug, Serialize)]
struct PanelNumbers<'a> {
    title: &'a str,
    series: Vec<(&'a str, &'a [Estimated])>,
}

/// Writes the figure, `columns` panels a row (PNG, SVG), and the estimates
/// it plots (JSON).
fn save_with_numbers(
    opts: &FigureOptions,
    mut panels: Vec<Panel>,
    columns: usize,
    name: &str,
) -> Result<Vec<PathBuf>, Error> {
    let numbers: Vec<PanelNumbers> = panels
        .iter()
        .map(|p| PanelNumbers {
            title: &p.title,
            series: p
                .series
                .iter()
                .filter_map(|s| match &s.mark {
                    Mark::Points(v) => Some((s.label.as_str(), v.as_slice())),
                    _ => None,
                })
                .collect(),
        })
        .collect();
    let json = opts.write_json(name, &numbers)?;
    // The labels name the JSON's series; the figure's one legend says it.
    for s in panels.iter_mut().flat_map(|p| &mut p.series) {
        s.label.clear();
    }
    let mut figure = Figure::new(panels, columns);
    figure.legend = legend();
    figure.panel_size = (470, 360);
    let mut written = figure.save(&opts.out, name)?;
    written.push(json);
    Ok(written)
}

/// Fig. 5: right- and left-going intensity against x with ±σ error bars,
/// thin and thick rods, one panel per rod and direction. Writes
/// `intensity_along_rod.{png,svg}`.
pub fn intensity_along_rod(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let bar = opts.bar(1, "intensity along the rod");
    let panels = row(opts, Method::Intensity, &Quantity::Intensity, |i| {
        100_000 * i as u64
    })?;
    bar.inc(1);
    bar.finish();
    // One rod a row: a strip of four would be too flat at the book's width.
    save_with_numbers(opts, panels, DIRECTIONS.len(), "intensity_along_rod")
}

/// Fig. 6a–d: s against x for rendering, expectation and transport, and
/// ∂xI from transport, each over the exact curves, thin and thick rods,
/// one panel per rod and direction. Writes
/// `sensitivity_along_rod.{png,svg}`.
pub fn sensitivity_along_rod(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let s = Quantity::sensitivity(PARAMETER);
    let g = Quantity::gradient("x");
    let rows = [
        (Method::Rendering, &s),
        (Method::Expectation, &s),
        (Method::Transport, &s),
        (Method::Transport, &g),
    ];
    let bar = opts.bar(rows.len() as u64, "sensitivity along the rod");
    let mut panels = Vec::new();
    for (r, (method, q)) in rows.into_iter().enumerate() {
        let salt_of = |i: usize| 200_000 + 100_000 * (2 * r + i) as u64;
        panels.extend(row(opts, method, q, salt_of)?);
        bar.inc(1);
    }
    bar.finish();
    save_with_numbers(opts, panels, 2 * DIRECTIONS.len(), "sensitivity_along_rod")
}
