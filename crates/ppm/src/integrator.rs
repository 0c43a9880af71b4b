//! The interface every integrator implements, so that [`crate::Renderer`] (and the checkpoint
//! code) never asks which method it runs. Each integrator is a module of its own (`path.rs`,
//! `photon_mapper/`, `independent/`) and is registered once, in `methods.rs`.

use crate::aov::Aov;
use crate::checkpoint::codec::{Reader, StateError, Writer};
use crate::independent::sums::PassSums;
use crate::params::RenderParams;
use crate::stats::{MemoryUse, PassStats};

/// A progressive render by one integrator: its state between passes, its passes, its image.
///
/// Every random number it draws is a function of (seed, pass, sample index, dimension), and
/// it reduces in a fixed order, so that its image does not depend on the thread count; its
/// saved state restores a render whose next passes are bit-identical.
pub(crate) trait Integrator: Send {
    /// The parameters it runs with.
    fn params(&self) -> &RenderParams;

    /// Passes completed so far.
    fn passes(&self) -> u32;

    /// Photons emitted over all passes so far (0 for integrators without photons).
    fn photons_emitted(&self) -> u64 {
        0
    }

    /// Runs one pass and returns its statistics.
    fn iterate(&mut self) -> PassStats;

    /// The current estimate: linear RGB radiance per pixel (the average over the pixel's
    /// square), row-major from the top-left.
    fn image(&self) -> Vec<[f32; 3]>;

    /// An auxiliary image of its own (radius, photon count, frequency radius, held share),
    /// `width × height` values; `None` if it has no such quantity. The first-hit AOVs
    /// (albedo, normal, depth) are the renderer's.
    fn aov(&self, _aov: Aov) -> Option<Vec<f32>> {
        None
    }

    /// Heap memory of its state and pass buffers, by part; `None` where it is only the image.
    fn memory(&self) -> Option<MemoryUse> {
        None
    }

    /// Writes the state that carries from one pass to the next (not the parameters or the
    /// pass count, which the checkpoint's header holds).
    fn save(&self, w: &mut Writer);

    /// The most bytes [`Integrator::save`] can write for this film and these parameters: a
    /// bound known before a checkpoint is decompressed, so that no checkpoint, however made,
    /// makes the reader allocate more.
    fn saved_bound(&self) -> usize;

    /// Takes back the state [`Integrator::save`] wrote after `passes` passes, checking every
    /// value a later pass relies on.
    ///
    /// # Errors
    /// [`StateError::Corrupt`] if the state does not fit this film and these parameters.
    fn restore(&mut self, r: &mut Reader<'_>, passes: u32) -> Result<(), StateError>;

    /// The exact sums of its pass images, for an integrator whose passes are independent.
    fn pass_sums(&self) -> Option<&PassSums> {
        None
    }

    /// Its per-slot kernels, for an integrator whose passes are independent.
    fn kernels(&self) -> Option<&[f64]> {
        None
    }
}
