//! A parameter may not be named like another quantity of the output: `x`,
//! `y` (3D: also `z`), the axes of transport's sensor gradient, whose
//! `∂I/∂x` row it would print twice (a flatland occluder's translation
//! named `x` printed `∂I/∂x = −0.941` and, four rows down, the gradient's
//! `∂I/∂x = 0.577`), and `I`, the intensity, whose image in a rendering's
//! Python result it replaced. Refused by the library and so by the command
//! line, with the clash named; other names, flatland's `z` among them,
//! still load.
use std::path::Path;
use std::process::Command;

fn shipped(name: &str) -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(name),
    )
    .unwrap()
}

/// The shipped scene `file` with its parameter `from` renamed `to`.
fn renamed(file: &str, from: &str, to: &str) -> String {
    let text = shipped(file);
    let old = format!("name = \"{from}\"");
    assert!(text.contains(&old), "{file} has no parameter {from}");
    text.replace(&old, &format!("name = \"{to}\""))
}

fn axis_message(name: &str, shape: &str) -> String {
    format!(
        "parameter \"{name}\" has the name of an axis of the sensor gradient: its ∂I/∂{name} \
         could not be told from the gradient's; rename it (for example \"{shape}_{name}\")"
    )
}

const INTENSITY: &str = "parameter \"I\" has the name of the intensity: a rendering's images \
                         of the two would share the key \"I\"";

#[test]
fn flatland_refuses_the_gradient_axes_and_the_intensity_as_names() {
    for axis in ["x", "y"] {
        let text = renamed("occluder.toml", "occluder_tx", axis);
        let err = geosens::flat::file::from_toml(&text)
            .unwrap_err()
            .to_string();
        assert!(err.ends_with(&axis_message(axis, "occluder")), "{err}");
    }
    let text = renamed("camera_line.toml", "tx", "I");
    let err = geosens::flat::file::from_toml(&text)
        .unwrap_err()
        .to_string();
    assert!(err.contains(INTENSITY), "{err}");
    // Flatland's gradient has no z: the name is free.
    let text = renamed("occluder.toml", "occluder_tx", "z");
    assert!(geosens::flat::file::from_toml(&text).is_ok());
}

#[test]
fn three_dimensions_refuse_the_gradient_axes_and_the_intensity_as_names() {
    for axis in ["x", "y", "z"] {
        let text = renamed("mesh/triangle.toml", "tri_tx", axis);
        let err = geosens::mesh::file::from_toml(&text)
            .unwrap_err()
            .to_string();
        assert!(err.ends_with(&axis_message(axis, "tri")), "{err}");
    }
    let text = renamed("mesh/triangle.toml", "tri_rot", "I");
    let err = geosens::mesh::file::from_toml(&text)
        .unwrap_err()
        .to_string();
    assert!(err.contains(INTENSITY), "{err}");
}

#[test]
fn the_command_line_names_the_clash() {
    let dir = std::env::temp_dir().join(format!("geosens-param-names-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (command, file, from, shape) in [
        ("flat", "occluder.toml", "occluder_tx", "occluder"),
        ("mesh", "mesh/triangle.toml", "tri_tx", "tri"),
    ] {
        let path = dir.join(format!("{command}.toml"));
        std::fs::write(&path, renamed(file, from, "x")).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_geosens"))
            .args([command, "--scene", path.to_str().unwrap()])
            .args(["--method", "transport", "--paths", "1000"])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{command}: {stderr}");
        assert!(out.stdout.is_empty(), "{command} printed a table");
        assert_eq!(
            stderr.trim_end(),
            format!(
                "error: invalid scene: {}: {}",
                path.display(),
                axis_message("x", shape)
            )
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
