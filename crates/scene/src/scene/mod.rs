//! The renderable scene: description + BVH + camera + light sampler.

use std::path::PathBuf;

use glam::{Vec2, Vec3, Vec3A};

use crate::{
    Aabb, Bsdf, CameraModel, Hit, LightSample, LightSampler, Material, Primitive, Ray, Rgb,
    SceneDescription,
    bvh::{Accel, RawHit},
};

#[cfg(test)]
mod cylinder_tests;
mod shading;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod texture_tests;

/// Relative floating-point error bound γₙ = n·ε/(1 − n·ε) of pbrt (ε = half an ulp of 1).
const fn gamma(n: f32) -> f32 {
    let e = f32::EPSILON * 0.5;
    n * e / (1.0 - n * e)
}

/// Why a [`SceneDescription`] cannot be rendered.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// Neither geometry nor lights.
    #[error("scene `{}` has no geometry and no lights", path.display())]
    Empty {
        /// The scene file.
        path: PathBuf,
    },
    /// No light source or emitter has positive power.
    #[error("scene `{}` has no light: every light and emitter has zero power or zero area", path.display())]
    NoLight {
        /// The scene file.
        path: PathBuf,
    },
    /// The camera cannot form an image.
    #[error("scene `{}` has a degenerate camera (look_at equal to position, up parallel to the view, fov_y outside (0, 180) degrees, empty film or a thin lens without focus distance)", path.display())]
    Camera {
        /// The scene file.
        path: PathBuf,
    },
    /// A shape refers to a material that does not exist.
    #[error("scene `{}`: {what} refers to material {index} but there are {count} materials", path.display())]
    MaterialIndex {
        /// The scene file.
        path: PathBuf,
        /// Which shape, e.g. `triangle 12`.
        what: String,
        /// The bad index.
        index: u32,
        /// Number of materials.
        count: usize,
    },
    /// A value is NaN, infinite or out of its range.
    #[error("scene `{}`: {what}", path.display())]
    Invalid {
        /// The scene file.
        path: PathBuf,
        /// What is wrong, e.g. `sphere 3 radius (-1)`.
        what: String,
    },
}

/// Per-triangle data that the hit shading needs, in description order.
#[derive(Clone, Copy, Debug)]
struct TriangleExtra {
    /// Unit geometric normal of the front (counter-clockwise) side.
    front_normal: Vec3A,
    /// `(p0 + p1 + p2) / 3`, the point [`Scene::triangle_hit`] nudges hits toward.
    centroid: Vec3A,
    /// Per-axis minimum of the vertices, the lower corner of the clamp in `triangle_hit`.
    lower: Vec3A,
    /// Per-axis maximum of the vertices.
    upper: Vec3A,
    /// The focusing curvature (see [`Hit::curvature`]) seen from the front and from the back.
    curvature: [f32; 2],
}

/// A scene ready for ray queries, camera rays, BSDFs and light sampling.
#[derive(Clone, Debug)]
pub struct Scene {
    description: SceneDescription,
    accel: Accel,
    extra: Vec<TriangleExtra>,
    camera: CameraModel,
    lights: LightSampler,
    bounds: Aabb,
    /// Whether some triangle's material has a cut-out (alpha test).
    cutouts: bool,
    /// Whether some hit needs texture work before it is returned (a cut-out, a normal map or
    /// a metallic-roughness texture).
    textured_hits: bool,
    /// Per material, the index its first variant has (see [`crate::texture::MetallicRoughness`]:
    /// the materials a hit on a metallic-roughness texture becomes, numbered after the
    /// description's); empty if no material has one.
    variant_first: Vec<Option<u32>>,
    /// The variants, in index order.
    variants: Vec<Material>,
    /// Which shape's media each primitive bounds; `None` in a scene without media.
    medium_map: Option<crate::medium::MediumMap>,
    /// Whether the scene has media or interface materials ([`SceneDescription::has_media`]).
    has_media: bool,
}

impl Scene {
    /// Validates the description and builds the BVH and the light sampler.
    ///
    /// Zero-area triangles are kept in the description but never hit.
    ///
    /// # Errors
    /// [`SceneError`] when the scene is empty, has no light with positive power, has a degenerate
    /// camera, a material index out of range, or a non-finite or out-of-range value (including a
    /// cylinder whose axis and facing are not perpendicular unit vectors, or whose material emits).
    pub fn new(description: SceneDescription) -> Result<Self, SceneError> {
        let source = || description.source.clone();
        if description.triangles.is_empty()
            && description.spheres.is_empty()
            && description.cylinders.is_empty()
            && description.lights.is_empty()
        {
            return Err(SceneError::Empty { path: source() });
        }
        let camera = CameraModel::new(&description.camera, &description.film)
            .ok_or_else(|| SceneError::Camera { path: source() })?;
        crate::validate::description(&description).map_err(|e| e.in_scene(&description.source))?;
        let invalid = |what: String| SceneError::Invalid {
            path: source(),
            what,
        };
        let mut bounds = Aabb::EMPTY;
        for t in &description.triangles {
            for p in t.positions {
                bounds = bounds.include(p);
            }
        }
        for s in &description.spheres {
            bounds = bounds
                .include(s.center - Vec3::splat(s.radius))
                .include(s.center + Vec3::splat(s.radius));
        }
        for c in &description.cylinders {
            bounds = bounds.union(c.bounds());
        }
        if bounds.is_empty() {
            // Only lights: bound their positions so that directional lights still have a disc.
            for l in &description.lights {
                match *l {
                    crate::Light::Point { position, .. } | crate::Light::Spot { position, .. } => {
                        bounds = bounds.include(position);
                    }
                    crate::Light::Directional { .. } => {}
                }
            }
            if bounds.is_empty() {
                bounds = Aabb::EMPTY.include(Vec3::ZERO);
            }
        }
        let extra = description.triangles.iter().map(triangle_extra).collect();
        let emitters = crate::light::powered(crate::light::Emitters::collect(&description, bounds))
            .map_err(|e| e.in_scene(&description.source))?;
        let lights = LightSampler::new(emitters);
        let primitives =
            description.triangles.len() + description.spheres.len() + description.cylinders.len();
        if primitives >= crate::bvh::MAX_PRIMITIVES {
            return Err(invalid(format!(
                "{primitives} primitives (at most {} per scene)",
                crate::bvh::MAX_PRIMITIVES - 1
            )));
        }
        let mut accel = Accel::build(
            &description.triangles,
            &description.spheres,
            &description.cylinders,
        );
        let cutout_materials: Vec<bool> = description
            .materials
            .iter()
            .map(|m| shading::has_cutout(m.textures.as_deref()))
            .collect();
        let cutouts = description
            .triangles
            .iter()
            .any(|t| cutout_materials[t.material as usize]);
        if cutouts {
            accel.set_cutouts(|i| {
                cutout_materials[description.triangles[i as usize].material as usize]
            });
        }
        let normal_mapped = description
            .materials
            .iter()
            .any(|m| m.textures.as_ref().is_some_and(|t| t.normal.is_some()));
        let (variant_first, variants) = shading::material_variants(&description.materials);
        let has_media = description.has_media();
        let medium_map = has_media.then(|| {
            crate::medium::MediumMap::new(
                &description.media,
                description.triangles.len(),
                description.spheres.len(),
            )
        });
        Ok(Self {
            description,
            accel,
            extra,
            camera,
            lights,
            bounds,
            cutouts,
            textured_hits: cutouts || normal_mapped || !variants.is_empty(),
            variant_first,
            variants,
            medium_map,
            has_media,
        })
    }

    /// Whether the scene has participating media or interface materials: only an integrator
    /// that handles media renders it right.
    #[inline]
    pub fn has_media(&self) -> bool {
        self.has_media
    }

    /// The scene's media, the shapes that bound them and the camera's medium.
    #[inline]
    pub fn media(&self) -> &crate::Media {
        &self.description.media
    }

    /// The media on either side of the shape of `hit`, if crossing it changes the medium.
    #[inline]
    pub fn shape_media(&self, hit: &Hit) -> Option<&crate::ShapeMedia> {
        let i = self.medium_map.as_ref()?.entry(hit.primitive)?;
        self.description.media.shapes.get(i)
    }

    /// Whether the material at `hit` is an interface, which does not scatter
    /// ([`crate::MaterialKind::Interface`]).
    #[inline]
    pub fn is_interface(&self, hit: &Hit) -> bool {
        self.material(hit.material)
            .is_some_and(|m| matches!(m.kind, crate::MaterialKind::Interface(_)))
    }

    /// The description the scene was built from.
    pub fn description(&self) -> &SceneDescription {
        &self.description
    }

    /// Every material.
    pub fn materials(&self) -> &[Material] {
        &self.description.materials
    }

    /// The material with index `idx` (as in [`Hit::material`]); `None` if out of range.
    /// Indices past the description's materials are the variants that hits on a
    /// metallic-roughness texture take (see [`crate::texture::MetallicRoughness`]).
    #[inline]
    pub fn material(&self, idx: u32) -> Option<&Material> {
        let materials = &self.description.materials;
        materials.get(idx as usize).or_else(|| {
            self.variants
                .get((idx as usize).checked_sub(materials.len())?)
        })
    }

    /// Bounding box of all geometry (of the light positions if there is no geometry).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The camera.
    pub fn camera(&self) -> &CameraModel {
        &self.camera
    }

    /// The lights, including emissive triangles and spheres.
    pub fn lights(&self) -> &LightSampler {
        &self.lights
    }

    /// Number of primitives in the BVH (non-degenerate triangles, spheres and cylinders).
    pub fn primitive_count(&self) -> usize {
        self.accel.len()
    }

    /// The closest hit with 0 < t < `ray.t_max`, or `None`.
    ///
    /// Always inlined, with the triangle hit, so that callers get the `Hit` in registers
    /// rather than through two copies in memory; the traversal itself stays a call
    /// ([`Scene::intersect_inlined`] compiles it in too).
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let raw = if self.textured_hits {
            self.intersect_raw_textured(ray)?
        } else {
            self.accel.intersect(ray)?
        };
        Some(self.finish_hit(ray, raw))
    }

    /// Whether some hit needs texture work before it is returned: a cut-out, a normal map or a
    /// metallic-roughness texture somewhere in the scene. What the `TEXTURED_HITS` of
    /// [`Scene::intersect_inlined`] must be.
    #[doc(hidden)]
    #[inline]
    pub fn textured_hits(&self) -> bool {
        self.textured_hits
    }

    /// [`Scene::intersect`], with the BVH traversal compiled into the caller instead of called:
    /// the same answer, for the photon tracer's loop, which does little else, so that the call
    /// and the vector registers saved around it do not weigh on its short rays. A code
    /// generation choice of that one loop rather than a query of its own, hence hidden from
    /// the documentation; every caller gets its own copy of the traversal.
    ///
    /// `TEXTURED_HITS` must be [`Scene::textured_hits`] (debug builds assert it): the caller
    /// compiles its loop once per value and picks the copy once, so that the loop of an
    /// untextured scene holds no trace of the textured case: neither the test nor the join of
    /// the two cases (docs/performance.md).
    /// With `false` in a scene that has textured hits, their cut-outs, normal maps and
    /// metallic-roughness textures would be ignored.
    #[doc(hidden)]
    #[inline(always)]
    pub fn intersect_inlined<const TEXTURED_HITS: bool>(&self, ray: &Ray) -> Option<Hit> {
        debug_assert_eq!(TEXTURED_HITS, self.textured_hits);
        if TEXTURED_HITS {
            let raw = self.intersect_raw_textured(ray)?;
            Some(self.finish_hit(ray, raw))
        } else {
            let raw = self.accel.intersect_inlined(ray)?;
            Some(self.hit(ray, raw))
        }
    }

    /// The closest hit in a scene with cut-outs or normal maps: the closest one the alpha
    /// tests let through. Out of line, returning the small `RawHit`, so that the queries of
    /// untextured scenes compile without the textured case.
    #[inline(never)]
    fn intersect_raw_textured(&self, ray: &Ray) -> Option<RawHit> {
        if self.cutouts {
            self.accel
                .intersect_cutout(ray, &|i, b1, b2| self.covered(ray, i, b1, b2))
        } else {
            self.accel.intersect(ray)
        }
    }

    /// The hit of `raw`, with its normal mapped and its metallic-roughness variant chosen in
    /// a scene that has either.
    ///
    /// The textured case is a call that takes the hit by value and returns only what it
    /// changes, so that the untextured case inlined beside it builds its hit in registers
    /// rather than in memory (docs/performance.md).
    #[inline(always)]
    fn finish_hit(&self, ray: &Ray, raw: RawHit) -> Hit {
        let mut hit = self.hit(ray, raw);
        if self.textured_hits {
            let (shading_normal, material) = self.textured_surface(hit);
            hit.shading_normal = shading_normal;
            hit.material = material;
        }
        hit
    }

    /// The shading normal and material of `hit` after its material's normal map and
    /// metallic-roughness texture.
    #[inline(never)]
    fn textured_surface(&self, mut hit: Hit) -> (Vec3, u32) {
        self.apply_normal_map(&mut hit);
        self.apply_metallic_roughness(&mut hit);
        (hit.shading_normal, hit.material)
    }

    #[inline(always)]
    fn hit(&self, ray: &Ray, raw: RawHit) -> Hit {
        match raw {
            RawHit::Triangle { index, t, b1, b2 } => self.triangle_hit(ray, index, t, b1, b2),
            RawHit::Sphere { index, t } => self.sphere_hit(ray, index, t),
            RawHit::Cylinder { index, t } => self.cylinder_hit(ray, index, t),
        }
    }

    /// Whether anything is hit with 0 < t < `ray.t_max` (a shadow-ray query, faster than [`Scene::intersect`]).
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if self.cutouts {
            return self
                .accel
                .occluded_cutout(ray, &|i, b1, b2| self.covered(ray, i, b1, b2));
        }
        self.accel.occluded(ray)
    }

    /// Whether the segment from the surface point of `from` to `target` is free of occluders
    /// (the surface at `target` itself does not count).
    #[inline]
    pub fn visible(&self, from: &Hit, target: Vec3) -> bool {
        !self.occluded(&from.spawn_ray_to(target))
    }

    /// Whether the light sample `sample`, drawn for the point of `from`, is unoccluded.
    #[inline]
    pub fn light_visible(&self, from: &Hit, sample: &LightSample) -> bool {
        if sample.distance.is_finite() {
            self.visible(from, from.position + sample.incoming * sample.distance)
        } else {
            !self.occluded(&from.spawn_ray(sample.incoming))
        }
    }

    /// The BSDF at `hit` (see [`Bsdf::new`]), with the material's colour texture; `None` if the
    /// hit's material index is out of range.
    #[inline]
    pub fn bsdf(&self, hit: &Hit) -> Option<Bsdf> {
        self.material(hit.material)
            .map(|m| self.material_bsdf(m, hit))
    }

    /// Radiance emitted at `hit` back along the ray: the material's emission (times its
    /// emission texture) on a front face, else zero.
    #[inline]
    pub fn emitted(&self, hit: &Hit) -> Rgb {
        match self.material(hit.material) {
            Some(m) if hit.front_face => {
                if m.textures.is_none() {
                    m.emission
                } else {
                    self.textured_emission(m, hit)
                }
            }
            _ => Rgb::ZERO,
        }
    }

    /// The arithmetic is on `Vec3A` (one SSE instruction per vector operation instead of three
    /// scalar ones): the same IEEE operations in the same order as on `Vec3`, lane by lane, so the
    /// same bits (dot products and lengths sum x, y, z in that order either way), in fewer
    /// instructions (docs/performance.md).
    #[inline(always)]
    fn triangle_hit(&self, ray: &Ray, index: u32, t: f32, b1: f32, b2: f32) -> Hit {
        let tri = &self.description.triangles[index as usize];
        let extra = &self.extra[index as usize];
        let b0 = 1.0 - b1 - b2;
        let [p0, p1, p2] = tri.positions.map(Vec3A::from);
        let position_error = gamma(7.0) * ((b0 * p0).abs() + (b1 * p1).abs() + (b2 * p2).abs());
        // Nudge the point toward the centroid by the size of its error bound, so that a hit on an edge
        // does not sit on the plane of an adjacent wall, from where a spawned ray could slip through the
        // corner. Then clamp it to the triangle's bounding box, so that points on axis-aligned walls
        // stay exactly on them.
        let mut position = b0 * p0 + b1 * p1 + b2 * p2;
        let to_centroid = extra.centroid - position;
        let len = to_centroid.length();
        if len > 0.0 {
            position += to_centroid * (position_error.length().min(0.5 * len) / len);
        }
        let position = position.clamp(extra.lower, extra.upper);
        let front_face = extra.front_normal.dot(Vec3A::from(ray.direction)) < 0.0;
        let sign = if front_face { 1.0 } else { -1.0 };
        let geometric_normal = sign * extra.front_normal;
        let shading_normal = match tri.normals {
            Some(normals) => {
                let [n0, n1, n2] = normals.map(Vec3A::from);
                // The geometric normal where the interpolated one has no direction. Not
                // `normalize_or_zero` and a comparison with zero, which is the same but compiles
                // to a branch on n.x = 0 first, which is data dependent (axis-aligned walls
                // against curved meshes) and often mispredicted.
                let n = (b0 * n0 + b1 * n1 + b2 * n2).normalize_or(geometric_normal);
                if n.dot(geometric_normal) < 0.0 { -n } else { n }
            }
            None => geometric_normal,
        };
        Hit {
            t,
            position: position.into(),
            position_error: position_error.into(),
            geometric_normal: geometric_normal.into(),
            shading_normal: shading_normal.into(),
            front_face,
            material: tri.material,
            curvature: extra.curvature[usize::from(!front_face)],
            primitive: Primitive::Triangle(index),
            uv: Vec2::new(b1, b2),
        }
    }

    /// Inlined, as [`Scene::cylinder_hit`] is, so that the hit of every kind of primitive is
    /// built in registers: called, their results arrive in memory, where the inlined triangle
    /// hit would be stored too and reloaded with wide loads that the stores just made cannot
    /// forward (docs/performance.md).
    #[inline(always)]
    fn sphere_hit(&self, ray: &Ray, index: u32, t: f32) -> Hit {
        let s = &self.description.spheres[index as usize];
        let outward = (ray.at(t) - s.center).normalize_or(Vec3::Z);
        // Reproject onto the surface, as pbrt does, which bounds the error by γ₅|p|.
        let position = s.center + s.radius * outward;
        let position_error = gamma(8.0) * (position.abs() + s.center.abs());
        let front_face = outward.dot(ray.direction) < 0.0;
        let (normal, curvature) = if front_face {
            (outward, -1.0 / s.radius)
        } else {
            (-outward, 1.0 / s.radius)
        };
        Hit {
            t,
            position,
            position_error,
            geometric_normal: normal,
            shading_normal: normal,
            front_face,
            material: s.material,
            curvature,
            primitive: Primitive::Sphere(index),
            // Computed from the position when a texture asks (`Scene::texture_uv`).
            uv: Vec2::ZERO,
        }
    }

    #[inline(always)]
    fn cylinder_hit(&self, ray: &Ray, index: u32, t: f32) -> Hit {
        let c = &self.description.cylinders[index as usize];
        let rel = ray.at(t) - c.center;
        let s = rel.dot(c.axis).clamp(0.0, c.height);
        let outward = (rel - rel.dot(c.axis) * c.axis).normalize_or(c.facing);
        // Reproject onto the surface, as for spheres. The bound covers the rounding of this sum and
        // of the intersection test's |f⊥|² − r² (whose error grows with the distance to the bottom
        // centre, at most the radius plus the height), so that an origin offset by it is on the
        // intended side of the surface.
        let position = c.center + s * c.axis + c.radius * outward;
        let position_error =
            gamma(16.0) * (position.abs() + c.center.abs() + Vec3::splat(c.radius + c.height));
        let front_face = outward.dot(ray.direction) < 0.0;
        // Principal curvatures 1/R around the axis and 0 along it: from outside (convex) the
        // larger is 0, from inside (concave) 1/R.
        let (normal, curvature) = if front_face {
            (outward, 0.0)
        } else {
            (-outward, 1.0 / c.radius)
        };
        let angle = outward
            .dot(c.axis.cross(c.facing))
            .atan2(outward.dot(c.facing));
        let u = ((angle + 0.5 * c.arc) / c.arc).clamp(0.0, 1.0);
        Hit {
            t,
            position,
            position_error,
            geometric_normal: normal,
            shading_normal: normal,
            front_face,
            material: c.material,
            curvature,
            primitive: Primitive::Cylinder(index),
            uv: Vec2::new(u, s / c.height),
        }
    }
}

/// What is wrong with a cylinder's numbers, if anything.
/// Front normal and front-side curvature of a triangle (see [`Hit::curvature`]).
fn triangle_extra(tri: &crate::Triangle) -> TriangleExtra {
    let [p0, p1, p2] = tri.positions;
    let front_normal = (p1 - p0).cross(p2 - p0).normalize_or_zero();
    // The normal curvature along each edge, −Δn·Δp/|Δp|² from the front side, lies between
    // the principal curvatures; the largest from each side stands for the most focusing one.
    let curvature = match tri.normals {
        Some(mut n) => {
            // Orient the vertex normals to the front side, as the shading normal is.
            if (n[0] + n[1] + n[2]).dot(front_normal) < 0.0 {
                n = n.map(|v| -v);
            }
            let (mut front, mut back) = (f32::NEG_INFINITY, f32::NEG_INFINITY);
            for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                let dp = tri.positions[b] - tri.positions[a];
                let dn = n[b] - n[a];
                let len2 = dp.length_squared();
                let k = if len2 > 0.0 { -dn.dot(dp) / len2 } else { 0.0 };
                let k = if k.is_finite() { k } else { 0.0 };
                front = front.max(k);
                back = back.max(-k);
            }
            [front, back]
        }
        None => [0.0, 0.0],
    };
    // The centroid and the bounds are computed by the same expressions `triangle_hit` would
    // evaluate per hit, so hoisting them here changes no bit.
    TriangleExtra {
        front_normal: front_normal.into(),
        curvature,
        centroid: ((p0 + p1 + p2) / 3.0).into(),
        lower: p0.min(p1).min(p2).into(),
        upper: p0.max(p1).max(p2).into(),
    }
}

/// [`Scene::intersect_inlined`] with the scene's own `TEXTURED_HITS`, as the photon tracer calls it.
#[cfg(test)]
fn intersect_inlined(scene: &Scene, ray: &Ray) -> Option<Hit> {
    if scene.textured_hits() {
        scene.intersect_inlined::<true>(ray)
    } else {
        scene.intersect_inlined::<false>(ray)
    }
}
