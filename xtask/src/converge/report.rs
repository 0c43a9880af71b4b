//! The CSV of a run and its log-log plots.

use super::*;

/// The line colour of `method` in the plots: a match, so that a new method cannot be left
/// without one.
pub(super) fn colour(method: ppm::Method) -> (u8, u8, u8) {
    match method {
        ppm::Method::Ppm => (31, 119, 180),
        ppm::Method::Sppm => (255, 127, 14),
        ppm::Method::FreqPpm => (44, 160, 44),
        ppm::Method::FreqSppm => (214, 39, 40),
        ppm::Method::Appm => (148, 103, 189),
        ppm::Method::Path => (100, 100, 100),
        ppm::Method::Light => (23, 190, 207),
        ppm::Method::Vcm => (188, 189, 34),
        ppm::Method::Bdpt => (227, 119, 194),
    }
}

/// One snapshot of one method.
pub(super) struct Row {
    pub(super) method: ppm::Method,
    pub(super) budget: f64,
    pub(super) seconds: f64,
    pub(super) passes: u32,
    pub(super) photons: u64,
    pub(super) all: Errors,
    pub(super) masked: [Errors; 3],
    /// The pointwise reference's own noise in relMSE units (whole image, then the three masks;
    /// NaN against a golden reference): the part of `all.rel_mse` and `masked[i].rel_mse` that
    /// the reference, not the method, contributes.
    pub(super) noise: [f64; 4],
}

/// Least-squares slope of y over x.
pub(super) fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    if n < 2.0 {
        return f64::NAN;
    }
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    sxy / sxx
}

pub(super) fn write_csv(
    path: &Path,
    entry: &SuiteScene,
    masks: &Masks,
    rows: &[Row],
) -> Result<()> {
    let mut csv =
        String::from("scene,method,budget_s,seconds,passes,photons,rmse,rel_mse,mean_ratio");
    for name in masks.names {
        let _ = write!(csv, ",rmse_{name},rel_mse_{name}");
    }
    csv.push_str(",ref_noise_rel_mse");
    for name in masks.names {
        let _ = write!(csv, ",ref_noise_rel_mse_{name}");
    }
    csv.push('\n');
    for r in rows {
        let _ = write!(
            csv,
            "{},{},{},{:.3},{},{},{:.6e},{:.6e},{:.5}",
            entry.name,
            r.method.name(),
            r.budget,
            r.seconds,
            r.passes,
            r.photons,
            r.all.rmse,
            r.all.rel_mse,
            r.all.mean_ratio
        );
        for m in &r.masked {
            let _ = write!(csv, ",{:.6e},{:.6e}", m.rmse, m.rel_mse);
        }
        for n in r.noise {
            let _ = write!(csv, ",{n:.6e}");
        }
        csv.push('\n');
    }
    std::fs::write(path, csv).with_context(|| format!("writing {}", path.display()))
}

/// Reads the rows back from a CSV written by [`write_csv`] (for `--replot`).
pub(super) fn read_csv(path: &Path) -> Result<Vec<Row>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let none = Errors {
        rmse: f64::NAN,
        rel_mse: f64::NAN,
        mean_ratio: f64::NAN,
    };
    let mut rows = Vec::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() < 9 {
            continue;
        }
        rows.push(Row {
            method: ppm::Method::from_name(f[1])
                .with_context(|| format!("unknown method `{}`", f[1]))?,
            budget: f[2].parse()?,
            seconds: f[3].parse()?,
            passes: f[4].parse()?,
            photons: f[5].parse()?,
            all: Errors {
                rmse: f[6].parse()?,
                rel_mse: f[7].parse()?,
                mean_ratio: f[8].parse()?,
            },
            masked: [none; 3],
            noise: [f64::NAN; 4],
        });
    }
    Ok(rows)
}

/// The two error plots of a scene: relMSE against seconds (`NAME-time.svg`) and against photons
/// emitted (`NAME-photons.svg`, the equal-photon-count comparison).
pub(super) fn plot_error_curves(out: &Path, name: &str, rows: &[Row]) -> Result<()> {
    plot(
        &out.join(format!("{name}-time.svg")),
        rows,
        |r| r.seconds,
        false,
    )?;
    plot(
        &out.join(format!("{name}-photons.svg")),
        rows,
        |r| r.photons as f64,
        true,
    )
}

/// relMSE against `x(row)` on log-log axes, one line per method; `photon_mappers_only` drops
/// the path tracer (which emits no photons).
pub(super) fn plot(
    path: &Path,
    rows: &[Row],
    x: impl Fn(&Row) -> f64,
    photon_mappers_only: bool,
) -> Result<()> {
    use plotters::prelude::*;
    let x_label = if photon_mappers_only {
        "photons emitted"
    } else {
        "seconds"
    };
    let pts = |m: ppm::Method| -> Vec<(f64, f64)> {
        rows.iter()
            .filter(|r| r.method == m && x(r) > 0.0 && r.all.rel_mse > 0.0)
            .map(|r| (x(r).log10(), r.all.rel_mse.log10()))
            .collect()
    };
    let methods: Vec<ppm::Method> = ppm::Method::ALL
        .into_iter()
        .filter(|m| !(photon_mappers_only && *m == ppm::Method::Path))
        .filter(|m| !pts(*m).is_empty())
        .collect();
    let all: Vec<(f64, f64)> = methods.iter().flat_map(|m| pts(*m)).collect();
    if all.is_empty() {
        return Ok(());
    }
    let (x0, x1) = bounds(all.iter().map(|p| p.0));
    let (y0, y1) = bounds(all.iter().map(|p| p.1));
    // Text is added to the SVG by hand afterwards: plotters' text needs a font backend, and
    // the workspace builds plotters without fonts.
    let mut texts: Vec<(i32, i32, &'static str, String, String)> = Vec::new();
    let root = SVGBackend::new(path, (640, 480)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let area = root.margin(20, 50, 70, 20);
    let mut chart = ChartBuilder::on(&area)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    // Decade grid lines (no text: the SVG backend is built without fonts; the axes are
    // described in docs/convergence.md).
    for d in (x0.floor() as i32)..=(x1.ceil() as i32) {
        let d = f64::from(d);
        if d >= x0 && d <= x1 {
            chart
                .draw_series(LineSeries::new([(d, y0), (d, y1)], BLACK.mix(0.25)))
                .map_err(|e| anyhow::anyhow!("{e:?}"))?;
            let (px, py) = chart.backend_coord(&(d, y0));
            texts.push((px, py + 16, "middle", "#000".into(), format!("1e{d}")));
        }
    }
    for d in (y0.floor() as i32)..=(y1.ceil() as i32) {
        let d = f64::from(d);
        if d >= y0 && d <= y1 {
            chart
                .draw_series(LineSeries::new([(x0, d), (x1, d)], BLACK.mix(0.25)))
                .map_err(|e| anyhow::anyhow!("{e:?}"))?;
            let (px, py) = chart.backend_coord(&(x0, d));
            texts.push((px - 4, py + 4, "end", "#000".into(), format!("1e{d}")));
        }
    }
    chart
        .draw_series(LineSeries::new(
            [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)],
            BLACK,
        ))
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let (bx, by) = chart.backend_coord(&(x1, y0));
    texts.push((
        bx,
        by + 34,
        "end",
        "#000".into(),
        format!("{x_label} (log scale)"),
    ));
    let (tx, ty) = chart.backend_coord(&(x0, y1));
    texts.push((
        tx + 4,
        ty - 6,
        "start",
        "#000".into(),
        "relMSE (log scale)".into(),
    ));
    for (i, m) in methods.iter().copied().enumerate() {
        let (r, g, b) = colour(m);
        let (lx, ly) = chart.backend_coord(&(x1, y1));
        texts.push((
            lx - 8,
            ly + 18 + 16 * i as i32,
            "end",
            format!("#{r:02x}{g:02x}{b:02x}"),
            m.name().to_string(),
        ));
        let colour = RGBColor(r, g, b);
        chart
            .draw_series(LineSeries::new(pts(m), colour.stroke_width(2)))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        chart
            .draw_series(
                pts(m)
                    .into_iter()
                    .map(|p| Circle::new(p, 3, colour.filled())),
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    }
    root.present().map_err(|e| anyhow::anyhow!("{e:?}"))?;
    drop(chart);
    drop(root);
    let svg =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut text = String::new();
    for (x, y, anchor, colour, label) in texts {
        let _ = writeln!(
            text,
            "<text x=\"{x}\" y=\"{y}\" font-family=\"sans-serif\" font-size=\"13\" text-anchor=\"{anchor}\" fill=\"{colour}\">{label}</text>"
        );
    }
    let svg = svg.replace("</svg>", &format!("{text}</svg>"));
    std::fs::write(path, svg).with_context(|| format!("writing {}", path.display()))
}

/// Padded bounds of log values.
pub(super) fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let pad = ((hi - lo) * 0.05).max(0.05);
    (lo - pad, hi + pad)
}
