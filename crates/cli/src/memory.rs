//! The memory bound: a render whose estimated memory ([`ppm::MemoryEstimate`]) exceeds the
//! limit is refused before anything is allocated, with one line saying how much it needs and
//! which flag to lower.

use crate::usage;

/// Share of physical memory a render may use unless `--max-memory` says otherwise.
const DEFAULT_SHARE: f64 = 0.8;

/// The memory limit of a render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Limit {
    /// Bytes; `None`: no limit (`--max-memory none`, or physical memory unknown).
    bytes: Option<u64>,
    /// Whether the limit is the default share of physical memory.
    default: bool,
}

impl Limit {
    /// The limit from `--max-memory` (`None`: the default).
    pub(crate) fn from_flag(flag: Option<&str>) -> anyhow::Result<Self> {
        match flag {
            None => {
                let mut system = sysinfo::System::new();
                system.refresh_memory();
                let physical = system.total_memory();
                Ok(Self {
                    bytes: (physical > 0).then_some((physical as f64 * DEFAULT_SHARE) as u64),
                    default: true,
                })
            }
            Some(text) if text.trim().eq_ignore_ascii_case("none") => Ok(Self {
                bytes: None,
                default: false,
            }),
            Some(text) => match parse_size(text) {
                Some(bytes) if bytes > 0 => Ok(Self {
                    bytes: Some(bytes),
                    default: false,
                }),
                _ => usage!(
                    "--max-memory {text} is not a size such as 8G, 512M, 2T or none (K, M, G, T are powers of 1024)"
                ),
            },
        }
    }

    /// Refuses the render of a `width × height` film with `params` if its estimate exceeds the
    /// limit.
    pub(crate) fn check(
        self,
        width: u32,
        height: u32,
        params: &ppm::RenderParams,
        with_checkpoint: bool,
    ) -> anyhow::Result<()> {
        let Some(limit) = self.bytes else {
            return Ok(());
        };
        let estimate = ppm::MemoryEstimate::of(width, height, params);
        let total = estimate.total(with_checkpoint);
        if total <= limit {
            return Ok(());
        }
        let checkpoint = if with_checkpoint {
            estimate.checkpoint
        } else {
            0
        };
        let pixels = if params.method.is_photon_mapper() {
            "lower --width/--height or --spp"
        } else {
            "lower --width/--height"
        };
        let mut parts = [
            (estimate.hitpoints + checkpoint, "hitpoints", pixels),
            (
                estimate.photons,
                "photon buffers",
                "lower --photons-per-pass",
            ),
            (estimate.film, "image", "lower --width/--height"),
        ];
        parts.sort_by_key(|&(bytes, _, _)| std::cmp::Reverse(bytes));
        let breakdown: Vec<String> = parts
            .iter()
            .filter(|&&(bytes, _, _)| bytes * 20 >= total)
            .map(|&(bytes, what, flag)| format!("{} for the {what}: {flag}", format_size(bytes)))
            .collect();
        let whose = if self.default {
            format!(
                "{:.0} % of physical memory; --max-memory to change",
                DEFAULT_SHARE * 100.0
            )
        } else {
            "--max-memory".to_owned()
        };
        usage!(
            "the render needs about {} ({}), more than the limit of {} ({whose})",
            format_size(total),
            breakdown.join("; "),
            format_size(limit)
        )
    }
}

/// `8G`, `512M`, `1.5G`, `2048` (bytes); K, M, G and T are powers of 1024.
fn parse_size(text: &str) -> Option<u64> {
    let text = text.trim();
    let (number, unit) = match text.char_indices().find(|(_, c)| c.is_ascii_alphabetic()) {
        Some((i, _)) => (&text[..i], text[i..].to_ascii_uppercase()),
        None => (text, String::new()),
    };
    let scale: u64 = match unit.trim_end_matches("IB").trim_end_matches('B') {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        "T" => 1 << 40,
        _ => return None,
    };
    let value: f64 = number.trim().parse().ok()?;
    let bytes = value * scale as f64;
    (bytes.is_finite() && bytes >= 0.0 && bytes < u64::MAX as f64).then_some(bytes as u64)
}

/// `12.3 GiB`.
fn format_size(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} B")
    } else {
        format!("{value:.1} {}", UNITS[unit])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_in_powers_of_1024() {
        assert_eq!(parse_size("2048"), Some(2048));
        assert_eq!(parse_size("8G"), Some(8 << 30));
        assert_eq!(parse_size("512M"), Some(512 << 20));
        assert_eq!(parse_size("1.5g"), Some(3 << 29));
        assert_eq!(parse_size("2 GiB"), Some(2 << 30));
        assert_eq!(parse_size("1T"), Some(1 << 40));
        for bad in ["", "G", "12X", "-1G", "nan", "1e30T"] {
            assert_eq!(parse_size(bad), None, "{bad}");
        }
    }

    #[test]
    fn sizes_print_in_binary_units() {
        assert_eq!(format_size(512), "512 B");
        assert_eq!(format_size(3 << 29), "1.5 GiB");
    }
}
