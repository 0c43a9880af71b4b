//! Textures at hits: cut-outs for every query, textured emitters sampled without bias, the
//! colour a hit reports, and normal maps in the triangle's frame or the vertex tangents' one.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::intersect_inlined;
use crate::test_util::{description, diffuse, point_light, tri};
use crate::texture::{Alpha, AlphaMode, MaterialTextures, NormalMap, TextureRef, Wrap, test_image};
use crate::{Ray, Scene};

/// A unit quad in the z = 0 plane facing +z, texture coordinates (0, 0) at its top-left
/// (x = 0, y = 1) as an image lies, made of two triangles of material `material`.
fn quad(material: u32) -> Vec<crate::Triangle> {
    let (p00, p10, p11, p01) = (
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    );
    let uv = |p: Vec3| Vec2::new(p.x, 1.0 - p.y);
    let mut a = tri(p00, p10, p11, material);
    a.uv = Some([uv(p00), uv(p10), uv(p11)]);
    let mut b = tri(p00, p11, p01, material);
    b.uv = Some([uv(p00), uv(p11), uv(p01)]);
    vec![a, b]
}

/// Black on the left half of the image, white on the right, clamped at the edges.
fn half_white(srgb: bool) -> TextureRef {
    let image = test_image(2, 1, vec![[0, 0, 0, 0], [255, 255, 255, 255]]);
    let mut t = TextureRef::new(image, srgb);
    t.wrap = [Wrap::Clamp; 2];
    t
}

fn with_textures(mut m: crate::Material, t: MaterialTextures) -> crate::Material {
    m.textures = Some(Arc::new(t));
    m
}

/// A grey diffuse material whose normals come from `image` (a tangent-space map).
fn normal_mapped(image: Arc<crate::texture::Image>) -> crate::Material {
    with_textures(
        diffuse(0.5, Vec3::ZERO),
        MaterialTextures {
            normal: Some(NormalMap {
                texture: TextureRef::new(image, false),
                scale: 1.0,
            }),
            ..Default::default()
        },
    )
}

#[test]
fn cutouts_let_every_query_through_their_holes() {
    // A masked quad (alpha 0 on the left, 1 on the right, cutoff ½: the hole is x < ½) in front
    // of a plain quad at z = −1.
    let mut d = description(quad(2), Vec::new(), Vec::new());
    let mut back = quad(0);
    for t in &mut back {
        t.positions = t.positions.map(|p| p - Vec3::Z);
    }
    d.triangles.extend(back);
    d.triangles.extend(quad(1).into_iter().map(|mut t| {
        t.positions = t.positions.map(|p| p + 3.0 * Vec3::Z);
        t.normals = None;
        t
    }));
    d.materials.push(with_textures(
        diffuse(0.5, Vec3::ZERO),
        MaterialTextures {
            alpha: Some(Alpha {
                texture: Some(half_white(false)),
                factor: 1.0,
                mode: AlphaMode::Mask { cutoff: 0.5 },
            }),
            ..Default::default()
        },
    ));
    let scene = Scene::new(d).unwrap();
    for (x, through) in [(0.2, true), (0.4, true), (0.6, false), (0.8, false)] {
        let ray = Ray::infinite(Vec3::new(x, 0.5, 1.0), -Vec3::Z);
        let hit = scene.intersect(&ray).unwrap();
        let expected_t = if through { 2.0 } else { 1.0 };
        assert!((hit.t - expected_t).abs() < 1e-5, "x = {x}: t = {}", hit.t);
        assert_eq!(intersect_inlined(&scene, &ray).map(|h| h.t), Some(hit.t));
        // A shadow ray from in front of the mask to just before the back quad.
        let shadow = Ray::new(Vec3::new(x, 0.5, 1.0), -Vec3::Z, 1.5);
        assert_eq!(scene.occluded(&shadow), !through, "x = {x}");
    }
}

#[test]
fn blend_cutouts_keep_the_share_alpha_says_and_the_same_ray_decides_alike() {
    // Alpha 0.25 everywhere in blend mode: about a quarter of the rays stop on the quad.
    let mut d = description(
        quad(2),
        Vec::new(),
        vec![point_light(Vec3::new(5.0, 5.0, 10.0))],
    );
    d.materials.push(with_textures(
        diffuse(0.5, Vec3::ZERO),
        MaterialTextures {
            alpha: Some(Alpha {
                texture: None,
                factor: 0.25,
                mode: AlphaMode::Blend,
            }),
            ..Default::default()
        },
    ));
    let scene = Scene::new(d).unwrap();
    let n = 4000;
    let mut hits = 0;
    for i in 0..n {
        let x = (i as f32 + 0.5) / n as f32;
        let ray = Ray::infinite(Vec3::new(x, 0.37, 1.0), Vec3::new(0.01, 0.0, -1.0));
        let hit = scene.intersect(&ray).is_some();
        assert_eq!(hit, scene.intersect(&ray).is_some());
        assert_eq!(hit, scene.occluded(&ray));
        hits += usize::from(hit);
    }
    let share = hits as f64 / f64::from(n);
    // Binomial standard deviation √(0.25·0.75/4000) ≈ 0.007.
    assert!((share - 0.25).abs() < 0.03, "{share}");
}

#[test]
fn textured_emitter_emits_its_texture_without_bias() {
    // The quad emits 2·texel; the texel's mean over the quad is ½ exactly (bilinear between
    // black and white texel centres at u = ¼ and ¾, clamped: symmetric about u = ½), so the
    // total flux is π·A·2·½ = π.
    let mut d = description(quad(2), Vec::new(), Vec::new());
    let mut lamp = diffuse(0.0, Vec3::splat(2.0));
    lamp = with_textures(
        lamp,
        MaterialTextures {
            emission: Some(half_white(false)),
            ..Default::default()
        },
    );
    d.materials.push(lamp);
    let scene = Scene::new(d).unwrap();
    let lights = scene.lights();
    let n = 200_000;
    let mut sum = Vec3::ZERO.as_dvec3();
    let mut rng = crate::test_util::Rng::new(7);
    for _ in 0..n {
        if let Some(s) = lights.sample_emission(rng.f32(), rng.vec2(), rng.vec2()) {
            sum += s.power.as_dvec3();
            // Photons start only where the texture is not black (u = x > ¼).
            assert!(s.origin.x > 0.25 - 1e-4, "{}", s.origin);
        }
    }
    let mean = sum / f64::from(n);
    let exact = std::f64::consts::PI;
    assert!((mean.x / exact - 1.0).abs() < 0.01, "{mean} vs {exact}");
    // A camera ray sees the texel.
    let hit = scene
        .intersect(&Ray::infinite(Vec3::new(0.75, 0.5, 1.0), -Vec3::Z))
        .unwrap();
    assert!((scene.emitted(&hit) - Vec3::splat(2.0)).length() < 1e-5);
}

#[test]
fn colour_textures_tint_the_bsdf_and_the_hitpoint() {
    let mut d = description(
        quad(2),
        Vec::new(),
        vec![point_light(Vec3::new(5.0, 5.0, 10.0))],
    );
    d.materials.push(with_textures(
        diffuse(0.5, Vec3::ZERO),
        MaterialTextures {
            color: Some(half_white(true)),
            ..Default::default()
        },
    ));
    let scene = Scene::new(d).unwrap();
    for (x, texel) in [(0.1, 0.0), (0.9, 1.0)] {
        let hit = scene
            .intersect(&Ray::infinite(Vec3::new(x, 0.5, 1.0), -Vec3::Z))
            .unwrap();
        assert_eq!(scene.scattering_tint(&hit), Vec3::splat(texel));
        let bsdf = scene.bsdf(&hit).unwrap();
        let f = bsdf.eval(Vec3::Z, Vec3::new(0.0, 0.6, 0.8));
        assert!((f.x - 0.5 * texel * std::f32::consts::FRAC_1_PI).abs() < 1e-6);
    }
}

#[test]
fn normal_maps_turn_the_shading_normal_in_the_texture_frame() {
    // A map that tilts the normal toward +u (texel (1 + sin 30°)/2, ½, (1 + cos 30°)/2 in data
    // terms): on the quad, +u is +x, so the shading normal tilts toward +x by about 30°.
    let (s, c) = (30f32.to_radians().sin(), 30f32.to_radians().cos());
    let byte = |v: f32| ((v * 0.5 + 0.5) * 255.0).round() as u8;
    let image = test_image(1, 1, vec![[byte(s), byte(0.0), byte(c), 255]]);
    let mut d = description(
        quad(2),
        Vec::new(),
        vec![point_light(Vec3::new(5.0, 5.0, 10.0))],
    );
    d.materials.push(normal_mapped(image));
    let scene = Scene::new(d).unwrap();
    let hit = scene
        .intersect(&Ray::infinite(Vec3::new(0.3, 0.6, 1.0), -Vec3::Z))
        .unwrap();
    let n = hit.shading_normal;
    assert!((n - Vec3::new(s, 0.0, c)).length() < 0.01, "{n}");
    // From behind, the same tilt seen from the other side.
    let back = scene
        .intersect(&Ray::infinite(Vec3::new(0.3, 0.6, -1.0), Vec3::Z))
        .unwrap();
    assert!(
        (back.shading_normal - Vec3::new(-s, 0.0, -c)).length() < 0.01,
        "{}",
        back.shading_normal
    );
}

#[test]
fn vertex_tangents_give_the_normal_map_frame() {
    // A texel whose tangent-space normal (x, y, z) has both tangent components, so that the
    // tangent and the bitangent's side both show in the result.
    let texel = [191u8, 166, 218, 255];
    let local = Vec3::new(
        f32::from(texel[0]),
        f32::from(texel[1]),
        f32::from(texel[2]),
    ) * (2.0 / 255.0)
        - Vec3::ONE;
    // The hit (0.3, 0.6) lies in the quad's second triangle (0,0), (1,1), (0,1), at
    // barycentrics b0 = 0.4, b1 = b2 = 0.3. Its vertex tangents: +x at the first vertex, +y
    // tilted out of the plane at the others; interpolated and made perpendicular to the normal
    // +z, T ∝ 0.4·x + 0.6·(up's y)·y.
    let up = Vec3::new(0.0, 1.0, 0.5).normalize();
    let t = Vec3::new(0.4, 0.6 * up.y, 0.0).normalize();
    let n = Vec3::Z;
    for w in [1.0f32, -1.0] {
        let mut triangles = quad(2);
        for tri in &mut triangles {
            tri.normals = Some([Vec3::Z; 3]);
        }
        triangles[1].tangents = Some([
            [1.0, 0.0, 0.0, w],
            [up.x, up.y, up.z, w],
            [up.x, up.y, up.z, w],
        ]);
        let mut d = description(
            triangles,
            Vec::new(),
            vec![point_light(Vec3::new(5.0, 5.0, 10.0))],
        );
        d.materials
            .push(normal_mapped(test_image(1, 1, vec![texel])));
        let scene = Scene::new(d).unwrap();
        let hit = scene
            .intersect(&Ray::infinite(Vec3::new(0.3, 0.6, 1.0), -Vec3::Z))
            .unwrap();
        // glTF 2.0: B = w·(N × T); z × (a, b, 0) = (−b, a, 0).
        let b = w * Vec3::new(-t.y, t.x, 0.0);
        let expected = (local.x * t + local.y * b + local.z * n).normalize();
        let got = hit.shading_normal;
        assert!(
            (got - expected).length() < 1e-5,
            "w {w}: {got} != {expected}"
        );
        // Not the triangle's own frame (T = +x, B = +y on this quad).
        let own = (local.x * Vec3::X + local.y * Vec3::Y + local.z * n).normalize();
        assert!((got - own).length() > 0.1, "w {w}: {got}");
    }
}

/// A quad whose metallic-roughness texture is, from left to right: a dielectric texel
/// (metallic 0), a smooth metal (metallic 1, roughness 0), a metal of roughness 0.5 and a
/// fully rough one, under a base colour of (0.9, 0.6, 0.3).
fn metallic_roughness_quad() -> Scene {
    use crate::MaterialKind;
    let image = test_image(
        4,
        1,
        vec![
            [0, 255, 0, 255],
            [0, 0, 255, 255],
            [0, 128, 255, 255],
            [0, 255, 255, 255],
        ],
    );
    let mut texture = TextureRef::new(image, false);
    texture.wrap = [Wrap::Clamp; 2];
    let base = Vec3::new(0.9, 0.6, 0.3);
    let mut d = description(
        quad(2),
        Vec::new(),
        vec![point_light(Vec3::new(5.0, 5.0, 10.0))],
    );
    d.materials.push(with_textures(
        crate::Material {
            name: "metal".into(),
            kind: MaterialKind::Diffuse(crate::Diffuse { albedo: base }),
            emission: Vec3::ZERO,
            textures: None,
            spectra: None,
        },
        MaterialTextures {
            metallic_roughness: Some(crate::texture::MetallicRoughness {
                texture,
                base,
                metallic: 1.0,
                roughness: 1.0,
            }),
            ..Default::default()
        },
    ));
    Scene::new(d).unwrap()
}

#[test]
fn metallic_roughness_textures_choose_the_model_per_texel() {
    use crate::MaterialKind;
    let scene = metallic_roughness_quad();
    let base = Vec3::new(0.9, 0.6, 0.3);
    // Texel centres at x = 1/8, 3/8, 5/8, 7/8; the expected kinds are glTF's mapping of
    // each texel's (metallic, roughness), written out here rather than taken from the loader.
    let expected = [
        MaterialKind::Diffuse(crate::Diffuse { albedo: base }),
        MaterialKind::Mirror(crate::Mirror { reflectance: base }),
        MaterialKind::Glossy(crate::Glossy {
            reflectance: base,
            // Roughness 128/255 rounds to level 32 of 64: 0.5, α = 0.25.
            roughness: 0.25,
            diffuse: Vec3::ZERO,
        }),
        MaterialKind::Glossy(crate::Glossy {
            reflectance: base,
            roughness: 1.0,
            diffuse: Vec3::ZERO,
        }),
    ];
    let materials = scene.materials().len() as u32;
    for (i, want) in expected.iter().enumerate() {
        let x = (2 * i + 1) as f32 / 8.0;
        let ray = Ray::infinite(Vec3::new(x, 0.5, 1.0), -Vec3::Z);
        let hit = scene.intersect(&ray).unwrap();
        assert!(hit.material >= materials, "x = {x}: not a variant");
        let m = scene.material(hit.material).unwrap();
        assert_eq!(m.kind, *want, "x = {x}");
        assert_eq!(
            intersect_inlined(&scene, &ray).map(|h| h.material),
            Some(hit.material)
        );
        // The BSDF the hit gets is the texel's: a mirror is specular, the others are not.
        let bsdf = scene.bsdf(&hit).unwrap();
        assert_eq!(bsdf.is_specular(), i == 1, "x = {x}");
    }
    // Past the variants there is no material.
    let variants = 2 + crate::texture::MetallicRoughness::LEVELS;
    assert!(scene.material(materials + variants - 1).is_some());
    assert!(scene.material(materials + variants).is_none());
}

#[test]
fn metallic_roughness_levels_round_to_the_nearest() {
    // Roughness r = (k ± 0.4)/64 lands on level k, α = (k/64)²; below 0.01 a mirror.
    let image = test_image(1, 1, vec![[0, 255, 255, 255]]);
    for k in [1u32, 7, 32, 63, 64] {
        for offset in [-0.4f32, 0.0, 0.4] {
            let r = ((k as f32 + offset) / 64.0).min(1.0);
            let mr = crate::texture::MetallicRoughness {
                texture: TextureRef::new(image.clone(), false),
                base: Vec3::ONE,
                metallic: 1.0,
                roughness: r,
            };
            let variant = mr.variant(Vec2::splat(0.5));
            let expected = if r < 0.01 { 1 } else { 1 + k };
            assert_eq!(variant, expected, "r = {r}");
            if let crate::MaterialKind::Glossy(crate::Glossy { roughness, .. }) =
                mr.variant_kinds()[variant as usize]
            {
                assert!((roughness.sqrt() - r).abs() <= 0.5 / 64.0 + 1e-6, "r = {r}");
            }
        }
    }
}
