//! The automatic camera for scenes that have none.

use glam::Vec3;

use scene::{Camera, Cylinder, Sphere, Triangle};

/// Vertical field of view of a framed camera, in degrees.
pub const FRAMED_FOV_Y_DEGREES: f32 = 40.0;

/// Extra room around the framed bounding box (5 %).
const MARGIN: f32 = 1.05;

/// A pinhole camera on the +Z side of the bounding box, looking down −Z at its centre, with
/// up = +Y and a 40° vertical field of view. It stands back far enough that the box's front
/// face (z = max z), and with it everything behind it, fits the image with a 5 % margin:
/// distance = max(half height, half width / aspect) / tan(fov / 2) from the front face.
/// (For McGuire's Cornell box this gives a camera at about z = 3.9, as in the classic setup.)
pub(crate) fn frame_camera(
    triangles: &[Triangle],
    spheres: &[Sphere],
    cylinders: &[Cylinder],
    aspect: f32,
) -> Camera {
    let (lo, hi) = scene::primitive_bounds(triangles, spheres, cylinders)
        .unwrap_or((Vec3::splat(-1.0), Vec3::splat(1.0)));
    let center = 0.5 * (lo + hi);
    let half = 0.5 * (hi - lo);
    let aspect = if aspect.is_finite() && aspect > 0.0 {
        aspect
    } else {
        1.0
    };
    let fov_y = FRAMED_FOV_Y_DEGREES.to_radians();
    // Guard against a flat or point-like scene: never stand closer than a bit of its size.
    let size = half.max_element().max(1e-3);
    let half_view = half.y.max(half.x / aspect).max(1e-3 * size);
    let distance = MARGIN * half_view / (0.5 * fov_y).tan();
    let position = Vec3::new(center.x, center.y, hi.z + distance);
    Camera {
        position,
        look_at: center,
        up: Vec3::Y,
        fov_y,
        aperture_radius: 0.0,
        focus_distance: (position - center).length(),
    }
}
