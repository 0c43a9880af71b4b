//! Inputs that crashed a loader (found by the fuzz targets of `fuzz/`, or reported), each with
//! the one-line error it must give now; and the in-memory loading the fuzz targets rely on.

use std::io;
use std::path::Path;

use import::{LoadError, LoadOptions, MemoryFiles, load_from};

use crate::assert_names_file;

/// Loads `main` (a path in `files`) accepting scenes without emitters, as `fppm info` does.
fn load_memory(main: &str, files: MemoryFiles) -> Result<scene::SceneDescription, LoadError> {
    load_from(Path::new(main), files, &LoadOptions::allow_no_emitter())
}

#[track_caller]
fn assert_gltf_error(result: Result<scene::SceneDescription, LoadError>, file: &str, needle: &str) {
    let err = result.expect_err("the file must be refused");
    assert!(matches!(err, LoadError::Gltf { .. }), "{err:?}");
    assert_names_file(&err, Path::new(file));
    assert!(err.to_string().contains(needle), "{err}");
}

/// A triangle whose position buffer is a data URI, with `accessors` spelt as given.
fn triangle_gltf(accessors_key: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
"{accessors_key}":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}}]}}"#
    )
}

#[test]
fn memory_files_load_a_scene_and_its_references() {
    let toml = "format = 1\n[[shapes]]\ntype = \"mesh\"\nfile = \"meshes/tri.gltf\"\n";
    let files = MemoryFiles::new()
        .with("/mem/scene.toml", toml)
        .with("/mem/meshes/tri.gltf", triangle_gltf("accessors"));
    let d = load_memory("/mem/scene.toml", files).unwrap();
    assert_eq!(d.triangles.len(), 1);
    assert_eq!(d.triangles[0].positions[1], glam::Vec3::X);
}

/// Textures are read through the file source too (the `texture` fuzz target serves them from
/// memory); before, the texture cache read the file system whatever the source.
#[test]
fn memory_files_serve_the_textures_of_a_scene() {
    let mut png = io::Cursor::new(Vec::new());
    image::RgbImage::from_pixel(2, 1, image::Rgb([255, 0, 0]))
        .write_to(&mut png, image::ImageFormat::Png)
        .unwrap();
    let toml = "format = 1\n[materials.red]\ntype = \"diffuse\"\n\
                albedo = { texture = \"tex/red.png\" }\n\
                [[shapes]]\ntype = \"quad\"\ncorner = [0, 0, 0]\nedge1 = [1, 0, 0]\n\
                edge2 = [0, 1, 0]\nmaterial = \"red\"\n";
    let files = MemoryFiles::new()
        .with("/mem/scene.toml", toml)
        .with("/mem/tex/red.png", png.into_inner());
    let d = load_memory("/mem/scene.toml", files).unwrap();
    let textures = d.materials[0]
        .textures
        .as_deref()
        .expect("a textured material");
    let color = textures.color.as_ref().expect("an albedo texture");
    assert_eq!(color.image.resolution(), (2, 1));
    // An 8-bit colour texture is sRGB-decoded: 255 is 1, 0 is 0.
    assert_eq!(color.color(glam::Vec2::new(0.5, 0.5)), glam::Vec3::X);
}

#[test]
fn a_resolver_closure_serves_files_and_missing_ones_name_the_path() {
    let obj = "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let resolver = move |p: &Path| -> io::Result<Vec<u8>> {
        match p.to_str() {
            Some("/mem/a.obj") => Ok(obj.as_bytes().to_vec()),
            _ => Err(io::ErrorKind::NotFound.into()),
        }
    };
    let d = load_from(
        Path::new("/mem/a.obj"),
        resolver,
        &LoadOptions::allow_no_emitter(),
    )
    .unwrap();
    assert_eq!(d.triangles.len(), 1);
    // The missing MTL is a warning, as on the file system.
    assert!(
        d.notes.warnings.iter().any(|w| w.contains("nowhere.mtl")),
        "{:?}",
        d.notes.warnings
    );
    let err = load_memory("/mem/b.obj", MemoryFiles::new()).unwrap_err();
    assert!(matches!(err, LoadError::Io { .. }), "{err:?}");
    assert_names_file(&err, Path::new("/mem/b.obj"));
}

/// Issue #19: a misspelt `"accessors"` key made gltf-json 1.4.1's validation index an empty
/// accessor list (`mesh.rs:151`) and `fppm info` exit with a panic.
#[test]
fn gltf_with_misspelt_accessors_key_is_an_error_not_a_panic() {
    let files = MemoryFiles::new().with("/mem/box.gltf", triangle_gltf("acessors"));
    assert_gltf_error(
        load_memory("/mem/box.gltf", files),
        "/mem/box.gltf",
        "POSITION accessor 0 does not exist",
    );
}

/// gltf's own buffer importer unwraps the percent-decoding of a relative URI, which panics
/// when the escapes are not UTF-8; the loader reads buffers itself.
#[test]
fn gltf_buffer_uri_with_non_utf8_escapes_is_an_error() {
    let gltf = triangle_gltf("accessors").replace(
        "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA",
        "%FF.bin",
    );
    let files = MemoryFiles::new().with("/mem/t.gltf", gltf);
    assert_gltf_error(
        load_memory("/mem/t.gltf", files),
        "/mem/t.gltf",
        "not UTF-8",
    );
}

#[test]
fn gltf_external_buffer_is_read_from_the_source() {
    let gltf = triangle_gltf("accessors").replace(
        "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA",
        "tri%20angle.bin",
    );
    let mut bin = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    let files = MemoryFiles::new()
        .with("/mem/t.gltf", gltf.clone())
        .with("/mem/tri angle.bin", bin.clone());
    let d = load_memory("/mem/t.gltf", files).unwrap();
    assert_eq!(d.triangles[0].positions[2], glam::Vec3::Y);
    // A buffer shorter than its declared length is refused with both lengths.
    let files = MemoryFiles::new()
        .with("/mem/t.gltf", gltf)
        .with("/mem/tri angle.bin", &bin[..20]);
    assert_gltf_error(
        load_memory("/mem/t.gltf", files),
        "/mem/t.gltf",
        "holds 20 bytes, the file says 36",
    );
}

/// Found by the `glb` fuzz target: a GLB header whose total length is below 12 made gltf
/// 1.4.1 subtract with overflow (`binary.rs`).
#[test]
fn glb_with_a_length_shorter_than_its_header_is_an_error() {
    let mut glb = b"glTF\x02\x00\x00\x00\x00\x00\x00\x00".to_vec();
    glb.extend_from_slice(&[0; 20]);
    let files = MemoryFiles::new().with("/mem/a.glb", glb);
    assert_gltf_error(
        load_memory("/mem/a.glb", files),
        "/mem/a.glb",
        "less than the 12-byte header",
    );
}

/// Found by the `gltf` fuzz target: positions read from a `VEC2` accessor failed a debug
/// assertion of gltf's reader (`accessor/util.rs`: item size 12, accessor size 8).
#[test]
fn gltf_positions_of_the_wrong_type_are_an_error() {
    let files = MemoryFiles::new().with(
        "/mem/t.gltf",
        triangle_gltf("accessors").replace("VEC3", "VEC2"),
    );
    assert_gltf_error(
        load_memory("/mem/t.gltf", files),
        "/mem/t.gltf",
        "accessor 0 (POSITION) is Vec2 of F32",
    );
}

/// `FLOAT` indices reach an `unreachable!` in gltf's index reader (`mesh/mod.rs`).
#[test]
fn gltf_float_indices_are_an_error() {
    let gltf = triangle_gltf("accessors")
        .replace(
            r#""attributes":{"POSITION":0}"#,
            r#""attributes":{"POSITION":0},"indices":1"#,
        )
        .replace(
            r#""max":[1,1,0]}"#,
            r#""max":[1,1,0]},{"bufferView":0,"componentType":5126,"count":3,"type":"SCALAR"}"#,
        );
    let files = MemoryFiles::new().with("/mem/t.gltf", gltf);
    assert_gltf_error(
        load_memory("/mem/t.gltf", files),
        "/mem/t.gltf",
        "accessor 1 (indices) is Scalar of F32",
    );
}

/// Found by the `ply` fuzz target: a binary PLY declaring 2 222 222 222 records of an element
/// without properties passed the size check (zero bytes each) and kept the parser busy for
/// minutes; such records now count one byte each against the file's size.
#[test]
fn ply_with_billions_of_empty_records_is_refused() {
    let scene = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n\
                 Shape \"plymesh\" \"string filename\" [ \"m.ply\" ]\n";
    let mut ply =
        b"ply\nformat binary_little_endian 1.0\nelement vertexce 2222222222\nend_header\n".to_vec();
    ply.extend_from_slice(&[0x79, 0, 0x32, 0x32]);
    let files = MemoryFiles::new()
        .with("/mem/s.pbrt", scene)
        .with("/mem/m.ply", ply);
    let err = load_memory("/mem/s.pbrt", files).unwrap_err();
    // The pbrt loader reports it at the Shape line, with the PLY file's own message.
    assert!(
        matches!(err, LoadError::Pbrt { line: Some(4), .. }),
        "{err:?}"
    );
    assert_names_file(&err, Path::new("/mem/s.pbrt"));
    assert!(
        err.to_string().contains("declares 2222222222 vertexce"),
        "{err}"
    );
}

/// Found by the `obj` fuzz target: the relative texture index `-12` with four `vt` defined made
/// tobj 4.0.5 wrap the offset around and overflow when scaling it (`lib.rs:852`).
#[test]
fn obj_relative_index_before_the_first_element_is_an_error() {
    let obj = "v -1.0 -1.0  0.0\nv  1.0 0  0.0\nv  1.0  1.0  0.0\n\nvt0 1.0\nvt 0.0 0.0\n\
               vt 0.0 1.0\nvt 1.0 0.0\n\nf 2/1 3/-12 1/3\nf 2/1 6/4 3/2";
    let files = MemoryFiles::new().with("/mem/a.obj", obj);
    let err = load_memory("/mem/a.obj", files).unwrap_err();
    assert!(
        matches!(err, LoadError::Obj { line: Some(10), .. }),
        "{err:?}"
    );
    assert_names_file(&err, Path::new("/mem/a.obj"));
    assert!(
        err.to_string()
            .contains("relative texture coordinate index -12, but only 3 are defined"),
        "{err}"
    );
    // Index 0 and indices beyond the file's count are refused the same way.
    for (face, needle) in [
        ("f 1/1 2/2 3/0", "texture coordinate index 0"),
        (
            "f 1/1 2/2 3/9",
            "texture coordinate index 9, but the file defines 3",
        ),
        (
            "f 1//-2 2//1 3//1",
            "relative normal index -2, but only 1 are defined",
        ),
    ] {
        let obj = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n{face}\n");
        let files = MemoryFiles::new().with("/mem/b.obj", obj);
        let err = load_memory("/mem/b.obj", files).unwrap_err();
        assert!(err.to_string().contains(needle), "{face}: {err}");
    }
}

/// Found by the `gltf` fuzz target: a buffer view whose stride (11) is shorter than a position
/// (12 bytes) failed a debug assertion of gltf's reader (`accessor/util.rs:376`); a count of 0
/// underflows there.
#[test]
fn gltf_accessor_layouts_gltf_cannot_read_are_errors() {
    let strided = triangle_gltf("accessors").replace(
        r#""bufferViews":[{"buffer":0,"byteLength":36}]"#,
        r#""bufferViews":[{"buffer":0,"byteLength":36,"byteStride":11}]"#,
    );
    let files = MemoryFiles::new().with("/mem/t.gltf", strided);
    assert_gltf_error(
        load_memory("/mem/t.gltf", files),
        "/mem/t.gltf",
        "accessor 0 (POSITION): buffer view 0 has a stride of 11 bytes, less than its 12-byte items",
    );
    let empty = triangle_gltf("accessors").replace(r#""count":3"#, r#""count":0"#);
    let files = MemoryFiles::new().with("/mem/t.gltf", empty);
    assert_gltf_error(
        load_memory("/mem/t.gltf", files),
        "/mem/t.gltf",
        "no items (count 0)",
    );
}

/// Found by the `gltf` fuzz target: a `TEXCOORD_0` accessor of `VEC3` (or of `UNSIGNED_INT`)
/// failed a debug assertion of gltf's reader (`accessor/util.rs:371`, the item's size), and
/// read texture coordinates across item boundaries without it. Texture coordinates are checked
/// like positions: `VEC2` of float, or of normalized unsigned byte or short.
#[test]
fn gltf_texture_coordinates_of_the_wrong_type_are_errors() {
    let with_uv = |uv_type: &str, component: u32| {
        triangle_gltf("accessors")
            .replace(r#""attributes":{"POSITION":0}"#, r#""attributes":{"POSITION":0,"TEXCOORD_0":1}"#)
            .replace(
                r#""max":[1,1,0]}]"#,
                &format!(
                    r#""max":[1,1,0]}},{{"bufferView":0,"componentType":{component},"count":3,"type":"{uv_type}"}}]"#
                ),
            )
    };
    for (uv_type, component, what) in [("VEC3", 5126, "Vec3 of F32"), ("VEC2", 5125, "Vec2 of U32")]
    {
        let files = MemoryFiles::new().with("/mem/t.gltf", with_uv(uv_type, component));
        assert_gltf_error(
            load_memory("/mem/t.gltf", files),
            "/mem/t.gltf",
            &format!("accessor 1 (TEXCOORD) is {what}"),
        );
    }
    // A valid one still loads (VEC2 of float, 24 of the buffer's 36 bytes).
    let files = MemoryFiles::new().with("/mem/t.gltf", with_uv("VEC2", 5126));
    let d = load_memory("/mem/t.gltf", files).unwrap();
    assert_eq!(d.triangles.len(), 1);
}

/// Found by the `glb` fuzz target: a texture's image in a buffer view without a `mimeType`
/// panicked in gltf's `Image::source` (`image.rs:128`, an unwrap), as does an image with
/// neither a URI nor a buffer view.
#[test]
fn gltf_images_gltf_cannot_describe_are_errors() {
    for (image, needle) in [
        (
            r#"{"bufferView":0}"#,
            "image 0 is stored in a buffer view but has no mimeType",
        ),
        ("{}", "image 0 has neither a uri nor a bufferView"),
    ] {
        let textured = triangle_gltf("accessors")
            .replace(r#""attributes":{"POSITION":0}"#, r#""attributes":{"POSITION":0},"material":0"#)
            .replace(
                r#""bufferViews""#,
                &format!(
                    r#""materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}}}}],"textures":[{{"source":0}}],"images":[{image}],"bufferViews""#
                ),
            );
        let files = MemoryFiles::new().with("/mem/t.gltf", textured);
        assert_gltf_error(load_memory("/mem/t.gltf", files), "/mem/t.gltf", needle);
    }
}

/// Found by the `envmap` fuzz target: a 453-byte EXR declaring a data window of
/// 520 093 700 × 2 texels was decoded (two seconds and 2 GB of memory) before the map was found
/// not to be 2:1. Its size is now checked from the header, before anything is decoded.
#[test]
fn environment_map_declaring_a_huge_image_is_refused_from_its_header() {
    let exr = include_bytes!("../fuzz/envmap-huge-data-window.exr");
    let toml = "format = 1\n[materials.grey]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
                [[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"grey\"\n\
                [[lights]]\ntype = \"environment\"\nfile = \"sky.exr\"\n";
    let files = MemoryFiles::new()
        .with("/mem/scene.toml", toml)
        .with("/mem/sky.exr", exr.to_vec());
    let err = load_memory("/mem/scene.toml", files).expect_err("the map must be refused");
    assert!(matches!(err, LoadError::EnvironmentMap { .. }), "{err:?}");
    assert_names_file(&err, Path::new("/mem/sky.exr"));
    assert!(err.to_string().contains("520093700×2, not 2:1"), "{err}");
}

/// Found by the `texture` fuzz target (as a timeout of the dev-profile build): a 519-byte EXR
/// texture whose display window is 16 252 927 × 2 texels was decoded into an image that large,
/// 3.7 s and 1 GB in a release build. Its windows are now bounded by the file's size before
/// decoding, as `film`'s EXR reader bounds its samples.
#[test]
fn texture_declaring_a_huge_data_window_is_refused_from_its_header() {
    let exr = include_bytes!("../fuzz/texture-huge-data-window.exr");
    let toml = "format = 1\n[materials.t]\ntype = \"diffuse\"\nalbedo = { texture = \"t.exr\" }\n\
                [[shapes]]\ntype = \"quad\"\ncorner = [0, 0, 0]\nedge1 = [1, 0, 0]\n\
                edge2 = [0, 1, 0]\nmaterial = \"t\"\n";
    let files = MemoryFiles::new()
        .with("/mem/scene.toml", toml)
        .with("/mem/t.exr", exr.to_vec());
    let err = load_memory("/mem/scene.toml", files).expect_err("the texture must be refused");
    assert!(matches!(err, LoadError::Texture { .. }), "{err:?}");
    assert_names_file(&err, Path::new("/mem/t.exr"));
    assert!(
        err.to_string()
            .contains("more than a 519-byte file can hold"),
        "{err}"
    );
}

/// The `vol` fuzz target's fixed scene (`fuzz/stubs/vol_scene.toml`) loads from memory with a
/// good grid and builds; the free flights and transmittances the target runs through it stay
/// finite; a grid the header of which lies is one line naming the `.vol`.
#[test]
fn the_vol_targets_scene_loads_its_grid_from_memory() {
    let stub = include_str!("../../../../fuzz/stubs/vol_scene.toml");
    let ramp: Vec<f32> = (0..24).map(|i| (i % 4) as f32 * 0.5).collect();
    let good = import::write_vol([4, 3, 2], glam::Vec3::ZERO, glam::Vec3::ONE, &ramp);
    let files = MemoryFiles::new()
        .with("/fuzz/scene.toml", stub)
        .with("/fuzz/smoke.vol", good.clone());
    let d = load_memory("/fuzz/scene.toml", files).unwrap();
    let scene = scene::Scene::new(d).unwrap();
    let medium = &scene.media().list[0];
    let mut state = 0u32;
    let mut u = move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 24) as f32
    };
    for (origin, direction) in [
        (glam::Vec3::new(-2.0, 0.1, 0.2), glam::Vec3::X),
        (glam::Vec3::new(0.0, 2.0, 0.0), -glam::Vec3::Y),
    ] {
        let tr = medium.transmittance_along(origin, direction, 4.0, &mut u);
        assert!(
            tr.is_finite() && tr.min_element() >= 0.0 && tr.max_element() <= 1.0,
            "{tr}"
        );
        match medium.sample_free_flight(
            origin,
            direction,
            4.0,
            glam::Vec3::splat(1.0 / 3.0),
            &mut u,
        ) {
            scene::FreeFlight::Scatter { t, weight } => {
                assert!(
                    (0.0..=4.0).contains(&t) && weight.is_finite(),
                    "{t} {weight}"
                );
            }
            scene::FreeFlight::Pass { weight } => assert!(weight.is_finite(), "{weight}"),
        }
    }
    let files = MemoryFiles::new()
        .with("/fuzz/scene.toml", stub)
        .with("/fuzz/smoke.vol", &good[..good.len() - 1]);
    let err = load_memory("/fuzz/scene.toml", files).unwrap_err();
    assert_names_file(&err, Path::new("/fuzz/smoke.vol"));
}
