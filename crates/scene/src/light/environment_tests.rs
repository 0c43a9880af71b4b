//! The environment light: orientation against Mitsuba's formula, the sampler's density against
//! its histogram and against 1, emission and next-event estimates against quadrature.

use std::f64::consts::PI as PI64;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::*;
use crate::test_util::Rng;

/// A 64 × 32 map with a bright small "sun", a colour gradient, a black band and a black pole.
fn test_map() -> EnvironmentMap {
    let (w, h) = (64u32, 32u32);
    let mut texels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let t = if (10..12).contains(&y) && (40..43).contains(&x) {
                Vec3::new(200.0, 180.0, 150.0)
            } else if y == 0 || (20..23).contains(&y) {
                Vec3::ZERO
            } else {
                Vec3::new(0.2 + x as f32 / w as f32, 0.5, 0.1 + y as f32 / h as f32)
            };
            texels.push(t);
        }
    }
    EnvironmentMap {
        path: "test.exr".into(),
        width: w,
        height: h,
        texels,
    }
}

fn environment(rotate: Vec3, scale: f32) -> Environment {
    Environment {
        radiance: EnvironmentRadiance::Map(Arc::new(test_map())),
        scale,
        to_world: Environment::rotation_degrees(rotate),
    }
}

fn unit_bounds() -> Aabb {
    Aabb::EMPTY.include(Vec3::splat(-1.0)).include(Vec3::ONE)
}

fn light(env: &Environment) -> EnvironmentLight {
    EnvironmentLight::new(env, unit_bounds()).unwrap()
}

/// World direction of (cos θ, φ) about +y, for quadratures over the sphere.
fn sphere_direction(cos: f64, phi: f64) -> Vec3 {
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    Vec3::new(
        (sin * phi.cos()) as f32,
        cos as f32,
        (sin * phi.sin()) as f32,
    )
}

/// ∫ f dω over the sphere by the midpoint rule on an (cos θ, φ) grid.
fn integrate(n_cos: usize, n_phi: usize, mut f: impl FnMut(Vec3) -> f64) -> f64 {
    let mut sum = 0.0;
    for i in 0..n_cos {
        let cos = -1.0 + 2.0 * (i as f64 + 0.5) / n_cos as f64;
        for j in 0..n_phi {
            let phi = 2.0 * PI64 * (j as f64 + 0.5) / n_phi as f64;
            sum += f(sphere_direction(cos, phi));
        }
    }
    sum * (2.0 / n_cos as f64) * (2.0 * PI64 / n_phi as f64)
}

/// Whether two radiances agree to float rounding.
fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() <= 1e-4 * a.abs().max(b.abs()).max_element() + 1e-4
}

/// Mitsuba's `uv_to_direction`, written out here.
fn mitsuba_direction(u: f64, v: f64) -> Vec3 {
    let (theta, phi) = (v * PI64, u * 2.0 * PI64);
    Vec3::new(
        (phi.sin() * theta.sin()) as f32,
        theta.cos() as f32,
        (-phi.cos() * theta.sin()) as f32,
    )
}

#[test]
fn orientation_is_mitsubas() {
    let map = test_map();
    let l = light(&environment(Vec3::ZERO, 1.0));
    let (w, h) = (map.width as usize, map.height as usize);
    let texel = |x: usize, y: usize| map.texels[y * w + x];
    // Mitsuba's `eval_spectrum` puts texel (x, y) at u = (x + ½)/W, v = y/(H − 1) and
    // interpolates bilinearly between them, periodic in u.
    for y in 0..h {
        let v = y as f64 / (h - 1) as f64;
        for x in 0..w {
            let d = mitsuba_direction((x as f64 + 0.5) / w as f64, v);
            assert!(close(l.eval(d), texel(x, y)), "texel ({x}, {y})");
            // Halfway to the next column (the last column's next is the first) ...
            let d = mitsuba_direction((x as f64 + 1.0) / w as f64, v);
            let want = (texel(x, y) + texel((x + 1) % w, y)) * 0.5;
            assert!(close(l.eval(d), want), "between ({x}, {y}) and its right");
            // ... and a quarter of the way to the next row.
            if y + 1 < h {
                let d = mitsuba_direction((x as f64 + 0.5) / w as f64, v + 0.25 / (h - 1) as f64);
                let want = texel(x, y) * 0.75 + texel(x, y + 1) * 0.25;
                assert!(close(l.eval(d), want), "below ({x}, {y})");
            }
        }
    }
    // Straight up is the top row, everywhere the same in the test map (black); the image's
    // centre (u = ½) looks toward +z, a quarter of the width toward +x, the left edge toward −z;
    // on the horizon v = ½ falls halfway between rows H/2 − 1 and H/2 (of positions
    // (H/2 − 1)/(H − 1) and (H/2)/(H − 1)).
    assert_eq!(l.eval(Vec3::Y), Vec3::ZERO);
    let horizon = |x: usize| (texel(x, h / 2 - 1) + texel(x, h / 2)) * 0.5;
    // Between columns W/2 − 1 and W/2, that is at u = ½.
    let centre = (horizon(w / 2 - 1) + horizon(w / 2)) * 0.5;
    assert!(close(l.eval(Vec3::Z), centre));
    let quarter = (horizon(w / 4 - 1) + horizon(w / 4)) * 0.5;
    assert!(close(l.eval(Vec3::X), quarter));
    let edge = (horizon(w - 1) + horizon(0)) * 0.5;
    assert!(close(l.eval(-Vec3::Z), edge));
    // rotate = [0, 90, 0] turns the map's +z toward world +x.
    let turned = light(&environment(Vec3::new(0.0, 90.0, 0.0), 1.0));
    assert!(close(turned.eval(Vec3::X), centre));
}

#[test]
fn uv_round_trip() {
    let mut rng = Rng::new(3);
    for _ in 0..10_000 {
        let uv = Vec2::new(rng.f32(), 0.001 + 0.998 * rng.f32());
        let (d, sin_theta) = uv_to_direction(uv);
        assert!((d.length() - 1.0).abs() < 1e-5);
        assert!((sin_theta - (d.x * d.x + d.z * d.z).sqrt()).abs() < 1e-5);
        let back = direction_to_uv(d);
        let du = (back.x - uv.x).abs();
        assert!(
            du.min(1.0 - du) < 1e-4 && (back.y - uv.y).abs() < 1e-4,
            "{uv} -> {back}"
        );
    }
}

#[test]
fn pdf_integrates_to_one_and_radiance_to_the_power() {
    for rotate in [Vec3::ZERO, Vec3::new(20.0, 35.0, -10.0)] {
        let env = environment(rotate, 2.5);
        let l = light(&env);
        // The midpoint rule over the texels' edges is good to a few 10⁻⁴ at this resolution.
        let total = integrate(2048, 4096, |d| f64::from(l.pdf(d)));
        assert!((total - 1.0).abs() < 2e-3, "∫ pdf dω = {total}");
        let radiance = integrate(2048, 4096, |d| f64::from(l.eval(d).y));
        let want = f64::from(env.integrated_radiance().y);
        assert!((radiance / want - 1.0).abs() < 2e-3, "{radiance} vs {want}");
        let r = unit_bounds().bounding_radius();
        let power = f64::from(l.power().y) / (PI64 * f64::from(r * r));
        assert!((power / want - 1.0).abs() < 1e-5);
    }
    let constant = Environment {
        radiance: EnvironmentRadiance::Constant(Vec3::new(1.0, 2.0, 3.0)),
        scale: 0.5,
        to_world: glam::Mat3::IDENTITY,
    };
    let want = 4.0 * std::f32::consts::PI * Vec3::new(0.5, 1.0, 1.5);
    assert!((constant.integrated_radiance() - want).abs().max_element() < 1e-5);
}

#[test]
fn samples_carry_their_own_radiance_and_density() {
    let l = light(&environment(Vec3::new(20.0, 35.0, -10.0), 1.0));
    let mut rng = Rng::new(5);
    let mut off = 0;
    let n = 20_000;
    for _ in 0..n {
        let s = l.sample(rng.vec2()).unwrap();
        assert!((s.direction.length() - 1.0).abs() < 1e-5);
        assert!(s.radiance.max_element() > 0.0, "a black patch was sampled");
        // A sample within rounding of a texel edge may look up its neighbour.
        let pdf = l.pdf(s.direction);
        if !close(l.eval(s.direction), s.radiance) || (pdf / s.pdf - 1.0).abs() > 1e-3 {
            off += 1;
        }
    }
    assert!(off < n / 500, "{off} of {n} samples disagree with eval/pdf");
}

#[test]
fn sampling_matches_pdf_chi_square() {
    const N_COS: usize = 32;
    const N_PHI: usize = 64;
    const N: usize = 400_000;
    let l = light(&environment(Vec3::new(20.0, 35.0, -10.0), 1.0));
    let bin = |d: Vec3| {
        let c = ((d.y * 0.5 + 0.5) * N_COS as f32).clamp(0.0, N_COS as f32 - 1.0) as usize;
        let phi = d.z.atan2(d.x).rem_euclid(2.0 * std::f32::consts::PI);
        let p = (phi / (2.0 * std::f32::consts::PI) * N_PHI as f32).clamp(0.0, N_PHI as f32 - 1.0)
            as usize;
        c * N_PHI + p
    };
    let mut observed = vec![0.0f64; N_COS * N_PHI];
    let mut rng = Rng::new(9);
    for _ in 0..N {
        if let Some(s) = l.sample(rng.vec2()) {
            observed[bin(s.direction)] += 1.0;
        }
    }
    let sub = 16;
    let mut expected = vec![0.0f64; N_COS * N_PHI];
    for c in 0..N_COS {
        for p in 0..N_PHI {
            let mut sum = 0.0;
            for i in 0..sub {
                for j in 0..sub {
                    let cos =
                        -1.0 + 2.0 * (c as f64 + (i as f64 + 0.5) / sub as f64) / N_COS as f64;
                    let phi =
                        2.0 * PI64 * (p as f64 + (j as f64 + 0.5) / sub as f64) / N_PHI as f64;
                    sum += f64::from(l.pdf(sphere_direction(cos, phi)));
                }
            }
            let area = (2.0 / N_COS as f64) * (2.0 * PI64 / N_PHI as f64);
            expected[c * N_PHI + p] = sum / f64::from(sub * sub) * area * N as f64;
        }
    }
    let (mut chi2, mut dof, mut pooled_o, mut pooled_e) = (0.0, 0usize, 0.0, 0.0);
    for (o, e) in observed.iter().zip(&expected) {
        if *e < 5.0 {
            pooled_o += o;
            pooled_e += e;
        } else {
            chi2 += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pooled_e >= 5.0 {
        chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
        dof += 1;
    }
    let dof = dof.saturating_sub(1) as f64;
    let limit = dof + 5.0 * (2.0 * dof).sqrt();
    assert!(
        chi2 < limit,
        "χ² {chi2:.1} with {dof} dof (limit {limit:.1})"
    );
}

#[test]
fn next_event_estimate_matches_quadrature() {
    let l = light(&environment(Vec3::new(20.0, 35.0, -10.0), 1.0));
    for n in [Vec3::Y, Vec3::new(0.3, -0.2, 0.9).normalize(), -Vec3::Y] {
        let want = integrate(1024, 2048, |d| {
            f64::from(l.eval(d).x) * f64::from(d.dot(n).max(0.0))
        });
        let mut rng = Rng::new(11);
        let count = 400_000;
        let mut sum = 0.0;
        for _ in 0..count {
            if let Some(s) = l.sample(rng.vec2()) {
                sum += f64::from(s.radiance.x * s.direction.dot(n).max(0.0) / s.pdf);
            }
        }
        let got = sum / f64::from(count);
        assert!((got / want - 1.0).abs() < 0.01, "n {n}: {got} vs {want}");
    }
}

#[test]
fn photons_start_outside_and_carry_the_power() {
    let env = environment(Vec3::new(20.0, 35.0, -10.0), 1.0);
    let l = light(&env);
    let (center, r) = (unit_bounds().center(), unit_bounds().bounding_radius());
    let mut rng = Rng::new(13);
    let count = 200_000;
    let mut sum = glam::DVec3::ZERO;
    for _ in 0..count {
        let Some((origin, direction, flux, angle)) = l.sample_emission(rng.vec2(), rng.vec2())
        else {
            continue;
        };
        // On the disc tangent to the bounding sphere, travelling into it.
        let along = (origin - center).dot(-direction);
        assert!((along - r).abs() < 1e-4 * r, "{along} vs {r}");
        assert!((origin - center).length() <= r * std::f32::consts::SQRT_2 * 1.0001);
        assert!(angle > 0.0 && angle < 0.2);
        sum += flux.as_dvec3();
    }
    let mean = sum / f64::from(count);
    let want = l.power().as_dvec3();
    assert!(
        ((mean - want) / want).abs().max_element() < 0.02,
        "{mean} vs {want}"
    );
}

/// pbrt's octahedral mapping is equal-area: uniform directions fill the square's cells evenly,
/// and its landmarks are where pbrt puts them.
#[test]
fn equal_area_square_is_equal_area() {
    let n = 8;
    let mut counts = vec![0u32; n * n];
    let mut rng = Rng::new(17);
    let samples = 256_000;
    for _ in 0..samples {
        let st = equal_area_sphere_to_square(uniform_sphere(rng.vec2()));
        let i = ((st.x * n as f32) as usize).min(n - 1);
        let j = ((st.y * n as f32) as usize).min(n - 1);
        counts[j * n + i] += 1;
    }
    let expected = f64::from(samples) / (n * n) as f64;
    let chi2: f64 = counts
        .iter()
        .map(|&c| (f64::from(c) - expected).powi(2) / expected)
        .sum();
    let dof = (n * n - 1) as f64;
    assert!(chi2 < dof + 5.0 * (2.0 * dof).sqrt(), "χ² {chi2:.1}");
    let close = |a: Vec2, b: Vec2| (a - b).length() < 1e-6;
    assert!(close(
        equal_area_sphere_to_square(Vec3::Z),
        Vec2::splat(0.5)
    ));
    assert!(close(
        equal_area_sphere_to_square(Vec3::X),
        Vec2::new(1.0, 0.5)
    ));
    assert!(close(
        equal_area_sphere_to_square(Vec3::Y),
        Vec2::new(0.5, 1.0)
    ));
    let corner = equal_area_sphere_to_square(-Vec3::Z);
    assert!(
        close(corner, Vec2::ZERO)
            || close(corner, Vec2::ONE)
            || close(corner, Vec2::new(1.0, 0.0))
            || close(corner, Vec2::new(0.0, 1.0))
    );
}
