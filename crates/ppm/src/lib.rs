//! Progressive photon mapping integrators: PPM (Hachisuka, Ogaki & Jensen 2008), SPPM
//! (Hachisuka & Jensen 2009) and their frequency-guided variants (Belcour & Soler 2011), behind
//! one progressive API.
//!
//! The principal type is [`Renderer`]: build it from a [`scene::Scene`] and
//! [`RenderParams`], call [`Renderer::iterate`] once per pass (each returns [`PassStats`]) and
//! read [`Renderer::image`] whenever you like.
//!
//! One pass runs four phases. The camera pass follows each hitpoint slot's camera path through
//! specular bounces to the first non-specular surface (once for PPM, every pass for SPPM). A hash
//! grid is built over the hitpoint spheres. Photons are traced from the emitters in fixed chunks;
//! a share of them (frequency photons) also carry the local light-field spectrum
//! [`spectrum::Spectrum`], updated at every travel, reflection and refraction. Photons are gathered
//! into the hitpoints in Morton order, and frequency photons deposit the spectrum each hitpoint
//! turns into a kernel radius r_freq. Finally each hitpoint folds the pass into its radius R,
//! count N and flux τ ([`GatherStats::update`]): it shrinks as in PPM while R > r_freq and keeps
//! its radius otherwise.
//!
//! Determinism: every random number is a function of (seed, pass, photon or slot index,
//! dimension) ([`Sampler`]), and every sum is taken in a fixed order, so an image is
//! bit-identical for any number of threads.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let description = import::load(std::path::Path::new("scene.toml"))?;
//! let scene = std::sync::Arc::new(scene::Scene::new(description)?);
//! let mut params = ppm::RenderParams::preview();
//! params.method = ppm::Method::FreqPpm;
//! let mut renderer = ppm::Renderer::new(std::sync::Arc::clone(&scene), params)?;
//! for _ in 0..10 {
//!     let stats = renderer.iterate();
//!     assert_eq!(stats.photons_traced, 100_000);
//! }
//! let pixels: Vec<[f32; 3]> = renderer.image();
//! # let _ = pixels;
//! # Ok(())
//! # }
//! ```

mod aov;
mod checkpoint;
mod disc;
mod independent;
mod integrator;
mod light_path;
mod light_tracer;
mod methods;
mod params;
mod path;
mod photon_mapper;
mod pointwise;
mod renderer;
mod rng;
mod stats;
mod update;
mod vcm;

pub use crate::aov::Aov;
#[doc(hidden)]
pub use crate::checkpoint::surgery as checkpoint_surgery;
pub use crate::checkpoint::{STATE_VERSION, StateError, StateHeader};
pub use crate::independent::{Part, PartError, PassSums};
pub use crate::params::{
    Budget, CameraSequence, Connections, FilmSampling, FrequencyParams, Kernel, Method, PARAMS,
    Param, ParamError, ParamKind, PoolMode, Pooling, RenderParams, param,
};
pub use crate::photon_mapper::{auto_initial_radius, bytes_per_hitpoint};
pub use crate::pointwise::{pointwise_reference, pointwise_reference_paths};
pub use crate::renderer::Renderer;
pub use crate::rng::Sampler;
pub use crate::stats::{MemoryEstimate, MemoryUse, PassStats, PassTimings};
pub use crate::update::{FrequencyFloor, FrequencyRadius, GatherStats};
pub use spectrum::{K_POSTER, K_STRICT, MergePolicy};
