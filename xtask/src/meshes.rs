//! Shapes as ASCII PLY meshes for the peers' exports (Mitsuba and LuxCore): triangles as they
//! are, and curved shapes tessellated where a peer has no such analytic shape.

use std::fmt::Write as _;

use glam::Vec3;

/// Triangles as an ASCII PLY, three vertices each, with their shading normals and texture
/// coordinates where every triangle has them (else flat, as fppm shades them). Texture
/// coordinates are as they are: Mitsuba's bitmap, like fppm, puts v = 0 at the image's top row.
pub(crate) fn triangles_ply(triangles: &[&scene::Triangle]) -> String {
    let normals = triangles.iter().all(|t| t.normals.is_some());
    let uvs = triangles.iter().all(|t| t.uv.is_some());
    let mut ply = String::new();
    let _ = writeln!(ply, "ply\nformat ascii 1.0");
    let _ = writeln!(ply, "element vertex {}", 3 * triangles.len());
    let _ = writeln!(ply, "property float x\nproperty float y\nproperty float z");
    if normals {
        let _ = writeln!(
            ply,
            "property float nx\nproperty float ny\nproperty float nz"
        );
    }
    if uvs {
        let _ = writeln!(ply, "property float u\nproperty float v");
    }
    let _ = writeln!(ply, "element face {}", triangles.len());
    let _ = writeln!(ply, "property list uchar int vertex_indices\nend_header");
    for t in triangles {
        for k in 0..3 {
            let p = t.positions[k];
            let _ = write!(ply, "{} {} {}", p.x, p.y, p.z);
            if let Some(n) = t.normals.filter(|_| normals) {
                let _ = write!(ply, " {} {} {}", n[k].x, n[k].y, n[k].z);
            }
            if let Some(uv) = t.uv.filter(|_| uvs) {
                let _ = write!(ply, " {} {}", uv[k].x, uv[k].y);
            }
            let _ = writeln!(ply);
        }
    }
    for i in 0..triangles.len() {
        let _ = writeln!(ply, "3 {} {} {}", 3 * i, 3 * i + 1, 3 * i + 2);
    }
    ply
}

/// An open cylinder's kept arc as an ASCII PLY of `segments` quads with exact outward normals,
/// counter-clockwise seen from outside (the front, as fppm's analytic cylinder).
pub(crate) fn cylinder_ply(c: &scene::Cylinder, segments: usize) -> String {
    let side = c.axis.cross(c.facing);
    let mut ply = String::new();
    let n_vertices = 2 * (segments + 1);
    let _ = writeln!(
        ply,
        "ply\nformat ascii 1.0\nelement vertex {n_vertices}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face {}\nproperty list uchar int vertex_indices\nend_header",
        2 * segments
    );
    for i in 0..=segments {
        let phi = c.arc * (i as f32 / segments as f32 - 0.5);
        let n = phi.cos() * c.facing + phi.sin() * side;
        for s in [0.0, c.height] {
            let p = c.center + s * c.axis + c.radius * n;
            let _ = writeln!(ply, "{} {} {} {} {} {}", p.x, p.y, p.z, n.x, n.y, n.z);
        }
    }
    for i in 0..segments {
        let (a, b, c2, d) = (2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1);
        // Seen from outside, going around counter-clockwise about the axis, then up.
        let _ = writeln!(ply, "3 {a} {b} {c2}");
        let _ = writeln!(ply, "3 {a} {c2} {d}");
    }
    ply
}

/// A sphere as an ASCII PLY of `segments` × `segments / 2` latitude–longitude quads with exact
/// outward normals, counter-clockwise seen from outside (its front, as fppm's sphere).
pub(crate) fn sphere_ply(s: &scene::Sphere, segments: usize) -> String {
    let rings = (segments / 2).max(2);
    let mut ply = String::new();
    let _ = writeln!(
        ply,
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face {}\nproperty list uchar int vertex_indices\nend_header",
        (rings + 1) * (segments + 1),
        2 * rings * segments
    );
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..=segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            let p = s.center + s.radius * n;
            let _ = writeln!(ply, "{} {} {} {} {} {}", p.x, p.y, p.z, n.x, n.y, n.z);
        }
    }
    let row = segments + 1;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b) = (i * row + j, i * row + j + 1);
            let (c, d) = (a + row, b + row);
            // From the north pole (+y) down, φ turning from +x towards +z: (a, b, d) and
            // (a, d, c) turn counter-clockwise seen from outside.
            let _ = writeln!(ply, "3 {a} {b} {d}");
            let _ = writeln!(ply, "3 {a} {d} {c}");
        }
    }
    ply
}
