//! The geometric bound of a held kernel: how large a hitpoint's gather disc may be and still
//! lie on the hitpoint's own surface.
//!
//! The frequency analysis predicts how smooth the *light* is around a hitpoint; it is blind to
//! the *surface*. A disc of radius R around a hitpoint near a concave corner (the floor
//! against a wall, a block standing on the floor) or near a convex edge (the top of a block)
//! hangs over geometry where no photon is accepted: photons on the perpendicular face fail the
//! normal test and there is no surface beyond an edge. The estimate τ/(πR²N) then divides the
//! flux of the part of the disc that receives photons by the area of the whole disc, a bias
//! that PPM removes by shrinking but that a held radius keeps for ever. A hold is therefore
//! only allowed at radii where the disc is clear, found by probe rays when a hitpoint first
//! becomes a candidate for holding (once per visible point).
//!
//! The probes, in [`DIRECTIONS`] evenly spaced directions of the tangent plane:
//! - a **wall probe** along the tangent plane, just above the surface, up to the initial
//!   radius R₀: a hit at distance d means a surface rises within d (a concave corner);
//! - **drop probes** at tangent distance r: a ray straight down onto the surface from height
//!   r/2, which must meet a surface within r/2 of the tangent plane whose normal agrees with
//!   the hitpoint's as the photon acceptance test requires (a missing or turned surface is a
//!   convex edge or a strongly curved surface).
//!
//! The clear radius is the largest r of R₀, R₀/2, …, R₀/2^(LEVELS−1) with r ≤ d and every
//! drop probe at r landing; 0 if none is. It is kept as the level (one byte per slot). The candidates are coarse on purpose: a factor of
//! two in radius is a factor of four in the variance the hold saves, and the bias of the
//! level just below an edge is that of the shrinking PPM radius anyway.

use glam::Vec3;
use scene::{Ray, Scene};

/// Probe directions in the tangent plane.
pub(crate) const DIRECTIONS: usize = 8;
/// Candidate radii R·2^−i, i < LEVELS, from the largest kernel R down to R/128.
pub(crate) const LEVELS: u32 = 8;
/// A drop probe must land on a surface whose geometric normal is within this cosine of the
/// hitpoint's (`photon::AcceptParams`' default normal agreement, 60°).
const NORMAL_COS: f32 = 0.5;

/// The level i of the largest radius r0·2^−i (i < [`LEVELS`]) at which the gather disc of the
/// hitpoint at `position` with unit geometric normal `normal` (facing the camera side) lies on
/// a surface that accepts photons; [`LEVELS`] if even the smallest candidate does not. Levels
/// fit a byte of the slot's state; [`level_radius`] turns one into a radius.
///
/// A drop probe at distance r falls from r/2 and must land within r/2 of the tangent plane, but
/// never further than `depth`: a ladder that starts far above the largest kernel (the blocks'
/// shared probe, eight times it) would otherwise take a surface a step below for the same one
/// (the ground around a pool for the water 7 cm under it) and call a disc that hangs over the
/// step clear. `depth` = r0/2 is the plain rule.
pub(crate) fn clear_level(scene: &Scene, position: Vec3, normal: Vec3, r0: f32, depth: f32) -> u8 {
    const NONE: u8 = LEVELS as u8;
    if !(r0 > 0.0 && r0.is_finite() && position.is_finite() && normal.is_finite()) {
        return NONE;
    }
    // Height of the wall probes: above the surface by more than the float error of a hit at
    // this magnitude, far below any radius.
    let lift = 1e-3 * r0 + 1e-5 * position.abs().max_element();
    let (t, b) = normal.any_orthonormal_pair();
    let directions: [Vec3; DIRECTIONS] = std::array::from_fn(|k| {
        let phi = std::f32::consts::TAU * k as f32 / DIRECTIONS as f32;
        t * phi.cos() + b * phi.sin()
    });
    let origin = position + normal * lift;
    let mut wall = r0;
    for &d in &directions {
        if let Some(hit) = scene.intersect(&Ray::new(origin, d, r0)) {
            wall = wall.min(hit.t);
        }
    }
    for level in 0..NONE {
        let r = r0 * 0.5f32.powi(i32::from(level));
        if r <= wall
            && directions
                .iter()
                .all(|&d| lands(scene, position, normal, d, r, depth.min(0.5 * r), lift))
        {
            return level;
        }
    }
    NONE
}

/// The clear radius of `level` ([`clear_level`]) for the initial radius `r0`: r0·2^−level, or 0
/// for [`LEVELS`] and above.
pub(crate) fn level_radius(level: u8, r0: f64) -> f64 {
    if u32::from(level) < LEVELS {
        r0 * 0.5f64.powi(i32::from(level))
    } else {
        0.0
    }
}

/// Whether the drop probe at tangent distance `r` along `d` meets the hitpoint's surface within
/// `depth` of its tangent plane.
fn lands(
    scene: &Scene,
    position: Vec3,
    normal: Vec3,
    d: Vec3,
    r: f32,
    depth: f32,
    lift: f32,
) -> bool {
    let height = depth + lift;
    let origin = position + d * r + normal * height;
    let ray = Ray::new(origin, -normal, 2.0 * height);
    scene
        .intersect(&ray)
        .is_some_and(|hit| hit.geometric_normal.dot(normal) >= NORMAL_COS)
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;

    /// The camera, film and material of the test scenes, and their point light.
    const HEADER: &str = r#"
format = 1
[camera]
position = [0.0, 3.0, 3.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 40.0
[film]
width = 8
height = 8
[materials.white]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]
[[lights]]
type = "point"
position = [0.0, 2.0, 0.0]
intensity = [1.0, 1.0, 1.0]
"#;

    /// A floor (y = 0, |x|, |z| ≤ 1), a wall standing on it at x = 0.5 and a platform
    /// (y = 0.3) over x ∈ [−1, −0.5].
    const SHAPES: &str = r#"
[[shapes]]
type = "quad"
corner = [-1.0, 0.0, 1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -2.0]
material = "white"
[[shapes]]
type = "quad"
corner = [0.5, 0.0, 1.0]
edge1 = [0.0, 0.0, -2.0]
edge2 = [0.0, 1.0, 0.0]
material = "white"
[[shapes]]
type = "quad"
corner = [-1.0, 0.3, 1.0]
edge1 = [0.5, 0.0, 0.0]
edge2 = [0.0, 0.0, -2.0]
material = "white"
"#;

    /// A step: a platform (y = 0.1) over x ≤ 0 above a floor (y = 0), both 8 wide, as the
    /// ground around a pool stands above its water.
    const STEP: &str = r#"
[[shapes]]
type = "quad"
corner = [-4.0, 0.0, 4.0]
edge1 = [8.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -8.0]
material = "white"
[[shapes]]
type = "quad"
corner = [-4.0, 0.1, 4.0]
edge1 = [4.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -8.0]
material = "white"
"#;

    fn build(shapes: &str) -> Scene {
        let text = format!("{HEADER}{shapes}");
        let description = import::load_toml_str(&text, Path::new("disc-test.toml"))
            .expect("the test scene parses");
        Scene::new(description).expect("the test scene builds")
    }

    fn scene() -> Scene {
        build(SHAPES)
    }

    fn clear_radius(scene: &Scene, position: Vec3, normal: Vec3, r0: f32) -> f64 {
        clear_radius_within(scene, position, normal, r0, 0.5 * r0)
    }

    /// The clear radius with drop probes no deeper than `depth`.
    fn clear_radius_within(
        scene: &Scene,
        position: Vec3,
        normal: Vec3,
        r0: f32,
        depth: f32,
    ) -> f64 {
        level_radius(
            clear_level(scene, position, normal, r0, depth),
            f64::from(r0),
        )
    }

    /// The blocks' shared ladder starts at eight times the largest kernel (0.1 here): with
    /// drop probes as deep as r/2 its large levels land on the floor a step below and call a
    /// disc 0.02 from the platform's edge clear at 0.8; held to the kernel's r/2 = 0.05 they
    /// find the edge, and the disc is clear only at 0.0125 (the level within 0.02).
    #[test]
    fn a_step_below_an_edge_is_not_the_same_surface_at_any_level() {
        let scene = build(STEP);
        let at = Vec3::new(-0.02, 0.1, 0.0);
        let wide = 0.8f32;
        let loose = clear_radius(&scene, at, Vec3::Y, wide);
        assert_eq!(loose, f64::from(wide));
        let held = clear_radius_within(&scene, at, Vec3::Y, wide, 0.05);
        assert_eq!(held, f64::from(wide) / 64.0);
    }

    #[test]
    fn open_floor_is_clear_at_the_initial_radius() {
        let r = clear_radius(&scene(), Vec3::new(0.0, 0.0, 0.0), Vec3::Y, 0.4);
        assert_eq!(r, f64::from(0.4f32));
    }

    #[test]
    fn a_wall_within_the_disc_limits_it_below_its_distance() {
        // The wall is 0.08 away: 0.4, 0.2 and 0.1 overhang it, 0.05 does not.
        let r = clear_radius(&scene(), Vec3::new(0.42, 0.0, 0.0), Vec3::Y, 0.4);
        assert_eq!(r, f64::from(0.4f32) / 8.0);
    }

    #[test]
    fn a_convex_edge_within_the_disc_limits_it_below_its_distance() {
        // The platform ends 0.13 away: its drop probes at 0.4 and 0.2 find no surface.
        let r = clear_radius(&scene(), Vec3::new(-0.63, 0.3, 0.0), Vec3::Y, 0.4);
        assert_eq!(r, f64::from(0.4f32) / 4.0);
    }

    #[test]
    fn a_disc_over_the_edge_of_the_last_level_is_not_clear() {
        // 0.002 from the wall: even r0/128 = 0.003125 overhangs it.
        let r = clear_radius(&scene(), Vec3::new(0.498, 0.0, 0.0), Vec3::Y, 0.4);
        assert_eq!(r, 0.0);
        // 0.01 from it: r0/64 = 0.00625 does not.
        let r = clear_radius(&scene(), Vec3::new(0.49, 0.0, 0.0), Vec3::Y, 0.4);
        assert_eq!(r, f64::from(0.4f32) / 64.0);
    }

    #[test]
    fn non_finite_input_is_not_clear() {
        let s = scene();
        assert_eq!(clear_radius(&s, Vec3::NAN, Vec3::Y, 0.4), 0.0);
        assert_eq!(clear_radius(&s, Vec3::ZERO, Vec3::Y, f32::NAN), 0.0);
        assert_eq!(clear_radius(&s, Vec3::ZERO, Vec3::Y, 0.0), 0.0);
    }
}
