//! Photon and hitpoint storage with range queries for progressive photon mapping.
//!
//! The principal type is [`HitPointGrid`]: a spatial hash over the hitpoints' gather spheres
//! that answers, for a photon at p, "which hitpoints x with radius R satisfy |p − x| ≤ R", exactly
//! and in a deterministic order. Hitpoints live in [`HitPoints`], a structure of arrays whose
//! progressive statistics (radius R, photon count N, flux τ) are `f64` and whose frequency state
//! is a generic column the integrator chooses. [`accepts`] adds the side and normal tests that
//! keep photons from the back of a thin wall out of a hitpoint's estimate, and [`gather()`] runs a
//! photon pass in parallel while summing every hitpoint's contributions in photon order, so the
//! result is bit-identical for any thread count.
//!
//! The crate knows nothing about passes, BSDFs or scenes: the `ppm` crate drives it.
//!
//! ```
//! use glam::Vec3;
//! use photon::{GridParams, HitPointGrid};
//!
//! let positions = [Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0)];
//! let radii = [0.5, 0.25];
//! let grid = HitPointGrid::build(&positions, &radii, GridParams::DEFAULT);
//! let mut found = Vec::new();
//! grid.for_each_containing(Vec3::new(0.9, 0.0, 0.0), |idx| found.push(idx));
//! assert_eq!(found, [1]);
//! ```

mod gather;
mod grid;
mod hitpoints;
mod morton;
mod photon;

pub use crate::gather::{GatherScratch, Gathered, gather, gather_with};
pub use crate::grid::{CellSize, GridParams, GridStats, HitPointGrid};
pub use crate::hitpoints::{HitPointColumnsMut, HitPoints, NewHitPoint};
pub use crate::morton::{MortonScratch, morton_order, morton_sort};
pub use crate::photon::{AcceptParams, Photon, accepts, faces, within_radius};
