//! The parts of the fuzz harness that need neither libFuzzer nor `arbitrary`: the stub files
//! served for the files a fuzzed scene refers to, and the checkpoint framing. `xtask` includes
//! this file too (`xtask/src/fuzz.rs`), to build the checkpoint seeds with the same framing and
//! to test, in the normal test suite, that the stubs load.

use std::io;
use std::path::{Path, PathBuf};

/// Directory of the fuzzed scene files (nothing is read from the disk: it need not exist).
pub const DIR: &str = "/fuzz";

/// A quad with normals and one emissive material from its MTL, served for every `.obj`.
pub const STUB_OBJ: &str = include_str!("../stubs/stub.obj");
/// The MTL served for every `.mtl`.
pub const STUB_MTL: &str = include_str!("../stubs/stub.mtl");
/// One triangle with its buffer in a data URI, served for every `.gltf` or `.glb`.
pub const STUB_GLTF: &str = include_str!("../stubs/stub.gltf");
/// An ASCII PLY triangle, served for every `.ply`.
pub const STUB_PLY: &str = include_str!("../stubs/stub.ply");
/// A spectrum, served for every `.spd` (Mitsuba).
pub const STUB_SPD: &str = include_str!("../stubs/stub.spd");
/// The pbrt scene of the `ply` target: a camera, a point light and `mesh.ply` (the fuzzed file).
pub const PLY_SCENE: &str = include_str!("../stubs/ply_scene.pbrt");
/// The fixed scene of the `checkpoint` target (and of its seeds).
pub const CHECKPOINT_SCENE: &str = include_str!("../stubs/checkpoint_scene.toml");

/// The path of the fuzzed file `name` in [`DIR`].
#[must_use]
pub fn fuzzed(name: &str) -> PathBuf {
    Path::new(DIR).join(name)
}

/// A resolver serving `main` as `path` and a stub for every other file by its extension
/// (`.obj`, `.mtl`, `.gltf`, `.glb`, `.ply`, `.spd`); anything else is not found.
pub fn with_stubs(path: PathBuf, main: Vec<u8>) -> impl Fn(&Path) -> io::Result<Vec<u8>> + 'static {
    move |p: &Path| {
        if p == path {
            return Ok(main.clone());
        }
        let extension = p
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        let stub = match extension.as_deref() {
            Some("obj") => STUB_OBJ,
            Some("mtl") => STUB_MTL,
            Some("gltf" | "glb") => STUB_GLTF,
            Some("ply") => STUB_PLY,
            Some("spd") => STUB_SPD,
            _ => return Err(io::ErrorKind::NotFound.into()),
        };
        Ok(stub.as_bytes().to_vec())
    }
}

/// Splits `data` at its first NUL byte: (before, after); all of it and nothing without one.
#[must_use]
pub fn split_nul(data: &[u8]) -> (&[u8], &[u8]) {
    match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &[]),
    }
}

/// The scene of the `checkpoint` target.
///
/// # Panics
///
/// If [`CHECKPOINT_SCENE`] does not load (a bug of the harness, caught by xtask's tests).
#[must_use]
pub fn checkpoint_scene() -> geometry::Scene {
    let description = geometry::load_toml_str(CHECKPOINT_SCENE, &fuzzed("checkpoint_scene.toml"))
        .expect("the checkpoint scene loads");
    geometry::Scene::new(description).expect("the checkpoint scene builds")
}

/// Bytes of a checkpoint before the fuzzed body: magic, format version, scene fingerprint.
pub const CHECKPOINT_HEADER: usize = 8 + 4 + 8;

/// A checkpoint of `scene` whose body (after [`CHECKPOINT_HEADER`], before the checksum) is
/// `body`: the header and the FNV-1a checksum are made right so that the fuzzer's mutations
/// reach the parser of the body instead of failing the checksum.
#[must_use]
pub fn checkpoint_bytes(scene: &geometry::Scene, body: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(CHECKPOINT_HEADER + body.len() + 8);
    out.extend_from_slice(b"FPPMSTAT");
    out.extend_from_slice(&ppm::STATE_VERSION.to_le_bytes());
    out.extend_from_slice(&ppm::scene_fingerprint(scene.description()).to_le_bytes());
    out.extend_from_slice(body);
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in &out {
        hash ^= u64::from(b);
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    out.extend_from_slice(&hash.to_le_bytes());
    out
}

/// The body of a checkpoint as the `checkpoint` target takes it: `saved` without its header
/// and checksum.
#[must_use]
pub fn checkpoint_body(saved: &[u8]) -> &[u8] {
    &saved[CHECKPOINT_HEADER..saved.len() - 8]
}
