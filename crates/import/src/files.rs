//! Where the loaders read files: the file system, or a [`FileSource`] given to [`load_from`].
//!
//! A scene file refers to other files (OBJ meshes and their MTL libraries, glTF buffers, Mitsuba
//! and pbrt includes, PLY and `.serialized` meshes, spectra, bitmaps). Every loader reads them
//! through [`read`], [`exists`] and [`canonical`] here, which ask the source installed for the
//! current load, or the file system when none is. The source is installed on the calling thread
//! for the duration of one [`load_from`] call (the loaders read on that thread only), so the many
//! read sites of the importers need no extra parameter; an installation restores the previous
//! one when it ends, even by unwinding.
//!
//! [`load_from`]: super::load_from

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::io;
use std::path::{Component, Path, PathBuf};
use std::rc::Rc;

/// A source of the files a scene refers to, for loading scenes held in memory (tests, fuzzing,
/// embedding) with [`load_from`](super::load_from).
///
/// Any `Fn(&Path) -> io::Result<Vec<u8>>` closure is a source (a resolver: it may serve one
/// stub for every `.obj`, say), and so is [`MemoryFiles`].
pub trait FileSource {
    /// The whole content of `path`; an error of kind [`io::ErrorKind::NotFound`] if there is
    /// no such file.
    ///
    /// # Errors
    ///
    /// Any [`io::Error`]; the loaders report it with the path.
    fn read(&self, path: &Path) -> io::Result<Vec<u8>>;

    /// Whether `path` names a file. The default reads it.
    fn exists(&self, path: &Path) -> bool {
        self.read(path).is_ok()
    }
}

impl<F: Fn(&Path) -> io::Result<Vec<u8>>> FileSource for F {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        self(path)
    }
}

/// Files held in memory, keyed by path. Paths are compared after lexical normalisation
/// (`a/./b` and `a/c/../b` name the same file), since the loaders join relative names to the
/// directory of the file that refers to them.
#[derive(Clone, Debug, Default)]
pub struct MemoryFiles {
    files: BTreeMap<PathBuf, Vec<u8>>,
}

impl MemoryFiles {
    /// No files.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds (or replaces) a file.
    pub fn insert(&mut self, path: impl AsRef<Path>, content: impl Into<Vec<u8>>) {
        self.files.insert(normalize(path.as_ref()), content.into());
    }

    /// This set with one more file.
    #[must_use]
    pub fn with(mut self, path: impl AsRef<Path>, content: impl Into<Vec<u8>>) -> Self {
        self.insert(path, content);
        self
    }
}

impl FileSource for MemoryFiles {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        self.files
            .get(&normalize(path))
            .cloned()
            .ok_or_else(|| io::Error::from(io::ErrorKind::NotFound))
    }

    fn exists(&self, path: &Path) -> bool {
        self.files.contains_key(&normalize(path))
    }
}

/// Removes `.` components and folds `..` into the preceding normal component.
fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if matches!(out.components().next_back(), Some(Component::Normal(_))) {
                    out.pop();
                } else {
                    out.push(c);
                }
            }
            _ => out.push(c),
        }
    }
    out
}

thread_local! {
    static SOURCE: RefCell<Option<Rc<dyn FileSource>>> = const { RefCell::new(None) };
}

/// Keeps a source installed on this thread until dropped, then restores the previous one.
pub(crate) struct Installed {
    previous: Option<Rc<dyn FileSource>>,
}

/// Installs `source` for the loads this thread runs until the guard drops.
pub(crate) fn install(source: Rc<dyn FileSource>) -> Installed {
    let previous = SOURCE.with(|s| s.borrow_mut().replace(source));
    Installed { previous }
}

impl Drop for Installed {
    fn drop(&mut self) {
        let previous = self.previous.take();
        SOURCE.with(|s| *s.borrow_mut() = previous);
    }
}

fn current() -> Option<Rc<dyn FileSource>> {
    SOURCE.with(|s| s.borrow().clone())
}

/// Reads a whole file from the current source.
pub(crate) fn read(path: &Path) -> io::Result<Vec<u8>> {
    match current() {
        Some(source) => source.read(path),
        None => std::fs::read(path),
    }
}

/// Whether `path` names a file of the current source.
pub(crate) fn exists(path: &Path) -> bool {
    match current() {
        Some(source) => source.exists(path),
        None => path.exists(),
    }
}

/// The name under which include cycles are detected: the canonical path on the file system,
/// the lexically normalised path in a [`FileSource`].
pub(crate) fn canonical(path: &Path) -> PathBuf {
    match current() {
        Some(_) => normalize(path),
        None => path.canonicalize().unwrap_or_else(|_| path.to_path_buf()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_files_match_normalised_paths() {
        let files = MemoryFiles::new().with("/s/meshes/a.obj", "v 0 0 0");
        assert!(files.exists(Path::new("/s/./meshes/a.obj")));
        assert!(files.exists(Path::new("/s/x/../meshes/a.obj")));
        assert!(!files.exists(Path::new("/s/a.obj")));
        let missing = files.read(Path::new("/s/b.obj")).unwrap_err();
        assert_eq!(missing.kind(), io::ErrorKind::NotFound);
    }

    #[test]
    fn installation_is_scoped() {
        let served = |_: &Path| -> io::Result<Vec<u8>> { Ok(b"x".to_vec()) };
        let nowhere = Path::new("/no/such/dir/file.obj");
        {
            let _outer = install(Rc::new(served));
            assert_eq!(read(nowhere).unwrap(), b"x");
            {
                let _inner = install(Rc::new(MemoryFiles::new()));
                assert!(!exists(nowhere));
            }
            assert!(exists(nowhere));
        }
        assert!(read(nowhere).is_err());
    }
}
