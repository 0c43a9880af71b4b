//! The command line of `cargo xtask converge`, its clocks and the parameter overrides.

use super::*;

pub(super) struct Flags {
    pub(super) scene: String,
    pub(super) budgets: Vec<f64>,
    pub(super) methods: Vec<ppm::Method>,
    pub(super) photons: u32,
    pub(super) seed: u64,
    pub(super) out: Option<PathBuf>,
    pub(super) quick: bool,
    pub(super) sweep: bool,
    pub(super) replot: bool,
    pub(super) budget: f64,
    pub(super) pointwise: Option<u32>,
    pub(super) film: Option<(u32, u32)>,
    pub(super) clock: Clock,
    pub(super) overrides: Overrides,
}

/// What a budget's seconds measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Clock {
    /// Wall-clock seconds (the default).
    Wall,
    /// Process CPU seconds (user + system, from `/proc/self/stat`) divided by the number of
    /// rayon threads: on an idle machine the same as wall-clock, on a shared one what the
    /// method would have taken alone. For comparisons while other jobs run.
    Cpu,
}

impl Clock {
    pub(super) fn now(self) -> (Instant, f64) {
        (
            Instant::now(),
            if self == Clock::Cpu {
                process_cpu_seconds()
            } else {
                0.0
            },
        )
    }

    pub(super) fn since(self, (wall, cpu): (Instant, f64)) -> Duration {
        match self {
            Clock::Wall => wall.elapsed(),
            Clock::Cpu => {
                Duration::from_secs_f64(((process_cpu_seconds() - cpu) / threads()).max(0.0))
            }
        }
    }
}

/// The threads the renderer uses: rayon's default pool size.
pub(super) fn threads() -> f64 {
    std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
        .filter(|&n| n > 0)
        .or_else(|| std::thread::available_parallelism().ok().map(usize::from))
        .unwrap_or(1) as f64
}

/// CPU seconds (user + system) used by this process so far, from `/proc/self/stat`
/// (fields 14 and 15, in clock ticks of 10 ms); 0 where it cannot be read.
pub(super) fn process_cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // The command name (field 2) may contain spaces: count fields after its closing ')'.
    let Some(rest) = stat.rsplit_once(')').map(|(_, r)| r) else {
        return 0.0;
    };
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|f| f.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    // After ')': field 3 is index 0, so utime (14) is index 11 and stime (15) index 12.
    (ticks(11) + ticks(12)) / 100.0
}

/// Render parameters given on the command line or varied by the sweep: `(name, text)` pairs
/// that `ppm::RenderParams::set` reads (names, parsing and ranges are defined there).
#[derive(Clone, Debug, Default)]
pub(super) struct Overrides(Vec<(&'static str, String)>);

impl Overrides {
    /// One parameter.
    pub(super) fn one(name: &str, value: impl ToString) -> Self {
        let mut o = Self::default();
        o.push(name, value.to_string())
            .expect("a parameter of ppm::PARAMS");
        o
    }

    /// Adds (or replaces) the parameter called `name` (with `-` or `_`).
    pub(super) fn push(&mut self, name: &str, value: String) -> Result<()> {
        let param = ppm::param(name).with_context(|| format!("unknown parameter `{name}`"))?;
        self.0.retain(|(n, _)| *n != param.name);
        self.0.push((param.name, value));
        Ok(())
    }

    pub(super) fn apply(&self, params: &mut ppm::RenderParams) -> Result<()> {
        for (name, value) in &self.0 {
            params.set(name, value)?;
        }
        Ok(())
    }

    /// Whether every parameter given is one of `names`.
    pub(super) fn only(&self, names: &[&str]) -> bool {
        self.0.iter().all(|(n, _)| names.contains(n))
    }

    pub(super) fn label(&self, defaults: &ppm::RenderParams) -> Result<String> {
        let mut p = *defaults;
        self.apply(&mut p)?;
        Ok(format!(
            "alpha={:.3} ff={} k={} merge={} geometry={}",
            p.kernel.alpha,
            p.frequency.fraction,
            k_name(p.frequency.kernel_k),
            value_of("freq_merge", &p),
            value_of("freq_geometry", &p),
        ))
    }
}

/// The text of the parameter called `name` in `params`.
pub(super) fn value_of(name: &str, params: &ppm::RenderParams) -> String {
    ppm::param(name).map_or_else(String::new, |p| p.get(params))
}

/// K by the name of its constant where it has one.
pub(super) fn k_name(k: f64) -> String {
    if (k - ppm::K_POSTER).abs() < 1e-12 {
        "poster".to_string()
    } else if (k - ppm::K_STRICT).abs() < 1e-12 {
        "strict".to_string()
    } else {
        format!("{k}")
    }
}

pub(super) fn parse_list<T>(text: &str, f: impl Fn(&str) -> Result<T>) -> Result<Vec<T>> {
    text.split(',')
        .filter(|s| !s.is_empty())
        .map(|s| f(s.trim()))
        .collect()
}

impl Flags {
    pub(super) fn parse(args: &[String]) -> Result<Self> {
        let mut flags = Flags {
            scene: String::new(),
            budgets: vec![2.0, 4.0, 8.0, 16.0, 32.0],
            methods: ppm::Method::ALL.to_vec(),
            photons: 100_000,
            seed: 1,
            out: None,
            quick: false,
            sweep: false,
            replot: false,
            budget: 8.0,
            clock: Clock::Wall,
            film: None,
            pointwise: None,
            overrides: Overrides::default(),
        };
        let mut methods_given = false;
        let mut it = args.iter();
        while let Some(arg) = it.next() {
            let mut value = || it.next().with_context(|| format!("{arg} needs a value"));
            match arg.as_str() {
                "--scene" => flags.scene = value()?.clone(),
                "--budgets" => flags.budgets = parse_list(value()?, |s| Ok(s.parse::<f64>()?))?,
                "--budget" => flags.budget = value()?.parse()?,
                "--methods" => {
                    methods_given = true;
                    flags.methods = parse_list(value()?, |s| {
                        ppm::Method::from_name(s).with_context(|| format!("unknown method `{s}`"))
                    })?;
                }
                "--photons" => flags.photons = value()?.parse()?,
                "--seed" => flags.seed = value()?.parse()?,
                "--out" => flags.out = Some(PathBuf::from(value()?)),
                "--quick" => flags.quick = true,
                "--sweep" => flags.sweep = true,
                "--replot" => flags.replot = true,
                "--pointwise" => flags.pointwise = Some(value()?.parse()?),
                "--film" => {
                    let v = value()?;
                    let (w, h) = v
                        .split_once('x')
                        .with_context(|| format!("--film takes WIDTHxHEIGHT, not `{v}`"))?;
                    let (w, h): (u32, u32) = (w.parse()?, h.parse()?);
                    if w == 0 || h == 0 || w > 4096 || h > 4096 {
                        bail!("--film {v}: each side must be in [1, 4096]");
                    }
                    flags.film = Some((w, h));
                }
                "--clock" => {
                    flags.clock = match value()?.as_str() {
                        "wall" => Clock::Wall,
                        "cpu" => Clock::Cpu,
                        other => bail!("--clock takes wall or cpu, not `{other}`"),
                    };
                }
                // Any render parameter by its name, e.g. --alpha 0.5, --kernel-k poster,
                // --freq-geometry off.
                other if other.starts_with("--") && ppm::param(&other[2..]).is_some() => {
                    flags.overrides.push(&other[2..], value()?.clone())?;
                }
                other => bail!("converge: unknown flag `{other}`"),
            }
        }
        if flags.scene.is_empty() {
            bail!("converge: --scene NAME is required (a name from tests/scenes.toml)");
        }
        if flags.quick {
            flags.budgets = vec![1.0, 2.0];
            flags.budget = 1.0;
        }
        if flags.sweep && !methods_given {
            flags.methods = vec![ppm::Method::FreqPpm, ppm::Method::Ppm];
        }
        if flags
            .budgets
            .iter()
            .any(|b| b.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
        {
            bail!("converge: budgets must be positive seconds");
        }
        flags.budgets.sort_by(f64::total_cmp);
        if flags.film.is_some() && flags.pointwise.is_none() {
            bail!(
                "converge: --film needs --pointwise (the golden references have the suite's film size)"
            );
        }
        if flags.pointwise.is_some()
            && flags
                .methods
                .iter()
                .any(|m| !matches!(m, ppm::Method::Ppm | ppm::Method::FreqPpm))
        {
            bail!("converge: --pointwise needs --methods ppm,freq (the fixed-hitpoint methods)");
        }
        Ok(flags)
    }
}
