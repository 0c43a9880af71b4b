//! Stable fingerprints: a 64-bit hash of what a value means for rendering, the same on every
//! machine and in every run (FNV-1a over little-endian bytes; not `std::hash`, whose values may
//! change between Rust versions and runs). Each description type says what it contributes next
//! to its definition ([`Fingerprint`]); [`crate::SceneDescription::fingerprint`] combines them,
//! so that a checkpoint is never resumed on another scene.

use glam::{Mat3, Vec2, Vec3};

/// FNV-1a's offset basis.
const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
/// FNV-1a's prime.
const PRIME: u64 = 0x0000_0100_0000_01b3;

/// An FNV-1a hash in progress, fed with little-endian encodings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fingerprinter {
    hash: u64,
}

impl Default for Fingerprinter {
    fn default() -> Self {
        Self::new()
    }
}

impl Fingerprinter {
    /// An empty hash.
    #[must_use]
    pub fn new() -> Self {
        Self { hash: OFFSET }
    }

    /// The hash of everything fed so far.
    #[must_use]
    pub fn finish(&self) -> u64 {
        self.hash
    }

    /// Feeds raw bytes.
    pub fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.hash ^= u64::from(b);
            self.hash = self.hash.wrapping_mul(PRIME);
        }
    }

    /// Feeds a `u32`.
    pub fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }

    /// Feeds a `u64`.
    pub fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }

    /// Feeds an `f32` by its bits.
    pub fn f32(&mut self, v: f32) {
        self.u32(v.to_bits());
    }

    /// Feeds a string with its length first.
    pub fn str(&mut self, s: &str) {
        self.u64(s.len() as u64);
        self.bytes(s.as_bytes());
    }

    /// Feeds a 2-vector.
    pub fn vec2(&mut self, v: Vec2) {
        v.to_array().iter().for_each(|&c| self.f32(c));
    }

    /// Feeds a 3-vector.
    pub fn vec3(&mut self, v: Vec3) {
        v.to_array().iter().for_each(|&c| self.f32(c));
    }

    /// Feeds a 3 × 3 matrix, column by column.
    pub fn mat3(&mut self, m: Mat3) {
        m.to_cols_array().iter().for_each(|&c| self.f32(c));
    }

    /// Feeds a value's own contribution.
    pub fn add(&mut self, value: &(impl Fingerprint + ?Sized)) {
        value.fingerprint(self);
    }

    /// Feeds whether `value` is there, then what `add` feeds of it.
    pub fn option<T>(&mut self, value: Option<T>, add: impl FnOnce(&mut Self, T)) {
        match value {
            None => self.u32(0),
            Some(v) => {
                self.u32(1);
                add(self, v);
            }
        }
    }

    /// Feeds a slice: its length, then each element.
    pub fn list<T: Fingerprint>(&mut self, values: &[T]) {
        self.u64(values.len() as u64);
        values.iter().for_each(|v| v.fingerprint(self));
    }
}

/// What a value contributes to a fingerprint: everything about it that affects rendering, in a
/// fixed order.
pub trait Fingerprint {
    /// Feeds the value into `h`.
    fn fingerprint(&self, h: &mut Fingerprinter);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn it_is_fnv1a() {
        // FNV-1a's published test vectors (Fowler, Noll and Vo).
        let hash = |s: &str| {
            let mut h = Fingerprinter::new();
            h.bytes(s.as_bytes());
            h.finish()
        };
        assert_eq!(hash(""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(hash("a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(hash("foobar"), 0x8594_4171_f739_67e8);
    }
}
