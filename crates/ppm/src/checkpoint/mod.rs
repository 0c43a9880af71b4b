//! Checkpoints: the exact state of a [`Renderer`], as bytes.
//!
//! Layout (little-endian, `codec.rs`): the magic `FPPMSTAT`, the format version, a
//! fingerprint of the scene ([`scene::SceneDescription::fingerprint`]), a caller's note (the
//! CLI stores the scene path there), the parameters as `(name, value)` texts of [`PARAMS`],
//! the pass count, then the integrator's own state ([`Integrator::save`]) as one zstd frame
//! (preceded by its uncompressed length), and a 64-bit checksum of everything before it. The
//! state is mostly floats that vary from slot to slot, yet zstd's fastest level shrinks it
//! about threefold at a few hundred megabytes a second, so that a checkpoint costs little more
//! to write than to copy. Restoring gives a renderer whose next passes are bit-identical to
//! those of the renderer that was saved. Nothing here knows which integrator runs: a new
//! integrator writes and reads its own state, and a new parameter is a line of [`PARAMS`].
//!
//! [`Integrator::save`]: crate::integrator::Integrator::save

pub(crate) mod codec;

use std::sync::Arc;

use scene::Scene;

use self::codec::{Reader, Writer, checksum};
pub use self::codec::{STATE_VERSION, StateError};
use crate::params::{PARAMS, RenderParams};
use crate::renderer::Renderer;

const MAGIC: &[u8; 8] = b"FPPMSTAT";
/// zstd level of the state: the fastest; higher levels gain a few per cent for several times
/// the time.
const ZSTD_LEVEL: i32 = 1;

/// Checkpoint surgery for tests and fuzzing: a checkpoint cut into its head (magic, version,
/// fingerprint, note, parameters, pass count) and its decompressed state, and put back
/// together with a correct length, compression and checksum, so that a test can change one
/// field and see the parser refuse it.
#[doc(hidden)]
pub mod surgery {
    use super::{ZSTD_LEVEL, checksum, open, read_header};

    /// The head and the decompressed state of `bytes`; `None` if they are not a checkpoint
    /// of this version.
    #[must_use]
    pub fn split(bytes: &[u8]) -> Option<(Vec<u8>, Vec<u8>)> {
        let mut r = open(bytes).ok()?;
        read_header(&mut r).ok()?;
        let head_len = bytes.len() - 8 - r.rest.len();
        let length = usize::try_from(r.u64().ok()?).ok()?;
        let body = zstd::bulk::decompress(r.rest, length).ok()?;
        Some((bytes[..head_len].to_vec(), body))
    }

    /// The checkpoint made of `head` and the state `body`.
    #[must_use]
    pub fn join(head: &[u8], body: &[u8]) -> Vec<u8> {
        let mut out = head.to_vec();
        out.extend_from_slice(&(body.len() as u64).to_le_bytes());
        out.extend_from_slice(&zstd::bulk::compress(body, ZSTD_LEVEL).unwrap_or_default());
        let sum = checksum(&out);
        out.extend_from_slice(&sum.to_le_bytes());
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
        let mut reader = open(bytes)?;
        read_header(&mut reader)
    }
}

impl Renderer {
    /// The exact state of this render, with a free-form `note` (e.g. the scene path) stored
    /// alongside; see [`Renderer::restore`].
    #[must_use]
    pub fn save_state(&self, note: &str) -> Vec<u8> {
        let mut w = Writer::default();
        w.bytes(MAGIC);
        w.u32(STATE_VERSION);
        w.u64(self.scene().description().fingerprint());
        w.str(note);
        write_params(&mut w, self.params());
        w.u32(self.passes());
        let mut body = Writer::default();
        self.integrator.save(&mut body);
        w.u64(body.out.len() as u64);
        // Compressing bytes in memory fails only if zstd cannot allocate, which aborts anyway.
        let compressed = zstd::bulk::compress(&body.out, ZSTD_LEVEL).unwrap_or_else(|e| {
            unreachable!("zstd cannot compress a checkpoint held in memory: {e}")
        });
        w.bytes(&compressed);
        let sum = checksum(&w.out);
        w.u64(sum);
        w.out
    }

    /// The renderer saved by [`Renderer::save_state`], for `scene`. Its next passes are
    /// bit-identical to those the saved renderer would have run.
    ///
    /// # Errors
    ///
    /// [`StateError`] if the bytes are not a checkpoint of this version, are corrupt, or were
    /// made for another scene.
    pub fn restore(scene: impl Into<Arc<Scene>>, bytes: &[u8]) -> Result<Self, StateError> {
        let scene = scene.into();
        let mut r = open(bytes)?;
        let header = read_header(&mut r)?;
        let expected = scene.description().fingerprint();
        if header.scene_fingerprint != expected {
            return Err(StateError::SceneMismatch {
                found: header.scene_fingerprint,
                expected,
            });
        }
        let mut renderer = Renderer::new(scene, header.params)?;
        // The state can be no longer than that of a full film: a bound known before anything
        // is decompressed, so that no checkpoint, however made, makes us allocate more.
        let length = r.len()?;
        if length > renderer.integrator.saved_bound() {
            return Err(StateError::Corrupt);
        }
        let body = zstd::bulk::decompress(r.rest, length).map_err(|_| StateError::Corrupt)?;
        if body.len() != length {
            return Err(StateError::Corrupt);
        }
        let mut r = Reader::new(&body);
        renderer.integrator.restore(&mut r, header.passes)?;
        if !r.rest.is_empty() {
            return Err(StateError::Corrupt);
        }
        Ok(renderer)
    }
}

/// A reader over the payload of `bytes`, after checking the magic and the trailing checksum.
fn open(bytes: &[u8]) -> Result<Reader<'_>, StateError> {
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        return Err(StateError::NotACheckpoint);
    }
    let split = bytes.len().checked_sub(8).ok_or(StateError::Corrupt)?;
    let (payload, sum) = bytes.split_at(split);
    let stored = u64::from_le_bytes(sum.try_into().map_err(|_| StateError::Corrupt)?);
    if checksum(payload) != stored {
        // A version mismatch is the more useful message when the header can be read.
        if payload.len() >= 12 {
            let found = u32::from_le_bytes([payload[8], payload[9], payload[10], payload[11]]);
            if found != STATE_VERSION {
                return Err(StateError::Version { found });
            }
        }
        return Err(StateError::Corrupt);
    }
    Ok(Reader::new(payload))
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

/// The parameters as `(name, value)` texts, every one of [`PARAMS`] in its order: the one
/// table that names, reads and shows them, so that a new parameter needs no line here.
fn write_params(w: &mut Writer, p: &RenderParams) {
    let entries = p.entries();
    w.u64(entries.len() as u64);
    for (name, value) in entries {
        w.str(name);
        w.str(&value);
    }
}

/// The parameters [`write_params`] wrote: each of [`PARAMS`] exactly once, by name, read by
/// [`RenderParams::set`]; anything else is a corrupt checkpoint.
fn read_params(r: &mut Reader<'_>) -> Result<RenderParams, StateError> {
    let n = r.u64()?;
    if n != PARAMS.len() as u64 {
        return Err(StateError::Corrupt);
    }
    let mut params = RenderParams::preview();
    let mut seen = [false; PARAMS.len()];
    for _ in 0..n {
        let name = r.str()?;
        let value = r.str()?;
        let i = PARAMS
            .iter()
            .position(|p| p.name == name)
            .ok_or(StateError::Corrupt)?;
        if std::mem::replace(&mut seen[i], true) {
            return Err(StateError::Corrupt);
        }
        params.set(&name, &value).map_err(|_| StateError::Corrupt)?;
    }
    Ok(params)
}
