//! The positions and directions of `sample_emission` and the points of `sample_direct` follow
//! the densities (χ² over bins whose expectations integrate the densities), which integrate to
//! one over the emitter's surface, disc, hemisphere or sphere.

use std::f64::consts::PI as PI64;

use super::*;
use crate::Frame;
use crate::test_util::pearson_chi_square;

/// Pearson χ² of `observed` against `expected` counts, pooling the bins that expect fewer than
/// five; fails if it exceeds its mean by five standard deviations.
#[track_caller]
fn assert_chi_square(observed: &[f64], expected: &[f64], what: &str) {
    let (chi2, dof) = pearson_chi_square(observed, expected, what);
    let dof = dof as f64;
    assert!(dof >= 10.0, "{what}: only {dof} degrees of freedom");
    let limit = dof + 5.0 * (2.0 * dof).sqrt();
    assert!(chi2 < limit, "{what}: χ² {chi2:.1} with {dof} dof");
}

/// Bins of unit directions by (cos θ, φ) about `frame.n`, cos θ ∈ [`cos_min`, `cos_max`].
struct DirectionBins {
    frame: Frame,
    cos_min: f64,
    cos_max: f64,
    n_cos: usize,
    n_phi: usize,
}

impl DirectionBins {
    fn new(axis: Vec3, cos_min: f64) -> Self {
        Self {
            frame: Frame::from_normal(axis),
            cos_min,
            cos_max: 1.0,
            n_cos: 12,
            n_phi: 24,
        }
    }

    fn len(&self) -> usize {
        self.n_cos * self.n_phi
    }

    /// The bin of `w`; `None` outside the range of cos θ, but for rounding.
    fn index(&self, w: Vec3) -> Option<usize> {
        let l = self.frame.to_local(w).as_dvec3();
        let c = (l.z - self.cos_min) / (self.cos_max - self.cos_min);
        if !(-1e-4..=1.0 + 1e-4).contains(&c) {
            return None;
        }
        let c = c.clamp(0.0, 1.0);
        let phi = l.y.atan2(l.x).rem_euclid(2.0 * PI64);
        let i = ((c * self.n_cos as f64) as usize).min(self.n_cos - 1);
        let j = ((phi / (2.0 * PI64) * self.n_phi as f64) as usize).min(self.n_phi - 1);
        Some(i * self.n_phi + j)
    }

    /// ∫ `density` dω over each bin by the midpoint rule on `sub` × `sub` points per bin.
    fn integrals(&self, sub: usize, density: impl Fn(Vec3) -> f64) -> Vec<f64> {
        let d_cos = (self.cos_max - self.cos_min) / (self.n_cos * sub) as f64;
        let d_phi = 2.0 * PI64 / (self.n_phi * sub) as f64;
        let mut out = vec![0.0; self.len()];
        for i in 0..self.n_cos * sub {
            let cos = self.cos_min + (i as f64 + 0.5) * d_cos;
            let sin = (1.0 - cos * cos).max(0.0).sqrt();
            for j in 0..self.n_phi * sub {
                let phi = (j as f64 + 0.5) * d_phi;
                let local = glam::DVec3::new(sin * phi.cos(), sin * phi.sin(), cos);
                let w = self.frame.to_world(local.as_vec3()).normalize();
                out[(i / sub) * self.n_phi + j / sub] += density(w) * d_cos * d_phi;
            }
        }
        out
    }
}

/// Bins of points on the lamp quad by (s, t).
const QUAD_BINS: usize = 8;

fn quad_bin(p: Vec3) -> usize {
    let d = p - CORNER;
    let s = f64::from(d.dot(E1) / E1.length_squared());
    let t = f64::from(d.dot(E2) / E2.length_squared());
    let i = ((s * QUAD_BINS as f64) as usize).min(QUAD_BINS - 1);
    let j = ((t * QUAD_BINS as f64) as usize).min(QUAD_BINS - 1);
    i * QUAD_BINS + j
}

/// ∫ `density` dA over each bin of the lamp quad on 8 × 8 cells a bin, each looked up through
/// the hit of a ray from below (the lamp's front) at two points, (¼, ¾) and (¾, ¼) of the cell:
/// exact for a density constant on each of the quad's triangles, whose shared diagonal
/// (s = t) halves the cells it crosses.
fn quad_integrals(scene: &Scene, density: impl Fn(&crate::Hit) -> f64) -> Vec<f64> {
    let sub = 8;
    let n = QUAD_BINS * sub;
    let point = f64::from(E1.cross(E2).length()) / (2 * n * n) as f64;
    let mut out = vec![0.0; QUAD_BINS * QUAD_BINS];
    for i in 0..n {
        for j in 0..n {
            for (a, b) in [(0.25, 0.75), (0.75, 0.25)] {
                let (s, t) = ((i as f32 + a) / n as f32, (j as f32 + b) / n as f32);
                let p = CORNER + s * E1 + t * E2;
                let hit = hit_at(scene, p - Vec3::Y, p).expect("the lamp seen from below");
                out[(i / sub) * QUAD_BINS + j / sub] += density(&hit) * point;
            }
        }
    }
    out
}

/// Bins of points on a disc of radius `r` about `center` facing `axis` by (ρ²/r², φ).
fn disc_bin(center: Vec3, axis: Vec3, r: f32, p: Vec3) -> Option<usize> {
    let frame = Frame::from_normal(axis);
    let l = frame.to_local(p - center);
    let rho2 = f64::from((l.x * l.x + l.y * l.y) / (r * r));
    if l.z.abs() > 1e-3 * r || rho2 > 1.0 + 1e-5 {
        return None;
    }
    let phi = f64::from(l.y).atan2(f64::from(l.x)).rem_euclid(2.0 * PI64);
    let i = ((rho2 * 8.0) as usize).min(7);
    let j = ((phi / (2.0 * PI64) * 16.0) as usize).min(15);
    Some(i * 16 + j)
}

/// Counts of `N` emission samples of `scene` by `bin` (which must place every sample).
fn emission_histogram(
    scene: &Scene,
    n_bins: usize,
    seed: u64,
    mut bin: impl FnMut(&crate::EmissionSample, &EmissionPdf) -> Option<usize>,
) -> Vec<f64> {
    let mut observed = vec![0.0; n_bins];
    let mut rng = Rng::new(seed);
    for _ in 0..N {
        if let Some((s, pdf)) =
            scene
                .lights()
                .sample_emission_with_pdf(rng.f32(), rng.vec2(), rng.vec2())
        {
            let b = bin(&s, &pdf).unwrap_or_else(|| panic!("unbinned sample {s:?}"));
            observed[b] += 1.0;
        }
    }
    observed
}

fn scaled(integrals: &[f64]) -> Vec<f64> {
    integrals.iter().map(|i| i * f64::from(N)).collect()
}

#[track_caller]
fn assert_one(integrals: &[f64], tolerance: f64, what: &str) {
    let total: f64 = integrals.iter().sum();
    assert!((total - 1.0).abs() < tolerance, "{what}: ∫ = {total}");
}

/// Triangle emitters, plain and textured: the start points follow pick · position over the
/// quad, which integrates to one; the directions follow the direction density about the
/// normal, which integrates to one over the hemisphere.
#[test]
fn triangle_emission_follows_its_densities() {
    for (name, scene) in [
        ("quad", quad_scene()),
        ("textured quad", textured_quad_scene()),
    ] {
        let lights = scene.lights();
        let position = quad_integrals(&scene, |hit| {
            let pdf = lights
                .pdf_emission(hit, -Vec3::Y, (Vec3::ZERO, Vec3::ZERO))
                .unwrap();
            f64::from(pdf.pick * pdf.position)
        });
        assert_one(&position, 1e-5, name);
        let observed =
            emission_histogram(&scene, position.len(), 2, |s, _| Some(quad_bin(s.origin)));
        assert_chi_square(&observed, &scaled(&position), &format!("{name} positions"));

        let centre = CORNER + 0.3 * E1 + 0.6 * E2;
        let hit = hit_at(&scene, centre - Vec3::Y, centre).unwrap();
        let bins = DirectionBins::new(-Vec3::Y, 0.0);
        let direction = bins.integrals(4, |w| {
            f64::from(
                lights
                    .pdf_emission(&hit, w, (Vec3::ZERO, Vec3::ZERO))
                    .unwrap()
                    .direction,
            )
        });
        assert_one(&direction, 1e-5, name);
        let behind = DirectionBins::new(Vec3::Y, 0.0).integrals(2, |w| {
            f64::from(
                lights
                    .pdf_emission(&hit, w, (Vec3::ZERO, Vec3::ZERO))
                    .unwrap()
                    .direction,
            )
        });
        assert_eq!(behind.iter().sum::<f64>(), 0.0, "{name}");
        let observed = emission_histogram(&scene, bins.len(), 3, |s, _| bins.index(s.direction));
        assert_chi_square(
            &observed,
            &scaled(&direction),
            &format!("{name} directions"),
        );
        // The back of the lamp does not emit.
        let back = hit_at(&scene, centre + Vec3::Y, centre).unwrap();
        assert!(
            !back.front_face
                && lights
                    .pdf_emission(&back, Vec3::Y, (Vec3::ZERO, Vec3::ZERO))
                    .is_none()
        );
    }
}

/// The start of a photon on a sphere at (cos θ, φ) about +y from its centre.
fn sphere_hit(scene: &Scene, normal: Vec3) -> crate::Hit {
    let p = SPHERE_CENTER + SPHERE_RADIUS * normal;
    hit_at(scene, p + 0.5 * normal, p).expect("the sphere seen from outside")
}

/// Sphere emitters: the start points follow pick · position over the sphere, which integrates
/// to one; the directions, about each start's normal, follow the direction density.
#[test]
fn sphere_emission_follows_its_densities() {
    let scene = sphere_scene();
    let lights = scene.lights();
    let normals = DirectionBins::new(Vec3::Y, -1.0);
    let area = f64::from(SPHERE_RADIUS * SPHERE_RADIUS);
    let position = normals.integrals(3, |n| {
        let hit = sphere_hit(&scene, n);
        let pdf = lights
            .pdf_emission(&hit, n, (Vec3::ZERO, Vec3::ZERO))
            .unwrap();
        // dA = R² dω on the sphere.
        f64::from(pdf.pick * pdf.position) * area
    });
    assert_one(&position, 1e-4, "sphere positions");
    let observed = emission_histogram(&scene, normals.len(), 4, |s, _| {
        normals.index((s.origin - SPHERE_CENTER).normalize())
    });
    assert_chi_square(&observed, &scaled(&position), "sphere positions");

    let top = sphere_hit(&scene, Vec3::Y);
    let bins = DirectionBins::new(Vec3::Z, 0.0);
    let top_frame = Frame::from_normal(Vec3::Y);
    let direction = bins.integrals(4, |w| {
        // The local direction w (about +z) at the top, whose normal is +y.
        let world = top_frame.to_world(w);
        f64::from(
            lights
                .pdf_emission(&top, world, (Vec3::ZERO, Vec3::ZERO))
                .unwrap()
                .direction,
        )
    });
    assert_one(&direction, 1e-5, "sphere directions");
    let observed = emission_histogram(&scene, bins.len(), 5, |s, _| {
        bins.index(Frame::from_normal(s.normal).to_local(s.direction))
    });
    assert_chi_square(&observed, &scaled(&direction), "sphere directions");
}

/// Point and spot lights: every photon starts at the light, and the directions follow the
/// direction density, which integrates to one over the sphere (zero outside a spot's cone).
#[test]
fn point_and_spot_emission_follow_their_densities() {
    for (light, axis, cos_min) in [
        (point(), Vec3::Y, -1.0),
        (spot(), spot_axis(), f64::from(35f32.to_radians().cos())),
    ] {
        let scene = light_scene(light);
        let lights = scene.lights();
        let density = |w: Vec3| f64::from(lights.emitter_pdf(0, Vec3::ZERO, w, None).direction);
        // One over the sphere, all of it inside a spot's cone: the bins' edge is the cone's.
        let bins = DirectionBins::new(axis, cos_min);
        let direction = bins.integrals(4, density);
        assert_one(&direction, 1e-5, &format!("{light:?}"));
        let outside = DirectionBins {
            cos_min: -1.0,
            cos_max: cos_min,
            ..DirectionBins::new(axis, -1.0)
        };
        assert_eq!(outside.integrals(4, density).iter().sum::<f64>(), 0.0);
        let position = match light {
            Light::Point { position, .. } | Light::Spot { position, .. } => position,
            Light::Directional { .. } => unreachable!(),
        };
        let observed = emission_histogram(&scene, bins.len(), 6, |s, pdf| {
            assert_eq!(s.origin, position);
            assert_eq!(*pdf, lights.emitter_pdf(0, Vec3::ZERO, s.direction, None));
            bins.index(s.direction)
        });
        assert_chi_square(&observed, &scaled(&direction), &format!("{light:?}"));
    }
}

/// Directional and environment lights: photons start uniformly on a disc of the scene's
/// bounding radius facing their direction, whose position density integrates to one; the
/// environment's directions follow its direction density, which integrates to one over the
/// sphere.
#[test]
fn directional_and_environment_emission_follow_their_densities() {
    for (name, scene) in [
        ("directional", light_scene(directional())),
        ("environment map", environment_scene(true)),
        ("constant environment", environment_scene(false)),
    ] {
        let lights = scene.lights();
        let (center, r) = (scene.bounds().center(), scene.bounds().bounding_radius());
        let mut position_pdf = None;
        let observed = emission_histogram(&scene, 8 * 16, 7, |s, pdf| {
            position_pdf.get_or_insert(pdf.pick * pdf.position);
            disc_bin(center - r * s.direction, s.direction, r, s.origin)
        });
        // The density is uniform: each bin holds 1/128 of the disc.
        let position = position_pdf.unwrap();
        let disc = f64::from(position) * PI64 * f64::from(r * r);
        assert!((disc - 1.0).abs() < 1e-5, "{name}: ∫ = {disc}");
        let expected = vec![f64::from(N) / 128.0; 128];
        assert_chi_square(&observed, &expected, &format!("{name} positions"));
        if name == "directional" {
            continue;
        }
        let density = |w: Vec3| {
            // A photon travelling along w comes from the sky in direction −w.
            let pdf = lights.pdf_emission_environment(-w).unwrap();
            assert_eq!(pdf.position, position);
            f64::from(pdf.pick * pdf.direction)
        };
        let sphere = DirectionBins {
            n_cos: 256,
            n_phi: 512,
            ..DirectionBins::new(Vec3::Y, -1.0)
        }
        .integrals(4, density);
        assert_one(&sphere, 2e-3, &format!("{name} directions"));
        let bins = DirectionBins::new(Vec3::Y, -1.0);
        let direction = bins.integrals(16, density);
        let observed = emission_histogram(&scene, bins.len(), 8, |s, _| bins.index(s.direction));
        assert_chi_square(
            &observed,
            &scaled(&direction),
            &format!("{name} directions"),
        );
    }
}

/// The points that next-event estimation draws on the quad and on the sphere's visible cap (in
/// area measure), and its directions toward the sky (in solid angle), follow pick · direct.
#[test]
fn direct_samples_follow_the_direct_density() {
    let x = Vec3::new(0.05, -0.5, 0.1);
    let histogram = |scene: &Scene, n_bins: usize, bin: &dyn Fn(Vec3, f32) -> Option<usize>| {
        let mut observed = vec![0.0; n_bins];
        let mut rng = Rng::new(10);
        for _ in 0..N {
            if let Some((s, _)) =
                scene
                    .lights()
                    .sample_direct_with_pdf(x, Vec3::ZERO, rng.f32(), rng.vec2())
            {
                let b = bin(s.incoming, s.distance).expect("a binned sample");
                observed[b] += 1.0;
            }
        }
        observed
    };

    for scene in [quad_scene(), textured_quad_scene()] {
        let lights = scene.lights();
        let direct = quad_integrals(&scene, |hit| {
            f64::from(
                lights
                    .pdf_emission(hit, -Vec3::Y, (x, Vec3::ZERO))
                    .unwrap()
                    .direct_with_pick(),
            )
        });
        assert_one(&direct, 1e-5, "quad direct");
        let observed = histogram(&scene, direct.len(), &|w, d| Some(quad_bin(x + w * d)));
        assert_chi_square(&observed, &scaled(&direct), "quad direct");
    }

    // The sphere's points visible from x are those with cos α > R/d about the axis toward x;
    // the sampler draws on the whole sphere and returns nothing for the others.
    let scene = sphere_scene();
    let lights = scene.lights();
    let to_x = x - SPHERE_CENTER;
    let cap = f64::from(SPHERE_RADIUS / to_x.length());
    let bins = DirectionBins::new(to_x.normalize(), cap);
    let area = f64::from(SPHERE_RADIUS * SPHERE_RADIUS);
    let direct = bins.integrals(4, |n| {
        let hit = sphere_hit(&scene, n);
        f64::from(
            lights
                .pdf_emission(&hit, n, (x, Vec3::ZERO))
                .unwrap()
                .direct_with_pick(),
        ) * area
    });
    let visible: f64 = direct.iter().sum();
    let want = (1.0 - cap) / 2.0;
    assert!((visible - want).abs() < 1e-4, "{visible} vs {want}");
    let whole = DirectionBins::new(Vec3::Y, -1.0).integrals(3, |n| {
        let hit = sphere_hit(&scene, n);
        f64::from(
            lights
                .pdf_emission(&hit, n, (x, Vec3::ZERO))
                .unwrap()
                .direct_with_pick(),
        ) * area
    });
    assert_one(&whole, 1e-4, "sphere direct");
    let observed = histogram(&scene, bins.len(), &|w, d| {
        bins.index((x + w * d - SPHERE_CENTER).normalize())
    });
    assert_chi_square(&observed, &scaled(&direct), "sphere direct");

    for scene in [environment_scene(true), environment_scene(false)] {
        let lights = scene.lights();
        let bins = DirectionBins::new(Vec3::Y, -1.0);
        let direct = bins.integrals(16, |w| {
            f64::from(
                lights
                    .pdf_emission_environment(w)
                    .unwrap()
                    .direct_with_pick(),
            )
        });
        assert_one(&direct, 3e-3, "environment direct");
        let observed = histogram(&scene, bins.len(), &|w, _| bins.index(w));
        assert_chi_square(&observed, &scaled(&direct), "environment direct");
    }
}
