use std::path::Path;

use glam::Vec2;

use super::*;

fn image(width: u32, height: u32, texels: Vec<[u8; 4]>) -> Arc<Image> {
    let image = Image::new(
        Path::new("test.png").to_path_buf(),
        width,
        height,
        Texels::Bytes(texels),
        true,
    );
    Arc::new(image.unwrap())
}

#[test]
fn wrap_modes_index_as_gltf_defines_them() {
    // Four texels: repeat tiles, mirror reflects every other copy, clamp extends the edge.
    let got: Vec<u32> = (-5..9).map(|i| Wrap::Repeat.index(i, 4)).collect();
    assert_eq!(got, [3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0]);
    let got: Vec<u32> = (-5..9).map(|i| Wrap::Mirror.index(i, 4)).collect();
    assert_eq!(got, [3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0]);
    let got: Vec<u32> = (-2..6).map(|i| Wrap::Clamp.index(i, 4)).collect();
    assert_eq!(got, [0, 0, 0, 1, 2, 3, 3, 3]);
}

/// Found by the `texture` fuzz target: a texture coordinate beyond the range of i64 overflowed
/// the index of the next texel.
#[test]
fn huge_texture_coordinates_look_up_an_edge_texel() {
    // A 2x1 image, black then white (data, not sRGB).
    let img = image(2, 1, vec![[0, 0, 0, 255], [255, 255, 255, 255]]);
    let mut t = TextureRef::new(img, false);
    for wrap in [Wrap::Repeat, Wrap::Mirror, Wrap::Clamp] {
        t.wrap = [wrap; 2];
        for uv in [
            (1e30, -1e30),
            (-1e30, 1e30),
            (f32::MAX, 0.5),
            (f32::MIN, 0.5),
        ] {
            let c = t.color(Vec2::new(uv.0, uv.1));
            assert!(
                c.is_finite() && c.x >= 0.0 && c.x <= 1.0,
                "{c} at {uv:?}, {wrap:?}"
            );
        }
    }
    // Clamped, far right is the white texel and far left the black one.
    t.wrap = [Wrap::Clamp; 2];
    assert_eq!(t.color(Vec2::new(1e30, -1e30)).x, 1.0);
    assert_eq!(t.color(Vec2::new(-1e30, 1e30)).x, 0.0);
}

#[test]
fn bilinear_lookup_interpolates_between_texel_centres() {
    // A 2x1 image, black then white (data, not sRGB): texel centres at u = 1/4 and 3/4.
    let img = image(2, 1, vec![[0, 0, 0, 255], [255, 255, 255, 255]]);
    let mut t = TextureRef::new(img, false);
    t.wrap = [Wrap::Clamp; 2];
    assert_eq!(t.color(Vec2::new(0.25, 0.5)).x, 0.0);
    assert_eq!(t.color(Vec2::new(0.75, 0.5)).x, 1.0);
    assert!((t.color(Vec2::new(0.5, 0.5)).x - 0.5).abs() < 1e-6);
    // Clamped beyond the edges.
    assert_eq!(t.color(Vec2::new(-3.0, 0.5)).x, 0.0);
    // Repeat wraps the right edge onto the left texel: halfway between them at u = 0.
    t.wrap = [Wrap::Repeat; 2];
    assert!((t.color(Vec2::new(0.0, 0.5)).x - 0.5).abs() < 1e-6);
}

#[test]
fn srgb_decoding_matches_the_standard_curve() {
    // 8-bit 188 is 0.50289 in linear sRGB (IEC 61966-2-1); alpha is never decoded.
    let img = image(1, 1, vec![[188, 0, 255, 128]]);
    let v = TextureRef::new(img.clone(), true).lookup(Vec2::splat(0.5));
    assert!((v.x - 0.502_886).abs() < 1e-5, "{v}");
    assert_eq!(v.y, 0.0);
    assert_eq!(v.z, 1.0);
    assert!((v.w - 128.0 / 255.0).abs() < 1e-7);
    let raw = TextureRef::new(img, false).lookup(Vec2::splat(0.5));
    assert!((raw.x - 188.0 / 255.0).abs() < 1e-7);
}

#[test]
fn texture_transform_is_applied_before_the_lookup() {
    // Left half black, right half white; scaling u by 0.5 keeps every lookup in the left half.
    let img = image(2, 1, vec![[0, 0, 0, 255], [255, 255, 255, 255]]);
    let mut t = TextureRef::new(img, false);
    t.wrap = [Wrap::Clamp; 2];
    t.transform = [0.5, 0.0, 0.0, 1.0, 0.0, 0.0];
    assert_eq!(t.color(Vec2::new(0.5, 0.5)).x, 0.0);
    t.transform = [1.0, 0.0, 0.0, 1.0, 0.5, 0.0];
    assert_eq!(t.color(Vec2::new(0.25, 0.5)).x, 1.0);
}

#[test]
fn mask_and_blend_cutouts() {
    let img = image(1, 1, vec![[255, 255, 255, 100]]);
    let alpha = |mode| MaterialTextures {
        alpha: Some(Alpha {
            texture: Some(TextureRef::new(img.clone(), true)),
            factor: 1.0,
            mode,
        }),
        ..Default::default()
    };
    let uv = Vec2::splat(0.5);
    let a = 100.0 / 255.0;
    assert!(!alpha(AlphaMode::Mask { cutoff: 0.5 }).opaque(uv, 0.0));
    assert!(alpha(AlphaMode::Mask { cutoff: 0.3 }).opaque(uv, 0.0));
    assert!(alpha(AlphaMode::Blend).opaque(uv, a - 0.01));
    assert!(!alpha(AlphaMode::Blend).opaque(uv, a + 0.01));
    assert!(MaterialTextures::default().opaque(uv, 0.99));
}
