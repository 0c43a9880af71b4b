//! The media checks of [`super::media`]: one line naming the problem for each.

use glam::Vec3;

use super::*;
use crate::test_util::{description, point_light, tri};
use crate::{Media, Medium, MediumShape, ShapeMedia};

#[track_caller]
fn check(d: &SceneDescription, expect: &str) {
    let got = super::description(d).err().map(|e| e.to_string());
    assert_eq!(got.as_deref(), Some(expect));
    let scene = crate::Scene::new(d.clone()).err().map(|e| e.to_string());
    assert!(scene.is_some_and(|e| e.ends_with(expect)), "{expect}");
}

/// The 12 triangles of the unit cube [0, 1]³, facing out.
fn cube() -> Vec<crate::Triangle> {
    let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let quad = |a: Vec3, b: Vec3, c: Vec3, d: Vec3| [tri(a, b, c, 0), tri(a, c, d, 0)];
    [
        quad(p(0., 0., 0.), p(0., 1., 0.), p(1., 1., 0.), p(1., 0., 0.)),
        quad(p(0., 0., 1.), p(1., 0., 1.), p(1., 1., 1.), p(0., 1., 1.)),
        quad(p(0., 0., 0.), p(1., 0., 0.), p(1., 0., 1.), p(0., 0., 1.)),
        quad(p(0., 1., 0.), p(0., 1., 1.), p(1., 1., 1.), p(1., 1., 0.)),
        quad(p(0., 0., 0.), p(0., 0., 1.), p(0., 1., 1.), p(0., 1., 0.)),
        quad(p(1., 0., 0.), p(1., 1., 0.), p(1., 1., 1.), p(1., 0., 1.)),
    ]
    .concat()
}

fn with_fog() -> SceneDescription {
    let mut d = description(cube(), Vec::new(), vec![point_light(Vec3::splat(3.0))]);
    d.media = Media {
        list: vec![Medium {
            name: "fog".into(),
            sigma_a: Vec3::splat(0.1),
            sigma_s: Vec3::splat(0.5),
            g: 0.3,
            density: None,
        }],
        shapes: vec![ShapeMedia {
            shape: MediumShape::Triangles { start: 0, end: 12 },
            interior: Some(0),
            exterior: None,
        }],
        camera: None,
    };
    d
}

#[test]
fn valid_media_pass_and_count_in_the_fingerprint() {
    let d = with_fog();
    assert_eq!(super::description(&d), Ok(()));
    assert!(d.has_media());
    let mut plain = d.clone();
    plain.media = Media::default();
    assert!(!plain.has_media());
    // A medium nothing refers to changes nothing.
    let mut unused = d.clone();
    unused.media.shapes.clear();
    assert!(!unused.has_media());
    assert_ne!(d.fingerprint(), plain.fingerprint());
    let mut thicker = d.clone();
    thicker.media.list[0].sigma_s.x = 0.6;
    assert_ne!(d.fingerprint(), thicker.fingerprint());
}

#[test]
fn bad_media_are_named_in_one_line() {
    let mut d = with_fog();
    d.media.list[0].sigma_a = Vec3::new(-1.0, 0.0, 0.0);
    check(
        &d,
        "medium \"fog\" sigma_a must not be negative, got [-1, 0, 0]",
    );
    let mut d = with_fog();
    d.media.list[0].sigma_s = Vec3::new(f32::NAN, 0.0, 0.0);
    check(&d, "medium \"fog\" sigma_s must be finite, got [NaN, 0, 0]");
    for g in [1.0, -1.0, f32::NAN] {
        let mut d = with_fog();
        d.media.list[0].g = g;
        check(&d, &format!("medium \"fog\" g must be in (-1, 1), got {g}"));
    }
    let mut d = with_fog();
    d.media.shapes[0].interior = Some(3);
    check(
        &d,
        "triangles 0..12 interior refers to medium 3 but there are 1 media",
    );
    let mut d = with_fog();
    d.media.camera = Some(1);
    check(&d, "camera medium refers to medium 1 but there are 1 media");
    let mut d = with_fog();
    d.media.shapes[0].shape = MediumShape::Triangles { start: 0, end: 13 };
    check(
        &d,
        "media of shape 0 name triangles 0..13 but there are 12 triangles",
    );
    let mut d = with_fog();
    d.media.shapes[0].shape = MediumShape::Sphere(0);
    check(&d, "media of shape 0 name sphere 0 but there are 0 spheres");
    // An open box (its last face missing) cannot hold a medium.
    let mut d = with_fog();
    d.triangles.truncate(10);
    d.media.shapes[0].shape = MediumShape::Triangles { start: 0, end: 10 };
    let got = super::description(&d).err().map(|e| e.to_string());
    assert!(
        got.as_deref().is_some_and(|e| e.starts_with(
            "the mesh of triangles 0..10 bounds a medium but is not closed: its edge"
        )),
        "{got:?}"
    );
    // The same open mesh with the same medium on both sides changes nothing: allowed.
    d.media.shapes[0].exterior = Some(0);
    assert_eq!(super::description(&d), Ok(()));
    let mut d = with_fog();
    d.materials[1].kind = crate::MaterialKind::Interface(crate::Interface);
    check(
        &d,
        "material \"m\" is an interface and cannot emit or have textures",
    );
}
