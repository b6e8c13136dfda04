//! `geosens render`: every pixel of a camera scene's image, for `I` and for
//! every parameter's sensitivity, with their standard-error images; float
//! images (OpenEXR, `.npy`), PNGs (a perceptual map for `I` and the error
//! images, a diverging map centred on 0 for each sensitivity, the scale in
//! the file name), and one JSON line whose means are the images' mean
//! pixel values.
use super::*;
use geosens::image::{ImageResult, render};
use geosens::image_io::{
    Plane, robust_scale, scale_tag, write_exr, write_npy, write_png_diverging, write_png_magnitude,
};
use geosens::job::SceneSource;
use geosens::job::{ImageReport, RenderJob};
use std::path::{Path, PathBuf};

/// `geosens render`: a camera scene, a method, paths per pixel, a folder.
#[derive(Debug, Args)]
pub(super) struct RenderArgs {
    /// Scene file (3D, or flatland for a line camera) with `[sensor] kind =
    /// "camera"`.
    #[arg(long)]
    scene: PathBuf,
    /// Estimation method.
    #[arg(long, value_enum)]
    method: Method,
    /// Paths per pixel, at least 2.
    #[arg(long, default_value_t = 64, allow_hyphen_values = true)]
    spp: u64,
    /// Folder the images go to (created if missing); not with `--state`.
    #[arg(long, required_unless_present = "state")]
    out: Option<PathBuf>,
    /// The finite differences' half step.
    #[command(flatten)]
    fd: FdArgs,
    /// Seed of the random streams.
    #[arg(long, default_value_t = 1, allow_hyphen_values = true)]
    seed: u64,
    /// Worker threads, 0 = all cores (images do not depend on it).
    #[arg(long, default_value_t = 0, allow_hyphen_values = true)]
    threads: usize,
    /// Sharding (by pixels of the image).
    #[command(flatten)]
    shard: RenderShardArgs,
}

/// `--shard I/N --state FILE` of `geosens render`: [`ShardArgs`] with the
/// help of a rendering's shards.
#[derive(Debug, Args)]
pub(super) struct RenderShardArgs {
    /// Render only shard I of N of the image (1 ≤ I ≤ N): the image's
    /// pixels, row by row from the top, split into N contiguous shares of
    /// nearly equal counts (so a single row splits too; past one shard per
    /// pixel the others are empty), each with all `--spp` paths of its
    /// pixels; needs `--state`.
    #[arg(long, value_name = "I/N")]
    shard: Option<Shard>,
    /// Write the shard's exact state (its pixels' sums) to FILE (JSON)
    /// instead of images; `geosens merge --out DIR` writes the images from
    /// all states. Without `--shard`, the whole image is one shard (1/1).
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

/// Writes the images of `result` into `dir`; returns the files written.
fn write_images(result: &ImageResult, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::Output(format!("cannot create {}: {e}", dir.display())))?;
    let size = (result.width as usize, result.height as usize);
    let mut written = Vec::new();
    for (q, img) in &result.images {
        let stem = match q {
            Quantity::Intensity => "I".to_owned(),
            Quantity::Sensitivity(p) => format!("d_{}", file_name(p)),
            Quantity::Gradient(a) => format!("grad_{}", file_name(a)),
        };
        let mean: Vec<f64> = img.iter().map(|e| e.mean).collect();
        let stderr: Vec<f64> = img.iter().map(|e| e.stderr).collect();
        for (name, data) in [(stem.clone(), &mean), (format!("{stem}_stderr"), &stderr)] {
            let exr = dir.join(format!("{name}.exr"));
            write_exr(&exr, &image_plane(size, data))?;
            let npy = dir.join(format!("{name}.npy"));
            write_npy(&npy, &image_plane(size, data))?;
            written.extend([exr, npy]);
        }
        // The sensitivity on a diverging map (±scale), I and the error
        // images on a perceptual one (0 to scale); the scale in the name.
        let scale = robust_scale(&mean);
        let main = if matches!(q, Quantity::Intensity) {
            let path = dir.join(format!("{stem}_max{}.png", scale_tag(scale)));
            write_png_magnitude(&path, &image_plane(size, &mean), scale)?;
            path
        } else {
            let path = dir.join(format!("{stem}_pm{}.png", scale_tag(scale)));
            write_png_diverging(&path, &image_plane(size, &mean), scale)?;
            path
        };
        let err_scale = robust_scale(&stderr);
        let err = dir.join(format!("{stem}_stderr_max{}.png", scale_tag(err_scale)));
        write_png_magnitude(&err, &image_plane(size, &stderr), err_scale)?;
        written.extend([main, err]);
    }
    Ok(written)
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
        fd_step: args.fd.fd_step,
    };
    if let Some(path) = &args.shard.state {
        if args.out.is_some() {
            return Err(Error::Config(
                "--state writes the shard's state, not images: `geosens merge --out DIR` writes them"
                    .into(),
            )
            .into());
        }
        super::output::writable_file(path)?;
        let which = args.shard.shard.unwrap_or(Shard::WHOLE);
        let state = job.run_shard(
            args.spp,
            args.seed,
            args.threads,
            which,
            &geosens::runner::quiet,
        )?;
        state.write(path)?;
        eprintln!(
            "wrote shard {which} ({} paths) to {}",
            state.paths,
            path.display()
        );
        return Ok(());
    }
    if let Some(s) = args.shard.shard {
        return Err(Error::Config(format!(
            "--shard {s} needs --state FILE, where the shard's state goes"
        ))
        .into());
    }
    let dir = args.out.as_deref().ok_or("--out DIR is needed")?;
    let (estimator, _) = job.prepare()?;
    super::output::writable_dir(dir)?;
    let pixels = estimator
        .image()
        .map_or(0, |(w, h)| u64::from(w) * u64::from(h));
    let bar =
        super::output::progress_bar(pixels, "pixels", format!("render {}", estimator.method()));
    let result = render(
        estimator.as_ref(),
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
        eprintln!("{w}");
    }
    let result = &report.result;
    let written = write_images(result, dir)?;
    eprintln!(
        "wrote {} files to {} ({}×{} pixels, {} paths per pixel, {:.2} s)",
        written.len(),
        dir.display(),
        result.width,
        result.height,
        result.spp,
        result.seconds
    );
    out.write_all(text.as_bytes())?;
    Ok(())
}
