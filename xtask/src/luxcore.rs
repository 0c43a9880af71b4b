//! LuxCore export for `cargo xtask peers`: the scene as LuxCore's text properties, rendered by
//! `xtask/peers/render_luxcore.py` with LuxCore's path tracer and its PhotonGI caustic cache.
//!
//! Why LuxCore: Mitsuba 3 has no estimator that resolves a caustic seen through a specular
//! surface (the caustic on a pool's floor seen through the water, a floor caustic seen in a
//! mirror): its `path` reads such a caustic far too dark at any budget we can afford, so a
//! reference of those pixels has to merge photons. LuxCore's caustic cache does, in code
//! independent of fppm's: photons re-traced every 4 samples per pixel, a lookup radius that
//! shrinks to a quarter of a pixel. On box-glass-mirror, where Mitsuba's `path` converges, the
//! two agree within 0.05 % in the image mean and 0.5 % on the glass ball's floor caustic.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use glam::Vec3;

use crate::meshes::{cylinder_ply, sphere_ply, triangles_ply};

/// The segments of a sphere's tessellation around its axis (and half as many from pole to
/// pole): at 512 the facets of a sphere 30 pixels wide are a tenth of a pixel, and their vertex
/// normals are exact, so the shading normal is the sphere's within 10⁻⁵.
const SPHERE_SEGMENTS: usize = 512;
/// The segments of a cylinder's kept arc, as the Mitsuba export.
const CYLINDER_SEGMENTS: usize = 512;

/// Writes `description` as a LuxCore scene (`scene.scn`, `render.cfg` with the film, and one
/// PLY per material group, sphere and cylinder) in `dir`; returns the scene file's path.
///
/// Conventions: a diffuse material is `matte` (two-sided, as fppm's), a mirror `mirror` of
/// reflectance `kr`, a dielectric `glass` with `interiorior` = ior, `kr` = `kt` = 1 (exact
/// Fresnel, as fppm's); emission is the material's `emission` radiance with gain 1 and no
/// power normalisation, one-sided towards the triangle's counter-clockwise side as in fppm;
/// spheres and cylinders are tessellated with exact vertex normals; the camera is
/// `perspective` with the field of view on the film's shorter side (LuxCore's convention,
/// converted from fppm's vertical one); the film is box-filtered over one pixel. Everything
/// else (textures, glossy and conductor materials, media, point, directional and environment
/// lights, a thin lens) is refused with an error naming it: the caustic scenes this serves do
/// not use them.
pub(crate) fn write_luxcore(description: &scene::SceneDescription, dir: &Path) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let dir = dir
        .canonicalize()
        .with_context(|| format!("resolving {}", dir.display()))?;
    if description.media.are_used() {
        bail!("media are not exported to LuxCore");
    }
    if description.environment.is_some() {
        bail!("an environment light is not exported to LuxCore");
    }
    if let Some(light) = description.lights.first() {
        bail!("light {light:?} is not exported to LuxCore");
    }
    let c = &description.camera;
    if c.aperture_radius > 0.0 {
        bail!("thin-lens cameras are not exported to LuxCore");
    }
    let v = |p: Vec3| format!("{} {} {}", p.x, p.y, p.z);
    let rgb = |c: Vec3| format!("{} {} {}", c.x, c.y, c.z);

    let mut scn = String::new();
    let (width, height) = (description.film.width, description.film.height);
    // LuxCore's field of view spans the shorter side of the film.
    let fov = if width < height {
        2.0 * ((c.fov_y * 0.5).tan() * width as f32 / height as f32).atan()
    } else {
        c.fov_y
    };
    writeln!(scn, "scene.camera.type = \"perspective\"")?;
    writeln!(scn, "scene.camera.lookat.orig = {}", v(c.position))?;
    writeln!(scn, "scene.camera.lookat.target = {}", v(c.look_at))?;
    writeln!(scn, "scene.camera.up = {}", v(c.up))?;
    writeln!(scn, "scene.camera.fieldofview = {}", fov.to_degrees())?;

    for (index, m) in description.materials.iter().enumerate() {
        if m.textures.is_some() {
            bail!("material {}: textures are not exported to LuxCore", m.name);
        }
        let key = format!("scene.materials.m{index}");
        match m.kind {
            scene::MaterialKind::Diffuse(scene::Diffuse { albedo }) => {
                writeln!(scn, "{key}.type = \"matte\"")?;
                writeln!(scn, "{key}.kd = {}", rgb(albedo))?;
            }
            scene::MaterialKind::Mirror(scene::Mirror { reflectance }) => {
                writeln!(scn, "{key}.type = \"mirror\"")?;
                writeln!(scn, "{key}.kr = {}", rgb(reflectance))?;
            }
            scene::MaterialKind::Dielectric(scene::Dielectric { ior }) => {
                writeln!(scn, "{key}.type = \"glass\"")?;
                writeln!(scn, "{key}.kr = 1 1 1")?;
                writeln!(scn, "{key}.kt = 1 1 1")?;
                writeln!(scn, "{key}.interiorior = {ior}")?;
                writeln!(scn, "{key}.exteriorior = 1")?;
            }
            ref other => bail!("material {}: {other:?} is not exported to LuxCore", m.name),
        }
        if m.emission.max_element() > 0.0 {
            writeln!(scn, "{key}.emission = {}", rgb(m.emission))?;
            writeln!(scn, "{key}.emission.gain = 1 1 1")?;
            writeln!(scn, "{key}.emission.power = 0")?;
            writeln!(scn, "{key}.emission.efficency = 0")?;
            writeln!(scn, "{key}.emission.normalizebycolor = 0")?;
        }
    }

    let object = |scn: &mut String, name: String, ply: String, material: u32| -> Result<()> {
        let file = dir.join(format!("{name}.ply"));
        std::fs::write(&file, ply).with_context(|| format!("writing {}", file.display()))?;
        writeln!(scn, "scene.shapes.{name}.type = \"mesh\"")?;
        writeln!(scn, "scene.shapes.{name}.ply = \"{}\"", file.display())?;
        writeln!(scn, "scene.objects.{name}.shape = \"{name}\"")?;
        writeln!(scn, "scene.objects.{name}.material = \"m{material}\"")?;
        Ok(())
    };
    let mut materials: Vec<u32> = description.triangles.iter().map(|t| t.material).collect();
    materials.sort_unstable();
    materials.dedup();
    for material in materials {
        let triangles: Vec<_> = description
            .triangles
            .iter()
            .filter(|t| t.material == material)
            .collect();
        object(
            &mut scn,
            format!("triangles{material}"),
            triangles_ply(&triangles),
            material,
        )?;
    }
    for (index, s) in description.spheres.iter().enumerate() {
        object(
            &mut scn,
            format!("sphere{index}"),
            sphere_ply(s, SPHERE_SEGMENTS),
            s.material,
        )?;
    }
    for (index, cylinder) in description.cylinders.iter().enumerate() {
        object(
            &mut scn,
            format!("cylinder{index}"),
            cylinder_ply(cylinder, CYLINDER_SEGMENTS),
            cylinder.material,
        )?;
    }
    let scene_file = dir.join("scene.scn");
    std::fs::write(&scene_file, scn)?;
    // The caustic cache's lookup radius starts at 0.5 % of the scene's diagonal (1.7 cm in a
    // 2 m box) and shrinks to 0.05 % (a quarter of a pixel where the box fills 256 pixels).
    let diagonal = scene_diagonal(description);
    let cfg = format!(
        "film.width = {width}\nfilm.height = {height}\nfilm.filter.type = \"BOX\"\nfilm.filter.width = 0.5\npath.photongi.caustic.lookup.radius = {}\npath.photongi.caustic.updatespp.minradius = {}\n",
        0.005 * diagonal,
        0.0005 * diagonal
    );
    std::fs::write(dir.join("render.cfg"), cfg)?;
    Ok(scene_file)
}

/// The diagonal of the box around every shape (1 for a scene without shapes).
fn scene_diagonal(description: &scene::SceneDescription) -> f32 {
    let mut bounds = scene::Aabb::EMPTY;
    for t in &description.triangles {
        bounds = t.positions.iter().fold(bounds, |b, &p| b.include(p));
    }
    for s in &description.spheres {
        bounds = bounds
            .include(s.center - s.radius)
            .include(s.center + s.radius);
    }
    for c in &description.cylinders {
        for end in [c.center, c.center + c.height * c.axis] {
            bounds = bounds.include(end - c.radius).include(end + c.radius);
        }
    }
    if bounds.is_empty() {
        1.0
    } else {
        2.0 * bounds.bounding_radius()
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use glam::Vec3;

    use super::write_luxcore;
    use crate::meshes::sphere_ply;

    /// The vertices and faces of an ASCII PLY with `x y z nx ny nz` vertices.
    fn read_ply(ply: &str) -> (Vec<[Vec3; 2]>, Vec<[usize; 3]>) {
        let body = ply.split("end_header\n").nth(1).unwrap();
        let (mut vertices, mut faces) = (Vec::new(), Vec::new());
        for line in body.lines() {
            let v: Vec<f32> = line.split(' ').map(|x| x.parse().unwrap()).collect();
            match v.len() {
                6 => vertices.push([Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5])]),
                4 => faces.push([v[1] as usize, v[2] as usize, v[3] as usize]),
                n => panic!("a line of {n} numbers"),
            }
        }
        (vertices, faces)
    }

    #[test]
    fn a_tessellated_sphere_lies_on_the_sphere_and_faces_out() {
        let s = scene::Sphere {
            center: Vec3::new(0.4, 0.75, 0.25),
            radius: 0.3,
            material: 0,
        };
        let (vertices, faces) = read_ply(&sphere_ply(&s, 16));
        for [p, n] in &vertices {
            assert!(((*p - s.center).length() - s.radius).abs() < 1e-5);
            assert!((*n - (*p - s.center) / s.radius).length() < 1e-5);
        }
        // Every face that is not collapsed at a pole turns counter-clockwise seen from outside.
        let mut faces_out = 0;
        for [a, b, c] in faces {
            let [a, b, c] = [a, b, c].map(|i| vertices[i][0]);
            let normal = (b - a).cross(c - a);
            if normal.length() < 1e-6 * s.radius * s.radius {
                continue;
            }
            assert!(normal.dot((a + b + c) / 3.0 - s.center) > 0.0);
            faces_out += 1;
        }
        // 16 × 8 quads, less the 2 × 16 triangles collapsed at the poles.
        assert_eq!(faces_out, 2 * 16 * 8 - 2 * 16);
    }

    /// The exported scene names the materials the peer scene has, with their numbers, and a
    /// scene with a light LuxCore's export does not carry is refused.
    #[test]
    fn caustic_scenes_export_their_materials_and_others_are_refused() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let dir = std::env::temp_dir().join(format!("fppm-luxcore-export-{}", std::process::id()));
        for name in ["box-glass-mirror", "ring-caustic", "pool-caustic"] {
            let path = root.join("scenes/peers").join(format!("{name}.toml"));
            let description = import::load(&path).unwrap();
            let scn = write_luxcore(&description, &dir.join(name)).unwrap();
            let text = std::fs::read_to_string(&scn).unwrap();
            let value = |key: &str| {
                text.lines()
                    .find_map(|l| l.strip_prefix(&format!("{key} = ")))
                    .unwrap_or_else(|| panic!("{name}: no {key}"))
                    .trim_matches('"')
                    .to_owned()
            };
            for (i, m) in description.materials.iter().enumerate() {
                let key = format!("scene.materials.m{i}");
                match m.kind {
                    scene::MaterialKind::Diffuse(d) => {
                        assert_eq!(value(&format!("{key}.type")), "matte");
                        let kd = format!("{} {} {}", d.albedo.x, d.albedo.y, d.albedo.z);
                        assert_eq!(value(&format!("{key}.kd")), kd);
                    }
                    scene::MaterialKind::Mirror(_) => {
                        assert_eq!(value(&format!("{key}.type")), "mirror");
                    }
                    scene::MaterialKind::Dielectric(d) => {
                        assert_eq!(value(&format!("{key}.type")), "glass");
                        assert_eq!(value(&format!("{key}.interiorior")), d.ior.to_string());
                    }
                    other => panic!("{name}: {other:?}"),
                }
                if m.emission.max_element() > 0.0 {
                    let e = m.emission;
                    assert_eq!(
                        value(&format!("{key}.emission")),
                        format!("{} {} {}", e.x, e.y, e.z)
                    );
                }
            }
            // Every shape is an object with its PLY beside the scene.
            let shapes = text.lines().filter(|l| l.ends_with(".ply\"")).count();
            assert!(shapes >= 2, "{name}: {shapes} shapes");
        }
        let path = root.join("scenes/peers/glossy-floor.toml");
        let glossy = import::load(&path).unwrap();
        let error = write_luxcore(&glossy, &dir.join("glossy-floor")).unwrap_err();
        assert!(
            error.to_string().contains("not exported to LuxCore"),
            "{error}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
