//! Image textures of imported scenes: a 2×2 texture on a quad, looked up where rays hit it,
//! pins each format's texture-coordinate convention to the source renderer's; the shared
//! textured scenes load with their images at the sizes the files have.
//!
//! The texture's texels, as the image file lies (row 0 at the top): top-left red, top-right
//! green, bottom-left blue, bottom-right white. Rays hit the quad [−1, 1]² (z = 0) at the
//! centres of its four quarters, which are texel centres, so bilinear filtering returns the
//! texels exactly.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use import::{LoadOptions, MemoryFiles, load_from, load_with};
use scene::{Ray, Scene};

use crate::shared_scenes;

const RED: [f32; 3] = [1.0, 0.0, 0.0];
const GREEN: [f32; 3] = [0.0, 1.0, 0.0];
const BLUE: [f32; 3] = [0.0, 0.0, 1.0];
const WHITE: [f32; 3] = [1.0, 1.0, 1.0];

/// World points (x, y) on the quad where the colours are read: (−,−), (+,−), (−,+), (+,+).
const QUARTERS: [(f32, f32); 4] = [(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)];

/// The 2×2 checker as a PNG.
fn checker_png() -> Vec<u8> {
    let texels = [255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255];
    let image = image::RgbImage::from_raw(2, 2, texels.to_vec()).unwrap();
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner()
}

/// Loads `scene` (held in memory as `dir/name`, with `files`) and returns the colour the
/// texture gives at each of [`QUARTERS`], seen from +z; `None` where the ray goes through.
fn colours_at_quarters(
    name: &str,
    scene: &str,
    files: &[(&str, Vec<u8>)],
) -> Vec<Option<[f32; 3]>> {
    let dir = PathBuf::from("/mem");
    let mut memory = MemoryFiles::new().with(dir.join(name), scene.as_bytes().to_vec());
    for (file, bytes) in files {
        memory.insert(dir.join(file), bytes.clone());
    }
    let description = load_from(&dir.join(name), memory, &LoadOptions::default()).unwrap();
    assert!(
        description.materials.iter().any(|m| m.textures.is_some()),
        "{name}: no textured material"
    );
    let scene = Scene::new(description).unwrap();
    QUARTERS
        .iter()
        .map(|&(x, y)| {
            let ray = Ray::infinite(Vec3::new(x, y, 1.0), -Vec3::Z);
            scene
                .intersect(&ray)
                .map(|hit| scene.scattering_tint(&hit).to_array())
        })
        .collect()
}

fn assert_colours(what: &str, got: &[Option<[f32; 3]>], expected: [[f32; 3]; 4]) {
    for ((got, want), at) in got.iter().zip(expected).zip(QUARTERS) {
        let got = got.unwrap_or_else(|| panic!("{what}: nothing hit at {at:?}"));
        assert!(
            Vec3::from(got).abs_diff_eq(Vec3::from(want), 1e-3),
            "{what}: at {at:?} the texture gives {got:?}, expected {want:?}"
        );
    }
}

/// A Mitsuba scene with a point light and `shape`.
fn mitsuba_scene(shape: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <emitter type="point"><point name="position" x="0" y="0" z="3"/><rgb name="intensity" value="1"/></emitter>
    {shape}
</scene>"#
    )
}

/// A diffuse BSDF whose reflectance is the checker bitmap, with `extra` properties.
fn mitsuba_bitmap(extra: &str) -> String {
    format!(
        r#"<bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="checker.png"/>{extra}</texture></bsdf>"#
    )
}

const QUAD_OBJ: &str = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";

const QUAD_PLY: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n-1 -1 0 0 0\n1 -1 0 1 0\n1 1 0 1 1\n-1 1 0 0 1\n3 0 1 2\n3 0 2 3\n";

// Mitsuba 3: `bitmap` looks up `to_uv · si.uv` in a texture whose first row is the image's top
// row (src/textures/bitmap.cpp), so uv (0, 0) is the top-left texel; `rectangle` gives the
// corner (−1, −1) uv (0, 0) (src/shapes/rectangle.cpp, its vertex records), PLY u/v are used
// as they are (src/shapes/ply.cpp, `flip_tex_coords` false by default) and OBJ v is flipped
// (src/shapes/obj.cpp, `flip_tex_coords` true by default). The same quads rendered by
// Mitsuba 3.9.1 (scalar_rgb, albedo AOV) gave exactly these corners.

#[test]
fn mitsuba_rectangle_bitmap_has_its_top_left_texel_at_uv_origin() {
    let scene = mitsuba_scene(&format!(
        r#"<shape type="rectangle">{}</shape>"#,
        mitsuba_bitmap("")
    ));
    let got = colours_at_quarters("scene.xml", &scene, &[("checker.png", checker_png())]);
    assert_colours("rectangle", &got, [RED, GREEN, BLUE, WHITE]);
}

#[test]
fn mitsuba_to_uv_shifts_the_lookup() {
    // to_uv translates u by ½: each quarter shows the texel of the other column.
    let scene = mitsuba_scene(&format!(
        r#"<shape type="rectangle">{}</shape>"#,
        mitsuba_bitmap(r#"<transform name="to_uv"><translate x="0.5"/></transform>"#)
    ));
    let got = colours_at_quarters("scene.xml", &scene, &[("checker.png", checker_png())]);
    assert_colours("to_uv", &got, [GREEN, RED, WHITE, BLUE]);
}

#[test]
fn mitsuba_ply_uv_are_not_flipped_and_obj_uv_are() {
    let ply = mitsuba_scene(&format!(
        r#"<shape type="ply"><string name="filename" value="quad.ply"/>{}</shape>"#,
        mitsuba_bitmap("")
    ));
    let got = colours_at_quarters(
        "scene.xml",
        &ply,
        &[
            ("checker.png", checker_png()),
            ("quad.ply", QUAD_PLY.as_bytes().to_vec()),
        ],
    );
    assert_colours("ply", &got, [RED, GREEN, BLUE, WHITE]);
    let obj = mitsuba_scene(&format!(
        r#"<shape type="obj"><string name="filename" value="quad.obj"/>{}</shape>"#,
        mitsuba_bitmap("")
    ));
    let got = colours_at_quarters(
        "scene.xml",
        &obj,
        &[
            ("checker.png", checker_png()),
            ("quad.obj", QUAD_OBJ.as_bytes().to_vec()),
        ],
    );
    assert_colours("obj", &got, [BLUE, WHITE, RED, GREEN]);
}

#[test]
fn mitsuba_mask_cuts_the_surface_out_where_the_opacity_is_zero() {
    // Opacity 1 in the image's left column, 0 in its right one; on the rectangle the right
    // column is x > 0, where rays go through.
    let grey = image::GrayImage::from_raw(2, 2, vec![255, 0, 255, 0]).unwrap();
    let mut png = std::io::Cursor::new(Vec::new());
    grey.write_to(&mut png, image::ImageFormat::Png).unwrap();
    let scene = mitsuba_scene(
        r#"<shape type="rectangle"><bsdf type="mask">
            <texture type="bitmap" name="opacity"><string name="filename" value="mask.png"/></texture>
            <bsdf type="diffuse"/>
        </bsdf></shape>"#,
    );
    let dir = PathBuf::from("/mem");
    let memory = MemoryFiles::new()
        .with(dir.join("scene.xml"), scene.into_bytes())
        .with(dir.join("mask.png"), png.into_inner());
    let description = load_from(&dir.join("scene.xml"), memory, &LoadOptions::default()).unwrap();
    let scene = Scene::new(description).unwrap();
    for (x, y) in QUARTERS {
        let hit = scene.intersect(&Ray::infinite(Vec3::new(x, y, 1.0), -Vec3::Z));
        assert_eq!(hit.is_some(), x < 0.0, "at ({x}, {y})");
    }
}

/// A pbrt scene with a point light and a textured diffuse quad: `textures` defines the texture
/// named "tex", `shape` the quad.
fn pbrt_scene(textures: &str, shape: &str) -> String {
    format!(
        r#"WorldBegin
LightSource "point" "rgb I" [1 1 1] "point3 from" [0 0 3]
{textures}
Material "diffuse" "texture reflectance" "tex"
{shape}
"#
    )
}

const PBRT_QUAD: &str = r#"Shape "trianglemesh" "point3 P" [-1 -1 0 1 -1 0 1 1 0 -1 1 0] "point2 uv" [0 0 1 0 1 1 0 1] "integer indices" [0 1 2 0 2 3]"#;
const PBRT_IMAGEMAP: &str =
    r#"Texture "tex" "spectrum" "imagemap" "string filename" "checker.png""#;

// pbrt-v4: `SpectrumImageTexture::Evaluate` (src/pbrt/textures.cpp) maps (s, t) =
// (uscale·u + udelta, vscale·v + vdelta) (`UVMapping::Map`, src/pbrt/textures.h) and then
// flips t, "texture coordinates are (0,0) in the lower left corner, but image coordinates are
// (0,0) in the upper left": uv (0, 0) is the bottom-left texel.

#[test]
fn pbrt_imagemap_has_its_bottom_left_texel_at_uv_origin() {
    let scene = pbrt_scene(PBRT_IMAGEMAP, PBRT_QUAD);
    let got = colours_at_quarters("scene.pbrt", &scene, &[("checker.png", checker_png())]);
    assert_colours("trianglemesh", &got, [BLUE, WHITE, RED, GREEN]);
}

#[test]
fn pbrt_uv_mapping_and_scale_texture_apply() {
    // udelta ½ swaps the columns; vscale −1 with vdelta 1 turns t into 1 − t, which swaps the
    // rows back; the scale texture halves the reflectance but not the texture.
    let textures = r#"Texture "img" "spectrum" "imagemap" "string filename" "checker.png"
    "float udelta" 0.5 "float vscale" -1 "float vdelta" 1
Texture "tex" "spectrum" "scale" "texture tex" "img" "float scale" 0.5"#;
    let scene = pbrt_scene(textures, PBRT_QUAD);
    let got = colours_at_quarters("scene.pbrt", &scene, &[("checker.png", checker_png())]);
    assert_colours("mapping", &got, [GREEN, RED, WHITE, BLUE]);
    let dir = PathBuf::from("/mem");
    let memory = MemoryFiles::new()
        .with(dir.join("scene.pbrt"), scene.into_bytes())
        .with(dir.join("checker.png"), checker_png());
    let description = load_from(&dir.join("scene.pbrt"), memory, &LoadOptions::default()).unwrap();
    let textured = description
        .materials
        .iter()
        .find(|m| m.textures.is_some())
        .unwrap();
    assert_eq!(
        textured.kind,
        scene::MaterialKind::Diffuse(scene::Diffuse {
            albedo: Vec3::splat(0.5)
        })
    );
}

#[test]
fn pbrt_plymesh_uv_follow_the_same_flip() {
    let scene = pbrt_scene(
        PBRT_IMAGEMAP,
        r#"Shape "plymesh" "string filename" "quad.ply""#,
    );
    let got = colours_at_quarters(
        "scene.pbrt",
        &scene,
        &[
            ("checker.png", checker_png()),
            ("quad.ply", QUAD_PLY.as_bytes().to_vec()),
        ],
    );
    assert_colours("plymesh", &got, [BLUE, WHITE, RED, GREEN]);
}

#[test]
fn pbrt_bilinearmesh_uv_follow_the_same_flip() {
    // pbrt's patch order p00 p10 p01 p11.
    let scene = pbrt_scene(
        PBRT_IMAGEMAP,
        r#"Shape "bilinearmesh" "point3 P" [-1 -1 0 1 -1 0 -1 1 0 1 1 0] "point2 uv" [0 0 1 0 0 1 1 1]"#,
    );
    let got = colours_at_quarters("scene.pbrt", &scene, &[("checker.png", checker_png())]);
    assert_colours("bilinearmesh", &got, [BLUE, WHITE, RED, GREEN]);
}

#[test]
fn mitsuba_plastic_textures_its_diffuse_part_with_a_warning() {
    let scene = mitsuba_scene(
        r#"<shape type="rectangle"><bsdf type="roughplastic">
            <texture type="bitmap" name="diffuse_reflectance"><string name="filename" value="checker.png"/></texture>
        </bsdf></shape>"#,
    );
    let got = colours_at_quarters("scene.xml", &scene, &[("checker.png", checker_png())]);
    assert_colours("roughplastic", &got, [RED, GREEN, BLUE, WHITE]);
    let dir = PathBuf::from("/mem");
    let memory = MemoryFiles::new()
        .with(dir.join("scene.xml"), scene.into_bytes())
        .with(dir.join("checker.png"), checker_png());
    let description = load_from(&dir.join("scene.xml"), memory, &LoadOptions::default()).unwrap();
    assert!(
        description
            .notes
            .warnings
            .iter()
            .any(|w| w.contains("tints the coating's reflection too")),
        "{:?}",
        description.notes.warnings
    );
}

/// Width and height of an image file, read by the `image` crate's header decoder.
fn dimensions(path: &Path) -> [u32; 2] {
    let (w, h) = image::image_dimensions(path).unwrap();
    [w, h]
}

/// The shared textured scenes: one texture each, of the file's size, on triangles that all
/// carry texture coordinates.
#[test]
fn shared_textured_scenes_load_their_images() {
    let mitsuba = shared_scenes().join("mitsuba3");
    let pbrt = shared_scenes().join("pbrt-v4/killeroos");
    let cases = [
        (
            mitsuba.join("docs/scenes/bsdf_diffuse_textured.xml"),
            mitsuba.join("common/textures/wood.jpg"),
            "color",
        ),
        (
            mitsuba.join("docs/scenes/bsdf_mask_after.xml"),
            mitsuba.join("common/textures/leaf_mask.png"),
            "alpha",
        ),
        (
            pbrt.join("killeroo-gold.pbrt"),
            pbrt.join("textures/lines.png"),
            "color",
        ),
        (
            pbrt.join("killeroo-coated-gold.pbrt"),
            pbrt.join("textures/lines.png"),
            "color",
        ),
    ];
    for (scene, image, use_) in cases {
        let description = load_with(&scene, &LoadOptions::allow_no_emitter()).unwrap();
        let summary = description.summary();
        assert_eq!(summary.textures.len(), 1, "{}", scene.display());
        let texture = &summary.textures[0];
        assert_eq!(
            Some(texture.file.as_str()),
            image.file_name().and_then(|n| n.to_str())
        );
        assert_eq!(
            texture.resolution,
            dimensions(&image),
            "{}",
            image.display()
        );
        assert_eq!(texture.uses, vec![use_]);
        let textured: Vec<u32> = (0..description.materials.len() as u32)
            .filter(|&i| description.materials[i as usize].textures.is_some())
            .collect();
        let triangles: Vec<_> = description
            .triangles
            .iter()
            .filter(|t| textured.contains(&t.material))
            .collect();
        assert!(!triangles.is_empty(), "{}", scene.display());
        assert!(
            triangles.iter().all(|t| t.uv.is_some()),
            "{}: textured triangles without uv",
            scene.display()
        );
        // The coordinates span more than a point (the mesh's own, not a default).
        let spread = triangles
            .iter()
            .flat_map(|t| t.uv.unwrap())
            .fold((Vec2::MAX, Vec2::MIN), |(lo, hi), uv| {
                (lo.min(uv), hi.max(uv))
            });
        assert!((spread.1 - spread.0).min_element() > 0.5, "{spread:?}");
    }
}

/// Untextured scenes keep no texture coordinates, although their meshes have some (the
/// matpreview `.serialized` shapes do, as the textured scene above shows): their descriptions
/// are what they were before the importers read uv.
#[test]
fn untextured_scenes_carry_no_uv() {
    let mitsuba = shared_scenes().join("mitsuba3/docs/scenes");
    for scene in ["bsdf_dielectric_diamond.xml", "shape_ply_bunny.xml"] {
        let description =
            load_with(&mitsuba.join(scene), &LoadOptions::allow_no_emitter()).unwrap();
        assert!(description.materials.iter().all(|m| m.textures.is_none()));
        assert!(
            description.triangles.iter().all(|t| t.uv.is_none()),
            "{scene}"
        );
    }
}
