//! Participating media in TOML scenes, an extension to scene format 1
//! (`docs/scene-format-extensions.md`): every key read into the description, files without
//! media unchanged, and every rejected value as one line naming the file.

use std::path::Path;

use glam::Vec3;
use import::{LoadError, load, load_toml_str};
use scene::{MaterialKind, Media, Medium, MediumShape, ShapeMedia};

use crate::{assert_names_file, fixture};

const HEAD: &str = r#"format = 1

[camera]
position = [0.0, 1.0, 3.9]
look_at = [0.0, 0.2, 0.0]
fov_y = 39.3
medium = "air"

[media.air]
sigma_a = [0.0, 0.0, 0.0]
sigma_s = [0.01, 0.02, 0.03]

[media.water]
sigma_a = [0.3, 0.1, 0.05]
sigma_s = [0.2, 0.2, 0.2]
g = 0.9

[materials.glass]
type = "dielectric"
ior = 1.33

[materials.boundary]
type = "interface"

[[lights]]
type = "directional"
direction = [0.0, -0.3, -1.0]
irradiance = [3.0, 3.0, 3.0]
"#;

fn load_with(extra: &str) -> Result<scene::SceneDescription, LoadError> {
    load_toml_str(&format!("{HEAD}\n{extra}"), Path::new("scenes/media.toml"))
}

#[test]
fn every_key_reads_into_the_description() {
    let cube = crate::shared_scenes().join("gltf/Box/glTF-Binary/Box.glb");
    let d = load_with(&format!(
        r#"
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 0.5
material = "glass"
interior = "water"
exterior = "air"

[[shapes]]
type = "quad"
corner = [-1.0, -1.0, -1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 0.0, 2.0]
material = "glass"

[[shapes]]
type = "mesh"
file = {file:?}
material = "boundary"
interior = "water"
"#,
        file = cube.display().to_string()
    ))
    .unwrap();
    // Media in name order: air, water.
    assert_eq!(
        d.media,
        Media {
            list: vec![
                Medium {
                    name: "air".into(),
                    sigma_a: Vec3::ZERO,
                    sigma_s: Vec3::new(0.01, 0.02, 0.03),
                    g: 0.0,
                    density: None,
                },
                Medium {
                    name: "water".into(),
                    sigma_a: Vec3::new(0.3, 0.1, 0.05),
                    sigma_s: Vec3::splat(0.2),
                    g: 0.9,
                    density: None,
                },
            ],
            shapes: vec![
                ShapeMedia {
                    shape: MediumShape::Sphere(0),
                    interior: Some(1),
                    exterior: Some(0),
                },
                // The quad's two triangles come first; the cube's twelve follow.
                ShapeMedia {
                    shape: MediumShape::Triangles { start: 2, end: 14 },
                    interior: Some(1),
                    exterior: None,
                },
            ],
            camera: Some(0),
        }
    );
    assert!(d.has_media());
    // `fppm info` lists each medium with what it fills: water inside the sphere and the cube,
    // air outside the sphere and around the camera.
    let summary = d.summary();
    let media: Vec<_> = summary
        .media
        .iter()
        .map(|m| {
            (
                m.name.as_str(),
                m.interior_of,
                m.exterior_of,
                m.around_camera,
            )
        })
        .collect();
    assert_eq!(media, [("air", 0, 1, true), ("water", 2, 0, false)]);
    let shown = summary.to_string();
    assert!(shown.contains("media      2\n"), "{shown}");
    assert!(
        shown.contains(
            "\"water\" homogeneous sigma_a [0.3, 0.1, 0.05] sigma_s [0.2, 0.2, 0.2] g 0.9 \
             (interior of 2, exterior of 0 shapes)"
        ),
        "{shown}"
    );
    assert!(shown.contains("(interior of 0, exterior of 1 shapes; around the camera)"));
    let boundary = d.materials.iter().find(|m| m.name == "boundary").unwrap();
    assert_eq!(boundary.kind, MaterialKind::Interface(scene::Interface));
    assert_eq!(boundary.kind.name(), "interface");
    assert!(scene::Scene::new(d).is_ok());
}

#[test]
fn a_file_without_media_has_none() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/glass-caustic.toml");
    let d = load(&path).unwrap();
    assert_eq!(d.media, Media::default());
    assert!(!d.has_media());
}

#[track_caller]
fn rejected(extra: &str, needles: &[&str]) {
    let err = load_with(extra).unwrap_err();
    assert_names_file(&err, Path::new("scenes/media.toml"));
    let msg = err.to_string();
    for needle in needles {
        assert!(msg.contains(needle), "{msg:?} lacks {needle:?}");
    }
}

const SPHERE: &str =
    "[[shapes]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 0.5\nmaterial = \"glass\"\n";

#[test]
fn bad_media_are_one_line_naming_the_file() {
    rejected(
        &format!("{SPHERE}interior = \"milk\"\n"),
        &["[[shapes]] #1 interior", "medium `milk`", "air, water"],
    );
    rejected(
        &format!("{SPHERE}[media.ink]\nsigma_a = [-1.0, 0.0, 0.0]\nsigma_s = [0.0, 0.0, 0.0]\n"),
        &["[media.ink] sigma_a must not be negative"],
    );
    rejected(
        &format!(
            "{SPHERE}[media.ink]\nsigma_a = [0.0, 0.0, 0.0]\nsigma_s = [1.0, 1.0, 1.0]\ng = 1.0\n"
        ),
        &["[media.ink] g must be in (-1, 1), got 1"],
    );
    rejected(
        &format!(
            "{SPHERE}[media.ink]\nsigma_a = [0.0, 0.0, 0.0]\nsigma_s = [1.0, 1.0, 1.0]\ndensity = 2.0\n"
        ),
        &["density"],
    );
    // A quad is open: it takes no media.
    rejected(
        "[[shapes]]\ntype = \"quad\"\ncorner = [0.0, 0.0, 0.0]\nedge1 = [1.0, 0.0, 0.0]\n\
         edge2 = [0.0, 1.0, 0.0]\nmaterial = \"glass\"\ninterior = \"water\"\n",
        &["interior"],
    );
    rejected(
        "[materials.glow]\ntype = \"interface\"\nemission = [1.0, 1.0, 1.0]\n",
        &["emission"],
    );
}

#[test]
fn an_open_mesh_cannot_bound_a_medium() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n";
    let toml = format!(
        "{HEAD}\n[[shapes]]\ntype = \"mesh\"\nfile = \"open.obj\"\nmaterial = \"boundary\"\ninterior = \"water\"\n"
    );
    let path = fixture(
        "open-mesh-medium",
        &[("scene.toml", &toml), ("open.obj", obj)],
    );
    let err = load(&path).unwrap_err();
    assert_names_file(&err, &path);
    assert!(
        err.to_string()
            .contains("the mesh of triangles 0..3 bounds a medium but is not closed"),
        "{err}"
    );
    // Closed by its fourth face, it is accepted.
    let closed = format!("{obj}f 2 3 4\n");
    let path = fixture(
        "closed-mesh-medium",
        &[("scene.toml", &toml), ("open.obj", &closed)],
    );
    assert!(load(&path).is_ok());
}

const MITSUBA_HEAD: &str = r#"<scene version="3.0.0">
    <medium type="homogeneous" id="smoke">
        <rgb name="sigma_t" value="2, 1, 0.5"/>
        <float name="albedo" value="0.25"/>
        <float name="scale" value="2"/>
        <phase type="hg"><float name="g" value="0.7"/></phase>
    </medium>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <ref name="medium" id="smoke"/>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
"#;

/// Mitsuba 3's `homogeneous` medium: σa = (1 − albedo)·σt·scale and σs = albedo·σt·scale, an
/// `hg` phase, `<ref>` and nested media on shapes and the sensor, a null BSDF as the interface.
#[test]
fn mitsuba_homogeneous_media_are_read() {
    let xml = format!(
        r#"{MITSUBA_HEAD}
    <shape type="cube">
        <bsdf type="null"/>
        <ref name="interior" id="smoke"/>
    </shape>
    <shape type="sphere">
        <float name="radius" value="0.5"/>
        <bsdf type="dielectric"/>
        <medium type="homogeneous" name="interior">
            <float name="sigma_t" value="1"/>
            <rgb name="albedo" value="0.5, 0.5, 0.5"/>
        </medium>
        <ref name="exterior" id="smoke"/>
    </shape>
</scene>"#
    );
    let path = fixture("mitsuba-media", &[("scene.xml", &xml)]);
    let d = load(&path).unwrap();
    let smoke = &d.media.list[0];
    assert_eq!(smoke.name, "smoke");
    assert!(
        (smoke.sigma_a - Vec3::new(3.0, 1.5, 0.75))
            .abs()
            .max_element()
            < 1e-6
    );
    assert!(
        (smoke.sigma_s - Vec3::new(1.0, 0.5, 0.25))
            .abs()
            .max_element()
            < 1e-6
    );
    assert_eq!(smoke.g, 0.7);
    let inner = &d.media.list[1];
    assert_eq!(
        (inner.sigma_a, inner.sigma_s, inner.g),
        (Vec3::splat(0.5), Vec3::splat(0.5), 0.0)
    );
    assert_eq!(d.media.camera, Some(0));
    assert_eq!(
        d.media.shapes,
        vec![
            ShapeMedia {
                shape: MediumShape::Triangles { start: 0, end: 12 },
                interior: Some(0),
                exterior: None,
            },
            ShapeMedia {
                shape: MediumShape::Sphere(0),
                interior: Some(1),
                exterior: Some(0),
            },
        ]
    );
    assert_eq!(
        d.materials[d.triangles[0].material as usize].kind,
        MaterialKind::Interface(scene::Interface)
    );
    assert!(scene::Scene::new(d).is_ok());
}

#[test]
fn mitsuba_media_that_fppm_cannot_render_are_refused() {
    for (body, needle) in [
        (
            r#"<shape type="rectangle"><bsdf type="null"/><ref name="interior" id="smoke"/></shape>"#,
            "not closed",
        ),
        (
            r#"<shape type="cylinder"><ref name="interior" id="smoke"/></shape>"#,
            "cannot bound a medium",
        ),
        (
            r#"<shape type="cube"><medium type="heterogeneous" name="interior"><volume name="albedo" type="gridvolume"/></medium></shape>"#,
            "an albedo given as a volume is not supported",
        ),
        (
            r#"<shape type="cube"><medium type="heterogeneous" name="interior"><volume name="sigma_t" type="constvolume"/></medium></shape>"#,
            "volume type \"constvolume\" is not supported",
        ),
        (
            r#"<shape type="cube"><medium type="foggy" name="interior"/></shape>"#,
            "medium type \"foggy\" is not supported",
        ),
        (
            r#"<shape type="cube"><medium type="homogeneous" name="interior"><phase type="rayleigh"/></medium></shape>"#,
            "phase function \"rayleigh\" is not supported",
        ),
    ] {
        let xml = format!("{MITSUBA_HEAD}{body}\n</scene>");
        let path = fixture("mitsuba-media-refused", &[("scene.xml", &xml)]);
        let err = load(&path).unwrap_err();
        assert_names_file(&err, &path);
        assert!(err.to_string().contains(needle), "{err}");
    }
}
