//! Triangulation of planar polygons that need not be convex.
//!
//! A polygon with more than three vertices is projected onto its best-fit plane, whose normal
//! is Newell's (the sum over edges of (yᵢ − yᵢ₊₁)(zᵢ + zᵢ₊₁), …: the area vector, so it
//! follows the polygon's winding). A constrained Delaunay triangulation (spade) of the
//! projected vertices with the polygon's edges as constraints then covers the convex hull;
//! the triangles whose centroid lies inside the polygon (even–odd rule) are kept, oriented
//! counter-clockwise in the plane, which is the polygon's own orientation in space.
//! Triangles and convex quads take a fast path.

use glam::{DVec2, DVec3, Vec3};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

/// Splits the polygon `points` (in order) into triangles of indices into `points`, wound like
/// the polygon. Degenerate input (fewer than three points, zero area, non-finite
/// coordinates) falls back to a triangle fan, whose degenerate triangles the caller drops.
pub(crate) fn triangulate(points: &[Vec3]) -> Vec<[usize; 3]> {
    let n = points.len();
    if n < 3 {
        return Vec::new();
    }
    if n == 3 {
        return vec![[0, 1, 2]];
    }
    let normal = newell_normal(points);
    if normal.length_squared() <= 0.0 || !normal.is_finite() {
        return fan(n);
    }
    if n == 4 && is_convex(points, normal) {
        return vec![[0, 1, 2], [0, 2, 3]];
    }
    constrained(points, normal).unwrap_or_else(|| fan(n))
}

/// Newell's normal: twice the vector area of the polygon.
pub(crate) fn newell_normal(points: &[Vec3]) -> DVec3 {
    let mut normal = DVec3::ZERO;
    for (i, p) in points.iter().enumerate() {
        let a = p.as_dvec3();
        let b = points[(i + 1) % points.len()].as_dvec3();
        normal += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    normal
}

fn fan(n: usize) -> Vec<[usize; 3]> {
    (1..n - 1).map(|i| [0, i, i + 1]).collect()
}

/// Every corner turns the same way as the normal.
fn is_convex(points: &[Vec3], normal: DVec3) -> bool {
    let n = points.len();
    (0..n).all(|i| {
        let a = points[i].as_dvec3();
        let b = points[(i + 1) % n].as_dvec3();
        let c = points[(i + 2) % n].as_dvec3();
        (b - a).cross(c - b).dot(normal) > 0.0
    })
}

fn constrained(points: &[Vec3], normal: DVec3) -> Option<Vec<[usize; 3]>> {
    let w = normal.normalize();
    let u = w.any_orthonormal_vector();
    let v = w.cross(u);
    let flat: Vec<DVec2> = points
        .iter()
        .map(|p| {
            let p = p.as_dvec3();
            DVec2::new(p.dot(u), p.dot(v))
        })
        .collect();

    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    let mut handles = Vec::with_capacity(points.len());
    // Map from spade's vertex index to the polygon's (first occurrence wins).
    let mut local = Vec::new();
    for (i, p) in flat.iter().enumerate() {
        let handle = cdt.insert(Point2::new(p.x, p.y)).ok()?;
        if handle.index() >= local.len() {
            local.resize(handle.index() + 1, usize::MAX);
        }
        if local[handle.index()] == usize::MAX {
            local[handle.index()] = i;
        }
        handles.push(handle);
    }
    for i in 0..handles.len() {
        let (a, b) = (handles[i], handles[(i + 1) % handles.len()]);
        if a != b {
            // An edge that crosses an earlier one (self-intersecting polygon) is not added;
            // the inside test below still decides which triangles are kept.
            let _ = cdt.try_add_constraint(a, b);
        }
    }

    let mut triangles = Vec::new();
    for face in cdt.inner_faces() {
        let [a, b, c] = face
            .vertices()
            .map(|vh| local.get(vh.fix().index()).copied());
        let (Some(a), Some(b), Some(c)) = (a, b, c) else {
            return None;
        };
        if a == usize::MAX || b == usize::MAX || c == usize::MAX {
            return None;
        }
        let (pa, pb, pc) = (flat[a], flat[b], flat[c]);
        let centroid = (pa + pb + pc) / 3.0;
        if !inside(&flat, centroid) {
            continue;
        }
        let signed = (pb - pa).perp_dot(pc - pa);
        if signed > 0.0 {
            triangles.push([a, b, c]);
        } else if signed < 0.0 {
            triangles.push([a, c, b]);
        }
    }
    Some(triangles)
}

/// Even–odd point-in-polygon test.
fn inside(polygon: &[DVec2], p: DVec2) -> bool {
    let mut inside = false;
    let n = polygon.len();
    for i in 0..n {
        let a = polygon[i];
        let b = polygon[(i + 1) % n];
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(points: &[Vec3], tris: &[[usize; 3]]) -> f32 {
        tris.iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| points[i]);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    #[test]
    fn concave_l_shape_keeps_area_and_orientation() {
        // An L in the z = 0 plane, counter-clockwise seen from +z; area 3.
        let pts: Vec<Vec3> = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]
        .iter()
        .map(|&(x, y)| Vec3::new(x, y, 0.0))
        .collect();
        let tris = triangulate(&pts);
        assert_eq!(tris.len(), 4);
        assert!((area(&pts, &tris) - 3.0).abs() < 1e-5);
        for t in &tris {
            let [a, b, c] = t.map(|i| pts[i]);
            assert!((b - a).cross(c - a).z > 0.0, "triangle {t:?} is flipped");
        }
    }

    #[test]
    fn concave_quad_is_split_at_the_reflex_corner() {
        // An arrowhead (dart) starting at a wing: the fan from vertex 0 would cover the
        // notch (total area 4.5 instead of 1.5).
        let pts = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 0.5, 0.0),
        ];
        let tris = triangulate(&pts);
        // Area of the dart: two triangles of 0.5 · 1.5 · 1 each.
        assert!((area(&pts, &tris) - 1.5).abs() < 1e-5, "{tris:?}");
    }
}
