//! Curved shapes as tessellated ASCII PLY meshes, for the peers' exports (Mitsuba and LuxCore
//! read them where they have no such analytic shape).

use std::fmt::Write as _;

use glam::Vec3;

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
