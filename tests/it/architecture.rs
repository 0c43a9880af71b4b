//! The dependency rules of ARCHITECTURE.md, read from `cargo metadata`: a change that adds a
//! forbidden edge fails here rather than in review.

use std::collections::BTreeMap;
use std::process::Command;

/// Workspace crates each product crate may depend on (normal dependencies).
const ALLOWED: &[(&str, &[&str])] = &[
    ("spectrum", &[]),
    ("geometry", &["spectrum"]),
    ("photon", &["spectrum", "geometry"]),
    ("ppm", &["spectrum", "geometry", "photon"]),
    ("film", &[]),
    ("cli", &["spectrum", "geometry", "photon", "ppm", "film"]),
    ("xtask", &["spectrum", "geometry", "photon", "ppm", "film"]),
];

/// Normal (non-dev, non-build) dependencies of every workspace package.
fn dependencies() -> BTreeMap<String, Vec<String>> {
    let output = Command::new(env!("CARGO"))
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let metadata: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    metadata["packages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|package| {
            let deps = package["dependencies"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|d| d["kind"].is_null())
                .map(|d| d["name"].as_str().unwrap().to_owned())
                .collect();
            (package["name"].as_str().unwrap().to_owned(), deps)
        })
        .collect()
}

#[test]
fn workspace_crates_depend_only_in_the_allowed_direction() {
    let deps = dependencies();
    let workspace: Vec<&str> = ALLOWED.iter().map(|(name, _)| *name).collect();
    for (name, allowed) in ALLOWED {
        let Some(actual) = deps.get(*name) else {
            panic!("workspace crate {name} is missing from cargo metadata");
        };
        for dep in actual {
            if workspace.contains(&dep.as_str()) {
                assert!(
                    allowed.contains(&dep.as_str()),
                    "{name} must not depend on {dep} (see ARCHITECTURE.md)"
                );
            }
        }
    }
}

#[test]
fn spectrum_depends_on_nothing_but_std() {
    let deps = dependencies();
    assert_eq!(deps["spectrum"], Vec::<String>::new());
}

#[test]
fn only_geometry_knows_the_scene_and_bvh_libraries() {
    let deps = dependencies();
    for (name, actual) in &deps {
        for library in ["obvhs", "tobj", "gltf", "spade", "roxmltree", "ply-rs-bw"] {
            if actual.iter().any(|d| d == library) {
                assert_eq!(name, "geometry", "{name} depends on {library}");
            }
        }
    }
}
