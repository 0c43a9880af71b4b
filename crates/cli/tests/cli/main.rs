//! Tests of the built `fppm` binary: every flag, every bad input of the issue, checkpoint/resume
//! bit-identity, Ctrl-C, `diff` and `info`.
//!
//! Renders stay tiny (at most 32×32 pixels, a few thousand photons, a few passes) because
//! tests run in the dev profile.

#![allow(clippy::unwrap_used, clippy::print_stderr, clippy::print_stdout)]

mod bad_input;
mod commands;
mod flags;
mod live;
mod resume;
mod units;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The Cornell box of the shared scenes (an OBJ with an emissive MTL material).
const CORNELL: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/scenes/cornell_box/CornellBox-Original.obj"
);

/// Flags that keep a render of the Cornell box tiny.
const TINY: &[&str] = &[
    "--width",
    "32",
    "--height",
    "32",
    "--photons-per-pass",
    "4000",
    "--passes",
    "2",
];

/// What a run of the binary gave.
#[derive(Debug)]
struct Run {
    code: i32,
    stdout: String,
    stderr: String,
}

impl Run {
    /// Asserts success and returns self.
    #[track_caller]
    fn ok(self) -> Self {
        assert_eq!(self.code, 0, "fppm failed:\n{}", self.stderr);
        self
    }

    /// Asserts a failure with `code` and a single stderr line starting with `fppm: ` that
    /// contains every one of `needles`.
    #[track_caller]
    fn fails(self, code: i32, needles: &[&str]) -> Self {
        assert_eq!(
            self.code, code,
            "expected exit {code}, stderr:\n{}",
            self.stderr
        );
        let lines: Vec<&str> = self.stderr.lines().collect();
        assert_eq!(lines.len(), 1, "expected one line, got:\n{}", self.stderr);
        assert!(lines[0].starts_with("fppm: "), "{}", lines[0]);
        assert!(!lines[0].contains("For more information"), "{}", lines[0]);
        for needle in needles {
            assert!(
                lines[0].contains(needle),
                "{:?} not in {:?}",
                needle,
                lines[0]
            );
        }
        self
    }
}

/// A fresh, empty directory for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cli-tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `fppm args…` in `dir`.
fn fppm(dir: &Path, args: &[&str]) -> Run {
    let output = Command::new(env!("CARGO_BIN_EXE_fppm"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    Run {
        code: output.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
    }
}

/// `render CORNELL` with [`TINY`] and `extra` flags.
fn render_cornell(dir: &Path, extra: &[&str]) -> Run {
    let mut args = vec!["render", CORNELL];
    args.extend_from_slice(TINY);
    args.extend_from_slice(extra);
    fppm(dir, &args)
}

/// The files in `dir`, sorted.
fn files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// An EXR as the tests look at it.
#[derive(Debug)]
struct Exr {
    width: usize,
    height: usize,
    channels: BTreeMap<String, Vec<f32>>,
    metadata: BTreeMap<String, String>,
}

impl Exr {
    fn rgb(&self) -> Vec<f32> {
        let (r, g, b) = (
            &self.channels["R"],
            &self.channels["G"],
            &self.channels["B"],
        );
        (0..r.len()).flat_map(|i| [r[i], g[i], b[i]]).collect()
    }

    fn mean(&self) -> f64 {
        let rgb = self.rgb();
        rgb.iter().map(|&v| f64::from(v)).sum::<f64>() / rgb.len() as f64
    }
}

fn read_exr(path: &Path) -> Exr {
    use exr::prelude::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_file(path)
        .unwrap();
    let layer = image.layer_data;
    let channels = layer
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
        .collect();
    let metadata = layer
        .attributes
        .other
        .iter()
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
            _ => None,
        })
        .collect();
    Exr {
        width: layer.size.0,
        height: layer.size.1,
        channels,
        metadata,
    }
}

/// Writes an RGB EXR whose pixels all have the value `rgb`.
fn write_flat_exr(
    path: &Path,
    width: usize,
    height: usize,
    pixel: impl Fn(usize, usize) -> [f32; 3] + Sync,
) {
    use exr::prelude::*;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let p = pixel(x, y);
        (p[0], p[1], p[2])
    });
    let layer = Layer::new(
        (width, height),
        LayerAttributes::named(""),
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_file(path)
        .unwrap();
}

/// The built-in default scene at 16×12 pixels with 2 passes of 2000 photons.
fn small_default_scene() -> String {
    let text = include_str!("../../src/default_scene.toml");
    let mut replaced = 0;
    let mut table = String::new();
    let lines: Vec<String> = text
        .lines()
        .map(|line| {
            if line.starts_with('[') {
                table = line.to_string();
            }
            let key = line.split('=').next().unwrap_or("").trim();
            let value = match (table.as_str(), key) {
                ("[film]", "width") => "16",
                ("[film]", "height") => "12",
                ("[render]", "passes") => "2",
                ("[render]", "photons_per_pass") => "2000",
                _ => return line.to_string(),
            };
            replaced += 1;
            format!("{key} = {value}")
        })
        .collect();
    assert_eq!(
        replaced, 4,
        "the default scene's [film] and [render] keys changed"
    );
    lines.join("\n")
}
