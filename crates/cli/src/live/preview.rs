//! `--preview`: a small HTTP server (tiny_http) on its own thread that serves one page
//! (`page.html`) and what the page asks for:
//!
//! - `GET /` the page;
//! - `GET /status` the [`Status`] as JSON (polled twice a second by the page);
//! - `GET /image.png?exposure=EV&tonemap=srgb|filmic` the latest image, tone-mapped as
//!   `--exposure` and `--tonemap` do for the PNG output (`film::encode_png`);
//! - `POST /stop` stops the render after the current pass, as Ctrl-C does.
//!
//! The render loop reads the image for the page only while someone asks for it: a request of
//! the last [`Preview::WATCH`] makes the page "watched".

use std::net::TcpListener;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::Context;

use super::{Status, resolve};

/// Where `--preview` alone listens; if that port is taken, on a free port of the same address.
const DEFAULT_ADDRESS: &str = "127.0.0.1:8700";

/// The page, with its script and style.
const PAGE: &str = include_str!("page.html");

/// What the render loop and the server thread share.
struct Shared {
    /// The latest status, as JSON.
    status: Mutex<String>,
    /// The latest image and its number (from 1).
    image: Mutex<Option<(u64, Arc<film::Frame>)>>,
    /// Milliseconds from `started` to the latest request; 0 before the first.
    last_request: AtomicU64,
    started: Instant,
    /// Set by `POST /stop`.
    stop: AtomicBool,
    /// The number of the latest image served as a PNG.
    served: AtomicU64,
}

/// The running server.
pub(super) struct Preview {
    server: Arc<tiny_http::Server>,
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
    url: String,
}

impl Preview {
    /// A request this recent means someone is watching.
    const WATCH: Duration = Duration::from_secs(3);

    /// Binds `spec` (`HOST:PORT`, or empty for the default) and starts serving.
    pub(super) fn start(spec: &str) -> anyhow::Result<Self> {
        let (listener, note) = bind(spec)?;
        let address = listener
            .local_addr()
            .context("--preview: cannot read the address listened on")?;
        let server = tiny_http::Server::from_listener(listener, None)
            .map_err(|e| anyhow::anyhow!("--preview {address}: cannot serve: {e}"))?;
        let server = Arc::new(server);
        let shared = Arc::new(Shared {
            status: Mutex::new("{}".to_owned()),
            image: Mutex::new(None),
            last_request: AtomicU64::new(0),
            started: Instant::now(),
            stop: AtomicBool::new(false),
            served: AtomicU64::new(0),
        });
        let thread = {
            let (server, shared) = (Arc::clone(&server), Arc::clone(&shared));
            std::thread::Builder::new()
                .name("fppm-preview".to_owned())
                .spawn(move || serve(&server, &shared))
                .context("cannot start the preview's thread")?
        };
        let url = format!("http://{address}/");
        // Printed even with --quiet: the address is what the flag asked for.
        eprintln!("fppm: preview at {url}{note}");
        Ok(Preview {
            server,
            shared,
            thread: Some(thread),
            url,
        })
    }

    pub(super) fn url(&self) -> &str {
        &self.url
    }

    pub(super) fn stop_requested(&self) -> bool {
        self.shared.stop.load(Ordering::SeqCst)
    }

    /// Whether a request came in the last [`Preview::WATCH`].
    pub(super) fn watched(&self) -> bool {
        let last = self.shared.last_request.load(Ordering::Relaxed);
        last > 0
            && millis(self.shared.started).saturating_sub(last) <= Self::WATCH.as_millis() as u64
    }

    /// The status after a pass, and a new image if there is one.
    pub(super) fn publish(&self, status: &Status, frame: Option<&Arc<film::Frame>>) {
        let mut status = status.clone();
        if self.stop_requested() && status.state == "rendering" {
            status.state = "stopping";
        }
        if let Some(frame) = frame {
            let mut slot = self
                .shared
                .image
                .lock()
                .unwrap_or_else(PoisonError::into_inner);
            let number = slot.as_ref().map_or(1, |(n, _)| n + 1);
            *slot = Some((number, Arc::clone(frame)));
        }
        let number = self
            .shared
            .image
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .as_ref()
            .map_or(0, |(n, _)| *n);
        let mut json = serde_json::to_value(&status).unwrap_or_default();
        json["image"] = serde_json::json!(number);
        *self
            .shared
            .status
            .lock()
            .unwrap_or_else(PoisonError::into_inner) = json.to_string();
    }
}

impl Preview {
    /// Once the final image is published: while a page is watching, gives it up to
    /// two seconds to fetch that image before the process exits.
    pub(super) fn linger(&self) {
        const LINGER: Duration = Duration::from_secs(2);
        let latest = self
            .shared
            .image
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .as_ref()
            .map_or(0, |(n, _)| *n);
        let start = Instant::now();
        while self.watched()
            && self.shared.served.load(Ordering::Relaxed) < latest
            && start.elapsed() < LINGER
        {
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Preview {
    fn drop(&mut self) {
        self.server.unblock();
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The listener for `spec`, and a note for the address line when the default port was taken.
fn bind(spec: &str) -> anyhow::Result<(TcpListener, String)> {
    if spec.is_empty() {
        return match TcpListener::bind(DEFAULT_ADDRESS) {
            Ok(listener) => Ok((listener, String::new())),
            Err(e) if e.kind() == std::io::ErrorKind::AddrInUse => {
                let listener = TcpListener::bind("127.0.0.1:0")
                    .context("--preview: cannot listen on a free port of 127.0.0.1")?;
                Ok((listener, format!(" ({DEFAULT_ADDRESS} is taken)")))
            }
            Err(e) => Err(anyhow::anyhow!(
                "--preview {DEFAULT_ADDRESS}: cannot listen: {}",
                film::lower_first(&e.to_string())
            )),
        };
    }
    let (_, addresses) = resolve("--preview", spec)?;
    let listener = TcpListener::bind(&addresses[..]).map_err(|e| {
        anyhow::anyhow!(
            "--preview {spec}: cannot listen: {}",
            film::lower_first(&e.to_string())
        )
    })?;
    Ok((listener, String::new()))
}

fn millis(since: Instant) -> u64 {
    since.elapsed().as_millis() as u64
}

/// What a served PNG was made from: the image's number, the exposure's scale (bits) and the curve.
type PngKey = (u64, u32, film::Curve);

/// Answers requests until the server is unblocked.
fn serve(server: &tiny_http::Server, shared: &Shared) {
    // The last PNG and what it was made from (image number, exposure, curve): browsers ask again
    // for the same one when the page only polls.
    let mut cache: Option<(PngKey, Arc<Vec<u8>>)> = None;
    for request in server.incoming_requests() {
        shared
            .last_request
            .store(millis(shared.started).max(1), Ordering::Relaxed);
        let url = request.url().to_owned();
        let (path, query) = url.split_once('?').unwrap_or((&url, ""));
        let method = request.method().clone();
        let response = match (&method, path) {
            (tiny_http::Method::Get, "/") => {
                reply(PAGE.as_bytes().to_vec(), "text/html; charset=utf-8")
            }
            (tiny_http::Method::Get, "/status") => {
                let status = shared
                    .status
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .clone();
                reply(status.into_bytes(), "application/json")
            }
            (tiny_http::Method::Get, "/image.png") => {
                let latest = shared
                    .image
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .clone();
                match latest {
                    None => text(503, "no image yet: the first pass is still running"),
                    Some((number, image)) => {
                        let tonemap = tonemap_of(query);
                        let key = (number, tonemap.scale.to_bits(), tonemap.curve);
                        let png = match &cache {
                            Some((k, png)) if *k == key => Arc::clone(png),
                            _ => {
                                let png = Arc::new(film::encode_png(&image.image, tonemap));
                                cache = Some((key, Arc::clone(&png)));
                                png
                            }
                        };
                        shared.served.fetch_max(number, Ordering::Relaxed);
                        reply(png.to_vec(), "image/png")
                    }
                }
            }
            (tiny_http::Method::Post, "/stop") => {
                shared.stop.store(true, Ordering::SeqCst);
                reply(b"{\"stopping\":true}".to_vec(), "application/json")
            }
            (_, "/" | "/status" | "/image.png" | "/stop") => text(405, "method not allowed"),
            _ => text(404, "not found"),
        };
        // A browser that went away is not worth stopping the render for.
        let _ = request.respond(response);
    }
}

/// A 200 response with `body` of `content_type`.
fn reply(body: Vec<u8>, content_type: &str) -> tiny_http::Response<std::io::Cursor<Vec<u8>>> {
    // An image's address names its number, exposure and curve: it may be kept.
    let cache = if content_type == "image/png" {
        "private, max-age=600"
    } else {
        "no-store"
    };
    let mut response = tiny_http::Response::from_data(body);
    for (name, value) in [("Content-Type", content_type), ("Cache-Control", cache)] {
        if let Ok(header) = tiny_http::Header::from_bytes(name.as_bytes(), value.as_bytes()) {
            response.add_header(header);
        }
    }
    response
}

/// A plain-text response with `code`.
fn text(code: u16, message: &str) -> tiny_http::Response<std::io::Cursor<Vec<u8>>> {
    reply(message.as_bytes().to_vec(), "text/plain; charset=utf-8").with_status_code(code)
}

/// The tone mapping a query asks for: `exposure` in stops (clamped to ±20) and `tonemap`;
/// what is missing or malformed is 0 EV and sRGB.
fn tonemap_of(query: &str) -> film::Tonemap {
    let mut stops = 0.0f32;
    let mut curve = film::Curve::Srgb;
    for pair in query.split('&') {
        match pair.split_once('=') {
            Some(("exposure", v)) => {
                if let Ok(ev) = v.parse::<f32>()
                    && ev.is_finite()
                {
                    stops = ev.clamp(-20.0, 20.0);
                }
            }
            Some(("tonemap", "filmic")) => curve = film::Curve::Filmic,
            Some(("tonemap", "srgb")) => curve = film::Curve::Srgb,
            _ => {}
        }
    }
    film::Tonemap::with_stops(stops, curve)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_query_sets_exposure_and_curve() {
        assert_eq!(
            tonemap_of(""),
            film::Tonemap::with_stops(0.0, film::Curve::Srgb)
        );
        assert_eq!(
            tonemap_of("v=3&exposure=-1.5&tonemap=filmic"),
            film::Tonemap::with_stops(-1.5, film::Curve::Filmic)
        );
        assert_eq!(
            tonemap_of("exposure=NaN&tonemap=other"),
            film::Tonemap::with_stops(0.0, film::Curve::Srgb)
        );
        assert_eq!(
            tonemap_of("exposure=1e9"),
            film::Tonemap::with_stops(20.0, film::Curve::Srgb)
        );
    }
}
