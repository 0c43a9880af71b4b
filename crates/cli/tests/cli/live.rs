//! The live views of a render: `--display-server` read back by a tev stand-in that decodes
//! pbrt-v4's packets and rebuilds the image, `--preview` opened in headless Chromium, the
//! error trend, bad addresses, and images unchanged by all of it.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Read};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use super::{CORNELL, TINY, fppm, read_exr, render_cornell, temp_dir};

/// One channel image as the tev stand-in rebuilt it.
type Channels = BTreeMap<String, Vec<f32>>;

/// What the stand-in read on one connection.
#[derive(Debug, Default)]
struct Received {
    title: String,
    width: usize,
    height: usize,
    channels: Channels,
    updates: usize,
}

/// A little-endian reader over one packet's body.
struct Fields<'a>(&'a [u8]);

impl Fields<'_> {
    fn u8(&mut self) -> u8 {
        let v = self.0[0];
        self.0 = &self.0[1..];
        v
    }

    fn i32(&mut self) -> i32 {
        let v = i32::from_le_bytes(self.0[..4].try_into().unwrap());
        self.0 = &self.0[4..];
        v
    }

    fn f32(&mut self) -> f32 {
        let v = f32::from_le_bytes(self.0[..4].try_into().unwrap());
        self.0 = &self.0[4..];
        v
    }

    fn string(&mut self) -> String {
        let end = self
            .0
            .iter()
            .position(|&b| b == 0)
            .expect("a NUL-terminated string");
        let s = String::from_utf8(self.0[..end].to_vec()).unwrap();
        self.0 = &self.0[end + 1..];
        s
    }
}

/// Reads packets as tev does (`Ipc.cpp`: a `u32` length that counts itself, a type byte) until
/// the connection ends or `stop_after` update packets came; rebuilds the image.
fn read_stream(stream: &mut TcpStream, stop_after: Option<usize>) -> Received {
    let mut received = Received::default();
    loop {
        let mut length = [0u8; 4];
        if stream.read_exact(&mut length).is_err() {
            return received;
        }
        let length = u32::from_le_bytes(length) as usize;
        assert!(length > 5, "packet of {length} bytes");
        let mut body = vec![0u8; length - 4];
        stream.read_exact(&mut body).unwrap();
        let mut fields = Fields(&body);
        match fields.u8() {
            4 => {
                assert_eq!(fields.u8(), 1, "create image grabs the focus");
                received.title = fields.string();
                received.width = fields.i32() as usize;
                received.height = fields.i32() as usize;
                let n = fields.i32();
                received.channels = (0..n)
                    .map(|_| (fields.string(), vec![0.0; received.width * received.height]))
                    .collect();
                assert!(fields.0.is_empty(), "trailing bytes in create image");
            }
            3 => {
                assert_eq!(fields.u8(), 0, "an update does not grab the focus");
                assert_eq!(fields.string(), received.title);
                let channel = fields.string();
                let [x, y, w, h] = [0; 4].map(|_| fields.i32() as usize);
                assert!(w <= 128 && h <= 128 && x % 128 == 0 && y % 128 == 0);
                assert!(x + w <= received.width && y + h <= received.height);
                assert_eq!(fields.0.len(), 4 * w * h, "tile payload");
                let plane = received
                    .channels
                    .get_mut(&channel)
                    .expect("a created channel");
                for row in y..y + h {
                    for col in x..x + w {
                        plane[row * received.width + col] = fields.f32();
                    }
                }
                received.updates += 1;
                if stop_after.is_some_and(|n| received.updates >= n) {
                    return received;
                }
            }
            other => panic!("unexpected packet type {other}"),
        }
    }
}

/// The next connection, or a panic after a minute (a test must not hang).
fn accept(listener: &TcpListener) -> TcpStream {
    listener.set_nonblocking(true).unwrap();
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        match listener.accept() {
            Ok((stream, _)) => {
                stream.set_nonblocking(false).unwrap();
                stream
                    .set_read_timeout(Some(Duration::from_secs(60)))
                    .unwrap();
                return stream;
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                assert!(Instant::now() < deadline, "fppm did not connect");
                std::thread::sleep(Duration::from_millis(20));
            }
            Err(e) => panic!("accept: {e}"),
        }
    }
}

/// The EXR's channels, bit for bit, against what the stand-in rebuilt.
fn assert_same_channels(exr: &Path, received: &Received) {
    let exr = read_exr(exr);
    assert_eq!((exr.width, exr.height), (received.width, received.height));
    let names: Vec<&String> = exr.channels.keys().collect();
    let streamed: Vec<&String> = received.channels.keys().collect();
    assert_eq!(names, streamed, "channels");
    for (name, values) in &exr.channels {
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert!(
            bits(values) == bits(&received.channels[name]),
            "channel {name} differs from the EXR"
        );
    }
}

/// A render streamed to the stand-in, which drops the first connection after a few tiles:
/// fppm connects again, creates the image again, and what the second connection rebuilds is
/// the EXR written at the end, R, G, B and the AOVs, bit for bit.
#[test]
fn the_tev_stream_rebuilds_the_exr_across_a_reconnection() {
    let dir = temp_dir("live-tev");
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let address = listener.local_addr().unwrap().to_string();
    let reader = std::thread::spawn(move || {
        let mut first = accept(&listener);
        let dropped = read_stream(&mut first, Some(2));
        drop(first);
        let mut second = accept(&listener);
        (dropped, read_stream(&mut second, None))
    });
    let run = fppm(
        &dir,
        &[
            "render",
            CORNELL,
            "--width",
            "160",
            "--height",
            "136",
            "--photons-per-pass",
            "3000",
            "--time",
            "3s",
            "--aov",
            "depth,albedo",
            "--display-server",
            &address,
        ],
    )
    .ok();
    let (dropped, received) = reader.join().unwrap();
    assert_eq!(dropped.updates, 2);
    assert!(
        received.title.starts_with("fppm.exr ("),
        "{}",
        received.title
    );
    assert!(received.channels.contains_key("albedo.G"));
    assert!(
        run.stderr.contains("lost the connection"),
        "the lost connection is reported:\n{}",
        run.stderr
    );
    assert_same_channels(&dir.join("fppm.exr"), &received);
}

/// Images do not depend on whether anything watches the render.
#[test]
fn live_views_leave_the_image_bit_identical() {
    let plain = temp_dir("live-plain");
    render_cornell(&plain, &["--aov", "depth", "--passes", "6"]).ok();
    let watched = temp_dir("live-watched");
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let address = listener.local_addr().unwrap().to_string();
    let reader = std::thread::spawn(move || {
        let mut stream = accept(&listener);
        read_stream(&mut stream, None)
    });
    let run = render_cornell(
        &watched,
        &[
            "--aov",
            "depth",
            "--passes",
            "6",
            "--preview",
            "127.0.0.1:0",
            "--display-server",
            &address,
            "--json",
        ],
    )
    .ok();
    let received = reader.join().unwrap();
    assert!(
        run.stderr.contains("fppm: preview at http://127.0.0.1:"),
        "{}",
        run.stderr
    );
    assert!(
        run.stdout.contains("\"event\":\"preview\""),
        "{}",
        run.stdout
    );
    let a = read_exr(&plain.join("fppm.exr"));
    let b = read_exr(&watched.join("fppm.exr"));
    for (name, values) in &a.channels {
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert!(bits(values) == bits(&b.channels[name]), "channel {name}");
    }
    assert_same_channels(&watched.join("fppm.exr"), &received);
    assert_eq!(
        std::fs::read(plain.join("fppm.png")).unwrap(),
        std::fs::read(watched.join("fppm.png")).unwrap()
    );
}

/// `--json` carries the latest error trend on every pass from the second on, with the passes
/// it was measured after: every snapshot pass (2, 4, 8, 16) at least, and it falls.
#[test]
fn json_carries_the_error_trend() {
    let dir = temp_dir("live-trend");
    let run = render_cornell(&dir, &["--passes", "16", "--json"]).ok();
    let trends: Vec<(Option<f64>, Option<u64>)> = run
        .stdout
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|v| v["event"] == "pass")
        .map(|v| (v["error_trend"].as_f64(), v["error_trend_pass"].as_u64()))
        .collect();
    assert_eq!(trends.len(), 16);
    assert_eq!(trends[0], (None, None));
    let mut measured = Vec::new();
    for (i, &(trend, at)) in trends.iter().enumerate().skip(1) {
        let passes = i as u64 + 1;
        let (trend, at) = (trend.expect("a trend"), at.expect("its pass"));
        assert!(trend > 0.0 && trend < 10.0, "{trends:?}");
        assert!(at <= passes, "{trends:?}");
        if at == passes {
            measured.push((passes, trend));
        } else {
            // Carried from the pass it was measured after.
            assert_eq!(Some(trend), trends[at as usize - 1].0, "{trends:?}");
        }
    }
    for snapshot in [2, 4, 8, 16] {
        assert!(measured.iter().any(|&(p, _)| p == snapshot), "{measured:?}");
    }
    let (first, last) = (measured[0].1, measured[measured.len() - 1].1);
    assert!(last < first, "{measured:?}");
    let done: serde_json::Value = serde_json::from_str(run.stdout.lines().last().unwrap()).unwrap();
    assert_eq!(done["error_trend"].as_f64(), Some(last));
}

#[test]
fn bad_addresses_are_one_line_errors() {
    let dir = temp_dir("live-bad");
    for (flag, value) in [
        ("--preview", "localhost"),
        ("--preview", "127.0.0.1:http"),
        ("--display-server", "127.0.0.1"),
        ("--display-server", "127.0.0.1:70000"),
    ] {
        render_cornell(&dir, &[flag, value]).fails(2, &[flag, "HOST:PORT"]);
    }
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let address = taken.local_addr().unwrap().to_string();
    render_cornell(&dir, &["--preview", &address])
        .fails(1, &["--preview", &address, "cannot listen"]);
    assert!(!dir.join("fppm.exr").exists());
}

/// A tev that is not there is a warning; the render goes on and writes its outputs.
#[test]
fn a_missing_display_server_is_a_warning() {
    let dir = temp_dir("live-no-tev");
    let free = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .to_string();
    let run = render_cornell(&dir, &["--display-server", &free]).ok();
    assert!(
        run.stderr.contains("fppm: warning: display server"),
        "{}",
        run.stderr
    );
    assert!(dir.join("fppm.exr").exists());
}

// ---- The page in a browser ------------------------------------------------------------------

/// Kills a child process when the test ends, however it ends.
struct Killed(Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The program on the PATH (or at a Debian path), if any.
fn program(names: &[&str]) -> Option<PathBuf> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    for name in names {
        for dir in std::env::split_paths(&path).chain([PathBuf::from("/usr/bin")]) {
            let candidate = dir.join(name);
            if candidate.is_file() {
                return Some(candidate);
            }
        }
    }
    None
}

/// A WebDriver session of chromedriver, spoken to over loopback HTTP.
struct Browser {
    agent: ureq::Agent,
    base: String,
    session: String,
    _driver: Killed,
}

impl Browser {
    /// Starts chromedriver and a headless Chromium with the flags of a closed network.
    fn start(driver: &Path, chromium: &Path, profile: &Path) -> Browser {
        let port = TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let child = Command::new(driver)
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let driver_process = Killed(child);
        let agent: ureq::Agent = ureq::Agent::config_builder()
            .proxy(None)
            .timeout_global(Some(Duration::from_secs(60)))
            .build()
            .into();
        let base = format!("http://127.0.0.1:{port}");
        let deadline = Instant::now() + Duration::from_secs(20);
        while agent.get(format!("{base}/status")).call().is_err() {
            assert!(Instant::now() < deadline, "chromedriver did not start");
            std::thread::sleep(Duration::from_millis(100));
        }
        let args = [
            "--headless".to_owned(),
            "--no-sandbox".to_owned(),
            "--disable-gpu".to_owned(),
            "--disable-quic".to_owned(),
            "--no-first-run".to_owned(),
            "--disable-background-networking".to_owned(),
            "--disable-component-update".to_owned(),
            "--disable-sync".to_owned(),
            "--disable-dev-shm-usage".to_owned(),
            "--window-size=900,700".to_owned(),
            format!("--user-data-dir={}", profile.display()),
        ];
        let capabilities = serde_json::json!({
            "capabilities": { "alwaysMatch": {
                "browserName": "chrome",
                "goog:chromeOptions": { "binary": chromium, "args": args },
            }}
        });
        let reply: serde_json::Value = agent
            .post(format!("{base}/session"))
            .send_json(capabilities)
            .unwrap()
            .body_mut()
            .read_json()
            .unwrap();
        let session = reply["value"]["sessionId"]
            .as_str()
            .unwrap_or_else(|| panic!("no session: {reply}"))
            .to_owned();
        Browser {
            agent,
            base,
            session,
            _driver: driver_process,
        }
    }

    fn command(&self, path: &str, body: serde_json::Value) -> serde_json::Value {
        let mut reply = self
            .agent
            .post(format!("{}/session/{}/{path}", self.base, self.session))
            .send_json(body)
            .unwrap();
        let value: serde_json::Value = reply.body_mut().read_json().unwrap();
        value["value"].clone()
    }

    fn open(&self, url: &str) {
        self.command("url", serde_json::json!({ "url": url }));
    }

    /// The value of a JavaScript expression in the page.
    fn eval(&self, expression: &str) -> serde_json::Value {
        self.command(
            "execute/sync",
            serde_json::json!({ "script": format!("return {expression};"), "args": [] }),
        )
    }

    fn click(&self, css: &str) {
        let element = self.command(
            "element",
            serde_json::json!({ "using": "css selector", "value": css }),
        );
        let id = element["element-6066-11e4-a52e-4f735466cecf"]
            .as_str()
            .unwrap_or_else(|| panic!("no element {css}: {element}"))
            .to_owned();
        self.command(&format!("element/{id}/click"), serde_json::json!({}));
    }

    /// Saves a screenshot of the page as a PNG.
    fn screenshot(&self, path: &Path) {
        let mut reply = self
            .agent
            .get(format!("{}/session/{}/screenshot", self.base, self.session))
            .call()
            .unwrap();
        let value: serde_json::Value = reply.body_mut().read_json().unwrap();
        std::fs::write(path, base64(value["value"].as_str().unwrap())).unwrap();
    }

    /// Waits until the expression is true, or panics after `timeout`.
    fn wait_for(&self, expression: &str, timeout: Duration) {
        let deadline = Instant::now() + timeout;
        while self.eval(expression) != serde_json::Value::Bool(true) {
            assert!(
                Instant::now() < deadline,
                "timed out waiting for {expression}"
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }
}

/// Standard base64 (WebDriver's screenshots) to bytes.
fn base64(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let digits: Vec<u8> = text.bytes().filter(|&c| c != b'=').map(value).collect();
    digits
        .chunks(4)
        .flat_map(|chunk| {
            let n =
                chunk.iter().fold(0u32, |n, &d| n << 6 | u32::from(d)) << (6 * (4 - chunk.len()));
            let bytes = n.to_be_bytes();
            bytes[1..chunk.len()].to_vec()
        })
        .collect()
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self
            .agent
            .delete(format!("{}/session/{}", self.base, self.session))
            .call();
    }
}

/// As a person would: open the page of a running render in headless Chromium, see the image
/// change between passes, press the stop button, and find the render ended with its outputs.
///
/// Needs Debian's `chromium` and `chromium-driver`; `.ci/run` installs them and sets
/// `FPPM_BROWSER_TEST=1`, which turns their absence into a failure instead of a skip.
#[test]
fn the_preview_page_updates_and_its_stop_button_ends_the_render() {
    let (Some(chromium), Some(driver)) = (
        program(&["chromium", "chromium-browser"]),
        program(&["chromedriver"]),
    ) else {
        assert!(
            std::env::var_os("FPPM_BROWSER_TEST").is_none(),
            "FPPM_BROWSER_TEST is set but chromium or chromedriver is missing"
        );
        eprintln!(
            "skipped: the preview's browser test needs chromium and chromedriver \
             (apt-get install chromium chromium-driver; .ci/run installs them)"
        );
        return;
    };
    let dir = temp_dir("live-browser");
    let child = Command::new(env!("CARGO_BIN_EXE_fppm"))
        .args(["render", CORNELL])
        .args([
            "--width",
            "96",
            "--height",
            "96",
            "--photons-per-pass",
            "20000",
        ])
        .args(["--time", "120s", "--preview", "127.0.0.1:0"])
        .current_dir(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut render = Killed(child);
    // stderr, line by line, on a thread: the first line is the page's address.
    let (lines_tx, lines) = mpsc::channel::<String>();
    let stderr = render.0.stderr.take().unwrap();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = lines_tx.send(line);
        }
    });
    let first = lines.recv_timeout(Duration::from_secs(60)).unwrap();
    let url = first
        .strip_prefix("fppm: preview at ")
        .unwrap_or_else(|| panic!("no address: {first}"))
        .to_owned();

    let browser = Browser::start(&driver, &chromium, &dir.join("profile"));
    browser.open(&url);
    browser.wait_for(
        "Number(document.getElementById('image').dataset.version) >= 1 \
         && document.getElementById('image').naturalWidth === 96",
        Duration::from_secs(30),
    );
    let first_version = browser.eval("Number(document.getElementById('image').dataset.version)");
    let first_pass = browser.eval("document.getElementById('pass').textContent");
    browser.wait_for(
        &format!("Number(document.getElementById('image').dataset.version) > {first_version}"),
        Duration::from_secs(30),
    );
    let later_pass = browser.eval("document.getElementById('pass').textContent");
    assert_ne!(first_pass, later_pass, "the pass count moves");
    browser.wait_for(
        "document.getElementById('error').textContent.endsWith('%')",
        Duration::from_secs(30),
    );
    // The exposure slider asks for the same image, brighter.
    browser.eval(
        "(() => { const s = document.getElementById('exposure'); s.value = '2'; \
         s.dispatchEvent(new Event('input')); return true; })()",
    );
    browser.wait_for(
        "document.getElementById('image').src.includes('exposure=2')",
        Duration::from_secs(30),
    );

    // For a person to look at: target/tmp/cli-tests/live-browser/page.png.
    browser.screenshot(&dir.join("page.png"));
    browser.click("#stop");
    let deadline = Instant::now() + Duration::from_secs(60);
    let status = loop {
        if let Some(status) = render.0.try_wait().unwrap() {
            break status;
        }
        assert!(
            Instant::now() < deadline,
            "the stop button did not end the render"
        );
        std::thread::sleep(Duration::from_millis(100));
    };
    let stderr: Vec<String> = lines.try_iter().collect();
    assert_eq!(status.code(), Some(130), "{stderr:?}");
    assert!(
        stderr
            .iter()
            .any(|l| l.starts_with("fppm: stopped from the preview page after pass")),
        "{stderr:?}"
    );
    let exr = read_exr(&dir.join("fppm.exr"));
    assert_eq!((exr.width, exr.height), (96, 96));
    assert!(exr.mean() > 0.0);
    assert!(dir.join("fppm.png").exists());
    browser.wait_for(
        "['done', 'the render has ended'].includes(document.getElementById('state').textContent)",
        Duration::from_secs(10),
    );
}

/// The flags' help names both views.
#[test]
fn help_lists_the_live_views() {
    let dir = temp_dir("live-help");
    let run = fppm(&dir, &["render", "--help"]).ok();
    assert!(
        run.stdout.contains("--preview [<HOST:PORT>]"),
        "{}",
        run.stdout
    );
    assert!(run.stdout.contains("--display-server <HOST:PORT>"));
}

/// `fppm render --preview scene` is read as the user means it: the page at its default
/// address and the scene rendered; with no scene at all the command says one is needed.
#[test]
fn a_scene_after_a_bare_preview_flag_is_the_scene() {
    let dir = temp_dir("live-scene-after-flag");
    let mut args = vec!["render", "--preview", CORNELL];
    args.extend_from_slice(TINY);
    let run = fppm(&dir, &args).ok();
    assert!(
        run.stderr.contains("fppm: preview at http://127.0.0.1:"),
        "{}",
        run.stderr
    );
    assert!(dir.join("fppm.exr").exists());
    fppm(&dir, &["render", "--preview", "127.0.0.1:0"])
        .fails(2, &["fppm render needs a SCENE file"]);
}
