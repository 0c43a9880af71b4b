//! The parts of the fuzz harness that need neither libFuzzer nor `arbitrary`: the stub files
//! served for the files a fuzzed scene refers to, the fixed scenes of the texture and
//! environment-map targets, and the framing of checkpoints, checkpoint columns and work-unit
//! parts. `xtask` includes this file too (`xtask/src/fuzz.rs`), to build the seeds with the same
//! framing and to test, in the normal test suite, that the stubs and seeds load.

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
/// The TOML scene of the `vol` target: a sphere of smoke whose grid is `smoke.vol` (the
/// fuzzed file).
pub const VOL_SCENE: &str = include_str!("../stubs/vol_scene.toml");
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
pub fn checkpoint_scene() -> std::sync::Arc<scene::Scene> {
    let description = import::load_toml_str(CHECKPOINT_SCENE, &fuzzed("checkpoint_scene.toml"))
        .expect("the checkpoint scene loads");
    std::sync::Arc::new(scene::Scene::new(description).expect("the checkpoint scene builds"))
}

/// Bytes of a checkpoint before the fuzzed body: magic, format version, scene fingerprint.
pub const CHECKPOINT_HEADER: usize = 8 + 4 + 8;

/// A checkpoint of `scene` whose body (after [`CHECKPOINT_HEADER`], before the checksum) is
/// `body`: the header and the FNV-1a checksum are made right so that the fuzzer's mutations
/// reach the parser of the body instead of failing the checksum.
#[must_use]
pub fn checkpoint_bytes(scene: &scene::Scene, body: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(CHECKPOINT_HEADER + body.len() + 8);
    out.extend_from_slice(b"FPPMSTAT");
    out.extend_from_slice(&ppm::STATE_VERSION.to_le_bytes());
    out.extend_from_slice(&scene.description().fingerprint().to_le_bytes());
    out.extend_from_slice(body);
    let hash = fnv1a(&out);
    out.extend_from_slice(&hash.to_le_bytes());
    out
}

/// The body of a checkpoint as the `checkpoint` target takes it: `saved` without its header
/// and checksum.
#[must_use]
pub fn checkpoint_body(saved: &[u8]) -> &[u8] {
    &saved[CHECKPOINT_HEADER..saved.len() - 8]
}

/// The fixed scene of the `texture` target: its images are all the fuzzed file.
pub const TEXTURE_SCENE: &str = include_str!("../stubs/texture_scene.toml");
/// The fixed scene of the `envmap` target: a floor under an environment map `sky.exr`.
pub const ENVMAP_SCENE: &str = include_str!("../stubs/envmap_scene.toml");

/// The scene of the `texture` target, whose every image (whatever its name) is `image`.
pub fn texture_files(image: Vec<u8>) -> (PathBuf, impl Fn(&Path) -> io::Result<Vec<u8>> + 'static) {
    let scene = fuzzed("texture_scene.toml");
    let served = scene.clone();
    (scene, move |p: &Path| {
        if p == served {
            Ok(TEXTURE_SCENE.as_bytes().to_vec())
        } else {
            Ok(image.clone())
        }
    })
}

/// The scene of the `envmap` target with `image` served as its map, `sky.hdr` (Radiance) if
/// `hdr`, else `sky.exr`.
pub fn envmap_files(
    image: Vec<u8>,
    hdr: bool,
) -> (PathBuf, impl Fn(&Path) -> io::Result<Vec<u8>> + 'static) {
    let scene = fuzzed("envmap_scene.toml");
    let served = scene.clone();
    let text = if hdr {
        ENVMAP_SCENE.replace("sky.exr", "sky.hdr")
    } else {
        ENVMAP_SCENE.to_owned()
    };
    (scene, move |p: &Path| {
        if p == served {
            Ok(text.as_bytes().to_vec())
        } else if p
            .file_name()
            .is_some_and(|n| n == "sky.exr" || n == "sky.hdr")
        {
            Ok(image.clone())
        } else {
            Err(io::ErrorKind::NotFound.into())
        }
    })
}

/// The pbrt scene of the `envmap` target's mode 3: an `infinite` light of `sky.exr`.
pub const ENVMAP_PBRT_SCENE: &str = include_str!("../stubs/envmap_scene.pbrt");

/// [`ENVMAP_PBRT_SCENE`] with `image` served as its (square, equal-area) map.
pub fn envmap_pbrt_files(
    image: Vec<u8>,
) -> (PathBuf, impl Fn(&Path) -> io::Result<Vec<u8>> + 'static) {
    let scene = fuzzed("envmap_scene.pbrt");
    let served = scene.clone();
    (scene, move |p: &Path| {
        if p == served {
            Ok(ENVMAP_PBRT_SCENE.as_bytes().to_vec())
        } else if p.file_name().is_some_and(|n| n == "sky.exr") {
            Ok(image.clone())
        } else {
            Err(io::ErrorKind::NotFound.into())
        }
    })
}

/// The plan fingerprint the `part` target reads its parts for.
pub const PART_PLAN: u64 = 0x5eed_f022_0000_0019;

/// Bytes of a part's header after the magic, version and plan: unit, first pass, passes,
/// pixels.
pub const PART_FIELDS: usize = 4 + 4 + 8 + 8;

/// The part file the `part` target reads, and the film size (pixels) it reads it for, from the
/// fuzzer's input: `[mode, pixels, rest...]`, the film `1 + pixels % 32` pixels.
///
/// - mode 0 (mod 3): `rest` is the part file as it is (checksum included);
/// - mode 1: `rest` is a part's fields ([`PART_FIELDS`]) and its compressed sums; the magic,
///   version, plan and checksum are made right so that mutations reach the decompression;
/// - mode 2: `rest` is the fields and the *decompressed* sums (48 bytes a pixel, cut to whole
///   pixels), written by [`ppm::Part::to_bytes`], so that mutations reach the sums themselves;
///   the stored pixel count is the input's, the sums' count what the bytes hold.
#[must_use]
pub fn part_bytes(data: &[u8]) -> (Vec<u8>, usize) {
    let (mode, pixels, rest) = match data {
        [mode, pixels, rest @ ..] => (*mode, 1 + usize::from(*pixels) % 32, rest),
        _ => return (data.to_vec(), 1),
    };
    let bytes = match mode % 3 {
        0 => rest.to_vec(),
        1 => {
            let mut out = Vec::with_capacity(20 + rest.len() + 8);
            out.extend_from_slice(b"FPPMPART");
            out.extend_from_slice(&1u32.to_le_bytes());
            out.extend_from_slice(&PART_PLAN.to_le_bytes());
            out.extend_from_slice(rest);
            let hash = fnv1a(&out);
            out.extend_from_slice(&hash.to_le_bytes());
            out
        }
        _ => {
            let mut fields = [0u8; PART_FIELDS];
            let n = rest.len().min(PART_FIELDS);
            fields[..n].copy_from_slice(&rest[..n]);
            let u32_at =
                |i: usize| u32::from_le_bytes(fields[i..i + 4].try_into().unwrap_or_default());
            let u64_at =
                |i: usize| u64::from_le_bytes(fields[i..i + 8].try_into().unwrap_or_default());
            let sums = rest[n..]
                .chunks_exact(48)
                .map(|pixel| {
                    let mut s = [0i128; 3];
                    for (c, b) in pixel.chunks_exact(16).enumerate() {
                        s[c] = i128::from_le_bytes(b.try_into().unwrap_or_default());
                    }
                    s
                })
                .collect();
            let part = ppm::Part {
                plan: PART_PLAN,
                unit: u32_at(0),
                first_pass: u32_at(4),
                sums: ppm::PassSums {
                    passes: u64_at(8),
                    sums,
                },
            };
            let mut bytes = part.to_bytes();
            // The stored pixel count is the input's (bytes 16..24 of the fields), so that a
            // count that disagrees with the sums is fuzzed too; the checksum is made right.
            bytes.truncate(bytes.len() - 8);
            bytes[20 + 16..20 + 24].copy_from_slice(&fields[16..24]);
            let hash = fnv1a(&bytes);
            bytes.extend_from_slice(&hash.to_le_bytes());
            bytes
        }
    };
    (bytes, pixels)
}

/// The input of the `part` target (mode 2) for a part of `pixels` pixels: what the seeds are.
#[must_use]
pub fn part_input(part: &ppm::Part, pixels: u8) -> Vec<u8> {
    let mut out = vec![2, pixels];
    out.extend_from_slice(&part.unit.to_le_bytes());
    out.extend_from_slice(&part.first_pass.to_le_bytes());
    out.extend_from_slice(&part.sums.passes.to_le_bytes());
    out.extend_from_slice(&(part.sums.sums.len() as u64).to_le_bytes());
    for s in &part.sums.sums {
        for v in s {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// FNV-1a, the checksum of checkpoints and parts.
fn fnv1a(bytes: &[u8]) -> u64 {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        hash ^= u64::from(b);
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

/// The parameters of the seed checkpoints of `method`: tiny passes, a short depth.
#[must_use]
pub fn checkpoint_params(method: ppm::Method) -> ppm::RenderParams {
    let mut params = ppm::RenderParams::preview();
    params.method = method;
    params.budget.photons_per_pass = 64;
    params.budget.max_depth = 8;
    params
}

/// Checkpoints of the `checkpoint` target's scene split into their head and decompressed
/// columns ([`ppm::checkpoint_surgery::split`]): one per method, after one and after two
/// passes, named `method-passes`. The `checkpoint_columns` target joins its input's columns to
/// one of these heads, and its seeds are these columns.
///
/// # Panics
///
/// If a checkpoint just saved does not split (a bug of the harness or of the library).
#[must_use]
pub fn column_checkpoints(scene: &std::sync::Arc<scene::Scene>) -> Vec<(String, Vec<u8>, Vec<u8>)> {
    let mut out = Vec::new();
    for method in ppm::Method::ALL {
        let Ok(mut renderer) =
            ppm::Renderer::new(std::sync::Arc::clone(scene), checkpoint_params(method))
        else {
            continue;
        };
        for pass in 1..=2 {
            renderer.iterate();
            let saved = renderer.save_state("seed");
            let (head, columns) =
                ppm::checkpoint_surgery::split(&saved).expect("a checkpoint just saved splits");
            out.push((format!("{}-{pass}", method.name()), head, columns));
        }
    }
    out
}
