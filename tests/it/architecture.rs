//! The dependency rules of ARCHITECTURE.md, read from `cargo metadata`: a change that adds a
//! forbidden edge fails here rather than in review.

use std::collections::BTreeMap;
use std::process::Command;

/// The workspace crates each workspace crate depends on (normal dependencies), exactly: a new
/// edge, or a missing one, is a change of ARCHITECTURE.md's map first.
const EDGES: &[(&str, &[&str])] = &[
    ("spectrum", &[]),
    ("scene", &[]),
    ("import", &["scene"]),
    ("photon", &[]),
    ("ppm", &["spectrum", "scene", "photon"]),
    ("film", &[]),
    ("cli", &["scene", "import", "ppm", "film"]),
    ("xtask", &["scene", "import", "ppm", "film"]),
    ("python", &["scene", "import", "ppm", "film"]),
];

/// The direction of ARCHITECTURE.md: the crates each crate may depend on.
const ALLOWED: &[(&str, &[&str])] = &[
    ("spectrum", &[]),
    ("scene", &["spectrum"]),
    ("import", &["spectrum", "scene"]),
    ("photon", &["spectrum", "scene"]),
    ("ppm", &["spectrum", "scene", "photon"]),
    ("film", &[]),
    (
        "cli",
        &["spectrum", "scene", "import", "photon", "ppm", "film"],
    ),
    (
        "xtask",
        &["spectrum", "scene", "import", "photon", "ppm", "film"],
    ),
    (
        "python",
        &["spectrum", "scene", "import", "photon", "ppm", "film"],
    ),
];

/// What `cargo ARGS` prints, run in the workspace offline; it must succeed.
fn cargo(args: &[&str]) -> Vec<u8> {
    let output = Command::new(env!("CARGO"))
        .args(args)
        .arg("--offline")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    output.stdout
}

/// Normal (non-dev, non-build) dependencies of every workspace package.
fn dependencies() -> BTreeMap<String, Vec<String>> {
    let stdout = cargo(&["metadata", "--format-version", "1", "--no-deps"]);
    let metadata: serde_json::Value = serde_json::from_slice(&stdout).unwrap();
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
fn workspace_edges_are_exactly_those_of_the_map() {
    let deps = dependencies();
    let workspace: Vec<&str> = EDGES.iter().map(|(name, _)| *name).collect();
    for (name, expected) in EDGES {
        let mut actual: Vec<&str> = deps[*name]
            .iter()
            .map(String::as_str)
            .filter(|d| workspace.contains(d))
            .collect();
        actual.sort_unstable();
        let mut expected = expected.to_vec();
        expected.sort_unstable();
        assert_eq!(actual, expected, "workspace dependencies of {name}");
        let allowed = ALLOWED.iter().find(|(n, _)| n == name).map(|(_, a)| *a);
        assert!(
            expected
                .iter()
                .all(|e| allowed.is_some_and(|a| a.contains(e))),
            "{name}: an edge against the direction of ARCHITECTURE.md"
        );
    }
    // Every workspace package is in the map.
    for name in deps.keys() {
        assert!(
            workspace.contains(&name.as_str()) || name == "tests",
            "{name} is missing from EDGES"
        );
    }
}

#[test]
fn spectrum_depends_on_nothing_but_std() {
    let deps = dependencies();
    assert_eq!(deps["spectrum"], Vec::<String>::new());
}

/// The third-party libraries only one workspace crate may name: the BVH builder and the complex
/// arithmetic of conductors' Fresnel belong to the scene runtime, the file-format parsers and
/// image decoders to the importers, the Python bindings to the Python module, the HTTP server of
/// the live preview to the command.
const OWNED_LIBRARIES: &[(&str, &[&str])] = &[
    ("scene", &["obvhs", "num-complex"]),
    ("cli", &["tiny_http"]),
    (
        "import",
        &[
            "tobj",
            "gltf",
            "spade",
            "roxmltree",
            "ply-rs-bw",
            "bevy_mikktspace",
            "flate2",
        ],
    ),
    ("python", &["pyo3", "numpy"]),
];

#[test]
fn only_their_owner_knows_the_bvh_and_format_libraries() {
    let deps = dependencies();
    for (name, actual) in &deps {
        for (owner, libraries) in OWNED_LIBRARIES {
            for library in *libraries {
                if actual.iter().any(|d| d == library) {
                    assert_eq!(name, owner, "{name} depends on {library}");
                }
            }
        }
    }
}

/// Every package `root` compiles in a normal build (its normal dependencies, transitively, on
/// this platform), as `cargo tree` lists them.
fn normal_closure(root: &str) -> Vec<String> {
    let stdout = cargo(&[
        "tree", "-p", root, "-e", "normal", "--prefix", "none", "-f", "{p}",
    ]);
    String::from_utf8(stdout)
        .unwrap()
        .lines()
        .filter_map(|line| line.split_whitespace().next())
        .map(str::to_owned)
        .collect()
}

#[test]
fn the_integrators_compile_no_importer() {
    let closure = normal_closure("ppm");
    assert!(closure.iter().any(|n| n == "scene"), "{closure:?}");
    for importer in [
        "import",
        "gltf",
        "tobj",
        "spade",
        "roxmltree",
        "ply-rs-bw",
        "image",
        "toml",
    ] {
        assert!(
            !closure.iter().any(|n| n == importer),
            "ppm compiles {importer}: {closure:?}"
        );
    }
}
