//! glTF 2.0 (`.gltf` with `.bin` files or data URIs, and `.glb`) through the gltf crate.
//!
//! The default scene (or else scene 0) is walked from its root nodes, composing world matrices.
//! Mapping (scene-format.md, "glTF 2.0 mapping"), with these decisions:
//! - materials: transmission > 0 → dielectric (ior from `KHR_materials_ior`, default 1.5);
//!   metallic ≥ 0.5 ([`scene::texture::METALLIC_THRESHOLD`]) with roughness < 0.01 → mirror with the base
//!   colour; metallic ≥ 0.5 otherwise → glossy with α = roughness² and no diffuse base;
//!   else diffuse with the base colour ([`scene::texture::MetallicRoughness::kind`]), per texel under a metallic-roughness
//!   texture; textures as `gltf_material.rs` says.
//!   Emission = emissive factor × emissive strength. A primitive without a material gets
//!   the glTF default material (white, metallic 1, roughness 1, so glossy with α = 1);
//! - the camera is the perspective camera with the lowest index that a node of the scene
//!   uses (its first such node); it looks down the node's −Z with the node's +Y up; its
//!   focus distance is the depth of the scene's bounding-box centre (1 if that is behind it);
//! - `KHR_lights_punctual` intensities are taken as radiometric (cd → W/sr, lux → W/m²) and
//!   multiplied by the colour; spot outer cone → `cone_angle`, inner → `falloff_start`;
//! - triangle strips and fans are converted to triangles; points and lines are skipped with
//!   a warning; primitives without positions are skipped with a warning;
//! - missing normals give flat shading; a node transform with negative determinant swaps
//!   the winding so that front faces stay front faces;
//! - `TANGENT` is kept under materials with a normal map (the map's frame, see
//!   [`scene::Triangle::tangents`]), carried by the node's matrix with w turned around by a
//!   mirroring one; without it the normal map uses the triangle's own frame;
//! - images are files beside the glTF file, base64 `data:` URIs or buffer views (GLB).

use std::path::Path;

use glam::{Mat3, Mat4, Vec2, Vec3};
use gltf::khr_lights_punctual::Kind;
use gltf::mesh::Mode;

use super::{MeshData, read_bytes};
use crate::error::{LoadError, gltf_error};
use crate::gltf_document::{
    INDICES_RULE, NORMAL_RULE, POSITION_RULE, TANGENT_RULE, TEXCOORD_RULE, layout,
};
use crate::gltf_material::{Textures, default_material, material};
use crate::image_file::TextureCache;
use scene::{Camera, Light};

/// Deepest node hierarchy accepted (guards against cyclic node graphs).
const MAX_DEPTH: usize = 1024;

/// Loads a glTF or GLB file.
pub(crate) fn load_gltf(path: &Path) -> Result<MeshData, LoadError> {
    let bytes = read_bytes(path)?;
    let gltf = super::gltf_document::parse(path, &bytes)?;
    let buffers = super::gltf_document::import_buffers(path, &gltf.document, gltf.blob)?;
    let doc = &gltf.document;

    let mut data = MeshData::default();
    let mut textures = Textures {
        path,
        dir: path.parent(),
        buffers: &buffers,
        cache: TextureCache::default(),
        warnings: Vec::new(),
    };
    let mut uv_sets = Vec::new();
    for (i, m) in doc.materials().enumerate() {
        let (converted, uv_set) = material(&m, i, &mut textures)?;
        data.materials.push(converted);
        uv_sets.push(uv_set);
    }
    data.warnings.append(&mut textures.warnings);

    let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) else {
        data.warnings.push("the file has no scene".to_owned());
        return Ok(data);
    };

    let mut walker = Walker {
        path,
        buffers: &buffers,
        uv_sets,
        data,
        default_material: None,
        camera: None,
        skipped_primitives: 0,
    };
    let mut stack: Vec<(gltf::Node<'_>, Mat4, usize)> =
        scene.nodes().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    stack.reverse();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > MAX_DEPTH {
            return Err(gltf_error(
                path,
                format!("node hierarchy deeper than {MAX_DEPTH} levels (cyclic?)"),
            ));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        walker.node(&node, world)?;
        let children: Vec<_> = node.children().collect();
        for child in children.into_iter().rev() {
            stack.push((child, world, depth + 1));
        }
    }
    let mut data = walker.data;
    if walker.skipped_primitives > 0 {
        data.warnings.push(format!(
            "{} point/line or position-less primitive(s) skipped",
            walker.skipped_primitives
        ));
    }
    data.camera = walker.camera.map(|(_, mut camera, aspect)| {
        // Focus on the scene's centre (depth along the view), for a later thin lens.
        if let Some((lo, hi)) = scene::primitive_bounds(&data.triangles, &[], &[]) {
            let forward = camera.look_at - camera.position;
            let depth = (0.5 * (lo + hi) - camera.position).dot(forward);
            if depth.is_finite() && depth > 0.0 {
                camera.focus_distance = depth;
            }
        }
        (camera, aspect)
    });
    Ok(data)
}

struct Walker<'a> {
    path: &'a Path,
    buffers: &'a [gltf::buffer::Data],
    /// Per material, the texture-coordinate set its textures read.
    uv_sets: Vec<u32>,
    data: MeshData,
    default_material: Option<u32>,
    /// (camera index, camera, aspect ratio).
    camera: Option<(usize, Camera, Option<f32>)>,
    skipped_primitives: usize,
}

impl Walker<'_> {
    fn node(&mut self, node: &gltf::Node<'_>, world: Mat4) -> Result<(), LoadError> {
        if !world.is_finite() {
            return Err(gltf_error(
                self.path,
                format!("node {} has a non-finite transform", node.index()),
            ));
        }
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                self.primitive(&prim, world)?;
            }
        }
        if let Some(cam) = node.camera()
            && let gltf::camera::Projection::Perspective(p) = cam.projection()
            && self
                .camera
                .as_ref()
                .is_none_or(|(i, _, _)| cam.index() < *i)
        {
            let yfov = p.yfov();
            if !(yfov.is_finite() && yfov > 0.0 && yfov < std::f32::consts::PI) {
                return Err(gltf_error(
                    self.path,
                    format!("camera {} has yfov {yfov}, outside (0, pi)", cam.index()),
                ));
            }
            let position = world.transform_point3(Vec3::ZERO);
            let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
            let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
            if forward == Vec3::ZERO || up == Vec3::ZERO {
                return Err(gltf_error(
                    self.path,
                    format!("camera node {} has a degenerate transform", node.index()),
                ));
            }
            let camera = Camera {
                position,
                look_at: position + forward,
                up,
                fov_y: yfov,
                aperture_radius: 0.0,
                focus_distance: 1.0,
            };
            self.camera = Some((cam.index(), camera, p.aspect_ratio()));
        }
        if let Some(light) = node.light() {
            let colour = Vec3::from(light.color()) * light.intensity();
            let position = world.transform_point3(Vec3::ZERO);
            // `+ Vec3::ZERO` turns -0.0 into +0.0 (see crates.md, G1).
            let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero() + Vec3::ZERO;
            let needs_direction = !matches!(light.kind(), Kind::Point);
            if needs_direction && direction == Vec3::ZERO {
                return Err(gltf_error(
                    self.path,
                    format!("light node {} has a degenerate transform", node.index()),
                ));
            }
            self.data.lights.push(match light.kind() {
                Kind::Point => Light::Point {
                    position,
                    intensity: colour,
                },
                Kind::Directional => Light::Directional {
                    direction,
                    irradiance: colour,
                },
                Kind::Spot {
                    inner_cone_angle,
                    outer_cone_angle,
                } => Light::Spot {
                    position,
                    direction,
                    intensity: colour,
                    cone_angle: outer_cone_angle,
                    falloff_start: inner_cone_angle.min(outer_cone_angle),
                },
            });
        }
        Ok(())
    }

    /// Checks the type and layout of the accessors the loader reads against what glTF 2.0
    /// allows. The gltf crate's validation does not, and its readers assume it: a `VEC2`
    /// position or a stride shorter than an item fails a debug assertion (`accessor/util.rs`),
    /// `FLOAT` indices reach an `unreachable!`, a count of 0 underflows.
    fn check_accessor_types(
        &self,
        prim: &gltf::Primitive<'_>,
        uv_set: u32,
    ) -> Result<(), LoadError> {
        let checks = [
            (prim.get(&gltf::Semantic::Positions), POSITION_RULE),
            (prim.get(&gltf::Semantic::Normals), NORMAL_RULE),
            (prim.get(&gltf::Semantic::Tangents), TANGENT_RULE),
            (prim.indices(), INDICES_RULE),
            (prim.get(&gltf::Semantic::TexCoords(uv_set)), TEXCOORD_RULE),
        ];
        for (accessor, rule) in checks {
            let Some(accessor) = accessor else {
                continue;
            };
            let (dimensions, data_type) = (accessor.dimensions(), accessor.data_type());
            if dimensions != rule.dimensions
                || !rule.types.contains(&data_type)
                || (accessor.normalized() && !rule.normalized)
            {
                return Err(gltf_error(
                    self.path,
                    format!(
                        "accessor {} ({}) is {dimensions:?} of {data_type:?}{}; glTF 2.0 requires {:?} of {:?}",
                        accessor.index(),
                        rule.what,
                        if accessor.normalized() {
                            " (normalized)"
                        } else {
                            ""
                        },
                        rule.dimensions,
                        rule.types,
                    ),
                ));
            }
            layout(&accessor).map_err(|problem| {
                gltf_error(
                    self.path,
                    format!("accessor {} ({}): {problem}", accessor.index(), rule.what),
                )
            })?;
        }
        Ok(())
    }

    fn primitive(&mut self, prim: &gltf::Primitive<'_>, world: Mat4) -> Result<(), LoadError> {
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            self.skipped_primitives += 1;
            return Ok(());
        }
        // The texture-coordinate set the primitive's material reads (the default material's
        // is 0).
        let uv_set = prim
            .material()
            .index()
            .and_then(|i| self.uv_sets.get(i))
            .copied()
            .unwrap_or(0);
        self.check_accessor_types(prim, uv_set)?;
        let reader = prim.reader(|b| self.buffers.get(b.index()).map(|d| &d.0[..]));
        let Some(positions) = reader.read_positions() else {
            if let Some(accessor) = prim.get(&gltf::Semantic::Positions) {
                // The attribute exists but its data cannot be read (buffer too short…).
                return Err(gltf_error(
                    self.path,
                    format!(
                        "cannot read positions of accessor {} (its buffer is too short?)",
                        accessor.index()
                    ),
                ));
            }
            self.skipped_primitives += 1;
            return Ok(());
        };
        let positions: Vec<Vec3> = positions.map(Vec3::from).collect();
        if let Some(bad) = positions.iter().find(|p| !p.is_finite()) {
            return Err(LoadError::NonFiniteVertex {
                path: self.path.to_path_buf(),
                line: None,
                what: if bad.is_nan() { "nan" } else { "infinite" },
            });
        }
        let normals: Option<Vec<Vec3>> = reader
            .read_normals()
            .map(|n| n.map(Vec3::from).collect())
            .filter(|n: &Vec<Vec3>| n.len() == positions.len());
        let indices: Vec<u32> = match (reader.read_indices(), prim.indices()) {
            (Some(i), _) => i.into_u32().collect(),
            (None, None) => (0..positions.len() as u32).collect(),
            (None, Some(accessor)) => {
                return Err(gltf_error(
                    self.path,
                    format!(
                        "cannot read indices of accessor {} (its buffer is too short?)",
                        accessor.index()
                    ),
                ));
            }
        };
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(gltf_error(
                self.path,
                format!(
                    "mesh primitive index {bad} is out of range ({} vertices)",
                    positions.len()
                ),
            ));
        }
        let triangles: Vec<[u32; 3]> = match mode {
            Mode::TriangleStrip => (2..indices.len())
                .map(|i| {
                    if i % 2 == 0 {
                        [indices[i - 2], indices[i - 1], indices[i]]
                    } else {
                        [indices[i - 1], indices[i - 2], indices[i]]
                    }
                })
                .collect(),
            Mode::TriangleFan => (2..indices.len())
                .map(|i| [indices[0], indices[i - 1], indices[i]])
                .collect(),
            _ => indices
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
        };
        let material = match prim.material().index() {
            Some(i) if i < self.data.materials.len() => i as u32,
            _ => *self.default_material.get_or_insert_with(|| {
                self.data.materials.push(default_material());
                (self.data.materials.len() - 1) as u32
            }),
        };
        let uvs: Option<Vec<Vec2>> = reader
            .read_tex_coords(uv_set)
            .map(|tc| tc.into_f32().map(Vec2::from).collect())
            .filter(|tc: &Vec<Vec2>| {
                tc.len() == positions.len() && tc.iter().all(|v| v.is_finite())
            });
        let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
        let flip = world.determinant() < 0.0;
        let world_positions: Vec<Vec3> = positions
            .iter()
            .map(|&p| world.transform_point3(p))
            .collect();
        // Tangents only matter to a normal map: read (or generated) only under one, so that
        // other triangles stay as they were. Per triangle corner, in the file's frame: the
        // file's TANGENT, else MikkTSpace's from the positions, normals and texture
        // coordinates (what glTF 2.0 asks for when a file has none, and what the tools that
        // bake normal maps use); without normals or texture coordinates the normal map falls
        // back on the triangle's own frame.
        let normal_mapped = self
            .data
            .materials
            .get(material as usize)
            .and_then(|m| m.textures.as_deref())
            .is_some_and(|t| t.normal.is_some());
        let corner_tangents: Option<Vec<[[f32; 4]; 3]>> = if !normal_mapped {
            None
        } else if let Some(tangents) = reader.read_tangents() {
            let tangents: Vec<[f32; 4]> = tangents.collect();
            (tangents.len() == positions.len()).then(|| {
                triangles
                    .iter()
                    .map(|t| t.map(|i| tangents[i as usize]))
                    .collect()
            })
        } else {
            match (&normals, &uvs) {
                (Some(normals), Some(uvs)) => {
                    Some(mikktspace_tangents(&triangles, &positions, normals, uvs))
                }
                _ => None,
            }
        };
        let world_normals: Option<Vec<Vec3>> = normals.map(|n| {
            n.iter()
                .map(|&v| (normal_matrix * v).normalize_or_zero())
                .collect()
        });
        for (k, mut t) in triangles.into_iter().enumerate() {
            // A tangent is a direction in the surface, carried by the node's matrix; a
            // mirroring matrix turns N × T around, so w changes sign (and the corners swap
            // with the positions). A tangent that vanishes or is not finite leaves its
            // triangle the triangle's own frame.
            let tangents = corner_tangents.as_ref().and_then(|corners| {
                let signed =
                    corners[k].map(|[x, y, z, w]| [x, y, z, if w < 0.0 { -1.0 } else { 1.0 }]);
                super::transform_tangents(signed, world, flip)
            });
            if flip {
                t.swap(1, 2);
            }
            let p = t.map(|i| world_positions[i as usize]);
            let n = world_normals.as_ref().map(|n| t.map(|i| n[i as usize]));
            let uv = uvs.as_ref().map(|uv| t.map(|i| uv[i as usize]));
            self.data.push_triangle(p, n, uv, tangents, material);
        }
        Ok(())
    }
}

/// MikkTSpace tangents (x, y, z, w) per triangle corner of the mesh `triangles` with per-vertex
/// `positions`, `normals` and texture coordinates `uvs` (glTF's, v downwards).
///
/// MikkTSpace gets v upwards (1 − v, as Blender gives it and as normal maps are baked): its
/// tangent follows ∂p/∂u and its sign makes w·(N × T) follow ∂p/∂v upwards, the frame that
/// glTF's TANGENT and the renderer's normal maps use (green up the image). A corner
/// MikkTSpace gives nothing (a degenerate triangle without neighbours) gets a zero tangent,
/// which leaves its triangle the triangle's own frame.
fn mikktspace_tangents(
    triangles: &[[u32; 3]],
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[Vec2],
) -> Vec<[[f32; 4]; 3]> {
    struct Mesh<'a> {
        triangles: &'a [[u32; 3]],
        positions: &'a [Vec3],
        normals: &'a [Vec3],
        uvs: &'a [Vec2],
        out: Vec<[[f32; 4]; 3]>,
    }
    impl bevy_mikktspace::Geometry for Mesh<'_> {
        fn num_faces(&self) -> usize {
            self.triangles.len()
        }
        fn num_vertices_of_face(&self, _face: usize) -> usize {
            3
        }
        fn position(&self, face: usize, vert: usize) -> [f32; 3] {
            self.positions[self.triangles[face][vert] as usize].to_array()
        }
        fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
            self.normals[self.triangles[face][vert] as usize].to_array()
        }
        fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
            let uv = self.uvs[self.triangles[face][vert] as usize];
            [uv.x, 1.0 - uv.y]
        }
        fn set_tangent(
            &mut self,
            tangent_space: Option<bevy_mikktspace::TangentSpace>,
            face: usize,
            vert: usize,
        ) {
            self.out[face][vert] = tangent_space.map_or([0.0; 4], |t| t.tangent_encoded());
        }
    }
    let mut mesh = Mesh {
        triangles,
        positions,
        normals,
        uvs,
        out: vec![[[0.0; 4]; 3]; triangles.len()],
    };
    // The error type has no values: generation cannot fail.
    if bevy_mikktspace::generate_tangents(&mut mesh).is_err() {
        return vec![[[0.0; 4]; 3]; triangles.len()];
    }
    mesh.out
}
