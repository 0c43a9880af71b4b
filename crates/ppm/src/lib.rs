//! Progressive photon mapping integrators: not yet built; filled by the issue
//! "`photon` and `ppm`: PPM, SPPM and frequency-guided PPM".

mod rng;
mod update;

pub use crate::rng::Sampler;
pub use crate::update::{FrequencyFloor, FrequencyRadius, GatherStats};
