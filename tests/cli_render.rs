//! `geosens render`: its JSON line, the files it writes (EXR, .npy, PNG,
//! error images) and what they hold, bit-identical images for any thread
//! count, and clear errors.
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn geosens(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_geosens"))
        .args(args)
        .output()
        .expect("the geosens binary runs")
}

fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/mesh")
        .join(name)
        .to_str()
        .unwrap()
        .to_owned()
}

fn scratch(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("geosens-cli-render-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn render(method: &str, dir: &Path, extra: &[&str]) -> Value {
    let s = scene("camera_shadow.toml");
    let d = dir.to_str().unwrap();
    let mut args = vec![
        "render", "--scene", &s, "--method", method, "--spp", "32", "--out", d,
    ];
    args.extend_from_slice(extra);
    let out = geosens(&args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{method} failed: {stderr}");
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.lines().count(), 1, "not one line: {stdout}");
    serde_json::from_str(&stdout).unwrap()
}

/// The `.npy` file's float64 values (the header parsed as numpy writes it).
fn npy(path: &Path) -> (Vec<usize>, Vec<f64>) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert!(header.contains("'descr': '<f8'"), "{header}");
    let shape = header
        .split("'shape': (")
        .nth(1)
        .unwrap()
        .split(')')
        .next()
        .unwrap();
    let shape: Vec<usize> = shape
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let data = bytes[10 + header_len..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    (shape, data)
}

#[test]
fn render_writes_every_image_and_its_mean() {
    let dir = scratch("rendering");
    let line = render("rendering", &dir, &[]);
    assert_eq!(line["method"], "rendering");
    assert_eq!(
        (line["width"].as_u64(), line["height"].as_u64()),
        (Some(32), Some(32))
    );
    assert_eq!(line["paths"].as_u64(), Some(32 * 32 * 32));
    assert!(line["seconds"].as_f64().unwrap() > 0.0);
    let names = ["tri_tx", "tri_tz", "tri_rot"];
    let files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    for stem in ["I".to_owned()]
        .into_iter()
        .chain(names.iter().map(|n| format!("d_{n}")))
    {
        for f in [
            format!("{stem}.exr"),
            format!("{stem}.npy"),
            format!("{stem}_stderr.exr"),
            format!("{stem}_stderr.npy"),
        ] {
            assert!(files.contains(&f), "{f} missing in {files:?}");
        }
        let pngs = files
            .iter()
            .filter(|f| f.starts_with(&stem) && f.ends_with(".png"))
            .count();
        assert_eq!(pngs, 2, "{stem}: one image and one error PNG");
        // The JSON mean is the image's mean pixel value, its error bar
        // that of a mean of independent pixels.
        let (shape, img) = npy(&dir.join(format!("{stem}.npy")));
        let (_, err) = npy(&dir.join(format!("{stem}_stderr.npy")));
        assert_eq!(shape, vec![32, 32]);
        let mean = img.iter().sum::<f64>() / img.len() as f64;
        let se = err.iter().map(|e| e * e).sum::<f64>().sqrt() / err.len() as f64;
        let entry = if stem == "I" {
            &line["I"]
        } else {
            &line["sensitivity"][&stem[2..]]
        };
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (a.abs() + b.abs());
        assert!(
            close(entry["mean"].as_f64().unwrap(), mean),
            "{stem}: {entry} vs {mean}"
        );
        assert!(
            close(entry["stderr"].as_f64().unwrap(), se),
            "{stem}: {entry} vs {se}"
        );
    }
    for png in [
        "I.png",
        "I_stderr.png",
        "d_tri_tx.png",
        "d_tri_tx_stderr.png",
    ] {
        assert!(
            files.contains(&png.to_owned()),
            "{png} missing in {files:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn images_do_not_depend_on_the_thread_count() {
    let (a, b) = (scratch("t1"), scratch("t2"));
    let one = render("expectation", &a, &["--threads", "1", "--seed", "9"]);
    let two = render("expectation", &b, &["--threads", "2", "--seed", "9"]);
    assert_eq!(one["I"], two["I"]);
    assert_eq!(one["sensitivity"], two["sensitivity"]);
    for f in ["I.npy", "d_tri_tx.npy", "d_tri_rot_stderr.npy"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
    let _ = std::fs::remove_dir_all(&a);
    let _ = std::fs::remove_dir_all(&b);
}

#[test]
fn bad_requests_are_refused_with_a_message() {
    let dir = scratch("bad");
    let d = dir.to_str().unwrap();
    let probe = scene("triangle.toml");
    let camera = scene("camera_shadow.toml");
    for (args, says) in [
        (
            vec![
                "render",
                "--scene",
                &probe,
                "--method",
                "rendering",
                "--out",
                d,
            ],
            "not a camera",
        ),
        (
            vec![
                "render",
                "--scene",
                &camera,
                "--method",
                "rendering",
                "--spp",
                "1",
                "--out",
                d,
            ],
            "spp",
        ),
        (
            vec!["mesh", "--scene", &camera, "--method", "intensity"],
            "geosens render",
        ),
    ] {
        let out = geosens(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
    // Cameras that cannot be: each named.
    let text = std::fs::read_to_string(&camera).unwrap();
    for (from, to, says) in [
        ("fov_deg = 90.0", "fov_deg = 180.0", "fov_deg"),
        // Pixels so narrow that their directions round to one another.
        ("fov_deg = 90.0", "fov_deg = 1e-13", "a pixel spans"),
        ("width = 32", "width = 0", "width"),
        ("up = [0.0, 1.0, 0.0]", "up = [0.0, 0.0, 1.0]", "up"),
        ("width = 32", "width = 32\nzoom = 2", "zoom"),
    ] {
        assert!(text.contains(from), "{from}");
        let bad = std::env::temp_dir().join(format!(
            "geosens-cli-render-{}-{says}.toml",
            std::process::id()
        ));
        std::fs::write(&bad, text.replace(from, to)).unwrap();
        let b = bad.to_str().unwrap();
        let out = geosens(&["render", "--scene", b, "--method", "intensity", "--out", d]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{to}: {stderr}");
        assert!(stderr.contains(says), "{to}: {stderr}");
        let _ = std::fs::remove_file(&bad);
    }
    // A file where the folder should be.
    let file = std::env::temp_dir().join(format!("geosens-cli-render-{}-file", std::process::id()));
    std::fs::write(&file, b"x").unwrap();
    let f = file.to_str().unwrap();
    let out = geosens(&[
        "render",
        "--scene",
        &camera,
        "--method",
        "intensity",
        "--out",
        f,
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(f), "{stderr}");
    let _ = std::fs::remove_file(&file);
}

/// A flatland scene with a line camera renders through the same command: a
/// row of pixels.
#[test]
fn flatland_line_cameras_render_a_row() {
    let dir = scratch("flat");
    let s = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/camera_line.toml")
        .to_str()
        .unwrap()
        .to_owned();
    let d = dir.to_str().unwrap();
    let out = geosens(&[
        "render",
        "--scene",
        &s,
        "--method",
        "transport",
        "--spp",
        "64",
        "--out",
        d,
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let line: Value = serde_json::from_str(&String::from_utf8(out.stdout).unwrap()).unwrap();
    assert_eq!(
        (line["width"].as_u64(), line["height"].as_u64()),
        (Some(40), Some(1))
    );
    assert!(line["sensitivity"]["tx"]["mean"].is_f64());
    let (shape, _) = npy(&dir.join("d_rot.npy"));
    assert_eq!(shape, vec![1, 40]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Pixels the EXR files' 32-bit floats cannot hold are said on stderr (a
/// lamp of radiance 10⁻⁴⁵ wrote EXR images of zeros without a word); the
/// .npy files keep the doubles.
#[test]
fn pixels_beyond_the_exr_range_are_a_warning() {
    let text = std::fs::read_to_string(scene("camera_shadow.toml")).unwrap();
    assert!(text.contains("radiance = 1.0"));
    let dir = scratch("exr-range");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("faint.toml");
    std::fs::write(&path, text.replace("radiance = 1.0", "radiance = 1e-45")).unwrap();
    let out = dir.join("out");
    let args = [
        "render",
        "--scene",
        path.to_str().unwrap(),
        "--method",
        "rendering",
        "--spp",
        "4",
        "--out",
        out.to_str().unwrap(),
    ];
    let o = geosens(&args);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    // Warnings are wrapped at 100 characters.
    let words = stderr.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(words.contains("32-bit range of the EXR files"), "{stderr}");
    let (_, intensity) = npy(&out.join("I.npy"));
    assert!(intensity.iter().any(|&x| x > 0.0 && x < 1e-40));
    // At radiance 1 no such warning.
    let plain = scene("camera_shadow.toml");
    let mut args = args;
    args[2] = &plain;
    let o = geosens(&args);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("32-bit"), "{stderr}");
}
