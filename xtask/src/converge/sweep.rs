//! The one-at-a-time parameter sweep.

use super::*;

/// One-at-a-time parameter sweep at one budget.
pub(super) fn sweep(
    scene: &std::sync::Arc<scene::Scene>,
    entry: &SuiteScene,
    reference: &Image,
    masks: &Masks,
    flags: &Flags,
    out: &Path,
) -> Result<bool> {
    let transport = suite::transport_mask(scene);
    let mut variants: Vec<Overrides> = vec![Overrides::default()];
    for alpha in [0.5, 2.0 / 3.0, 0.8] {
        variants.push(Overrides::one("alpha", alpha));
    }
    for ff in [0.05, 0.2] {
        variants.push(Overrides::one("freq_fraction", ff));
    }
    for k in [
        ppm::K_POSTER,
        4.0 * ppm::K_STRICT,
        2.0 * ppm::K_STRICT,
        0.5 * ppm::K_STRICT,
    ] {
        variants.push(Overrides::one("kernel_k", k));
    }
    variants.push(Overrides::one("freq_geometry", "off"));
    variants.push(Overrides::one("freq_merge", "poster-max"));
    let mut csv = String::from(
        "scene,method,budget_s,alpha,freq_fraction,kernel_k,freq_merge,freq_geometry,seconds,passes,rel_mse,rmse,mean_ratio,rel_mse_low,rel_mse_caustic,rel_mse_glossy\n",
    );
    for &method in &flags.methods {
        for v in &variants {
            if !method.uses_frequency() && !v.only(&["alpha"]) {
                continue;
            }
            let mut params = base_params(entry, scene, method, flags)?;
            v.apply(&mut params)?;
            let mut renderer = ppm::Renderer::new(std::sync::Arc::clone(scene), params)
                .context("render parameters")?;
            let mut elapsed = Duration::ZERO;
            while elapsed.as_secs_f64() < flags.budget {
                let start = flags.clock.now();
                renderer.iterate();
                elapsed += flags.clock.since(start);
            }
            let image = Image::new(reference.width, reference.height, renderer.image());
            let e = film::errors(&image, reference, Some(&transport))?;
            let m = [0, 1, 2].map(|i| {
                film::errors(&image, reference, Some(&masks.masks[i])).expect("sizes match")
            });
            println!(
                "sweep {} {:<9} {:<48} relMSE {:.5} [low {:.5} caustic {:.5} glossy {:.5}] mean {:.4} ({} passes)",
                entry.name,
                method.name(),
                v.label(&params)?,
                e.rel_mse,
                m[0].rel_mse,
                m[1].rel_mse,
                m[2].rel_mse,
                e.mean_ratio,
                renderer.passes()
            );
            let _ = writeln!(
                csv,
                "{},{},{},{:.4},{},{},{},{},{:.3},{},{:.6e},{:.6e},{:.5},{:.6e},{:.6e},{:.6e}",
                entry.name,
                method.name(),
                flags.budget,
                params.kernel.alpha,
                params.frequency.fraction,
                k_name(params.frequency.kernel_k),
                value_of("freq_merge", &params),
                value_of("freq_geometry", &params),
                elapsed.as_secs_f64(),
                renderer.passes(),
                e.rel_mse,
                e.rmse,
                e.mean_ratio,
                m[0].rel_mse,
                m[1].rel_mse,
                m[2].rel_mse
            );
        }
    }
    let path = out.join(format!("{}-sweep.csv", entry.name));
    std::fs::write(&path, csv).with_context(|| format!("writing {}", path.display()))?;
    println!("converge: wrote {}", path.display());
    Ok(true)
}
