//! The Mitsuba export of `cargo xtask peers`: every peer scene exports, and Mitsuba's XML read
//! back by fppm's own importer gives the materials it came from (so the export names what fppm
//! renders: a rough dielectric's α and ior, a glossy conductor's reflectance through the η of
//! its Fresnel).

use std::path::Path;

use scene::MaterialKind;

use crate::peers::write_mitsuba;

/// Whether two material kinds agree to within rounding of the XML's decimal numbers.
fn same_kind(a: MaterialKind, b: MaterialKind) -> bool {
    let close = |x: f32, y: f32| (x - y).abs() <= 1e-4 * x.abs().max(1.0);
    let close3 = |x: glam::Vec3, y: glam::Vec3| (x - y).abs().max_element() <= 1e-3;
    match (a, b) {
        (MaterialKind::Diffuse(x), MaterialKind::Diffuse(y)) => close3(x.albedo, y.albedo),
        (MaterialKind::Mirror(x), MaterialKind::Mirror(y)) => close3(x.reflectance, y.reflectance),
        (MaterialKind::Dielectric(x), MaterialKind::Dielectric(y)) => close(x.ior, y.ior),
        (MaterialKind::RoughDielectric(x), MaterialKind::RoughDielectric(y)) => {
            close(x.ior, y.ior) && close(x.roughness, y.roughness)
        }
        (MaterialKind::Glossy(x), MaterialKind::Glossy(y)) => {
            close3(x.reflectance, y.reflectance)
                && close(x.roughness, y.roughness)
                && close3(x.diffuse, y.diffuse)
        }
        _ => false,
    }
}

#[test]
fn peer_scenes_export_the_materials_fppm_renders() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let dir = std::env::temp_dir().join(format!("fppm-peers-export-{}", std::process::id()));
    let mut kinds_seen = Vec::new();
    for name in [
        "glossy-floor",
        "frosted-panel",
        "glossy-caustic",
        "room-indirect",
    ] {
        let path = root.join("scenes/peers").join(format!("{name}.toml"));
        let original = import::load(&path).unwrap();
        let xml = write_mitsuba(&original, &dir.join(name)).unwrap();
        let back = import::load(&xml).unwrap();
        for m in original
            .materials
            .iter()
            .filter(|m| m.emission == glam::Vec3::ZERO)
        {
            assert!(
                back.materials.iter().any(|b| same_kind(m.kind, b.kind)),
                "{name}: {:?} came back as none of {:?}",
                m.kind,
                back.materials.iter().map(|b| b.kind).collect::<Vec<_>>()
            );
            kinds_seen.push(m.kind.name());
        }
    }
    for kind in ["roughdielectric", "glossy", "dielectric", "diffuse"] {
        assert!(kinds_seen.contains(&kind), "no {kind} exported");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
