//! Wavefront OBJ + MTL through tobj, with the mapping of the scene format.
//!
//! MTL → material (checked in this order):
//! 1. `illum 5` → mirror with reflectance `Ks` (white if `Ks` is absent);
//! 2. `illum 4`, `6` or `7` → dielectric with ior `Ni` (1.5 if absent);
//! 3. `d` < 1 with `Ni` → dielectric with ior `Ni`;
//! 4. `Ks` ≥ 0.9 (largest channel) with `Ns` ≥ 1000 → mirror with reflectance `Ks`;
//! 5. any other `Ks` > 0 → glossy: reflectance `Ks`, GGX α = √(2 / (`Ns` + 2)), Lambertian base `Kd`;
//! 6. otherwise diffuse with albedo `Kd`.
//!
//! `Kd` defaults to [`DEFAULT_ALBEDO`] grey; `Ke` is the emission (none if absent). `Ka` is
//! ignored, with a warning when it looks like it was meant as emission (non-zero, no `Ke`, and
//! above 1 or different from `Kd`: the tinyobjloader Cornell box's light).
//!
//! A missing MTL file is never an error, only a warning: its faces get the default material
//! (diffuse, albedo [`DEFAULT_ALBEDO`]), as do faces whose `usemtl` names no loaded material
//! and faces without `usemtl`. An MTL file that exists but is malformed is an error.

use std::cell::RefCell;
use std::collections::BTreeSet;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::{MeshData, polygon};
use crate::error::LoadError;
use scene::texture::{Alpha, AlphaMode, MaterialTextures, NormalMap, TextureRef};
use scene::{Material, MaterialKind};

use crate::image_file::TextureCache;

/// Albedo of the default material and of MTL materials without `Kd`.
pub const DEFAULT_ALBEDO: f32 = 0.8;

/// Name of the default material.
pub(crate) const DEFAULT_MATERIAL_NAME: &str = "default";

fn tobj_options() -> tobj::LoadOptions {
    tobj::LoadOptions {
        triangulate: false,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    }
}

/// Loads an OBJ file and the MTL files it names.
pub(crate) fn load_obj(path: &Path) -> Result<MeshData, LoadError> {
    let text = super::read_text(path)?;
    let scan = prescan(path, &text)?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();

    let mtl_error: RefCell<Option<LoadError>> = RefCell::new(None);
    let warnings: RefCell<Vec<String>> = RefCell::new(Vec::new());
    let loaded = tobj::load_obj_buf(&mut Cursor::new(text.as_bytes()), &tobj_options(), |mtl| {
        let full = dir.join(mtl);
        match read_mtl(&full) {
            Ok(Some(result)) => result,
            Ok(None) => {
                warnings.borrow_mut().push(format!(
                    "material library {} not found: its materials use the default material",
                    mtl.display()
                ));
                Err(tobj::LoadError::OpenFileFailed)
            }
            Err(e) => {
                mtl_error.borrow_mut().get_or_insert(e);
                Err(tobj::LoadError::MaterialParseError)
            }
        }
    });
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let (models, materials) = loaded.map_err(|e| LoadError::Obj {
        path: path.to_path_buf(),
        line: find_error_line(&text),
        message: e.to_string(),
    })?;
    // A failed MTL load was either reported above (malformed) or warned about (missing).
    let tobj_materials = materials.unwrap_or_default();

    let mut data = MeshData {
        warnings: warnings.into_inner(),
        ..MeshData::default()
    };
    if scan.skipped_points_lines > 0 {
        data.warnings.push(format!(
            "{} point or line elements skipped (only faces are rendered)",
            scan.skipped_points_lines
        ));
    }
    let mut textures = TextureCache::default();
    for m in &tobj_materials {
        let mut material = mtl_material(m, &mut data.warnings);
        material.textures = mtl_textures(m, &dir, &mut textures, &mut data.warnings)?;
        data.materials.push(material);
    }
    let known: BTreeSet<&str> = tobj_materials.iter().map(|m| m.name.as_str()).collect();
    for name in scan.usemtl.iter().filter(|n| !known.contains(n.as_str())) {
        data.warnings.push(format!(
            "usemtl {name:?} names no loaded material: the default material is used"
        ));
    }

    let mut default_material: Option<u32> = None;
    for model in &models {
        let mesh = &model.mesh;
        let material = match mesh.material_id {
            Some(id) if id < data.materials.len() => id as u32,
            _ => *default_material.get_or_insert_with(|| {
                data.materials.push(default_material_value());
                (data.materials.len() - 1) as u32
            }),
        };
        if !mesh.normals.is_empty() && mesh.normals.len() != mesh.positions.len() {
            data.warnings.push(format!(
                "object {:?}: only some faces have vertex normals, so none are used (flat shading)",
                model.name
            ));
        }
        add_mesh(&mut data, mesh, material);
    }
    Ok(data)
}

/// The default material: diffuse grey.
pub(crate) fn default_material_value() -> Material {
    Material {
        name: DEFAULT_MATERIAL_NAME.to_owned(),
        kind: MaterialKind::Diffuse(scene::Diffuse {
            albedo: Vec3::splat(DEFAULT_ALBEDO),
        }),
        emission: Vec3::ZERO,
        textures: None,
        spectra: None,
    }
}

fn add_mesh(data: &mut MeshData, mesh: &tobj::Mesh, material: u32) {
    let vertex = |i: u32| -> Vec3 {
        let i = i as usize * 3;
        mesh.positions
            .get(i..i + 3)
            .map_or(Vec3::NAN, |p| Vec3::new(p[0], p[1], p[2]))
    };
    let has_normals = !mesh.normals.is_empty() && mesh.normals.len() == mesh.positions.len();
    let has_uv = !mesh.texcoords.is_empty() && mesh.texcoords.len() / 2 == mesh.positions.len() / 3;
    // OBJ puts v = 0 at the bottom of the image; texture coordinates here grow downwards.
    let uv = |i: u32| -> Vec2 {
        let i = i as usize * 2;
        mesh.texcoords
            .get(i..i + 2)
            .map_or(Vec2::ZERO, |t| Vec2::new(t[0], 1.0 - t[1]))
    };
    let normal = |i: u32| -> Vec3 {
        let i = i as usize * 3;
        mesh.normals
            .get(i..i + 3)
            .map_or(Vec3::NAN, |p| Vec3::new(p[0], p[1], p[2]))
    };
    let mut start = 0usize;
    let n_faces = if mesh.face_arities.is_empty() {
        mesh.indices.len() / 3
    } else {
        mesh.face_arities.len()
    };
    for face in 0..n_faces {
        let arity = mesh.face_arities.get(face).map_or(3, |&a| a as usize);
        let Some(indices) = mesh.indices.get(start..start + arity) else {
            break;
        };
        start += arity;
        if arity < 3 {
            continue;
        }
        let points: Vec<Vec3> = indices.iter().map(|&i| vertex(i)).collect();
        for tri in polygon::triangulate(&points) {
            let corner = tri.map(|k| indices[k]);
            let normals = has_normals.then(|| corner.map(normal));
            let uvs = has_uv
                .then(|| corner.map(uv))
                .filter(|t| t.iter().all(|v| v.is_finite()));
            data.push_triangle(corner.map(vertex), normals, uvs, None, material);
        }
    }
}

/// What a quick pass over the OBJ text finds before tobj parses it.
struct Prescan {
    usemtl: BTreeSet<String>,
    skipped_points_lines: usize,
}

/// Finds non-finite vertex coordinates (with their line), `usemtl` names and point/line
/// elements.
fn prescan(path: &Path, text: &str) -> Result<Prescan, LoadError> {
    let mut scan = Prescan {
        usemtl: BTreeSet::new(),
        skipped_points_lines: 0,
    };
    let mut totals = [0usize; 3];
    for line in text.lines() {
        if let Some(kind) = vertex_kind(line.split_whitespace().next()) {
            totals[kind] += 1;
        }
    }
    let mut so_far = [0usize; 3];
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let keyword = words.clone().next();
        if let Some(kind) = vertex_kind(keyword) {
            so_far[kind] += 1;
        }
        if matches!(keyword, Some("f" | "l")) {
            check_face_indices(path, line_number(i), line, so_far, totals)?;
        }
        match words.next() {
            Some("v") => {
                for word in words.take(3) {
                    if let Ok(x) = word.parse::<f32>()
                        && !x.is_finite()
                    {
                        return Err(LoadError::NonFiniteVertex {
                            path: path.to_path_buf(),
                            line: Some(line_number(i)),
                            what: if x.is_nan() { "nan" } else { "infinite" },
                        });
                    }
                }
            }
            Some("usemtl") => {
                let name = line.trim().split_once(' ').map_or("", |(_, n)| n.trim());
                if !name.is_empty() {
                    scan.usemtl.insert(name.to_owned());
                }
            }
            Some("l" | "p") => scan.skipped_points_lines += 1,
            Some("f") if words.count() < 3 => scan.skipped_points_lines += 1,
            _ => {}
        }
    }
    Ok(scan)
}

/// 0 for `v`, 1 for `vt`, 2 for `vn`.
fn vertex_kind(keyword: Option<&str>) -> Option<usize> {
    match keyword {
        Some("v") => Some(0),
        Some("vt") => Some(1),
        Some("vn") => Some(2),
        _ => None,
    }
}

/// Checks the texture and normal indices of a face or line element (`v/vt/vn`): not 0, a
/// relative (negative) index no further back than the first element of its kind, an absolute
/// one no larger than the file's count. tobj 4.0.5 turns them into array offsets without
/// checking for overflow (a relative index before the start wraps around and overflows when
/// scaled). Vertex indices need no check (tobj bounds them with saturating arithmetic and
/// reports them itself), nor do texture or normal indices when the file has none (tobj
/// ignores them then).
fn check_face_indices(
    path: &Path,
    line: u32,
    text: &str,
    so_far: [usize; 3],
    totals: [usize; 3],
) -> Result<(), LoadError> {
    const NAMES: [&str; 3] = ["", "texture coordinate", "normal"];
    for vertex in text.split_whitespace().skip(1) {
        for (kind, word) in vertex.split('/').enumerate().take(3) {
            if kind == 0 || word.is_empty() || totals[kind] == 0 {
                continue;
            }
            let Ok(index) = word.parse::<i64>() else {
                continue; // tobj reports what does not parse
            };
            let name = NAMES[kind];
            let problem = if index == 0 {
                Some(format!("{name} index 0 (OBJ indices start at 1)"))
            } else if index < 0 && index.unsigned_abs() > so_far[kind] as u64 {
                Some(format!(
                    "relative {name} index {index}, but only {} are defined before it",
                    so_far[kind]
                ))
            } else if index > 0 && index as u64 > totals[kind] as u64 {
                Some(format!(
                    "{name} index {index}, but the file defines {}",
                    totals[kind]
                ))
            } else {
                None
            };
            if let Some(message) = problem {
                return Err(LoadError::Obj {
                    path: path.to_path_buf(),
                    line: Some(line),
                    message,
                });
            }
        }
    }
    Ok(())
}

/// Finds the first line at which tobj fails, by bisection over prefixes of the text
/// (materials are not loaded meanwhile). `None` if no prefix fails on its own.
fn find_error_line(text: &str) -> Option<u32> {
    let lines: Vec<&str> = text.lines().collect();
    let fails = |k: usize| {
        let prefix = lines[..k].join("\n");
        tobj::load_obj_buf(&mut Cursor::new(prefix.as_bytes()), &tobj_options(), |_| {
            Ok((Vec::new(), Default::default()))
        })
        .is_err()
    };
    if !fails(lines.len()) {
        return None;
    }
    // Invariant: fails(hi), !fails(lo) (the empty text parses).
    let (mut lo, mut hi) = (0, lines.len());
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if fails(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(line_number(hi - 1))
}

/// 1-based line number of a 0-based line index.
fn line_number(index: usize) -> u32 {
    u32::try_from(index + 1).unwrap_or(u32::MAX)
}

/// Reads and checks an MTL file. `Ok(None)` if it does not exist.
fn read_mtl(path: &Path) -> Result<Option<tobj::MTLLoadResult>, LoadError> {
    let bytes = match super::files::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(source) => {
            return Err(LoadError::Io {
                path: path.to_path_buf(),
                source,
            });
        }
    };
    let text = String::from_utf8(bytes).map_err(|_| LoadError::NotUtf8 {
        path: path.to_path_buf(),
    })?;
    let fixed = check_mtl(path, &text)?;
    let result =
        tobj::load_mtl_buf(&mut Cursor::new(fixed.as_bytes())).map_err(|e| LoadError::Mtl {
            path: path.to_path_buf(),
            line: None,
            message: e.to_string(),
        })?;
    Ok(Some(Ok(result)))
}

/// Checks the MTL statements tobj reads, with line numbers, and expands the one-number colour
/// form (`Kd 0.5` means `Kd 0.5 0.5 0.5`), which tobj would not accept.
fn check_mtl(path: &Path, text: &str) -> Result<String, LoadError> {
    let error = |line: usize, message: String| LoadError::Mtl {
        path: PathBuf::from(path),
        line: Some(line_number(line - 1)),
        message,
    };
    let mut out = String::with_capacity(text.len() + 64);
    for (i, line) in text.lines().enumerate() {
        let code = line.split('#').next().unwrap_or("");
        let mut words = code.split_whitespace();
        let key = words.next();
        let values: Vec<&str> = words.collect();
        let numbers = || -> Option<Vec<f32>> { values.iter().map(|w| w.parse().ok()).collect() };
        match key {
            Some(k @ ("Ka" | "Kd" | "Ks" | "Ke")) => match numbers().as_deref() {
                Some([x]) => {
                    out.push_str(&format!("{k} {x} {x} {x}\n"));
                    continue;
                }
                Some([_, _, _]) => {}
                _ => {
                    return Err(error(
                        i + 1,
                        format!("{k} needs 1 or 3 numbers, got {:?}", values.join(" ")),
                    ));
                }
            },
            Some(k @ ("Ns" | "Ni" | "d")) if !matches!(numbers().as_deref(), Some([_])) => {
                return Err(error(
                    i + 1,
                    format!("{k} needs one number, got {:?}", values.join(" ")),
                ));
            }
            Some("illum") if !matches!(values.as_slice(), [v] if v.parse::<u8>().is_ok()) => {
                return Err(error(
                    i + 1,
                    format!(
                        "illum needs an integer from 0 to 10, got {:?}",
                        values.join(" ")
                    ),
                ));
            }
            Some("newmtl") if values.is_empty() => {
                return Err(error(i + 1, "newmtl needs a name".to_owned()));
            }
            _ => {}
        }
        out.push_str(code);
        out.push('\n');
    }
    Ok(out)
}

/// Maps one MTL material (see the module doc).
fn mtl_material(m: &tobj::Material, warnings: &mut Vec<String>) -> Material {
    let kd = m.diffuse.map_or(Vec3::splat(DEFAULT_ALBEDO), Vec3::from);
    let ks = m.specular.map(Vec3::from);
    let ns = m.shininess.unwrap_or(0.0);
    let emission = match m.emissive.map(Vec3::from) {
        // `map_Ke` alone means the texture is the emission.
        Some(e) if e != Vec3::ZERO => e,
        _ if m.unknown_param.contains_key("map_Ke") => Vec3::ONE,
        _ => Vec3::ZERO,
    };
    let illum = m.illumination_model;
    let dissolve = m.dissolve.unwrap_or(1.0);
    let kind = if illum == Some(5) {
        MaterialKind::Mirror(scene::Mirror {
            reflectance: ks.unwrap_or(Vec3::ONE),
        })
    } else if matches!(illum, Some(4 | 6 | 7)) {
        MaterialKind::Dielectric(scene::Dielectric {
            ior: m.optical_density.unwrap_or(1.5),
        })
    } else if let (true, Some(ior)) = (dissolve < 1.0, m.optical_density) {
        MaterialKind::Dielectric(scene::Dielectric { ior })
    } else {
        match ks {
            Some(ks) if ks.max_element() >= 0.9 && ns >= 1000.0 => {
                MaterialKind::Mirror(scene::Mirror { reflectance: ks })
            }
            Some(ks) if ks.max_element() > 0.0 => MaterialKind::Glossy(scene::Glossy {
                reflectance: ks,
                roughness: (2.0 / (ns.max(0.0) + 2.0)).sqrt(),
                diffuse: kd,
            }),
            _ => MaterialKind::Diffuse(scene::Diffuse { albedo: kd }),
        }
    };
    if let Some(ka) = m.ambient.map(Vec3::from)
        && emission.max_element() <= 0.0
        && ka.max_element() > 0.0
        && (ka.max_element() > 1.0 || ka != kd)
    {
        warnings.push(format!(
            "material {:?} has Ka {} but no Ke: Ka is ambient colour, not emission, so it emits nothing",
            m.name,
            super::fmt_vec(ka)
        ));
    }
    Material {
        name: m.name.clone(),
        kind,
        emission,
        textures: None,
        spectra: None,
    }
}

/// The file of a texture statement: its last word (options such as `-bm 1` come first).
fn texture_file(statement: &str) -> Option<&str> {
    statement.split_whitespace().last()
}

/// The textures of an MTL material: `map_Kd` multiplies the diffuse colour (the whole glossy
/// BSDF of a `Kd` + `Ks` material, see `docs/scene-format-extensions.md`), `map_Ke` the
/// emission, `map_d` cuts the surface out where it is below ½, and `norm` (or a `bump` /
/// `map_Bump` image that is a tangent-space normal map: mean blue above 0.7, mean red and green
/// within 0.1 of ½) perturbs the shading normal; a height `bump` map is ignored with a warning.
fn mtl_textures(
    m: &tobj::Material,
    dir: &Path,
    cache: &mut TextureCache,
    warnings: &mut Vec<String>,
) -> Result<Option<Arc<MaterialTextures>>, LoadError> {
    let mut load =
        |statement: Option<&String>, srgb: bool| -> Result<Option<TextureRef>, LoadError> {
            match statement.and_then(|s| texture_file(s)) {
                None => Ok(None),
                Some(file) => Ok(Some(TextureRef::new(cache.load(&dir.join(file))?, srgb))),
            }
        };
    let mut maps = MaterialTextures {
        color: load(m.diffuse_texture.as_ref(), true)?,
        emission: load(m.unknown_param.get("map_Ke"), true)?,
        ..MaterialTextures::default()
    };
    if maps.emission.is_some() && m.emissive.is_none_or(|e| e == [0.0; 3]) {
        warnings.push(format!(
            "material {:?} has map_Ke but no Ke: taken as Ke 1 1 1",
            m.name
        ));
    }
    maps.alpha = load(m.dissolve_texture.as_ref(), false)?.map(|texture| Alpha {
        texture: Some(texture),
        factor: 1.0,
        mode: AlphaMode::Mask { cutoff: 0.5 },
    });
    let norm = m.unknown_param.get("norm");
    if let Some(texture) = load(norm.or(m.normal_texture.as_ref()), false)? {
        let mean = texture.image.mean(false);
        let looks_normal = mean.z > 0.7 && (mean.x - 0.5).abs() < 0.1 && (mean.y - 0.5).abs() < 0.1;
        if norm.is_some() || looks_normal {
            maps.normal = Some(NormalMap {
                texture,
                scale: 1.0,
            });
        } else {
            warnings.push(format!(
                "material {:?}: bump map {} is a height map, which is ignored",
                m.name,
                texture.image.path().display()
            ));
        }
    }
    Ok((!maps.is_empty()).then(|| Arc::new(maps)))
}
