//! Bad input: one test per kind of error. Each checks the variant and that the message is one
//! line starting with the offending file's path.

use std::path::Path;

use geometry::{LoadError, LoadOptions, load, load_toml_str, load_with};

use crate::{assert_names_file, fixture};

/// A small valid scene: a white sphere lit by an emissive quad.
pub(crate) const BASE: &str = r#"format = 1

[camera]
position = [0.0, 1.0, 3.9]
look_at = [0.0, 1.0, 0.0]
fov_y = 39.3

[materials.white]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]

[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [17.0, 12.0, 4.0]

[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "white"

[[shapes]]
type = "quad"
corner = [-0.25, 1.98, -0.2]
edge1 = [0.5, 0.0, 0.0]
edge2 = [0.0, 0.0, 0.4]
material = "lamp"
"#;

/// Loads `BASE` with one textual replacement, as if from `dir/scene.toml`.
fn load_edited(
    from: &str,
    to: &str,
) -> (Result<geometry::SceneDescription, LoadError>, &'static Path) {
    assert!(BASE.contains(from), "{from:?} not in the base scene");
    let path = Path::new("scenes/edited.toml");
    (load_toml_str(&BASE.replacen(from, to, 1), path), path)
}

#[test]
fn base_scene_loads() {
    let scene = load_toml_str(BASE, Path::new("scenes/base.toml")).unwrap();
    assert_eq!(scene.spheres.len(), 1);
    assert_eq!(scene.triangles.len(), 2);
}

#[test]
fn missing_file() {
    let path = crate::temp_dir("missing_file").join("nope.toml");
    let err = load(&path).unwrap_err();
    assert!(matches!(err, LoadError::Io { .. }), "{err:?}");
    assert_names_file(&err, &path);
    // The OS message ("No such file…") is lowercased after the path.
    let msg = err.to_string();
    let rest = msg.split("cannot read file: ").nth(1).unwrap();
    assert!(rest.starts_with(char::is_lowercase), "{msg}");
}

#[test]
fn non_utf8_file() {
    let dir = crate::temp_dir("non_utf8");
    let path = dir.join("latin1.toml");
    std::fs::write(&path, b"format = 1\n# caf\xe9\n").unwrap();
    let err = load(&path).unwrap_err();
    assert!(matches!(err, LoadError::NotUtf8 { .. }), "{err:?}");
    assert_names_file(&err, &path);
}

#[test]
fn unreadable_path_is_an_io_error() {
    // A directory named like a scene cannot be read as a file.
    let dir = crate::temp_dir("unreadable").join("dir.toml");
    std::fs::create_dir_all(&dir).unwrap();
    let err = load(&dir).unwrap_err();
    assert!(matches!(err, LoadError::Io { .. }), "{err:?}");
    assert_names_file(&err, &dir);
}

#[test]
fn malformed_toml() {
    let (result, path) = load_edited("fov_y = 39.3", "fov_y = = 39.3");
    let err = result.unwrap_err();
    assert!(
        matches!(err, LoadError::Toml { line: Some(6), .. }),
        "{err:?}: {err}"
    );
    assert_names_file(&err, path);
}

#[test]
fn unknown_key() {
    let (result, path) = load_edited("albedo = [0.8, 0.8, 0.8]", "colour = [0.8, 0.8, 0.8]");
    let err = result.unwrap_err();
    let LoadError::UnknownKey {
        key, table, line, ..
    } = &err
    else {
        panic!("{err:?}: {err}")
    };
    assert_eq!(key, "colour");
    assert_eq!(table, "[materials.white]");
    assert_eq!(*line, Some(10));
    assert_names_file(&err, path);
    let msg = err.to_string();
    assert!(
        msg.contains("unknown key \"colour\" in [materials.white]"),
        "{msg}"
    );
    assert!(msg.contains("albedo") && msg.contains("emission"), "{msg}");
}

#[test]
fn unknown_key_in_array_of_tables() {
    let (result, path) = load_edited("radius = 1.0", "radius = 1.0\nradious = 2.0");
    let err = result.unwrap_err();
    let LoadError::UnknownKey { key, table, .. } = &err else {
        panic!("{err:?}: {err}")
    };
    assert_eq!(key, "radious");
    assert_eq!(table, "[[shapes]] #1");
    assert_names_file(&err, path);
}

#[test]
fn wrong_type() {
    let (result, path) = load_edited("albedo = [0.8, 0.8, 0.8]", "albedo = \"white\"");
    let err = result.unwrap_err();
    let LoadError::WrongType { key, table, .. } = &err else {
        panic!("{err:?}: {err}")
    };
    assert_eq!(key, "albedo");
    assert_eq!(table, "[materials.white]");
    assert_names_file(&err, path);
}

#[test]
fn wrong_vector_length() {
    let (result, path) = load_edited("albedo = [0.8, 0.8, 0.8]", "albedo = [0.8, 0.8]");
    let err = result.unwrap_err();
    assert!(matches!(err, LoadError::WrongType { .. }), "{err:?}: {err}");
    assert_names_file(&err, path);
}

#[test]
fn missing_required_key() {
    let (result, path) = load_edited("fov_y = 39.3\n", "");
    let err = result.unwrap_err();
    let LoadError::MissingKey { key, table, .. } = &err else {
        panic!("{err:?}: {err}")
    };
    assert_eq!(key, "fov_y");
    assert_eq!(table, "[camera]");
    assert_names_file(&err, path);
}

#[test]
fn missing_format() {
    let (result, path) = load_edited("format = 1\n", "");
    let err = result.unwrap_err();
    assert!(
        matches!(&err, LoadError::MissingKey { key, .. } if key == "format"),
        "{err:?}: {err}"
    );
    assert_names_file(&err, path);
}

#[test]
fn unknown_material_type() {
    let (result, path) = load_edited("type = \"diffuse\"", "type = \"velvet\"");
    let err = result.unwrap_err();
    let LoadError::UnknownType {
        found,
        expected,
        table,
        ..
    } = &err
    else {
        panic!("{err:?}: {err}")
    };
    assert_eq!(found, "velvet");
    assert_eq!(table, "[materials.white]");
    assert!(expected.contains("dielectric"), "{expected}");
    assert_names_file(&err, path);
}

#[test]
fn unknown_material_reference() {
    let (result, path) = load_edited("material = \"white\"", "material = \"chalk\"");
    let err = result.unwrap_err();
    let LoadError::UnknownMaterial { name, context, .. } = &err else {
        panic!("{err:?}: {err}")
    };
    assert_eq!(name, "chalk");
    assert_eq!(context, "[[shapes]] #1");
    assert_names_file(&err, path);
}

#[test]
fn unsupported_format_version() {
    // Unknown keys of a future version must not hide the version error.
    let (result, path) = load_edited("format = 1", "format = 2\nsky = \"blue\"");
    let err = result.unwrap_err();
    assert!(
        matches!(&err, LoadError::UnsupportedVersion { found, .. } if found == "2"),
        "{err:?}: {err}"
    );
    assert_names_file(&err, path);
}

#[test]
fn fov_zero_and_180() {
    for fov in ["0.0", "180.0", "-5.0", "nan"] {
        let (result, path) = load_edited("fov_y = 39.3", &format!("fov_y = {fov}"));
        let err = result.unwrap_err();
        assert!(
            matches!(&err, LoadError::InvalidValue { key, .. } if key.contains("fov_y")),
            "fov {fov}: {err:?}"
        );
        assert_names_file(&err, path);
    }
    let (result, _) = load_edited("fov_y = 39.3", "fov_y = 179.9");
    result.unwrap();
}

#[test]
fn negative_radiance() {
    let (result, path) = load_edited(
        "emission = [17.0, 12.0, 4.0]",
        "emission = [17.0, -1.0, 4.0]",
    );
    let err = result.unwrap_err();
    assert!(
        matches!(&err, LoadError::InvalidValue { key, .. } if key.contains("emission")),
        "{err:?}: {err}"
    );
    assert_names_file(&err, path);
}

#[test]
fn negative_albedo() {
    let (result, path) = load_edited("albedo = [0.8, 0.8, 0.8]", "albedo = [0.8, -0.1, 0.8]");
    let err = result.unwrap_err();
    assert!(
        matches!(err, LoadError::InvalidValue { .. }),
        "{err:?}: {err}"
    );
    assert_names_file(&err, path);
}

#[test]
fn non_positive_radius_and_film() {
    for (from, to) in [
        ("radius = 1.0", "radius = 0.0"),
        ("radius = 1.0", "radius = -1.0"),
        ("radius = 1.0", "radius = inf"),
        (
            "fov_y = 39.3",
            "fov_y = 39.3\n\n[film]\nwidth = 0\nheight = 10",
        ),
        (
            "fov_y = 39.3",
            "fov_y = 39.3\n\n[film]\nwidth = 10\nheight = -3",
        ),
        (
            "fov_y = 39.3",
            "fov_y = 39.3\n\n[film]\nwidth = 100000\nheight = 10",
        ),
    ] {
        let (result, path) = load_edited(from, to);
        let err = result.unwrap_err();
        assert!(
            matches!(err, LoadError::InvalidValue { .. }),
            "{to}: {err:?}"
        );
        assert_names_file(&err, path);
    }
}

#[test]
fn camera_position_equals_look_at() {
    let (result, path) = load_edited("look_at = [0.0, 1.0, 0.0]", "look_at = [0.0, 1.0, 3.9]");
    let err = result.unwrap_err();
    assert!(matches!(err, LoadError::InvalidValue { .. }), "{err:?}");
    assert_names_file(&err, path);
}

#[test]
fn unknown_extension() {
    let path = fixture("unknown_extension", &[("scene.ply", "ply\n")]);
    let err = load(&path).unwrap_err();
    assert!(
        matches!(&err, LoadError::UnsupportedExtension { extension, .. } if extension == "ply"),
        "{err:?}"
    );
    assert_names_file(&err, &path);
    assert!(err.to_string().contains("\"ply\""));
}

#[test]
fn malformed_obj() {
    let path = fixture(
        "malformed_obj",
        &[(
            "bad.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1 x 0\nf 1 2 3\n",
        )],
    );
    let err = load(&path).unwrap_err();
    assert!(
        matches!(err, LoadError::Obj { line: Some(5), .. }),
        "{err:?}: {err}"
    );
    assert_names_file(&err, &path);
}

#[test]
fn obj_face_index_out_of_range() {
    let path = fixture(
        "obj_face_out_of_range",
        &[("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 7\n")],
    );
    let err = load(&path).unwrap_err();
    assert!(
        matches!(err, LoadError::Obj { line: Some(5), .. }),
        "{err:?}: {err}"
    );
    assert_names_file(&err, &path);
}

#[test]
fn malformed_mtl() {
    let dir_file = fixture(
        "malformed_mtl",
        &[
            ("bad.mtl", "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 2\n"),
            (
                "scene.obj",
                "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl lamp\nf 1 2 3\n",
            ),
        ],
    );
    let mtl = dir_file.clone();
    let obj = dir_file.with_file_name("scene.obj");
    let err = load(&obj).unwrap_err();
    assert!(
        matches!(err, LoadError::Mtl { line: Some(3), .. }),
        "{err:?}: {err}"
    );
    assert_names_file(&err, &mtl);
}

#[test]
fn missing_mtl_is_a_warning() {
    let path = fixture(
        "missing_mtl",
        &[(
            "scene.obj",
            "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl lamp\nf 1 2 3\n",
        )],
    );
    let scene = load_with(&path, &LoadOptions::allow_no_emitter()).unwrap();
    assert_eq!(scene.triangles.len(), 1);
    assert_eq!(scene.materials[0].name, "default");
    assert!(scene.notes.warnings.iter().any(|w| w.contains("gone.mtl")));
}

#[test]
fn malformed_gltf_json() {
    let path = fixture(
        "malformed_gltf",
        &[("bad.gltf", "{ \"asset\": { \"version\": \"2.0\" }, ")],
    );
    let err = load(&path).unwrap_err();
    assert!(matches!(err, LoadError::Gltf { .. }), "{err:?}: {err}");
    assert_names_file(&err, &path);
}

#[test]
fn nan_vertex() {
    let path = fixture(
        "nan_vertex",
        &[("nan.obj", "v 0 0 0\nv 1 0 0\n\nv 0 NaN 0\nf 1 2 3\n")],
    );
    let err = load(&path).unwrap_err();
    assert!(
        matches!(
            err,
            LoadError::NonFiniteVertex {
                line: Some(4),
                what: "nan",
                ..
            }
        ),
        "{err:?}: {err}"
    );
    assert_names_file(&err, &path);
    assert!(
        err.to_string()
            .contains("line 4: vertex has a nan coordinate"),
        "{err}"
    );
}

#[test]
fn infinite_vertex() {
    let path = fixture(
        "inf_vertex",
        &[("inf.obj", "v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n")],
    );
    let err = load(&path).unwrap_err();
    assert!(
        matches!(
            err,
            LoadError::NonFiniteVertex {
                line: Some(2),
                what: "infinite",
                ..
            }
        ),
        "{err:?}: {err}"
    );
    assert_names_file(&err, &path);
    // Overflowing f32 is infinite too.
    let path = fixture(
        "big_vertex",
        &[("big.obj", "v 0 0 0\nv 1 0 1e39\nv 0 1 0\nf 1 2 3\n")],
    );
    let err = load(&path).unwrap_err();
    assert!(matches!(err, LoadError::NonFiniteVertex { .. }), "{err:?}");
}

#[test]
fn degenerate_triangles_are_skipped_and_counted() {
    let obj = "mtllib l.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n\
               usemtl lamp\nf 1 2 3\nf 1 2 4\nf 1 1 3\n";
    let path = fixture(
        "degenerate",
        &[
            ("d.obj", obj),
            ("l.mtl", "newmtl lamp\nKd 0 0 0\nKe 1 1 1\n"),
        ],
    );
    let scene = load(&path).unwrap();
    assert_eq!(scene.triangles.len(), 1);
    assert_eq!(scene.notes.degenerate_triangles, 2);
}

#[test]
fn empty_scene() {
    let path = fixture("empty_obj", &[("empty.obj", "# nothing\nv 0 0 0\n")]);
    let err = load(&path).unwrap_err();
    assert!(matches!(err, LoadError::EmptyScene { .. }), "{err:?}");
    assert_names_file(&err, &path);

    let toml = "format = 1\n[materials.a]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n";
    let path = Path::new("empty.toml");
    let err = load_toml_str(toml, path).unwrap_err();
    assert!(matches!(err, LoadError::EmptyScene { .. }), "{err:?}");
    assert_names_file(&err, path);
}

#[test]
fn zero_area_emitter() {
    // The lamp quad has parallel edges: both its triangles are degenerate.
    let (result, path) = load_edited("edge2 = [0.0, 0.0, 0.4]", "edge2 = [1.0, 0.0, 0.0]");
    let err = result.unwrap_err();
    assert!(
        matches!(&err, LoadError::ZeroAreaEmitter { material, .. } if material == "lamp"),
        "{err:?}: {err}"
    );
    assert_names_file(&err, path);
}

#[test]
fn no_emitter() {
    let (result, path) = load_edited("emission = [17.0, 12.0, 4.0]", "emission = [0.0, 0.0, 0.0]");
    let err = result.unwrap_err();
    assert!(matches!(err, LoadError::NoEmitter { .. }), "{err:?}");
    assert_names_file(&err, path);

    let obj = fixture(
        "no_emitter",
        &[("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")],
    );
    let err = load(&obj).unwrap_err();
    assert!(matches!(err, LoadError::NoEmitter { .. }), "{err:?}");
    assert_names_file(&err, &obj);
    load_with(&obj, &LoadOptions::allow_no_emitter()).unwrap();
}

#[test]
fn mesh_file_errors_name_the_mesh_file() {
    let dir = crate::temp_dir("mesh_file_error");
    std::fs::write(
        dir.join("nan.obj"),
        "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let scene = BASE.replacen(
        "[[shapes]]",
        "[[shapes]]\ntype = \"mesh\"\nfile = \"nan.obj\"\n\n[[shapes]]",
        1,
    );
    let toml = dir.join("scene.toml");
    std::fs::write(&toml, scene).unwrap();
    let err = load(&toml).unwrap_err();
    assert!(matches!(err, LoadError::NonFiniteVertex { .. }), "{err:?}");
    assert_names_file(&err, &dir.join("nan.obj"));
}

/// The messages users see, one line each, file first.
#[test]
fn messages_read_well() {
    let edits = [
        ("fov_y = 39.3", "fov_y = = 39.3"),
        ("albedo = [0.8, 0.8, 0.8]", "colour = [0.8, 0.8, 0.8]"),
        ("albedo = [0.8, 0.8, 0.8]", "albedo = \"white\""),
        ("albedo = [0.8, 0.8, 0.8]", "albedo = [0.8, 0.8]"),
        ("fov_y = 39.3\n", ""),
        ("type = \"diffuse\"", "type = \"velvet\""),
        ("material = \"white\"", "material = \"chalk\""),
        ("format = 1", "format = 2"),
        ("fov_y = 39.3", "fov_y = 180"),
        ("radius = 1.0", "radius = 0"),
        (
            "emission = [17.0, 12.0, 4.0]",
            "emission = [17.0, -1.0, 4.0]",
        ),
        ("emission = [17.0, 12.0, 4.0]", "emission = [0.0, 0.0, 0.0]"),
        ("edge2 = [0.0, 0.0, 0.4]", "edge2 = [1.0, 0.0, 0.0]"),
        ("fov_y = 39.3", "fov_y = 39.3\nfocal = 1"),
    ];
    let mut lines: Vec<String> = edits
        .iter()
        .map(|(from, to)| load_edited(from, to).0.unwrap_err().to_string())
        .collect();
    let dir = crate::temp_dir("messages");
    let files = [
        ("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
        ("nan.obj", "v 0 0 0\nv nan 0 0\n"),
        ("bad.gltf", "{ \"asset\": 1 }"),
        ("scene.ply", ""),
    ];
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
        let err = load(&dir.join(name)).unwrap_err();
        lines.push(err.to_string().replace(&dir.display().to_string(), "<dir>"));
    }
    insta::assert_snapshot!(lines.join("\n"));
}
