//! Bad input: tables of bad edits and bad files, each with the error it must give (its variant
//! and fields), the message one line starting with the offending file's path; then the cases
//! that need more than a table.

use std::path::Path;

use import::{LoadError, LoadOptions, load, load_toml_str, load_with};

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

/// A scene whose emitter's albedo is the texture `tex.png` next to it.
const TEXTURED: &str = "format = 1\n[materials.m]\ntype = \"diffuse\"\nalbedo = { texture = \"tex.png\" }\nemission = [1, 1, 1]\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n";

/// A glTF triangle whose material's base colour is the image at the URI `$uri` (a string
/// literal); positions in one base64 buffer; the material emits.
macro_rules! gltf_textured_uri {
    ($uri:literal) => {
        concat!(
            r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}],
"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0},"metallicFactor":0},"emissiveFactor":[1,1,1]}],
"textures":[{"source":0}],"images":[{"uri":""#,
            $uri,
            r#""}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
"bufferViews":[{"buffer":0,"byteLength":36}],
"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]}"#
        )
    };
}

/// A glTF triangle whose material's base colour is the texture `tex.png` beside it.
const GLTF_TEXTURED: &str = gltf_textured_uri!("tex.png");

/// Loads `BASE` with one textual replacement, as if from `dir/scene.toml`.
fn load_edited(
    from: &str,
    to: &str,
) -> (Result<scene::SceneDescription, LoadError>, &'static Path) {
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

/// Edits of `BASE` and what each error must be: fragments of its `Debug` form (the variant
/// and the fields that matter).
const EDITS: &[(&str, &str, &[&str])] = &[
    (
        "fov_y = 39.3",
        "fov_y = = 39.3",
        &["Toml {", "line: Some(6)"],
    ),
    (
        "albedo = [0.8, 0.8, 0.8]",
        "colour = [0.8, 0.8, 0.8]",
        &[
            "UnknownKey {",
            "line: Some(10)",
            "table: \"[materials.white]\"",
            "key: \"colour\"",
        ],
    ),
    (
        "radius = 1.0",
        "radius = 1.0\nradious = 2.0",
        &[
            "UnknownKey {",
            "table: \"[[shapes]] #1\"",
            "key: \"radious\"",
        ],
    ),
    (
        "albedo = [0.8, 0.8, 0.8]",
        "albedo = \"white\"",
        &[
            "WrongType {",
            "line: Some(10)",
            "column: Some(1)",
            "table: \"[materials.white]\"",
            "key: \"albedo\"",
        ],
    ),
    (
        "albedo = [0.8, 0.8, 0.8]",
        "albedo = [0.8, 0.8]",
        &[
            "WrongType {",
            "line: Some(10)",
            "table: \"[materials.white]\"",
            "key: \"albedo\"",
        ],
    ),
    // The same value twice in a table: the key at fault, not the first with that value.
    (
        "emission = [17.0, 12.0, 4.0]",
        "emission = [0.0, 0.0]",
        &[
            "WrongType {",
            "line: Some(15)",
            "table: \"[materials.lamp]\"",
            "key: \"emission\"",
        ],
    ),
    (
        "radius = 1.0",
        "radius = \"big\"",
        &[
            "WrongType {",
            "line: Some(20)",
            "table: \"[[shapes]] #1\"",
            "key: \"radius\"",
        ],
    ),
    (
        "edge2 = [0.0, 0.0, 0.4]",
        "edge2 = true",
        &[
            "WrongType {",
            "line: Some(27)",
            "table: \"[[shapes]] #2\"",
            "key: \"edge2\"",
        ],
    ),
    (
        "fov_y = 39.3\n",
        "",
        &["MissingKey {", "table: \"[camera]\"", "key: \"fov_y\""],
    ),
    ("format = 1\n", "", &["MissingKey {", "key: \"format\""]),
    (
        "type = \"diffuse\"",
        "type = \"velvet\"",
        &[
            "UnknownType {",
            "table: \"[materials.white]\"",
            "found: \"velvet\"",
            "dielectric",
        ],
    ),
    (
        "material = \"white\"",
        "material = \"chalk\"",
        &[
            "UnknownMaterial {",
            "name: \"chalk\"",
            "context: \"[[shapes]] #1\"",
        ],
    ),
    // Unknown keys of a future version must not hide the version error.
    (
        "format = 1",
        "format = 2\nsky = \"blue\"",
        &["UnsupportedVersion {", "found: \"2\""],
    ),
    ("fov_y = 39.3", "fov_y = 0.0", &["InvalidValue {", "fov_y"]),
    (
        "fov_y = 39.3",
        "fov_y = 180.0",
        &["InvalidValue {", "fov_y"],
    ),
    ("fov_y = 39.3", "fov_y = -5.0", &["InvalidValue {", "fov_y"]),
    ("fov_y = 39.3", "fov_y = nan", &["InvalidValue {", "fov_y"]),
    (
        "emission = [17.0, 12.0, 4.0]",
        "emission = [17.0, -1.0, 4.0]",
        &["InvalidValue {", "emission"],
    ),
    (
        "albedo = [0.8, 0.8, 0.8]",
        "albedo = [0.8, -0.1, 0.8]",
        &["InvalidValue {"],
    ),
    ("radius = 1.0", "radius = 0.0", &["InvalidValue {"]),
    ("radius = 1.0", "radius = -1.0", &["InvalidValue {"]),
    ("radius = 1.0", "radius = inf", &["InvalidValue {"]),
    (
        "fov_y = 39.3",
        "fov_y = 39.3\n\n[film]\nwidth = 0\nheight = 10",
        &["InvalidValue {"],
    ),
    (
        "fov_y = 39.3",
        "fov_y = 39.3\n\n[film]\nwidth = 10\nheight = -3",
        &["InvalidValue {"],
    ),
    (
        "fov_y = 39.3",
        "fov_y = 39.3\n\n[film]\nwidth = 100000\nheight = 10",
        &["InvalidValue {"],
    ),
    // The camera looks at its own position.
    (
        "look_at = [0.0, 1.0, 0.0]",
        "look_at = [0.0, 1.0, 3.9]",
        &["InvalidValue {"],
    ),
    // The lamp quad has parallel edges: both its triangles are degenerate.
    (
        "edge2 = [0.0, 0.0, 0.4]",
        "edge2 = [1.0, 0.0, 0.0]",
        &["ZeroAreaEmitter {", "material: \"lamp\""],
    ),
    (
        "emission = [17.0, 12.0, 4.0]",
        "emission = [0.0, 0.0, 0.0]",
        &["NoEmitter {"],
    ),
    // Environment lights (an extension, docs/scene-format-extensions.md).
    (
        "material = \"lamp\"\n",
        "material = \"lamp\"\n[[lights]]\ntype = \"environment\"\nfile = \"sky.exr\"\nradiance = [1.0, 1.0, 1.0]\n",
        &["InvalidValue {", "[[lights]] #1 file", "exactly one"],
    ),
    (
        "material = \"lamp\"\n",
        "material = \"lamp\"\n[[lights]]\ntype = \"environment\"\n",
        &["InvalidValue {", "exactly one"],
    ),
    (
        "material = \"lamp\"\n",
        "material = \"lamp\"\n[[lights]]\ntype = \"environment\"\nradiance = [1.0, -1.0, 1.0]\n",
        &["InvalidValue {", "radiance"],
    ),
    (
        "material = \"lamp\"\n",
        "material = \"lamp\"\n[[lights]]\ntype = \"environment\"\nradiance = [1.0, 1.0, 1.0]\nscale = -2.0\n",
        &["InvalidValue {", "scale"],
    ),
    (
        "material = \"lamp\"\n",
        "material = \"lamp\"\n[[lights]]\ntype = \"environment\"\nradiance = [1.0, 1.0, 1.0]\nrotate = [0.0, nan, 0.0]\n",
        &["InvalidValue {", "rotate"],
    ),
    (
        "material = \"lamp\"\n",
        "material = \"lamp\"\n[[lights]]\ntype = \"environment\"\nradiance = [1.0, 1.0, 1.0]\n\
         [[lights]]\ntype = \"environment\"\nradiance = [2.0, 2.0, 2.0]\n",
        &["InvalidValue {", "[[lights]] #2", "twice"],
    ),
    (
        "material = \"lamp\"\n",
        "material = \"lamp\"\n[[lights]]\ntype = \"environment\"\nradiance = [1.0, 1.0, 1.0]\nturn = 3.0\n",
        &["UnknownKey {", "key: \"turn\""],
    ),
];

/// Files (name, text; the first is loaded) and what the error must be, as in [`EDITS`], and
/// the file it names.
struct BadFile {
    test: &'static str,
    files: &'static [(&'static str, &'static str)],
    expect: &'static [&'static str],
    named: &'static str,
}

const FILES: &[BadFile] = &[
    BadFile {
        test: "unknown_extension",
        files: &[("scene.ply", "ply\n")],
        expect: &["UnsupportedExtension {", "extension: \"ply\""],
        named: "scene.ply",
    },
    BadFile {
        test: "malformed_obj",
        files: &[(
            "bad.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1 x 0\nf 1 2 3\n",
        )],
        expect: &["Obj {", "line: Some(5)"],
        named: "bad.obj",
    },
    BadFile {
        test: "obj_face_out_of_range",
        files: &[("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 7\n")],
        expect: &["Obj {", "line: Some(5)"],
        named: "bad.obj",
    },
    BadFile {
        test: "malformed_mtl",
        files: &[
            (
                "scene.obj",
                "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl lamp\nf 1 2 3\n",
            ),
            ("bad.mtl", "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 2\n"),
        ],
        expect: &["Mtl {", "line: Some(3)"],
        named: "bad.mtl",
    },
    BadFile {
        test: "malformed_gltf",
        files: &[("bad.gltf", "{ \"asset\": { \"version\": \"2.0\" }, ")],
        expect: &["Gltf {"],
        named: "bad.gltf",
    },
    BadFile {
        test: "nan_vertex",
        files: &[("nan.obj", "v 0 0 0\nv 1 0 0\n\nv 0 NaN 0\nf 1 2 3\n")],
        expect: &["NonFiniteVertex {", "line: Some(4)", "what: \"nan\""],
        named: "nan.obj",
    },
    BadFile {
        test: "inf_vertex",
        files: &[("inf.obj", "v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n")],
        expect: &["NonFiniteVertex {", "line: Some(2)", "what: \"infinite\""],
        named: "inf.obj",
    },
    BadFile {
        test: "big_vertex",
        files: &[("big.obj", "v 0 0 0\nv 1 0 1e39\nv 0 1 0\nf 1 2 3\n")],
        expect: &["NonFiniteVertex {"],
        named: "big.obj",
    },
    BadFile {
        test: "empty_obj",
        files: &[("empty.obj", "# nothing\nv 0 0 0\n")],
        expect: &["EmptyScene {"],
        named: "empty.obj",
    },
    BadFile {
        test: "missing_texture",
        files: &[("scene.toml", TEXTURED)],
        expect: &["Texture {", "cannot read texture"],
        named: "tex.png",
    },
    BadFile {
        test: "texture_of_unknown_format",
        files: &[
            ("scene.toml", TEXTURED),
            ("tex.png", "not an image at all\n"),
        ],
        expect: &["Texture {", "unsupported texture format"],
        named: "tex.png",
    },
    BadFile {
        test: "texture_of_unsupported_format",
        files: &[
            ("scene.toml", TEXTURED),
            ("tex.png", "GIF89a\x01\x00\x01\x00"),
        ],
        expect: &["Texture {", "unsupported texture format gif"],
        named: "tex.png",
    },
    BadFile {
        test: "missing_cutout_mask",
        files: &[(
            "scene.toml",
            "format = 1\n[materials.m]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\nemission = [1, 1, 1]\ncutout = \"mask.png\"\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n",
        )],
        expect: &["Texture {", "cannot read texture"],
        named: "mask.png",
    },
    BadFile {
        test: "missing_mtl_texture",
        files: &[
            (
                "scene.obj",
                "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl lamp\nf 1 2 3\n",
            ),
            ("m.mtl", "newmtl lamp\nKe 1 1 1\nmap_Kd -bm 1 kd.png\n"),
        ],
        expect: &["Texture {", "cannot read texture"],
        named: "kd.png",
    },
    BadFile {
        test: "missing_gltf_texture",
        files: &[("scene.gltf", GLTF_TEXTURED)],
        expect: &["Texture {", "cannot read texture"],
        named: "tex.png",
    },
    BadFile {
        test: "gltf_image_data_uri_not_base64",
        files: &[(
            "scene.gltf",
            gltf_textured_uri!("data:image/png;base64,iVBOR*w0KGgo"),
        )],
        expect: &["Gltf {", "image 0: data URI is not valid base64"],
        named: "scene.gltf",
    },
    BadFile {
        test: "gltf_image_data_uri_without_base64",
        files: &[("scene.gltf", gltf_textured_uri!("data:image/png,abc"))],
        expect: &["Gltf {", "image 0: data URI is not base64-encoded"],
        named: "scene.gltf",
    },
    BadFile {
        // Valid base64 of "hello, world": not an image.
        test: "gltf_image_data_uri_not_an_image",
        files: &[(
            "scene.gltf",
            gltf_textured_uri!("data:image/png;base64,aGVsbG8sIHdvcmxk"),
        )],
        expect: &["Texture {"],
        named: "scene.gltf#image0",
    },
    BadFile {
        test: "no_emitter",
        files: &[("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")],
        expect: &["NoEmitter {"],
        named: "tri.obj",
    },
];

#[test]
fn every_bad_edit_is_its_own_error() {
    for (from, to, expect) in EDITS {
        let (result, path) = load_edited(from, to);
        let err = result.expect_err(to);
        let debug = format!("{err:?}");
        for fragment in *expect {
            assert!(
                debug.contains(fragment),
                "{to:?}: {fragment} not in {debug}"
            );
        }
        assert_names_file(&err, path);
    }
    // Just inside the range.
    load_edited("fov_y = 39.3", "fov_y = 179.9").0.unwrap();
}

#[test]
fn every_bad_file_is_its_own_error() {
    for BadFile {
        test,
        files,
        expect,
        named,
    } in FILES
    {
        let first = fixture(test, files);
        let err = load(&first).expect_err(test);
        let debug = format!("{err:?}");
        for fragment in *expect {
            assert!(
                debug.contains(fragment),
                "{test}: {fragment} not in {debug}"
            );
        }
        assert_names_file(&err, &first.with_file_name(named));
    }
}

#[test]
fn unknown_key_lists_the_known_ones() {
    let (result, _) = load_edited("albedo = [0.8, 0.8, 0.8]", "colour = [0.8, 0.8, 0.8]");
    let msg = result.unwrap_err().to_string();
    assert!(
        msg.contains("unknown key \"colour\" in [materials.white]"),
        "{msg}"
    );
    assert!(msg.contains("albedo") && msg.contains("emission"), "{msg}");
}

#[test]
fn extension_and_vertex_messages() {
    let path = fixture(
        "nan_message",
        &[("nan.obj", "v 0 0 0\nv 1 0 0\n\nv 0 NaN 0\nf 1 2 3\n")],
    );
    let msg = load(&path).unwrap_err().to_string();
    assert!(msg.contains("line 4: vertex has a nan coordinate"), "{msg}");
    let path = fixture("ply_message", &[("scene.ply", "ply\n")]);
    assert!(load(&path).unwrap_err().to_string().contains("\"ply\""));
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
fn empty_toml_scene() {
    let toml = "format = 1\n[materials.a]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n";
    let path = Path::new("empty.toml");
    let err = load_toml_str(toml, path).unwrap_err();
    assert!(matches!(err, LoadError::EmptyScene { .. }), "{err:?}");
    assert_names_file(&err, path);
}

#[test]
fn a_scene_without_emitter_loads_when_allowed() {
    let obj = fixture(
        "no_emitter_allowed",
        &[("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")],
    );
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
        ("textured.toml", TEXTURED),
    ];
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
        let err = load(&dir.join(name)).unwrap_err();
        lines.push(err.to_string().replace(&dir.display().to_string(), "<dir>"));
    }
    insta::assert_snapshot!(lines.join("\n"));
}

/// A PNG file of `width` × `height` (8-bit grey) with a valid signature and header and
/// `rest` after the header (CRCs computed, so only what is meant to be wrong is).
fn png(width: u32, height: u32, rest: &[u8]) -> Vec<u8> {
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(width.to_be_bytes());
    ihdr.extend(height.to_be_bytes());
    ihdr.extend([8, 0, 0, 0, 0]);
    out.extend(13u32.to_be_bytes());
    out.extend(&ihdr);
    let mut crc = flate2::Crc::new();
    crc.update(&ihdr);
    out.extend(crc.sum().to_be_bytes());
    out.extend(rest);
    out
}

/// Texture files that need bytes, not text: each must fail with one line naming the image.
#[test]
fn bad_texture_files_name_the_image() {
    let nan_exr = {
        let dir = crate::temp_dir("nan_exr_source");
        let path = dir.join("nan.exr");
        let img =
            image::Rgba32FImage::from_raw(2, 1, vec![0.5, 0.5, 0.5, 1.0, f32::NAN, 0.0, 0.0, 1.0])
                .unwrap();
        image::DynamicImage::ImageRgba32F(img).save(&path).unwrap();
        std::fs::read(&path).unwrap()
    };
    let cases: [(&str, Vec<u8>, &str); 5] = [
        ("zero_size", png(0, 4, b""), "tex.png"),
        (
            "truncated_png",
            png(4, 4, b"\x00\x00"),
            "corrupt png texture",
        ),
        (
            "corrupt_jpeg",
            b"\xff\xd8\xff\xe0garbage".to_vec(),
            "corrupt jpg texture",
        ),
        ("nan_texel", nan_exr, "nan texel at (1, 0)"),
        (
            "hdr_declares_more_than_it_holds",
            b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 8192\n\x02\x02\x20\x00".to_vec(),
            "more scanlines than",
        ),
    ];
    for (test, bytes, needle) in cases {
        let dir = crate::temp_dir(test);
        let scene = dir.join("scene.toml");
        std::fs::write(&scene, TEXTURED).unwrap();
        std::fs::write(dir.join("tex.png"), &bytes).unwrap();
        let err = load(&scene).expect_err(test);
        assert!(matches!(err, LoadError::Texture { .. }), "{test}: {err:?}");
        assert_names_file(&err, &dir.join("tex.png"));
        let msg = err.to_string();
        assert!(msg.contains(needle), "{test}: {msg}");
        assert!(!msg.contains('\n'), "{test}: {msg}");
    }
}
/// An OpenEXR file of `width` × `height` RGB texels from `texel(x, y)`.
fn write_exr(path: &Path, width: usize, height: usize, texel: impl Fn(usize, usize) -> f32 + Sync) {
    exr::prelude::write_rgb_file(path, width, height, |x, y| {
        let t = texel(x, y);
        (t, t, t)
    })
    .unwrap();
}

/// Test name, map file name, how to make it, fragments of the error.
type BadMap = (
    &'static str,
    &'static str,
    fn(&Path),
    &'static [&'static str],
);

/// Bad environment maps: how each file is made, and what the error must be (as in [`EDITS`]).
/// The scene (the valid `BASE` plus an environment light of that file) and `--env` must both
/// fail with an error naming the map.
const ENV_MAPS: &[BadMap] = &[
    ("env_missing", "sky.exr", |_| {}, &["Io {"]),
    (
        "env_corrupt",
        "sky.exr",
        |p| std::fs::write(p, "not an exr file").unwrap(),
        &["EnvironmentMap {", "cannot decode"],
    ),
    (
        "env_truncated",
        "sky.exr",
        |p| {
            write_exr(p, 16, 8, |_, _| 1.0);
            let bytes = std::fs::read(p).unwrap();
            std::fs::write(p, &bytes[..bytes.len() / 2]).unwrap();
        },
        &["EnvironmentMap {", "cannot decode"],
    ),
    (
        "env_png",
        "sky.png",
        |p| std::fs::write(p, "png").unwrap(),
        &["EnvironmentMap {", "unsupported image format"],
    ),
    (
        "env_square",
        "sky.exr",
        |p| write_exr(p, 8, 8, |_, _| 1.0),
        &["EnvironmentMap {", "8×8, not 2:1"],
    ),
    (
        "env_zero_size",
        "sky.hdr",
        |p| std::fs::write(p, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 0\n").unwrap(),
        &["EnvironmentMap {"],
    ),
    (
        // A header of a few dozen bytes declaring 32 M texels: refused before `image`
        // allocates them (every scanline takes at least 4 bytes of the file).
        "env_hdr_declares_more_than_it_holds",
        "sky.hdr",
        |p| {
            std::fs::write(
                p,
                "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4096 +X 8192\n\x02\x02\x20\x00",
            )
            .unwrap()
        },
        &["EnvironmentMap {", "8192x4096", "more scanlines than"],
    ),
    (
        "env_nan",
        "sky.exr",
        |p| {
            write_exr(
                p,
                16,
                8,
                |x, y| if (x, y) == (3, 5) { f32::NAN } else { 1.0 },
            )
        },
        &["EnvironmentMap {", "texel (3, 5) is not finite"],
    ),
    (
        "env_inf",
        "sky.exr",
        |p| write_exr(p, 16, 8, |x, _| if x == 15 { f32::INFINITY } else { 1.0 }),
        &["EnvironmentMap {", "texel (15, 0) is not finite"],
    ),
    (
        "env_black",
        "sky.exr",
        |p| write_exr(p, 16, 8, |_, _| 0.0),
        &["EnvironmentMap {", "black"],
    ),
];

#[test]
fn every_bad_environment_map_is_its_own_error() {
    for (test, name, make, expect) in ENV_MAPS {
        let dir = crate::temp_dir(test);
        let map = dir.join(name);
        make(&map);
        let scene = dir.join("scene.toml");
        std::fs::write(
            &scene,
            format!("{BASE}\n[[lights]]\ntype = \"environment\"\nfile = \"{name}\"\n"),
        )
        .unwrap();
        let options = LoadOptions {
            environment: Some(map.clone()),
            ..Default::default()
        };
        let base = dir.join("base.toml");
        std::fs::write(&base, BASE).unwrap();
        for err in [
            load(&scene).expect_err(test),
            load_with(&base, &options).expect_err(test),
        ] {
            let debug = format!("{err:?}");
            for fragment in *expect {
                assert!(
                    debug.contains(fragment),
                    "{test}: {fragment} not in {debug}"
                );
            }
            assert_names_file(&err, &map);
        }
    }
}

#[test]
fn a_good_environment_map_loads_and_lights_a_scene_alone() {
    let dir = crate::temp_dir("env_good");
    write_exr(&dir.join("sky.exr"), 16, 8, |x, y| {
        if x == 2 { -0.5 } else { (x + y) as f32 }
    });
    // No other emitter: the environment alone must do.
    let scene = dir.join("scene.toml");
    let without_lamp = BASE.replace("emission = [17.0, 12.0, 4.0]", "emission = [0.0, 0.0, 0.0]");
    std::fs::write(
        &scene,
        format!("{without_lamp}\n[[lights]]\ntype = \"environment\"\nfile = \"sky.exr\"\nscale = 2.0\nrotate = [0.0, 90.0, 0.0]\n"),
    )
    .unwrap();
    let description = load(&scene).unwrap();
    let env = description.environment.as_ref().unwrap();
    assert_eq!(env.scale, 2.0);
    // 90° about y: the map's +z (its centre) looks toward world +x.
    assert!((env.to_world * glam::Vec3::Z - glam::Vec3::X).length() < 1e-6);
    let scene::EnvironmentRadiance::Map(map) = &env.radiance else {
        panic!("{env:?}");
    };
    assert_eq!((map.width, map.height), (16, 8));
    // Row-major, top row first, as the file stores it; negative texels read as zero.
    assert_eq!(map.texels[16 * 3 + 5], glam::Vec3::splat(8.0));
    assert_eq!(map.texels[2], glam::Vec3::ZERO);
    assert!(
        description
            .notes
            .warnings
            .iter()
            .any(|w| w.contains("8 negative texels"))
    );
    scene::Scene::new(description).unwrap();
}

/// The size bound on Radiance HDR files refuses only what a file cannot hold: a map stored
/// uncompressed (4 bytes a texel, written here by hand: RGBE (128, 128, 128, 129) is 1.0) loads,
/// and its integral over the sphere is 4π.
#[test]
fn an_uncompressed_hdr_map_loads() {
    let dir = crate::temp_dir("hdr_uncompressed");
    let path = dir.join("sky.hdr");
    let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n".to_vec();
    for _ in 0..4 * 8 {
        bytes.extend_from_slice(&[128, 128, 128, 129]);
    }
    std::fs::write(&path, &bytes).unwrap();
    let (env, negative) = import::environment_from_file(&path).unwrap();
    assert_eq!(negative, 0);
    let total = env.integrated_radiance();
    for c in [total.x, total.y, total.z] {
        assert!((c - 4.0 * std::f32::consts::PI).abs() < 1e-3, "{total:?}");
    }
}
