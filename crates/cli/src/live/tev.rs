//! `--display-server`: the image streamed to the tev viewer with the protocol of pbrt-v4's
//! `--display-server` (`src/pbrt/util/display.cpp`), so that a pbrt user's tev works unchanged.
//!
//! Every packet is little-endian: a `u32` length of the whole packet (these four bytes
//! included), a type byte, then its fields; strings end in a NUL byte.
//!
//! - Create image (type 4): `u8` grab focus (1), title, `i32` width, `i32` height,
//!   `i32` channel count, the channel names.
//! - Update image (type 3, one channel of one tile): `u8` grab focus (0), title, channel name,
//!   `i32` x, y, width, height of the tile, then width × height `f32` values, row by row.
//!
//! As in pbrt, tiles are 128 × 128 pixels and a tile of a channel is sent only when it differs
//! from what tev already has. A failed connection or send is tried again with the next image:
//! the new connection creates the image again and sends every tile that is not zero.

use std::io::Write;
use std::net::{SocketAddr, TcpStream};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::Duration;

/// Tile edge in pixels (pbrt's `tileSize`).
const TILE: usize = 128;
/// How long a connection attempt may take, per address.
const CONNECT_TIMEOUT: Duration = Duration::from_secs(2);
/// How long one send may block when tev does not read (pbrt's `SO_SNDTIMEO`).
const SEND_TIMEOUT: Duration = Duration::from_secs(3);

const CREATE_IMAGE: u8 = 4;
const UPDATE_IMAGE: u8 = 3;

/// The create-image packet.
fn create_image_packet(title: &str, width: u32, height: u32, channels: &[&str]) -> Vec<u8> {
    let mut packet = Packet::new(CREATE_IMAGE);
    packet.u8(1);
    packet.string(title);
    packet.i32(width as i32);
    packet.i32(height as i32);
    packet.i32(channels.len() as i32);
    for name in channels {
        packet.string(name);
    }
    packet.finish()
}

/// The update-image packet of one channel of the tile at `(x, y)` of `width × height` pixels,
/// whose values are taken, row by row, from `plane` (the channel's whole image, `stride`
/// values a row).
fn update_image_packet(
    title: &str,
    channel: &str,
    (x, y): (usize, usize),
    (width, height): (usize, usize),
    plane: &[f32],
    stride: usize,
) -> Vec<u8> {
    let mut packet = Packet::new(UPDATE_IMAGE);
    packet.u8(0);
    packet.string(title);
    packet.string(channel);
    for v in [x, y, width, height] {
        packet.i32(v as i32);
    }
    packet.bytes.reserve(4 * width * height);
    for row in y..y + height {
        for &v in &plane[row * stride + x..row * stride + x + width] {
            packet.bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    packet.finish()
}

/// A packet being written: the length is filled in at the end.
struct Packet {
    bytes: Vec<u8>,
}

impl Packet {
    fn new(kind: u8) -> Self {
        let mut bytes = vec![0; 4];
        bytes.push(kind);
        Packet { bytes }
    }

    fn u8(&mut self, v: u8) {
        self.bytes.push(v);
    }

    fn i32(&mut self, v: i32) {
        self.bytes.extend_from_slice(&v.to_le_bytes());
    }

    /// The text up to any NUL it holds, then a NUL.
    fn string(&mut self, s: &str) {
        self.bytes.extend(s.bytes().take_while(|&b| b != 0));
        self.bytes.push(0);
    }

    fn finish(mut self) -> Vec<u8> {
        let length = self.bytes.len() as u32;
        self.bytes[..4].copy_from_slice(&length.to_le_bytes());
        self.bytes
    }
}

/// What the render loop hands the stream's thread.
#[derive(Default)]
struct Mailbox {
    /// The newest frame not sent yet (an older one is dropped unsent).
    frame: Option<Arc<film::Frame>>,
    /// No more frames will come.
    finished: bool,
    /// Messages for the render loop to print.
    notes: Vec<String>,
}

/// The stream's thread and its mailbox.
pub(super) struct Stream {
    mailbox: Arc<(Mutex<Mailbox>, Condvar)>,
    thread: Option<JoinHandle<()>>,
}

impl Stream {
    /// Starts the thread that connects to `addresses` (`text` as the user wrote it).
    pub(super) fn start(
        text: &str,
        addresses: Vec<SocketAddr>,
        title: String,
        quiet: bool,
    ) -> Self {
        let mailbox = Arc::new((Mutex::new(Mailbox::default()), Condvar::new()));
        let connection = Connection {
            text: text.to_owned(),
            addresses,
            title,
            quiet,
            stream: None,
            shown: Vec::new(),
            failing: false,
        };
        let thread = {
            let mailbox = Arc::clone(&mailbox);
            std::thread::Builder::new()
                .name("fppm-display-server".to_owned())
                .spawn(move || run(connection, &mailbox))
        };
        let thread = match thread {
            Ok(thread) => Some(thread),
            Err(e) => {
                eprintln!(
                    "fppm: warning: cannot start the display server's thread ({e}); not streaming"
                );
                None
            }
        };
        Stream { mailbox, thread }
    }

    /// Hands over a frame, replacing one not sent yet.
    pub(super) fn send(&self, frame: Arc<film::Frame>) {
        let (lock, wake) = &*self.mailbox;
        lock.lock().unwrap_or_else(PoisonError::into_inner).frame = Some(frame);
        wake.notify_one();
    }

    /// The messages of the thread since the last call.
    pub(super) fn notes(&self) -> Vec<String> {
        std::mem::take(
            &mut self
                .mailbox
                .0
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .notes,
        )
    }

    /// Sends the final frame, waits for the thread, and returns its last messages.
    pub(super) fn finish(mut self, frame: Arc<film::Frame>) -> Vec<String> {
        {
            let (lock, wake) = &*self.mailbox;
            let mut mailbox = lock.lock().unwrap_or_else(PoisonError::into_inner);
            mailbox.frame = Some(frame);
            mailbox.finished = true;
            wake.notify_one();
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
        self.notes()
    }
}

impl Drop for Stream {
    /// A render that ends in an error ends the thread too, without a last frame.
    fn drop(&mut self) {
        let (lock, wake) = &*self.mailbox;
        lock.lock().unwrap_or_else(PoisonError::into_inner).finished = true;
        wake.notify_one();
    }
}

/// The thread: sends each frame it is handed until told there are no more.
fn run(mut connection: Connection, mailbox: &(Mutex<Mailbox>, Condvar)) {
    let (lock, wake) = mailbox;
    loop {
        let (frame, finished) = {
            let mut mailbox = lock.lock().unwrap_or_else(PoisonError::into_inner);
            while mailbox.frame.is_none() && !mailbox.finished {
                mailbox = wake.wait(mailbox).unwrap_or_else(PoisonError::into_inner);
            }
            (mailbox.frame.take(), mailbox.finished)
        };
        if let Some(frame) = frame
            && let Some(note) = connection.show(&frame)
        {
            lock.lock()
                .unwrap_or_else(PoisonError::into_inner)
                .notes
                .push(note);
        }
        if finished {
            return;
        }
    }
}

/// The connection to tev and what tev shows.
struct Connection {
    text: String,
    addresses: Vec<SocketAddr>,
    title: String,
    quiet: bool,
    stream: Option<TcpStream>,
    /// Per channel, the values tev shows (zeros after the image is created).
    shown: Vec<Vec<f32>>,
    /// The last attempt failed (its warning was given).
    failing: bool,
}

impl Connection {
    /// Sends what changed in `frame`, connecting first if needed; returns a message to print.
    fn show(&mut self, frame: &film::Frame) -> Option<String> {
        let mut note = None;
        if self.stream.is_none() {
            match self.connect(frame) {
                Ok(stream) => {
                    self.stream = Some(stream);
                    if self.failing && !self.quiet {
                        note = Some(format!("streaming to the display server at {}", self.text));
                    }
                    self.failing = false;
                }
                Err(e) => return self.failed(&format!("cannot connect ({e})")).or(note),
            }
        }
        if let Err(e) = self.send_tiles(frame) {
            // Once more at once on a new connection (tev may have been restarted), then with
            // the next image.
            self.stream = None;
            let again = self.connect(frame).and_then(|stream| {
                self.stream = Some(stream);
                self.send_tiles(frame)
            });
            if again.is_err() {
                self.stream = None;
                return self.failed(&format!("lost the connection ({e})"));
            }
            if !self.quiet {
                note = Some(format!(
                    "fppm: warning: display server {}: lost the connection ({}); connected again",
                    self.text,
                    film::lower_first(&e.to_string())
                ));
            }
        }
        note
    }

    /// The first failure in a row is worth a warning; the next ones are not.
    fn failed(&mut self, what: &str) -> Option<String> {
        let first = !self.failing;
        self.failing = true;
        first.then(|| {
            format!(
                "fppm: warning: display server {}: {}; trying again after the next passes",
                self.text,
                film::lower_first(what)
            )
        })
    }

    /// Connects and creates the image.
    fn connect(&mut self, frame: &film::Frame) -> std::io::Result<TcpStream> {
        let mut last = None;
        for address in &self.addresses {
            match TcpStream::connect_timeout(address, CONNECT_TIMEOUT) {
                Ok(mut stream) => {
                    stream.set_write_timeout(Some(SEND_TIMEOUT))?;
                    stream.set_nodelay(true)?;
                    let names = channel_names(frame);
                    let image = &frame.image;
                    stream.write_all(&create_image_packet(
                        &self.title,
                        image.width as u32,
                        image.height as u32,
                        &names,
                    ))?;
                    let size = image.width * image.height;
                    self.shown = vec![vec![0.0; size]; names.len()];
                    return Ok(stream);
                }
                Err(e) => last = Some(e),
            }
        }
        Err(last.unwrap_or_else(|| std::io::Error::other("no address")))
    }

    /// Sends every tile of every channel that differs from what tev shows.
    fn send_tiles(&mut self, frame: &film::Frame) -> std::io::Result<()> {
        let Some(stream) = self.stream.as_mut() else {
            return Ok(());
        };
        let (width, height) = (frame.image.width, frame.image.height);
        let names = channel_names(frame);
        let rgb: [Vec<f32>; 3] =
            std::array::from_fn(|c| frame.image.pixels.iter().map(|p| p[c]).collect());
        let planes = rgb
            .iter()
            .map(Vec::as_slice)
            .chain(frame.channels.iter().map(|(_, plane)| plane.as_slice()));
        for ((name, plane), shown) in names.iter().zip(planes).zip(&mut self.shown) {
            for y in (0..height).step_by(TILE) {
                for x in (0..width).step_by(TILE) {
                    let (w, h) = (TILE.min(width - x), TILE.min(height - y));
                    let changed = (y..y + h).any(|row| {
                        let span = row * width + x..row * width + x + w;
                        plane[span.clone()]
                            .iter()
                            .zip(&shown[span])
                            .any(|(a, b)| a.to_bits() != b.to_bits())
                    });
                    if !changed {
                        continue;
                    }
                    let packet =
                        update_image_packet(&self.title, name, (x, y), (w, h), plane, width);
                    stream.write_all(&packet)?;
                    for row in y..y + h {
                        let span = row * width + x..row * width + x + w;
                        shown[span.clone()].copy_from_slice(&plane[span]);
                    }
                }
            }
        }
        stream.flush()
    }
}

/// R, G, B and the frame's auxiliary channels, in the EXR's names.
fn channel_names(frame: &film::Frame) -> Vec<&'static str> {
    ["R", "G", "B"]
        .into_iter()
        .chain(frame.channels.iter().map(|(name, _)| *name))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bytes of pbrt-v4's `SendOpenImage` for a 3 × 2 RGB image titled "t".
    #[test]
    fn create_image_is_pbrts_layout() {
        let packet = create_image_packet("t", 3, 2, &["R", "G", "B"]);
        let mut expected = vec![0, 0, 0, 0, 4, 1, b't', 0];
        for v in [3i32, 2, 3] {
            expected.extend_from_slice(&v.to_le_bytes());
        }
        expected.extend_from_slice(b"R\0G\0B\0");
        let length = expected.len() as u32;
        expected[..4].copy_from_slice(&length.to_le_bytes());
        assert_eq!(packet, expected);
    }

    /// An update of the 2 × 1 tile at (1, 1) of a 3 × 2 plane: its values, row by row.
    #[test]
    fn update_image_is_pbrts_layout() {
        let plane = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0f32];
        let packet = update_image_packet("t", "G", (1, 1), (2, 1), &plane, 3);
        let mut expected = vec![0, 0, 0, 0, 3, 0, b't', 0, b'G', 0];
        for v in [1i32, 1, 2, 1] {
            expected.extend_from_slice(&v.to_le_bytes());
        }
        for v in [4.0f32, 5.0] {
            expected.extend_from_slice(&v.to_le_bytes());
        }
        let length = expected.len() as u32;
        expected[..4].copy_from_slice(&length.to_le_bytes());
        assert_eq!(packet, expected);
    }
}
