use glam::{Vec2, Vec3};

use super::CameraModel;
use crate::{Camera, Film};

fn camera(aperture_radius: f32) -> CameraModel {
    let cam = Camera {
        position: Vec3::new(1.0, 2.0, 5.0),
        look_at: Vec3::new(0.0, 1.0, 0.0),
        up: Vec3::Y,
        fov_y: 40f32.to_radians(),
        aperture_radius,
        focus_distance: 4.0,
    };
    CameraModel::new(
        &cam,
        &Film {
            width: 64,
            height: 48,
        },
    )
    .unwrap()
}

#[test]
fn centre_ray_points_at_look_at() {
    let cam = camera(0.0);
    let ray = cam.generate_ray(Vec2::new(32.0, 24.0), Vec2::splat(0.5));
    let expected = (Vec3::new(0.0, 1.0, 0.0) - Vec3::new(1.0, 2.0, 5.0)).normalize();
    assert!(ray.direction.abs_diff_eq(expected, 1e-6), "{ray:?}");
    assert!((ray.direction.length() - 1.0).abs() < 1e-6);
}

#[test]
fn corner_rays_subtend_fov() {
    let cam = camera(0.0);
    let top = cam.generate_ray(Vec2::new(32.0, 0.0), Vec2::ZERO).direction;
    let bottom = cam
        .generate_ray(Vec2::new(32.0, 48.0), Vec2::ZERO)
        .direction;
    let angle = top.angle_between(bottom);
    assert!((angle - 40f32.to_radians()).abs() < 1e-5, "{angle}");
    // Top of the film is up, left is left.
    assert!(top.y > bottom.y);
    let left = cam.generate_ray(Vec2::new(0.0, 24.0), Vec2::ZERO).direction;
    let right = cam
        .generate_ray(Vec2::new(64.0, 24.0), Vec2::ZERO)
        .direction;
    let cam_right = cam.forward().cross(Vec3::Y);
    assert!(left.dot(cam_right) < 0.0 && right.dot(cam_right) > 0.0);
    let half_h = (20f32.to_radians()).tan() * 64.0 / 48.0;
    assert!((left.angle_between(right) - 2.0 * half_h.atan()).abs() < 1e-5);
}

#[test]
fn focus_plane_is_sharp() {
    let cam = camera(0.3);
    for film in [
        Vec2::new(3.5, 7.25),
        Vec2::new(32.0, 24.0),
        Vec2::new(60.0, 40.0),
    ] {
        let centre = cam.generate_ray(film, Vec2::splat(0.5));
        // The point on the focus plane (at distance 4 along the view axis).
        let t = 4.0 / centre.direction.dot(cam.forward());
        let target = centre.at(t);
        for u in [
            Vec2::new(0.1, 0.9),
            Vec2::new(0.95, 0.05),
            Vec2::new(0.3, 0.3),
        ] {
            let ray = cam.generate_ray(film, u);
            assert!(ray.origin.distance(cam.position()) > 1e-3);
            let s = (target - ray.origin).dot(cam.forward()) / ray.direction.dot(cam.forward());
            assert!(ray.at(s).distance(target) < 1e-4, "{film} {u}");
        }
    }
}

#[test]
fn project_inverts_generate_ray() {
    let cam = camera(0.0);
    for film in [
        Vec2::new(3.5, 7.25),
        Vec2::new(32.0, 24.0),
        Vec2::new(63.0, 47.0),
    ] {
        let ray = cam.generate_ray(film, Vec2::ZERO);
        let p = cam.project(ray.at(3.0)).unwrap();
        assert!(p.abs_diff_eq(film, 1e-3), "{p} {film}");
    }
    assert!(cam.project(Vec3::new(1.0, 2.0, 6.0)).is_none());
}

#[test]
fn degenerate_cameras_are_rejected() {
    let film = Film {
        width: 4,
        height: 4,
    };
    let good = Camera {
        position: Vec3::ZERO,
        look_at: Vec3::Z,
        up: Vec3::Y,
        fov_y: 1.0,
        aperture_radius: 0.0,
        focus_distance: 1.0,
    };
    assert!(CameraModel::new(&good, &film).is_some());
    assert!(
        CameraModel::new(
            &Camera {
                look_at: Vec3::ZERO,
                ..good
            },
            &film
        )
        .is_none()
    );
    assert!(
        CameraModel::new(
            &Camera {
                up: Vec3::Z,
                ..good
            },
            &film
        )
        .is_none()
    );
    assert!(CameraModel::new(&Camera { fov_y: 3.2, ..good }, &film).is_none());
    assert!(
        CameraModel::new(
            &Camera {
                aperture_radius: 0.1,
                focus_distance: 0.0,
                ..good
            },
            &film
        )
        .is_none()
    );
    assert!(
        CameraModel::new(
            &good,
            &Film {
                width: 0,
                height: 4
            }
        )
        .is_none()
    );
}

/// The film area a small surface patch covers, from projecting its corners (an independent
/// route to the density: no formula of `film_density` is used).
fn projected_area(cam: &CameraModel, centre: Vec3, normal: Vec3, side: f32) -> f32 {
    let t = normal.any_orthonormal_vector();
    let b = normal.cross(t);
    let corner = |s: f32, u: f32| cam.project(centre + side * (s * t + u * b)).unwrap();
    let (a, b2, c, d) = (
        corner(-0.5, -0.5),
        corner(0.5, -0.5),
        corner(0.5, 0.5),
        corner(-0.5, 0.5),
    );
    // Two triangles from corner a, in coordinates relative to it (no cancellation).
    let (e1, e2, e3) = (b2 - a, c - a, d - a);
    0.5 * ((e1.x * e2.y - e2.x * e1.y) + (e2.x * e3.y - e3.x * e2.y)).abs()
}

#[test]
fn film_density_is_the_projected_area_per_unit_area() {
    let cam = camera(0.0);
    for (point, normal) in [
        (Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 1.0)),
        (
            Vec3::new(0.7, 0.4, -0.5),
            Vec3::new(0.3, 0.9, 0.2).normalize(),
        ),
        (
            Vec3::new(-0.9, 1.6, 0.8),
            Vec3::new(-0.6, 0.1, 0.7).normalize(),
        ),
    ] {
        let side = 1e-2;
        let expected = projected_area(&cam, point, normal, side) / (side * side);
        let density = cam.film_density(point, normal);
        assert!(
            (density / expected - 1.0).abs() < 2e-3,
            "{point}: {density} against {expected}"
        );
        // A pinhole's connection carries the same density once the cosine is applied.
        let c = cam.connect(point, Vec2::ZERO).unwrap();
        let to_lens = (c.lens - point).normalize();
        let via_connect = c.density * normal.dot(to_lens).abs();
        assert!((via_connect / density - 1.0).abs() < 1e-4);
        assert!(c.film.abs_diff_eq(cam.project(point).unwrap(), 1e-4));
    }
    assert_eq!(cam.film_density(Vec3::new(1.0, 2.0, 6.0), Vec3::Z), 0.0);
}

#[test]
fn thin_lens_connection_inverts_generate_ray() {
    let cam = camera(0.3);
    for film in [
        Vec2::new(3.5, 7.25),
        Vec2::new(32.0, 24.0),
        Vec2::new(60.0, 40.0),
    ] {
        for u in [
            Vec2::new(0.1, 0.9),
            Vec2::new(0.95, 0.05),
            Vec2::new(0.5, 0.5),
        ] {
            let ray = cam.generate_ray(film, u);
            // A point off the focus plane, so that the lens point matters.
            let point = ray.at(2.5);
            let c = cam.connect(point, u).unwrap();
            assert!(c.lens.distance(ray.origin) < 1e-5, "{film} {u}");
            assert!(c.film.abs_diff_eq(film, 2e-3), "{} against {film}", c.film);
            // du/dω of a ray from a fixed lens point is the pinhole's: F²/cos³θ.
            let cos = ray.direction.dot(cam.forward());
            let f = 0.5 * 48.0 / (20f32.to_radians()).tan();
            let d2 = (point - c.lens).length_squared();
            assert!((c.density * d2 * cos.powi(3) / (f * f) - 1.0).abs() < 1e-4);
        }
    }
}
