//! Spectra in scene files (issue #34, phase 2): what the RGB transport gets from them, checked
//! against values computed here independently (Schott's Sellmeier law, Planck's law integrated
//! against the CIE tables by a quadrature of its own, closed-form Fresnel), and what the
//! description keeps for spectral transport.

use glam::Vec3;
use import::{LoadOptions, load, load_with};
use scene::MaterialKind;
use scene::spectral::{self, Ior};

use crate::fixture;

/// A scene with one sphere of material `m` and a lamp of emission `lamp` (TOML values).
fn toml_scene(m: &str, lamp: &str) -> String {
    format!(
        "format = 1\n[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov_y = 40\n\
         [film]\nwidth = 8\nheight = 8\n[materials.m]\n{m}\n[materials.lamp]\ntype = \"diffuse\"\n\
         albedo = [0, 0, 0]\nemission = {lamp}\n\
         [[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n\
         [[shapes]]\ntype = \"sphere\"\ncenter = [0, 3, 0]\nradius = 0.5\nmaterial = \"lamp\"\n"
    )
}

fn material(text: &str, lamp: &str) -> (scene::Material, scene::Material, u64) {
    // Each call in a directory of its own: the tests run in parallel.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = format!("spectra_toml_{n}");
    let path = fixture(&dir, &[("scene.toml", &toml_scene(text, lamp))]);
    let d = load(&path).unwrap();
    let fingerprint = d.fingerprint();
    let find = |name: &str| d.materials.iter().find(|m| m.name == name).unwrap().clone();
    (find("m"), find("lamp"), fingerprint)
}

/// N-BK7 by Schott's Sellmeier coefficients at `lambda` nm.
fn schott_bk7(lambda: f64) -> f64 {
    let l2 = (lambda / 1000.0).powi(2);
    let b = [1.039_612_12, 0.231_792_344, 1.010_469_45];
    let c = [0.006_000_698_67, 0.020_017_914_4, 103.560_653];
    (1.0 + (0..3).map(|i| b[i] * l2 / (l2 - c[i])).sum::<f64>()).sqrt()
}

/// Planck's law integrated against the CIE 1931 ȳ by the midpoint rule at 0.25 nm, over the
/// integral of ȳ: the luminance of a black body at `t` K in W/(m² sr nm) per unit of ȳ.
fn blackbody_luminance(t: f64) -> f64 {
    let planck = |l: f64| {
        let (h, c, k) = (6.626_070_15e-34, 299_792_458.0, 1.380_649e-23);
        let m = l * 1e-9;
        2.0 * h * c * c / (m.powi(5) * ((h * c / (m * k * t)).exp() - 1.0)) * 1e-9
    };
    let (mut y, mut y_bar) = (0.0, 0.0);
    for i in 0..1880 {
        let l = 360.0 + (f64::from(i) + 0.5) * 0.25;
        let cmf = spectral::cie_xyz(l).y;
        y += planck(l) * cmf * 0.25;
        y_bar += cmf * 0.25;
    }
    y / y_bar
}

#[test]
fn toml_spectra_become_their_colours_and_stay_in_the_description() {
    // A flat measured reflectance is its grey; a D65 illuminant of scale 2 is white 2.
    let (m, lamp, fp_spectral) = material(
        "type = \"diffuse\"\nalbedo = { samples = [[300.0, 0.5], [900.0, 0.5]] }",
        "{ illuminant = \"D65\", scale = 2.0 }",
    );
    let MaterialKind::Diffuse(d) = m.kind else {
        panic!("{m:?}")
    };
    assert!(
        (d.albedo - Vec3::splat(0.5)).abs().max_element() < 2e-3,
        "{}",
        d.albedo
    );
    assert!(
        (lamp.emission - Vec3::splat(2.0)).abs().max_element() < 5e-3,
        "{}",
        lamp.emission
    );
    assert!(m.spectra.as_ref().unwrap().reflectance.is_some());
    assert!(lamp.spectra.as_ref().unwrap().emission.is_some());
    // The same colours given as RGB: no spectra, and another fingerprint.
    let rgb_d = format!(
        "albedo = [{0}, {1}, {2}]",
        d.albedo.x, d.albedo.y, d.albedo.z
    );
    let rgb_l = format!(
        "[{}, {}, {}]",
        lamp.emission.x, lamp.emission.y, lamp.emission.z
    );
    let (m2, lamp2, fp_rgb) = material(&format!("type = \"diffuse\"\n{rgb_d}"), &rgb_l);
    assert_eq!((m2.kind, lamp2.emission), (m.kind, lamp.emission));
    assert!(m2.spectra.is_none() && lamp2.spectra.is_none());
    assert_ne!(fp_spectral, fp_rgb);

    // A blackbody of scale 3 has luminance 3 (Rec.709's Y of its colour).
    let (_, lamp, _) = material(
        "type = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]",
        "{ blackbody = 3000.0, scale = 3.0 }",
    );
    let y = lamp.emission.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    assert!((y - 3.0).abs() < 3e-3, "{}", lamp.emission);
    assert!(
        lamp.emission.x > 2.0 * lamp.emission.z,
        "warm: {}",
        lamp.emission
    );
}

#[test]
fn toml_glass_and_metal() {
    let (m, _, _) = material("type = \"dielectric\"\nior = \"glass-BK7\"", "[1, 1, 1]");
    let MaterialKind::Dielectric(g) = m.kind else {
        panic!("{m:?}")
    };
    let expected = schott_bk7(scene::REPRESENTATIVE_WAVELENGTH);
    assert!(
        (f64::from(g.ior) - expected).abs() < 2e-4,
        "{} vs {expected}",
        g.ior
    );
    let ior = m.spectra.as_ref().unwrap().ior.as_ref().unwrap();
    assert!(ior.is_dispersive() && (ior.eval(450.0) - schott_bk7(450.0)).abs() < 2e-4);
    // A Sellmeier law given by its coefficients, rough.
    let (m, _, _) = material(
        "type = \"dielectric\"\nroughness = 0.2\nior = { sellmeier = [1.03961212, 0.231792344, 1.01046945, 0.00600069867, 0.0200179144, 103.560653] }",
        "[1, 1, 1]",
    );
    let MaterialKind::RoughDielectric(r) = m.kind else {
        panic!("{m:?}")
    };
    assert!((f64::from(r.ior) - expected).abs() < 1e-5 && r.roughness == 0.2);
    assert!(matches!(
        m.spectra.as_ref().unwrap().ior,
        Some(Ior::Sellmeier(_))
    ));

    // Gold: the RGB η and k of its spectra; Fresnel at normal incidence in closed form.
    let (m, _, _) = material(
        "type = \"conductor\"\nmetal = \"Au\"\nroughness = 0.1",
        "[1, 1, 1]",
    );
    let MaterialKind::Conductor(c) = m.kind else {
        panic!("{m:?}")
    };
    let gold = spectral::Conductor::named("Au").unwrap();
    let (eta, k) = gold.rgb();
    assert_eq!(c.eta, Vec3::from_array(eta.map(|x| x as f32)));
    assert_eq!(c.k, Vec3::from_array(k.map(|x| x as f32)));
    assert_eq!((c.roughness, c.specular_reflectance), (0.1, Vec3::ONE));
    let r = |n: f32, k: f32| ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
    let albedo = m.kind.albedo();
    for i in 0..3 {
        assert!((albedo[i] - r(c.eta[i], c.k[i])).abs() < 1e-5);
    }
    assert_eq!(m.spectra.as_ref().unwrap().conductor.as_ref(), Some(&gold));
    // Mitsuba's RGB-only conductors by name, and η, k as colours.
    let (m, _, _) = material("type = \"conductor\"\nmetal = \"Cr\"", "[1, 1, 1]");
    assert!(matches!(m.kind, MaterialKind::Conductor(_)) && m.spectra.is_none());
    let (m, _, _) = material(
        "type = \"conductor\"\neta = [0.2, 0.4, 1.4]\nk = [3.9, 2.4, 1.6]",
        "[1, 1, 1]",
    );
    let MaterialKind::Conductor(c) = m.kind else {
        panic!("{m:?}")
    };
    assert_eq!(
        (c.eta, c.k),
        (Vec3::new(0.2, 0.4, 1.4), Vec3::new(3.9, 2.4, 1.6))
    );
}

#[test]
fn pbrt_named_glass_and_metal_and_blackbody() {
    let pbrt = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n\
        Material \"dielectric\" \"spectrum eta\" \"glass-BK7\"\nShape \"sphere\"\n\
        Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" \"float roughness\" 0.01\n\
        Shape \"sphere\" \"float radius\" 0.5\n\
        AttributeBegin\nAreaLightSource \"diffuse\" \"blackbody L\" [ 6500 ] \"float scale\" 2\n\
        Shape \"sphere\" \"float radius\" 0.1\nAttributeEnd\n";
    let path = fixture("spectra_pbrt", &[("scene.pbrt", pbrt)]);
    let d = load(&path).unwrap();
    let glass = d
        .materials
        .iter()
        .find(|m| matches!(m.kind, MaterialKind::Dielectric(_)))
        .unwrap();
    let MaterialKind::Dielectric(g) = glass.kind else {
        unreachable!()
    };
    assert!((f64::from(g.ior) - schott_bk7(scene::REPRESENTATIVE_WAVELENGTH)).abs() < 2e-4);
    assert!(glass.spectra.as_ref().unwrap().ior.is_some());
    let gold = d
        .materials
        .iter()
        .find(|m| matches!(m.kind, MaterialKind::Conductor(_)))
        .unwrap();
    let MaterialKind::Conductor(c) = gold.kind else {
        unreachable!()
    };
    assert!(
        (c.roughness - 0.1).abs() < 1e-6,
        "remapped: {}",
        c.roughness
    );
    let (_, m_eta, m_k) = spectral::MITSUBA_RGB_METALS
        .iter()
        .find(|(n, _, _)| *n == "Au")
        .unwrap();
    assert_eq!(
        (c.eta, c.k),
        (Vec3::from_array(*m_eta), Vec3::from_array(*m_k))
    );
    assert_eq!(
        gold.spectra.as_ref().unwrap().conductor,
        spectral::Conductor::named("Au")
    );
    // pbrt-v4 normalizes a light's spectrum to luminance 1: the lamp's luminance is its scale.
    let lamp = d
        .materials
        .iter()
        .find(|m| m.emission != Vec3::ZERO)
        .unwrap();
    let y = lamp.emission.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    assert!((y - 2.0).abs() < 2e-3, "{}", lamp.emission);
    assert!(
        d.notes
            .warnings
            .iter()
            .all(|w| !w.contains("Fresnel") && !w.contains("blackbody")),
        "{:?}",
        d.notes.warnings
    );
}

#[test]
fn mitsuba_conductor_and_blackbody() {
    let xml = r#"<scene version="3.0.0">
    <shape type="sphere"><bsdf type="roughconductor"><string name="material" value="Cu"/><float name="alpha" value="0.2"/></bsdf></shape>
    <shape type="rectangle"><emitter type="area"><spectrum type="blackbody" name="radiance"><float name="temperature" value="3000"/></spectrum></emitter></shape>
</scene>"#;
    let path = fixture("spectra_mitsuba", &[("scene.xml", xml)]);
    let d = load_with(&path, &LoadOptions::default()).unwrap();
    let copper = d
        .materials
        .iter()
        .find(|m| matches!(m.kind, MaterialKind::Conductor(_)))
        .unwrap();
    let MaterialKind::Conductor(c) = copper.kind else {
        unreachable!()
    };
    let (_, m_eta, m_k) = spectral::MITSUBA_RGB_METALS
        .iter()
        .find(|(n, _, _)| *n == "Cu")
        .unwrap();
    assert_eq!(
        (c.eta, c.k, c.roughness),
        (Vec3::from_array(*m_eta), Vec3::from_array(*m_k), 0.2)
    );
    assert_eq!(
        copper.spectra.as_ref().unwrap().conductor,
        spectral::Conductor::named("Cu")
    );
    // Mitsuba's blackbody is Planck's radiance per nm: its luminance is the integral's.
    let lamp = d
        .materials
        .iter()
        .find(|m| m.emission != Vec3::ZERO)
        .unwrap();
    let y = f64::from(lamp.emission.dot(Vec3::new(0.2126, 0.7152, 0.0722)));
    let expected = blackbody_luminance(3000.0);
    assert!((y / expected - 1.0).abs() < 2e-3, "{y} vs {expected}");
    assert!(lamp.spectra.as_ref().unwrap().emission.is_some());
    assert!(
        d.notes
            .warnings
            .iter()
            .all(|w| !w.contains("Fresnel") && !w.contains("stands in")),
        "{:?}",
        d.notes.warnings
    );
}
