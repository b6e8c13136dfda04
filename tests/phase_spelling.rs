//! A medium's phase function is spelled `phase = { kind, g }` (flatland's
//! first spelling) or `g` (3D's) in both dimensions' files, with the same
//! meaning; giving both is refused with a message naming them.
use geosens::flat;
use geosens::mesh;

const FLAT: &str = r#"
[sensor]
kind = "irradiance"
point = [0.0, 0.0]
normal = [0.0, 1.0]

[[shapes]]
name = "lamp"
vertices = [[-1.0, 2.0], [1.0, 2.0]]
surface = { kind = "emitter", radiance = 1.0 }

[[shapes]]
name = "fog"
closed = true
vertices = [[-0.5, 0.8], [0.5, 0.8], [0.5, 1.3], [-0.5, 1.3]]
surface = { kind = "transparent" }
MEDIUM
"#;

const MESH: &str = r#"
[sensor]
kind = "irradiance"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[shapes]]
name = "lamp"
vertices = [[-0.5, -0.5, 2.0], [0.5, -0.5, 2.0], [0.5, 0.5, 2.0], [-0.5, 0.5, 2.0]]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = { kind = "emitter", radiance = 1.0 }

[[shapes]]
name = "fog"
vertices = [
    [-0.4, -0.4, 0.6], [0.4, -0.4, 0.6], [-0.4, 0.4, 0.6], [0.4, 0.4, 0.6],
    [-0.4, -0.4, 1.4], [0.4, -0.4, 1.4], [-0.4, 0.4, 1.4], [0.4, 0.4, 1.4],
]
triangles = [
    [0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
    [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5],
]
surface = { kind = "transparent" }
MEDIUM
"#;

fn with(text: &str, medium: &str) -> String {
    text.replace(
        "MEDIUM",
        &format!("medium = {{ ks = 1.0, ke = 1.5{medium} }}"),
    )
}

const TABLE: &str = r#", phase = { kind = "henyey_greenstein", g = 0.3 }"#;
const G: &str = ", g = 0.3";
const ISOTROPIC: &str = r#", phase = { kind = "isotropic" }"#;

#[test]
fn flatland_reads_g_as_the_henyey_greenstein_table() {
    let table = flat::file::from_toml(&with(FLAT, TABLE)).unwrap();
    let g = flat::file::from_toml(&with(FLAT, G)).unwrap();
    let medium = |s: &flat::Scene| s.shapes()[1].medium.unwrap();
    assert_eq!(medium(&table), medium(&g));
    assert_eq!(medium(&g).phase, flat::Phase::HenyeyGreenstein { g: 0.3 });
    // g = 0 and no phase at all are both isotropic.
    let zero = flat::file::from_toml(&with(FLAT, ", g = 0.0")).unwrap();
    let none = flat::file::from_toml(&with(FLAT, "")).unwrap();
    assert_eq!(medium(&zero).phase, flat::Phase::Isotropic);
    assert_eq!(medium(&none).phase, flat::Phase::Isotropic);
}

#[test]
fn three_d_reads_the_table_as_g() {
    let table = mesh::file::from_toml(&with(MESH, TABLE)).unwrap();
    let g = mesh::file::from_toml(&with(MESH, G)).unwrap();
    let iso = mesh::file::from_toml(&with(MESH, ISOTROPIC)).unwrap();
    let medium = |s: &mesh::Scene| s.shapes()[1].medium.unwrap();
    assert_eq!(medium(&table), medium(&g));
    assert_eq!(medium(&g).g, 0.3);
    assert_eq!(medium(&iso).g, 0.0);
}

#[test]
fn both_spellings_at_once_are_refused() {
    let both = format!("{G}{ISOTROPIC}");
    let e = flat::file::from_toml(&with(FLAT, &both))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`phase` or `g`") && e.contains("not both"),
        "{e}"
    );
    let e = mesh::file::from_toml(&with(MESH, &both))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`g` or `phase`") && e.contains("not both"),
        "{e}"
    );
    // A field neither spelling has is still named.
    let e = mesh::file::from_toml(&with(MESH, ", gee = 0.3"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown field `gee`"), "{e}");
}
