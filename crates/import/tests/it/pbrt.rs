//! pbrt-v4 scenes: every shared scene loads, with counts derived independently of the
//! importer, summaries snapshotted, conventions checked, and one test per kind of bad input.

use std::path::{Path, PathBuf};

use import::{LoadError, load};

use crate::{assert_names_file, fixture, shared_scenes};

fn pbrt(rel: &str) -> PathBuf {
    shared_scenes().join("pbrt-v4").join(rel)
}

/// Number of values in the first `"integer indices" [ ... ]` list of a pbrt file.
fn index_count(path: &Path) -> usize {
    let text = std::fs::read_to_string(path).unwrap();
    let start = text.find("\"integer indices\"").unwrap();
    let open = start + text[start..].find('[').unwrap();
    let close = open + text[open..].find(']').unwrap();
    text[open + 1..close].split_whitespace().count()
}

/// The `element face N` count of a PLY header (the veach-mis PLYs hold triangles only: their
/// headers say `property list uchar int vertex_indices` and every face line is `3 a b c`).
fn ply_faces(path: &Path) -> usize {
    let bytes = std::fs::read(path).unwrap();
    let header = String::from_utf8_lossy(&bytes[..bytes.len().min(512)]).into_owned();
    header
        .lines()
        .find_map(|l| l.strip_prefix("element face "))
        .unwrap()
        .trim()
        .parse()
        .unwrap()
}

/// (triangles, emissive triangles, emissive spheres, directional lights, materials) expected of
/// each shared scene, and how they were derived.
fn expected(rel: &str) -> (usize, usize, usize, usize, usize) {
    // The killeroo's Loop control mesh: indices / 3 (8,316) triangles, times 4 per level of
    // subdivision (SOURCE.md: 33,264 after one level, 532,224 after three).
    let killeroo = index_count(&pbrt("killeroos/geometry/killeroo.pbrt")) / 3;
    match rel {
        // Two killeroos (levels 1), two 2-triangle quads (trianglemesh, 6 indices each), one
        // sphere light. Materials: the light's, the floor/wall diffuse, two coateddiffuse.
        "killeroos/killeroo-simple.pbrt" | "killeroos/killeroo-moving.pbrt" => {
            (2 * 4 * killeroo + 4, 0, 1, 0, 4)
        }
        // One killeroo (killeroo3.pbrt: levels 3), three textured quads, a 64-triangle disk
        // light, the distant light. Materials: light, textured diffuse, gold.
        "killeroos/killeroo-gold.pbrt" | "killeroos/killeroo-coated-gold.pbrt" => {
            (64 * killeroo + 6 + 64, 64, 0, 1, 3)
        }
        // Four plates and the floor from their PLY headers; five sphere lights; materials: five
        // lights (each its own L), four plates, the floor.
        "veach-mis/veach-mis.pbrt" => {
            let g = |f: &str| ply_faces(&pbrt(&format!("veach-mis/geometry/{f}.ply")));
            (
                g("floor") + g("plate1") + g("plate2") + g("plate3") + g("plate4"),
                0,
                5,
                0,
                10,
            )
        }
        other => panic!("no expectation for {other}"),
    }
}

const SCENES: &[&str] = &[
    "killeroos/killeroo-simple.pbrt",
    "killeroos/killeroo-moving.pbrt",
    "killeroos/killeroo-gold.pbrt",
    "killeroos/killeroo-coated-gold.pbrt",
    "veach-mis/veach-mis.pbrt",
];

#[test]
fn every_shared_pbrt_scene_loads_with_independent_counts() {
    for rel in SCENES {
        // Every one has an emitter fppm renders, so it loads with the default options too.
        let scene = load(&pbrt(rel)).unwrap();
        let s = scene.summary();
        let (triangles, emissive, emissive_spheres, directional, materials) = expected(rel);
        assert_eq!(
            s.triangles + s.degenerate_triangles,
            triangles,
            "{rel} triangles"
        );
        assert_eq!(s.emissive_triangles, emissive, "{rel} emissive triangles");
        assert_eq!(
            s.emissive_spheres, emissive_spheres,
            "{rel} emissive spheres"
        );
        assert_eq!(s.lights.directional, directional, "{rel} distant lights");
        assert_eq!(s.materials.len(), materials, "{rel} materials");
        assert!(!s.camera_framed, "{rel} has a camera");
        let mut summary = s.clone();
        summary.source = format!("pbrt-v4/{rel}");
        let name = format!("pbrt__{}", rel.replace(['/', '.'], "_"));
        insta::assert_yaml_snapshot!(name, summary);
    }
}

#[test]
fn veach_mis_conventions() {
    let scene = load(&pbrt("veach-mis/veach-mis.pbrt")).unwrap();
    // maxdepth 5 counts scattering events in both renderers.
    assert_eq!(scene.render.get("max_depth"), Some("5"));
    // pbrt's fov spans the shorter side (the height of a 1152 x 864 film).
    assert!((scene.camera.fov_y.to_degrees() - 28.000_026).abs() < 1e-3);
    // `Scale -1 1 1` before and after LookAt cancel in position: the eye is at (0, 2, 15).
    assert!((scene.camera.position - glam::Vec3::new(0.0, 2.0, 15.0)).length() < 1e-4);
    // The sphere light of radius 0.9 sits at world (3.75, 0, 0). In pbrt's camera space
    // (Scale −1 1 1 · LookAt · Scale −1 1 1, with LookAt's x axis up × dir = (−1, 0, 0)) its
    // x is −3.75: pbrt draws it on the image's left. fppm's camera is right-handed, so the
    // importer reflects the world across the camera's vertical plane (x = 0 here): the sphere
    // moves to x = −3.75 and fppm draws it on the left too.
    let s = scene
        .spheres
        .iter()
        .find(|s| (s.radius - 0.9).abs() < 1e-6)
        .unwrap();
    assert!(
        (s.center - glam::Vec3::new(-3.75, 0.0, 0.0)).length() < 1e-5,
        "{}",
        s.center
    );
    let c = scene.camera;
    let right = (c.look_at - c.position).cross(c.up);
    assert!((s.center - c.position).dot(right) < 0.0);
}

/// pbrt's camera space is left-handed: with a plain LookAt, the image's right is
/// up × forward, the mirror of a right-handed camera's. The importer reflects the world so
/// that fppm's right-handed camera sees pbrt's image: a point on pbrt's image right must
/// land on the right of fppm's image.
#[test]
fn pbrt_handedness_is_kept() {
    let text = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 45\n\
                WorldBegin\nLightSource \"point\" \"point3 from\" [ 0 0 4 ] \"rgb I\" [ 1 1 1 ]\n\
                Shape \"sphere\" \"float radius\" 0.1\n\
                AttributeBegin\nTranslate 1 0 0\nShape \"sphere\" \"float radius\" 0.2\nAttributeEnd\n";
    let path = fixture("pbrt_handedness", &[("scene.pbrt", text)]);
    let scene = load(&path).unwrap();
    // pbrt camera x = normalize(up × dir) with dir = −z, up = +y: (0,1,0) × (0,0,−1) = (−1,0,0).
    // So world −x is on pbrt's image right, and the sphere at world +x is on its left.
    let c = scene.camera;
    let forward = (c.look_at - c.position).normalize();
    let fppm_right = forward.cross(c.up).normalize();
    let big = scene.spheres.iter().find(|s| s.radius > 0.15).unwrap();
    assert!(
        (big.center - c.position).dot(fppm_right) < 0.0,
        "the sphere pbrt shows on the left must be on fppm's left"
    );
}

/// A small valid scene.
const BASE: &str = r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 45 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 32 ]
WorldBegin
LightSource "point" "rgb I" [ 5 5 5 ] "point3 from" [ 0 0 3 ]
AttributeBegin
  Material "diffuse" "rgb reflectance" [ 0.8 0.8 0.8 ]
  Shape "trianglemesh" "point3 P" [ -1 -1 0  1 -1 0  1 1 0 ] "integer indices" [ 0 1 2 ]
AttributeEnd
"#;

fn load_edited(
    test: &str,
    from: &str,
    to: &str,
) -> (Result<scene::SceneDescription, LoadError>, PathBuf) {
    assert!(BASE.contains(from), "{from:?} not in the base scene");
    let path = fixture(test, &[("scene.pbrt", &BASE.replacen(from, to, 1))]);
    (load(&path), path)
}

#[test]
fn base_scene_loads() {
    let path = fixture("pbrt_base", &[("scene.pbrt", BASE)]);
    let scene = load(&path).unwrap();
    assert_eq!(scene.triangles.len(), 1);
    assert_eq!((scene.film.width, scene.film.height), (32, 32));
}

#[track_caller]
fn assert_message(err: &LoadError, file: &Path, fragments: &[&str]) {
    assert_names_file(err, file);
    let msg = err.to_string();
    for f in fragments {
        assert!(msg.contains(f), "{msg:?} lacks {f:?}");
    }
}

#[test]
fn syntax_errors() {
    let (err, path) = load_edited("pbrt_unterminated", "\"float fov\"", "\"float fov");
    assert_message(&err.unwrap_err(), &path, &["line 2", "syntax error"]);
    let (err, path) = load_edited("pbrt_unknown_directive", "WorldBegin", "WorldBgin");
    assert_message(
        &err.unwrap_err(),
        &path,
        &["line 4", "unknown directive \"WorldBgin\""],
    );
    let (err, path) = load_edited("pbrt_unclosed", "[ 0 0 3 ]", "[ 0 0 3");
    assert_message(&err.unwrap_err(), &path, &["line 5"]);
    let (err, path) = load_edited("pbrt_unbalanced", "AttributeBegin\n", "");
    assert_message(
        &err.unwrap_err(),
        &path,
        &["line 8", "AttributeEnd without a matching begin"],
    );
}

#[test]
fn wrong_parameter_type_or_arity() {
    let (err, path) = load_edited(
        "pbrt_arity",
        "\"float fov\" [ 45 ]",
        "\"float fov\" [ 45 50 ]",
    );
    assert_message(
        &err.unwrap_err(),
        &path,
        &["line 2", "expects 1 value, got 2"],
    );
    let (err, path) = load_edited(
        "pbrt_type",
        "\"float fov\" [ 45 ]",
        "\"string fov\" [ \"wide\" ]",
    );
    assert_message(
        &err.unwrap_err(),
        &path,
        &["line 2", "must be of type float"],
    );
    let (err, path) = load_edited("pbrt_rgb_arity", "[ 0.8 0.8 0.8 ]", "[ 0.8 0.8 ]");
    assert_message(
        &err.unwrap_err(),
        &path,
        &["line 7", "expects 3 values, got 2"],
    );
    let (err, path) = load_edited(
        "pbrt_points",
        "[ -1 -1 0  1 -1 0  1 1 0 ]",
        "[ -1 -1 0  1 -1 0  1 1 ]",
    );
    assert_message(&err.unwrap_err(), &path, &["line 8", "multiple of 3"]);
    let (err, path) = load_edited("pbrt_index_range", "[ 0 1 2 ]", "[ 0 1 7 ]");
    assert_message(&err.unwrap_err(), &path, &["line 8", "refers to vertex 7"]);
}

#[test]
fn include_cycle() {
    let path = fixture(
        "pbrt_cycle",
        &[
            ("scene.pbrt", "Include \"a.pbrt\"\n"),
            ("a.pbrt", "\n  Include \"scene.pbrt\"\n"),
        ],
    );
    let err = load(&path).unwrap_err();
    assert_message(
        &err,
        &path.with_file_name("a.pbrt"),
        &["line 2", "include cycle"],
    );
}

#[test]
fn missing_mesh_file() {
    let (err, path) = load_edited(
        "pbrt_missing_ply",
        "Shape \"trianglemesh\" \"point3 P\" [ -1 -1 0  1 -1 0  1 1 0 ] \"integer indices\" [ 0 1 2 ]",
        "Shape \"plymesh\" \"string filename\" \"nope.ply\"",
    );
    assert_message(
        &err.unwrap_err(),
        &path,
        &["line 8", "nope.ply", "cannot read file"],
    );
}

#[test]
fn lying_ply_header() {
    let ply = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 500\nproperty list uchar int vertex_indices\nend_header\n";
    let scene = BASE.replacen(
        "Shape \"trianglemesh\" \"point3 P\" [ -1 -1 0  1 -1 0  1 1 0 ] \"integer indices\" [ 0 1 2 ]",
        "Shape \"plymesh\" \"string filename\" \"lie.ply\"",
        1,
    );
    let path = fixture(
        "pbrt_lying_ply",
        &[("scene.pbrt", &scene), ("lie.ply", ply)],
    );
    let err = load(&path).unwrap_err();
    assert_message(
        &err,
        &path,
        &["line 8", "lie.ply", "header declares 3 vertex, 500 face"],
    );
}

#[test]
fn infinite_lights_constant_and_octahedral_map() {
    // A constant sky alone lights the scene.
    let (scene, _) = load_edited(
        "pbrt_infinite_constant",
        "LightSource \"point\" \"rgb I\" [ 5 5 5 ] \"point3 from\" [ 0 0 3 ]",
        "LightSource \"infinite\" \"rgb L\" [ 1 2 3 ] \"float scale\" 2",
    );
    let env = scene.unwrap().environment.unwrap();
    assert_eq!(
        env.radiance,
        scene::EnvironmentRadiance::Constant(glam::Vec3::new(1.0, 2.0, 3.0))
    );
    assert_eq!(env.scale, 2.0);
    // An equal-area octahedral map: written here with distinct texels where pbrt's
    // `EqualAreaSphereToSquare` puts +z (the centre), +x (the middle of the right edge) and +y
    // (the middle of the bottom edge), and found in the world where point lights placed along
    // those axes of the light's frame end up (the same transform, by another route).
    let dir = crate::temp_dir("pbrt_infinite_map");
    exr::prelude::write_rgb_file(dir.join("sky.exr"), 8, 8, |i, j| {
        let v = match (i, j) {
            (3..=4, 3..=4) => 10.0f32,
            (7, 3..=4) => 20.0,
            (3..=4, 7) => 30.0,
            _ => 1.0,
        };
        (v, v, v)
    })
    .unwrap();
    let light = "LightSource \"point\" \"rgb I\" [ 5 5 5 ] \"point3 from\" [ 0 0 3 ]";
    // A rotation, and a rotation with a mirror (the map is then resampled mirrored).
    for transform in ["Rotate 30 0 1 0", "Rotate 30 0 1 0\nScale -2 2 2"] {
        let scene = BASE.replacen(
            light,
            &format!(
                "AttributeBegin\n{transform}\n\
                 LightSource \"infinite\" \"string filename\" \"sky.exr\" \"float scale\" 2\n\
                 LightSource \"point\" \"rgb I\" [ 1 1 1 ] \"point3 from\" [ 0 0 3 ]\n\
                 LightSource \"point\" \"rgb I\" [ 1 1 1 ] \"point3 from\" [ 3 0 0 ]\n\
                 LightSource \"point\" \"rgb I\" [ 1 1 1 ] \"point3 from\" [ 0 3 0 ]\n\
                 AttributeEnd"
            ),
            1,
        );
        std::fs::write(dir.join("scene.pbrt"), scene).unwrap();
        let description = load(&dir.join("scene.pbrt")).unwrap();
        let positions: Vec<glam::Vec3> = description
            .lights
            .iter()
            .map(|l| match *l {
                scene::Light::Point { position, .. } => position.normalize(),
                ref other => panic!("{other:?}"),
            })
            .collect();
        let scene = scene::Scene::new(description).unwrap();
        for (axis, want) in positions.iter().zip([10.0, 20.0, 30.0]) {
            let got = scene.lights().environment_radiance(*axis);
            assert_eq!(
                got,
                glam::Vec3::splat(2.0 * want),
                "{transform}: toward {axis}"
            );
        }
    }
    // A missing map names itself.
    let (err, _) = load_edited(
        "pbrt_infinite_missing",
        light,
        "LightSource \"infinite\" \"string filename\" \"gone.exr\"",
    );
    let err = err.unwrap_err();
    assert!(matches!(err, LoadError::Io { .. }), "{err}");
    assert!(err.path().ends_with("gone.exr"), "{err}");
}

/// Graphics-state directives, with positions worked out by hand from pbrt-v4's file-format
/// documentation: transforms post-multiply the CTM, `Transform`/`ConcatTransform` list the
/// matrix column by column (translation in the 13th–15th numbers), `CoordSysTransform`
/// restores a saved CTM, `ObjectInstance` applies the instance's CTM on top of the object's.
#[test]
fn graphics_state_directives() {
    let text = r#"LookAt 0 0 10  0 0 0  0 1 0
Camera "perspective"
WorldBegin
LightSource "point" "rgb I" [ 1 1 1 ]
MakeNamedMaterial "red" "string type" "diffuse" "rgb reflectance" [ 0.9 0.1 0.1 ]
ObjectBegin "tri"
  NamedMaterial "red"
  Translate 0 0 1
  Shape "trianglemesh" "point3 P" [ 0 0 0  1 0 0  0 1 0 ]
ObjectEnd
AttributeBegin
  Translate 10 0 0
  CoordinateSystem "moved"
  ObjectInstance "tri"
AttributeEnd
AttributeBegin
  ConcatTransform [ 2 0 0 0  0 2 0 0  0 0 2 0  0 5 0 1 ]
  ObjectInstance "tri"
AttributeEnd
AttributeBegin
  Scale 7 7 7
  Transform [ 1 0 0 0  0 1 0 0  0 0 1 0  0 0 -3 1 ]
  Shape "trianglemesh" "point3 P" [ 0 0 0  1 0 0  0 1 0 ]
AttributeEnd
AttributeBegin
  CoordSysTransform "moved"
  Rotate 90 0 0 1
  Shape "trianglemesh" "point3 P" [ 0 0 0  1 0 0  0 1 0 ]
AttributeEnd
"#;
    let path = fixture("pbrt_state", &[("scene.pbrt", text)]);
    let scene = load(&path).unwrap();
    let corners: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.positions).collect();
    // The camera looks down −z with +y up: pbrt's image right is up × dir = −x, so the importer
    // mirrors the world in x (see `pbrt_handedness_is_kept`). Expected positions below are
    // pbrt's world positions with x negated.
    let v = |x: f32, y: f32, z: f32| glam::Vec3::new(-x, y, z);
    let expected = [
        // Instance under Translate 10 0 0: object translate (0, 0, 1) then (10, 0, 0).
        [v(10.0, 0.0, 1.0), v(11.0, 0.0, 1.0), v(10.0, 1.0, 1.0)],
        // Instance under scale 2 and translation (0, 5, 0) (column-major).
        [v(0.0, 5.0, 2.0), v(2.0, 5.0, 2.0), v(0.0, 7.0, 2.0)],
        // Transform replaces the Scale: translation (0, 0, −3) only.
        [v(0.0, 0.0, -3.0), v(1.0, 0.0, -3.0), v(0.0, 1.0, -3.0)],
        // Back at "moved" (Translate 10 0 0), then a quarter turn about z.
        [v(10.0, 0.0, 0.0), v(10.0, 1.0, 0.0), v(9.0, 0.0, 0.0)],
    ];
    assert_eq!(corners.len(), expected.len());
    for (i, (got, want)) in corners.iter().zip(&expected).enumerate() {
        // Mirroring reverses the winding: compare as sets of corners.
        for w in want {
            assert!(
                got.iter().any(|g| (*g - *w).length() < 1e-5),
                "triangle {i}: {got:?} lacks {w}"
            );
        }
    }
    // The instanced triangles use the named material.
    let red = &scene.materials[scene.triangles[0].material as usize];
    assert_eq!(red.name, "red");
}
