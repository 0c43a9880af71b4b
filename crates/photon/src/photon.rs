//! Photon records and the test that decides whether a photon counts for a hitpoint.

use glam::Vec3;

/// A photon stored on a surface: plain data, public fields.
///
/// 56 bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Photon {
    /// Where the photon hit the surface.
    pub position: Vec3,
    /// Unit direction pointing away from the surface, back toward where the photon came from.
    pub incoming: Vec3,
    /// Flux carried by the photon (RGB, watts).
    pub power: Vec3,
    /// Unit geometric normal of the surface at the photon hit, faced toward the side the photon
    /// arrived from: `normal.dot(incoming) ≥ 0`.
    pub normal: Vec3,
    /// Scattering events on the photon's path before this hit (0 for a hit straight from the
    /// emitter), so that a renderer can bound the bounces of the whole light path.
    pub bounces: u32,
    /// Free for the caller: this crate never reads it. E.g. the index of a record with more
    /// state about some of the photons, which a gather's contribution can carry to the
    /// accumulators ([`crate::gather_with`], [`crate::Gathered::accumulate_again`]).
    pub tag: u32,
}

impl AsRef<Photon> for Photon {
    fn as_ref(&self) -> &Photon {
        self
    }
}

/// Parameters of the photon acceptance test [`accepts`].
///
/// No `Default` on purpose: the threshold is a choice the caller makes and documents.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AcceptParams {
    /// The photon's surface normal and the hitpoint's geometric normal must satisfy
    /// `dot(n_photon, n_hitpoint) > min_normal_cos`.
    pub min_normal_cos: f32,
}

impl AcceptParams {
    /// `min_normal_cos = cos 60° = 0.5`.
    ///
    /// It rejects photons from the other face of a thin wall (cos ≈ −1) and from a perpendicular
    /// wall in a corner (cos ≈ 0), but accepts photons on a curved surface whose normal turns by
    /// less than 60° within the gather radius (a sphere of radius ≥ 1.15 R).
    pub const COS_60: Self = Self {
        min_normal_cos: 0.5,
    };
}

/// Whether `photon` counts for a hitpoint at `position` with unit geometric normal `normal`
/// (faced toward the viewer, i.e. toward the hitpoint's outgoing direction) and gather radius
/// `radius`.
///
/// Three conditions, all required:
/// 1. distance: [`within_radius`]`(photon.position, position, radius²)`;
/// 2. side: the photon arrives on the hitpoint's side of the surface,
///    `dot(photon.incoming, normal) > 0`;
/// 3. normal agreement: `dot(photon.normal, normal) > params.min_normal_cos`.
///
/// Conditions 2 and 3 fix the defect reported against Mitsuba's SPPM, where photons on the back
/// face of a thin wall land within the radius, count, and shrink the radius of front-face
/// hitpoints.
#[must_use]
#[inline]
pub fn accepts(
    photon: &Photon,
    position: Vec3,
    normal: Vec3,
    radius: f64,
    params: AcceptParams,
) -> bool {
    within_radius(photon.position, position, radius * radius) && faces(photon, normal, params)
}

/// Conditions 2 and 3 of [`accepts`] (side and normal agreement) without the distance test:
/// for photons that [`crate::HitPointGrid::for_each_containing`] reported, whose distance test
/// is already exactly condition 1 (same predicate, same radius).
#[must_use]
#[inline]
pub fn faces(photon: &Photon, normal: Vec3, params: AcceptParams) -> bool {
    photon.incoming.dot(normal) > 0.0 && photon.normal.dot(normal) > params.min_normal_cos
}

/// The distance predicate every query in this crate uses: `|p − x|² ≤ r²`, with the squared
/// distance computed in `f32` and compared in `f64`.
///
/// The grid and the brute-force scan of the tests share this one function, so their results are
/// identical sets, rounding included. NaN inputs never match.
#[must_use]
#[inline]
pub fn within_radius(p: Vec3, x: Vec3, radius_sq: f64) -> bool {
    f64::from(crate::grid::distance_sq(p, x)) <= radius_sq
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hitpoint on the top face (z = 0, normal +z) of a wall, gather radius 0.1.
    const HIT: Vec3 = Vec3::ZERO;
    const UP: Vec3 = Vec3::Z;
    const R: f64 = 0.1;

    fn photon(position: Vec3, incoming: Vec3, normal: Vec3) -> Photon {
        Photon {
            bounces: 0,
            position,
            incoming: incoming.normalize(),
            power: Vec3::ONE,
            normal,
            tag: 0,
        }
    }

    #[test]
    fn front_photon_counts() {
        let p = photon(Vec3::new(0.05, 0.0, 0.0), Vec3::new(1.0, 0.0, 1.0), UP);
        assert!(accepts(&p, HIT, UP, R, AcceptParams::COS_60));
    }

    #[test]
    fn thin_wall_back_face_photon_is_rejected() {
        // Mitsuba SPPM defect: the wall is 0.01 thick, so the photon on its bottom face
        // (z = −0.01, normal −z, arriving from below) is well inside the radius.
        let p = photon(Vec3::new(0.02, 0.0, -0.01), Vec3::new(0.0, 0.3, -1.0), -UP);
        assert!(within_radius(p.position, HIT, R * R));
        assert!(!accepts(&p, HIT, UP, R, AcceptParams::COS_60));
        // Zero thickness, and the photon normal faced to the top by mistake: the side test alone
        // still rejects it.
        let p = photon(Vec3::new(0.02, 0.0, 0.0), Vec3::new(0.0, 0.3, -1.0), UP);
        assert!(!accepts(&p, HIT, UP, R, AcceptParams::COS_60));
    }

    #[test]
    fn corner_photon_on_perpendicular_wall_is_rejected() {
        // Photon on the wall x = 0.03 facing −x, arriving from a direction above the floor.
        let p = photon(
            Vec3::new(0.03, 0.0, 0.02),
            Vec3::new(-1.0, 0.0, 0.5),
            -Vec3::X,
        );
        assert!(!accepts(&p, HIT, UP, R, AcceptParams::COS_60));
        let lenient = AcceptParams {
            min_normal_cos: -1.0,
        };
        assert!(accepts(&p, HIT, UP, R, lenient));
    }

    #[test]
    fn outside_radius_is_rejected() {
        let p = photon(Vec3::new(0.2, 0.0, 0.0), UP, UP);
        assert!(!accepts(&p, HIT, UP, R, AcceptParams::COS_60));
    }

    #[test]
    fn within_radius_boundary_and_nan() {
        assert!(within_radius(Vec3::new(0.5, 0.0, 0.0), Vec3::ZERO, 0.25));
        assert!(!within_radius(Vec3::new(0.5, 0.0, 0.0), Vec3::ZERO, 0.2499));
        assert!(!within_radius(Vec3::NAN, Vec3::ZERO, f64::INFINITY));
    }
}
