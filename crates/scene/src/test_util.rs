//! Helpers shared by the unit tests.

use glam::{Vec2, Vec3};

use crate::{
    Camera, Film, Light, LoadNotes, Material, MaterialKind, RenderDefaults, SceneDescription,
    Sphere, Triangle,
};

/// A small deterministic generator (PCG32).
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64) -> Self {
        let mut r = Rng(seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407));
        r.next_u32();
        r
    }

    pub(crate) fn next_u32(&mut self) -> u32 {
        let old = self.0;
        self.0 = old
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in [0, 1).
    pub(crate) fn f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    pub(crate) fn vec2(&mut self) -> Vec2 {
        Vec2::new(self.f32(), self.f32())
    }

    pub(crate) fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.f32(), self.f32(), self.f32()) * (hi - lo) + Vec3::splat(lo)
    }

    pub(crate) fn unit(&mut self) -> Vec3 {
        crate::sampling::uniform_sphere(self.vec2())
    }
}

pub(crate) fn diffuse(albedo: f32, emission: Vec3) -> Material {
    Material {
        name: "m".into(),
        kind: MaterialKind::Diffuse(crate::Diffuse {
            albedo: Vec3::splat(albedo),
        }),
        emission,
        textures: None,
        spectra: None,
    }
}

/// A description with a default camera, one diffuse and one emissive material (index 1).
pub(crate) fn description(
    triangles: Vec<Triangle>,
    spheres: Vec<Sphere>,
    lights: Vec<Light>,
) -> SceneDescription {
    SceneDescription {
        source: "test.toml".into(),
        camera: Camera {
            position: Vec3::new(0.0, 0.0, 10.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            fov_y: 0.7,
            aperture_radius: 0.0,
            focus_distance: 10.0,
        },
        film: Film {
            width: 32,
            height: 32,
        },
        materials: vec![diffuse(0.5, Vec3::ZERO), diffuse(0.0, Vec3::ONE)],
        environment: None,
        media: crate::Media::default(),
        triangles,
        spheres,
        cylinders: Vec::new(),
        lights,
        render: RenderDefaults::default(),
        notes: LoadNotes::default(),
    }
}

pub(crate) fn point_light(position: Vec3) -> Light {
    Light::Point {
        position,
        intensity: Vec3::ONE,
    }
}

pub(crate) fn tri(a: Vec3, b: Vec3, c: Vec3, material: u32) -> Triangle {
    Triangle {
        positions: [a, b, c],
        normals: None,
        material,
        uv: None,
        tangents: None,
    }
}

/// Two triangles of the parallelogram corner, corner+e1, corner+e1+e2, corner+e2; front = e1 × e2.
pub(crate) fn quad(corner: Vec3, e1: Vec3, e2: Vec3, material: u32) -> [Triangle; 2] {
    [
        tri(corner, corner + e1, corner + e1 + e2, material),
        tri(corner, corner + e1 + e2, corner + e2, material),
    ]
}

/// An axis-aligned closed box [lo, hi] with fronts facing inward (like a Cornell box).
pub(crate) fn closed_box(lo: Vec3, hi: Vec3, material: u32) -> Vec<Triangle> {
    let d = hi - lo;
    let (x, y, z) = (
        Vec3::new(d.x, 0.0, 0.0),
        Vec3::new(0.0, d.y, 0.0),
        Vec3::new(0.0, 0.0, d.z),
    );
    let mut t = Vec::new();
    t.extend(quad(lo, z, x, material)); // floor, front +y
    t.extend(quad(lo + y, x, z, material)); // ceiling, front -y
    t.extend(quad(lo, y, z, material)); // x = lo, front +x
    t.extend(quad(lo + x, z, y, material)); // x = hi, front -x
    t.extend(quad(lo, x, y, material)); // z = lo, front +z
    t.extend(quad(lo + z, y, x, material)); // z = hi, front -z
    t
}

/// Pearson χ² of `observed` against `expected` counts, pooling the bins that expect fewer than
/// five (as pbrt's and Mitsuba's χ² tests do); returns (χ², degrees of freedom). Fails where 50
/// or more samples fell in a bin whose expectation is zero: `what` names the check.
#[track_caller]
pub(crate) fn pearson_chi_square(observed: &[f64], expected: &[f64], what: &str) -> (f64, usize) {
    let (mut chi2, mut dof, mut pooled_o, mut pooled_e) = (0.0, 0usize, 0.0, 0.0);
    for (o, e) in observed.iter().zip(expected) {
        if *e < 5.0 {
            pooled_o += o;
            pooled_e += e;
            assert!(
                *o < 50.0 || *e > 0.0,
                "{what}: {o} samples where the density is zero"
            );
        } else {
            chi2 += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pooled_e >= 5.0 {
        chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
        dof += 1;
    }
    (chi2, dof.saturating_sub(1))
}
