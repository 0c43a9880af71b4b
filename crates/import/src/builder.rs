//! What the importers of other renderers' formats (Mitsuba 3 XML, pbrt-v4) share: a builder
//! that gathers world-space geometry, materials and lights, indexed meshes with their
//! transforms, the primitive shapes both formats define, and the stand-ins for what fppm
//! cannot render yet (textures where fppm cannot use an image, environment lights). Each stand-in is one small function so
//! that it can be replaced by the real thing later.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use glam::{Mat3, Mat4, Vec2, Vec3};

use super::{LoadOptions, SceneParts, finish, is_degenerate};
use crate::error::LoadError;
use scene::{
    Camera, Cylinder, Film, Light, LoadNotes, Material, RenderDefaults, Rgb, SceneDescription,
    Sphere, Triangle,
};

/// Grey that stands in for a texture that cannot be read (or is procedural).
pub(crate) const TEXTURE_STANDIN_GREY: f32 = 0.5;

/// Segments of the polygon that stands in for a disk (and of the circles of a tessellated
/// cylinder or sphere).
pub(crate) const DISK_SEGMENTS: u32 = 64;

/// Largest image (in pixels) whose mean is computed for a texture stand-in; bigger images get
/// the grey stand-in rather than a long decode.
const MAX_TEXTURE_PIXELS: u64 = 64 << 20;

/// An indexed triangle mesh in its own object space.
#[derive(Clone, Debug, Default)]
pub(crate) struct IndexedMesh {
    pub(crate) positions: Vec<Vec3>,
    pub(crate) normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates in fppm's convention (v = 0 at the image's top row, see
    /// [`scene::texture`]): Mitsuba's own uv as read (its bitmaps put v = 0 at the top), pbrt's
    /// with v flipped by [`IndexedMesh::flip_v`].
    pub(crate) uvs: Option<Vec<Vec2>>,
    pub(crate) indices: Vec<[u32; 3]>,
}

impl IndexedMesh {
    /// Checks that every index is in range; `Err` names the first bad face.
    pub(crate) fn check_indices(&self) -> Result<(), String> {
        let n = self.positions.len();
        for (i, face) in self.indices.iter().enumerate() {
            if let Some(bad) = face.iter().find(|&&v| v as usize >= n) {
                return Err(format!(
                    "face {i} refers to vertex {bad}, but there are only {n} vertices"
                ));
            }
        }
        if let Some(normals) = &self.normals
            && normals.len() != n
        {
            return Err(format!("{} normals for {n} vertices", normals.len()));
        }
        if let Some(uvs) = &self.uvs {
            if uvs.len() != n {
                return Err(format!(
                    "{} texture coordinates for {n} vertices",
                    uvs.len()
                ));
            }
            if let Some(uv) = uvs.iter().find(|uv| !uv.is_finite()) {
                return Err(format!("non-finite texture coordinate {uv}"));
            }
        }
        if let Some(p) = self.positions.iter().find(|p| !p.is_finite()) {
            return Err(format!("non-finite vertex position {p}"));
        }
        Ok(())
    }

    /// Smooth vertex normals, each the angle-weighted mean of the normals of the faces around
    /// the vertex (what Mitsuba computes for a mesh that has none).
    pub(crate) fn compute_vertex_normals(&mut self) {
        let mut normals = vec![Vec3::ZERO; self.positions.len()];
        for face in &self.indices {
            let p = face.map(|i| self.positions[i as usize]);
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            let Some(n) = n.try_normalize() else {
                continue;
            };
            for k in 0..3 {
                let a = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
                let b = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
                let angle = a.dot(b).clamp(-1.0, 1.0).acos();
                normals[face[k] as usize] += n * angle;
            }
        }
        self.normals = Some(normals.into_iter().map(Vec3::normalize_or_zero).collect());
    }

    /// Mitsuba's `rectangle`: [−1, 1]² in the z = 0 plane, front face +z, with Mitsuba's
    /// texture coordinates uv = ((x + 1)/2, (y + 1)/2) (`src/shapes/rectangle.cpp`, its vertex
    /// records), which its bitmaps read with v = 0 at the image's top row, as fppm does.
    pub(crate) fn rectangle() -> Self {
        Self {
            positions: vec![
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(-1.0, 1.0, 0.0),
            ],
            normals: None,
            uvs: Some(vec![
                Vec2::new(0.0, 0.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(0.0, 1.0),
            ]),
            indices: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    /// Flips every texture coordinate's v (v → 1 − v): from a format whose v = 0 is the
    /// image's bottom row (pbrt) to fppm's convention.
    pub(crate) fn flip_v(&mut self) {
        if let Some(uvs) = &mut self.uvs {
            for uv in uvs {
                uv.y = 1.0 - uv.y;
            }
        }
    }

    /// Mitsuba's `cube`: [−1, 1]³, front faces outside.
    pub(crate) fn cube() -> Self {
        let mut mesh = Self::default();
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let mut n = Vec3::ZERO;
                n[axis] = sign;
                let u = Vec3::new(n.y.abs(), n.z.abs(), n.x.abs());
                let v = n.cross(u);
                let base = mesh.positions.len() as u32;
                for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    mesh.positions.push(n + a * u + b * v);
                }
                mesh.indices.push([base, base + 1, base + 2]);
                mesh.indices.push([base, base + 2, base + 3]);
            }
        }
        mesh
    }

    /// A unit disk in the z = 0 plane (front face +z) as a fan of [`DISK_SEGMENTS`] triangles.
    pub(crate) fn disk() -> Self {
        let mut mesh = Self {
            positions: vec![Vec3::ZERO],
            ..Self::default()
        };
        for i in 0..DISK_SEGMENTS {
            let phi = std::f32::consts::TAU * i as f32 / DISK_SEGMENTS as f32;
            mesh.positions.push(Vec3::new(phi.cos(), phi.sin(), 0.0));
            let next = (i + 1) % DISK_SEGMENTS;
            mesh.indices.push([0, i + 1, next + 1]);
        }
        mesh
    }

    /// Reverses every face (front becomes back) and every normal.
    pub(crate) fn flip(&mut self) {
        for f in &mut self.indices {
            f.swap(1, 2);
        }
        if let Some(normals) = &mut self.normals {
            for n in normals {
                *n = -*n;
            }
        }
    }
}

/// Gathers a scene from an importer, in world space.
#[derive(Default)]
pub(crate) struct Builder {
    pub(crate) materials: Vec<Material>,
    pub(crate) triangles: Vec<Triangle>,
    pub(crate) spheres: Vec<Sphere>,
    pub(crate) cylinders: Vec<Cylinder>,
    pub(crate) lights: Vec<Light>,
    warnings: Vec<String>,
    seen_warnings: HashSet<String>,
    /// Identical materials share one index.
    material_index: HashMap<String, u32>,
    degenerate_triangles: usize,
    degenerate_materials: HashSet<u32>,
    /// Emitters that were skipped (environment lights), for the no-emitter error.
    pub(crate) skipped_emitters: Vec<String>,
    /// The environment light (the first the file defines).
    pub(crate) environment: Option<scene::Environment>,
    /// Participating media and the shapes that bound them.
    pub(crate) media: scene::Media,
}

impl Builder {
    /// Records a warning once (repeats of the same text are dropped).
    pub(crate) fn warn(&mut self, message: impl Into<String>) {
        let message = message.into();
        if self.seen_warnings.insert(message.clone()) {
            self.warnings.push(message);
        }
    }

    /// Adds a material, or returns the index of an identical one added before.
    pub(crate) fn material(&mut self, material: Material) -> u32 {
        let key = format!("{material:?}");
        if let Some(&i) = self.material_index.get(&key) {
            return i;
        }
        let i = self.materials.len() as u32;
        self.materials.push(material);
        self.material_index.insert(key, i);
        i
    }

    /// Adds a mesh transformed by `to_world`. A transform that mirrors (negative determinant)
    /// swaps the winding so that the front face follows the transformed normals.
    ///
    /// Texture coordinates are kept only for a textured material, so that an untextured scene's
    /// description (and its checkpoint fingerprint) is what it was before importers read uv.
    pub(crate) fn mesh(&mut self, mesh: &IndexedMesh, to_world: Mat4, material: u32) {
        let textured = self
            .materials
            .get(material as usize)
            .is_some_and(|m| m.textures.is_some());
        let uvs = mesh.uvs.as_ref().filter(|_| textured);
        if to_world == Mat4::IDENTITY {
            // Keep the file's numbers bit for bit (no renormalised normals).
            for face in &mesh.indices {
                let positions = face.map(|i| mesh.positions[i as usize]);
                let n = mesh
                    .normals
                    .as_ref()
                    .map(|ns| {
                        face.map(|i| {
                            let v = ns[i as usize];
                            if v.is_normalized() {
                                v
                            } else {
                                v.normalize_or_zero()
                            }
                        })
                    })
                    .filter(|n| n.iter().all(|v| *v != Vec3::ZERO));
                let uv = uvs.map(|uvs| face.map(|i| uvs[i as usize]));
                self.triangle(positions, n, uv, material);
            }
            return;
        }
        let normal_matrix = Mat3::from_mat4(to_world).inverse().transpose();
        let flip = to_world.determinant() < 0.0;
        let world: Vec<Vec3> = mesh
            .positions
            .iter()
            .map(|&p| to_world.transform_point3(p))
            .collect();
        let normals: Option<Vec<Vec3>> = mesh.normals.as_ref().map(|ns| {
            ns.iter()
                .map(|&n| (normal_matrix * n).normalize_or_zero())
                .collect()
        });
        for face in &mesh.indices {
            let mut f = *face;
            if flip {
                f.swap(1, 2);
            }
            let positions = f.map(|i| world[i as usize]);
            let n = normals
                .as_ref()
                .map(|ns| f.map(|i| ns[i as usize]))
                .filter(|n| n.iter().all(|v| *v != Vec3::ZERO));
            let uv = uvs.map(|uvs| f.map(|i| uvs[i as usize]));
            self.triangle(positions, n, uv, material);
        }
    }

    /// Adds one world-space triangle, or counts it if degenerate.
    pub(crate) fn triangle(
        &mut self,
        positions: [Vec3; 3],
        normals: Option<[Vec3; 3]>,
        uv: Option<[Vec2; 3]>,
        material: u32,
    ) {
        if is_degenerate(positions) {
            self.degenerate_triangles += 1;
            self.degenerate_materials.insert(material);
            return;
        }
        self.triangles.push(Triangle {
            positions,
            normals,
            material,
            uv,
            tangents: None,
        });
    }

    /// Adds a sphere of radius `radius` at the origin of `to_world`. A transform that scales
    /// unevenly keeps the sphere round (mean scale), with a warning naming `what`.
    pub(crate) fn sphere(
        &mut self,
        center: Vec3,
        radius: f32,
        to_world: Mat4,
        material: u32,
        what: &str,
    ) {
        let m = Mat3::from_mat4(to_world);
        let scales = Vec3::new(m.x_axis.length(), m.y_axis.length(), m.z_axis.length());
        if (scales.max_element() - scales.min_element()) > 1e-4 * scales.max_element() {
            self.warn(format!(
                "{what}: a transform that scales unevenly ({scales}) would make an ellipsoid; \
                 fppm keeps a sphere with the mean scale"
            ));
        }
        let scale = (scales.x + scales.y + scales.z) / 3.0;
        self.spheres.push(Sphere {
            center: to_world.transform_point3(center),
            radius: radius * scale,
            material,
        });
    }

    /// Ends the import: the final checks of every loader, after a clear error if the only
    /// emitters were skipped ones.
    pub(crate) fn finish(
        self,
        path: &Path,
        camera: Option<Camera>,
        film: Film,
        render: RenderDefaults,
        options: &LoadOptions,
    ) -> Result<SceneDescription, LoadError> {
        let has_area = self
            .materials
            .iter()
            .any(|m| m.emission.max_element() > 0.0);
        if options.require_emitter
            && !has_area
            && self.lights.is_empty()
            && self.environment.is_none()
            && !self.skipped_emitters.is_empty()
        {
            return Err(LoadError::NoSupportedEmitter {
                path: path.to_path_buf(),
                skipped: self.skipped_emitters.join(", "),
            });
        }
        let parts = SceneParts {
            camera,
            film,
            materials: self.materials,
            triangles: self.triangles,
            spheres: self.spheres,
            cylinders: self.cylinders,
            lights: self.lights,
            environment: self.environment,
            media: self.media,
            render,
            notes: LoadNotes {
                degenerate_triangles: self.degenerate_triangles,
                camera_framed: false,
                warnings: self.warnings,
            },
            degenerate_materials: self.degenerate_materials,
        };
        finish(path, parts, options)
    }
}

/// The constant colour that stands in for an image texture: the mean of its pixels in linear
/// RGB (8-bit images are sRGB-encoded and decoded first), or [`TEXTURE_STANDIN_GREY`] when the
/// image cannot be decoded cheaply. The second value says which, for the warning.
pub(crate) fn image_texture_standin(path: &Path) -> Result<(Rgb, &'static str), LoadError> {
    let bytes = super::read_bytes(path)?;
    let Ok(reader) = image::ImageReader::new(std::io::Cursor::new(&bytes)).with_guessed_format()
    else {
        return Ok((Rgb::splat(TEXTURE_STANDIN_GREY), "a grey"));
    };
    let Ok((w, h)) = reader.into_dimensions() else {
        return Ok((Rgb::splat(TEXTURE_STANDIN_GREY), "a grey"));
    };
    if u64::from(w) * u64::from(h) > MAX_TEXTURE_PIXELS {
        return Ok((Rgb::splat(TEXTURE_STANDIN_GREY), "a grey"));
    }
    let Ok(img) = image::load_from_memory(&bytes) else {
        return Ok((Rgb::splat(TEXTURE_STANDIN_GREY), "a grey"));
    };
    let rgb = img.to_rgb8();
    let lut: Vec<f64> = (0..256).map(|v| srgb_to_linear(v as f64 / 255.0)).collect();
    let mut sum = glam::DVec3::ZERO;
    for p in rgb.pixels() {
        sum += glam::DVec3::new(lut[p[0] as usize], lut[p[1] as usize], lut[p[2] as usize]);
    }
    let n = (rgb.width() as f64 * rgb.height() as f64).max(1.0);
    Ok(((sum / n).as_vec3(), "its mean colour"))
}

/// The sRGB transfer function, decoded.
fn srgb_to_linear(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Sets the scene's environment light; a second one is dropped with a warning (fppm renders
/// one environment).
pub(crate) fn set_environment(builder: &mut Builder, element: &str, env: scene::Environment) {
    if builder.environment.is_some() {
        builder.warn(format!(
            "{element}: a second environment light is ignored (fppm renders one)"
        ));
    } else {
        builder.environment = Some(env);
    }
}

/// The rotation of an affine transform whose linear part is a rotation times a uniform scale;
/// `None` for anything else (a mirror, a shear, a non-uniform scale).
pub(crate) fn rotation_part(m: glam::DMat4) -> Option<glam::Mat3> {
    let linear = glam::DMat3::from_mat4(m);
    let scale = linear.determinant().cbrt();
    if !(scale.is_finite() && scale > 0.0) {
        return None;
    }
    let r = linear * (1.0 / scale);
    let off = (r.transpose() * r - glam::DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |a, e| a.max(e.abs()));
    (off < 1e-4).then(|| r.as_mat3())
}

/// The stand-in for an environment light fppm cannot render (Mitsuba `sunsky`, pbrt
/// `infinite` with an image): nothing, and a warning; the element is remembered for the
/// no-emitter error.
pub(crate) fn environment_light_standin(builder: &mut Builder, element: &str) {
    builder.warn(format!(
        "{element}: environment lights are not supported yet; the scene is rendered without it"
    ));
    builder.skipped_emitters.push(element.to_owned());
}

/// An open cylinder between `p0` and `p1` of `radius`, transformed; analytic when the transform
/// keeps circles round, else tessellated.
pub(crate) fn cylinder(
    builder: &mut Builder,
    p0: Vec3,
    p1: Vec3,
    radius: f32,
    to_world: Mat4,
    material: u32,
    emissive: bool,
) {
    let axis = (p1 - p0).normalize_or(Vec3::Z);
    let u = axis.any_orthonormal_vector();
    let v = axis.cross(u);
    let w0 = to_world.transform_point3(p0);
    let w1 = to_world.transform_point3(p1);
    let wu = to_world.transform_vector3(u * radius);
    let wv = to_world.transform_vector3(v * radius);
    let round = (wu.length() - wv.length()).abs() < 1e-4 * wu.length()
        && wu.dot(wv).abs() < 1e-4 * wu.length_squared()
        && wu.dot(w1 - w0).abs() < 1e-4 * wu.length() * (w1 - w0).length();
    if round && !emissive {
        let height = (w1 - w0).length();
        builder.cylinders.push(Cylinder {
            center: w0,
            axis: (w1 - w0) / height,
            radius: wu.length(),
            height,
            arc: std::f32::consts::TAU,
            facing: wu.normalize(),
            material,
        });
        return;
    }
    // Tessellated: a ring of quads with smooth normals, front face outside.
    let mut mesh = IndexedMesh::default();
    let mut normals = Vec::new();
    for i in 0..DISK_SEGMENTS {
        let phi = std::f32::consts::TAU * i as f32 / DISK_SEGMENTS as f32;
        let r = u * phi.cos() + v * phi.sin();
        mesh.positions.push(p0 + r * radius);
        mesh.positions.push(p1 + r * radius);
        normals.push(r);
        normals.push(r);
        let j = (i + 1) % DISK_SEGMENTS;
        let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * j, 2 * j + 1);
        mesh.indices.push([a, c, d]);
        mesh.indices.push([a, d, b]);
    }
    mesh.normals = Some(normals);
    builder.mesh(&mesh, to_world, material);
}
