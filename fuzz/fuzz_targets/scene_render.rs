//! Structure-aware: an arbitrary small `SceneDescription` (raw floats, so NaN, infinities,
//! huge and tiny values, degenerate triangles, zero-area or zero-power lights, bad material
//! indices) → `Scene::new` → one or two tiny passes of one method. What `Scene::new` accepts
//! must render without panicking or hanging.
#![no_main]

use arbitrary::{Arbitrary, Unstructured};
use glam::Vec3;
use libfuzzer_sys::fuzz_target;
use ppm::{FrequencyFloor, MergePolicy, Method, RenderParams, Renderer};
use scene::{
    Camera, Cylinder, Film, Light, LoadNotes, Material, MaterialKind, RenderDefaults,
    SceneDescription, Sphere, Triangle,
};

/// A float as the fuzzer picks it: mostly a small multiple of 1/16 (so that many scenes are
/// valid and reach the integrators), sometimes a special value (zero, ±0, tiny, huge, NaN,
/// infinities), sometimes any bit pattern.
#[derive(Clone, Copy, Debug)]
struct F(f32);

impl<'a> Arbitrary<'a> for F {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        const SPECIAL: [f32; 10] = [
            0.0,
            -0.0,
            1e-30,
            1e-7,
            1e7,
            1e30,
            f32::MAX,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        Ok(F(match u.int_in_range(0u8..=9)? {
            0 => f32::from_bits(u.arbitrary()?),
            1 => *u.choose(&SPECIAL)?,
            _ => f32::from(u.arbitrary::<i8>()?) / 16.0,
        }))
    }
}

#[derive(Arbitrary, Debug)]
struct V([F; 3]);

impl V {
    fn get(&self) -> Vec3 {
        Vec3::new(self.0[0].0, self.0[1].0, self.0[2].0)
    }
}

#[derive(Arbitrary, Debug)]
enum Kind {
    Diffuse(V),
    Mirror(V),
    Dielectric(F),
    Glossy(V, F, V),
    Conductor(V, V, V, F),
}

#[derive(Arbitrary, Debug)]
struct Mat {
    kind: Kind,
    emission: Option<V>,
}

#[derive(Arbitrary, Debug)]
enum Shape {
    Triangle([V; 3], Option<[V; 3]>, u8),
    Sphere(V, F, u8),
    Cylinder(V, V, F, F, F, V, u8),
}

#[derive(Arbitrary, Debug)]
enum Lamp {
    Point(V, V),
    Spot(V, V, V, F, F),
    Directional(V, V),
}

#[derive(Arbitrary, Debug)]
struct Input {
    camera: (V, V, V, F, F, F),
    film: (u8, u8),
    materials: Vec<Mat>,
    shapes: Vec<Shape>,
    lights: Vec<Lamp>,
    method: u8,
    photons: u8,
    max_depth: u8,
    two_passes: bool,
    seed: u64,
    alpha: u8,
    freq_fraction: u8,
    kernel_k: u8,
    freq_grow: u8,
    freq_pilot: u8,
    options: u8,
    /// Sometimes one parameter gets any value at all: `Renderer::new` must refuse it or run.
    wild: Option<(u8, f64)>,
}

fn material(m: &Mat, i: usize) -> Material {
    let kind = match &m.kind {
        Kind::Diffuse(a) => MaterialKind::Diffuse(scene::Diffuse { albedo: a.get() }),
        Kind::Mirror(r) => MaterialKind::Mirror(scene::Mirror {
            reflectance: r.get(),
        }),
        Kind::Dielectric(ior) => MaterialKind::Dielectric(scene::Dielectric { ior: ior.0 }),
        Kind::Glossy(r, roughness, d) => MaterialKind::Glossy(scene::Glossy {
            reflectance: r.get(),
            roughness: roughness.0,
            diffuse: d.get(),
        }),
        Kind::Conductor(eta, k, tint, roughness) => MaterialKind::Conductor(scene::Conductor {
            eta: eta.get(),
            k: k.get(),
            specular_reflectance: tint.get(),
            roughness: roughness.0,
        }),
    };
    Material {
        name: format!("m{i}"),
        kind,
        emission: m.emission.as_ref().map_or(Vec3::ZERO, V::get),
        textures: None,
        spectra: None,
    }
}

fn description(input: &Input) -> SceneDescription {
    let (position, look_at, up, fov_y, aperture_radius, focus_distance) = &input.camera;
    let mut d = SceneDescription {
        source: "/fuzz/scene".into(),
        camera: Camera {
            position: position.get(),
            look_at: look_at.get(),
            up: up.get(),
            fov_y: fov_y.0 * 8.0,
            aperture_radius: aperture_radius.0,
            focus_distance: focus_distance.0,
        },
        film: Film {
            width: u32::from(input.film.0 % 8) + 1,
            height: u32::from(input.film.1 % 8) + 1,
        },
        materials: input
            .materials
            .iter()
            .take(4)
            .enumerate()
            .map(|(i, m)| material(m, i))
            .collect(),
        triangles: Vec::new(),
        spheres: Vec::new(),
        cylinders: Vec::new(),
        lights: Vec::new(),
        environment: None,
        media: scene::Media::default(),
        render: RenderDefaults::default(),
        notes: LoadNotes::default(),
    };
    for shape in input.shapes.iter().take(12) {
        match shape {
            Shape::Triangle(p, n, m) => d.triangles.push(Triangle {
                positions: [p[0].get(), p[1].get(), p[2].get()],
                normals: n.as_ref().map(|n| [n[0].get(), n[1].get(), n[2].get()]),
                material: u32::from(*m % 5),
                uv: None,
                tangents: None,
            }),
            Shape::Sphere(c, r, m) => d.spheres.push(Sphere {
                center: c.get(),
                radius: r.0,
                material: u32::from(*m % 5),
            }),
            Shape::Cylinder(c, axis, radius, height, arc, facing, m) => {
                d.cylinders.push(Cylinder {
                    center: c.get(),
                    axis: axis.get(),
                    radius: radius.0,
                    height: height.0,
                    arc: arc.0,
                    facing: facing.get(),
                    material: u32::from(*m % 5),
                });
            }
        }
    }
    for lamp in input.lights.iter().take(3) {
        d.lights.push(match lamp {
            Lamp::Point(p, i) => Light::Point {
                position: p.get(),
                intensity: i.get(),
            },
            Lamp::Spot(p, dir, i, cone, falloff) => Light::Spot {
                position: p.get(),
                direction: dir.get(),
                intensity: i.get(),
                cone_angle: cone.0,
                falloff_start: falloff.0,
            },
            Lamp::Directional(dir, e) => Light::Directional {
                direction: dir.get(),
                irradiance: e.get(),
            },
        });
    }
    d
}

fn params(input: &Input) -> RenderParams {
    let mut p = RenderParams::preview();
    p.method = Method::ALL[usize::from(input.method) % Method::ALL.len()];
    p.budget.photons_per_pass = u32::from(input.photons % 64) + 1;
    p.budget.max_depth = u32::from(input.max_depth % 12);
    p.seed = input.seed;
    // Mostly in range, so that passes run; 0 is out of range for α and K.
    p.kernel.alpha = f64::from(input.alpha) / 255.0;
    p.frequency.fraction = f64::from(input.freq_fraction) / 255.0;
    p.frequency.kernel_k = f64::from(input.kernel_k) / 32.0;
    p.frequency.grow = 1.0 + f64::from(input.freq_grow) / 64.0;
    if let Some((which, value)) = input.wild {
        match which % 5 {
            0 => p.kernel.alpha = value,
            1 => p.frequency.fraction = value,
            2 => p.frequency.kernel_k = value,
            3 => p.frequency.grow = value,
            _ => p.frequency.hold_alpha = value,
        }
    }
    p.frequency.pilot = u32::from(input.freq_pilot % 4);
    p.frequency.merge = if input.options & 1 == 0 {
        MergePolicy::MinRadius
    } else {
        MergePolicy::PosterMax
    };
    p.frequency.floor = if input.options & 2 == 0 {
        FrequencyFloor::Keep
    } else {
        FrequencyFloor::Clamp
    };
    p.frequency.occlusion = input.options & 4 != 0;
    p.frequency.geometry = input.options & 8 != 0;
    p.connections.direct_lighting = input.options & 16 != 0;
    p.frequency.clear_cap = input.options & 32 != 0;
    p
}

fuzz_target!(|input: Input| {
    let Some(scene) = fppm_fuzz::build(description(&input)) else {
        return;
    };
    let Ok(mut renderer) = Renderer::new(scene, params(&input)) else {
        return;
    };
    renderer.iterate();
    if input.two_passes {
        renderer.iterate();
    }
    let _ = renderer.image();
});
