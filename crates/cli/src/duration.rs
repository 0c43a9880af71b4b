//! Durations on the command line: `30s`, `2m`, `1h30m`, `500ms`, `1.5s`; a bare number is
//! seconds.

use std::time::Duration;

/// Parses a duration that must be longer than zero (`--time`, `--snapshot-every`).
pub(crate) fn parse_positive(text: &str) -> Result<Duration, String> {
    let d = parse(text)?;
    if d.is_zero() {
        return Err("must be longer than zero".to_string());
    }
    Ok(d)
}

/// Parses a sequence of number-unit pairs (units: ms, s, m or min, h).
pub(crate) fn parse(text: &str) -> Result<Duration, String> {
    const HINT: &str = "expected a duration such as 30s, 2m, 1h30m or 500ms";
    let text = text.trim();
    if text.is_empty() {
        return Err(HINT.to_string());
    }
    if let Ok(seconds) = text.parse::<f64>() {
        return seconds_to_duration(seconds).ok_or_else(|| HINT.to_string());
    }
    let mut total = 0.0f64;
    let mut rest = text;
    while !rest.is_empty() {
        let number_len = rest
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(rest.len());
        let unit_len = rest[number_len..]
            .find(|c: char| c.is_ascii_digit() || c == '.')
            .unwrap_or(rest.len() - number_len);
        let number: f64 = rest[..number_len].parse().map_err(|_| HINT.to_string())?;
        let unit = rest[number_len..number_len + unit_len].trim();
        let scale = match unit {
            "ms" => 1e-3,
            "s" | "sec" => 1.0,
            "m" | "min" => 60.0,
            "h" => 3600.0,
            _ => return Err(HINT.to_string()),
        };
        total += number * scale;
        rest = &rest[number_len + unit_len..];
    }
    seconds_to_duration(total).ok_or_else(|| HINT.to_string())
}

fn seconds_to_duration(seconds: f64) -> Option<Duration> {
    Duration::try_from_secs_f64(seconds).ok()
}

/// `1.5s`, `2m05s`, `1h02m`: short and readable.
pub(crate) fn format(d: Duration) -> String {
    let s = d.as_secs_f64();
    if s < 60.0 {
        format!("{s:.1}s")
    } else if s < 3600.0 {
        format!("{}m{:02}s", (s / 60.0) as u64, (s % 60.0) as u64)
    } else {
        format!(
            "{}h{:02}m",
            (s / 3600.0) as u64,
            ((s % 3600.0) / 60.0) as u64
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units() {
        assert_eq!(parse("30s"), Ok(Duration::from_secs(30)));
        assert_eq!(parse("2m"), Ok(Duration::from_secs(120)));
        assert_eq!(parse("1h"), Ok(Duration::from_secs(3600)));
        assert_eq!(parse("500ms"), Ok(Duration::from_millis(500)));
        assert_eq!(parse("1h30m"), Ok(Duration::from_secs(5400)));
        assert_eq!(parse("1.5s"), Ok(Duration::from_millis(1500)));
        assert_eq!(parse("12"), Ok(Duration::from_secs(12)));
    }

    #[test]
    fn refusals() {
        assert!(parse("").is_err());
        assert!(parse("s").is_err());
        assert!(parse("10 parsecs").is_err());
        assert!(parse("-3s").is_err());
        assert!(parse_positive("0s").is_err());
        assert!(parse_positive("0").is_err());
    }

    #[test]
    fn formatting() {
        assert_eq!(format(Duration::from_millis(1500)), "1.5s");
        assert_eq!(format(Duration::from_secs(125)), "2m05s");
        assert_eq!(format(Duration::from_secs(3720)), "1h02m");
    }
}
