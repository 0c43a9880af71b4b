//! Checkpoints: resuming gives bit-for-bit the uninterrupted image; Ctrl-C writes everything
//! and exits 130.

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

use crate::{CORNELL, files, fppm, read_exr, temp_dir};

fn bits(exr: &crate::Exr) -> Vec<u32> {
    exr.rgb().iter().map(|v| v.to_bits()).collect()
}

#[track_caller]
fn check_resume_is_exact(name: &str, method: &str) {
    let dir = temp_dir(name);
    let common = [
        "--width",
        "24",
        "--height",
        "24",
        "--photons-per-pass",
        "3000",
        "--method",
        method,
        "--seed",
        "5",
    ];
    let render = |extra: &[&str]| fppm(&dir, &[&["render", CORNELL][..], &common, extra].concat());
    // Uninterrupted: 6 passes.
    render(&["--passes", "6", "-o", "full.exr", "--aov", "depth"]).ok();
    // 3 passes with a checkpoint, then resumed to 6 in total.
    let first = render(&[
        "--passes",
        "3",
        "-o",
        "part.exr",
        "--checkpoint",
        "state.fppm",
        "--aov",
        "depth",
    ])
    .ok();
    assert!(
        first.stderr.contains("fppm resume state.fppm"),
        "{}",
        first.stderr
    );
    let part = read_exr(&dir.join("part.exr"));
    assert_eq!(part.metadata["fppm.passes"], "3");
    let resumed = fppm(
        &dir,
        &["resume", "state.fppm", "--passes", "6", "-o", "resumed.exr"],
    )
    .ok();
    assert!(resumed.stderr.contains("pass 4/6"), "{}", resumed.stderr);
    assert!(!resumed.stderr.contains("pass 3/6"), "{}", resumed.stderr);

    let (full, resumed) = (
        read_exr(&dir.join("full.exr")),
        read_exr(&dir.join("resumed.exr")),
    );
    assert_eq!(resumed.metadata["fppm.passes"], "6");
    assert_eq!(
        resumed.metadata["fppm.photons"],
        full.metadata["fppm.photons"]
    );
    assert_eq!(
        bits(&full),
        bits(&resumed),
        "{method}: resumed image differs"
    );
    assert!(
        resumed.channels.contains_key("depth"),
        "the AOV list comes from the checkpoint"
    );
    assert_ne!(bits(&part), bits(&full));
    // The PNG follows the new EXR name; the checkpoint was updated to 6 passes.
    assert!(dir.join("resumed.png").exists());
    fppm(
        &dir,
        &["resume", "state.fppm", "--passes", "6", "-o", "again.exr"],
    )
    .ok();
    assert_eq!(bits(&read_exr(&dir.join("again.exr"))), bits(&full));
}

#[test]
fn resume_is_bit_identical_ppm() {
    check_resume_is_exact("resume_ppm", "ppm");
}

#[test]
fn resume_is_bit_identical_freq_sppm() {
    check_resume_is_exact("resume_freq_sppm", "freq-sppm");
}

#[test]
fn resume_is_bit_identical_path() {
    check_resume_is_exact("resume_path", "path");
}

#[test]
fn resume_without_budget_continues_to_the_original_target() {
    let dir = temp_dir("resume_default_budget");
    let args = [
        "render",
        CORNELL,
        "--width",
        "16",
        "--height",
        "16",
        "--photons-per-pass",
        "2000",
        "--passes",
        "3",
    ];
    fppm(
        &dir,
        &[&args[..], &["--checkpoint", "s.fppm", "-o", "a.exr"]].concat(),
    )
    .ok();
    // Already at its 3 passes: resuming only rewrites the outputs (to the stored paths).
    std::fs::remove_file(dir.join("a.exr")).unwrap();
    fppm(&dir, &["resume", "s.fppm"]).ok();
    assert_eq!(read_exr(&dir.join("a.exr")).metadata["fppm.passes"], "3");
    fppm(&dir, &["resume", "s.fppm", "--passes", "2"]).fails(2, &["--passes 2", "3 passes"]);
}

#[test]
fn resume_of_the_default_scene() {
    let dir = temp_dir("resume_default_scene");
    let args = [
        "--width",
        "16",
        "--photons-per-pass",
        "1000",
        "--passes",
        "1",
        "--checkpoint",
        "s.fppm",
    ];
    fppm(&dir, &args).ok();
    fppm(&dir, &["resume", "s.fppm", "--passes", "2", "--json"]).ok();
    let exr = read_exr(&dir.join("fppm.exr"));
    assert_eq!(exr.metadata["fppm.passes"], "2");
    assert_eq!(exr.metadata["fppm.scene"], "<built-in default scene>");
    assert_eq!((exr.width, exr.height), (16, 12));
}

#[test]
fn ctrl_c_stops_after_the_pass_writes_everything_and_exits_130() {
    let dir = temp_dir("ctrl_c");
    // Stderr goes to a file: a full pipe would block the render.
    let log = temp_dir("ctrl_c_log").join("stderr.txt");
    let mut child = Command::new(env!("CARGO_BIN_EXE_fppm"))
        .args([
            "render",
            CORNELL,
            "--width",
            "16",
            "--height",
            "16",
            "--photons-per-pass",
            "2000",
        ])
        .args(["--passes", "100000", "--checkpoint", "s.fppm", "--json"])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    // Wait for two passes, so that the handler is surely installed.
    for _ in 0..2 {
        line.clear();
        stdout.read_line(&mut line).unwrap();
        assert!(line.contains("\"event\":\"pass\""), "{line}");
    }
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut stdout, &mut rest).unwrap();
    let status = child.wait().unwrap();
    let stderr = std::fs::read_to_string(&log).unwrap();
    assert_eq!(status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted after pass"), "{stderr}");
    let summary: serde_json::Value = serde_json::from_str(rest.lines().last().unwrap()).unwrap();
    assert_eq!(summary["event"], "done");
    assert_eq!(summary["interrupted"], true);
    let passes = summary["passes"].as_u64().unwrap();
    assert!((2..100_000).contains(&passes), "{summary}");
    assert_eq!(files(&dir), ["fppm.exr", "fppm.png", "s.fppm"]);
    let exr = read_exr(&dir.join("fppm.exr"));
    assert_eq!(exr.metadata["fppm.passes"], passes.to_string());
    // The checkpoint holds the same passes: resuming to one more pass works.
    fppm(
        &dir,
        &[
            "resume",
            "s.fppm",
            "--passes",
            &(passes + 1).to_string(),
            "-o",
            "more.exr",
        ],
    )
    .ok();
    assert_eq!(
        read_exr(&dir.join("more.exr")).metadata["fppm.passes"],
        (passes + 1).to_string()
    );
}

/// `kill -9` in the middle of a render leaves the last checkpoint written (the writes are
/// atomic, and spaced out so that they take little of the render): resuming it gives bit for bit
/// the image of an uninterrupted render.
#[test]
fn kill_9_then_resume_gives_the_uninterrupted_image() {
    let dir = temp_dir("kill_9");
    let common = [
        "--width",
        "16",
        "--height",
        "16",
        "--photons-per-pass",
        "20000",
        "--seed",
        "3",
    ];
    let log = temp_dir("kill_9_log").join("stderr.txt");
    let mut child = Command::new(env!("CARGO_BIN_EXE_fppm"))
        .args(["render", CORNELL])
        .args(common)
        .args(["--passes", "100000", "--checkpoint", "s.fppm", "--json"])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    let mut seen = 0;
    for _ in 0..6 {
        line.clear();
        stdout.read_line(&mut line).unwrap();
        let pass: serde_json::Value = serde_json::from_str(&line).unwrap();
        seen = pass["passes"].as_u64().unwrap();
    }
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), None, "killed by a signal");
    assert!(
        files(&dir).contains(&"s.fppm".to_owned()),
        "{:?}",
        files(&dir)
    );
    // Well past the kill, whatever pass the checkpoint holds.
    let target = (seen + 40).to_string();
    fppm(
        &dir,
        &["resume", "s.fppm", "--passes", &target, "-o", "resumed.exr"],
    )
    .ok();
    fppm(
        &dir,
        &[
            &["render", CORNELL][..],
            &common,
            &["--passes", &target, "-o", "full.exr"],
        ]
        .concat(),
    )
    .ok();
    let (full, resumed) = (
        read_exr(&dir.join("full.exr")),
        read_exr(&dir.join("resumed.exr")),
    );
    assert_eq!(resumed.metadata["fppm.passes"], target);
    assert_eq!(bits(&full), bits(&resumed));
}
