//! Snapshots of the per-pass statistics of short fixed-seed renders, so that any change of
//! behaviour shows in review (rounded to 4 significant digits).

use ppm::{Method, PassStats, Renderer};

use crate::support::{cornell, params};

fn round4(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    format!("{:.4e}", x)
}

fn describe(stats: &PassStats) -> String {
    format!(
        "pass {}: camera_paths {}, photons {}, freq_photons {}, deposited {}, hit {}, valid {}, radius mean {} min {} max {}, held {}",
        stats.pass,
        stats.camera_paths,
        stats.photons_traced,
        stats.frequency_photons,
        stats.photons_deposited,
        stats.hitpoints_hit,
        stats.hitpoints_valid,
        round4(stats.mean_radius),
        round4(stats.min_radius),
        round4(stats.max_radius),
        round4(stats.frequency_held),
    )
}

#[test]
fn per_pass_statistics_of_each_method() {
    let scene = cornell("CornellBox-Sphere.obj", 16, 16);
    for method in Method::ALL {
        let mut renderer =
            Renderer::new(std::sync::Arc::clone(&scene), params(method, 4_000)).unwrap();
        let lines: Vec<String> = (0..3).map(|_| describe(&renderer.iterate())).collect();
        insta::assert_snapshot!(format!("stats_{}", method.name()), lines.join("\n"));
    }
}
