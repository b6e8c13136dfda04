//! The worked 3D inverse problem `scenes/mesh/inverse_triangle.toml`: runs the
//! optimiser by several methods from the file's pose and prints the final
//! parameters and their error against the true pose
//! (`geosens::mesh::inverse::TRIANGLE`).
//!
//! `cargo run --release --example inverse_triangle [-- --iterations N --paths N --step F --seed N --methods a,b]`
#[path = "common/inverse_3d.rs"]
mod common;
use geosens::Method;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = common::Args::parse(
        300,
        16384,
        0.01,
        &[Method::Expectation, Method::Rendering, Method::Transport],
    );
    common::solve(geosens::mesh::inverse::TRIANGLE, &args)
}
