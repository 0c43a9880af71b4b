//! Every render flag parses and takes effect where that can be checked.

use crate::{CORNELL, files, fppm, read_exr, render_cornell, temp_dir};

#[test]
fn width_and_height_set_the_film() {
    let dir = temp_dir("width_height");
    fppm(
        &dir,
        &[
            "render",
            CORNELL,
            "--width",
            "16",
            "--height",
            "8",
            "--photons-per-pass",
            "2000",
            "--passes",
            "1",
        ],
    )
    .ok();
    let exr = read_exr(&dir.join("fppm.exr"));
    assert_eq!((exr.width, exr.height), (16, 8));
    let png = image_size(&dir.join("fppm.png"));
    assert_eq!(png, (16, 8));
}

#[test]
fn a_lone_width_keeps_the_aspect_ratio() {
    let dir = temp_dir("lone_width");
    // The default scene is 512 x 384.
    fppm(
        &dir,
        &[
            "--width",
            "32",
            "--photons-per-pass",
            "2000",
            "--passes",
            "1",
        ],
    )
    .ok();
    let exr = read_exr(&dir.join("fppm.exr"));
    assert_eq!((exr.width, exr.height), (32, 24));
}

#[test]
fn outputs_go_where_asked_and_metadata_is_written() {
    let dir = temp_dir("outputs");
    let run = render_cornell(&dir, &["-o", "a.exr", "--png", "b.png", "--seed", "7"]).ok();
    assert_eq!(files(&dir), ["a.exr", "b.png"]);
    assert!(run.stderr.contains("wrote a.exr"), "{}", run.stderr);
    assert!(run.stderr.contains("wrote b.png"), "{}", run.stderr);
    let exr = read_exr(&dir.join("a.exr"));
    let m = &exr.metadata;
    assert_eq!(m["fppm.passes"], "2");
    // The library's default method.
    assert_eq!(m["fppm.method"], "freq-sppm");
    assert_eq!(m["fppm.seed"], "7");
    assert_eq!(m["fppm.photons"], "8000");
    assert_eq!(m["fppm.photons_per_pass"], "4000");
    assert!(
        m["fppm.scene"].ends_with("CornellBox-Original.obj"),
        "{m:?}"
    );
    assert!(m["fppm.render_seconds"].parse::<f64>().unwrap() > 0.0);
    // Every render parameter, with the value the library reads back.
    for param in ppm::PARAMS {
        assert!(
            m.contains_key(&format!("fppm.{}", param.name)),
            "{}",
            param.name
        );
    }
    assert_eq!(m["fppm.freq_merge"], "min");
    assert_eq!(m["fppm.freq_floor"], "keep");
    assert_eq!(m["fppm.initial_radius"], "auto");
    assert_eq!(exr.channels.keys().collect::<Vec<_>>(), ["B", "G", "R"]);
    assert!(exr.mean() > 0.0, "the Cornell box is lit");
}

#[test]
fn png_defaults_to_the_exr_name() {
    let dir = temp_dir("png_default");
    render_cornell(&dir, &["-o", "picture.exr"]).ok();
    assert_eq!(files(&dir), ["picture.exr", "picture.png"]);
}

#[test]
fn passes_photons_and_integrator_parameters_reach_the_renderer() {
    let dir = temp_dir("params");
    let args = [
        "--passes",
        "3",
        "--photons-per-pass",
        "3k",
        "--alpha",
        "0.5",
        "--spp",
        "2",
        "--max-depth",
        "4",
        "--initial-radius",
        "0.05",
    ];
    fppm(
        &dir,
        &[
            &["render", CORNELL, "--width", "16", "--height", "16"][..],
            &args,
        ]
        .concat(),
    )
    .ok();
    let m = read_exr(&dir.join("fppm.exr")).metadata;
    assert_eq!(m["fppm.passes"], "3");
    assert_eq!(m["fppm.photons"], "9000");
    assert_eq!(m["fppm.alpha"], "0.5");
    assert_eq!(m["fppm.spp"], "2");
    assert_eq!(m["fppm.max_depth"], "4");
}

#[test]
fn initial_radius_changes_the_image() {
    let dir = temp_dir("initial_radius");
    render_cornell(&dir, &["-o", "a.exr", "--initial-radius", "0.02"]).ok();
    render_cornell(&dir, &["-o", "b.exr", "--initial-radius", "0.2"]).ok();
    assert_ne!(
        read_exr(&dir.join("a.exr")).rgb(),
        read_exr(&dir.join("b.exr")).rgb()
    );
}

#[test]
fn every_method_renders() {
    let dir = temp_dir("methods");
    for method in ["ppm", "sppm", "freq", "freq-sppm", "path"] {
        let exr = format!("{method}.exr");
        render_cornell(&dir, &["--method", method, "-o", &exr]).ok();
        let image = read_exr(&dir.join(&exr));
        assert_eq!(image.metadata["fppm.method"], method);
        assert!(image.mean() > 0.0, "{method} rendered black");
        assert!(image.rgb().iter().all(|v| v.is_finite()), "{method}");
    }
}

#[test]
fn frequency_flags_take_effect() {
    let dir = temp_dir("freq_flags");
    let base = ["--method", "freq", "--passes", "3"];
    render_cornell(&dir, &[&base[..], &["-o", "a.exr"]].concat()).ok();
    let a = read_exr(&dir.join("a.exr"));
    assert_eq!(a.metadata["fppm.freq_fraction"], "0.1");
    for (name, extra) in [
        ("fraction", &["--freq-fraction", "1"][..]),
        (
            "merge",
            &["--freq-merge", "poster-max", "--freq-fraction", "0.5"][..],
        ),
        ("k", &["--kernel-k", "0.05", "--freq-fraction", "0.5"][..]),
        (
            "floor",
            &["--freq-floor", "clamp", "--freq-fraction", "0.5"][..],
        ),
    ] {
        let out = format!("{name}.exr");
        render_cornell(
            &dir,
            &[&base[..], extra, &["-o", &out, "--aov", "freq"]].concat(),
        )
        .ok();
        let b = read_exr(&dir.join(&out));
        assert!(b.channels.contains_key("freq.radius"), "{name}");
        assert!(b.rgb().iter().all(|v| v.is_finite()), "{name}");
    }
    assert_eq!(a.metadata["fppm.freq_geometry"], "on");
    render_cornell(
        &dir,
        &[&base[..], &["--no-freq-geometry", "-o", "nogeo.exr"]].concat(),
    )
    .ok();
    let nogeo = read_exr(&dir.join("nogeo.exr"));
    assert_eq!(nogeo.metadata["fppm.freq_geometry"], "off");
    assert_ne!(nogeo.rgb(), a.rgb(), "--no-freq-geometry changed nothing");
    let k = read_exr(&dir.join("k.exr"));
    assert_eq!(k.metadata["fppm.kernel_k"], "0.05");
    let fraction = read_exr(&dir.join("fraction.exr"));
    assert_eq!(fraction.metadata["fppm.freq_fraction"], "1");
}

#[test]
fn direct_lighting_flag_renders_and_is_recorded() {
    let dir = temp_dir("direct_lighting");
    render_cornell(&dir, &["--direct-lighting"]).ok();
    let exr = read_exr(&dir.join("fppm.exr"));
    assert!(exr.mean() > 0.0);
    assert_eq!(exr.metadata["fppm.direct_lighting"], "on");
}

#[test]
fn aovs_become_named_channels() {
    let dir = temp_dir("aovs");
    render_cornell(&dir, &["--aov", "radius,count,albedo,normal,depth"]).ok();
    let exr = read_exr(&dir.join("fppm.exr"));
    let names: Vec<&str> = exr.channels.keys().map(String::as_str).collect();
    for name in [
        "R", "G", "B", "radius", "count", "albedo.R", "albedo.G", "albedo.B", "normal.X",
        "normal.Y", "normal.Z", "depth",
    ] {
        assert!(names.contains(&name), "{name} missing from {names:?}");
    }
    let depth = &exr.channels["depth"];
    let seen = depth.iter().filter(|&&d| d > 0.0).count();
    assert!(seen > depth.len() / 2, "most pixels see the box: {seen}");
    assert!(exr.channels["radius"].iter().any(|&r| r > 0.0));

    render_cornell(
        &dir,
        &["--method", "freq", "--aov", "freq", "-o", "freq.exr"],
    )
    .ok();
    let freq = read_exr(&dir.join("freq.exr"));
    assert!(freq.channels.contains_key("freq.radius"));
    assert!(freq.channels.contains_key("freq.held"));
}

#[test]
fn seed_changes_the_image_and_the_same_seed_repeats_it() {
    let dir = temp_dir("seed");
    render_cornell(&dir, &["--seed", "1", "-o", "a.exr"]).ok();
    render_cornell(&dir, &["--seed", "1", "-o", "b.exr"]).ok();
    render_cornell(&dir, &["--seed", "2", "-o", "c.exr"]).ok();
    let (a, b, c) = (
        read_exr(&dir.join("a.exr")),
        read_exr(&dir.join("b.exr")),
        read_exr(&dir.join("c.exr")),
    );
    assert_eq!(a.rgb(), b.rgb());
    assert_ne!(a.rgb(), c.rgb());
}

#[test]
fn thread_count_does_not_change_the_image() {
    let dir = temp_dir("threads");
    render_cornell(
        &dir,
        &["--threads", "1", "-o", "one.exr", "--method", "sppm"],
    )
    .ok();
    render_cornell(
        &dir,
        &["--threads", "2", "-o", "two.exr", "--method", "sppm"],
    )
    .ok();
    let (one, two) = (
        read_exr(&dir.join("one.exr")),
        read_exr(&dir.join("two.exr")),
    );
    let bits = |e: &crate::Exr| e.rgb().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&one), bits(&two));
}

#[test]
fn json_prints_one_object_per_pass_and_a_summary() {
    let dir = temp_dir("json");
    let run = render_cornell(&dir, &["--json", "--passes", "3"]).ok();
    let lines: Vec<serde_json::Value> = run
        .stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 4, "{}", run.stdout);
    for (i, line) in lines[..3].iter().enumerate() {
        assert_eq!(line["event"], "pass");
        assert_eq!(line["pass"], i as u64);
        assert_eq!(line["passes"], i as u64 + 1);
        assert_eq!(line["photons_traced"], 4000);
        assert!(line["elapsed_seconds"].as_f64().unwrap() > 0.0);
        assert!(line["mean_radius"].as_f64().unwrap() > 0.0);
        assert_eq!(line["non_finite"], 0);
    }
    let summary = &lines[3];
    assert_eq!(summary["event"], "done");
    assert_eq!(summary["non_finite"], 0);
    assert_eq!(summary["passes"], 3);
    assert_eq!(summary["photons_emitted"], 12000);
    assert_eq!(summary["interrupted"], false);
}

#[test]
fn quiet_prints_nothing() {
    let dir = temp_dir("quiet");
    let run = render_cornell(&dir, &["--quiet"]).ok();
    assert_eq!(run.stderr, "");
    assert_eq!(run.stdout, "");
    assert_eq!(files(&dir), ["fppm.exr", "fppm.png"]);
}

#[test]
fn plain_progress_lines_when_not_a_terminal() {
    let dir = temp_dir("progress");
    let run = render_cornell(&dir, &[]).ok();
    assert!(run.stderr.contains("pass 1/2"), "{}", run.stderr);
    assert!(run.stderr.contains("pass 2/2"), "{}", run.stderr);
    assert!(run.stderr.contains("photons"), "{}", run.stderr);
}

#[test]
fn time_budget_stops_the_render() {
    let dir = temp_dir("time");
    let run = fppm(
        &dir,
        &[
            "render",
            CORNELL,
            "--width",
            "16",
            "--height",
            "16",
            "--photons-per-pass",
            "1000",
            "--time",
            "300ms",
            "--json",
        ],
    )
    .ok();
    let summary: serde_json::Value =
        serde_json::from_str(run.stdout.lines().last().unwrap()).unwrap();
    let passes = summary["passes"].as_u64().unwrap();
    assert!(passes >= 1, "{summary}");
    assert!(summary["seconds"].as_f64().unwrap() >= 0.3);
    // Both budgets: the pass count wins when it comes first.
    let run = fppm(
        &dir,
        &[
            "render",
            CORNELL,
            "--width",
            "16",
            "--height",
            "16",
            "--photons-per-pass",
            "1000",
            "--time",
            "1h",
            "--passes",
            "2",
            "--json",
        ],
    )
    .ok();
    let summary: serde_json::Value =
        serde_json::from_str(run.stdout.lines().last().unwrap()).unwrap();
    assert_eq!(summary["passes"], 2);
}

#[test]
fn png_exposure_and_tone_curve() {
    let dir = temp_dir("png");
    render_cornell(&dir, &["--seed", "3", "--png", "plain.png"]).ok();
    render_cornell(
        &dir,
        &["--seed", "3", "--png", "bright.png", "--exposure", "2"],
    )
    .ok();
    render_cornell(
        &dir,
        &["--seed", "3", "--png", "filmic.png", "--tonemap", "filmic"],
    )
    .ok();
    let mean = |name: &str| {
        let img = image::open(dir.join(name)).unwrap().to_rgb8();
        img.as_raw().iter().map(|&v| f64::from(v)).sum::<f64>() / img.as_raw().len() as f64
    };
    let (plain, bright, filmic) = (mean("plain.png"), mean("bright.png"), mean("filmic.png"));
    assert!(bright > plain + 10.0, "{plain} {bright}");
    assert!((filmic - plain).abs() > 0.1, "{plain} {filmic}");
    let raw = |name: &str| image::open(dir.join(name)).unwrap().to_rgb8().into_raw();
    assert_ne!(raw("filmic.png"), raw("plain.png"));
}

#[test]
fn snapshots_rewrite_the_outputs_during_the_render() {
    let dir = temp_dir("snapshots");
    let run = render_cornell(&dir, &["--snapshot-every", "1ms", "--passes", "3"]).ok();
    let snapshots = run.stderr.matches("snapshot written to fppm.exr").count();
    assert!(snapshots >= 2, "{}", run.stderr);
    assert_eq!(files(&dir), ["fppm.exr", "fppm.png"]);
}

fn image_size(path: &std::path::Path) -> (u32, u32) {
    let img = image::open(path).unwrap();
    (img.width(), img.height())
}

/// A scene whose photons overflow f32 (huge emission, a nearly smooth glossy sphere): the
/// dropped values are reported per pass and in the summary, with one warning, and the image is
/// finite.
#[test]
fn dropped_non_finite_values_are_reported() {
    let dir = temp_dir("non_finite");
    let scene = r#"
format = 1
[camera]
position = [0.0, 1.0, 3.0]
look_at = [0.0, 1.0, 0.0]
fov_y = 40.0
[film]
width = 16
height = 16
[materials.white]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]
[materials.shiny]
type = "glossy"
reflectance = [0.9, 0.9, 0.9]
roughness = 1e-12
[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [1e37, 1e37, 1e37]
[[shapes]]
type = "quad"
corner = [-1.0, 0.0, 1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -2.0]
material = "white"
[[shapes]]
type = "quad"
corner = [-1.0, 1.99, -1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 0.0, 2.0]
material = "lamp"
[[shapes]]
type = "sphere"
center = [0.0, 0.5, 0.0]
radius = 0.4
material = "shiny"
"#;
    std::fs::write(dir.join("hot.toml"), scene).unwrap();
    let run = fppm(
        &dir,
        &[
            "render",
            "hot.toml",
            "--photons-per-pass",
            "5000",
            "--passes",
            "2",
            "--json",
        ],
    )
    .ok();
    let lines: Vec<serde_json::Value> = run
        .stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let per_pass: u64 = lines[..2]
        .iter()
        .map(|l| l["non_finite"].as_u64().unwrap())
        .sum();
    assert!(per_pass > 0, "{}", run.stdout);
    assert_eq!(lines[2]["non_finite"], per_pass);
    assert!(
        run.stderr.contains(&format!(
            "warning: {per_pass} NaN or infinite values were dropped"
        )),
        "{}",
        run.stderr
    );
    let image = read_exr(&dir.join("fppm.exr"));
    assert!(image.rgb().iter().all(|v| v.is_finite()));
}
