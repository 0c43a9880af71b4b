//! `fppm` alone, `scene`, `info`, `diff`, `--help`.

use crate::{CORNELL, files, fppm, read_exr, temp_dir, write_flat_exr};

#[test]
fn without_a_subcommand_fppm_renders_the_default_scene_here() {
    let dir = temp_dir("no_subcommand");
    let run = fppm(
        &dir,
        &[
            "--width",
            "32",
            "--photons-per-pass",
            "3000",
            "--passes",
            "2",
        ],
    )
    .ok();
    assert_eq!(files(&dir), ["fppm.exr", "fppm.png"]);
    assert!(run.stderr.contains("wrote fppm.exr"), "{}", run.stderr);
    assert!(run.stderr.contains("wrote fppm.png"), "{}", run.stderr);
    let exr = read_exr(&dir.join("fppm.exr"));
    assert_eq!(exr.metadata["fppm.scene"], "<built-in default scene>");
    // The scene's [render] table picks the method and the seed.
    assert_eq!(exr.metadata["fppm.method"], "freq-sppm");
    assert_eq!(exr.metadata["fppm.seed"], "1");
    assert!(exr.mean() > 0.0);
}

/// The full default render (the README's command), only when asked for: it takes about 25 s in
/// release and much longer in the dev profile.
#[test]
fn full_default_render_when_slow_tests_are_on() {
    if std::env::var_os("RUN_SLOW_TESTS").is_none() {
        return;
    }
    let dir = temp_dir("full_default");
    fppm(&dir, &[]).ok();
    let exr = read_exr(&dir.join("fppm.exr"));
    assert_eq!((exr.width, exr.height), (512, 384));
    assert_eq!(exr.metadata["fppm.passes"], "24");
}

#[test]
fn scene_default_prints_a_scene_that_renders() {
    let dir = temp_dir("scene_default");
    let run = fppm(&dir, &["scene", "default"]).ok();
    assert!(
        run.stdout.contains("type     = \"cylinder\""),
        "{}",
        run.stdout
    );
    std::fs::write(dir.join("default.toml"), &run.stdout).unwrap();
    let info = fppm(&dir, &["info", "default.toml"]).ok();
    assert!(info.stdout.contains("default.toml"), "{}", info.stdout);
    fppm(
        &dir,
        &[
            "render",
            "default.toml",
            "--width",
            "16",
            "--photons-per-pass",
            "1000",
            "--passes",
            "1",
        ],
    )
    .ok();
    // The same scene as the built-in one: the same image.
    fppm(
        &dir,
        &[
            "--width",
            "16",
            "--photons-per-pass",
            "1000",
            "--passes",
            "1",
            "-o",
            "builtin.exr",
        ],
    )
    .ok();
    let (a, b) = (
        read_exr(&dir.join("fppm.exr")),
        read_exr(&dir.join("builtin.exr")),
    );
    assert_eq!(a.rgb(), b.rgb());
}

#[test]
fn info_describes_the_cornell_box() {
    let dir = temp_dir("info");
    let run = fppm(&dir, &["info", CORNELL]).ok();
    let out = &run.stdout;
    for needle in [
        "CornellBox-Original.obj",
        "triangles",
        "materials",
        "camera",
        "bounds",
        "light",
    ] {
        assert!(out.contains(needle), "{needle:?} not in:\n{out}");
    }
    assert!(!out.contains("no emitter"), "{out}");
    assert_eq!(files(&dir), Vec::<String>::new());
    let default = fppm(&dir, &["info"]).ok();
    assert!(default.stdout.contains("cylinder"), "{}", default.stdout);
}

/// `fppm info` lists the images of imported scenes, with the sizes the files have (SOURCE.md
/// of the shared scenes: wood.jpg 2048x1571, lines.png 1024x1024).
#[test]
fn info_lists_the_textures_of_imported_scenes() {
    let dir = temp_dir("info_textures");
    let shared = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/scenes");
    for (scene, needles) in [
        (
            "mitsuba3/docs/scenes/bsdf_diffuse_textured.xml",
            ["textures   1", "wood.jpg 2048x1571", "textured (color)"],
        ),
        (
            "pbrt-v4/killeroos/killeroo-gold.pbrt",
            ["textures   1", "lines.png 1024x1024", "textured (color)"],
        ),
    ] {
        let run = fppm(&dir, &["info", &format!("{shared}/{scene}")]).ok();
        for needle in needles {
            assert!(
                run.stdout.contains(needle),
                "{needle:?} not in:\n{}",
                run.stdout
            );
        }
    }
}

#[test]
fn info_accepts_a_scene_without_emitters_and_says_so() {
    let dir = temp_dir("info_dark");
    let dark = crate::small_default_scene();
    let dark = dark[..dark.find("[[lights]]").unwrap()].to_string();
    std::fs::write(dir.join("dark.toml"), dark).unwrap();
    let run = fppm(&dir, &["info", "dark.toml"]).ok();
    assert!(run.stdout.contains("no emitter"), "{}", run.stdout);
    fppm(&dir, &["render", "dark.toml"]).fails(1, &["dark.toml", "no emitter"]);
    fppm(&dir, &["info", "missing.obj"]).fails(1, &["missing.obj"]);
}

#[test]
fn diff_by_hand() {
    let dir = temp_dir("diff");
    // A: 1 everywhere; B: 0.5 on the left half, 1 on the right half (4 x 2 pixels).
    write_flat_exr(&dir.join("a.exr"), 4, 2, |_, _| [1.0, 1.0, 1.0]);
    write_flat_exr(&dir.join("b.exr"), 4, 2, |x, _| {
        if x < 2 { [0.5; 3] } else { [1.0; 3] }
    });
    let run = fppm(&dir, &["diff", "a.exr", "b.exr", "--json"]).ok();
    let m: serde_json::Value = serde_json::from_str(run.stdout.trim()).unwrap();
    // Half the values differ by 0.5: MSE = 0.125, RMSE = 0.35355.
    let close = |key: &str, expected: f64| {
        let got = m[key].as_f64().unwrap();
        assert!((got - expected).abs() < 1e-9, "{key}: {got} vs {expected}");
    };
    close("rmse", 0.125f64.sqrt());
    // relMSE: half the values give 0.25 / (0.25 + 0.01).
    close("rel_mse", 0.5 * 0.25 / 0.26);
    // mean ratio: 1 / 0.75.
    close("mean_ratio", 1.0 / 0.75);

    let text = fppm(&dir, &["diff", "a.exr", "b.exr", "--out", "d.png"]).ok();
    assert!(text.stdout.contains("rmse"), "{}", text.stdout);
    assert!(text.stdout.contains("3.535534e-1"), "{}", text.stdout);
    let png = image::open(dir.join("d.png")).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (4, 2));
    // Zero error is the dark end of the ramp, a large one the bright end.
    assert_eq!(png.get_pixel(3, 0).0, [68, 1, 84]);
    assert_ne!(png.get_pixel(0, 0).0, [68, 1, 84]);

    let same = fppm(&dir, &["diff", "a.exr", "a.exr", "--json"]).ok();
    let m: serde_json::Value = serde_json::from_str(same.stdout.trim()).unwrap();
    assert_eq!(m["rmse"], 0.0);
    assert_eq!(m["mean_ratio"], 1.0);
}

#[test]
fn diff_refuses_mismatched_or_missing_images() {
    let dir = temp_dir("diff_bad");
    write_flat_exr(&dir.join("a.exr"), 4, 2, |_, _| [1.0; 3]);
    write_flat_exr(&dir.join("c.exr"), 2, 2, |_, _| [1.0; 3]);
    fppm(&dir, &["diff", "a.exr", "c.exr", "--out", "d.png"]).fails(1, &["a.exr", "4x2", "2x2"]);
    fppm(&dir, &["diff", "a.exr", "nope.exr"]).fails(1, &["nope.exr"]);
    std::fs::write(dir.join("text.exr"), "not an image").unwrap();
    fppm(&dir, &["diff", "text.exr", "a.exr"]).fails(1, &["text.exr"]);
    assert_eq!(files(&dir), ["a.exr", "c.exr", "text.exr"]);
}

#[test]
fn help_and_version() {
    let dir = temp_dir("help");
    let help = fppm(&dir, &["--help"]).ok();
    for flag in [
        "--method",
        "--time",
        "--passes",
        "--photons-per-pass",
        "--alpha",
        "--initial-radius",
        "--freq-fraction",
        "--freq-merge",
        "--kernel-k",
        "--max-depth",
        "--spp",
        "--seed",
        "--threads",
        "--width",
        "--height",
        "--output",
        "--png",
        "--exposure",
        "--tonemap",
        "--aov",
        "--snapshot-every",
        "--checkpoint",
        "--quiet",
        "--json",
    ] {
        assert!(help.stdout.contains(flag), "{flag} missing from --help");
    }
    let render_help = fppm(&dir, &["render", "--help"]).ok();
    assert!(render_help.stdout.contains("SCENE"));
    let resume_help = fppm(&dir, &["resume", "--help"]).ok();
    assert!(resume_help.stdout.contains("CHECKPOINT"));
    let version = fppm(&dir, &["--version"]).ok();
    assert!(version.stdout.starts_with("fppm "));
    assert_eq!(files(&dir), Vec::<String>::new());
}

/// A shared glTF scene, by its path under `shared/scenes/gltf`.
fn gltf(path: &str) -> String {
    format!(
        "{}/../../../shared/scenes/gltf/{path}",
        env!("CARGO_MANIFEST_DIR")
    )
}

#[test]
fn gltf_and_glb_scenes_render() {
    let dir = temp_dir("gltf");
    for (name, path) in [
        (
            "gltf",
            "EmissiveStrengthTest/glTF/EmissiveStrengthTest.gltf",
        ),
        (
            "glb",
            "EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb",
        ),
    ] {
        let out = format!("{name}.exr");
        let scene = gltf(path);
        let args = [
            "render",
            &scene,
            "--width",
            "24",
            "--height",
            "16",
            "--photons-per-pass",
            "3000",
            "--passes",
            "2",
        ];
        fppm(&dir, &[&args[..], &["-o", &out]].concat()).ok();
        let exr = read_exr(&dir.join(&out));
        assert_eq!((exr.width, exr.height), (24, 16));
        assert!(exr.mean() > 0.0, "{path}");
    }
    // The glTF and its binary twin are the same scene.
    assert_eq!(
        read_exr(&dir.join("gltf.exr")).rgb(),
        read_exr(&dir.join("glb.exr")).rgb()
    );
    // A glTF without lights can be inspected but not rendered.
    let dark = gltf("Box/glTF-Binary/Box.glb");
    let info = fppm(&dir, &["info", &dark]).ok();
    assert!(info.stdout.contains("no emitter"), "{}", info.stdout);
    fppm(&dir, &["render", &dark, "-o", "box.exr"]).fails(1, &["Box.glb", "no emitter"]);
    assert_eq!(files(&dir), ["glb.exr", "glb.png", "gltf.exr", "gltf.png"]);
}

/// `--env` lights any scene: `info` lists the map, a render through the open front of the
/// Cornell box sees it, and `resume` finds the map again from the checkpoint.
#[test]
fn env_flag_lights_a_scene_and_survives_resume() {
    let dir = temp_dir("env_flag");
    // A uniform grey sky of radiance 0.25, 16 × 8 texels.
    exr::prelude::write_rgb_file(dir.join("sky.exr"), 16, 8, |_, _| {
        (0.25f32, 0.25f32, 0.25f32)
    })
    .unwrap();
    let info = fppm(&dir, &["info", CORNELL, "--env", "sky.exr"]).ok();
    assert!(
        info.stdout.contains("environment sky.exr (16×8"),
        "{}",
        info.stdout
    );
    let tiny = [
        "--width",
        "16",
        "--height",
        "16",
        "--photons-per-pass",
        "2000",
    ];
    let mut args = vec!["render", CORNELL, "--env", "sky.exr", "--method", "path"];
    args.extend_from_slice(&tiny);
    let plain: Vec<&str> = args
        .iter()
        .copied()
        .filter(|&a| a != "--env" && a != "sky.exr")
        .collect();
    fppm(
        &dir,
        &[&plain[..], &["--passes", "2", "-o", "plain.exr"]].concat(),
    )
    .ok();
    fppm(
        &dir,
        &[
            &args[..],
            &[
                "--passes",
                "2",
                "--checkpoint",
                "state.fppm",
                "-o",
                "lit.exr",
            ],
        ]
        .concat(),
    )
    .ok();
    let (plain, lit) = (
        read_exr(&dir.join("plain.exr")),
        read_exr(&dir.join("lit.exr")),
    );
    let sum = |e: &crate::Exr| e.rgb().iter().map(|&v| f64::from(v)).sum::<f64>();
    assert!(sum(&lit) > sum(&plain) * 1.01, "the sky adds no light");
    fppm(
        &dir,
        &["resume", "state.fppm", "--passes", "3", "-o", "more.exr"],
    )
    .ok();
    assert!(dir.join("more.exr").exists());
}
