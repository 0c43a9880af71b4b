//! Every bad input of the issue: the exit code, one line naming the file or the flag, and no
//! output file left behind.

use std::path::Path;

use crate::{CORNELL, TINY, files, fppm, render_cornell, temp_dir};

/// Runs `args` in a fresh directory and checks the failure; the directory must stay empty
/// (apart from the `keep` files the test put there).
#[track_caller]
fn check(name: &str, args: &[&str], code: i32, needles: &[&str]) {
    let dir = temp_dir(name);
    check_in(&dir, args, code, needles, &[]);
}

#[track_caller]
fn check_in(dir: &Path, args: &[&str], code: i32, needles: &[&str], keep: &[&str]) {
    fppm(dir, args).fails(code, needles);
    assert_eq!(files(dir), keep, "files left behind after {args:?}");
}

#[test]
fn missing_scene() {
    check(
        "missing_scene",
        &["render", "no-such-scene.toml"],
        1,
        &["no-such-scene.toml", "cannot read file"],
    );
}

#[test]
fn unknown_extension() {
    check(
        "unknown_extension",
        &["render", "scene.blend"],
        1,
        &["scene.blend", "unsupported scene file extension"],
    );
}

#[test]
fn unwritable_output_directory() {
    let dir = temp_dir("unwritable");
    // A directory that does not exist, and a "directory" that is a file: unwritable even for root.
    check_in(
        &dir,
        &[&["render", CORNELL, "-o", "missing-dir/out.exr"], TINY].concat(),
        1,
        &["missing-dir", "cannot write"],
        &[],
    );
    std::fs::write(dir.join("plain-file"), "x").unwrap();
    check_in(
        &dir,
        &[&["render", CORNELL, "--png", "plain-file/out.png"], TINY].concat(),
        1,
        &["plain-file", "--png", "cannot write"],
        &["plain-file"],
    );
    check_in(
        &dir,
        &[
            &["render", CORNELL, "--checkpoint", "missing-dir/state.fppm"],
            TINY,
        ]
        .concat(),
        1,
        &["missing-dir", "--checkpoint"],
        &["plain-file"],
    );
}

#[test]
fn zero_time() {
    check(
        "zero_time",
        &["render", CORNELL, "--time", "0s"],
        2,
        &["--time", "0s", "longer than zero"],
    );
    check(
        "bad_time",
        &["render", CORNELL, "--time", "soon"],
        2,
        &["--time", "soon"],
    );
    check(
        "zero_snapshot",
        &["render", CORNELL, "--snapshot-every", "0ms"],
        2,
        &["--snapshot-every"],
    );
}

#[test]
fn negative_or_zero_photons() {
    check(
        "negative_photons",
        &["render", CORNELL, "--photons-per-pass", "-5"],
        2,
        &["--photons-per-pass", "-5", "positive"],
    );
    check(
        "zero_photons",
        &["render", CORNELL, "--photons-per-pass", "0"],
        2,
        &["--photons-per-pass", "0", "positive"],
    );
    check(
        "word_photons",
        &["render", CORNELL, "--photons-per-pass", "many"],
        2,
        &["--photons-per-pass", "many"],
    );
}

#[test]
fn unknown_method() {
    check(
        "unknown_method",
        &["render", CORNELL, "--method", "mlt"],
        2,
        &["--method", "mlt", "ppm", "freq-sppm", "vcm", "bdpt"],
    );
}

#[test]
fn alpha_outside_its_range() {
    check(
        "alpha_high",
        &["render", CORNELL, "--alpha", "1.5"],
        2,
        &["--alpha 1.5 is outside (0, 1]"],
    );
    check(
        "alpha_zero",
        &["render", CORNELL, "--alpha", "0"],
        2,
        &["--alpha 0 is outside (0, 1]"],
    );
    check(
        "alpha_negative",
        &["render", CORNELL, "--alpha", "-0.5"],
        2,
        &["--alpha -0.5 is outside (0, 1]"],
    );
}

#[test]
fn freq_fraction_outside_its_range() {
    check(
        "freq_fraction_high",
        &["render", CORNELL, "--freq-fraction", "1.5"],
        2,
        &["--freq-fraction 1.5 is outside [0, 1]"],
    );
    check(
        "freq_fraction_low",
        &["render", CORNELL, "--freq-fraction", "-0.1"],
        2,
        &["--freq-fraction -0.1 is outside [0, 1]"],
    );
}

#[test]
fn other_flag_ranges() {
    check(
        "passes_zero",
        &["render", CORNELL, "--passes", "0"],
        2,
        &["--passes 0"],
    );
    check(
        "threads_zero",
        &["render", CORNELL, "--threads", "0"],
        2,
        &["--threads 0"],
    );
    check(
        "width_zero",
        &["render", CORNELL, "--width", "0"],
        2,
        &["--width 0"],
    );
    check(
        "spp_zero",
        &["render", CORNELL, "--spp", "0"],
        2,
        &["--spp 0"],
    );
    check(
        "max_depth_zero",
        &["render", CORNELL, "--max-depth", "0"],
        2,
        &["--max-depth 0"],
    );
    check(
        "radius_negative",
        &["render", CORNELL, "--initial-radius", "-1"],
        2,
        &["--initial-radius -1"],
    );
    check(
        "kernel_k_zero",
        &["render", CORNELL, "--kernel-k", "0"],
        2,
        &["--kernel-k 0"],
    );
    check(
        "merge",
        &["render", CORNELL, "--freq-merge", "max"],
        2,
        &["--freq-merge", "max"],
    );
    check(
        "aov",
        &["render", CORNELL, "--aov", "depth,colour"],
        2,
        &["--aov", "colour"],
    );
    check(
        "aov_method",
        &["render", CORNELL, "--method", "ppm", "--aov", "freq"],
        2,
        &["--aov freq", "frequency method"],
    );
    check(
        "freq_grow_below_one",
        &["render", CORNELL, "--freq-grow", "0.5"],
        2,
        &["freq-grow", "[1, 64]"],
    );
    check(
        "freq_hold_alpha_zero",
        &["render", CORNELL, "--freq-hold-alpha", "0"],
        2,
        &["freq-hold-alpha", "(0, 1]"],
    );
    check(
        "freq_pilot_negative",
        &["render", CORNELL, "--freq-pilot", "-1"],
        2,
        &["--freq-pilot -1"],
    );
    check(
        "aov_path",
        &["render", CORNELL, "--method", "path", "--aov", "radius"],
        2,
        &["--aov radius"],
    );
    check(
        "exr_name",
        &["render", CORNELL, "-o", "out.png"],
        2,
        &["-o out.png", ".exr"],
    );
    check(
        "png_name",
        &["render", CORNELL, "--png", "out.jpg"],
        2,
        &["--png out.jpg", ".png"],
    );
    check(
        "unknown_flag",
        &["render", CORNELL, "--colour", "red"],
        2,
        &["--colour"],
    );
    check("no_scene", &["render"], 2, &["SCENE"]);
    check("unknown_command", &["paint"], 2, &["paint"]);
    // A flag error wins over a missing scene: usage errors come first.
    check(
        "flag_before_scene",
        &["render", "missing.toml", "--alpha", "2"],
        2,
        &["--alpha 2"],
    );
}

#[test]
fn bad_scene_file_names_the_file_and_line() {
    let dir = temp_dir("bad_scene");
    std::fs::write(
        dir.join("bad.toml"),
        "format = 1\n[camera]\nposition = [0, 1]\n",
    )
    .unwrap();
    check_in(
        &dir,
        &["render", "bad.toml"],
        1,
        &["bad.toml"],
        &["bad.toml"],
    );
    std::fs::write(
        dir.join("render.toml"),
        crate::small_default_scene().replace("alpha = 0.7", "alpha = 3.0"),
    )
    .unwrap();
    check_in(
        &dir,
        &["render", "render.toml"],
        1,
        &["render.toml", "[render] alpha 3 is outside (0, 1]"],
        &["bad.toml", "render.toml"],
    );
    // The flag overrides the bad scene value.
    fppm(
        &dir,
        &[
            "render",
            "render.toml",
            "--alpha",
            "0.5",
            "--width",
            "8",
            "--photons-per-pass",
            "500",
            "--passes",
            "1",
            "-o",
            "ok.exr",
        ],
    )
    .ok();
}

#[test]
fn checkpoint_from_another_scene() {
    let dir = temp_dir("checkpoint_other_scene");
    std::fs::write(dir.join("scene.toml"), crate::small_default_scene()).unwrap();
    fppm(
        &dir,
        &[
            "render",
            "scene.toml",
            "--checkpoint",
            "state.fppm",
            "--passes",
            "1",
            "--photons-per-pass",
            "500",
            "-o",
            "a.exr",
        ],
    )
    .ok();
    // The scene changes under the checkpoint.
    let changed = crate::small_default_scene()
        .replace("albedo = [0.75, 0.73, 0.70]", "albedo = [0.5, 0.5, 0.5]");
    assert_ne!(changed, crate::small_default_scene());
    std::fs::write(dir.join("scene.toml"), changed).unwrap();
    let before = files(&dir);
    fppm(&dir, &["resume", "state.fppm", "-o", "b.exr"]).fails(1, &["state.fppm", "another scene"]);
    assert_eq!(files(&dir), before);
    // The same for a change of the curved mirror alone.
    let changed = crate::small_default_scene().replace("radius   = 1.0", "radius   = 0.9");
    assert_ne!(changed, crate::small_default_scene());
    std::fs::write(dir.join("scene.toml"), changed).unwrap();
    fppm(&dir, &["resume", "state.fppm", "-o", "b.exr"]).fails(1, &["state.fppm", "another scene"]);
    assert_eq!(files(&dir), before);
}

#[test]
fn checkpoint_of_another_version_or_not_a_checkpoint() {
    let dir = temp_dir("checkpoint_version");
    let mut bytes = b"FPPMSTAT".to_vec();
    bytes.extend_from_slice(&999u32.to_le_bytes());
    bytes.extend_from_slice(&[0; 64]);
    std::fs::write(dir.join("future.fppm"), &bytes).unwrap();
    std::fs::write(dir.join("text.fppm"), "hello").unwrap();
    let keep = ["future.fppm", "text.fppm"];
    check_in(
        &dir,
        &["resume", "future.fppm"],
        1,
        &["future.fppm", "version 999"],
        &keep,
    );
    check_in(
        &dir,
        &["resume", "text.fppm"],
        1,
        &["text.fppm", "not an fppm checkpoint"],
        &keep,
    );
    check_in(
        &dir,
        &["resume", "none.fppm"],
        1,
        &["none.fppm", "cannot read checkpoint"],
        &keep,
    );
    check_in(
        &dir,
        &["resume", "text.fppm", "--passes", "0"],
        2,
        &["--passes 0"],
        &keep,
    );
}

#[test]
fn a_failed_render_keeps_an_existing_output() {
    let dir = temp_dir("keep_existing");
    render_cornell(&dir, &[]).ok();
    let before = std::fs::read(dir.join("fppm.exr")).unwrap();
    fppm(&dir, &["render", "missing.toml"]).fails(1, &["missing.toml"]);
    assert_eq!(std::fs::read(dir.join("fppm.exr")).unwrap(), before);
    assert_eq!(files(&dir), ["fppm.exr", "fppm.png"]);
}

/// Bad textures: a missing image, one that is not an image and one of a format fppm does not
/// read each fail with exit 1 and one line naming the image, and no output; `info` fails alike.
#[test]
fn bad_textures_name_the_image() {
    let dir = temp_dir("bad_textures");
    let scene = "format = 1\n[materials.m]\ntype = \"diffuse\"\nalbedo = { texture = \"tex.png\" }\nemission = [1, 1, 1]\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n";
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    let args = [&["render", "scene.toml"], TINY].concat();
    check_in(
        &dir,
        &args,
        1,
        &["tex.png", "cannot read texture"],
        &["scene.toml"],
    );
    check_in(
        &dir,
        &["info", "scene.toml"],
        1,
        &["tex.png", "cannot read texture"],
        &["scene.toml"],
    );
    std::fs::write(dir.join("tex.png"), "plain text").unwrap();
    check_in(
        &dir,
        &args,
        1,
        &["tex.png", "unsupported texture format"],
        &["scene.toml", "tex.png"],
    );
    std::fs::write(dir.join("tex.png"), "GIF89a\x01\x00\x01\x00").unwrap();
    check_in(
        &dir,
        &args,
        1,
        &["tex.png", "unsupported texture format gif"],
        &["scene.toml", "tex.png"],
    );
}

/// Absurd sizes are refused from the estimate, before anything is allocated: at once, with how
/// much the render would need and which flag to lower.
#[test]
fn absurd_sizes_are_refused_at_once_with_the_flag_to_lower() {
    let cases: [(&str, &[&str], &[&str]); 5] = [
        (
            "huge_film",
            &["--width", "16384", "--height", "16384", "--spp", "1024"],
            &[
                "needs about",
                "TiB",
                "--width/--height or --spp",
                "--max-memory",
            ],
        ),
        (
            "huge_photon_pass",
            &["--photons-per-pass", "4000M"],
            &["needs about", "TiB", "lower --photons-per-pass"],
        ),
        (
            "photons_beyond_u32",
            &["--photons-per-pass", "10G"],
            &[
                "--photons-per-pass 10G",
                "too large",
                "TiB of photon buffers",
            ],
        ),
        (
            "small_limit",
            &["--max-memory", "1M"],
            &["needs about", "more than the limit of 1.0 MiB"],
        ),
        (
            "bad_limit",
            &["--max-memory", "lots"],
            &["--max-memory lots", "not a size"],
        ),
    ];
    for (name, flags, needles) in cases {
        let dir = temp_dir(name);
        let clock = std::time::Instant::now();
        check_in(
            &dir,
            &[&["render", CORNELL, "--passes", "1"], flags].concat(),
            2,
            needles,
            &[],
        );
        // Generous for a loaded machine: allocating what these ask for would take minutes, or
        // be killed.
        assert!(
            clock.elapsed() < std::time::Duration::from_secs(5),
            "{name} took {:?}",
            clock.elapsed()
        );
    }
    // A limit the render fits in lets it run.
    let dir = temp_dir("limit_that_fits");
    fppm(
        &dir,
        &[&["render", CORNELL, "--max-memory", "2G"], TINY].concat(),
    )
    .ok();
}

/// `--env` with a bad map: exit 1, one line naming the map, nothing written.
#[test]
fn bad_environment_maps() {
    let dir = temp_dir("bad_env");
    check_in(
        &dir,
        &[&["render", CORNELL, "--env", "gone.exr"], TINY].concat(),
        1,
        &["gone.exr", "cannot read file"],
        &[],
    );
    exr::prelude::write_rgb_file(dir.join("square.exr"), 8, 8, |_, _| {
        (1.0f32, 1.0f32, 1.0f32)
    })
    .unwrap();
    check_in(
        &dir,
        &[&["render", CORNELL, "--env", "square.exr"], TINY].concat(),
        1,
        &["square.exr", "invalid environment map", "not 2:1"],
        &["square.exr"],
    );
    exr::prelude::write_rgb_file(dir.join("nan.exr"), 8, 4, |x, _| {
        let v = if x == 1 { f32::NAN } else { 1.0 };
        (v, v, v)
    })
    .unwrap();
    check_in(
        &dir,
        &[&["render", CORNELL, "--env", "nan.exr"], TINY].concat(),
        1,
        &["nan.exr", "texel (1, 0) is not finite"],
        &["nan.exr", "square.exr"],
    );
    std::fs::write(dir.join("sky.hdr"), "#?RADIANCE\ngarbage").unwrap();
    check_in(
        &dir,
        &["info", CORNELL, "--env", "sky.hdr"],
        1,
        &["sky.hdr", "cannot decode"],
        &["nan.exr", "sky.hdr", "square.exr"],
    );
}

/// A scene with participating media asked of a method that does not render them (`vcm`), or of
/// a photon mapper with `--direct-lighting`: a usage error (exit 2) naming the scene and the
/// method or the switch, and no output; the path tracer and the default method render it.
#[test]
fn media_with_a_method_that_cannot_render_them() {
    let dir = temp_dir("media_method");
    let scene = r#"format = 1
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 30.0
medium = "fog"
[film]
width = 8
height = 8
[media.fog]
sigma_a = [0.1, 0.1, 0.1]
sigma_s = [0.2, 0.2, 0.2]
[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
[[shapes]]
type = "quad"
corner = [-1.0, -1.0, 0.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 2.0, 0.0]
material = "lamp"
"#;
    std::fs::write(dir.join("fog.toml"), scene).unwrap();
    check_in(
        &dir,
        &["render", "fog.toml", "--method", "vcm", "--passes", "1"],
        2,
        &["fog.toml", "participating media", "vcm"],
        &["fog.toml"],
    );
    check_in(
        &dir,
        &["render", "fog.toml", "--direct-lighting", "--passes", "1"],
        2,
        &["fog.toml", "direct_lighting", "participating media"],
        &["fog.toml"],
    );
    fppm(
        &dir,
        &["render", "fog.toml", "--method", "path", "--passes", "1"],
    )
    .ok();
    fppm(&dir, &["render", "fog.toml", "--passes", "1"]).ok();
}

/// A medium's density grid that is broken (a `.vol` whose header and size disagree, a negative
/// density, absurd dimensions): one line naming the grid file and the problem, exit 2 (a usage
/// error, as issue #35 asks of bad media input), and no output. A good grid renders with the
/// path tracer.
#[test]
fn bad_density_grids() {
    let dir = temp_dir("bad_grid");
    let scene = r#"format = 1
[camera]
position = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 30.0
[film]
width = 8
height = 8
[media.smoke]
sigma_a = [0.1, 0.1, 0.1]
sigma_s = [2.0, 2.0, 2.0]
[media.smoke.grid]
file = "smoke.vol"
min = [-1.0, -1.0, -1.0]
max = [1.0, 1.0, 1.0]
[materials.boundary]
type = "interface"
[[lights]]
type = "directional"
direction = [0.0, -1.0, -1.0]
irradiance = [3.0, 3.0, 3.0]
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "boundary"
interior = "smoke"
"#;
    std::fs::write(dir.join("smoke.toml"), scene).unwrap();
    // Mitsuba's .vol: "VOL", version 3, encoding 1, x, y, z resolutions, channels, a box, data.
    let vol = |size: [i32; 3], data: &[f32]| {
        let mut out = b"VOL\x03".to_vec();
        for v in [1, size[0], size[1], size[2], 1] {
            out.extend_from_slice(&i32::to_le_bytes(v));
        }
        for v in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0].iter().chain(data) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out
    };
    let cases: [(Vec<u8>, &str); 3] = [
        (vol([2, 2, 2], &[1.0; 5]), "the file has 68"),
        (vol([1, 1, 2], &[1.0, -0.5]), "density value 1 is -0.5"),
        (vol([1 << 20, 1 << 20, 1], &[]), "exceeds the limit"),
    ];
    for (bytes, needle) in cases {
        std::fs::write(dir.join("smoke.vol"), bytes).unwrap();
        check_in(
            &dir,
            &["render", "smoke.toml", "--method", "path", "--passes", "1"],
            2,
            &["smoke.vol", "invalid volume grid file", needle],
            &["smoke.toml", "smoke.vol"],
        );
    }
    std::fs::write(dir.join("smoke.vol"), vol([1, 1, 2], &[1.0, 0.5])).unwrap();
    fppm(
        &dir,
        &["render", "smoke.toml", "--method", "path", "--passes", "1"],
    )
    .ok();
}

/// Bad media (issue #35): a negative coefficient, g outside (−1, 1), a medium inside a mesh that
/// is not closed, in the TOML, Mitsuba and pbrt formats: one line naming the file, the medium or
/// shape and the value, exit 2, and no output.
#[test]
fn bad_media_are_usage_errors() {
    let dir = temp_dir("bad_media");
    let toml = |medium: &str, shape: &str| {
        format!(
            r#"format = 1
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 30.0
[film]
width = 8
height = 8
[media.fog]
{medium}
[materials.boundary]
type = "interface"
[[lights]]
type = "point"
position = [0.0, 3.0, 0.0]
intensity = [1.0, 1.0, 1.0]
{shape}
"#
        )
    };
    let sphere = "[[shapes]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"boundary\"\ninterior = \"fog\"";
    // One face of a cube: a mesh that bounds nothing.
    std::fs::write(
        dir.join("face.obj"),
        "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\nf 1 2 3 4\n",
    )
    .unwrap();
    let open = "[[shapes]]\ntype = \"mesh\"\nfile = \"face.obj\"\nmaterial = \"boundary\"\ninterior = \"fog\"";
    let good = "sigma_a = [0.1, 0.1, 0.1]\nsigma_s = [0.2, 0.2, 0.2]";
    let cases: [(&str, String, &[&str]); 3] = [
        (
            "negative.toml",
            toml(
                "sigma_a = [0.1, -0.1, 0.1]\nsigma_s = [0.2, 0.2, 0.2]",
                sphere,
            ),
            &["negative.toml", "[media.fog] sigma_a", "-0.1"],
        ),
        (
            "anisotropy.toml",
            toml(&format!("{good}\ng = 1.0"), sphere),
            &["anisotropy.toml", "[media.fog] g", "(-1, 1)"],
        ),
        (
            "open.toml",
            toml(good, open),
            &["open.toml", "bounds a medium but is not closed"],
        ),
    ];
    let mut files = vec!["face.obj".to_owned()];
    for (name, text, needles) in cases {
        std::fs::write(dir.join(name), text).unwrap();
        files.push(name.to_owned());
        files.sort();
        let keep: Vec<&str> = files.iter().map(String::as_str).collect();
        check_in(&dir, &["render", name, "--passes", "1"], 2, needles, &keep);
    }
    let mitsuba = r#"<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="30"/><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
  <emitter type="point"><point name="position" x="0" y="3" z="0"/></emitter>
  <shape type="sphere"><bsdf type="null"/>
    <medium type="homogeneous" name="interior"><rgb name="sigma_t" value="1"/><rgb name="albedo" value="0.5"/>
      <phase type="hg"><float name="g" value="-1.5"/></phase></medium></shape>
</scene>"#;
    std::fs::write(dir.join("hg.xml"), mitsuba).unwrap();
    fppm(&dir, &["render", "hg.xml", "--passes", "1"]).fails(2, &["hg.xml", "g", "(-1, 1)"]);
    let pbrt = r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
WorldBegin
LightSource "point" "point3 from" [0 3 0]
MakeNamedMedium "fog" "string type" "homogeneous" "rgb sigma_a" [-1 0 0] "rgb sigma_s" [1 1 1]
AttributeBegin
MediumInterface "fog" ""
Material "interface"
Shape "sphere" "float radius" 1
AttributeEnd
"#;
    std::fs::write(dir.join("fog.pbrt"), pbrt).unwrap();
    fppm(&dir, &["render", "fog.pbrt", "--passes", "1"]).fails(2, &["fog.pbrt", "sigma_a"]);
}

/// Bad spectral input (issue #34): a negative or decreasing wavelength list, a Sellmeier law
/// below 1 in range, unknown named spectra. One line naming the file, the material and the
/// value, exit 2, in the TOML, Mitsuba and pbrt formats.
#[test]
fn bad_spectra_are_usage_errors() {
    let dir = temp_dir("bad_spectra");
    let scene = crate::small_default_scene();
    let albedo = "albedo = [0.75, 0.73, 0.70]";
    assert!(scene.contains(albedo));
    let mirror = "type        = \"mirror\"\nreflectance = [0.95, 0.93, 0.88]";
    assert!(scene.contains(mirror));
    let cases: [(&str, String, &[&str]); 7] = [
        (
            "decreasing.toml",
            scene.replace(
                albedo,
                "albedo = { samples = [[500.0, 0.5], [400.0, 0.4]] }",
            ),
            &[
                "[materials.floor] albedo",
                "wavelengths must increase",
                "400 nm",
            ],
        ),
        (
            "negative.toml",
            scene.replace(
                albedo,
                "albedo = { samples = [[-400.0, 0.5], [700.0, 0.4]] }",
            ),
            &["[materials.floor] albedo", "-400 nm"],
        ),
        (
            "sellmeier.toml",
            scene.replace(
                mirror,
                "type = \"dielectric\"\nior = { sellmeier = [-0.3, 0.0, 0.0, 0.01, 0.01, 0.01] }",
            ),
            &["[materials.mirror] ior", "index of refraction"],
        ),
        (
            "glass.toml",
            scene.replace(mirror, "type = \"dielectric\"\nior = \"glass-unobtainium\""),
            &["[materials.mirror] ior", "glass-unobtainium"],
        ),
        (
            "metal.toml",
            scene.replace(mirror, "type = \"conductor\"\nmetal = \"Mithril\""),
            &["[materials.mirror] metal", "Mithril"],
        ),
        (
            "illuminant.toml",
            scene.replace(
                albedo,
                &format!("{albedo}\nemission = {{ illuminant = \"D50\" }}"),
            ),
            &["[materials.floor] emission", "D50"],
        ),
        (
            "eta.toml",
            scene.replace(
                mirror,
                "type = \"conductor\"\neta = { samples = [[400.0, 0.2], [400.0, 0.3]] }",
            ),
            &["[materials.mirror] eta", "400 nm appears twice"],
        ),
    ];
    let mut keep: Vec<&str> = Vec::new();
    for (name, text, needles) in &cases {
        std::fs::write(dir.join(name), text).unwrap();
        keep.push(name);
        keep.sort_unstable();
        let needles: Vec<&str> = [&[*name][..], needles].concat();
        check_in(&dir, &["render", name], 2, &needles, &keep);
    }
    let xml = r#"<scene version="3.0.0">
    <shape type="sphere"><bsdf type="conductor" id="gold"><string name="material" value="Mithril"/></bsdf></shape>
    <shape type="rectangle"><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
</scene>"#;
    std::fs::write(dir.join("metal.xml"), xml).unwrap();
    keep.push("metal.xml");
    keep.sort_unstable();
    check_in(
        &dir,
        &["render", "metal.xml"],
        2,
        &["metal.xml", "id=\"gold\"", "Mithril"],
        &keep,
    );
    std::fs::write(
        dir.join("metal.xml"),
        xml.replace(
            "<string name=\"material\" value=\"Mithril\"/>",
            "<spectrum name=\"eta\" value=\"500:0.2, 400:0.3\"/>",
        ),
    )
    .unwrap();
    check_in(
        &dir,
        &["render", "metal.xml"],
        2,
        &[
            "metal.xml",
            "line 2",
            "name=\"eta\"",
            "wavelengths must increase",
        ],
        &keep,
    );
    let pbrt = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n\
        Material \"dielectric\" \"spectrum eta\" \"glass-XYZ\"\nShape \"sphere\"\n\
        AttributeBegin\nAreaLightSource \"diffuse\" \"blackbody L\" [ -5 ]\n\
        Shape \"sphere\" \"float radius\" 0.1\nAttributeEnd\n";
    std::fs::write(dir.join("glass.pbrt"), pbrt).unwrap();
    keep.push("glass.pbrt");
    keep.sort_unstable();
    check_in(
        &dir,
        &["render", "glass.pbrt"],
        2,
        &["glass.pbrt", "line 4", "glass-XYZ"],
        &keep,
    );
    std::fs::write(
        dir.join("glass.pbrt"),
        pbrt.replace(
            "\"spectrum eta\" \"glass-XYZ\"",
            "\"spectrum eta\" \"glass-BK7\"",
        ),
    )
    .unwrap();
    check_in(
        &dir,
        &["render", "glass.pbrt"],
        2,
        &["glass.pbrt", "line 7", "blackbody L", "-5"],
        &keep,
    );
}
