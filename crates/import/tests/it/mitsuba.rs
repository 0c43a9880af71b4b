//! Mitsuba 3 XML scenes: every shared scene loads, with counts derived independently of the
//! importer, summaries snapshotted, and one test per kind of bad input.

use std::path::{Path, PathBuf};

use import::{LoadError, LoadOptions, load, load_with};

use crate::{assert_names_file, fixture, shared_scenes};

fn mitsuba(rel: &str) -> PathBuf {
    shared_scenes().join("mitsuba3").join(rel)
}

/// Triangles of an OBJ file: each `f` line of n vertices is n − 2 triangles.
fn obj_triangles(path: &Path) -> usize {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("f "))
        .map(|f| f.split_whitespace().count() - 2)
        .sum()
}

/// The `element face N` count of a PLY header (every bunny face is a triangle: its header
/// says `property list uchar int vertex_indices` and VCG writes triangles only).
fn ply_faces(path: &Path) -> usize {
    let bytes = std::fs::read(path).unwrap();
    let header = String::from_utf8_lossy(&bytes[..bytes.len().min(1024)]).into_owned();
    header
        .lines()
        .find_map(|l| l.strip_prefix("element face "))
        .unwrap()
        .trim()
        .parse()
        .unwrap()
}

/// (triangles, emissive triangles, materials) expected of each shared scene, and how they
/// were derived.
fn expected(rel: &str) -> (usize, usize, usize) {
    let cbox = mitsuba("scenes/cbox/meshes");
    let obj = |name: &str| obj_triangles(&cbox.join(format!("cbox_{name}.obj")));
    // The eight OBJ files of the box; the luminaire is the only emitter. Materials: the five
    // BSDFs (light, white, red, green, box) each used by some shape; the light's gets the
    // emission.
    let cbox_all = [
        "luminaire",
        "floor",
        "ceiling",
        "back",
        "greenwall",
        "redwall",
        "smallbox",
        "largebox",
    ]
    .iter()
    .map(|n| obj(n))
    .sum::<usize>();
    // matpreview.serialized: SOURCE.md reports shapes 0/1/2 as 512, 3,936 and 57,152
    // triangles (read by Mitsuba 3.9.1).
    let (plane, interior, shell) = (512, 3936, 57_152);
    match rel {
        "scenes/cbox/cbox.xml" | "scenes/cbox/cbox-rgb.xml" | "scenes/cbox/cbox-spectral.xml" => {
            (cbox_all, obj("luminaire"), 5)
        }
        // object_bsdf on the shell, diffmat on the interior, planemat on the plane.
        "docs/scenes/bsdf_dielectric_diamond.xml" | "docs/scenes/bsdf_diffuse_textured.xml" => {
            (plane + interior + shell, 0, 3)
        }
        // The leaf quad (rectangle.obj) plus the plane; object_bsdf and planemat.
        "docs/scenes/bsdf_mask_after.xml" => (
            obj_triangles(&mitsuba("common/meshes/rectangle.obj")) + plane,
            0,
            2,
        ),
        "docs/scenes/shape_ply_bunny.xml" => {
            (ply_faces(&mitsuba("common/meshes/bunny.ply")) + plane, 0, 2)
        }
        other => panic!("no expectation for {other}"),
    }
}

const SCENES: &[&str] = &[
    "scenes/cbox/cbox.xml",
    "scenes/cbox/cbox-rgb.xml",
    "scenes/cbox/cbox-spectral.xml",
    "docs/scenes/bsdf_dielectric_diamond.xml",
    "docs/scenes/bsdf_diffuse_textured.xml",
    "docs/scenes/bsdf_mask_after.xml",
    "docs/scenes/shape_ply_bunny.xml",
];

#[test]
fn every_shared_mitsuba_scene_loads_with_independent_counts() {
    for rel in SCENES {
        let scene = load_with(&mitsuba(rel), &LoadOptions::allow_no_emitter()).unwrap();
        let s = scene.summary();
        let (triangles, emissive, materials) = expected(rel);
        assert_eq!(
            s.triangles + s.degenerate_triangles,
            triangles,
            "{rel} triangles"
        );
        assert_eq!(s.emissive_triangles, emissive, "{rel} emissive triangles");
        assert_eq!(s.materials.len(), materials, "{rel} materials");
        assert!(!s.camera_framed, "{rel} has a sensor");
        let mut summary = s.clone();
        summary.source = format!("mitsuba3/{rel}");
        let name = format!("mitsuba__{}", rel.replace(['/', '.'], "_"));
        insta::assert_yaml_snapshot!(name, summary);
    }
}

#[test]
fn cornell_boxes_render_settings_follow_mitsuba() {
    let scene = load(&mitsuba("scenes/cbox/cbox-rgb.xml")).unwrap();
    // `$res` defaults to 256; fov_axis "smaller" on a square film is the vertical fov.
    assert_eq!((scene.film.width, scene.film.height), (256, 256));
    assert!((scene.camera.fov_y.to_degrees() - 39.3077).abs() < 1e-3);
    // Mitsuba's max_depth 6 counts path segments: 5 scattering events in fppm's convention.
    assert_eq!(scene.render.get("max_depth"), Some("5"));
    // The emitter declared after the includes reaches the light through <ref>.
    let light = scene
        .materials
        .iter()
        .find(|m| m.emission.max_element() > 0.0)
        .unwrap();
    assert_eq!(light.emission.to_array(), [18.387, 10.9873, 2.75357]);
    // The spectral file gives the same geometry as the RGB one.
    let spectral = load(&mitsuba("scenes/cbox/cbox-spectral.xml")).unwrap();
    assert_eq!(spectral.triangles.len(), scene.triangles.len());
    for (a, b) in spectral.triangles.iter().zip(&scene.triangles) {
        assert_eq!(a.positions, b.positions);
    }
}

#[test]
fn envmap_only_scene_loads_with_its_environment() {
    let path = mitsuba("docs/scenes/shape_ply_bunny.xml");
    let scene = load(&path).unwrap();
    let env = scene.environment.as_ref().unwrap();
    let scene::EnvironmentRadiance::Map(map) = &env.radiance else {
        panic!("{env:?}");
    };
    assert!(map.path.ends_with("museum.exr"), "{}", map.path.display());
    assert_eq!((map.width, map.height), (512, 256));
    scene::Scene::new(scene).unwrap();
}

/// A small valid scene: a rectangle lit by a point light, with a parameter.
const BASE: &str = r#"<scene version="3.0.0">
    <default name="res" value="32"/>
    <bsdf type="diffuse" id="white">
        <rgb name="reflectance" value="0.8"/>
    </bsdf>
    <shape type="rectangle">
        <ref id="white"/>
    </shape>
    <emitter type="point">
        <point name="position" x="0" y="0" z="2"/>
        <rgb name="intensity" value="5"/>
    </emitter>
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world">
            <lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <film type="hdrfilm">
            <integer name="width" value="$res"/>
            <integer name="height" value="$res"/>
        </film>
    </sensor>
</scene>
"#;

fn load_edited(
    test: &str,
    from: &str,
    to: &str,
) -> (Result<scene::SceneDescription, LoadError>, PathBuf) {
    assert!(BASE.contains(from), "{from:?} not in the base scene");
    let path = fixture(test, &[("scene.xml", &BASE.replacen(from, to, 1))]);
    (load(&path), path)
}

#[test]
fn base_scene_loads() {
    let path = fixture("mitsuba_base", &[("scene.xml", BASE)]);
    let scene = load(&path).unwrap();
    assert_eq!(scene.triangles.len(), 2);
    assert_eq!(scene.film.width, 32);
    // Mitsuba's default fov_axis is x; on a square film that is also the vertical fov.
    assert!((scene.camera.fov_y.to_degrees() - 45.0).abs() < 1e-4);
}

/// Asserts a one-line message naming the file and containing every fragment.
#[track_caller]
fn assert_message(err: &LoadError, file: &Path, fragments: &[&str]) {
    assert_names_file(err, file);
    let msg = err.to_string();
    for f in fragments {
        assert!(msg.contains(f), "{msg:?} lacks {f:?}");
    }
}

#[test]
fn malformed_xml() {
    let (err, path) = load_edited("mitsuba_malformed", "</shape>", "</shap>");
    assert_message(&err.unwrap_err(), &path, &["line 8", "malformed xml"]);
}

#[test]
fn unknown_tag() {
    let (err, path) = load_edited(
        "mitsuba_unknown_tag",
        "<ref id=\"white\"/>",
        "<colour value=\"1\"/>",
    );
    assert_message(
        &err.unwrap_err(),
        &path,
        &["line 7", "unknown element <colour>"],
    );
}

#[test]
fn missing_parameter_default() {
    let (err, path) = load_edited(
        "mitsuba_missing_param",
        "<default name=\"res\" value=\"32\"/>",
        "",
    );
    assert_message(
        &err.unwrap_err(),
        &path,
        &["line 19", "undefined parameter $res"],
    );
}

#[test]
fn ref_to_nothing() {
    let (err, path) = load_edited(
        "mitsuba_bad_ref",
        "<ref id=\"white\"/>",
        "<ref id=\"black\"/>",
    );
    assert_message(
        &err.unwrap_err(),
        &path,
        &["line 7", "<ref id=\"black\">", "no element defines"],
    );
}

#[test]
fn include_cycle() {
    let path = fixture(
        "mitsuba_cycle",
        &[
            (
                "scene.xml",
                "<scene version=\"3.0.0\">\n<include filename=\"a.xml\"/>\n</scene>\n",
            ),
            (
                "a.xml",
                "<scene version=\"3.0.0\">\n  <include filename=\"scene.xml\"/>\n</scene>\n",
            ),
        ],
    );
    let err = load(&path).unwrap_err();
    let a = path.with_file_name("a.xml");
    assert_message(&err, &a, &["line 2", "include cycle"]);
}

#[test]
fn wrong_property_type() {
    let (err, path) = load_edited(
        "mitsuba_wrong_type",
        "<float name=\"fov\" value=\"45\"/>",
        "<string name=\"fov\" value=\"45\"/>",
    );
    assert_message(&err.unwrap_err(), &path, &["line 14", "must be a <float>"]);
    let (err, path) = load_edited("mitsuba_wrong_arity", "value=\"0.8\"", "value=\"0.8 0.1\"");
    assert_message(&err.unwrap_err(), &path, &["line 4", "1 or 3 values"]);
}

#[test]
fn missing_mesh_file() {
    let (err, path) = load_edited(
        "mitsuba_missing_mesh",
        "<shape type=\"rectangle\">",
        "<shape type=\"ply\"><string name=\"filename\" value=\"nope.ply\"/>",
    );
    assert_message(
        &err.unwrap_err(),
        &path,
        &[
            "line 6",
            "<shape type=\"ply\">",
            "nope.ply",
            "cannot read file",
        ],
    );
}

#[test]
fn lying_ply_header() {
    let ply = "ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let scene = BASE.replacen(
        "<shape type=\"rectangle\">",
        "<shape type=\"ply\"><string name=\"filename\" value=\"lie.ply\"/>",
        1,
    );
    let path = fixture(
        "mitsuba_lying_ply",
        &[("scene.xml", &scene), ("lie.ply", ply)],
    );
    let err = load(&path).unwrap_err();
    assert_message(
        &err,
        &path,
        &["line 6", "lie.ply", "header declares 1000 vertex"],
    );
}

#[test]
fn no_emitter_at_all_is_an_error() {
    let (err, path) = load_edited(
        "mitsuba_no_emitter",
        "<emitter type=\"point\">",
        "<emitter type=\"sunsky\">",
    );
    let err = err.unwrap_err();
    assert!(matches!(err, LoadError::NoSupportedEmitter { .. }), "{err}");
    assert_message(&err, &path, &["<emitter type=\"sunsky\">"]);
}

#[test]
fn missing_texture_file() {
    let (err, path) = load_edited(
        "mitsuba_missing_texture",
        "<rgb name=\"reflectance\" value=\"0.8\"/>",
        "<texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"wood.png\"/></texture>",
    );
    assert_message(
        &err.unwrap_err(),
        &path,
        &[
            "line 4",
            "<texture type=\"bitmap\"",
            "wood.png",
            "cannot read texture",
        ],
    );
}

#[test]
fn serialized_shape_index_out_of_range() {
    let path = mitsuba("common/meshes/matpreview.serialized");
    let scene = BASE.replacen(
        "<shape type=\"rectangle\">",
        &format!(
            "<shape type=\"serialized\"><string name=\"filename\" value=\"{}\"/><integer name=\"shape_index\" value=\"3\"/>",
            path.display()
        ),
        1,
    );
    let file = fixture("mitsuba_serialized_index", &[("scene.xml", &scene)]);
    let err = load(&file).unwrap_err();
    assert_message(
        &err,
        &file,
        &[
            "line 6",
            "shape_index 3 is out of range (the file holds 3 meshes)",
        ],
    );
}

/// Scenes of version 0.6 use camelCase names and `<lookAt>`; they are upgraded as Mitsuba does.
#[test]
fn version_0_6_names_are_upgraded() {
    let old = BASE
        .replace("version=\"3.0.0\"", "version=\"0.6.0\"")
        .replace("<lookat ", "<lookAt ")
        .replace("name=\"to_world\"", "name=\"toWorld\"")
        .replace(
            "<sensor type=\"perspective\">",
            "<integrator type=\"path\"><integer name=\"maxDepth\" value=\"4\"/><integer name=\"rrDepth\" value=\"7\"/></integrator>\n    <sensor type=\"perspective\">",
        );
    let path = fixture("mitsuba_v06", &[("scene.xml", &old)]);
    let scene = load(&path).unwrap();
    assert_eq!(scene.render.get("max_depth"), Some("3"));
    // Both renderers apply the roulette from the rr_depth-th bounce on: carried as is.
    assert_eq!(scene.render.get("rr_depth"), Some("7"));
    assert_eq!(scene.camera.position, glam::Vec3::new(0.0, 0.0, 4.0));
}

/// Transform composition and the lookat frame against Mitsuba 3.9.1 itself: the corners of
/// the two rectangles below, as `mi.traverse(shape)['to_world'] @ corner` gives them
/// (`scalar_rgb`, printed to 6 decimals).
#[test]
fn transforms_match_mitsuba() {
    let xml = r#"<scene version="3.0.0">
  <shape type="rectangle">
    <transform name="to_world">
      <scale x="2" y="0.5" z="1"/>
      <rotate x="1" y="1" z="0" angle="30"/>
      <translate x="1" y="-2" z="0.5"/>
      <matrix value="0 -1 0 3  1 0 0 0  0 0 1 -1  0 0 0 1"/>
    </transform>
  </shape>
  <shape type="rectangle">
    <transform name="to_world">
      <lookat origin="1, 2, 3" target="4, 6, 3" up="0, 0, 1"/>
    </transform>
  </shape>
</scene>"#;
    let path = fixture("mitsuba_transforms", &[("scene.xml", xml)]);
    let scene = load_with(&path, &LoadOptions::allow_no_emitter()).unwrap();
    // Corners (−1,−1), (1,−1), (1,1), (−1,1) of each rectangle, from Mitsuba.
    let mitsuba = [
        [
            [5.767949, -1.066987, 0.25],
            [5.232051, 2.933013, -1.75],
            [4.232051, 3.066987, -1.25],
            [4.767949, -0.933013, 0.75],
        ],
        [
            [1.8, 1.4, 2.0],
            [0.2, 2.6, 2.0],
            [0.2, 2.6, 4.0],
            [1.8, 1.4, 4.0],
        ],
    ];
    assert_eq!(scene.triangles.len(), 4);
    for (r, corners) in mitsuba.iter().enumerate() {
        // The rectangle's triangles are (0, 1, 2) and (0, 2, 3).
        let t = &scene.triangles[2 * r..2 * r + 2];
        let ours = [
            t[0].positions[0],
            t[0].positions[1],
            t[0].positions[2],
            t[1].positions[2],
        ];
        for (a, b) in ours.iter().zip(corners) {
            assert!(
                (*a - glam::Vec3::from_array(*b)).abs().max_element() < 2e-5,
                "rectangle {r}: {a} vs {b:?}"
            );
        }
    }
}

/// `fov_axis` against Mitsuba 3.9.1: on a 96 × 54 film with `fov` 40, the vertical field of
/// view Mitsuba's sensor ends up with (from `mi.traverse(sensor)['x_fov']` and the aspect).
#[test]
fn fov_axis_matches_mitsuba() {
    for (axis, mitsuba_fov_y) in [
        ("x", 23.140917),
        ("y", 40.0),
        ("diagonal", 20.234804),
        ("smaller", 40.0),
        ("larger", 23.140917),
    ] {
        let xml = format!(
            r#"<scene version="3.0.0"><sensor type="perspective"><float name="fov" value="40"/><string name="fov_axis" value="{axis}"/>
<film type="hdrfilm"><integer name="width" value="96"/><integer name="height" value="54"/></film></sensor>
<shape type="sphere"/></scene>"#
        );
        let path = fixture(&format!("mitsuba_fov_{axis}"), &[("scene.xml", &xml)]);
        let scene = load_with(&path, &LoadOptions::allow_no_emitter()).unwrap();
        let ours = scene.camera.fov_y.to_degrees();
        assert!(
            (ours - mitsuba_fov_y).abs() < 1e-3,
            "{axis}: {ours} vs {mitsuba_fov_y}"
        );
    }
}

/// A conductor's η and k given as `<spectrum filename=".spd">` become RGB as Mitsuba 3.9.1
/// loads them (`scalar_rgb`, `mi.traverse`: η (0.0798705, 0.404652, 1.55897), k (3.38675,
/// 2.50071, 1.76891) for the shared gold files), and the spectra are kept for spectral
/// transport.
#[test]
fn spectral_eta_k_match_mitsuba() {
    let spds = shared_scenes().join("pbrt-v4/killeroos/spds");
    let xml = BASE.replacen(
        "<bsdf type=\"diffuse\" id=\"white\">\n        <rgb name=\"reflectance\" value=\"0.8\"/>",
        &format!(
            "<bsdf type=\"conductor\" id=\"white\"><spectrum name=\"eta\" filename=\"{}\"/><spectrum name=\"k\" filename=\"{}\"/>",
            spds.join("Au.eta.spd").display(),
            spds.join("Au.k.spd").display()
        ),
        1,
    );
    assert_ne!(xml, BASE);
    let path = fixture("mitsuba_spectral_eta", &[("scene.xml", &xml)]);
    let scene = load(&path).unwrap();
    let eta = glam::Vec3::new(0.079_870_5, 0.404_652, 1.558_97);
    let k = glam::Vec3::new(3.386_75, 2.500_71, 1.768_91);
    let scene::MaterialKind::Conductor(c) = scene.materials[0].kind else {
        panic!("{:?}", scene.materials[0]);
    };
    assert!(
        (c.eta - eta).abs().max_element() < 1e-4 && (c.k - k).abs().max_element() < 1e-4,
        "{c:?}"
    );
    assert_eq!(
        (c.roughness, c.specular_reflectance),
        (0.0, glam::Vec3::ONE)
    );
    let spectra = scene.materials[0].spectra.as_deref().expect("spectra");
    let gold = spectra.conductor.as_ref().expect("conductor spectra");
    // Au.eta.spd at 600 nm: linear between its samples, as the file gives them.
    let (n, _) = gold.eval(600.0);
    assert!(n > 0.1 && n < 0.5, "{n}");
}

/// `shapegroup` and `instance`: a group of one unit rectangle (its corners at x, y = ±1 in
/// Mitsuba's convention), shifted inside the group by +1 in z, placed twice: translated by
/// x = +5, and scaled by 2 then translated by y = −5. Mitsuba applies the member's `to_world`
/// first, then the instance's; the corners follow by hand.
#[test]
fn instances_place_their_group_with_the_group_transform_first() {
    let group = r#"<shape type="shapegroup" id="g">
        <shape type="rectangle">
            <ref id="white"/>
            <transform name="to_world"><translate z="1"/></transform>
        </shape>
    </shape>
    <shape type="instance">
        <ref id="g"/>
        <transform name="to_world"><translate x="5"/></transform>
    </shape>
    <shape type="instance">
        <ref id="g"/>
        <transform name="to_world"><scale value="2"/><translate y="-5"/></transform>
    </shape>
    <shape type="rectangle">"#;
    let (scene, _) = load_edited("mitsuba_instances", "<shape type=\"rectangle\">", group);
    let scene = scene.unwrap();
    // The base rectangle, and two placed copies of the group's.
    assert_eq!(scene.triangles.len(), 6);
    let corners = |lo: [f32; 3], hi: [f32; 3]| {
        scene.triangles.iter().any(|t| {
            let min = t
                .positions
                .iter()
                .fold(glam::Vec3::INFINITY, |a, &p| a.min(p));
            let max = t
                .positions
                .iter()
                .fold(glam::Vec3::NEG_INFINITY, |a, &p| a.max(p));
            (min - glam::Vec3::from(lo)).abs().max_element() < 1e-5
                && (max - glam::Vec3::from(hi)).abs().max_element() < 1e-5
        })
    };
    // x in [4, 6], y in [−1, 1], z = 1.
    assert!(corners([4.0, -1.0, 1.0], [6.0, 1.0, 1.0]));
    // Scaled by 2 about the origin after the shift (z = 2), then y − 5: x in [−2, 2],
    // y in [−7, −3].
    assert!(corners([-2.0, -7.0, 2.0], [2.0, -3.0, 2.0]));
    // Only the base scene's one material: the group's member shares it.
    assert_eq!(scene.materials.len(), 1);
}

#[test]
fn an_instance_of_what_is_not_a_shapegroup_is_refused() {
    let bad = r#"<shape type="instance"><ref id="white"/></shape>
    <shape type="rectangle">"#;
    let (err, path) = load_edited("mitsuba_bad_instance", "<shape type=\"rectangle\">", bad);
    let err = err.unwrap_err();
    assert_names_file(&err, &path);
    assert!(
        err.to_string().contains("must refer to a shapegroup"),
        "{err}"
    );
}
