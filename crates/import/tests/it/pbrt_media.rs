//! Participating media in pbrt-v4 scenes: `MakeNamedMedium "homogeneous"` with pbrt-v4's
//! parameters and defaults (`HomogeneousMedium::Create`, src/pbrt/media.cpp: σa = σs = 1,
//! scale 1, g 0), `MediumInterface` on the shapes that follow it and around the camera (the
//! outside medium at `Camera`), `Material "interface"` as the media's boundary, and every
//! refusal as one line naming the file.

use glam::Vec3;
use import::load;
use scene::{MaterialKind, Medium, MediumShape, ShapeMedia};

use crate::{assert_names_file, fixture};

/// A closed cube of side 1 at the origin, counter-clockwise seen from outside (pbrt's normal
/// `cross(p0 − p2, p1 − p2)` points out: worked out face by face, e.g. −z: (0, 3, 2) turns
/// (0, 1, 0) × (1, 1, 0) = (0, 0, −1)).
const CUBE: &str = r#"Shape "trianglemesh"
    "point3 P" [ -0.5 -0.5 -0.5  0.5 -0.5 -0.5  0.5 0.5 -0.5  -0.5 0.5 -0.5
                 -0.5 -0.5 0.5   0.5 -0.5 0.5   0.5 0.5 0.5   -0.5 0.5 0.5 ]
    "integer indices" [ 0 3 2  0 2 1  4 5 6  4 6 7  0 1 5  0 5 4  3 7 6  3 6 2  0 4 7  0 7 3  1 2 6  1 6 5 ]"#;

fn scene_text(world: &str) -> String {
    format!(
        r#"MakeNamedMedium "ink" "string type" "homogeneous"
    "rgb sigma_a" [ 0.5 0.25 0.125 ] "rgb sigma_s" [ 1 2 4 ] "float scale" 2 "float g" 0.5
MakeNamedMedium "haze" "string type" "homogeneous"
    "rgb sigma_a" [ 0 0 0 ] "spectrum sigma_s" [ 300 0.1  900 0.1 ]
MakeNamedMedium "defaults" "string type" "homogeneous"
MediumInterface "" "haze"
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 45 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
WorldBegin
LightSource "point" "rgb I" [ 5 5 5 ] "point3 from" [ 0 3 3 ]
{world}
"#
    )
}

const WORLD: &str = r#"AttributeBegin
  MediumInterface "ink" "haze"
  Material "interface"
  CUBE
AttributeEnd
AttributeBegin
  Translate 2 0 0
  MediumInterface "ink" ""
  Material "dielectric" "float eta" 1.33
  Shape "sphere" "float radius" 0.5
AttributeEnd
AttributeBegin
  Translate -2 0 0
  ReverseOrientation
  MediumInterface "ink" ""
  Material "dielectric" "float eta" 1.33
  Shape "sphere" "float radius" 0.5
AttributeEnd
AttributeBegin
  MediumInterface "haze" "haze"
  Material "interface"
  Translate 0 -2 0
  CUBE
AttributeEnd"#;

#[test]
fn homogeneous_media_and_interfaces_read_into_the_description() {
    let path = fixture(
        "pbrt_media",
        &[("scene.pbrt", &scene_text(&WORLD.replace("CUBE", CUBE)))],
    );
    let d = load(&path).unwrap();
    // In the order of definition; ink's coefficients times its scale 2; the flat spectrum 0.1
    // is grey 0.1 (checked loosely: the spectrum's conversion to RGB rounds).
    let [ink, haze, defaults] = d.media.list.as_slice() else {
        panic!("{:?}", d.media.list)
    };
    assert_eq!(
        *ink,
        Medium {
            name: "ink".into(),
            sigma_a: Vec3::new(1.0, 0.5, 0.25),
            sigma_s: Vec3::new(2.0, 4.0, 8.0),
            g: 0.5,
            density: None,
        }
    );
    assert_eq!(haze.sigma_a, Vec3::ZERO);
    assert!(
        (haze.sigma_s - Vec3::splat(0.1)).abs().max_element() < 0.005,
        "{haze:?}"
    );
    assert_eq!(
        (defaults.sigma_a, defaults.sigma_s, defaults.g),
        (Vec3::ONE, Vec3::ONE, 0.0)
    );
    // The camera sits in the outside medium of the MediumInterface before Camera.
    assert_eq!(d.media.camera, Some(1));
    // The first cube (ink in haze) and the two spheres; the second cube has haze on both
    // sides, which changes nothing, so it bounds no medium (it is still there, invisible).
    assert_eq!(
        d.media.shapes,
        vec![
            ShapeMedia {
                shape: MediumShape::Triangles { start: 0, end: 12 },
                interior: Some(0),
                exterior: Some(1),
            },
            ShapeMedia {
                shape: MediumShape::Sphere(0),
                interior: Some(0),
                exterior: None,
            },
            // ReverseOrientation turns the sphere's normal inward: pbrt's inside is then the
            // space around it.
            ShapeMedia {
                shape: MediumShape::Sphere(1),
                interior: None,
                exterior: Some(0),
            },
        ]
    );
    // The first cube's triangles face out of it (their front faces look away from the
    // centre), so fppm's interior is pbrt's inside; its material is the interface.
    for t in &d.triangles[..12] {
        let [a, b, c] = t.positions;
        let centroid = (a + b + c) / 3.0;
        assert!((b - a).cross(c - a).dot(centroid) > 0.0, "{t:?} faces in");
        assert!(matches!(
            d.materials[t.material as usize].kind,
            MaterialKind::Interface(_)
        ));
    }
    // The second cube is invisible (pbrt's interface without a medium transition).
    assert_eq!(d.triangles.len(), 12);
}

#[test]
fn refusals_name_the_file() {
    let cases: [(&str, &str, &[&str]); 6] = [
        (
            "pbrt_media_grid",
            r#"MakeNamedMedium "smoke" "string type" "uniformgrid" "float density" [ 1 ] "integer nx" [ 2 ]"#,
            &["line 12", "smoke", "needs 2 density values, got 1"],
        ),
        (
            "pbrt_media_nanovdb",
            r#"MakeNamedMedium "smoke" "string type" "nanovdb" "string filename" "smoke.nvdb""#,
            &["nanovdb", "only homogeneous"],
        ),
        (
            "pbrt_media_preset",
            r#"MakeNamedMedium "milk" "string type" "homogeneous" "string preset" "Wholemilk""#,
            &["milk", "preset \"Wholemilk\"", "not supported"],
        ),
        (
            "pbrt_media_emissive",
            r#"MakeNamedMedium "glow" "string type" "homogeneous" "rgb Le" [ 1 1 1 ]"#,
            &["glow", "emissive"],
        ),
        (
            "pbrt_media_unknown",
            "AttributeBegin\n MediumInterface \"nowhere\" \"\"\n Shape \"sphere\"\nAttributeEnd",
            &["nowhere", "MediumInterface"],
        ),
        (
            "pbrt_media_cylinder",
            "AttributeBegin\n MediumInterface \"ink\" \"\"\n Shape \"cylinder\"\nAttributeEnd",
            &["cylinder", "cannot bound a medium"],
        ),
    ];
    for (test, world, fragments) in cases {
        let path = fixture(test, &[("scene.pbrt", &scene_text(world))]);
        let err = load(&path).unwrap_err();
        assert_names_file(&err, &path);
        let msg = err.to_string();
        assert!(!msg.contains('\n'), "{msg:?} is more than one line");
        for f in fragments {
            assert!(msg.contains(f), "{test}: {msg:?} lacks {f:?}");
        }
    }
}
