//! The 2D Gaussian light-transport algebra.

mod caps;
mod covariance;
mod emitters;
mod estimate;
mod lobe;
mod radius;
mod spectrum;

pub use caps::{Caps, MU_MIN};
pub use covariance::Covariance;
pub use estimate::{FrequencyEstimate, MergePolicy};
pub use lobe::Lobe;
pub use radius::{BETA_95, K_POSTER, K_STRICT, angular_radius, spatial_radius};
pub use spectrum::{PrimalCovariance, Spectrum, refracted_cosine};
