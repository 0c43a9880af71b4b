//! Shared by the BVH benchmark and the `rayset` example: a minimal scene loader and ray sets.
#![allow(
    dead_code,
    clippy::unwrap_used,
    clippy::print_stdout,
    clippy::print_stderr,
    missing_docs,
    unreachable_pub
)]

use std::path::Path;

use geometry::{
    Camera, Film, Light, LoadNotes, Material, MaterialKind, Ray, RenderDefaults, Scene,
    SceneDescription, Triangle,
};
use glam::{Mat3, Mat4, Vec2, Vec3};

// replaced by geometry::load after the loaders land
pub fn load_triangles(path: &Path) -> SceneDescription {
    let triangles = match path.extension().and_then(|e| e.to_str()) {
        Some("obj") => load_obj(path),
        Some("gltf" | "glb") => load_gltf(path),
        _ => panic!("unsupported file {}", path.display()),
    };
    framed_description(path, triangles)
}

fn load_obj(path: &Path) -> Vec<Triangle> {
    let (models, _) = tobj::load_obj(path, &tobj::GPU_LOAD_OPTIONS).unwrap();
    let mut triangles = Vec::new();
    for m in models {
        let mesh = m.mesh;
        let p = |i: u32| Vec3::from_slice(&mesh.positions[3 * i as usize..3 * i as usize + 3]);
        let n = |i: u32| {
            Vec3::from_slice(&mesh.normals[3 * i as usize..3 * i as usize + 3]).normalize_or_zero()
        };
        for f in mesh.indices.chunks_exact(3) {
            triangles.push(Triangle {
                positions: [p(f[0]), p(f[1]), p(f[2])],
                normals: (!mesh.normals.is_empty()).then(|| [n(f[0]), n(f[1]), n(f[2])]),
                material: 0,
            });
        }
    }
    triangles
}

fn load_gltf(path: &Path) -> Vec<Triangle> {
    let (doc, buffers, _) = gltf::import(path).unwrap();
    let mut triangles = Vec::new();
    fn visit(
        node: gltf::Node,
        parent: Mat4,
        buffers: &[gltf::buffer::Data],
        out: &mut Vec<Triangle>,
    ) {
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                if prim.mode() != gltf::mesh::Mode::Triangles {
                    continue;
                }
                let reader = prim.reader(|b| Some(&buffers[b.index()]));
                let positions: Vec<Vec3> = reader
                    .read_positions()
                    .unwrap()
                    .map(|p| world.transform_point3(Vec3::from(p)))
                    .collect();
                let normals: Option<Vec<Vec3>> = reader.read_normals().map(|it| {
                    it.map(|n| (normal_matrix * Vec3::from(n)).normalize_or_zero())
                        .collect()
                });
                let indices: Vec<u32> = match reader.read_indices() {
                    Some(i) => i.into_u32().collect(),
                    None => (0..positions.len() as u32).collect(),
                };
                for f in indices.chunks_exact(3) {
                    let [a, b, c] = [f[0], f[1], f[2]].map(|i| i as usize);
                    out.push(Triangle {
                        positions: [positions[a], positions[b], positions[c]],
                        normals: normals.as_ref().map(|n| [n[a], n[b], n[c]]),
                        material: 0,
                    });
                }
            }
        }
        for child in node.children() {
            visit(child, world, buffers, out);
        }
    }
    let scene = doc.default_scene().or_else(|| doc.scenes().next()).unwrap();
    for node in scene.nodes() {
        visit(node, Mat4::IDENTITY, &buffers, &mut triangles);
    }
    triangles
}

/// A description with a camera framing the triangles' bounding box and a point light above.
fn framed_description(path: &Path, triangles: Vec<Triangle>) -> SceneDescription {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for t in &triangles {
        for p in t.positions {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    let center = 0.5 * (lo + hi);
    let radius = 0.5 * (hi - lo).length();
    let fov_y = 40f32.to_radians();
    let distance = radius / (0.5 * fov_y).sin();
    SceneDescription {
        source: path.to_path_buf(),
        camera: Camera {
            position: center + Vec3::new(0.0, 0.2, 1.0).normalize() * distance,
            look_at: center,
            up: Vec3::Y,
            fov_y,
            aperture_radius: 0.0,
            focus_distance: distance,
        },
        film: Film {
            width: 1024,
            height: 1024,
        },
        materials: vec![Material {
            name: "default".into(),
            kind: MaterialKind::Diffuse {
                albedo: Vec3::splat(0.8),
            },
            emission: Vec3::ZERO,
        }],
        triangles,
        spheres: vec![],
        cylinders: Vec::new(),
        lights: vec![Light::Point {
            position: center + Vec3::Y * 2.0 * radius,
            intensity: Vec3::ONE,
        }],
        render: RenderDefaults::default(),
        notes: LoadNotes::default(),
    }
}

/// A hash-based uniform number in [0, 1) for (index, dimension).
pub fn uniform(index: u64, dim: u64) -> f32 {
    let mut x = index.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ dim.wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    x ^= x >> 33;
    x = x.wrapping_mul(0xFF51_AFD7_ED55_8CCD);
    x ^= x >> 33;
    x = x.wrapping_mul(0xC4CE_B9FE_1A85_EC53);
    x ^= x >> 33;
    (x >> 40) as f32 / (1u64 << 24) as f32
}

/// One camera ray per pixel through the pixel centre.
pub fn primary_rays(scene: &Scene) -> Vec<Ray> {
    let (w, h) = scene.camera().resolution();
    let mut rays = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            rays.push(
                scene
                    .camera()
                    .generate_ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), Vec2::splat(0.5)),
            );
        }
    }
    rays
}

/// For every primary ray that hits: a cosine-distributed bounce from its hit point (the
/// realistic incoherent set of a path tracer's or photon tracer's second segment).
pub fn diffuse_bounce_rays(scene: &Scene, primary: &[Ray]) -> Vec<Ray> {
    let mut rays = Vec::new();
    for (i, ray) in primary.iter().enumerate() {
        let Some(hit) = scene.intersect(ray) else {
            continue;
        };
        let (u1, u2) = (uniform(i as u64, 0), uniform(i as u64, 1));
        let r = u1.sqrt();
        let phi = std::f32::consts::TAU * u2;
        let local = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt());
        let frame = geometry::Frame::from_normal(hit.geometric_normal);
        rays.push(hit.spawn_ray(frame.to_world(local)));
    }
    rays
}
