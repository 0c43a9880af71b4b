//! Round trip through Mitsuba 3 XML: a scene written as Mitsuba XML by the helper below (an
//! exporter that knows nothing of the importer's code, only Mitsuba's documented plugins) and
//! read back by `import::load` describes the same scene and renders the same image.
//!
//! What Mitsuba cannot say is lost on purpose and checked as such: an arc of a cylinder comes
//! back whole (Mitsuba's `cylinder` has no arc), and the render settings other than the
//! integrator's `max_depth` are not Mitsuba concepts.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use glam::Vec3;
use scene::{Light, MaterialKind, SceneDescription};

/// The Fresnel reflectance at normal incidence of ior 1.5 (the coat of Mitsuba's plastic as
/// written here), ((1.5 − 1) / (1.5 + 1))².
const F0: f32 = 0.04;

fn v3(v: Vec3) -> String {
    format!("{} {} {}", v.x, v.y, v.z)
}
fn c3(v: Vec3) -> String {
    format!("{}, {}, {}", v.x, v.y, v.z)
}

/// Writes `scene` as a Mitsuba 3 scene in `dir` (one OBJ per material for the triangles).
fn write_mitsuba(scene: &SceneDescription, dir: &Path) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let mut x = String::from("<scene version=\"3.0.0\">\n");
    if let Some(depth) = scene.render.get("max_depth") {
        let depth: u32 = depth.parse().unwrap();
        // Mitsuba counts path segments: one more than scattering events.
        writeln!(
            x,
            "  <integrator type=\"path\"><integer name=\"max_depth\" value=\"{}\"/></integrator>",
            depth + 1
        )
        .unwrap();
    }
    let c = scene.camera;
    let thin = c.aperture_radius > 0.0;
    writeln!(
        x,
        "  <sensor type=\"{}\">",
        if thin { "thinlens" } else { "perspective" }
    )
    .unwrap();
    writeln!(
        x,
        "    <float name=\"fov\" value=\"{}\"/>",
        c.fov_y.to_degrees()
    )
    .unwrap();
    writeln!(x, "    <string name=\"fov_axis\" value=\"y\"/>").unwrap();
    writeln!(
        x,
        "    <float name=\"focus_distance\" value=\"{}\"/>",
        c.focus_distance
    )
    .unwrap();
    if thin {
        writeln!(
            x,
            "    <float name=\"aperture_radius\" value=\"{}\"/>",
            c.aperture_radius
        )
        .unwrap();
    }
    writeln!(
        x,
        "    <transform name=\"to_world\"><lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>",
        c3(c.position),
        c3(c.look_at),
        c3(c.up)
    )
    .unwrap();
    writeln!(
        x,
        "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"{}\"/><integer name=\"height\" value=\"{}\"/><rfilter type=\"box\"/></film>",
        scene.film.width, scene.film.height
    )
    .unwrap();
    x.push_str("  </sensor>\n");
    for (i, m) in scene.materials.iter().enumerate() {
        let body = match m.kind {
            MaterialKind::Diffuse(scene::Diffuse { albedo }) => {
                format!(
                    "<bsdf type=\"diffuse\" id=\"m{i}\"><rgb name=\"reflectance\" value=\"{}\"/></bsdf>",
                    c3(albedo)
                )
            }
            MaterialKind::Mirror(scene::Mirror { reflectance }) => format!(
                "<bsdf type=\"conductor\" id=\"m{i}\"><string name=\"material\" value=\"none\"/><rgb name=\"specular_reflectance\" value=\"{}\"/></bsdf>",
                c3(reflectance)
            ),
            MaterialKind::Dielectric(scene::Dielectric { ior }) => format!(
                "<bsdf type=\"dielectric\" id=\"m{i}\"><float name=\"int_ior\" value=\"{ior}\"/><float name=\"ext_ior\" value=\"1\"/></bsdf>"
            ),
            MaterialKind::RoughDielectric(scene::RoughDielectric { ior, roughness }) => format!(
                "<bsdf type=\"roughdielectric\" id=\"m{i}\"><float name=\"alpha\" value=\"{roughness}\"/><float name=\"int_ior\" value=\"{ior}\"/><float name=\"ext_ior\" value=\"1\"/></bsdf>"
            ),
            MaterialKind::Glossy(scene::Glossy {
                reflectance,
                roughness,
                diffuse,
            }) if diffuse == Vec3::ZERO => format!(
                "<bsdf type=\"roughconductor\" id=\"m{i}\"><string name=\"material\" value=\"none\"/><float name=\"alpha\" value=\"{roughness}\"/><rgb name=\"specular_reflectance\" value=\"{}\"/></bsdf>",
                c3(reflectance)
            ),
            // A coat over a diffuse base: Mitsuba's roughplastic, whose import scales the
            // specular part by the coat's Fresnel F0 and the diffuse part by 1 − F0.
            MaterialKind::Glossy(scene::Glossy {
                reflectance,
                roughness,
                diffuse,
            }) => format!(
                "<bsdf type=\"roughplastic\" id=\"m{i}\"><float name=\"int_ior\" value=\"1.5\"/><float name=\"ext_ior\" value=\"1\"/><float name=\"alpha\" value=\"{roughness}\"/><rgb name=\"specular_reflectance\" value=\"{}\"/><rgb name=\"diffuse_reflectance\" value=\"{}\"/></bsdf>",
                c3(reflectance / F0),
                c3(diffuse / (1.0 - F0))
            ),
            MaterialKind::Interface(_) => format!("<bsdf type=\"null\" id=\"m{i}\"/>"),
            MaterialKind::Conductor(c) => format!(
                "<bsdf type=\"roughconductor\" id=\"m{i}\"><float name=\"alpha\" value=\"{}\"/><rgb name=\"eta\" value=\"{}\"/><rgb name=\"k\" value=\"{}\"/><rgb name=\"specular_reflectance\" value=\"{}\"/></bsdf>",
                c.roughness,
                c3(c.eta),
                c3(c.k),
                c3(c.specular_reflectance)
            ),
        };
        writeln!(x, "  {body}").unwrap();
    }
    let emitter = |m: u32| {
        let e = scene.materials[m as usize].emission;
        if e.max_element() > 0.0 {
            format!(
                "<emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/></emitter>",
                c3(e)
            )
        } else {
            String::new()
        }
    };
    // One OBJ per run of consecutive triangles of one material, so the order is kept.
    let mut runs: Vec<(u32, Vec<&scene::Triangle>)> = Vec::new();
    for t in &scene.triangles {
        match runs.last_mut() {
            Some((m, tris)) if *m == t.material => tris.push(t),
            _ => runs.push((t.material, vec![t])),
        }
    }
    for (r, (m, tris)) in runs.iter().enumerate() {
        let mut obj = String::new();
        for t in tris {
            for p in t.positions {
                writeln!(obj, "v {}", v3(p)).unwrap();
            }
            for n in t.normals.unwrap_or([Vec3::ZERO; 3]) {
                writeln!(obj, "vn {}", v3(n)).unwrap();
            }
        }
        for (k, t) in tris.iter().enumerate() {
            let b = 3 * k + 1;
            if t.normals.is_some() {
                writeln!(obj, "f {b}//{b} {}//{} {}//{}", b + 1, b + 1, b + 2, b + 2).unwrap();
            } else {
                writeln!(obj, "f {b} {} {}", b + 1, b + 2).unwrap();
            }
        }
        let file = format!("mesh{r}.obj");
        std::fs::write(dir.join(&file), obj).unwrap();
        writeln!(
            x,
            "  <shape type=\"obj\"><string name=\"filename\" value=\"{file}\"/><ref id=\"m{m}\"/>{}</shape>",
            emitter(*m)
        )
        .unwrap();
    }
    for s in &scene.spheres {
        writeln!(
            x,
            "  <shape type=\"sphere\"><point name=\"center\" value=\"{}\"/><float name=\"radius\" value=\"{}\"/><ref id=\"m{}\"/>{}</shape>",
            v3(s.center),
            s.radius,
            s.material,
            emitter(s.material)
        )
        .unwrap();
    }
    for c in &scene.cylinders {
        writeln!(
            x,
            "  <shape type=\"cylinder\"><point name=\"p0\" value=\"{}\"/><point name=\"p1\" value=\"{}\"/><float name=\"radius\" value=\"{}\"/><ref id=\"m{}\"/></shape>",
            v3(c.center),
            v3(c.center + c.height * c.axis),
            c.radius,
            c.material
        )
        .unwrap();
    }
    for l in &scene.lights {
        let body = match *l {
            Light::Point {
                position,
                intensity,
            } => format!(
                "<emitter type=\"point\"><point name=\"position\" value=\"{}\"/><rgb name=\"intensity\" value=\"{}\"/></emitter>",
                v3(position),
                c3(intensity)
            ),
            Light::Spot {
                position,
                direction,
                intensity,
                cone_angle,
                falloff_start,
            } => format!(
                "<emitter type=\"spot\"><transform name=\"to_world\"><lookat origin=\"{}\" target=\"{}\"/></transform><rgb name=\"intensity\" value=\"{}\"/><float name=\"cutoff_angle\" value=\"{}\"/><float name=\"beam_width\" value=\"{}\"/></emitter>",
                c3(position),
                c3(position + direction),
                c3(intensity),
                cone_angle.to_degrees(),
                falloff_start.to_degrees()
            ),
            Light::Directional {
                direction,
                irradiance,
            } => format!(
                "<emitter type=\"directional\"><vector name=\"direction\" value=\"{}\"/><rgb name=\"irradiance\" value=\"{}\"/></emitter>",
                v3(direction),
                c3(irradiance)
            ),
        };
        writeln!(x, "  {body}").unwrap();
    }
    x.push_str("</scene>\n");
    let path = dir.join("scene.xml");
    std::fs::write(&path, x).unwrap();
    path
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fppm-roundtrip-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[track_caller]
fn close(a: Vec3, b: Vec3, what: &str) {
    let scale = a.abs().max(b.abs()).max_element().max(1.0);
    assert!(
        (a - b).abs().max_element() <= 2e-6 * scale,
        "{what}: {a} vs {b}"
    );
}

#[track_caller]
fn close_f(a: f32, b: f32, what: &str) {
    assert!(
        (a - b).abs() <= 2e-6 * a.abs().max(b.abs()).max(1.0),
        "{what}: {a} vs {b}"
    );
}

fn close_kind(a: MaterialKind, b: MaterialKind, what: &str) {
    match (a, b) {
        (
            MaterialKind::Diffuse(scene::Diffuse { albedo: x }),
            MaterialKind::Diffuse(scene::Diffuse { albedo: y }),
        ) => close(x, y, what),
        (
            MaterialKind::Mirror(scene::Mirror { reflectance: x }),
            MaterialKind::Mirror(scene::Mirror { reflectance: y }),
        ) => close(x, y, what),
        (
            MaterialKind::Dielectric(scene::Dielectric { ior: x }),
            MaterialKind::Dielectric(scene::Dielectric { ior: y }),
        ) => close_f(x, y, what),
        (
            MaterialKind::RoughDielectric(scene::RoughDielectric {
                ior: x,
                roughness: a1,
            }),
            MaterialKind::RoughDielectric(scene::RoughDielectric {
                ior: y,
                roughness: a2,
            }),
        ) => {
            close_f(x, y, what);
            close_f(a1, a2, what);
        }
        (
            MaterialKind::Glossy(scene::Glossy {
                reflectance: r1,
                roughness: a1,
                diffuse: d1,
            }),
            MaterialKind::Glossy(scene::Glossy {
                reflectance: r2,
                roughness: a2,
                diffuse: d2,
            }),
        ) => {
            close(r1, r2, what);
            close_f(a1, a2, what);
            close(d1, d2, what);
        }
        (MaterialKind::Conductor(x), MaterialKind::Conductor(y)) => {
            close(x.eta, y.eta, what);
            close(x.k, y.k, what);
            close(x.specular_reflectance, y.specular_reflectance, what);
            close_f(x.roughness, y.roughness, what);
        }
        _ => panic!("{what}: {a:?} vs {b:?}"),
    }
}

/// Everything the XML can carry is the same, triangle by triangle, sphere by sphere.
fn assert_same(a: &SceneDescription, b: &SceneDescription, name: &str) {
    // Camera: the same eye, view direction, image-up side and field of view.
    let (ca, cb) = (a.camera, b.camera);
    close(ca.position, cb.position, &format!("{name} camera position"));
    let (fa, fb) = (
        (ca.look_at - ca.position).normalize(),
        (cb.look_at - cb.position).normalize(),
    );
    close(fa, fb, &format!("{name} camera direction"));
    close(
        fa.cross(ca.up).normalize(),
        fb.cross(cb.up).normalize(),
        &format!("{name} camera right"),
    );
    close_f(ca.fov_y, cb.fov_y, &format!("{name} fov"));
    close_f(
        ca.aperture_radius,
        cb.aperture_radius,
        &format!("{name} aperture"),
    );
    assert_eq!(a.film, b.film, "{name} film");
    assert_eq!(
        a.render.get("max_depth"),
        b.render.get("max_depth"),
        "{name} max depth"
    );
    assert_eq!(a.triangles.len(), b.triangles.len(), "{name} triangles");
    for (i, (t, u)) in a.triangles.iter().zip(&b.triangles).enumerate() {
        for k in 0..3 {
            close(
                t.positions[k],
                u.positions[k],
                &format!("{name} triangle {i}"),
            );
        }
        assert_eq!(
            t.normals.is_some(),
            u.normals.is_some(),
            "{name} triangle {i} normals"
        );
        if let (Some(n), Some(m)) = (t.normals, u.normals) {
            for k in 0..3 {
                close(n[k], m[k], &format!("{name} triangle {i} normal"));
            }
        }
        let (ma, mb) = (
            &a.materials[t.material as usize],
            &b.materials[u.material as usize],
        );
        close_kind(ma.kind, mb.kind, &format!("{name} triangle {i} material"));
        close(
            ma.emission,
            mb.emission,
            &format!("{name} triangle {i} emission"),
        );
    }
    assert_eq!(a.spheres.len(), b.spheres.len(), "{name} spheres");
    for (s, t) in a.spheres.iter().zip(&b.spheres) {
        close(s.center, t.center, &format!("{name} sphere"));
        close_f(s.radius, t.radius, &format!("{name} sphere radius"));
        close_kind(
            a.materials[s.material as usize].kind,
            b.materials[t.material as usize].kind,
            name,
        );
        close(
            a.materials[s.material as usize].emission,
            b.materials[t.material as usize].emission,
            name,
        );
    }
    assert_eq!(a.lights.len(), b.lights.len(), "{name} lights");
    for (l, m) in a.lights.iter().zip(&b.lights) {
        match (*l, *m) {
            (
                Light::Point {
                    position: p,
                    intensity: i,
                },
                Light::Point {
                    position: q,
                    intensity: j,
                },
            ) => {
                close(p, q, name);
                close(i, j, name);
            }
            (
                Light::Spot {
                    position: p,
                    direction: d,
                    intensity: i,
                    cone_angle: c,
                    falloff_start: f,
                },
                Light::Spot {
                    position: q,
                    direction: e,
                    intensity: j,
                    cone_angle: c2,
                    falloff_start: f2,
                },
            ) => {
                close(p, q, name);
                close(d, e, name);
                close(i, j, name);
                close_f(c, c2, name);
                close_f(f, f2, name);
            }
            (
                Light::Directional {
                    direction: d,
                    irradiance: i,
                },
                Light::Directional {
                    direction: e,
                    irradiance: j,
                },
            ) => {
                close(d, e, name);
                close(i, j, name);
            }
            _ => panic!("{name}: {l:?} vs {m:?}"),
        }
    }
}

/// A few path-traced passes at a small size.
fn render(scene: SceneDescription) -> Vec<[f32; 3]> {
    crate::path_image(scene, (24, 18), 7, 4)
}

/// The two images agree: the same pixels up to the rounding of the camera frame rebuilt from
/// the written look-at (measured: 0 to 2e-6 of the image's sum).
fn assert_same_image(a: &[[f32; 3]], b: &[[f32; 3]], name: &str) {
    let sum: f64 = a.iter().flatten().map(|&v| f64::from(v)).sum();
    let diff: f64 = a
        .iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(&x, &y)| f64::from((x - y).abs()))
        .sum();
    assert!(sum > 0.0, "{name}: black image");
    assert!(
        diff <= 1e-5 * sum,
        "{name}: images differ by {:.3e} of their sum",
        diff / sum
    );
}

#[test]
fn shared_cornell_boxes_round_trip_through_mitsuba_xml() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/scenes/cornell_box");
    for name in [
        "CornellBox-Original",
        "CornellBox-Mirror",
        "CornellBox-Sphere",
        "CornellBox-Glossy",
        "CornellBox-Water",
        "CornellBox-Empty-RG",
    ] {
        let original = import::load(&root.join(format!("{name}.obj"))).unwrap();
        let xml = write_mitsuba(&original, &temp_dir(name));
        let back = import::load(&xml).unwrap();
        assert_same(&original, &back, name);
        assert_same_image(&render(original), &render(back), name);
    }
}

#[test]
fn default_scene_round_trips_through_mitsuba_xml() {
    let text = include_str!("../../crates/cli/src/default_scene.toml");
    let original = import::load_toml_str(text, Path::new("default_scene.toml")).unwrap();
    let xml = write_mitsuba(&original, &temp_dir("default"));
    let back = import::load(&xml).unwrap();
    // The render settings other than max_depth (method, passes, photons, seed) are not
    // Mitsuba's to carry; the default scene sets none of max_depth.
    assert_same(&original, &back, "default scene");
    // The half-ring cylinder comes back whole (Mitsuba's cylinder has no arc), the rest equal.
    assert_eq!(original.cylinders.len(), 1);
    assert_eq!(back.cylinders.len(), 1);
    let (c, d) = (original.cylinders[0], back.cylinders[0]);
    close(c.center, d.center, "cylinder centre");
    close(c.axis, d.axis, "cylinder axis");
    close_f(c.radius, d.radius, "cylinder radius");
    close_f(c.height, d.height, "cylinder height");
    assert!(c.arc < std::f32::consts::TAU && d.arc == std::f32::consts::TAU);
    // With the arc restored, the two describe one scene and render one image.
    let mut restored = back.clone();
    restored.cylinders[0].arc = c.arc;
    restored.cylinders[0].facing = c.facing;
    assert_same_image(&render(original), &render(restored), "default scene");
}
