//! The perspective camera: pinhole or thin lens.

use glam::{Vec2, Vec3};

use crate::{Camera, Film, Ray, sampling::concentric_disk};

#[cfg(test)]
mod tests;

/// A light-tracing connection to the lens ([`CameraModel::connect`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensConnection {
    /// Film position in pixels.
    pub film: Vec2,
    /// The point on the lens.
    pub lens: Vec3,
    /// (du/dω)/d² of the connecting ray, in pixels per unit area at normal incidence.
    pub density: f32,
}

/// A camera ready to generate rays for a film.
///
/// Film coordinates are in pixels: pixel (i, j) covers `[i, i+1] × [j, j+1]`, (0, 0) is the top-left
/// corner, x grows to the right and y downwards. `fov_y` spans the film's height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraModel {
    position: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    tan_half_fov_y: f32,
    aspect: f32,
    width: f32,
    height: f32,
    aperture_radius: f32,
    focus_distance: f32,
}

impl CameraModel {
    /// Builds the camera; `None` when it is degenerate: `look_at` at `position`, `up` parallel to the
    /// view direction, `fov_y` outside (0, π), an empty film, a negative aperture, or a thin lens
    /// without a positive focus distance, or anything non-finite.
    pub fn new(camera: &Camera, film: &Film) -> Option<Self> {
        let finite = camera.position.is_finite()
            && camera.look_at.is_finite()
            && camera.up.is_finite()
            && camera.fov_y.is_finite()
            && camera.aperture_radius.is_finite();
        if !finite || film.width == 0 || film.height == 0 {
            return None;
        }
        if !(camera.fov_y > 0.0 && camera.fov_y < std::f32::consts::PI) {
            return None;
        }
        if camera.aperture_radius < 0.0
            || (camera.aperture_radius > 0.0
                && !(camera.focus_distance > 0.0 && camera.focus_distance.is_finite()))
        {
            return None;
        }
        let forward = (camera.look_at - camera.position).try_normalize()?;
        let right = forward.cross(camera.up).try_normalize()?;
        let up = right.cross(forward);
        Some(Self {
            position: camera.position,
            forward,
            right,
            up,
            tan_half_fov_y: (0.5 * camera.fov_y).tan(),
            aspect: film.width as f32 / film.height as f32,
            width: film.width as f32,
            height: film.height as f32,
            aperture_radius: camera.aperture_radius,
            focus_distance: camera.focus_distance,
        })
    }

    /// The primary ray through the film position `film` (in pixels), using the lens sample `u_lens`
    /// in [0, 1)² for a thin lens (ignored by a pinhole). Points on the focus plane are sharp.
    #[inline]
    pub fn generate_ray(&self, film: Vec2, u_lens: Vec2) -> Ray {
        let sx = (2.0 * film.x / self.width - 1.0) * self.tan_half_fov_y * self.aspect;
        let sy = (1.0 - 2.0 * film.y / self.height) * self.tan_half_fov_y;
        // Direction with unit component along `forward`.
        let d = self.forward + sx * self.right + sy * self.up;
        if self.aperture_radius > 0.0 {
            let focus = self.position + d * self.focus_distance;
            let lens = self.aperture_radius * concentric_disk(u_lens);
            let origin = self.position + lens.x * self.right + lens.y * self.up;
            Ray::infinite(origin, focus - origin)
        } else {
            Ray::infinite(self.position, d)
        }
    }

    /// The film position (in pixels) where `point` appears through the lens centre, or `None` if it is
    /// behind the camera or outside the film.
    pub fn project(&self, point: Vec3) -> Option<Vec2> {
        let (film, _) = self.film_point(point)?;
        let inside =
            film.x >= 0.0 && film.x <= self.width && film.y >= 0.0 && film.y <= self.height;
        inside.then_some(film)
    }

    /// The film position (in pixels, possibly off the film) where `point` appears through the
    /// lens centre, and its depth along the view direction; `None` if it is not in front of the
    /// camera.
    pub fn film_point(&self, point: Vec3) -> Option<(Vec2, f32)> {
        let v = point - self.position;
        let z = v.dot(self.forward);
        if z.is_nan() || z <= 0.0 {
            return None;
        }
        let sx = v.dot(self.right) / z / (self.tan_half_fov_y * self.aspect);
        let sy = v.dot(self.up) / z / self.tan_half_fov_y;
        let film = Vec2::new(
            0.5 * (sx + 1.0) * self.width,
            0.5 * (1.0 - sy) * self.height,
        );
        Some((film, z))
    }

    /// Film pixels per unit area of a surface at `point` with normal `normal`, as seen through
    /// the lens centre: F²·|n·(c − x)| / ((x − c)·forward)³ with F the focal length in pixels
    /// (`height / (2 tan(fov_y/2))`), i.e. (du/dω)·|cos θₓ|/d², the density of one camera sample
    /// per pixel on that surface. `0` behind the camera. Light tracing multiplies a photon's
    /// reflected flux by it (for a pinhole), and its MIS weight against photon merging compares
    /// it with the kernel's area.
    #[inline]
    pub fn film_density(&self, point: Vec3, normal: Vec3) -> f32 {
        let v = self.position - point;
        let z = -v.dot(self.forward);
        if z.is_nan() || z <= 0.0 {
            return 0.0;
        }
        let f = self.focal_pixels();
        f * f * normal.dot(v).abs() / (z * z * z)
    }

    /// The focal length in pixels: the distance from the lens to the film plane in units of
    /// one pixel's side.
    #[inline]
    pub fn focal_pixels(&self) -> f32 {
        0.5 * self.height / self.tan_half_fov_y
    }

    /// A light-tracing connection from `point` to the lens (the lens sample `u_lens` in [0, 1)²,
    /// ignored by a pinhole): the film position the ray from the lens point through `point`
    /// lands on, the lens point, and `du/dω / d²` of that ray (F² / (cos³θ · d²), θ from the
    /// view axis, d the distance), so that flux reflected toward the lens with |cos θₓ| at
    /// `point` lands on the film as (du/dω)·|cos θₓ|/d² per unit area. `None` if the point is
    /// behind the lens plane or its film position is off the film.
    pub fn connect(&self, point: Vec3, u_lens: Vec2) -> Option<LensConnection> {
        let lens = if self.aperture_radius > 0.0 {
            let l = self.aperture_radius * concentric_disk(u_lens);
            self.position + l.x * self.right + l.y * self.up
        } else {
            self.position
        };
        let d = point - lens;
        let z = d.dot(self.forward);
        if z.is_nan() || z <= 0.0 {
            return None;
        }
        // Where the ray lens → point crosses the focus plane (for a pinhole, any plane), seen
        // through the lens centre.
        let through = if self.aperture_radius > 0.0 {
            lens + d * (self.focus_distance / z)
        } else {
            point
        };
        let film = self.project(through)?;
        let distance2 = d.length_squared();
        let cos = z / distance2.sqrt();
        let f = self.focal_pixels();
        let density = f * f / (cos * cos * cos * distance2);
        density.is_finite().then_some(LensConnection {
            film,
            lens,
            density,
        })
    }

    /// Eye position (centre of the lens).
    pub fn position(&self) -> Vec3 {
        self.position
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// Lens radius (0 for a pinhole).
    pub fn aperture_radius(&self) -> f32 {
        self.aperture_radius
    }

    /// Film width and height in pixels.
    pub fn resolution(&self) -> (u32, u32) {
        (self.width as u32, self.height as u32)
    }
}
