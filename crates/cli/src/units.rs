//! Work units: `fppm plan` cuts a pass-independent render (`--method appm`, `vcm` or `bdpt`)
//! into units,
//! `fppm unit` renders one (on any machine, in any order, e.g. as a Slurm array task), and
//! `fppm merge` sums the parts into the image.
//!
//! The plan is a checkpoint of the render before its first pass, with the kernels of the
//! frequency pilot already computed (so that every unit gathers with the same kernels) and a
//! note saying which passes each unit renders. Parts hold the exact (fixed-point) sums of their
//! passes, so the merged image is the same bits for any number of units, any order of
//! completion, and as `fppm render --method appm --passes N` on one machine.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use ppm::{Part, Renderer, StateHeader};

use crate::args::{BudgetArgs, LiveArgs, MergeArgs, OutputArgs, PlanArgs, RenderArgs, UnitArgs};
use crate::render::in_pool;
use crate::settings::{self, Note};
use crate::{Outcome, usage};

/// The plan file inside a job folder.
const PLAN: &str = "plan.fppm";

/// What the plan's note records besides what a checkpoint note does.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
struct PlanNote {
    /// The scene and film, as a checkpoint's note.
    render: Note,
    /// Passes of the whole render.
    passes: u32,
    /// Number of units.
    units: u32,
}

impl PlanNote {
    /// The passes of unit `index` (first, count): contiguous shares in unit order, whose
    /// lengths differ by at most one.
    fn passes_of(&self, index: u32) -> (u32, u32) {
        let (n, k) = (u64::from(self.passes), u64::from(self.units));
        let start = |i: u64| (n * i / k) as u32;
        let i = u64::from(index);
        (start(i), start(i + 1) - start(i))
    }
}

fn part_path(job: &Path, index: u32) -> PathBuf {
    job.join(format!("unit-{index}.part"))
}

/// `fppm plan SCENE --passes N --units K -o JOB/`.
pub(crate) fn plan(args: PlanArgs) -> anyhow::Result<Outcome> {
    let Some(passes) = settings::passes_flag(args.passes)? else {
        usage!("fppm plan needs --passes N (the passes of the whole render)");
    };
    let units = match args.units {
        k if k >= 1 && u64::try_from(k).is_ok_and(|k| k <= u64::from(passes)) => k as u32,
        k => usage!("--units {k} must be from 1 to the number of passes ({passes})"),
    };
    let mut params = args.params;
    if !params.values.iter().any(|(name, _)| *name == "method") {
        params.values.push(("method", "appm".to_owned()));
    }
    let render_args = RenderArgs {
        params,
        budget: BudgetArgs {
            passes: Some(i64::from(passes)),
            time: None,
        },
        film: args.film,
        output: OutputArgs {
            exr: None,
            png: None,
            exposure: None,
            tonemap: None,
        },
        aov: Vec::new(),
        checkpoint: None,
        run: args.run,
        live: LiveArgs {
            preview: None,
            display_server: None,
        },
    };
    let job = settings::render_job(Some(&args.scene), &render_args)?;
    if !job.params.method.is_pass_independent() {
        usage!(
            "--method {} renders passes that depend on each other; work units need --method appm, vcm or bdpt",
            job.params.method
        );
    }
    let film = job.description.film;
    job.run
        .max_memory
        .check(film.width, film.height, &job.params, true)?;
    std::fs::create_dir_all(&args.job)
        .with_context(|| format!("{}: cannot create the job folder", args.job.display()))?;
    let scene = std::sync::Arc::new(scene::Scene::new(job.description.clone())?);
    let clock = Instant::now();
    let bytes = in_pool(job.run.threads, || {
        let kernels = Renderer::pass_independent_kernels(std::sync::Arc::clone(&scene), job.params)
            .map_err(|e| crate::render::renderer_error(&job.description.source, e))?;
        let renderer =
            Renderer::with_kernels(std::sync::Arc::clone(&scene), job.params, kernels, 0)
                .map_err(|e| crate::render::renderer_error(&job.description.source, e))?;
        let note = PlanNote {
            render: settings::note_for(&job, 0.0),
            passes,
            units,
        };
        Ok(renderer.save_state(&serde_json::to_string(&note)?))
    })?;
    let path = args.job.join(PLAN);
    film::write_atomically(&path, |w| {
        std::io::Write::write_all(w, &bytes).map_err(|e| e.to_string())
    })?;
    if args.slurm {
        let script = slurm_script(&args.job, units)?;
        let path = args.job.join("submit.sh");
        film::write_atomically(&path, |w| {
            std::io::Write::write_all(w, script.as_bytes()).map_err(|e| e.to_string())
        })?;
        if !job.run.quiet {
            eprintln!(
                "wrote {} (submit with: sh {})",
                path.display(),
                path.display()
            );
        }
    }
    if !job.run.quiet {
        eprintln!(
            "wrote {} ({units} units of {passes} passes; pilot {:.1}s). Render each with `fppm unit {} --index I` (I from 0 to {}), then `fppm merge {}`",
            path.display(),
            clock.elapsed().as_secs_f64(),
            args.job.display(),
            units - 1,
            args.job.display()
        );
    }
    Ok(Outcome::Done)
}

/// `JOB/submit.sh`: an `sbatch --array` job of the units, each on one CPU, and a merge job
/// that starts when all of them have succeeded. Paths are absolute, so that the script can be
/// run from anywhere on a cluster whose nodes see the same file system.
fn slurm_script(job: &Path, units: u32) -> anyhow::Result<String> {
    let fppm = std::env::current_exe().context("cannot find the fppm executable")?;
    let job = settings::absolute(job);
    let quote = |p: &Path| format!("'{}'", p.display().to_string().replace('\'', "'\\''"));
    let (fppm, job_q) = (quote(&fppm), quote(&job));
    let image = quote(&job.join("image.exr"));
    Ok(format!(
        "#!/bin/sh
# Written by `fppm plan --slurm`: {units} work units as a Slurm array job, then the merge.
# Each unit reads its index from SLURM_ARRAY_TASK_ID; a unit that fails or is lost can be
# resubmitted alone (sbatch --array=I), and renders the same bytes again.
set -e
cd {job_q}
units=$(sbatch --parsable --array=0-{last} --cpus-per-task=1 --job-name=fppm-units \
  --output=unit-%a.log --wrap=\"{fppm} unit {job_q} --threads 1 --quiet\")
merge=$(sbatch --parsable --dependency=afterok:${{units%%;*}} --job-name=fppm-merge \
  --output=merge.log --wrap=\"{fppm} merge {job_q} -o {image}\")
echo \"submitted units (job ${{units%%;*}}) and their merge (job ${{merge%%;*}}) into {image}\"
",
        last = units - 1,
    ))
}

/// The plan of a job folder: its bytes, header and note.
fn read_plan(job: &Path) -> anyhow::Result<(Vec<u8>, StateHeader, PlanNote)> {
    let path = job.join(PLAN);
    let bytes = std::fs::read(&path).with_context(|| {
        format!(
            "{}: cannot read the plan (run `fppm plan` first)",
            path.display()
        )
    })?;
    let header =
        StateHeader::read(&bytes).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let note: PlanNote = serde_json::from_str(&header.note)
        .with_context(|| format!("{}: not a plan written by `fppm plan`", path.display()))?;
    if note.units == 0 || note.units > note.passes || !header.params.method.is_pass_independent() {
        anyhow::bail!("{}: not a plan written by `fppm plan`", path.display());
    }
    Ok((bytes, header, note))
}

/// The scene of a plan, with the plan's film.
fn plan_scene(note: &PlanNote) -> anyhow::Result<std::sync::Arc<scene::Scene>> {
    let mut description =
        settings::load_scene(note.render.scene.as_deref(), note.render.env.as_deref())?;
    settings::apply_film(
        &mut description,
        (Some(note.render.width), Some(note.render.height)),
    );
    Ok(std::sync::Arc::new(scene::Scene::new(description)?))
}

/// The unit index: `--index`, else Slurm's `SLURM_ARRAY_TASK_ID`, else Kubernetes'
/// `JOB_COMPLETION_INDEX`.
fn unit_index(flag: Option<i64>, units: u32) -> anyhow::Result<u32> {
    let (value, source) = match flag {
        Some(i) => (i.to_string(), "--index".to_owned()),
        None => match ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"]
            .iter()
            .find_map(|name| std::env::var(name).ok().map(|v| (v, format!("${name}"))))
        {
            Some(found) => found,
            None => {
                usage!("fppm unit needs --index I (or SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX)")
            }
        },
    };
    match value.trim().parse::<u32>() {
        Ok(i) if i < units => Ok(i),
        _ => usage!(
            "{source} {value} is not a unit of this plan (0 to {})",
            units - 1
        ),
    }
}

/// `fppm unit JOB/ --index I`.
pub(crate) fn unit(args: &UnitArgs) -> anyhow::Result<Outcome> {
    let run = settings::run_settings(&args.run)?;
    let (plan_bytes, header, note) = read_plan(&args.job)?;
    let index = unit_index(args.index, note.units)?;
    let (first, count) = note.passes_of(index);
    run.max_memory
        .check(note.render.width, note.render.height, &header.params, false)?;
    let scene = plan_scene(&note)?;
    let plan_path = args.job.join(PLAN);
    let clock = Instant::now();
    let part = in_pool(run.threads, || {
        let planned = Renderer::restore(std::sync::Arc::clone(&scene), &plan_bytes)
            .map_err(|e| anyhow::anyhow!("{}: {e}", plan_path.display()))?;
        let kernels = planned
            .kernels()
            .ok_or_else(|| anyhow::anyhow!("{}: the plan holds no kernels", plan_path.display()))?
            .to_vec();
        let mut renderer =
            Renderer::with_kernels(std::sync::Arc::clone(&scene), header.params, kernels, first)
                .map_err(|e| anyhow::anyhow!("{}: {e}", plan_path.display()))?;
        for _ in 0..count {
            renderer.iterate();
        }
        let sums = renderer.pass_sums().cloned().unwrap_or_default();
        Ok(Part {
            plan: Part::plan_fingerprint(&plan_bytes),
            unit: index,
            first_pass: first,
            sums,
        })
    })?;
    let path = part_path(&args.job, index);
    let bytes = part.to_bytes();
    film::write_atomically(&path, |w| {
        std::io::Write::write_all(w, &bytes).map_err(|e| e.to_string())
    })?;
    if !run.quiet {
        eprintln!(
            "wrote {} (passes {} to {}, {:.1}s)",
            path.display(),
            first,
            first + count - 1,
            clock.elapsed().as_secs_f64()
        );
    }
    Ok(Outcome::Done)
}

/// `fppm merge JOB/ -o out.exr [--png ...] [--partial]`.
pub(crate) fn merge(args: &MergeArgs) -> anyhow::Result<Outcome> {
    let outputs = settings::outputs(&args.output, &[], None)?;
    settings::check_outputs(&outputs, None)?;
    let (plan_bytes, header, note) = read_plan(&args.job)?;
    let fingerprint = Part::plan_fingerprint(&plan_bytes);
    let pixels = note.render.width as usize * note.render.height as usize;
    let mut total = ppm::PassSums::new(pixels);
    let mut missing = Vec::new();
    for index in 0..note.units {
        let path = part_path(&args.job, index);
        let bytes = match std::fs::read(&path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                missing.push(index);
                continue;
            }
            Err(e) => return Err(e).with_context(|| format!("{}: cannot read", path.display())),
        };
        let part = Part::from_bytes(&bytes, fingerprint, pixels)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let (first, count) = note.passes_of(index);
        if part.unit != index || part.first_pass != first || part.sums.passes != u64::from(count) {
            anyhow::bail!(
                "{}: holds passes {}..{} of unit {}, not those of unit {index}",
                path.display(),
                part.first_pass,
                u64::from(part.first_pass) + part.sums.passes,
                part.unit
            );
        }
        if !total.add(&part.sums) {
            anyhow::bail!("{}: the sums overflow", path.display());
        }
    }
    let list = |m: &[u32]| m.iter().map(u32::to_string).collect::<Vec<_>>().join(", ");
    let are_missing = |m: &[u32]| match m {
        [one] => format!("unit {one} is missing"),
        _ => format!("units {} are missing", list(m)),
    };
    if !missing.is_empty() && !args.partial {
        anyhow::bail!(
            "{}: {} ({} of {}); render them, or merge what is there with --partial",
            args.job.display(),
            are_missing(&missing),
            missing.len(),
            note.units
        );
    }
    if total.passes == 0 {
        anyhow::bail!("{}: no unit has been rendered yet", args.job.display());
    }
    let scene_name = note.render.scene.as_ref().map_or_else(
        || crate::DEFAULT_SCENE_NAME.to_owned(),
        |p| p.display().to_string(),
    );
    let mut metadata = vec![
        ("scene".to_owned(), scene_name),
        ("passes".to_owned(), total.passes.to_string()),
        (
            "photons".to_owned(),
            (total.passes * u64::from(header.params.budget.photons_per_pass)).to_string(),
        ),
    ];
    metadata.extend(
        header
            .params
            .entries()
            .into_iter()
            .map(|(name, value)| (name.to_owned(), value)),
    );
    metadata.push(("units".to_owned(), note.units.to_string()));
    if !missing.is_empty() {
        metadata.push(("missing_units".to_owned(), list(&missing)));
    }
    metadata.push(("version".to_owned(), env!("CARGO_PKG_VERSION").to_owned()));
    let mut frame = film::Frame::new(film::Image::new(
        note.render.width as usize,
        note.render.height as usize,
        total.image(),
    ));
    frame.metadata = metadata;
    film::write_exr(&outputs.exr, &frame)?;
    film::write_preview(&outputs.png, &frame.image, outputs.tonemap.film(), 1)?;
    if !missing.is_empty() {
        eprintln!(
            "fppm: warning: merged {} of {} passes; {}",
            total.passes,
            note.passes,
            are_missing(&missing)
        );
    }
    if !args.quiet {
        eprintln!(
            "wrote {} ({}x{}, {} of {} passes from {} units)",
            outputs.exr.display(),
            note.render.width,
            note.render.height,
            total.passes,
            note.passes,
            note.units as usize - missing.len()
        );
        eprintln!("wrote {}", outputs.png.display());
    }
    Ok(Outcome::Done)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::args::TonemapArg;

    fn note(passes: u32, units: u32) -> PlanNote {
        PlanNote {
            render: Note {
                scene: None,
                env: None,
                width: 1,
                height: 1,
                exr: PathBuf::new(),
                png: PathBuf::new(),
                aovs: Vec::new(),
                exposure: 0.0,
                tonemap: TonemapArg::Srgb,
                passes: Some(passes),
                time_seconds: None,
                render_seconds: 0.0,
            },
            passes,
            units,
        }
    }

    #[test]
    fn units_cover_every_pass_once_in_order() {
        for (passes, units) in [(10, 3), (7, 7), (100, 1), (5, 2), (1000, 64)] {
            let plan = note(passes, units);
            let mut next = 0;
            for i in 0..units {
                let (first, count) = plan.passes_of(i);
                assert_eq!(first, next, "{passes} passes, {units} units, unit {i}");
                assert!(count >= 1);
                next = first + count;
            }
            assert_eq!(next, passes);
        }
    }
}
