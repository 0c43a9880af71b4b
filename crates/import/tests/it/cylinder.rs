//! The `cylinder` shape, an extension to scene format 1 (`docs/scene-format-extensions.md`):
//! every key, the defaults, and every rejected value.

use std::f32::consts::{PI, TAU};
use std::path::Path;

use glam::Vec3;
use import::{LoadError, load, load_toml_str};
use scene::{Primitive, Ray, Scene};

use crate::{assert_names_file, fixture};

const HEAD: &str = r#"format = 1

[camera]
position = [0.0, 1.0, 3.9]
look_at = [0.0, 0.2, 0.0]
fov_y = 39.3

[materials.silver]
type = "mirror"
reflectance = [0.95, 0.95, 0.95]

[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]

[[lights]]
type = "directional"
direction = [0.0, -0.3, -1.0]
irradiance = [3.0, 3.0, 3.0]
"#;

/// The head plus one `[[shapes]]` table with the given body.
fn scene(shape: &str) -> String {
    format!("{HEAD}\n[[shapes]]\n{shape}")
}

fn load_shape(shape: &str) -> Result<scene::SceneDescription, LoadError> {
    load_toml_str(&scene(shape), Path::new("scenes/cylinder.toml"))
}

#[track_caller]
fn assert_close(a: Vec3, b: Vec3) {
    assert!(a.distance(b) < 1e-6, "{a} vs {b}");
}

#[test]
fn every_key() {
    let d = load_shape(
        r#"type     = "cylinder"
center   = [1.0, 2.0, 3.0]
axis     = [0.0, 0.0, 2.0]
radius   = 0.5
height   = 0.35
arc      = 180.0
facing   = [0.0, 1.0, 5.0]
material = "silver"
"#,
    )
    .unwrap();
    assert!(d.triangles.is_empty() && d.spheres.is_empty());
    let [c] = d.cylinders[..] else {
        panic!("{:?}", d.cylinders)
    };
    assert_close(c.center, Vec3::new(1.0, 2.0, 3.0));
    assert_close(c.axis, Vec3::Z); // normalised
    assert_eq!(c.radius, 0.5);
    assert_eq!(c.height, 0.35);
    assert!((c.arc - PI).abs() < 1e-6);
    assert_close(c.facing, Vec3::Y); // projected perpendicular to the axis, normalised
    assert_eq!(d.materials[c.material as usize].name, "silver");
    let summary = d.summary();
    assert_eq!(summary.cylinders, 1);
    let silver = summary
        .materials
        .iter()
        .find(|m| m.name == "silver")
        .unwrap();
    assert_eq!(silver.cylinders, 1);
    assert!(summary.to_string().contains("1 cylinders"), "{summary}");
    let b = summary.bounds.unwrap();
    assert_close(b.min, Vec3::new(0.5, 1.5, 3.0));
    assert_close(b.max, Vec3::new(1.5, 2.5, 3.35));
}

#[test]
fn defaults() {
    let d = load_shape(
        r#"type = "cylinder"
center = [0.0, 0.0, 0.0]
radius = 0.5
height = 0.35
material = "silver"
"#,
    )
    .unwrap();
    let c = d.cylinders[0];
    assert_eq!(c.axis, Vec3::Y);
    assert_eq!(c.arc, TAU);
    assert_close(c.facing, Vec3::Z);
    // Along z the default facing is +x.
    let d = load_shape(
        r#"type = "cylinder"
center = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, -1.0]
radius = 0.5
height = 0.35
material = "silver"
"#,
    )
    .unwrap();
    assert_close(d.cylinders[0].facing, Vec3::X);
    // A whole circle is exactly 2π.
    let d = load_shape(
        r#"type = "cylinder"
center = [0.0, 0.0, 0.0]
radius = 0.5
height = 0.35
arc = 360.0
material = "silver"
"#,
    )
    .unwrap();
    assert_eq!(d.cylinders[0].arc, TAU);
}

/// The seed paper's Figure 1 set-up: a mirror half-ring on a floor, rendered from a file.
#[test]
fn half_ring_scene_renders_rays() {
    let text = format!(
        "{HEAD}
[materials.floor]
type = \"diffuse\"
albedo = [0.8, 0.8, 0.8]

[[shapes]]
type = \"quad\"
corner = [-1.0, 0.0, 1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -2.0]
material = \"floor\"

[[shapes]]
type = \"cylinder\"
center = [0.0, 0.0, 0.0]
radius = 0.5
height = 0.35
arc = 180.0
facing = [0.0, 0.0, -1.0]
material = \"silver\"
"
    );
    let path = fixture("cylinder_half_ring", &[("ring.toml", &text)]);
    let scene = Scene::new(load(&path).unwrap()).unwrap();
    assert_eq!(scene.primitive_count(), 3);
    // Looking from the open side at the inside of the back wall.
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(0.0, 0.2, 2.0), -Vec3::Z))
        .unwrap();
    assert_eq!(h.primitive, Primitive::Cylinder(0));
    assert!(!h.front_face);
    assert!((h.position.z + 0.5).abs() < 1e-5);
    assert!((h.curvature - 2.0).abs() < 1e-5); // +1/R, concave across the axis
}

#[track_caller]
fn assert_invalid(shape: &str, key: &str) {
    let err = load_shape(shape).unwrap_err();
    assert_names_file(&err, Path::new("scenes/cylinder.toml"));
    match &err {
        LoadError::InvalidValue { key: k, .. } => {
            assert_eq!(k, &format!("[[shapes]] #1 {key}"), "{err}");
        }
        _ => panic!("expected InvalidValue for {key}, got {err:?}"),
    }
}

#[test]
fn invalid_values() {
    let base = r#"type = "cylinder"
center = [0.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
radius = 0.5
height = 0.35
arc = 180.0
facing = [0.0, 0.0, -1.0]
material = "silver"
"#;
    assert!(load_shape(base).is_ok());
    let edit = |from: &str, to: &str| {
        assert!(base.contains(from), "{from}");
        base.replacen(from, to, 1)
    };
    for (from, to, key) in [
        ("radius = 0.5", "radius = 0.0", "radius"),
        ("radius = 0.5", "radius = -0.5", "radius"),
        ("radius = 0.5", "radius = nan", "radius"),
        ("radius = 0.5", "radius = inf", "radius"),
        ("height = 0.35", "height = 0.0", "height"),
        ("height = 0.35", "height = -1.0", "height"),
        ("axis = [0.0, 1.0, 0.0]", "axis = [0.0, 0.0, 0.0]", "axis"),
        ("axis = [0.0, 1.0, 0.0]", "axis = [0.0, nan, 0.0]", "axis"),
        (
            "center = [0.0, 0.0, 0.0]",
            "center = [inf, 0.0, 0.0]",
            "center",
        ),
        ("arc = 180.0", "arc = 0.0", "arc"),
        ("arc = 180.0", "arc = -90.0", "arc"),
        ("arc = 180.0", "arc = 360.5", "arc"),
        ("arc = 180.0", "arc = nan", "arc"),
        (
            "facing = [0.0, 0.0, -1.0]",
            "facing = [0.0, -3.0, 0.0]",
            "facing",
        ),
        (
            "facing = [0.0, 0.0, -1.0]",
            "facing = [0.0, 0.0, 0.0]",
            "facing",
        ),
        ("material = \"silver\"", "material = \"lamp\"", "material"),
    ] {
        assert_invalid(&edit(from, to), key);
    }
    let err = load_shape(&edit("material = \"silver\"", "material = \"lamp\"")).unwrap_err();
    assert!(err.to_string().contains("cannot emit"), "{err}");
}

#[test]
fn schema_errors() {
    let err = load_shape(
        r#"type = "cylinder"
center = [0.0, 0.0, 0.0]
radius = 0.5
height = 0.35
caps = true
material = "silver"
"#,
    )
    .unwrap_err();
    match &err {
        LoadError::UnknownKey { key, expected, .. } => {
            assert_eq!(key, "caps");
            for k in [
                "type", "center", "axis", "radius", "height", "arc", "facing", "material",
            ] {
                assert!(expected.split(", ").any(|e| e == k), "{expected}");
            }
        }
        _ => panic!("{err:?}"),
    }
    let err = load_shape(
        r#"type = "cylinder"
center = [0.0, 0.0, 0.0]
radius = 0.5
material = "silver"
"#,
    )
    .unwrap_err();
    assert!(
        matches!(&err, LoadError::MissingKey { key, .. } if key == "height"),
        "{err:?}"
    );
    let err = load_shape(
        r#"type = "cylinder"
center = [0.0, 0.0, 0.0]
radius = 0.5
height = 0.35
material = "gold"
"#,
    )
    .unwrap_err();
    assert!(matches!(err, LoadError::UnknownMaterial { .. }), "{err:?}");
}
