//! A TOML scene using every table and key of scene format version 1, checked value by value.

use std::path::Path;

use glam::Vec3;
use import::{load, load_toml_str};
use scene::{Light, MaterialKind};

const SCENE: &str = r#"format = 1

[camera]
position = [0.0, 1.0, 3.9]
look_at  = [0.0, 1.0, 0.0]
up       = [0.0, 1.0, 0.1]
fov_y    = 39.3
aperture_radius = 0.05
focus_distance  = 3.5

[film]
width  = 640
height = 480

[materials.white]
type   = "diffuse"
albedo = [0.8, 0.8, 0.8]

[materials.silver]
type = "mirror"

[materials.glass]
type = "dielectric"
ior  = 1.5

[materials.brushed]
type        = "glossy"
reflectance = [0.9, 0.9, 0.9]
roughness   = 0.1

[materials.lamp]
type     = "diffuse"
albedo   = [0.0, 0.0, 0.0]
emission = [17.0, 12.0, 4.0]

[[shapes]]
type     = "mesh"
file     = "meshes/tri.obj"
material = "white"
transform = { scale = [2.0, 3.0, 4.0], rotate = [90.0, 90.0, 90.0], translate = [10.0, 20.0, 30.0] }

[[shapes]]
type = "mesh"
file = "meshes/flat.obj"
transform = { scale = [-1.0, 1.0, 1.0] }

[[shapes]]
type     = "sphere"
center   = [0.3, 0.35, 0.2]
radius   = 0.35
material = "glass"

[[shapes]]
type     = "quad"
corner   = [-0.25, 1.98, -0.2]
edge1    = [0.5, 0.0, 0.0]
edge2    = [0.0, 0.0, 0.4]
material = "lamp"

[[lights]]
type      = "point"
position  = [0.0, 1.9, 0.0]
intensity = [5.0, 5.0, 5.0]

[[lights]]
type          = "spot"
position      = [0.0, 1.9, 0.0]
direction     = [0.0, -2.0, 0.0]
intensity     = [20.0, 20.0, 20.0]
cone_angle    = 30.0
falloff_start = 25.0

[[lights]]
type       = "directional"
direction  = [-0.3, -1.0, 0.2]
irradiance = [3.0, 3.0, 3.0]

[render]
method = "ppm"
passes = 64
photons_per_pass = 100000
alpha = 0.7
initial_radius = 0.05
max_depth = 12
seed = 7
"#;

/// (1, 1, 1) scaled by (2, 3, 4), rotated 90° about x, then y, then z, translated by (10, 20, 30).
const TRANSFORMED_ONES: Vec3 = Vec3::new(14.0, 23.0, 28.0);

fn assert_close(a: Vec3, b: Vec3) {
    assert!((a - b).length() < 1e-4, "{a} != {b}");
}

fn write_scene(test: &str) -> std::path::PathBuf {
    let dir = crate::temp_dir(test);
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    std::fs::write(
        dir.join("meshes/tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("meshes/flat.obj"),
        "mtllib flat.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nusemtl paper\nf 1//1 2//1 3//1\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("meshes/flat.mtl"),
        "newmtl paper\nKd 0.5 0.5 0.5\n",
    )
    .unwrap();
    let path = dir.join("every_key.toml");
    std::fs::write(&path, SCENE).unwrap();
    path
}

#[test]
fn every_key_of_the_format() {
    let path = write_scene("toml_every_key");
    let scene = load(&path).unwrap();

    // Camera: degrees become radians; the thin lens is kept.
    let c = scene.camera;
    assert_eq!(c.position, Vec3::new(0.0, 1.0, 3.9));
    assert_eq!(c.look_at, Vec3::new(0.0, 1.0, 0.0));
    assert_close(c.up, Vec3::new(0.0, 1.0, 0.1).normalize());
    assert!((c.fov_y - 39.3f32.to_radians()).abs() < 1e-6);
    assert_eq!((c.aperture_radius, c.focus_distance), (0.05, 3.5));
    assert!(!scene.notes.camera_framed);
    assert_eq!((scene.film.width, scene.film.height), (640, 480));

    // Materials: scene materials by name, then the mesh file's own as FILE/NAME.
    let find = |name: &str| {
        let i = scene.materials.iter().position(|m| m.name == name);
        i.unwrap_or_else(|| panic!("no material {name}: {:?}", scene.materials)) as u32
    };
    let kind = |name: &str| scene.materials[find(name) as usize].kind;
    assert_eq!(
        kind("white"),
        MaterialKind::Diffuse(scene::Diffuse {
            albedo: Vec3::splat(0.8)
        })
    );
    assert_eq!(
        kind("silver"),
        MaterialKind::Mirror(scene::Mirror {
            reflectance: Vec3::ONE
        })
    );
    assert_eq!(
        kind("glass"),
        MaterialKind::Dielectric(scene::Dielectric { ior: 1.5 })
    );
    assert_eq!(
        kind("brushed"),
        MaterialKind::Glossy(scene::Glossy {
            reflectance: Vec3::splat(0.9),
            roughness: 0.1,
            diffuse: Vec3::ZERO
        })
    );
    assert_eq!(
        scene.materials[find("lamp") as usize].emission,
        Vec3::new(17.0, 12.0, 4.0)
    );
    assert_eq!(
        kind("meshes/flat.obj/paper"),
        MaterialKind::Diffuse(scene::Diffuse {
            albedo: Vec3::splat(0.5)
        })
    );

    // Mesh 1: material override and scale → rotate x, y, z → translate.
    let tri: Vec<_> = scene
        .triangles
        .iter()
        .filter(|t| t.material == find("white"))
        .collect();
    assert_eq!(tri.len(), 1);
    assert_close(tri[0].positions[0], Vec3::new(10.0, 20.0, 30.0));
    assert_close(tri[0].positions[2], TRANSFORMED_ONES);
    // Normals use the inverse transpose: (0, 0, 1) → S⁻¹ → (0, 0, ¼) → Rx → (0, −¼, 0)
    // → Ry → (0, −¼, 0) → Rz → (¼, 0, 0), normalised.
    assert_close(tri[0].normals.unwrap()[0], Vec3::X);
    // The geometric normal (0, −1, 1) maps the same way, to (3, −4, 0) / 5 (hand-computed),
    // which is where the transformed vertices' cross product points.
    let [a, b, c] = tri[0].positions;
    assert_close((b - a).cross(c - a).normalize(), Vec3::new(0.6, -0.8, 0.0));

    // Mesh 2: a mirroring transform keeps the front face (+z) in front by swapping vertices.
    let flat: Vec<_> = scene
        .triangles
        .iter()
        .filter(|t| t.material == find("meshes/flat.obj/paper"))
        .collect();
    assert_eq!(flat.len(), 1);
    let [a, b, cc] = flat[0].positions;
    assert!(
        (b - a).cross(cc - a).z > 0.0,
        "mirrored triangle flipped: {:?}",
        flat[0].positions
    );
    assert_close(flat[0].normals.unwrap()[0], Vec3::Z);

    // Sphere.
    assert_eq!(scene.spheres.len(), 1);
    assert_eq!(scene.spheres[0].center, Vec3::new(0.3, 0.35, 0.2));
    assert_eq!(
        (scene.spheres[0].radius, scene.spheres[0].material),
        (0.35, find("glass"))
    );

    // Quad: corner, corner+e1, corner+e1+e2 and corner, corner+e1+e2, corner+e2; front = e1 × e2 = −y.
    let quad: Vec<_> = scene
        .triangles
        .iter()
        .filter(|t| t.material == find("lamp"))
        .collect();
    assert_eq!(quad.len(), 2);
    let corner = Vec3::new(-0.25, 1.98, -0.2);
    let (e1, e2) = (Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.0, 0.4));
    assert_eq!(quad[0].positions, [corner, corner + e1, corner + e1 + e2]);
    assert_eq!(quad[1].positions, [corner, corner + e1 + e2, corner + e2]);
    for t in &quad {
        let [a, b, c] = t.positions;
        let normal = (b - a).cross(c - a).normalize();
        assert_close(normal, Vec3::NEG_Y);
        assert!(t.normals.is_none());
    }

    // Lights: directions normalised, angles in radians.
    assert_eq!(scene.lights.len(), 3);
    assert_eq!(
        scene.lights[0],
        Light::Point {
            position: Vec3::new(0.0, 1.9, 0.0),
            intensity: Vec3::splat(5.0)
        }
    );
    let Light::Spot {
        direction,
        cone_angle,
        falloff_start,
        intensity,
        ..
    } = scene.lights[1]
    else {
        panic!("{:?}", scene.lights[1])
    };
    assert_eq!(direction, Vec3::NEG_Y);
    assert_eq!(intensity, Vec3::splat(20.0));
    assert!((cone_angle - 30f32.to_radians()).abs() < 1e-6);
    assert!((falloff_start - 25f32.to_radians()).abs() < 1e-6);
    let Light::Directional {
        direction,
        irradiance,
    } = scene.lights[2]
    else {
        panic!("{:?}", scene.lights[2])
    };
    assert_close(direction, Vec3::new(-0.3, -1.0, 0.2).normalize());
    assert_eq!(irradiance, Vec3::splat(3.0));

    // Render defaults.
    let r = &scene.render;
    assert_eq!(r.passes, Some(64));
    let params: Vec<(&str, &str)> = r
        .params
        .iter()
        .map(|(k, v)| (k.as_str(), v.as_str()))
        .collect();
    assert_eq!(
        params,
        [
            ("alpha", "0.7"),
            ("initial_radius", "0.05"),
            ("max_depth", "12"),
            ("method", "ppm"),
            ("photons_per_pass", "100000"),
            ("seed", "7"),
        ]
    );
}

#[test]
fn defaults_of_optional_keys() {
    let text = r#"format = 1
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 1.0]
fov_y = 60
[materials.lamp]
type = "mirror"
emission = [1.0, 1.0, 1.0]
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1
material = "lamp"
[[lights]]
type = "spot"
position = [0.0, 0.0, 0.0]
direction = [0.0, 0.0, 1.0]
intensity = [1.0, 1.0, 1.0]
cone_angle = 10
"#;
    let scene = load_toml_str(text, Path::new("defaults.toml")).unwrap();
    assert_eq!(scene.camera.up, Vec3::Y);
    assert_eq!(scene.camera.aperture_radius, 0.0);
    assert_eq!(scene.camera.focus_distance, 4.0);
    assert_eq!((scene.film.width, scene.film.height), (512, 512));
    assert_eq!(
        scene.materials[0].kind,
        MaterialKind::Mirror(scene::Mirror {
            reflectance: Vec3::ONE
        })
    );
    let Light::Spot {
        cone_angle,
        falloff_start,
        ..
    } = scene.lights[0]
    else {
        panic!()
    };
    assert_eq!(cone_angle, falloff_start);
    assert_eq!(scene.render, scene::RenderDefaults::default());
    assert_eq!(scene.summary().emissive_spheres, 1);
}

#[test]
fn scene_without_camera_is_framed() {
    let text = "format = 1\n[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\nemission = [1.0, 1.0, 1.0]\n\
                [[shapes]]\ntype = \"sphere\"\ncenter = [1.0, 2.0, 3.0]\nradius = 0.5\nmaterial = \"m\"\n";
    let scene = load_toml_str(text, Path::new("framed.toml")).unwrap();
    assert!(scene.notes.camera_framed);
    assert_eq!(scene.camera.look_at, Vec3::new(1.0, 2.0, 3.0));
    assert!(scene.camera.position.z > 3.5);
}

#[test]
fn paths_resolve_relative_to_the_source() {
    let path = write_scene("toml_relative_paths");
    let text = std::fs::read_to_string(&path).unwrap();
    // Same text, given in memory with the same source path: same scene.
    let scene = load_toml_str(&text, &path).unwrap();
    assert_eq!(scene, load(&path).unwrap());
    // From another directory the mesh file is missing, and the error names it.
    let err = load_toml_str(&text, Path::new("elsewhere/scene.toml")).unwrap_err();
    assert!(matches!(err, import::LoadError::Io { .. }), "{err:?}");
    crate::assert_names_file(&err, Path::new("elsewhere/meshes/tri.obj"));
}

#[test]
fn gltf_mesh_inside_a_toml_scene() {
    let gltf = crate::shared_scenes().join("gltf/Box/glTF-Binary/Box.glb");
    let text = format!(
        r#"format = 1
[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
[[shapes]]
type = "mesh"
file = {file:?}
transform = {{ translate = [0.0, 0.0, -3.0] }}
[[shapes]]
type = "quad"
corner = [-1.0, 2.0, -1.0]
edge1 = [0.0, 0.0, 2.0]
edge2 = [2.0, 0.0, 0.0]
material = "lamp"
"#,
        file = gltf.display().to_string()
    );
    let scene = load_toml_str(&text, Path::new("box.toml")).unwrap();
    let summary = scene.summary();
    assert_eq!(summary.triangles, 12 + 2);
    assert_eq!(summary.emissive_triangles, 2);
    let red = summary
        .materials
        .iter()
        .find(|m| m.name.ends_with("Box.glb/Red"))
        .unwrap();
    assert_eq!(red.triangles, 12);
    // The Box is a unit cube around the origin; moved to z = −3.
    let bounds = summary.bounds.unwrap();
    assert!((bounds.min.z - -3.5).abs() < 1e-5 && (bounds.max.y - 2.0).abs() < 1e-5);
    // The lamp quad's front is edge1 × edge2 = (0, 0, 2) × (2, 0, 0) = (0, 4, 0): up.
    let quad = scene.triangles.iter().find(|t| t.material == 0).unwrap();
    let [a, b, c] = quad.positions;
    assert!((b - a).cross(c - a).y > 0.0);
    assert!(scene.notes.camera_framed);
}
