//! Rough dielectrics as each format writes them: TOML's `dielectric` with a `roughness`,
//! Mitsuba's `roughdielectric`, pbrt's `dielectric` with a roughness (remapped or not), and the
//! one-line errors of bad values.

use import::{LoadError, load};
use scene::{MaterialKind, RoughDielectric};

use crate::bad_input::BASE as TOML_BASE;
use crate::{assert_names_file, fixture};

/// The kind of the first material called `name`.
fn kind(scene: &scene::SceneDescription, name: &str) -> MaterialKind {
    scene
        .materials
        .iter()
        .find(|m| m.name == name)
        .map(|m| m.kind)
        .unwrap()
}

#[track_caller]
fn assert_error(
    result: Result<scene::SceneDescription, LoadError>,
    file: &std::path::Path,
    fragment: &str,
) {
    let err = result.unwrap_err();
    assert_names_file(&err, file);
    assert!(err.to_string().contains(fragment), "{err}");
}

#[test]
fn toml_dielectric_with_a_roughness() {
    let edit = |test: &str, roughness: &str| {
        let text = TOML_BASE.replacen(
            "type = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]",
            &format!("type = \"dielectric\"\nior = 1.4\n{roughness}"),
            1,
        );
        assert_ne!(text, TOML_BASE);
        let path = fixture(test, &[("scene.toml", &text)]);
        (load(&path), path)
    };
    let (scene, _) = edit("toml_rough", "roughness = 0.2");
    assert_eq!(
        kind(&scene.unwrap(), "white"),
        MaterialKind::RoughDielectric(RoughDielectric {
            ior: 1.4,
            roughness: 0.2
        })
    );
    for (test, line) in [("toml_smooth", ""), ("toml_zero", "roughness = 0.0")] {
        let (scene, _) = edit(test, line);
        assert_eq!(
            kind(&scene.unwrap(), "white"),
            MaterialKind::Dielectric(scene::Dielectric { ior: 1.4 })
        );
    }
    for (test, line) in [
        ("toml_negative", "roughness = -0.1"),
        ("toml_nan", "roughness = nan"),
    ] {
        let (result, path) = edit(test, line);
        assert_error(result, &path, "[materials.white] roughness");
    }
}

/// A Mitsuba scene whose rectangle has the BSDF `bsdf`.
fn mitsuba(
    test: &str,
    bsdf: &str,
) -> (
    Result<scene::SceneDescription, LoadError>,
    std::path::PathBuf,
) {
    let text = format!(
        r#"<scene version="3.0.0">
    <bsdf id="glass" {bsdf}</bsdf>
    <shape type="rectangle"><ref id="glass"/></shape>
    <emitter type="point"><point name="position" x="0" y="0" z="2"/><rgb name="intensity" value="5"/></emitter>
</scene>"#
    );
    let path = fixture(test, &[("scene.xml", &text)]);
    (load(&path), path)
}

#[test]
fn mitsuba_roughdielectric() {
    let (scene, _) = mitsuba(
        "mitsuba_rough",
        r#"type="roughdielectric"><float name="alpha" value="0.3"/><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/>"#,
    );
    let scene = scene.unwrap();
    assert_eq!(
        kind(&scene, "glass"),
        MaterialKind::RoughDielectric(RoughDielectric {
            ior: 1.5,
            roughness: 0.3
        })
    );
    assert!(
        scene.notes.warnings.is_empty(),
        "{:?}",
        scene.notes.warnings
    );
    // Mitsuba's defaults: α = 0.1, GGX; Beckmann is rendered as GGX of the same α, with a warning.
    let (scene, _) = mitsuba(
        "mitsuba_beckmann",
        r#"type="roughdielectric"><string name="distribution" value="beckmann"/>"#,
    );
    let scene = scene.unwrap();
    assert!(matches!(
        kind(&scene, "glass"),
        MaterialKind::RoughDielectric(RoughDielectric { roughness: 0.1, .. })
    ));
    assert!(
        scene.notes.warnings.iter().any(|w| w.contains("beckmann")),
        "{:?}",
        scene.notes.warnings
    );
    let (result, path) = mitsuba(
        "mitsuba_negative_alpha",
        r#"type="roughdielectric"><float name="alpha" value="-0.2"/>"#,
    );
    assert_error(result, &path, "alpha must be ≥ 0");
    let (result, path) = mitsuba(
        "mitsuba_negative_ior",
        r#"type="roughdielectric"><float name="int_ior" value="-1.5"/>"#,
    );
    assert_error(result, &path, "int_ior and ext_ior must be > 0");
}

/// A pbrt scene whose triangle has the material `material`.
fn pbrt(
    test: &str,
    material: &str,
) -> (
    Result<scene::SceneDescription, LoadError>,
    std::path::PathBuf,
) {
    let text = format!(
        r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 45 ]
WorldBegin
LightSource "point" "rgb I" [ 5 5 5 ] "point3 from" [ 0 0 3 ]
AttributeBegin
  MakeNamedMaterial "glass" {material}
  NamedMaterial "glass"
  Shape "trianglemesh" "point3 P" [ -1 -1 0  1 -1 0  1 1 0 ] "integer indices" [ 0 1 2 ]
AttributeEnd
"#
    );
    let path = fixture(test, &[("scene.pbrt", &text)]);
    (load(&path), path)
}

#[test]
fn pbrt_dielectric_with_a_roughness() {
    let cases = [
        // remaproughness (the default) takes α = √roughness, as pbrt-v4's RoughnessToAlpha.
        (
            r#""string type" "dielectric" "float roughness" [ 0.09 ] "float eta" [ 1.33 ]"#,
            0.3,
        ),
        (
            r#""string type" "dielectric" "float roughness" [ 0.09 ] "bool remaproughness" false"#,
            0.09,
        ),
        (
            r#""string type" "dielectric" "float uroughness" [ 0.2 ] "float vroughness" [ 0.2 ] "bool remaproughness" false"#,
            0.2,
        ),
    ];
    for (i, (material, alpha)) in cases.into_iter().enumerate() {
        let (scene, _) = pbrt(&format!("pbrt_rough_{i}"), material);
        let MaterialKind::RoughDielectric(m) = kind(&scene.unwrap(), "glass") else {
            panic!("{material}");
        };
        assert!((m.roughness - alpha).abs() < 1e-6, "{material}: {m:?}");
    }
    let (scene, _) = pbrt("pbrt_smooth", r#""string type" "dielectric""#);
    assert_eq!(
        kind(&scene.unwrap(), "glass"),
        MaterialKind::Dielectric(scene::Dielectric { ior: 1.5 })
    );
    let (result, path) = pbrt(
        "pbrt_negative_roughness",
        r#""string type" "dielectric" "float roughness" [ -0.1 ]"#,
    );
    assert_error(result, &path, "\"roughness\" must be ≥ 0");
    let (result, path) = pbrt(
        "pbrt_zero_eta",
        r#""string type" "dielectric" "float roughness" [ 0.1 ] "float eta" [ 0 ]"#,
    );
    assert_error(result, &path, "ior");
}
