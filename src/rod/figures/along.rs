//! Intensity and sensitivity along the rod, over the exact curves (the
//! paper's Figs. 5 and 6a–d).
use super::{FigureOptions, exact_value, positions, thick, thin};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::plot::{Figure, Legend, Mark, Panel, Series};
use crate::rod::{Direction, Method, PARAMETER, Rod};
use serde::Serialize;
use std::path::PathBuf;

/// Paths per point of the along-the-rod figures (times the effort).
pub const PATHS: u64 = 100_000;

const DIRECTIONS: [(Direction, &str, usize); 2] = [
    (Direction::Right, "ω = +1", 0),
    (Direction::Left, "ω = −1", 1),
];

/// One panel: `method`'s estimates of `q` at 21 positions, both directions,
/// over the exact curves.
fn panel(
    opts: &FigureOptions,
    rod: Rod,
    name: &str,
    method: Method,
    q: &Quantity,
    salt: u64,
) -> Result<Panel, Error> {
    let xs = positions(&rod, 21);
    let fine = positions(&rod, 201);
    let mut series = Vec::new();
    for (k, &(omega, label, color)) in DIRECTIONS.iter().enumerate() {
        let exact = fine
            .iter()
            .map(|&x| (x, exact_value(&rod, x, omega, q)))
            .collect();
        series.push(Series::line(&format!("exact, {label}"), color, exact));
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
        series.push(Series::points(
            &format!("{}, {label}", method.name()),
            color,
            points,
        ));
    }
    Ok(Panel {
        title: format!(
            "{name} rod (κs = {}, κe = {}): {q} by {}",
            rod.ks,
            rod.ke,
            method.name()
        ),
        x_label: "x".into(),
        y_label: q.to_string(),
        series,
        legend: if q == &Quantity::Intensity {
            Legend::UpperRight
        } else {
            Legend::UpperLeft
        },
        ..Panel::default()
    })
}

/// `(x, mean, σ)` of one point.
type Estimated = (f64, f64, f64);

/// The estimates behind one panel: its title and `(x, mean, σ)` per series.
#[derive(Debug, Serialize)]
struct PanelNumbers<'a> {
    title: &'a str,
    series: Vec<(&'a str, &'a [Estimated])>,
}

/// Writes the figure (PNG, SVG) and the estimates it plots (JSON).
fn save_with_numbers(
    opts: &FigureOptions,
    panels: Vec<Panel>,
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
    let mut written = Figure::new(panels, 2).save(&opts.out, name)?;
    written.push(json);
    Ok(written)
}

/// Fig. 5: right- and left-going intensity against x with ±σ error bars,
/// thin and thick rods. Writes `intensity_along_rod.{png,svg}`.
pub fn intensity_along_rod(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let bar = opts.bar(2, "intensity along the rod");
    let mut panels = Vec::new();
    for (i, (rod, name)) in [(thin(), "thin"), (thick(), "thick")]
        .into_iter()
        .enumerate()
    {
        panels.push(panel(
            opts,
            rod,
            name,
            Method::Intensity,
            &Quantity::Intensity,
            100_000 * i as u64,
        )?);
        bar.inc(1);
    }
    bar.finish();
    save_with_numbers(opts, panels, "intensity_along_rod")
}

/// Fig. 6a–d: s against x for rendering, expectation and transport, and
/// ∂xI from transport, each over the exact curves, thin and thick rods.
/// Writes `sensitivity_along_rod.{png,svg}`.
pub fn sensitivity_along_rod(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let s = Quantity::sensitivity(PARAMETER);
    let g = Quantity::gradient("x");
    let rows = [
        (Method::Rendering, &s),
        (Method::Expectation, &s),
        (Method::Transport, &s),
        (Method::Transport, &g),
    ];
    let bar = opts.bar(2 * rows.len() as u64, "sensitivity along the rod");
    let mut panels = Vec::new();
    for (r, (method, q)) in rows.into_iter().enumerate() {
        for (i, (rod, name)) in [(thin(), "thin"), (thick(), "thick")]
            .into_iter()
            .enumerate()
        {
            let salt = 200_000 + 100_000 * (2 * r + i) as u64;
            panels.push(panel(opts, rod, name, method, q, salt)?);
            bar.inc(1);
        }
    }
    bar.finish();
    save_with_numbers(opts, panels, "sensitivity_along_rod")
}
