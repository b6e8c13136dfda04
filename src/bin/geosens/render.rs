//! `geosens render`: every pixel of a camera scene's image, for `I` and for
//! every parameter's sensitivity, with their standard-error images; float
//! images (OpenEXR, `.npy`), PNGs (a perceptual map for `I` and the error
//! images, a diverging map centred on 0 for each sensitivity, a colour bar
//! with the scale under the image, the scale in the PNG's text too), and one JSON line whose means are the images' mean
//! pixel values. The files are written as one set (`file_set`): fixed
//! names, so a rerun replaces them, and a failure leaves none of its own.
use super::*;
use geosens::file_set::FileSet;
use geosens::image::{ImageResult, render};
use geosens::image_io::{
    Plane, add_exr, add_npy, add_png_diverging, add_png_magnitude, robust_scale,
};
use geosens::job::SceneSource;
use geosens::job::{ImageReport, RenderJob};
use std::path::{Path, PathBuf};

/// `geosens render`: a camera scene, a method, paths per pixel, and where
/// the result goes: a folder of images (`--out`) or, for a shard, a state
/// file (`--state`); one of the two is required.
#[derive(Debug, Args)]
#[command(group = clap::ArgGroup::new("output").required(true).args(["out", "state"]))]
pub(super) struct RenderArgs {
    /// Scene file (3D, or flatland for a line camera) with `[sensor] kind =
    /// "camera"`.
    #[arg(long)]
    scene: PathBuf,
    /// Estimation method: the images of `I` and of every `∂I/∂π` (each
    /// pixel's estimate, its standard error beside it).
    #[arg(long, value_enum)]
    method: Method,
    /// Paths per pixel, at least 2.
    #[arg(long, default_value_t = 64, allow_hyphen_values = true)]
    spp: u64,
    /// Folder the images go to (created if missing): `I`, `d_<parameter>`
    /// and their `_stderr` images as EXR, .npy and PNG.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Half step of `--method fd`, used at every pixel: times the scene's
    /// size for a translation, radians for a rotation, the relative change
    /// for a scale; in [1e-12, 1) [default: 0.001]. A larger step: less
    /// noise in the images, a bias of O(step²).
    #[arg(long, allow_hyphen_values = true)]
    fd_step: Option<f64>,
    /// Seed of the random streams.
    #[arg(long, default_value_t = 1, allow_hyphen_values = true)]
    seed: u64,
    /// Worker threads, 0 = all cores (images do not depend on it).
    #[arg(long, default_value_t = 0, allow_hyphen_values = true)]
    threads: usize,
    /// Render only shard I of N of the image (1 ≤ I ≤ N): its pixels, row
    /// by row from the top, split into N shares of nearly equal counts,
    /// each pixel with all `--spp` paths; needs `--state`.
    #[arg(long, value_name = "I/N", requires = "state")]
    shard: Option<Shard>,
    /// Instead of images, write the shard's exact state (its pixels' sums)
    /// to FILE (JSON); `geosens merge --out DIR FILE…` writes the images
    /// from all the shards' states. Without `--shard`, the whole image is
    /// one shard (1/1).
    #[arg(long, value_name = "FILE")]
    state: Option<PathBuf>,
}

/// A parameter name as a file name: letters, digits, `-` and `_` kept,
/// anything else `_`.
fn file_name(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The image of `size` (width, height) holding `data`.
fn image_plane(size: (usize, usize), data: &[f64]) -> Plane<'_> {
    Plane {
        width: size.0,
        height: size.1,
        data,
    }
}

/// Writes the images of `result` into `dir` as one set; returns the files
/// written. A failure leaves none of them (nor a temporary), and a folder
/// it made is removed again.
fn write_images(result: &ImageResult, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let made = super::output::missing_folders(dir);
    let written = std::fs::create_dir_all(dir)
        .map_err(|e| Error::Output(format!("cannot create {}: {e}", dir.display())))
        .and_then(|()| write_image_set(result, dir));
    if written.is_err() {
        super::output::remove_empty(&made);
    }
    written
}

/// The files of [`write_images`], written into the existing folder `dir`.
fn write_image_set(result: &ImageResult, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let size = (result.width as usize, result.height as usize);
    let mut set = FileSet::new();
    for (q, img) in &result.images {
        let stem = match q {
            Quantity::Intensity => "I".to_owned(),
            Quantity::Sensitivity(p) => format!("d_{}", file_name(p)),
            Quantity::Gradient(a) => format!("grad_{}", file_name(a)),
        };
        let mean: Vec<f64> = img.iter().map(|e| e.mean).collect();
        let stderr: Vec<f64> = img.iter().map(|e| e.stderr).collect();
        for (name, data) in [(stem.clone(), &mean), (format!("{stem}_stderr"), &stderr)] {
            let plane = image_plane(size, data);
            add_exr(&mut set, &dir.join(format!("{name}.exr")), &plane)?;
            add_npy(&mut set, &dir.join(format!("{name}.npy")), &plane)?;
            // The sensitivity on a diverging map (±scale), I and the error
            // images on a perceptual one (0 to scale); the scale in the
            // PNG's colour bar and text, not its name, so that a rerun
            // replaces it.
            let png = dir.join(format!("{name}.png"));
            let scale = robust_scale(data);
            if name == stem && !matches!(q, Quantity::Intensity) {
                add_png_diverging(&mut set, &png, &plane, scale)?;
            } else {
                add_png_magnitude(&mut set, &png, &plane, scale)?;
            }
        }
    }
    set.commit()
}

/// `geosens render`.
pub(super) fn render_command(
    args: &RenderArgs,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    geosens::runner::check_threads(args.threads)?;
    let job = RenderJob {
        scene: SceneSource::File(args.scene.clone()),
        method: args.method,
        fd_step: args.fd_step,
    };
    if let Some(path) = &args.state {
        super::output::writable_file(path)?;
        let which = args.shard.unwrap_or(Shard::WHOLE);
        let state = job.run_shard(
            args.spp,
            args.seed,
            args.threads,
            which,
            &geosens::runner::quiet,
        )?;
        state.write(path)?;
        eprint!(
            "{}",
            super::output::paragraph(&format!(
                "wrote shard {which} ({} paths) to {}",
                state.paths,
                path.display()
            ))
        );
        return Ok(());
    }
    // clap requires one of --out and --state.
    let Some(dir) = args.out.as_deref() else {
        return Err(Error::Config("--out DIR says where the images go".into()).into());
    };
    let (estimator, _) = job.prepare()?;
    // The folders made for the images go again if the run fails.
    let made = super::output::missing_folders(dir);
    let rendered = render_into(args, estimator.as_ref(), dir, out);
    if rendered.is_err() {
        super::output::remove_empty(&made);
    }
    rendered
}

/// Renders `estimator`'s image as `args` says and writes it into `dir`.
fn render_into(
    args: &RenderArgs,
    estimator: &dyn geosens::estimator::Estimator,
    dir: &Path,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    super::output::writable_dir(dir)?;
    let pixels = estimator
        .image()
        .map_or(0, |(w, h)| u64::from(w) * u64::from(h));
    let bar =
        super::output::progress_bar(pixels, "pixels", format!("render {}", estimator.method()));
    let result = render(
        estimator,
        args.spp,
        args.seed,
        args.threads,
        &super::output::shown(&bar),
    );
    bar.finish_and_clear();
    let report = ImageReport {
        result: result?,
        caveats: estimator.caveats(),
    };
    finish(&report, dir, out)
}

/// Writes the images of `report` into `dir` and prints its warnings, what
/// was written (stderr) and its JSON line (`out`): the end of `geosens
/// render`, and of `geosens merge` on a rendering's states.
pub(super) fn finish(
    report: &ImageReport,
    dir: &Path,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let text = report.json()? + "\n";
    for w in report.warnings() {
        eprint!("{}", super::output::paragraph(&w));
    }
    let result = &report.result;
    let written = write_images(result, dir)?;
    eprint!(
        "{}",
        super::output::paragraph(&format!(
            "wrote {} files to {} ({}×{} pixels, {} paths per pixel, {:.2} s)",
            written.len(),
            dir.display(),
            result.width,
            result.height,
            result.spp,
            result.seconds
        ))
    );
    out.write_all(text.as_bytes())?;
    Ok(())
}
