//! What the fuzz targets share: the stub files served for the files a fuzzed scene refers to,
//! the fixed scene of the checkpoint target, and the checks run on whatever loads.
//!
//! Every target reads its input in memory (no temporary files): scenes through
//! [`geometry::load_from`] with a resolver closure, checkpoints and EXRs from byte slices.

use std::io;
use std::path::{Path, PathBuf};

use geometry::{LoadOptions, Scene, SceneDescription};

/// Directory of the fuzzed scene files (nothing is read from the disk: it need not exist).
pub const DIR: &str = "/fuzz";

/// A small OBJ served for every `.obj` a fuzzed scene names: a quad with normals, one
/// material from its MTL.
pub const STUB_OBJ: &str = "mtllib stub.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
vn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nusemtl lamp\nf 1//1 2//2 3//3 4//4\n";

/// The MTL served for every `.mtl`: one emissive material.
pub const STUB_MTL: &str = "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\n";

/// A small glTF served for every `.gltf` or `.glb`: one triangle, its buffer in a data URI.
pub const STUB_GLTF: &str = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
"bufferViews":[{"buffer":0,"byteLength":36}],
"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]}"#;

/// An ASCII PLY served for every `.ply`: one triangle.
pub const STUB_PLY: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n\
end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

/// A `.spd` spectrum served for every `.spd` (Mitsuba).
pub const STUB_SPD: &str = "400 0.5\n500 0.6\n600 0.7\n700 0.8\n";

/// The pbrt scene of the `ply` target: a camera, a point light and `mesh.ply` (the fuzzed file).
pub const PLY_SCENE: &str = r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
WorldBegin
LightSource "point" "rgb I" [ 10 10 10 ] "point3 from" [ 0 0 4 ]
Shape "plymesh" "string filename" [ "mesh.ply" ]
"#;

/// The fixed scene of the `checkpoint` target (also the scene of its seeds).
pub const CHECKPOINT_SCENE: &str = include_str!("../seeds/checkpoint_scene.toml");

/// The path of the fuzzed file `name` in [`DIR`].
#[must_use]
pub fn fuzzed(name: &str) -> PathBuf {
    Path::new(DIR).join(name)
}

/// A resolver serving `main` as `path` and a stub for every other file by its extension
/// (`.obj`, `.mtl`, `.gltf`, `.glb`, `.ply`, `.spd`); anything else is not found.
pub fn with_stubs(
    path: PathBuf,
    main: Vec<u8>,
) -> impl Fn(&Path) -> io::Result<Vec<u8>> + 'static {
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

/// Loads `path` from `files` and, if it loads, builds the [`Scene`] (validation, lights, BVH)
/// and summarises it: what every loader target runs.
pub fn load_and_build(path: &Path, files: impl geometry::FileSource + 'static) {
    let Ok(description) = geometry::load_from(path, files, &LoadOptions::allow_no_emitter())
    else {
        return;
    };
    build(description);
}

/// Summarises a description and builds its scene; errors are fine, panics are not.
pub fn build(description: SceneDescription) -> Option<Scene> {
    let _ = description.summary();
    Scene::new(description).ok()
}

/// The scene of the `checkpoint` target.
///
/// # Panics
///
/// If [`CHECKPOINT_SCENE`] does not load (a bug of the fuzz crate, caught by its tests).
#[must_use]
pub fn checkpoint_scene() -> Scene {
    let description =
        geometry::load_toml_str(CHECKPOINT_SCENE, &fuzzed("checkpoint_scene.toml"))
            .expect("the checkpoint scene loads");
    Scene::new(description).expect("the checkpoint scene builds")
}

/// Bytes of a checkpoint layout before the fuzzed part: magic, format version, fingerprint.
pub const CHECKPOINT_HEADER: usize = 8 + 4 + 8;

/// A checkpoint of `scene` whose body (after [`CHECKPOINT_HEADER`], before the checksum) is
/// `body`: the header and the FNV-1a checksum are made right so that the fuzzer's mutations
/// reach the parser of the body instead of failing the checksum.
#[must_use]
pub fn checkpoint_bytes(scene: &Scene, body: &[u8]) -> Vec<u8> {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn loads(path: &Path, files: impl geometry::FileSource + 'static) -> SceneDescription {
        geometry::load_from(path, files, &LoadOptions::default())
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    }

    /// The stubs are real scenes: a harness that served broken stubs would fuzz error paths only.
    #[test]
    fn stubs_load() {
        let toml = "format = 1\n[[shapes]]\ntype = \"mesh\"\nfile = \"a.obj\"\n\
                    [[shapes]]\ntype = \"mesh\"\nfile = \"b.gltf\"\n";
        let path = fuzzed("scene.toml");
        let d = loads(&path, with_stubs(path.clone(), toml.into()));
        assert_eq!(d.triangles.len(), 3);
        let path = fuzzed("scene.pbrt");
        let d = loads(&path, with_stubs(path.clone(), PLY_SCENE.into()));
        assert_eq!(d.triangles.len(), 1);
        assert_eq!(d.lights.len(), 1);
    }

    #[test]
    fn checkpoint_of_the_fixed_scene_round_trips() {
        let scene = checkpoint_scene();
        let mut params = ppm::RenderParams::preview();
        params.photons_per_pass = 100;
        let mut renderer = ppm::Renderer::new(&scene, params).unwrap();
        renderer.iterate();
        let saved = renderer.save_state("seed");
        let body = &saved[CHECKPOINT_HEADER..saved.len() - 8];
        assert_eq!(checkpoint_bytes(&scene, body), saved);
        assert!(ppm::Renderer::restore(&scene, &saved).is_ok());
    }
}
