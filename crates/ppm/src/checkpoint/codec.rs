//! The encoding every part of a checkpoint uses: little-endian numbers and length-prefixed
//! strings ([`Writer`], [`Reader`]), the checksum, and the errors of reading them back. The
//! checkpoint's framing is in `checkpoint/mod.rs`; each integrator writes and reads its own
//! state with these.

use scene::fingerprint::Fingerprinter;

use crate::params::ParamError;

/// Version of the checkpoint layout; bump it whenever the layout or the meaning of a field
/// changes, so that old checkpoints are refused rather than misread.
pub const STATE_VERSION: u32 = 13;

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

/// The checksum of a checkpoint or a work unit's part: FNV-1a of the bytes.
pub(crate) fn checksum(bytes: &[u8]) -> u64 {
    let mut h = Fingerprinter::new();
    h.bytes(bytes);
    h.finish()
}

/// Little-endian encoder.
#[derive(Default)]
pub(crate) struct Writer {
    pub(crate) out: Vec<u8>,
}

impl Writer {
    pub(crate) fn bytes(&mut self, b: &[u8]) {
        self.out.extend_from_slice(b);
    }
    pub(crate) fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }
    pub(crate) fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }
    pub(crate) fn f32(&mut self, v: f32) {
        self.bytes(&v.to_bits().to_le_bytes());
    }
    pub(crate) fn f64(&mut self, v: f64) {
        self.bytes(&v.to_bits().to_le_bytes());
    }
    pub(crate) fn str(&mut self, s: &str) {
        self.u64(s.len() as u64);
        self.bytes(s.as_bytes());
    }
}

/// Little-endian decoder: every read past the end, and every value out of its domain, is
/// [`StateError::Corrupt`].
pub(crate) struct Reader<'a> {
    pub(crate) rest: &'a [u8],
}

impl<'a> Reader<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Self { rest: bytes }
    }
    pub(crate) fn take(&mut self, n: usize) -> Result<&'a [u8], StateError> {
        if self.rest.len() < n {
            return Err(StateError::Corrupt);
        }
        let (head, tail) = self.rest.split_at(n);
        self.rest = tail;
        Ok(head)
    }
    pub(crate) fn array<const N: usize>(&mut self) -> Result<[u8; N], StateError> {
        self.take(N)?.try_into().map_err(|_| StateError::Corrupt)
    }
    pub(crate) fn u32(&mut self) -> Result<u32, StateError> {
        Ok(u32::from_le_bytes(self.array()?))
    }
    pub(crate) fn u64(&mut self) -> Result<u64, StateError> {
        Ok(u64::from_le_bytes(self.array()?))
    }
    /// A `u64` length or count as a `usize`.
    pub(crate) fn len(&mut self) -> Result<usize, StateError> {
        usize::try_from(self.u64()?).map_err(|_| StateError::Corrupt)
    }
    pub(crate) fn f32(&mut self) -> Result<f32, StateError> {
        Ok(f32::from_bits(self.u32()?))
    }
    pub(crate) fn f64(&mut self) -> Result<f64, StateError> {
        Ok(f64::from_bits(self.u64()?))
    }
    pub(crate) fn bool(&mut self) -> Result<bool, StateError> {
        match self.u32()? {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(StateError::Corrupt),
        }
    }
    pub(crate) fn str(&mut self) -> Result<String, StateError> {
        let n = self.len()?;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|_| StateError::Corrupt)
    }
}
