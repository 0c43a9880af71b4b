//! Heterogeneous (grid) media in the three scene formats: TOML `[media.NAME.grid]` (inline or
//! a `.vol` file), Mitsuba 3's `heterogeneous` medium with a `gridvolume`, pbrt-v4's
//! `uniformgrid`; every value read into the description, and bad grids refused in one line
//! naming the file.

use glam::Vec3;
use import::{load, write_vol};
use scene::{GridEdge, Medium};

use crate::{assert_names_file, fixture};

/// A TOML scene with a sphere of the medium `smoke` whose table ends in `grid`.
fn toml_scene(grid: &str) -> String {
    format!(
        r#"format = 1
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 30.0
[media.smoke]
sigma_a = [0.1, 0.2, 0.3]
sigma_s = [1.0, 2.0, 3.0]
g = 0.25
{grid}
[materials.boundary]
type = "interface"
[[lights]]
type = "directional"
direction = [0.0, -1.0, 0.0]
irradiance = [3.0, 3.0, 3.0]
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "boundary"
interior = "smoke"
"#
    )
}

fn smoke(d: &scene::SceneDescription) -> &Medium {
    &d.media.list[0]
}

#[test]
fn toml_reads_inline_and_vol_grids() {
    let path = fixture(
        "grid_toml_inline",
        &[(
            "scene.toml",
            &toml_scene(
                "[media.smoke.grid]\nsize = [2, 1, 1]\ndensity = [0.5, 1.5]\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 1.0]\nedge = \"zero\"",
            ),
        )],
    );
    let d = load(&path).unwrap();
    let m = smoke(&d);
    assert_eq!(
        (m.sigma_a, m.sigma_s, m.g),
        (Vec3::new(0.1, 0.2, 0.3), Vec3::new(1.0, 2.0, 3.0), 0.25)
    );
    let grid = m.density.as_ref().unwrap();
    assert_eq!(grid.size(), [2, 1, 1]);
    assert_eq!(grid.data(), &[0.5, 1.5]);
    assert_eq!(grid.edge(), GridEdge::Zero);
    assert_eq!(grid.bounds(), (Vec3::splat(-1.0), Vec3::ONE));
    // `fppm info` shows the grid.
    let summary = d.summary().to_string();
    assert!(
        summary.contains("grid 2x1x1 (max density 1.5, edge zero)"),
        "{summary}"
    );

    // A .vol file: its box by default, clamped at the faces.
    let dir = path.parent().unwrap();
    let vol = write_vol([1, 2, 1], Vec3::splat(-2.0), Vec3::splat(2.0), &[0.25, 4.0]);
    std::fs::write(dir.join("smoke.vol"), vol).unwrap();
    std::fs::write(
        dir.join("file.toml"),
        toml_scene("[media.smoke.grid]\nfile = \"smoke.vol\""),
    )
    .unwrap();
    let d = load(&dir.join("file.toml")).unwrap();
    let grid = smoke(&d).density.clone().unwrap();
    assert_eq!((grid.size(), grid.data()), ([1, 2, 1], &[0.25f32, 4.0][..]));
    assert_eq!(grid.edge(), GridEdge::Clamp);
    assert_eq!(grid.bounds(), (Vec3::splat(-2.0), Vec3::splat(2.0)));
    // The fingerprint sees the grid; a homogeneous medium's is unchanged by grids' existence.
    let mut other = d.clone();
    other.media.list[0].density = None;
    assert_ne!(d.fingerprint(), other.fingerprint());
}

#[test]
fn bad_grids_are_one_line_naming_the_file() {
    let dir = fixture("grid_bad", &[("unused", "")])
        .parent()
        .unwrap()
        .to_path_buf();
    let cases: [(&str, Vec<u8>, &str); 4] = [
        (
            "short.vol",
            write_vol([2, 2, 2], Vec3::ZERO, Vec3::ONE, &[1.0; 7]),
            "needs 80 bytes, the file has 76",
        ),
        (
            "negative.vol",
            write_vol([2, 1, 1], Vec3::ZERO, Vec3::ONE, &[1.0, -2.0]),
            "density value 1 is -2",
        ),
        (
            "huge.vol",
            write_vol([1 << 12, 1 << 12, 1 << 12], Vec3::ZERO, Vec3::ONE, &[]),
            "exceeds the limit",
        ),
        (
            "flat.vol",
            write_vol([1, 1, 1], Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0), &[1.0]),
            "not a finite box",
        ),
    ];
    for (name, bytes, needle) in cases {
        let vol = dir.join(name);
        std::fs::write(&vol, bytes).unwrap();
        let scene = dir.join(format!("{name}.toml"));
        std::fs::write(
            &scene,
            toml_scene(&format!("[media.smoke.grid]\nfile = {name:?}")),
        )
        .unwrap();
        let err = load(&scene).unwrap_err();
        assert_names_file(&err, &vol);
        assert!(err.to_string().contains(needle), "{err}");
    }
    // Inline: the scene file is named.
    for (grid, needle) in [
        (
            "size = [2, 2, 1]\ndensity = [1.0, 2.0]",
            "needs 4 density values, got 2",
        ),
        (
            "size = [1, 1, 1]\ndensity = [-1.0]",
            "density value 0 is -1",
        ),
        ("size = [0, 1, 1]\ndensity = []", "zero dimension"),
        (
            "size = [1, 1, 1]\ndensity = [1.0]\nedge = \"wrap\"",
            "\"clamp\" or \"zero\"",
        ),
        ("density = [1.0]", "give either file, or size and density"),
    ] {
        let scene = dir.join("inline.toml");
        std::fs::write(&scene, toml_scene(&format!("[media.smoke.grid]\n{grid}"))).unwrap();
        let err = load(&scene).unwrap_err();
        assert_names_file(&err, &scene);
        assert!(err.to_string().contains(needle), "{err}");
    }
}

const MITSUBA: &str = r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    </sensor>
    <emitter type="directional">
        <vector name="direction" value="0, -1, 0"/>
        <rgb name="irradiance" value="3"/>
    </emitter>
    <medium type="heterogeneous" id="smoke">
        <volume name="sigma_t" type="gridvolume">
            <string name="filename" value="smoke.vol"/>
            <transform name="to_world"><scale value="2"/><translate x="-1" y="-1" z="-1"/></transform>
        </volume>
        <rgb name="albedo" value="0.8, 0.5, 0.25"/>
        <float name="scale" value="4"/>
        <phase type="hg"><float name="g" value="0.3"/></phase>
    </medium>
    <shape type="cube">
        <bsdf type="null"/>
        <ref name="interior" id="smoke"/>
    </shape>
</scene>"#;

#[test]
fn mitsuba_heterogeneous_gridvolume() {
    let path = fixture("grid_mitsuba", &[("scene.xml", MITSUBA)]);
    let dir = path.parent().unwrap();
    std::fs::write(
        dir.join("smoke.vol"),
        write_vol([2, 1, 1], Vec3::splat(7.0), Vec3::splat(9.0), &[0.5, 1.0]),
    )
    .unwrap();
    let d = load(&path).unwrap();
    let m = smoke(&d);
    // σs = scale·albedo, σa = scale·(1 − albedo) at density 1; the grid is the file's values.
    assert!(
        (m.sigma_s - Vec3::new(3.2, 2.0, 1.0)).abs().max_element() < 1e-5,
        "{m:?}"
    );
    assert!(
        (m.sigma_a - Vec3::new(0.8, 2.0, 3.0)).abs().max_element() < 1e-5,
        "{m:?}"
    );
    assert!((m.g - 0.3).abs() < 1e-6);
    let grid = m.density.as_ref().unwrap();
    assert_eq!((grid.size(), grid.edge()), ([2, 1, 1], GridEdge::Clamp));
    // The unit cube through to_world (the file's box is ignored, as Mitsuba does): the
    // world box is [-1, 1]³; x = 0.5 is the second voxel's centre.
    assert_eq!(grid.bounds(), (Vec3::ZERO, Vec3::ONE));
    assert!((grid.density(Vec3::new(0.5, 0.0, 0.0)) - 1.0).abs() < 1e-5);
    assert!((grid.density(Vec3::new(-0.5, 0.0, 0.0)) - 0.5).abs() < 1e-5);
    assert_eq!(grid.density(Vec3::new(1.5, 0.0, 0.0)), 0.0);

    // The volume declared at the top level and referred to by id reads the same.
    let volume = r#"<volume name="sigma_t" type="gridvolume">
            <string name="filename" value="smoke.vol"/>
            <transform name="to_world"><scale value="2"/><translate x="-1" y="-1" z="-1"/></transform>
        </volume>"#;
    assert!(MITSUBA.contains(volume));
    let by_ref = MITSUBA
        .replace(volume, r#"<ref name="sigma_t" id="grid"/>"#)
        .replace(
            "<medium type=",
            &format!(
                "{}\n    <medium type=",
                volume.replace(r#"name="sigma_t""#, r#"id="grid""#)
            ),
        );
    std::fs::write(&path, &by_ref).unwrap();
    let d = load(&path).unwrap();
    assert_eq!(smoke(&d).density.as_ref(), Some(grid), "{by_ref}");
    std::fs::write(&path, MITSUBA).unwrap();
    // A corrupt file: one line naming the scene and the grid file.
    std::fs::write(dir.join("smoke.vol"), b"VOL\x03").unwrap();
    let err = load(&path).unwrap_err();
    assert_names_file(&err, &path);
    assert!(
        err.to_string()
            .contains("smoke.vol: invalid volume grid file"),
        "{err}"
    );
    // Unsupported wrap modes are refused rather than read differently.
    let wrap = MITSUBA.replace(
        r#"<string name="filename" value="smoke.vol"/>"#,
        r#"<string name="filename" value="smoke.vol"/><string name="wrap_mode" value="repeat"/>"#,
    );
    std::fs::write(&path, wrap).unwrap();
    let err = load(&path).unwrap_err();
    assert!(err.to_string().contains("wrap_mode \"repeat\""), "{err}");
}

#[test]
fn pbrt_uniformgrid() {
    let scene = r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 45 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
WorldBegin
LightSource "point" "rgb I" [ 5 5 5 ] "point3 from" [ 0 3 3 ]
AttributeBegin
  Translate 10 0 0
  MakeNamedMedium "smoke" "string type" "uniformgrid"
      "float density" [ 0 1 2 3 ] "integer nx" 2 "integer ny" 2
      "point3 p0" [ -1 -1 -1 ] "point3 p1" [ 1 1 1 ]
      "rgb sigma_a" [ 1 1 1 ] "rgb sigma_s" [ 2 3 4 ] "float scale" 0.5 "float g" -0.2
AttributeEnd
AttributeBegin
  MediumInterface "smoke" ""
  Material "interface"
  Shape "sphere" "float radius" 1
AttributeEnd
"#;
    let path = fixture("grid_pbrt", &[("scene.pbrt", scene)]);
    let d = load(&path).unwrap();
    let m = smoke(&d);
    assert_eq!(m.sigma_a, Vec3::splat(0.5));
    assert_eq!(m.sigma_s, Vec3::new(1.0, 1.5, 2.0));
    assert!((m.g + 0.2).abs() < 1e-6);
    let grid = m.density.as_ref().unwrap();
    assert_eq!((grid.size(), grid.edge()), ([2, 2, 1], GridEdge::Zero));
    assert_eq!(grid.data(), &[0.0, 1.0, 2.0, 3.0]);
    // Placed by the transform at MakeNamedMedium: the box's centre is (10, 0, 0) in the world
    // (the camera's mirror fix keeps x here: pbrt's LookAt frame is left-handed, fixed by
    // flipping the world's x, so the box lands at x = ±10).
    let centre = grid.to_world().transform_point3(Vec3::ZERO);
    assert!(
        (centre.x.abs() - 10.0).abs() < 1e-4 && centre.y.abs() < 1e-4,
        "{centre}"
    );
    // Mean of the four samples at the centre (z: a single layer).
    assert!((grid.density(centre) - 1.5).abs() < 1e-4);

    let bad = scene.replace(r#""integer nx" 2"#, r#""integer nx" 3"#);
    std::fs::write(&path, bad).unwrap();
    let err = load(&path).unwrap_err();
    assert_names_file(&err, &path);
    assert!(
        err.to_string().contains("needs 6 density values, got 4"),
        "{err}"
    );
    let huge = scene.replace(
        r#""integer nx" 2"#,
        r#""integer nx" 100000 "integer nz" 100000"#,
    );
    std::fs::write(&path, huge).unwrap();
    let err = load(&path).unwrap_err();
    assert!(err.to_string().contains("exceeds the limit"), "{err}");
}
