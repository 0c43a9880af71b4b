//! Work units: plan, units in any order and number, merge; the merged image is bit for bit the
//! one-machine render of the same pass-independent method.

use std::process::Command;

use crate::{CORNELL, files, fppm, read_exr, temp_dir};

const FILM: &[&str] = &[
    "--width",
    "20",
    "--height",
    "16",
    "--photons-per-pass",
    "3000",
    "--seed",
    "11",
];

fn bits(dir: &std::path::Path, name: &str) -> Vec<u32> {
    read_exr(&dir.join(name))
        .rgb()
        .iter()
        .map(|v| v.to_bits())
        .collect()
}

fn plan(dir: &std::path::Path, job: &str, passes: &str, units: &str) {
    fppm(
        dir,
        &[
            &[
                "plan", CORNELL, "-o", job, "--passes", passes, "--units", units,
            ][..],
            FILM,
        ]
        .concat(),
    )
    .ok();
}

#[test]
fn merged_units_are_the_one_machine_render_bit_for_bit() {
    let dir = temp_dir("units_exact");
    fppm(
        &dir,
        &[
            &[
                "render",
                CORNELL,
                "--method",
                "appm",
                "--passes",
                "7",
                "-o",
                "single.exr",
            ][..],
            FILM,
        ]
        .concat(),
    )
    .ok();
    let single = bits(&dir, "single.exr");
    for (job, units, order) in [
        ("one", "1", vec![0]),
        ("three", "3", vec![2, 0, 1]),
        ("seven", "7", vec![6, 5, 4, 3, 2, 1, 0]),
    ] {
        plan(&dir, job, "7", units);
        for i in order {
            fppm(&dir, &["unit", job, "--index", &i.to_string()]).ok();
        }
        let out = format!("{job}.exr");
        fppm(&dir, &["merge", job, "-o", &out]).ok();
        assert_eq!(bits(&dir, &out), single, "{units} units");
        let exr = read_exr(&dir.join(&out));
        assert_eq!(exr.metadata["fppm.passes"], "7");
        assert_eq!(exr.metadata["fppm.method"], "appm");
    }
}

/// `vcm` and `bdpt` need no pilot: their units merge into the one-machine render too.
#[test]
fn bidirectional_units_merge_into_the_one_machine_render_bit_for_bit() {
    let dir = temp_dir("units_vcm");
    for method in ["vcm", "bdpt"] {
        let film = [FILM, &["--method", method, "--spp", "1"]].concat();
        let single = format!("{method}-single.exr");
        fppm(
            &dir,
            &[
                &["render", CORNELL, "--passes", "5", "-o", &single][..],
                &film,
            ]
            .concat(),
        )
        .ok();
        let job = format!("{method}-job");
        fppm(
            &dir,
            &[
                &["plan", CORNELL, "-o", &job, "--passes", "5", "--units", "3"][..],
                &film,
            ]
            .concat(),
        )
        .ok();
        for i in [1, 2, 0] {
            fppm(&dir, &["unit", &job, "--index", &i.to_string()]).ok();
        }
        let out = format!("{method}.exr");
        fppm(&dir, &["merge", &job, "-o", &out]).ok();
        assert_eq!(bits(&dir, &out), bits(&dir, &single), "{method}");
        assert_eq!(read_exr(&dir.join(&out)).metadata["fppm.method"], method);
    }
}

#[test]
fn the_unit_index_comes_from_slurm_or_kubernetes() {
    let dir = temp_dir("units_env");
    plan(&dir, "job", "4", "2");
    for (variable, index) in [("SLURM_ARRAY_TASK_ID", "0"), ("JOB_COMPLETION_INDEX", "1")] {
        let status = Command::new(env!("CARGO_BIN_EXE_fppm"))
            .args(["unit", "job", "--quiet"])
            .env_remove("SLURM_ARRAY_TASK_ID")
            .env_remove("JOB_COMPLETION_INDEX")
            .env(variable, index)
            .current_dir(&dir)
            .status()
            .unwrap();
        assert!(status.success(), "{variable}");
    }
    assert_eq!(
        files(&dir.join("job")),
        ["plan.fppm", "unit-0.part", "unit-1.part"]
    );
}

#[test]
fn missing_units_are_refused_or_merged_partially() {
    let dir = temp_dir("units_partial");
    plan(&dir, "job", "6", "3");
    fppm(&dir, &["unit", "job", "--index", "1"]).ok();
    fppm(&dir, &["merge", "job", "-o", "out.exr"])
        .fails(1, &["job", "units 0, 2 are missing", "--partial"]);
    assert!(!dir.join("out.exr").exists());
    let run = fppm(&dir, &["merge", "job", "-o", "out.exr", "--partial"]).ok();
    assert!(
        run.stderr
            .contains("merged 2 of 6 passes; units 0, 2 are missing"),
        "{}",
        run.stderr
    );
    let exr = read_exr(&dir.join("out.exr"));
    assert_eq!(exr.metadata["fppm.passes"], "2");
    assert_eq!(exr.metadata["fppm.missing_units"], "0, 2");
    assert!(exr.mean() > 0.0);
}

#[test]
fn bad_plans_units_and_parts_get_one_line() {
    let dir = temp_dir("units_bad");
    fppm(
        &dir,
        &[
            &[
                "plan", CORNELL, "-o", "job", "--passes", "4", "--units", "3", "--method", "sppm",
            ][..],
            FILM,
        ]
        .concat(),
    )
    .fails(2, &["--method sppm", "appm"]);
    fppm(
        &dir,
        &[
            &[
                "plan", CORNELL, "-o", "job", "--passes", "4", "--units", "5",
            ][..],
            FILM,
        ]
        .concat(),
    )
    .fails(2, &["--units 5", "from 1 to the number of passes (4)"]);
    fppm(&dir, &["unit", "nojob", "--index", "0"]).fails(1, &["nojob", "cannot read the plan"]);
    plan(&dir, "job", "4", "2");
    fppm(&dir, &["unit", "job", "--index", "2"])
        .fails(2, &["--index 2", "not a unit of this plan (0 to 1)"]);
    // A part cut short, and a part of another plan.
    fppm(&dir, &["unit", "job", "--index", "0"]).ok();
    let part = dir.join("job/unit-0.part");
    let bytes = std::fs::read(&part).unwrap();
    std::fs::write(&part, &bytes[..bytes.len() / 2]).unwrap();
    fppm(&dir, &["merge", "job", "-o", "out.exr", "--partial"])
        .fails(1, &["unit-0.part", "truncated or corrupt"]);
    plan(&dir, "other", "6", "2");
    std::fs::write(dir.join("other/unit-0.part"), &bytes).unwrap();
    fppm(&dir, &["merge", "other", "-o", "out.exr", "--partial"])
        .fails(1, &["unit-0.part", "another plan"]);
    assert!(!dir.join("out.exr").exists());
}

/// A scheduler's retry renders the same bytes; a unit of a plan whose scene file changed since
/// planning is refused.
#[test]
fn a_rerun_unit_gives_the_same_bytes_and_a_changed_scene_is_refused() {
    let dir = temp_dir("units_rerun");
    let scene = dir.join("box.obj");
    std::fs::copy(CORNELL, &scene).unwrap();
    let mtl = std::path::Path::new(CORNELL).with_extension("mtl");
    std::fs::copy(&mtl, dir.join(mtl.file_name().unwrap())).unwrap();
    fppm(
        &dir,
        &[
            &[
                "plan", "box.obj", "-o", "job", "--passes", "4", "--units", "2",
            ][..],
            FILM,
        ]
        .concat(),
    )
    .ok();
    fppm(&dir, &["unit", "job", "--index", "1"]).ok();
    let first = std::fs::read(dir.join("job/unit-1.part")).unwrap();
    fppm(&dir, &["unit", "job", "--index", "1"]).ok();
    assert_eq!(std::fs::read(dir.join("job/unit-1.part")).unwrap(), first);
    // Move one vertex of the box: the plan no longer fits the scene.
    let text = std::fs::read_to_string(&scene).unwrap();
    let line = text.lines().find(|l| l.starts_with("v ")).unwrap();
    let moved: Vec<String> = line
        .split_whitespace()
        .skip(1)
        .map(|x| (x.parse::<f64>().unwrap() + 0.01).to_string())
        .collect();
    let edited_line = format!("v {}", moved.join(" "));
    std::fs::write(&scene, text.replacen(line, &edited_line, 1)).unwrap();
    fppm(&dir, &["unit", "job", "--index", "0"]).fails(1, &["plan.fppm", "another scene"]);
}
