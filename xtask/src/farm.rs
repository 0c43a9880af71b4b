//! `cargo xtask farm-test`: a real Slurm cluster of one node on this machine runs a job of work
//! units, and the merged image must be the bytes of a one-process render.
//!
//! Installs Debian's `slurm-wlm` and `munge` if they are missing (needs root and apt), starts
//! `munged`, `slurmctld` and `slurmd` with a generated minimal `slurm.conf` in a temporary
//! folder, submits `fppm plan --slurm`'s script (4 units and a dependent merge), waits, compares
//! the pixels bit for bit with `fppm render --method appm`, and stops the daemons it started, by
//! their process ids, whatever happened.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};

pub(crate) const HELP: &str = "\
cargo xtask farm-test [--units K] [--passes N] [--size PIXELS] [--photons N]

Starts a one-node Slurm cluster on this machine (installing slurm-wlm and munge with apt-get if
they are missing; needs root), renders a Cornell box as K work units (default 4) of N passes in
all (default 16) through `fppm plan --slurm` (a square film of --size pixels, default 48, and
--photons per pass, default 20000), and checks that the merged image is bit for bit
the one-process `fppm render --method appm` image. Stops the daemons it started.";

/// The scene of the test, read in place from the shared scenes.
const SCENE: &str = "../shared/scenes/cornell_box/CornellBox-Sphere.obj";
/// How long the job may take before the test gives up.
const TIMEOUT: Duration = Duration::from_secs(300);

pub(crate) fn run(root: &Path, args: &[String]) -> Result<bool> {
    let mut units = 4u32;
    let mut passes = 16u32;
    let mut size = 48u32;
    let mut photons = 20_000u32;
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let mut value = |name: &str| -> Result<u32> {
            it.next()
                .with_context(|| format!("{name} needs a value"))?
                .parse()
                .with_context(|| format!("{name} needs a whole number"))
        };
        match flag.as_str() {
            "--units" => units = value("--units")?,
            "--passes" => passes = value("--passes")?,
            "--size" => size = value("--size")?,
            "--photons" => photons = value("--photons")?,
            other => bail!("farm-test: unknown flag {other}\n\n{HELP}"),
        }
    }
    if units == 0 || units > passes {
        bail!("farm-test: --units must be from 1 to --passes");
    }
    install_if_missing()?;
    let fppm = crate::peers::build_fppm(root)?;
    let dir = root.join("target/farm-test");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir)?;
    let mut daemons = Daemons::default();
    let result = (|| -> Result<bool> {
        let conf = daemons.start(&dir)?;
        let size = Size {
            units,
            passes,
            pixels: size,
            photons,
        };
        job(root, &fppm, &dir, &conf, size)
    })();
    daemons.stop();
    result
}

/// The job's size.
#[derive(Clone, Copy)]
struct Size {
    units: u32,
    passes: u32,
    /// Side of the square film.
    pixels: u32,
    photons: u32,
}

/// Runs the job on the cluster and compares it with one process.
fn job(root: &Path, fppm: &Path, dir: &Path, conf: &Path, size: Size) -> Result<bool> {
    let Size {
        units,
        passes,
        pixels,
        photons,
    } = size;
    let scene = root.join(SCENE);
    let (pixels, photons) = (pixels.to_string(), photons.to_string());
    let film = [
        "--width",
        pixels.as_str(),
        "--height",
        pixels.as_str(),
        "--photons-per-pass",
        photons.as_str(),
    ];
    let job = dir.join("job");
    let passes = passes.to_string();
    let status = Command::new(fppm)
        .arg("plan")
        .arg(&scene)
        .arg("-o")
        .arg(&job)
        .args([
            "--passes",
            &passes,
            "--units",
            &units.to_string(),
            "--slurm",
        ])
        .args(film)
        .status()?;
    if !status.success() {
        bail!("fppm plan failed");
    }
    let clock = Instant::now();
    let status = Command::new("sh")
        .arg(job.join("submit.sh"))
        .env("SLURM_CONF", conf)
        .status()?;
    if !status.success() {
        bail!("submitting the job failed");
    }
    let image = job.join("image.exr");
    while !image.exists() {
        if clock.elapsed() > TIMEOUT {
            bail!(
                "the job did not finish within {TIMEOUT:?}; see {}",
                job.display()
            );
        }
        std::thread::sleep(Duration::from_millis(200));
    }
    // The merge writes atomically: the image exists only once complete.
    let cluster_seconds = clock.elapsed().as_secs_f64();
    let single = dir.join("single.exr");
    let clock = Instant::now();
    let status = Command::new(fppm)
        .arg("render")
        .arg(&scene)
        .args(["--method", "appm", "--passes", &passes, "-q", "-o"])
        .arg(&single)
        .args(film)
        .status()?;
    if !status.success() {
        bail!("fppm render failed");
    }
    let single_seconds = clock.elapsed().as_secs_f64();
    let (a, b) = (film::read_exr(&image)?, film::read_exr(&single)?);
    let same = a.pixels.len() == b.pixels.len()
        && a.pixels
            .iter()
            .zip(&b.pixels)
            .all(|(p, q)| p.map(f32::to_bits) == q.map(f32::to_bits));
    println!(
        "farm-test: {units} units on Slurm in {cluster_seconds:.1} s (submit to merged image), \
         one process {single_seconds:.1} s; images {}",
        if same { "bit-identical" } else { "DIFFER" }
    );
    Ok(same)
}

/// Installs slurm-wlm and munge with apt-get if their daemons are missing.
fn install_if_missing() -> Result<()> {
    let present = ["slurmctld", "slurmd", "munged", "sbatch"]
        .iter()
        .all(|d| which(d).is_some());
    if present {
        return Ok(());
    }
    println!("farm-test: installing slurm-wlm and munge with apt-get");
    let status = Command::new("apt-get")
        .args(["install", "-y", "-q", "slurm-wlm", "munge"])
        .env("DEBIAN_FRONTEND", "noninteractive")
        .status()
        .context("running apt-get (farm-test needs root and Debian's packages)")?;
    if !status.success() {
        bail!("apt-get install slurm-wlm munge failed");
    }
    Ok(())
}

fn which(program: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .chain(["/usr/sbin".into(), "/sbin".into()])
        .map(|d| d.join(program))
        .find(|p| p.is_file())
}

/// The daemons this test started, by process id.
#[derive(Default)]
struct Daemons {
    pids: Vec<(String, u32)>,
}

impl Daemons {
    /// Starts munged (unless one runs), slurmctld and slurmd; returns the slurm.conf.
    fn start(&mut self, dir: &Path) -> Result<PathBuf> {
        if !running("munged") {
            for d in [
                "/run/munge",
                "/var/log/munge",
                "/var/lib/munge",
                "/etc/munge",
            ] {
                std::fs::create_dir_all(d)?;
                chown_munge(d)?;
            }
            if !Path::new("/etc/munge/munge.key").exists() {
                let status = Command::new(which("mungekey").context("mungekey is missing")?)
                    .args(["--create", "--keyfile=/etc/munge/munge.key"])
                    .status()?;
                if !status.success() {
                    bail!("mungekey --create failed");
                }
                chown_munge("/etc/munge/munge.key")?;
                Command::new("chmod")
                    .args(["400", "/etc/munge/munge.key"])
                    .status()?;
            }
            // munged refuses to run as root; it forks into the background.
            let status = Command::new("runuser")
                .args(["-u", "munge", "--"])
                .arg(which("munged").context("munged is missing")?)
                .status()?;
            if !status.success() {
                bail!("starting munged failed");
            }
            std::thread::sleep(Duration::from_millis(500));
            if let Some(pid) = pid_of("munged") {
                self.pids.push(("munged".to_owned(), pid));
            }
        }
        let host = String::from_utf8(Command::new("hostname").arg("-s").output()?.stdout)?
            .trim()
            .to_owned();
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let state = dir.join("state");
        let spool = dir.join("spool");
        std::fs::create_dir_all(&state)?;
        std::fs::create_dir_all(&spool)?;
        let conf = dir.join("slurm.conf");
        let d = dir.display();
        std::fs::write(
            &conf,
            format!(
                "ClusterName=fppm-farm-test
SlurmctldHost={host}
AuthType=auth/munge
SlurmUser=root
SlurmdUser=root
SlurmctldPort=6917
SlurmdPort=6918
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
SlurmctldLogFile={d}/slurmctld.log
SlurmdLogFile={d}/slurmd.log
NodeName={host} CPUs={cpus} RealMemory=1024 State=UNKNOWN
PartitionName=farm Nodes=ALL Default=YES MaxTime=INFINITE State=UP
"
            ),
        )?;
        for (daemon, pid_file) in [("slurmctld", "slurmctld.pid"), ("slurmd", "slurmd.pid")] {
            let status =
                Command::new(which(daemon).with_context(|| format!("{daemon} is missing"))?)
                    .arg("-f")
                    .arg(&conf)
                    .env("SLURM_CONF", &conf)
                    .status()?;
            if !status.success() {
                bail!("starting {daemon} failed; see {d}/{daemon}.log");
            }
            let pid_path = dir.join(pid_file);
            let clock = Instant::now();
            while !pid_path.exists() && clock.elapsed() < Duration::from_secs(10) {
                std::thread::sleep(Duration::from_millis(100));
            }
            let pid = std::fs::read_to_string(&pid_path)
                .ok()
                .and_then(|s| s.trim().parse().ok())
                .with_context(|| format!("{daemon} wrote no pid file; see {d}/{daemon}.log"))?;
            self.pids.push((daemon.to_owned(), pid));
        }
        // Wait until the node is up.
        let clock = Instant::now();
        loop {
            let out = Command::new("sinfo")
                .args(["-h", "-o", "%t"])
                .env("SLURM_CONF", &conf)
                .output()?;
            let state = String::from_utf8_lossy(&out.stdout).trim().to_owned();
            if state.starts_with("idle") || state.starts_with("mix") {
                break;
            }
            if clock.elapsed() > Duration::from_secs(30) {
                bail!("the Slurm node did not come up (state {state:?}); see {d}/slurmd.log");
            }
            std::thread::sleep(Duration::from_millis(200));
        }
        Ok(conf)
    }

    /// Stops what was started, newest first.
    fn stop(&mut self) {
        for (name, pid) in self.pids.drain(..).rev() {
            let _ = Command::new("kill").arg(pid.to_string()).status();
            println!("farm-test: stopped {name} ({pid})");
        }
    }
}

fn chown_munge(path: &str) -> Result<()> {
    let status = Command::new("chown").args(["munge:munge", path]).status()?;
    if !status.success() {
        bail!("chown munge {path} failed");
    }
    Ok(())
}

fn running(name: &str) -> bool {
    pid_of(name).is_some()
}

fn pid_of(name: &str) -> Option<u32> {
    let out = Command::new("pgrep")
        .args(["-x", "-o", name])
        .output()
        .ok()?;
    String::from_utf8_lossy(&out.stdout).trim().parse().ok()
}
