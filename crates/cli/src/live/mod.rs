//! Watching a render while it runs: the preview page of `--preview` (`preview.rs`, with
//! `page.html`) and the tev stream of `--display-server` (`tev.rs`).
//!
//! Each runs on its own thread; the render loop only hands them, after a pass, what they need
//! and never waits for them. A render without either opens no socket and starts no thread.
//! The image is read from the renderer (which changes nothing in it) at most every
//! [`Live::PERIOD`], and for the page only while a browser is looking; images are bit for bit
//! those of a render without a live view.

mod preview;
mod tev;

use std::net::{SocketAddr, ToSocketAddrs};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::args::LiveArgs;
use crate::usage;

/// What the live views show besides the image, after each pass.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub(crate) struct Status {
    /// Which render this is (process id and start time): a page left open across renders on
    /// one address starts afresh when it changes.
    pub(crate) run: String,
    /// The scene file (or the built-in scene's name).
    pub(crate) scene: String,
    pub(crate) method: String,
    pub(crate) width: u32,
    pub(crate) height: u32,
    /// Passes in total.
    pub(crate) pass: u32,
    /// The pass budget, if there is one.
    pub(crate) passes: Option<u32>,
    /// The time budget of this run, in seconds, if there is one.
    pub(crate) time_budget: Option<f64>,
    pub(crate) photons: u64,
    /// Seconds into this run.
    pub(crate) elapsed: f64,
    /// Seconds left, estimated.
    pub(crate) remaining: Option<f64>,
    /// Share of the budget spent, in [0, 1].
    pub(crate) fraction: f64,
    /// The latest error trend (`trend.rs`).
    pub(crate) error_trend: Option<f64>,
    /// `rendering`, `stopping` (after this pass), `writing` (the outputs) or `done`.
    pub(crate) state: &'static str,
    /// The exposure (EV) and tone curve of the PNG, the page's starting point.
    pub(crate) exposure: f32,
    pub(crate) tonemap: &'static str,
}

/// The live views of one render.
pub(crate) struct Live {
    preview: Option<preview::Preview>,
    tev: Option<tev::Stream>,
    /// When the views last got an image.
    last_image: Option<Instant>,
}

impl Live {
    /// The views get a new image at most this often (and after a pass, never during one).
    pub(crate) const PERIOD: Duration = Duration::from_millis(500);

    /// Opens what `args` ask for: binds the preview's socket (an error if it cannot) and starts
    /// the tev stream (which connects on its own thread and retries after each pass). `title`
    /// names the image in tev; `channels` are the AOV channels after R, G and B.
    pub(crate) fn start(args: &LiveArgs, title: &str, quiet: bool) -> anyhow::Result<Self> {
        // Both flags are checked before either starts.
        let tev_address = args
            .display_server
            .as_deref()
            .map(|text| resolve("--display-server", text))
            .transpose()?;
        let preview = args
            .preview
            .as_deref()
            .map(preview::Preview::start)
            .transpose()?;
        let tev = tev_address.map(|(text, addresses)| {
            tev::Stream::start(
                text,
                addresses,
                format!("{title} ({})", std::process::id()),
                quiet,
            )
        });
        Ok(Live {
            preview,
            tev,
            last_image: None,
        })
    }

    /// Whether any view is open.
    pub(crate) fn is_on(&self) -> bool {
        self.preview.is_some() || self.tev.is_some()
    }

    /// The page's address, if the preview is on.
    pub(crate) fn url(&self) -> Option<&str> {
        self.preview.as_ref().map(preview::Preview::url)
    }

    /// Whether the stop button of the page was pressed.
    pub(crate) fn stop_requested(&self) -> bool {
        self.preview
            .as_ref()
            .is_some_and(preview::Preview::stop_requested)
    }

    /// Whether the views want an image after this pass: one is watching and the last image is
    /// at least `period` old (at least [`Live::PERIOD`], longer where reading one is costly).
    pub(crate) fn wants_image(&self, period: Duration) -> bool {
        let watched =
            self.tev.is_some() || self.preview.as_ref().is_some_and(preview::Preview::watched);
        watched && self.last_image.is_none_or(|t| t.elapsed() >= period)
    }

    /// Whether the views that want an image also want the AOV channels (tev shows them).
    pub(crate) fn wants_aovs(&self) -> bool {
        self.tev.is_some()
    }

    /// After a pass (or at the end): the status, and the frame if [`Live::wants_image`] asked
    /// for one.
    pub(crate) fn publish(&mut self, status: &Status, frame: Option<&Arc<film::Frame>>) {
        if frame.is_some() {
            self.last_image = Some(Instant::now());
        }
        if let Some(preview) = &self.preview {
            preview.publish(status, frame);
        }
        if let (Some(tev), Some(frame)) = (&self.tev, frame) {
            tev.send(Arc::clone(frame));
        }
    }

    /// What the views' threads have to say (a lost connection), to print between passes.
    pub(crate) fn notes(&self) -> Vec<String> {
        self.tev
            .as_ref()
            .map(tev::Stream::notes)
            .unwrap_or_default()
    }

    /// The final frame and status: the tev stream sends it (and ends, after at most a few
    /// seconds if tev does not read), the page shows it until the process exits.
    pub(crate) fn finish(mut self, status: &Status, frame: &Arc<film::Frame>) -> Vec<String> {
        if let Some(preview) = &self.preview {
            preview.publish(status, Some(frame));
        }
        let notes = match self.tev.take() {
            Some(tev) => tev.finish(Arc::clone(frame)),
            None => Vec::new(),
        };
        if let Some(preview) = &self.preview {
            preview.linger();
        }
        notes
    }
}

/// `HOST:PORT` given to `flag`, resolved: a host name, an IPv4 address or an IPv6 address in
/// brackets, and a port. Anything else is a usage error.
fn resolve<'a>(flag: &str, text: &'a str) -> anyhow::Result<(&'a str, Vec<SocketAddr>)> {
    let well_formed = text
        .rsplit_once(':')
        .is_some_and(|(host, port)| !host.is_empty() && port.parse::<u16>().is_ok());
    if !well_formed {
        usage!("{flag} {text:?}: expected HOST:PORT, e.g. 127.0.0.1:14158");
    }
    let addresses: Vec<SocketAddr> = match text.to_socket_addrs() {
        Ok(addresses) => addresses.collect(),
        Err(e) => usage!("{flag} {text}: {}", film::lower_first(&e.to_string())),
    };
    if addresses.is_empty() {
        usage!("{flag} {text}: the host has no address");
    }
    Ok((text, addresses))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses_need_a_host_and_a_port() {
        for bad in [
            "",
            "8700",
            ":8700",
            "localhost",
            "127.0.0.1:",
            "127.0.0.1:99999",
            "a:b",
        ] {
            let err = resolve("--preview", bad).expect_err(bad);
            assert!(err.downcast_ref::<crate::UsageError>().is_some(), "{bad}");
            assert!(err.to_string().contains("HOST:PORT"), "{err}");
        }
        let (_, v4) = resolve("--preview", "127.0.0.1:8700").expect("IPv4");
        assert_eq!(v4, [SocketAddr::from(([127, 0, 0, 1], 8700))]);
        let (_, v6) = resolve("--preview", "[::1]:0").expect("IPv6");
        assert!(v6[0].is_ipv6());
    }
}
