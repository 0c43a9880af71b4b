//! Checkpoints: the exact state of a [`Renderer`], as bytes.
//!
//! Layout (little-endian): the magic `FPPMSTAT`, the format version, a fingerprint of the scene,
//! a caller's note (the CLI stores the scene path there), the parameters, the pass count, then
//! the integrator's columns as one zstd frame (preceded by their uncompressed length), and a
//! 64-bit checksum of everything before it. The columns are floats that vary from slot to slot,
//! yet zstd's fastest level shrinks them about threefold at a few hundred megabytes a second, so
//! that a checkpoint costs little more to write than to copy. Restoring gives a
//! renderer whose next passes are bit-identical to those of the renderer that was saved; the
//! hash grid is not stored (it is rebuilt, and gathers do not depend on its layout).

use glam::Vec3;
use photon::{HitPoints, NewHitPoint};
use scene::Scene;
use spectrum::{FrequencyEstimate, MergePolicy, Spectrum};

use crate::params::{Method, ParamError, RenderParams};
use crate::path::PathTracer;
use crate::photon_mapper::{MAX_PHOTON_BUDGET, PhotonMapper, SavedState, SlotFrequency};
use crate::renderer::{Engine, Renderer};
use crate::update::FrequencyFloor;

const MAGIC: &[u8; 8] = b"FPPMSTAT";
/// Version of the checkpoint layout; bump it whenever the layout or the meaning of a field
/// changes, so that old checkpoints are refused rather than misread.
pub const STATE_VERSION: u32 = 7;
/// zstd level of the columns: the fastest; higher levels gain a few per cent for several times
/// the time.
const ZSTD_LEVEL: i32 = 1;

/// Why a checkpoint could not be restored.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StateError {
    /// The bytes do not start with the checkpoint magic.
    #[error("not an fppm checkpoint")]
    NotACheckpoint,
    /// A checkpoint of another format version.
    #[error("checkpoint format version {found}, this fppm reads version {STATE_VERSION}")]
    Version {
        /// The version in the file.
        found: u32,
    },
    /// The checkpoint was made for a different scene (or a changed scene file).
    #[error(
        "checkpoint was made for another scene (fingerprint {found:016x}, this scene {expected:016x})"
    )]
    SceneMismatch {
        /// Fingerprint stored in the checkpoint.
        found: u64,
        /// Fingerprint of the scene given.
        expected: u64,
    },
    /// The file ends early or its checksum does not match.
    #[error("checkpoint is truncated or corrupt")]
    Corrupt,
    /// The stored parameters are invalid.
    #[error("checkpoint parameters are invalid: {0}")]
    Params(#[from] ParamError),
}

/// Checkpoint surgery for tests and fuzzing: a checkpoint cut into its head (magic, version,
/// fingerprint, note, parameters, pass count) and its decompressed columns, and put back
/// together with a correct length, compression and checksum, so that a test can change one
/// field and see the parser refuse it.
#[doc(hidden)]
pub mod surgery {
    use super::{FNV_OFFSET, Reader, ZSTD_LEVEL, fnv1a, read_header};

    /// The head and the decompressed columns of `bytes`; `None` if they are not a checkpoint
    /// of this version.
    #[must_use]
    pub fn split(bytes: &[u8]) -> Option<(Vec<u8>, Vec<u8>)> {
        let mut r = Reader::new(bytes).ok()?;
        read_header(&mut r).ok()?;
        let head_len = bytes.len() - 8 - r.rest.len();
        let length = usize::try_from(r.u64().ok()?).ok()?;
        let body = zstd::bulk::decompress(r.rest, length).ok()?;
        Some((bytes[..head_len].to_vec(), body))
    }

    /// The checkpoint made of `head` and the columns `body`.
    #[must_use]
    pub fn join(head: &[u8], body: &[u8]) -> Vec<u8> {
        let mut out = head.to_vec();
        out.extend_from_slice(&(body.len() as u64).to_le_bytes());
        out.extend_from_slice(&zstd::bulk::compress(body, ZSTD_LEVEL).unwrap_or_default());
        let checksum = fnv1a(FNV_OFFSET, &out);
        out.extend_from_slice(&checksum.to_le_bytes());
        out
    }
}

/// What a checkpoint says about itself, readable without the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct StateHeader {
    /// The note given to [`Renderer::save_state`].
    pub note: String,
    /// The render parameters.
    pub params: RenderParams,
    /// Passes completed.
    pub passes: u32,
    /// Fingerprint of the scene ([`scene::SceneDescription::fingerprint`]).
    pub scene_fingerprint: u64,
}

impl StateHeader {
    /// Reads the header of a checkpoint.
    ///
    /// # Errors
    ///
    /// [`StateError`] if the bytes are not a checkpoint of this version or are corrupt.
    pub fn read(bytes: &[u8]) -> Result<Self, StateError> {
        let mut reader = Reader::new(bytes)?;
        read_header(&mut reader)
    }
}

impl<'s> Renderer<'s> {
    /// The exact state of this render, with a free-form `note` (e.g. the scene path) stored
    /// alongside; see [`Renderer::restore`].
    #[must_use]
    pub fn save_state(&self, note: &str) -> Vec<u8> {
        let mut w = Writer::default();
        w.bytes(MAGIC);
        w.u32(STATE_VERSION);
        w.u64(self.scene.description().fingerprint());
        w.str(note);
        write_params(&mut w, self.params());
        w.u32(self.passes());
        let mut body = Writer::default();
        match &self.engine {
            Engine::Photons(p) if p.params().method.is_pass_independent() => {
                write_independent(&mut body, p);
            }
            Engine::Photons(p) => write_photon_mapper(&mut body, p),
            Engine::Path(p) => {
                body.u64(p.sum.len() as u64);
                for s in &p.sum {
                    s.iter().for_each(|&v| body.f64(v));
                }
            }
        }
        w.u64(body.out.len() as u64);
        // Compressing bytes in memory fails only if zstd cannot allocate, which aborts anyway.
        let compressed = zstd::bulk::compress(&body.out, ZSTD_LEVEL).unwrap_or_else(|e| {
            unreachable!("zstd cannot compress a checkpoint held in memory: {e}")
        });
        w.bytes(&compressed);
        let checksum = fnv1a(FNV_OFFSET, &w.out);
        w.u64(checksum);
        w.out
    }

    /// The renderer saved by [`Renderer::save_state`], for `scene`. Its next passes are
    /// bit-identical to those the saved renderer would have run.
    ///
    /// # Errors
    ///
    /// [`StateError`] if the bytes are not a checkpoint of this version, are corrupt, or were
    /// made for another scene.
    pub fn restore(scene: &'s Scene, bytes: &[u8]) -> Result<Self, StateError> {
        let mut r = Reader::new(bytes)?;
        let header = read_header(&mut r)?;
        let expected = scene.description().fingerprint();
        if header.scene_fingerprint != expected {
            return Err(StateError::SceneMismatch {
                found: header.scene_fingerprint,
                expected,
            });
        }
        let mut renderer = Renderer::new(scene, header.params)?;
        // The columns can be no longer than those of a full film: a bound known before
        // anything is decompressed, so that no checkpoint, however made, makes us allocate more.
        let most = match &renderer.engine {
            Engine::Photons(p) if header.params.method.is_pass_independent() => {
                let (width, height) = renderer.resolution();
                independent_body_bound(width as usize * height as usize, p.n_slots())
            }
            Engine::Photons(p) => photon_mapper_body_bound(p.n_slots()),
            Engine::Path(p) => 8 + p.sum.len().saturating_mul(24),
        };
        let length = usize::try_from(r.u64()?).map_err(|_| StateError::Corrupt)?;
        if length > most {
            return Err(StateError::Corrupt);
        }
        let body = zstd::bulk::decompress(r.rest, length).map_err(|_| StateError::Corrupt)?;
        if body.len() != length {
            return Err(StateError::Corrupt);
        }
        let mut r = Reader { rest: &body };
        match &mut renderer.engine {
            Engine::Photons(p) if header.params.method.is_pass_independent() => {
                read_independent(&mut r, p, header.passes)?;
            }
            Engine::Photons(p) => read_photon_mapper(&mut r, p, header.passes)?,
            Engine::Path(p) => read_path_tracer(&mut r, p, header.passes)?,
        }
        if !r.rest.is_empty() {
            return Err(StateError::Corrupt);
        }
        Ok(renderer)
    }
}

fn read_header(r: &mut Reader<'_>) -> Result<StateHeader, StateError> {
    if r.take(8)? != MAGIC {
        return Err(StateError::NotACheckpoint);
    }
    let found = r.u32()?;
    if found != STATE_VERSION {
        return Err(StateError::Version { found });
    }
    let scene_fingerprint = r.u64()?;
    let note = r.str()?;
    let params = read_params(r)?;
    params.validate()?;
    let passes = r.u32()?;
    // The pass counter is a u32: a checkpoint after which no pass can be counted is corrupt.
    if passes == u32::MAX {
        return Err(StateError::Corrupt);
    }
    Ok(StateHeader {
        note,
        params,
        passes,
        scene_fingerprint,
    })
}

fn write_params(w: &mut Writer, p: &RenderParams) {
    w.str(p.method.name());
    w.u32(p.photons_per_pass);
    w.f64(p.alpha);
    w.f64(p.initial_radius.unwrap_or(-1.0));
    w.u32(p.max_depth);
    w.u32(p.rr_depth);
    w.u32(p.samples_per_pixel);
    w.u64(p.seed);
    w.f64(p.freq_fraction);
    w.u32(match p.freq_merge {
        MergePolicy::MinRadius => 0,
        MergePolicy::PosterMax => 1,
    });
    w.f64(p.kernel_k);
    w.u32(match p.freq_floor {
        FrequencyFloor::Keep => 0,
        FrequencyFloor::Clamp => 1,
    });
    w.u32(u32::from(p.direct_lighting));
    w.u32(u32::from(p.freq_occlusion));
    w.u32(u32::from(p.freq_geometry));
    w.f64(p.freq_grow);
    w.f64(p.freq_hold_alpha);
    w.u32(p.freq_pilot);
    w.u32(u32::from(p.freq_clear_cap));
    w.u32(u32::from(p.light_tracing));
    w.u32(u32::from(p.freq_probe_share));
}

fn read_params(r: &mut Reader<'_>) -> Result<RenderParams, StateError> {
    let method = Method::from_name(&r.str()?).ok_or(StateError::Corrupt)?;
    let photons_per_pass = r.u32()?;
    let alpha = r.f64()?;
    let initial_radius = r.f64()?;
    let max_depth = r.u32()?;
    let rr_depth = r.u32()?;
    let samples_per_pixel = r.u32()?;
    let seed = r.u64()?;
    let freq_fraction = r.f64()?;
    let freq_merge = match r.u32()? {
        0 => MergePolicy::MinRadius,
        1 => MergePolicy::PosterMax,
        _ => return Err(StateError::Corrupt),
    };
    let kernel_k = r.f64()?;
    let freq_floor = match r.u32()? {
        0 => FrequencyFloor::Keep,
        1 => FrequencyFloor::Clamp,
        _ => return Err(StateError::Corrupt),
    };
    let direct_lighting = r.bool()?;
    let freq_occlusion = r.bool()?;
    let freq_geometry = r.bool()?;
    let freq_grow = r.f64()?;
    let freq_hold_alpha = r.f64()?;
    let freq_pilot = r.u32()?;
    let freq_clear_cap = r.bool()?;
    let light_tracing = r.bool()?;
    let freq_probe_share = r.bool()?;
    Ok(RenderParams {
        method,
        photons_per_pass,
        alpha,
        initial_radius: (initial_radius >= 0.0).then_some(initial_radius),
        max_depth,
        rr_depth,
        samples_per_pixel,
        seed,
        freq_fraction,
        freq_merge,
        kernel_k,
        freq_floor,
        freq_occlusion,
        freq_geometry,
        direct_lighting,
        freq_grow,
        freq_hold_alpha,
        freq_pilot,
        freq_clear_cap,
        light_tracing,
        freq_probe_share,
    })
}

/// The most bytes [`write_independent`] writes.
fn independent_body_bound(pixels: usize, n_slots: usize) -> usize {
    8 + 8 + pixels.saturating_mul(48) + 8 + n_slots.saturating_mul(8)
}

/// The pass-independent estimator: its exact sums and its kernels (nothing else carries from
/// pass to pass). Before the first pass (no kernels yet) both are empty.
fn write_independent(w: &mut Writer, p: &PhotonMapper<'_>) {
    let empty = crate::PassSums::default();
    let sums = p.pass_sums().unwrap_or(&empty);
    w.u64(sums.passes);
    w.u64(sums.sums.len() as u64);
    for s in &sums.sums {
        for v in s {
            w.bytes(&v.to_le_bytes());
        }
    }
    let kernels = p.kernels().unwrap_or(&[]);
    w.u64(kernels.len() as u64);
    kernels.iter().for_each(|&r| w.f64(r));
}

fn read_independent(
    r: &mut Reader<'_>,
    p: &mut PhotonMapper<'_>,
    passes: u32,
) -> Result<(), StateError> {
    let summed = r.u64()?;
    let n = usize::try_from(r.u64()?).map_err(|_| StateError::Corrupt)?;
    let mut sums = Vec::with_capacity(n.min(r.rest.len() / 48));
    for _ in 0..n {
        let mut s = [0i128; 3];
        for v in &mut s {
            *v = i128::from_le_bytes(r.array()?);
        }
        sums.push(s);
    }
    let k = usize::try_from(r.u64()?).map_err(|_| StateError::Corrupt)?;
    let mut kernels = Vec::with_capacity(k.min(r.rest.len() / 8));
    for _ in 0..k {
        kernels.push(r.f64()?);
    }
    if k == 0 && n == 0 && summed == 0 {
        return Ok(());
    }
    if k != p.n_slots()
        || summed != u64::from(passes)
        || !kernels.iter().all(|r| r.is_finite() && *r > 0.0)
    {
        return Err(StateError::Corrupt);
    }
    let pixels = p.n_slots() / p.params().samples_per_pixel as usize;
    if n != pixels {
        return Err(StateError::Corrupt);
    }
    p.set_independent(
        kernels,
        crate::PassSums {
            passes: summed,
            sums,
        },
        passes,
    );
    Ok(())
}

/// Bytes of a slot's record in [`write_photon_mapper`], with a spectrum.
const SLOT_RECORD_MAX: usize = 5 * 12 + 4 + 4 + 8 + 8 + 24 + 4 + 4 + 4 + 4 + 32 + 4 + 4 + 24;

/// The most bytes [`write_photon_mapper`] writes for `n_slots` slots.
fn photon_mapper_body_bound(n_slots: usize) -> usize {
    8 + 4 + 8 + n_slots.saturating_mul(SLOT_RECORD_MAX)
}

fn write_photon_mapper(w: &mut Writer, p: &PhotonMapper<'_>) {
    w.u64(p.photons_emitted());
    w.u32(p.camera_passes());
    let s = p.slots();
    let spp = p.params().samples_per_pixel as usize;
    w.u64(s.len() as u64);
    for i in 0..s.len() {
        for v in [
            s.position()[i],
            s.shading_normal()[i],
            s.geometric_normal()[i],
            s.outgoing()[i],
            s.weight()[i],
        ] {
            v.to_array().iter().for_each(|&c| w.f32(c));
        }
        w.u32(s.material_idx()[i]);
        // The pixel is redundant (slot / spp) and checked on reading.
        w.u32((i / spp) as u32);
        w.f64(s.radius()[i]);
        w.f64(s.photon_count()[i]);
        s.flux()[i].iter().for_each(|&c| w.f64(c));
        let freq = s.freq()[i];
        let estimate = freq.estimate();
        w.u32(u32::from(estimate.has_freq()));
        w.f32(freq.normal_distance());
        w.u32(u32::from(freq.clear_level()));
        match estimate.spectrum() {
            None => w.u32(0),
            Some(spectrum) => {
                w.u32(1);
                spectrum.to_bits().iter().for_each(|&b| w.u64(b));
            }
        }
        // An invalid slot stores the budget of a camera path without bounces.
        let budget = p.photon_budget(i);
        w.u32(u32::from(budget.is_some()));
        w.u32(budget.map_or(p.params().max_depth - 1, u32::from));
        p.direct(i).iter().for_each(|&c| w.f64(c));
    }
}

fn read_photon_mapper(
    r: &mut Reader<'_>,
    p: &mut PhotonMapper<'_>,
    passes: u32,
) -> Result<(), StateError> {
    let n_emitted = r.u64()?;
    let camera_passes = r.u32()?;
    // Every pass emits `photons_per_pass` and runs at most one camera pass; the photon indices
    // of the next pass start at `n_emitted`.
    if n_emitted != u64::from(passes) * u64::from(p.params().photons_per_pass)
        || camera_passes > passes
    {
        return Err(StateError::Corrupt);
    }
    let n = usize::try_from(r.u64()?).map_err(|_| StateError::Corrupt)?;
    if n != p.n_slots() && n != 0 {
        return Err(StateError::Corrupt);
    }
    let spp = p.params().samples_per_pixel as usize;
    let mut slots = HitPoints::with_capacity(n);
    let mut stats = Vec::with_capacity(n);
    let mut photon_budget = Vec::with_capacity(n);
    let mut direct = Vec::with_capacity(n);
    for i in 0..n {
        let mut v = [Vec3::ZERO; 5];
        for item in &mut v {
            *item = Vec3::new(r.f32()?, r.f32()?, r.f32()?);
        }
        let material_idx = r.u32()?;
        if r.u32()? as usize != i / spp {
            return Err(StateError::Corrupt);
        }
        let radius = r.f64()?;
        // Every slot of a saved renderer has a positive radius (the update rule divides by it).
        if !(radius.is_finite() && radius > 0.0) {
            return Err(StateError::Corrupt);
        }
        let photon_count = r.f64()?;
        let flux = [r.f64()?, r.f64()?, r.f64()?];
        let has_freq = r.bool()?;
        let normal_distance = r.f32()?;
        let clear_level = u8::try_from(r.u32()?).map_err(|_| StateError::Corrupt)?;
        let spectrum = match r.u32()? {
            0 => None,
            1 => Some(
                Spectrum::from_bits([r.u64()?, r.u64()?, r.u64()?, r.u64()?])
                    .ok_or(StateError::Corrupt)?,
            ),
            _ => return Err(StateError::Corrupt),
        };
        if has_freq != spectrum.is_some() {
            return Err(StateError::Corrupt);
        }
        let valid = r.bool()?;
        let budget = u16::try_from(r.u32()?)
            .ok()
            .filter(|&b| b <= MAX_PHOTON_BUDGET)
            .ok_or(StateError::Corrupt)?;
        photon_budget.push(valid.then_some(budget));
        direct.push([r.f64()?, r.f64()?, r.f64()?]);
        slots.push(NewHitPoint {
            position: v[0],
            shading_normal: v[1],
            geometric_normal: v[2],
            outgoing: v[3],
            weight: v[4],
            material_idx,
            radius,
            freq: SlotFrequency::restored(
                FrequencyEstimate::from_spectrum(spectrum),
                normal_distance,
                clear_level,
                v[3].dot(v[1]).abs(),
            ),
        });
        stats.push((photon_count, flux));
    }
    let columns = slots.columns_mut();
    for (i, (photon_count, flux)) in stats.into_iter().enumerate() {
        columns.photon_count[i] = photon_count;
        columns.flux[i] = flux;
    }
    p.restore(
        passes,
        SavedState {
            n_emitted,
            camera_passes,
            slots,
            photon_budget,
            direct,
        },
    );
    Ok(())
}

fn read_path_tracer(
    r: &mut Reader<'_>,
    p: &mut PathTracer<'_>,
    passes: u32,
) -> Result<(), StateError> {
    let n = usize::try_from(r.u64()?).map_err(|_| StateError::Corrupt)?;
    if n != p.sum.len() {
        return Err(StateError::Corrupt);
    }
    for s in &mut p.sum {
        *s = [r.f64()?, r.f64()?, r.f64()?];
    }
    p.passes = passes;
    Ok(())
}

pub(crate) const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

pub(crate) fn fnv1a(mut hash: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        hash ^= u64::from(b);
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

/// Little-endian encoder.
#[derive(Default)]
struct Writer {
    out: Vec<u8>,
}

impl Writer {
    fn bytes(&mut self, b: &[u8]) {
        self.out.extend_from_slice(b);
    }
    fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.bytes(&v.to_bits().to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.bytes(&v.to_bits().to_le_bytes());
    }
    fn str(&mut self, s: &str) {
        self.u64(s.len() as u64);
        self.bytes(s.as_bytes());
    }
}

struct Reader<'a> {
    rest: &'a [u8],
}

impl<'a> Reader<'a> {
    /// A reader over the payload of `bytes`, after checking the trailing checksum.
    fn new(bytes: &'a [u8]) -> Result<Self, StateError> {
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(StateError::NotACheckpoint);
        }
        let split = bytes.len().checked_sub(8).ok_or(StateError::Corrupt)?;
        let (payload, checksum) = bytes.split_at(split);
        let stored = u64::from_le_bytes(checksum.try_into().map_err(|_| StateError::Corrupt)?);
        if fnv1a(FNV_OFFSET, payload) != stored {
            // A version mismatch is the more useful message when the header can be read.
            if payload.len() >= 12 {
                let found = u32::from_le_bytes([payload[8], payload[9], payload[10], payload[11]]);
                if found != STATE_VERSION {
                    return Err(StateError::Version { found });
                }
            }
            return Err(StateError::Corrupt);
        }
        Ok(Self { rest: payload })
    }
    fn take(&mut self, n: usize) -> Result<&'a [u8], StateError> {
        if self.rest.len() < n {
            return Err(StateError::Corrupt);
        }
        let (head, tail) = self.rest.split_at(n);
        self.rest = tail;
        Ok(head)
    }
    fn array<const N: usize>(&mut self) -> Result<[u8; N], StateError> {
        self.take(N)?.try_into().map_err(|_| StateError::Corrupt)
    }
    fn u32(&mut self) -> Result<u32, StateError> {
        Ok(u32::from_le_bytes(self.array()?))
    }
    fn u64(&mut self) -> Result<u64, StateError> {
        Ok(u64::from_le_bytes(self.array()?))
    }
    fn f32(&mut self) -> Result<f32, StateError> {
        Ok(f32::from_bits(self.u32()?))
    }
    fn f64(&mut self) -> Result<f64, StateError> {
        Ok(f64::from_bits(self.u64()?))
    }
    fn bool(&mut self) -> Result<bool, StateError> {
        match self.u32()? {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(StateError::Corrupt),
        }
    }
    fn str(&mut self) -> Result<String, StateError> {
        let n = usize::try_from(self.u64()?).map_err(|_| StateError::Corrupt)?;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|_| StateError::Corrupt)
    }
}
