//! A hand-written glTF: node hierarchy, negative scale, camera, spot light, a skipped
//! line primitive, emissive strength.

use glam::Vec3;
use import::{LoadError, load};
use scene::Light;

fn assert_close(a: Vec3, b: Vec3) {
    assert!((a - b).length() < 1e-5, "{a} != {b}");
}

const GLTF: &str = r#"{
  "asset": { "version": "2.0" },
  "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
  "extensions": { "KHR_lights_punctual": { "lights": [
    { "type": "spot", "color": [1.0, 0.5, 0.25], "intensity": 3.0,
      "spot": { "innerConeAngle": 0.2, "outerConeAngle": 0.4 } } ] } },
  "scene": 0,
  "scenes": [ { "nodes": [0] } ],
  "nodes": [
    { "translation": [0, 0, -5], "children": [1, 2, 3, 4, 5] },
    { "mesh": 0, "rotation": [0, 0, 0.70710678, 0.70710678] },
    { "mesh": 0, "scale": [-1, 1, 1] },
    { "camera": 0, "translation": [0, 0, 10] },
    { "rotation": [0.70710678, 0, 0, 0.70710678],
      "extensions": { "KHR_lights_punctual": { "light": 0 } } },
    { "mesh": 1 }
  ],
  "cameras": [ { "type": "perspective",
                 "perspective": { "yfov": 0.5, "aspectRatio": 2.0, "znear": 0.1 } } ],
  "materials": [ { "name": "glow", "emissiveFactor": [1, 1, 1],
                   "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": 2 } },
                   "pbrMetallicRoughness": { "baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0 } } ],
  "meshes": [
    { "primitives": [ { "attributes": { "POSITION": 0 }, "material": 0 } ] },
    { "primitives": [ { "attributes": { "POSITION": 0 }, "mode": 1 } ] }
  ],
  "accessors": [ { "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0] } ],
  "bufferViews": [ { "buffer": 0, "byteLength": 36 } ],
  "buffers": [ { "uri": "tri.bin", "byteLength": 36 } ]
}"#;

fn write(test: &str, gltf: &str) -> std::path::PathBuf {
    let dir = crate::temp_dir(test);
    let floats: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    std::fs::write(dir.join("tri.bin"), bytes).unwrap();
    let path = dir.join("scene.gltf");
    std::fs::write(&path, gltf).unwrap();
    path
}

#[test]
fn hierarchy_camera_light_and_materials() {
    let scene = load(&write("gltf_hierarchy", GLTF)).unwrap();

    // Node 1: rotated 90° about z, then moved by the parent to z = −5.
    assert_eq!(scene.triangles.len(), 2);
    let [a, b, c] = scene.triangles[0].positions;
    assert_close(a, Vec3::new(0.0, 0.0, -5.0));
    assert_close(b, Vec3::new(0.0, 1.0, -5.0));
    assert_close(c, Vec3::new(-1.0, 0.0, -5.0));
    // Node 2: mirrored in x; the winding is swapped so the front still faces +z.
    for t in &scene.triangles {
        let [a, b, c] = t.positions;
        assert!((b - a).cross(c - a).z > 0.0, "{t:?}");
    }

    // Emission = factor × strength; metallic 0 → diffuse base colour.
    let glow = &scene.materials[0];
    assert_eq!(glow.emission, Vec3::splat(2.0));
    assert_eq!(
        glow.kind,
        scene::MaterialKind::Diffuse(scene::Diffuse {
            albedo: Vec3::splat(0.5)
        })
    );

    // Camera: world position (0, 0, 5), looking down −z; film from the aspect ratio.
    assert_close(scene.camera.position, Vec3::new(0.0, 0.0, 5.0));
    assert_close(
        (scene.camera.look_at - scene.camera.position).normalize(),
        Vec3::NEG_Z,
    );
    assert_close(scene.camera.up, Vec3::Y);
    assert_eq!(scene.camera.fov_y, 0.5);
    assert_eq!((scene.film.width, scene.film.height), (512, 256));
    assert!(!scene.notes.camera_framed);

    // Spot light: node −z rotated 90° about x points along +y; colour × intensity.
    let [
        Light::Spot {
            position,
            direction,
            intensity,
            cone_angle,
            falloff_start,
        },
    ] = scene.lights[..]
    else {
        panic!("{:?}", scene.lights)
    };
    assert_close(position, Vec3::new(0.0, 0.0, -5.0));
    assert_close(direction, Vec3::Y);
    assert_close(intensity, Vec3::new(3.0, 1.5, 0.75));
    assert_eq!((cone_angle, falloff_start), (0.4, 0.2));

    // The line primitive is skipped with a warning.
    assert!(
        scene.notes.warnings.iter().any(|w| w.contains("skipped")),
        "{:?}",
        scene.notes.warnings
    );
}

#[test]
fn missing_buffer_is_a_gltf_error() {
    let path = write("gltf_missing_buffer", &GLTF.replace("tri.bin", "gone.bin"));
    let err = load(&path).unwrap_err();
    assert!(matches!(err, LoadError::Gltf { .. }), "{err:?}");
    crate::assert_names_file(&err, &path);
}

#[test]
fn nan_position_in_gltf() {
    let dir = crate::temp_dir("gltf_nan");
    let floats: [f32; 9] = [0.0, 0.0, 0.0, f32::NAN, 0.0, 0.0, 0.0, 1.0, 0.0];
    let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    std::fs::write(dir.join("tri.bin"), bytes).unwrap();
    let path = dir.join("scene.gltf");
    std::fs::write(&path, GLTF).unwrap();
    let err = load(&path).unwrap_err();
    assert!(
        matches!(err, LoadError::NonFiniteVertex { what: "nan", .. }),
        "{err:?}"
    );
    crate::assert_names_file(&err, &path);
}

#[test]
fn unsupported_required_extension() {
    let gltf = GLTF.replacen(
        "\"extensionsUsed\"",
        "\"extensionsRequired\": [\"KHR_mesh_quantization\"], \"extensionsUsed\"",
        1,
    );
    let path = write("gltf_required_extension", &gltf);
    let err = load(&path).unwrap_err();
    assert!(matches!(err, LoadError::Gltf { .. }), "{err:?}");
    crate::assert_names_file(&err, &path);
}

#[test]
fn accessor_larger_than_its_buffer_is_an_error() {
    let gltf = GLTF.replace("\"count\": 3", "\"count\": 300");
    let path = write("gltf_short_buffer", &gltf);
    let err = load(&path).unwrap_err();
    assert!(matches!(err, LoadError::Gltf { .. }), "{err:?}");
    crate::assert_names_file(&err, &path);
}

#[test]
fn index_out_of_range_is_an_error() {
    // A second buffer view holds u16 indices 0, 1, 7 (7 is past the 3 vertices).
    let dir = crate::temp_dir("gltf_bad_index");
    let floats: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let mut bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    bytes.extend([0u16, 1, 7, 0].iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.join("tri.bin"), bytes).unwrap();
    let gltf = GLTF
        .replace(
            "\"attributes\": { \"POSITION\": 0 }, \"material\": 0",
            "\"attributes\": { \"POSITION\": 0 }, \"indices\": 1, \"material\": 0",
        )
        .replace(
            "\"min\": [0, 0, 0], \"max\": [1, 1, 0] } ]",
            "\"min\": [0, 0, 0], \"max\": [1, 1, 0] },\n    { \"bufferView\": 1, \"componentType\": 5123, \"count\": 3, \"type\": \"SCALAR\" } ]",
        )
        .replace(
            "\"bufferViews\": [ { \"buffer\": 0, \"byteLength\": 36 } ]",
            "\"bufferViews\": [ { \"buffer\": 0, \"byteLength\": 36 }, { \"buffer\": 0, \"byteOffset\": 36, \"byteLength\": 6 } ]",
        )
        .replace("\"byteLength\": 36 } ]\n}", "\"byteLength\": 44 } ]\n}");
    let path = dir.join("scene.gltf");
    std::fs::write(&path, gltf).unwrap();
    let err = load(&path).unwrap_err();
    assert!(matches!(err, LoadError::Gltf { .. }), "{err:?}");
    crate::assert_names_file(&err, &path);
    assert!(err.to_string().contains("index 7"), "{err}");
}

/// A 2 × 1 PNG, red on the left and blue on the right, written by the `image` crate's encoder.
fn red_blue_png() -> Vec<u8> {
    let image = image::RgbaImage::from_raw(2, 1, vec![255, 0, 0, 255, 0, 0, 255, 255]).unwrap();
    let mut png = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    png
}

/// One triangle whose material's base colour is image 0, given by `uri`.
fn gltf_with_image(uri: &str) -> String {
    GLTF.replace(
        r#""pbrMetallicRoughness": { "baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0 }"#,
        r#""pbrMetallicRoughness": { "baseColorTexture": { "index": 0 }, "metallicFactor": 0 }"#,
    )
    .replace(
        r#""meshes": ["#,
        &format!(
            r#""textures": [ {{ "source": 0 }} ], "images": [ {{ "uri": "{uri}" }} ], "meshes": ["#
        ),
    )
}

#[test]
fn image_embedded_as_a_data_uri_is_read() {
    let uri = format!("data:image/png;base64,{}", base64::encode(red_blue_png()));
    let gltf = gltf_with_image(&uri);
    assert!(gltf.contains("baseColorTexture") && gltf.contains(&uri));
    let path = write("gltf_data_uri_image", &gltf);
    let scene = load(&path).unwrap();
    let textures = scene.materials[0].textures.as_deref().expect("textured");
    let color = textures.color.as_ref().expect("a base colour texture");
    assert_eq!(color.image.resolution(), (2, 1));
    // Texel centres (sRGB 255 and 0 decode to 1 and 0 exactly).
    assert_close(color.color(glam::Vec2::new(0.25, 0.5)), Vec3::X);
    assert_close(color.color(glam::Vec2::new(0.75, 0.5)), Vec3::Z);
    // Named after the glTF file, as an image in a buffer view is.
    assert_eq!(
        color.image.path(),
        std::path::Path::new(&format!("{}#image0", path.display()))
    );
    assert!(
        scene.notes.warnings.iter().all(|w| !w.contains("data")),
        "{:?}",
        scene.notes.warnings
    );
}

#[test]
fn image_data_uri_read_as_a_file_gives_the_same_texels() {
    // The same PNG beside the file: the data URI is decoded to the same bytes.
    let path = write("gltf_data_uri_vs_file", &gltf_with_image("rb.png"));
    std::fs::write(path.with_file_name("rb.png"), red_blue_png()).unwrap();
    let from_file = load(&path).unwrap();
    let uri = format!("data:image/png;base64,{}", base64::encode(red_blue_png()));
    let from_uri = load(&write("gltf_data_uri_vs_file2", &gltf_with_image(&uri))).unwrap();
    let texture = |s: &scene::SceneDescription| {
        s.materials[0]
            .textures
            .as_deref()
            .unwrap()
            .color
            .clone()
            .unwrap()
    };
    let (a, b) = (texture(&from_file), texture(&from_uri));
    for uv in [(0.1, 0.5), (0.5, 0.5), (0.9, 0.2)] {
        let uv = glam::Vec2::from(uv);
        assert_eq!(a.lookup(uv), b.lookup(uv));
    }
}

/// One triangle with normals, texture coordinates and `TANGENT`s (given unnormalised, all
/// with w = −1), drawn by three nodes: as it is, mirrored by a scale of −1 along x, and under a
/// material without a normal map.
fn gltf_with_tangents() -> String {
    let floats: [f32; 3 * 3 + 3 * 3 + 3 * 2 + 3 * 4] = [
        // POSITION
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, //
        // NORMAL
        0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, //
        // TEXCOORD_0
        0.0, 1.0, 1.0, 1.0, 0.0, 0.0, //
        // TANGENT
        2.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0, -1.0, 1.0, 1.0, 0.0, -1.0,
    ];
    let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    let png = base64::encode(red_blue_png());
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1,2]}}],
"nodes":[{{"mesh":0}},{{"mesh":0,"scale":[-1,1,1]}},{{"mesh":1}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1,"TEXCOORD_0":2,"TANGENT":3}},"material":0}}]}},
          {{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1,"TEXCOORD_0":2,"TANGENT":3}},"material":1}}]}}],
"materials":[{{"normalTexture":{{"index":0}},"emissiveFactor":[1,1,1],"pbrMetallicRoughness":{{"metallicFactor":0}}}},
             {{"pbrMetallicRoughness":{{"metallicFactor":0}}}}],
"textures":[{{"source":0}}],"images":[{{"uri":"data:image/png;base64,{png}"}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
             {{"bufferView":0,"byteOffset":36,"componentType":5126,"count":3,"type":"VEC3"}},
             {{"bufferView":0,"byteOffset":72,"componentType":5126,"count":3,"type":"VEC2"}},
             {{"bufferView":0,"byteOffset":96,"componentType":5126,"count":3,"type":"VEC4"}}],
"bufferViews":[{{"buffer":0,"byteLength":{len}}}],
"buffers":[{{"byteLength":{len},"uri":"data:application/octet-stream;base64,{data}"}}]}}"#,
        len = bytes.len(),
        data = base64::encode(&bytes),
    )
}

#[test]
fn tangents_are_read_under_a_normal_map_and_follow_the_node() {
    let scene = load(&write("gltf_tangents", &gltf_with_tangents())).unwrap();
    assert_eq!(scene.triangles.len(), 3);
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let close = |got: [[f32; 4]; 3], want: [[f32; 4]; 3]| {
        for (g, w) in got.iter().zip(&want) {
            let d = glam::Vec4::from_array(*g) - glam::Vec4::from_array(*w);
            assert!(d.length() < 1e-6, "{got:?} != {want:?}");
        }
    };
    // As given: unit xyz, w kept.
    close(
        scene.triangles[0].tangents.expect("tangents"),
        [
            [1.0, 0.0, 0.0, -1.0],
            [0.0, 1.0, 0.0, -1.0],
            [h, h, 0.0, -1.0],
        ],
    );
    // Mirrored in x: x negated, the winding swapped (vertices 1 and 2), and w turned around
    // (B = w·(N × T) must stay the mirror image of the unmirrored bitangent).
    assert_eq!(
        scene.triangles[1].positions,
        [Vec3::ZERO, Vec3::Y, Vec3::new(-1.0, 0.0, 0.0)]
    );
    close(
        scene.triangles[1].tangents.expect("tangents"),
        [
            [-1.0, 0.0, 0.0, 1.0],
            [-h, h, 0.0, 1.0],
            [0.0, 1.0, 0.0, 1.0],
        ],
    );
    // No normal map: the tangents are not kept.
    assert_eq!(scene.triangles[2].tangents, None);
}

#[test]
fn tangent_accessor_of_the_wrong_type_is_an_error() {
    let gltf = gltf_with_tangents().replace(
        r#""byteOffset":96,"componentType":5126,"count":3,"type":"VEC4""#,
        r#""byteOffset":96,"componentType":5126,"count":3,"type":"VEC3""#,
    );
    let path = write("gltf_tangent_vec3", &gltf);
    let err = load(&path).unwrap_err();
    assert!(err.to_string().contains("(TANGENT) is Vec3"), "{err}");
    crate::assert_names_file(&err, &path);
}

#[test]
fn tangents_follow_a_mirroring_toml_transform() {
    // The glTF of `gltf_with_tangents` as a mesh of a TOML scene, mirrored in x by the
    // transform: node 0's triangle ends up as node 1's does inside the glTF.
    let gltf = write("gltf_tangents_in_toml", &gltf_with_tangents());
    let toml = gltf.with_file_name("scene.toml");
    std::fs::write(
        &toml,
        "format = 1\n[[shapes]]\ntype = \"mesh\"\nfile = \"scene.gltf\"\ntransform = { scale = [-1.0, 1.0, 1.0] }\n",
    )
    .unwrap();
    let scene = load(&toml).unwrap();
    let inside = load(&gltf).unwrap();
    assert_eq!(scene.triangles[0].positions, inside.triangles[1].positions);
    let (got, want) = (
        scene.triangles[0].tangents.expect("tangents"),
        inside.triangles[1].tangents.expect("tangents"),
    );
    for (g, w) in got.iter().zip(&want) {
        let d = glam::Vec4::from_array(*g) - glam::Vec4::from_array(*w);
        assert!(d.length() < 1e-6, "{got:?} != {want:?}");
    }
}

/// NormalTangentMirrorTest's own `TANGENT`s (exported by Blender, which computes MikkTSpace)
/// against the tangents generated when the attribute is removed: the same frames, w included.
#[test]
fn generated_tangents_match_the_files_own() {
    let dir = crate::shared_scenes()
        .join("gltf/NormalTangentMirrorTest/glTF")
        .canonicalize()
        .unwrap();
    let original = dir.join("NormalTangentMirrorTest.gltf");
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&original).unwrap()).unwrap();
    for mesh in json["meshes"].as_array_mut().unwrap() {
        for prim in mesh["primitives"].as_array_mut().unwrap() {
            prim["attributes"]
                .as_object_mut()
                .unwrap()
                .remove("TANGENT");
        }
    }
    // The copy reads the shared buffer and images where they are.
    for list in ["buffers", "images"] {
        for item in json[list].as_array_mut().unwrap() {
            let uri = item["uri"].as_str().unwrap();
            item["uri"] = dir.join(uri).to_string_lossy().into_owned().into();
        }
    }
    let copy = crate::temp_dir("gltf_generated_tangents").join("no-tangents.gltf");
    std::fs::write(&copy, serde_json::to_string(&json).unwrap()).unwrap();

    let options = import::LoadOptions::allow_no_emitter();
    let with = import::load_with(&original, &options).unwrap();
    let without = import::load_with(&copy, &options).unwrap();
    assert_eq!(with.triangles.len(), without.triangles.len());
    let (mut corners, mut close, mut same_sign) = (0usize, 0usize, 0usize);
    for (a, b) in with.triangles.iter().zip(&without.triangles) {
        let (Some(ta), Some(tb)) = (a.tangents, b.tangents) else {
            panic!("a triangle without tangents");
        };
        for (ta, tb) in ta.iter().zip(&tb) {
            corners += 1;
            let (va, vb) = (Vec3::from_slice(ta), Vec3::from_slice(tb));
            if va.normalize().dot(vb.normalize()) > 0.996 {
                close += 1; // within 5°
            }
            if ta[3] == tb[3] {
                same_sign += 1;
            }
        }
    }
    println!("{corners} corners: {close} within 5°, {same_sign} with the same w");
    assert!(
        close as f64 >= 0.99 * corners as f64,
        "{close} of {corners} within 5°"
    );
    assert!(
        same_sign as f64 >= 0.99 * corners as f64,
        "{same_sign} of {corners} with the same w"
    );
}
