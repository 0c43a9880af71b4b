//! Output files: where they may go and how the PNG preview looks. The files themselves are
//! written by the `film` crate (atomically).

use std::path::Path;

use crate::args::TonemapArg;

/// Checks, before any rendering, that `path` can be written: it names a file, not a
/// directory, and its directory accepts a new file. `what` names the flag, e.g. `-o`.
pub(crate) fn check_writable(path: &Path, what: &str) -> anyhow::Result<()> {
    if path.file_name().is_none() {
        anyhow::bail!(
            "{}: {what} needs a file name, not a directory",
            path.display()
        );
    }
    if path.is_dir() {
        anyhow::bail!("{}: {what} names a directory, not a file", path.display());
    }
    film::check_writable(path).map_err(|e| anyhow::anyhow!("{e} (the {what} output)"))
}

/// Exposure and tone curve of the PNG preview, as the flags give them.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tonemap {
    /// Stops: linear values are scaled by 2^exposure.
    pub(crate) exposure: f32,
    pub(crate) curve: TonemapArg,
}

impl Tonemap {
    /// The tone mapping `film` applies.
    pub(crate) fn film(self) -> film::Tonemap {
        let curve = match self.curve {
            TonemapArg::Srgb => film::Curve::Srgb,
            TonemapArg::Filmic => film::Curve::Filmic,
        };
        film::Tonemap::with_stops(self.exposure, curve)
    }
}
