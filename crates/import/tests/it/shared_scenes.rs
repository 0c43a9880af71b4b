//! Every scene under `shared/scenes`: triangle, emitter, light and camera counts checked
//! against counts made here independently from the files' text (OBJ `f` lines, MTL `Ke`,
//! glTF JSON accessors walked through the node tree), and a YAML snapshot of each summary.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use import::{LoadError, LoadOptions, load, load_with};
use scene::SceneDescription;
use serde_json::Value;

/// What an independent reading of a file says the loader must find.
#[derive(Debug, PartialEq, Eq)]
struct Expected {
    /// Triangles before dropping degenerate ones.
    triangles: usize,
    /// Triangles whose material emits.
    emissive_triangles: usize,
    /// Punctual lights.
    lights: usize,
    /// Whether the file has a (perspective) camera.
    camera: bool,
}

/// Every scene file, sorted, relative to the shared scene folder.
fn scene_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path
                .extension()
                .is_some_and(|e| e == "obj" || e == "gltf" || e == "glb")
            {
                out.push(path);
            }
        }
    }
    let root = crate::shared_scenes();
    let mut files = Vec::new();
    walk(&root, &mut files);
    files.sort();
    files
        .into_iter()
        .map(|f| f.strip_prefix(&root).unwrap().to_path_buf())
        .collect()
}

/// Counts OBJ faces (a polygon of n vertices gives n − 2 triangles) and those under a
/// `usemtl` whose MTL entry has a non-zero `Ke`.
fn count_obj(path: &Path) -> Expected {
    let text = std::fs::read_to_string(path).unwrap();
    let mut emissive: BTreeSet<String> = BTreeSet::new();
    for line in text.lines() {
        if let Some(lib) = line.strip_prefix("mtllib ") {
            let Ok(mtl) = std::fs::read_to_string(path.with_file_name(lib.trim())) else {
                continue;
            };
            let mut current = String::new();
            for l in mtl.lines() {
                let words: Vec<&str> = l.split_whitespace().collect();
                match words.as_slice() {
                    ["newmtl", name] => current = (*name).to_owned(),
                    ["Ke", rgb @ ..]
                        if rgb.iter().take(3).any(|v| v.parse::<f32>().unwrap() > 0.0) =>
                    {
                        emissive.insert(current.clone());
                    }
                    _ => {}
                }
            }
        }
    }
    let (mut triangles, mut emissive_triangles) = (0, 0);
    let mut current_emits = false;
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["usemtl", name] => current_emits = emissive.contains(*name),
            ["f", vertices @ ..] if vertices.len() >= 3 => {
                triangles += vertices.len() - 2;
                if current_emits {
                    emissive_triangles += vertices.len() - 2;
                }
            }
            _ => {}
        }
    }
    Expected {
        triangles,
        emissive_triangles,
        lights: 0,
        camera: false,
    }
}

/// The JSON of a `.gltf`, or the JSON chunk of a `.glb`.
fn gltf_json(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap();
    if path.extension().is_some_and(|e| e == "glb") {
        let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        assert_eq!(&bytes[16..20], b"JSON");
        serde_json::from_slice(&bytes[20..20 + length]).unwrap()
    } else {
        serde_json::from_slice(&bytes).unwrap()
    }
}

/// Walks the default scene's node tree in the JSON and adds up `indices` counts / 3 per
/// triangle primitive instance.
fn count_gltf(path: &Path) -> Expected {
    let json = gltf_json(path);
    let empty = Vec::new();
    let array = |key: &str| json[key].as_array().unwrap_or(&empty);
    let (nodes, meshes, accessors, materials, cameras) = (
        array("nodes"),
        array("meshes"),
        array("accessors"),
        array("materials"),
        array("cameras"),
    );
    let emits: Vec<bool> = materials
        .iter()
        .map(|m| {
            let factor = m["emissiveFactor"].as_array().map_or(0.0, |f| {
                f.iter().map(|v| v.as_f64().unwrap()).fold(0.0, f64::max)
            });
            let strength = m["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"]
                .as_f64()
                .unwrap_or(1.0);
            factor * strength > 0.0
        })
        .collect();
    let scene = json["scene"].as_u64().unwrap_or(0) as usize;
    let mut stack: Vec<usize> = json["scenes"][scene]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_u64().unwrap() as usize)
        .collect();
    let mut expected = Expected {
        triangles: 0,
        emissive_triangles: 0,
        lights: 0,
        camera: false,
    };
    while let Some(n) = stack.pop() {
        let node = &nodes[n];
        if let Some(m) = node["mesh"].as_u64() {
            for prim in meshes[m as usize]["primitives"].as_array().unwrap() {
                assert_eq!(prim["mode"].as_u64().unwrap_or(4), 4, "only triangles here");
                let count = match prim["indices"].as_u64() {
                    Some(i) => accessors[i as usize]["count"].as_u64().unwrap(),
                    None => {
                        let p = prim["attributes"]["POSITION"].as_u64().unwrap();
                        accessors[p as usize]["count"].as_u64().unwrap()
                    }
                } as usize
                    / 3;
                expected.triangles += count;
                if prim["material"].as_u64().is_some_and(|i| emits[i as usize]) {
                    expected.emissive_triangles += count;
                }
            }
        }
        if let Some(c) = node["camera"].as_u64() {
            expected.camera |= cameras[c as usize]["type"] == "perspective";
        }
        if node["extensions"]["KHR_lights_punctual"].is_object() {
            expected.lights += 1;
        }
        if let Some(children) = node["children"].as_array() {
            stack.extend(children.iter().map(|c| c.as_u64().unwrap() as usize));
        }
    }
    expected
}

/// What the loader found, in the shape of [`Expected`].
fn found(scene: &SceneDescription) -> Expected {
    let summary = scene.summary();
    Expected {
        triangles: summary.triangles + summary.degenerate_triangles,
        emissive_triangles: summary.emissive_triangles,
        lights: scene.lights.len(),
        camera: !summary.camera_framed,
    }
}

#[test]
fn every_shared_scene_matches_independent_counts() {
    let root = crate::shared_scenes();
    let files = scene_files();
    assert!(files.len() >= 25, "found only {files:?}");
    let mut table = BTreeMap::new();
    for rel in &files {
        let path = root.join(rel);
        let scene =
            load_with(&path, &LoadOptions::allow_no_emitter()).unwrap_or_else(|e| panic!("{e}"));
        let expected = if rel.extension().is_some_and(|e| e == "obj") {
            count_obj(&path)
        } else {
            count_gltf(&path)
        };
        assert_eq!(found(&scene), expected, "{}", rel.display());
        // `load` (emitter required) succeeds exactly when there is an emitter.
        let has_emitter = expected.emissive_triangles > 0 || expected.lights > 0;
        match load(&path) {
            Ok(_) => assert!(has_emitter, "{} loaded without emitter", rel.display()),
            Err(LoadError::NoEmitter { path: p }) => {
                assert!(
                    !has_emitter,
                    "{}: NoEmitter despite emitters",
                    rel.display()
                );
                assert_eq!(p, path);
            }
            Err(e) => panic!("{e}"),
        }
        table.insert(rel.display().to_string(), expected);
    }
    // The figures stated in the SOURCE.md files.
    let bunny = &table["stanford_bunny/stanford-bunny.obj"];
    assert_eq!(bunny.triangles, 69_451);
    assert_eq!(
        table["gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf"].triangles,
        6000
    );
}

#[test]
fn which_scenes_have_emitters() {
    let root = crate::shared_scenes();
    let with_emitters: Vec<String> = scene_files()
        .into_iter()
        .filter(|rel| load(&root.join(rel)).is_ok())
        .map(|rel| rel.display().to_string())
        .collect();
    insta::assert_yaml_snapshot!(with_emitters);
}

#[test]
fn embree_cornell_box_reports_no_emitter_and_a_ka_warning() {
    let path = crate::shared_scenes().join("cornell_box_embree/cornell_box.obj");
    let err = load(&path).unwrap_err();
    assert!(matches!(err, LoadError::NoEmitter { .. }), "{err:?}");
    crate::assert_names_file(&err, &path);
    let scene = load_with(&path, &LoadOptions::allow_no_emitter()).unwrap();
    let summary = scene.summary();
    assert_eq!(summary.emitters(), 0);
    assert!(
        summary
            .warnings
            .iter()
            .any(|w| w.contains("\"light\"") && w.contains("Ka")),
        "{:?}",
        summary.warnings
    );
    // Millimetre units: the framed camera stands well outside the 0..559 box.
    assert!(scene.camera.position.z > 559.2);
}

#[test]
fn gltf_without_emitter_is_no_emitter() {
    let path = crate::shared_scenes().join("gltf/Box/glTF/Box.gltf");
    let err = load(&path).unwrap_err();
    assert!(matches!(err, LoadError::NoEmitter { .. }), "{err:?}");
    crate::assert_names_file(&err, &path);
}

#[test]
fn box_variants_load_identically() {
    let root = crate::shared_scenes().join("gltf/Box");
    let load = |p: &str| {
        let mut s = load_with(&root.join(p), &LoadOptions::allow_no_emitter()).unwrap();
        s.source = PathBuf::new();
        s
    };
    let plain = load("glTF/Box.gltf");
    assert_eq!(plain, load("glTF-Binary/Box.glb"));
    assert_eq!(plain, load("glTF-Embedded/Box.gltf"));
}

#[test]
fn gltf_camera_follows_its_node() {
    let path = crate::shared_scenes().join("gltf/Cameras/glTF/Cameras.gltf");
    let scene = load_with(&path, &LoadOptions::allow_no_emitter()).unwrap();
    // Node 1: translation (0.5, 0.5, 3), perspective yfov 0.7, aspect 1.
    assert!((scene.camera.position - glam::Vec3::new(0.5, 0.5, 3.0)).length() < 1e-6);
    let forward = (scene.camera.look_at - scene.camera.position).normalize();
    assert!((forward - glam::Vec3::NEG_Z).length() < 1e-6);
    assert!((scene.camera.fov_y - 0.7).abs() < 1e-6);
    assert_eq!((scene.film.width, scene.film.height), (512, 512));
    assert!(!scene.notes.camera_framed);
}

#[test]
fn gltf_punctual_lights_and_emissive_strength() {
    let root = crate::shared_scenes().join("gltf");
    let lamp = load(&root.join("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf")).unwrap();
    assert_eq!(lamp.lights.len(), 5);
    // "Point.002" has intensity 1.5 and the default white colour.
    assert!(lamp.lights.iter().any(|l| matches!(l,
        scene::Light::Point { intensity, .. } if (*intensity - glam::Vec3::splat(1.5)).length() < 1e-6)));

    let emissive = load(&root.join("EmissiveStrengthTest/glTF/EmissiveStrengthTest.gltf")).unwrap();
    let emit16 = emissive
        .materials
        .iter()
        .find(|m| m.name == "Emit16")
        .unwrap();
    assert!((emit16.emission - glam::Vec3::new(1.6, 8.0, 14.4)).length() < 1e-5);
}

/// The summary with the source made relative, so snapshots do not depend on the checkout.
fn snapshot_summary(rel: &Path) -> scene::SceneSummary {
    let path = crate::shared_scenes().join(rel);
    let scene = load_with(&path, &LoadOptions::allow_no_emitter()).unwrap();
    let mut summary = scene.summary();
    summary.source = rel.display().to_string();
    summary
}

#[test]
fn summaries_of_shared_scenes() {
    for rel in scene_files() {
        let name = rel
            .display()
            .to_string()
            .replace(['/', '.'], "_")
            .replace("__", "_");
        insta::assert_yaml_snapshot!(name, snapshot_summary(&rel));
    }
}

#[test]
fn summary_display_reads_well() {
    let summary = snapshot_summary(Path::new("cornell_box/CornellBox-Mirror.obj"));
    insta::assert_snapshot!(summary.to_string());
}
