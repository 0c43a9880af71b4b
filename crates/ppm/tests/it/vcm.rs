//! Vertex connection and merging and bidirectional path tracing against analytic scenes and
//! the path tracer.

use ppm::Method;

use crate::analytic::{FURNACE, emissive_box};
use crate::support::{cornell, mean, params, render, scene};

#[test]
fn explore_vcm() {
    let furnace = scene(FURNACE);
    for method in [Method::Bdpt, Method::Vcm] {
        let mut p = params(method, 256);
        p.budget.max_depth = 64;
        let m = mean(&render(&furnace, p, 16));
        eprintln!("{method}: {m}");
    }
    let wall = scene(&emissive_box(
        "[camera]\nposition = [0.0, 0.0, 0.5]\nlook_at = [1.0, 0.0, 0.5]\nfov_y = 40.0",
    ));
    let mirror = scene(&emissive_box(
        "[camera]\nposition = [0.0, 0.0, 0.5]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 5.0",
    ));
    for r in [0.25, 0.1, 0.03] {
        for k in [2u32, 1024] {
            let mut p = params(Method::Vcm, 256);
            p.budget.max_depth = k;
            p.kernel.initial_radius = Some(r);
            let a = mean(&render(&wall, p, 16));
            let b = mean(&render(&mirror, p, 16));
            eprintln!(
                "vcm r={r} k={k}: wall {a} expected {} mirror {b} expected {}",
                1.0 - 0.5f64.powi(k as i32 + 1),
                1.0 - 0.5f64.powi(k as i32)
            );
        }
    }
}
