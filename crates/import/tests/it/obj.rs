//! OBJ specifics: non-convex polygon triangulation, shading normals, the MTL mapping.

use glam::{Vec2, Vec3};
use import::{LoadOptions, load_with};
use scene::{MaterialKind, SceneDescription, Triangle};

use crate::fixture;

fn load_obj(test: &str, obj: &str, mtl: &str) -> SceneDescription {
    let path = fixture(test, &[("mesh.obj", obj), ("mesh.mtl", mtl)]);
    load_with(&path, &LoadOptions::allow_no_emitter()).unwrap()
}

fn area(t: &Triangle) -> f32 {
    let [a, b, c] = t.positions;
    0.5 * (b - a).cross(c - a).length()
}

/// Even–odd test in the xy plane.
fn inside(polygon: &[Vec2], p: Vec2) -> bool {
    let mut inside = false;
    for i in 0..polygon.len() {
        let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

/// Checks a polygon in the plane z = 1 written as one `f` line: the triangles cover exactly
/// its area, none lies outside, and all face +z like the (counter-clockwise) polygon.
#[track_caller]
fn check_polygon(test: &str, outline: &[(f32, f32)], expected_area: f32) {
    let mut obj = String::new();
    for (x, y) in outline {
        obj.push_str(&format!("v {x} {y} 1\n"));
    }
    obj.push('f');
    for i in 1..=outline.len() {
        obj.push_str(&format!(" {i}"));
    }
    obj.push('\n');
    let scene = load_obj(test, &obj, "");
    let polygon: Vec<Vec2> = outline.iter().map(|&(x, y)| Vec2::new(x, y)).collect();
    assert_eq!(scene.triangles.len(), outline.len() - 2);
    let total: f32 = scene.triangles.iter().map(area).sum();
    assert!(
        (total - expected_area).abs() < 1e-5,
        "area {total}, expected {expected_area}"
    );
    for t in &scene.triangles {
        let [a, b, c] = t.positions;
        assert!((b - a).cross(c - a).z > 0.0, "{t:?} faces away");
        let centroid = (a + b + c) / 3.0;
        assert!(
            inside(&polygon, centroid.truncate()),
            "{t:?} lies outside the polygon"
        );
    }
}

#[test]
fn l_shaped_polygon() {
    check_polygon(
        "obj_l_shape",
        &[
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ],
        3.0,
    );
}

#[test]
fn arrow_polygon_starting_at_a_reflex_neighbour() {
    // An arrow pointing +x whose first vertex sees the notch: a fan from it would leave the
    // polygon. Area: shaft 2 × 1 plus head ½ · 2 · 1.5 = 3.5.
    check_polygon(
        "obj_arrow",
        &[
            (0.0, 1.5),
            (0.0, 0.5),
            (2.0, 0.5),
            (2.0, 0.0),
            (3.5, 1.0),
            (2.0, 2.0),
            (2.0, 1.5),
        ],
        3.5,
    );
}

#[test]
fn comb_polygon() {
    // A comb with three teeth (a fan from vertex 0 would cross the gaps).
    check_polygon(
        "obj_comb",
        &[
            (0.0, 0.0),
            (5.0, 0.0),
            (5.0, 3.0),
            (4.0, 3.0),
            (4.0, 1.0),
            (3.0, 1.0),
            (3.0, 3.0),
            (2.0, 3.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (0.0, 3.0),
        ],
        5.0 + 3.0 * 2.0,
    );
}

#[test]
fn clockwise_polygon_keeps_its_orientation() {
    // The L above, listed clockwise: every triangle must face −z.
    let obj = "v 0 0 0\nv 0 2 0\nv 1 2 0\nv 1 1 0\nv 2 1 0\nv 2 0 0\nf 1 2 3 4 5 6\n";
    let scene = load_obj("obj_clockwise", obj, "");
    assert_eq!(scene.triangles.len(), 4);
    for t in &scene.triangles {
        let [a, b, c] = t.positions;
        assert!((b - a).cross(c - a).z < 0.0, "{t:?}");
    }
    let total: f32 = scene.triangles.iter().map(area).sum();
    assert!((total - 3.0).abs() < 1e-5);
}

#[test]
fn vertex_normals_are_normalised_and_follow_the_triangulation() {
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
               vn 0 0 2\nvn 0 0 3\nvn 0 0 4\nvn 0 0 5\n\
               f 1//1 2//2 3//3 4//4\no other\nv 5 5 5\nf 1 2 5\n";
    let scene = load_obj("obj_normals", obj, "");
    assert_eq!(scene.triangles.len(), 3);
    for t in &scene.triangles[..2] {
        assert_eq!(t.normals, Some([Vec3::Z; 3]));
    }
    // A face without normal indices gets none (flat shading). (Within one object, faces
    // with and without normals mixed lose all normals: tobj cannot align them.)
    assert_eq!(scene.triangles[2].normals, None);
}

#[test]
fn mixed_normals_in_one_object_are_dropped_with_a_warning() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1 2 4\n";
    let scene = load_obj("obj_mixed_normals", obj, "");
    assert!(scene.triangles.iter().all(|t| t.normals.is_none()));
    assert!(
        scene
            .notes
            .warnings
            .iter()
            .any(|w| w.contains("only some faces"))
    );
}

#[test]
fn zero_normals_are_dropped() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n";
    let scene = load_obj("obj_zero_normals", obj, "");
    assert_eq!(scene.triangles[0].normals, None);
}

#[test]
fn mtl_mapping() {
    let mtl = "\
newmtl matte
Kd 0.5 0.25 0.125
newmtl mirror_illum
Ks 0.9 0.8 0.7
illum 5
newmtl mirror_shiny
Ks 0.95 0.95 0.95
Ns 1000
newmtl glass_illum
illum 7
Ni 1.33
newmtl glass_dissolve
d 0.5
Ni 1.7
newmtl plastic
Kd 0.2 0.3 0.4
Ks 0.5 0.5 0.5
Ns 98
newmtl lamp
Kd 0.5 0.5 0.5
Ke 4 5 6
newmtl grey
Kd 0.3
newmtl ambient_only
Ka 3 3 3
";
    let mut obj = String::from("mtllib mesh.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for name in [
        "matte",
        "mirror_illum",
        "mirror_shiny",
        "glass_illum",
        "glass_dissolve",
        "plastic",
        "lamp",
        "grey",
        "ambient_only",
    ] {
        obj.push_str(&format!("usemtl {name}\nf 1 2 3\n"));
    }
    let scene = load_obj("obj_mtl_mapping", &obj, mtl);
    let kind = |name: &str| {
        scene
            .materials
            .iter()
            .find(|m| m.name == name)
            .unwrap()
            .kind
    };
    assert_eq!(
        kind("matte"),
        MaterialKind::Diffuse(scene::Diffuse {
            albedo: Vec3::new(0.5, 0.25, 0.125)
        })
    );
    assert_eq!(
        kind("mirror_illum"),
        MaterialKind::Mirror(scene::Mirror {
            reflectance: Vec3::new(0.9, 0.8, 0.7)
        })
    );
    assert_eq!(
        kind("mirror_shiny"),
        MaterialKind::Mirror(scene::Mirror {
            reflectance: Vec3::splat(0.95)
        })
    );
    assert_eq!(
        kind("glass_illum"),
        MaterialKind::Dielectric(scene::Dielectric { ior: 1.33 })
    );
    assert_eq!(
        kind("glass_dissolve"),
        MaterialKind::Dielectric(scene::Dielectric { ior: 1.7 })
    );
    // α = √(2 / (Ns + 2)) = √(2 / 100).
    assert_eq!(
        kind("plastic"),
        MaterialKind::Glossy(scene::Glossy {
            reflectance: Vec3::splat(0.5),
            roughness: 0.02f32.sqrt(),
            diffuse: Vec3::new(0.2, 0.3, 0.4)
        })
    );
    let lamp = scene.materials.iter().find(|m| m.name == "lamp").unwrap();
    assert_eq!(lamp.emission, Vec3::new(4.0, 5.0, 6.0));
    assert_eq!(
        kind("grey"),
        MaterialKind::Diffuse(scene::Diffuse {
            albedo: Vec3::splat(0.3)
        })
    );
    assert!(
        scene
            .notes
            .warnings
            .iter()
            .any(|w| w.contains("ambient_only"))
    );
    assert_eq!(scene.summary().emissive_triangles, 1);
}

#[test]
fn faces_without_material_get_the_default() {
    let scene = load_obj(
        "obj_default_material",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        "",
    );
    assert_eq!(scene.materials.len(), 1);
    assert_eq!(scene.materials[0].name, "default");
    assert_eq!(
        scene.materials[0].kind,
        MaterialKind::Diffuse(scene::Diffuse {
            albedo: Vec3::splat(import::DEFAULT_ALBEDO)
        })
    );
}

#[test]
fn lone_obj_gets_a_framed_camera() {
    let scene = load_obj("obj_framed", "v -1 0 -1\nv 1 0 -1\nv 1 2 1\nf 1 2 3\n", "");
    assert!(scene.notes.camera_framed);
    let c = scene.camera;
    assert_eq!(c.look_at, Vec3::new(0.0, 1.0, 0.0));
    assert_eq!(c.up, Vec3::Y);
    assert!((c.fov_y - import::FRAMED_FOV_Y_DEGREES.to_radians()).abs() < 1e-6);
    // Looking down −z from beyond the box's front face, far enough that its
    // half-height 1 fits within tan(20°) · distance.
    assert_eq!((c.position.x, c.position.y), (0.0, 1.0));
    let distance_to_front = c.position.z - 1.0;
    assert!(distance_to_front * (c.fov_y / 2.0).tan() >= 1.0);
    assert_eq!((scene.film.width, scene.film.height), (512, 512));
}

#[test]
fn points_and_lines_are_skipped_with_a_warning() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\np 3\nf 1 2 3\n";
    let scene = load_obj("obj_points_lines", obj, "");
    assert_eq!(scene.triangles.len(), 1);
    assert!(
        scene
            .notes
            .warnings
            .iter()
            .any(|w| w.contains("2 point or line")),
        "{:?}",
        scene.notes.warnings
    );
}

/// MTL textures: `map_Kd` colours, `map_Ke` alone emits its texture (Ke taken as 1), `map_d`
/// cuts out, `norm` is a normal map, a height `bump` is dropped with a warning; OBJ texture
/// coordinates are flipped to the image convention (v down); one image file read once.
#[test]
fn mtl_textures_and_texture_coordinates() {
    let dir = crate::temp_dir("mtl_textures");
    let rgba = |c: [u8; 4]| image::RgbaImage::from_pixel(2, 2, image::Rgba(c));
    rgba([200, 100, 50, 255]).save(dir.join("kd.png")).unwrap();
    rgba([128, 128, 255, 255])
        .save(dir.join("normal.png"))
        .unwrap();
    rgba([90, 90, 90, 255])
        .save(dir.join("height.png"))
        .unwrap();
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl lamp\nKd 1 1 1\nmap_Kd kd.png\nmap_Ke kd.png\nmap_d kd.png\nnorm normal.png\n\
         newmtl bumpy\nKd 0.5 0.5 0.5\nbump -bm 1 height.png\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("quad.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 0.25\n\
         usemtl lamp\nf 1/1 2/2 3/3\nusemtl bumpy\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    let scene = import::load(&dir.join("quad.obj")).unwrap();
    let lamp = &scene.materials[0];
    assert_eq!(lamp.emission, glam::Vec3::ONE);
    let t = lamp.textures.as_deref().unwrap();
    let (color, emission) = (t.color.as_ref().unwrap(), t.emission.as_ref().unwrap());
    assert!(std::sync::Arc::ptr_eq(&color.image, &emission.image));
    assert!(color.srgb && t.alpha.is_some() && t.normal.is_some());
    assert!(!t.normal.as_ref().unwrap().texture.srgb);
    assert!(scene.materials[1].textures.is_none());
    assert!(
        scene
            .notes
            .warnings
            .iter()
            .any(|w| w.contains("height map")),
        "{:?}",
        scene.notes.warnings
    );
    let uv = scene.triangles[0].uv.unwrap();
    assert_eq!(
        uv,
        [
            glam::Vec2::new(0.0, 1.0),
            glam::Vec2::new(1.0, 1.0),
            glam::Vec2::new(1.0, 0.75)
        ]
    );
    // sRGB 200 decodes to 0.578 (IEC 61966-2-1), the texel of every lookup on a flat image.
    let texel = color.color(glam::Vec2::new(0.3, 0.6));
    assert!((texel.x - 0.577_580).abs() < 1e-4, "{texel}");
}
