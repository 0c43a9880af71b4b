//! Loop subdivision for pbrt's `loopsubdiv` shape, with the rules pbrt-v4 uses
//! (`src/pbrt/util/loopsubdiv.cpp`): every level splits each triangle into four; an old
//! vertex moves to (1 − nβ)·p + β·Σ ring with β = 3/16 for valence 3 and 3/(8n) otherwise,
//! or to ¾·p + ⅛·(its two boundary neighbours) on a boundary; a new edge vertex is
//! ⅜·(ends) + ⅛·(the two opposite vertices), or the edge's midpoint on a boundary. After the
//! last level every vertex is pushed to its limit position: γ = 1 / (n + 3/(8β)) in the
//! interior, ⅗·p + ⅕·(boundary neighbours) on a boundary.
//!
//! pbrt also computes limit-surface tangents for shading normals; here the shading normals
//! are the angle-weighted vertex normals of the final mesh, which follow its winding.
//! An edge shared by more than two triangles (not a manifold) is treated as a boundary, and a
//! vertex with other than two boundary edges keeps its position (a corner).

use std::collections::BTreeMap;

use glam::Vec3;

use crate::builder::IndexedMesh;

/// Largest number of triangles a subdivision may produce.
pub(crate) const MAX_TRIANGLES: usize = 1 << 25;

#[derive(Clone, Copy)]
struct Edge {
    /// The vertex opposite the edge in its first two triangles.
    opposite: [u32; 2],
    faces: u32,
    /// Index of the edge's new vertex in the next level.
    new_vertex: u32,
}

/// One-ring information of each vertex.
struct Rings {
    sum: Vec<Vec3>,
    valence: Vec<u32>,
    boundary_sum: Vec<Vec3>,
    boundary_edges: Vec<u32>,
}

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

fn edges_of(faces: &[[u32; 3]]) -> BTreeMap<(u32, u32), Edge> {
    let mut edges: BTreeMap<(u32, u32), Edge> = BTreeMap::new();
    for f in faces {
        for k in 0..3 {
            let (a, b, c) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
            let e = edges.entry(key(a, b)).or_insert(Edge {
                opposite: [c, c],
                faces: 0,
                new_vertex: 0,
            });
            if e.faces < 2 {
                e.opposite[e.faces as usize] = c;
            }
            e.faces += 1;
        }
    }
    edges
}

fn rings(positions: &[Vec3], edges: &BTreeMap<(u32, u32), Edge>) -> Rings {
    let n = positions.len();
    let mut r = Rings {
        sum: vec![Vec3::ZERO; n],
        valence: vec![0; n],
        boundary_sum: vec![Vec3::ZERO; n],
        boundary_edges: vec![0; n],
    };
    for (&(a, b), e) in edges {
        let (a, b) = (a as usize, b as usize);
        r.sum[a] += positions[b];
        r.sum[b] += positions[a];
        r.valence[a] += 1;
        r.valence[b] += 1;
        if e.faces != 2 {
            r.boundary_sum[a] += positions[b];
            r.boundary_sum[b] += positions[a];
            r.boundary_edges[a] += 1;
            r.boundary_edges[b] += 1;
        }
    }
    r
}

fn beta(valence: u32) -> f32 {
    if valence == 3 {
        3.0 / 16.0
    } else {
        3.0 / (8.0 * valence as f32)
    }
}

/// Moves vertex `i` by the interior rule with weight `w`, or the boundary rule with `wb`.
fn smooth(r: &Rings, p: Vec3, i: usize, w: f32, wb: f32) -> Vec3 {
    match r.boundary_edges[i] {
        0 if r.valence[i] > 0 => (1.0 - r.valence[i] as f32 * w) * p + w * r.sum[i],
        2 => (1.0 - 2.0 * wb) * p + wb * r.boundary_sum[i],
        _ => p,
    }
}

/// Subdivides `levels` times and pushes the vertices to the limit surface. The caller checks
/// that `4^levels` times the triangle count stays below [`MAX_TRIANGLES`].
pub(crate) fn subdivide(positions: &[Vec3], faces: &[[u32; 3]], levels: u32) -> IndexedMesh {
    let mut p = positions.to_vec();
    let mut f = faces.to_vec();
    for _ in 0..levels {
        let mut edges = edges_of(&f);
        let r = rings(&p, &edges);
        // Even (old) vertices.
        let mut next: Vec<Vec3> = (0..p.len())
            .map(|i| {
                let w = beta(r.valence[i]);
                smooth(&r, p[i], i, w, 1.0 / 8.0)
            })
            .collect();
        // Odd (edge) vertices, in a deterministic order.
        let mut keys: Vec<(u32, u32)> = edges.keys().copied().collect();
        keys.sort_unstable();
        for k in keys {
            let Some(e) = edges.get_mut(&k) else { continue };
            let (a, b) = (p[k.0 as usize], p[k.1 as usize]);
            let pos = if e.faces == 2 {
                0.375 * (a + b) + 0.125 * (p[e.opposite[0] as usize] + p[e.opposite[1] as usize])
            } else {
                0.5 * (a + b)
            };
            e.new_vertex = next.len() as u32;
            next.push(pos);
        }
        let mut children = Vec::with_capacity(f.len() * 4);
        for t in &f {
            let m = |a: u32, b: u32| edges[&key(a, b)].new_vertex;
            let (ab, bc, ca) = (m(t[0], t[1]), m(t[1], t[2]), m(t[2], t[0]));
            children.push([t[0], ab, ca]);
            children.push([ab, t[1], bc]);
            children.push([ca, bc, t[2]]);
            children.push([ab, bc, ca]);
        }
        p = next;
        f = children;
    }
    // Push to the limit surface.
    let edges = edges_of(&f);
    let r = rings(&p, &edges);
    let limit: Vec<Vec3> = (0..p.len())
        .map(|i| {
            let n = r.valence[i].max(1);
            let gamma = 1.0 / (n as f32 + 3.0 / (8.0 * beta(n)));
            smooth(&r, p[i], i, gamma, 1.0 / 5.0)
        })
        .collect();
    let mut mesh = IndexedMesh {
        positions: limit,
        normals: None,
        uvs: None,
        indices: f,
    };
    mesh.compute_vertex_normals();
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    fn octahedron() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p = vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        let f = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        (p, f)
    }

    #[test]
    fn subdivision_is_deterministic() {
        // The neighbour sums are taken in a fixed edge order: the same mesh gives the same bits
        // every time (a hash map's per-instance random order made the killeroo scenes render
        // differently from run to run).
        let (p, f) = octahedron();
        let p: Vec<Vec3> = p
            .iter()
            .enumerate()
            .map(|(i, v)| *v * (1.0 + 0.1 * i as f32) + Vec3::splat(0.013 * i as f32))
            .collect();
        let first = subdivide(&p, &f, 3);
        for _ in 0..8 {
            let again = subdivide(&p, &f, 3);
            assert_eq!(again.indices, first.indices);
            let bits = |m: &IndexedMesh| -> Vec<[u32; 3]> {
                m.positions
                    .iter()
                    .map(|v| v.to_array().map(f32::to_bits))
                    .collect()
            };
            assert_eq!(bits(&again), bits(&first));
        }
    }

    #[test]
    fn each_level_quadruples_the_triangles() {
        let (p, f) = octahedron();
        for levels in 0..4 {
            let mesh = subdivide(&p, &f, levels);
            assert_eq!(mesh.indices.len(), 8 * 4usize.pow(levels));
            mesh.check_indices().unwrap();
        }
    }

    #[test]
    fn octahedron_limit_is_symmetric_and_inside() {
        // Valence 4 everywhere, β = 3/32, γ = 1 / (4 + 3/(8β)) = 1/8; a vertex's ring sums to
        // zero, so it moves to (1 − 4γ)·p: radius 1/2.
        let (p, f) = octahedron();
        let mesh = subdivide(&p, &f, 0);
        for v in &mesh.positions {
            assert!((v.length() - 0.5).abs() < 1e-6, "{v}");
        }
        // Normals point outwards (the faces wind counter-clockwise seen from outside).
        let normals = mesh.normals.unwrap();
        for (v, n) in mesh.positions.iter().zip(&normals) {
            assert!(v.dot(*n) > 0.99 * v.length());
        }
    }

    #[test]
    fn flat_patch_stays_flat_and_inside() {
        // Two triangles of a square in z = 0: every vertex is on the boundary.
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let f = vec![[0, 1, 2], [0, 2, 3]];
        let mesh = subdivide(&p, &f, 2);
        assert!(mesh.positions.iter().all(|v| v.z == 0.0));
        // Every rule is an affine combination of neighbours with weights in [0, 1]: the patch
        // shrinks into its convex hull (the corners are rounded off, as in pbrt).
        assert!(
            mesh.positions
                .iter()
                .all(|v| (0.0..=1.0).contains(&v.x) && (0.0..=1.0).contains(&v.y))
        );
    }
}
