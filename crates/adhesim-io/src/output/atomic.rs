//! Atomic file replacement.
//!
//! Every output file that is rewritten as a whole (VTU snapshots, the PVD collection, PNG
//! plots) goes through this module: the new content is written to a hidden temporary file in
//! the target's directory, flushed and fsynced, then renamed over the target. A reader (or a
//! run killed half-way) therefore sees either the previous complete file or the new complete
//! file, never a truncated one. Temporary files are removed when anything fails.

use std::ffi::OsString;
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `bytes` to `path` atomically (temporary file in the same directory, fsync, rename).
///
/// Errors carry `path` in their message.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let (tmp, mut file) = TempFile::create(path, "")?;
    file.write_all(bytes)
        .map_err(|e| with_path(e, "cannot write", path))?;
    tmp.commit(file, path)
}

/// Streams the content of `path` through `write` and replaces `path` atomically.
///
/// `write` receives a buffered writer; it may be called with large numbers of small writes.
/// If `write` returns an error, the target is left untouched, the temporary file is removed
/// and the error is returned with `path` added to its message.
pub fn write_atomic_with<F>(path: &Path, write: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let (tmp, file) = TempFile::create(path, "")?;
    let mut buffered = BufWriter::with_capacity(1 << 16, file);
    write(&mut buffered).map_err(|e| with_path(e, "cannot write", path))?;
    let file = buffered
        .into_inner()
        .map_err(|e| with_path(e.into_error(), "cannot write", path))?;
    tmp.commit(file, path)
}

/// A reserved temporary path next to a target file, removed on drop unless committed.
///
/// Used by writers that must hand a path (not a [`Write`]) to a library, such as the PNG
/// encoder of the plotting backend.
pub(crate) struct TempPath {
    path: PathBuf,
    armed: bool,
}

impl TempPath {
    /// Reserves a fresh temporary path in `target`'s directory whose name ends with `suffix`
    /// (for example `".png"`, so that extension-based encoders pick the right format).
    pub(crate) fn reserve(target: &Path, suffix: &str) -> io::Result<Self> {
        let (tmp, file) = TempFile::create(target, suffix)?;
        drop(file);
        Ok(tmp.0)
    }

    /// The temporary path.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// Fsyncs the temporary file and renames it over `target`.
    pub(crate) fn persist(self, target: &Path) -> io::Result<()> {
        let file = File::open(&self.path).map_err(|e| with_path(e, "cannot reopen", &self.path))?;
        TempFile(self).commit(file, target)
    }
}

impl Drop for TempPath {
    fn drop(&mut self) {
        if self.armed {
            let _ = fs::remove_file(&self.path);
        }
    }
}

/// A temporary file being written; removed on drop unless committed.
struct TempFile(TempPath);

impl TempFile {
    /// Creates a new, empty temporary file beside `target`.
    fn create(target: &Path, suffix: &str) -> io::Result<(Self, File)> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let name = target.file_name().ok_or_else(|| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{}: path has no file name", target.display()),
            )
        })?;
        let dir = parent_dir(target);
        let pid = std::process::id();
        let mut attempts = 0;
        loop {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let mut tmp_name = OsString::from(".");
            tmp_name.push(name);
            tmp_name.push(format!(".{pid}.{n}.tmp{suffix}"));
            let tmp_path = dir.join(tmp_name);
            match OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&tmp_path)
            {
                Ok(file) => {
                    let tmp = TempPath {
                        path: tmp_path,
                        armed: true,
                    };
                    return Ok((TempFile(tmp), file));
                }
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists && attempts < 1000 => {
                    attempts += 1;
                }
                Err(e) => {
                    return Err(with_path(e, "cannot create a temporary file for", target));
                }
            }
        }
    }

    /// Flushes and fsyncs `file` (the temporary file), renames it over `target` and fsyncs
    /// the directory so that the rename itself is durable.
    fn commit(self, mut file: File, target: &Path) -> io::Result<()> {
        let mut tmp = self.0;
        file.flush()
            .and_then(|()| file.sync_all())
            .map_err(|e| with_path(e, "cannot flush", target))?;
        drop(file);
        fs::rename(&tmp.path, target).map_err(|e| with_path(e, "cannot replace", target))?;
        tmp.armed = false;
        sync_dir(&parent_dir(target));
        Ok(())
    }
}

/// Removes the temporary files that writers in this module leave in `dir` when their
/// process is killed between creating and renaming them (`.<name>.<pid>.<n>.tmp…`). Returns
/// how many were removed. For a directory no running process is writing to, such as the
/// output of a run being resumed.
pub fn remove_stale_temps(dir: &Path) -> io::Result<usize> {
    let mut removed = 0;
    for entry in fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        if is_temp_name(name) && entry.file_type()?.is_file() {
            fs::remove_file(entry.path())?;
            removed += 1;
        }
    }
    Ok(removed)
}

/// Whether `name` has the form `.<target>.<pid>.<n>.tmp<suffix>` of [`TempFile::create`].
fn is_temp_name(name: &str) -> bool {
    let Some(rest) = name.strip_prefix('.') else {
        return false;
    };
    let Some(i) = rest.rfind(".tmp") else {
        return false;
    };
    let mut parts = rest[..i].rsplitn(3, '.');
    let digits =
        |s: Option<&str>| s.is_some_and(|s| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()));
    digits(parts.next()) && digits(parts.next()) && parts.next().is_some_and(|t| !t.is_empty())
}

/// The directory holding `path` (`.` for a bare file name).
fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Best-effort fsync of a directory (makes a rename durable on POSIX systems; some file
/// systems and platforms do not support it, which is not an error for the caller).
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

/// Wraps an I/O error with an action and the path it concerns, keeping its kind.
pub(crate) fn with_path(e: io::Error, action: &str, path: &Path) -> io::Error {
    io::Error::new(e.kind(), format!("{action} {}: {e}", path.display()))
}

#[cfg(test)]
pub(crate) mod test_support {
    use std::path::{Path, PathBuf};
    use std::sync::atomic::{AtomicU64, Ordering};

    /// A fresh, empty directory under the system temporary directory, removed on drop.
    pub(crate) struct TestDir(PathBuf);

    impl TestDir {
        pub(crate) fn new(tag: &str) -> Self {
            static N: AtomicU64 = AtomicU64::new(0);
            let n = N.fetch_add(1, Ordering::Relaxed);
            let dir =
                std::env::temp_dir().join(format!("adhesim-test-{tag}-{}-{n}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).expect("create test dir");
            TestDir(dir)
        }

        pub(crate) fn path(&self) -> &Path {
            &self.0
        }

        /// Names of all entries in the directory, sorted.
        pub(crate) fn entries(&self) -> Vec<String> {
            let mut v: Vec<String> = std::fs::read_dir(&self.0)
                .expect("read test dir")
                .map(|e| {
                    e.expect("dir entry")
                        .file_name()
                        .to_string_lossy()
                        .into_owned()
                })
                .collect();
            v.sort();
            v
        }
    }

    impl Drop for TestDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::TestDir;
    use super::*;

    #[test]
    fn write_then_overwrite_leaves_only_the_target() {
        let dir = TestDir::new("atomic-overwrite");
        let target = dir.path().join("a.txt");
        write_atomic(&target, b"first version, rather long content").unwrap();
        assert_eq!(
            fs::read(&target).unwrap(),
            b"first version, rather long content"
        );
        write_atomic(&target, b"second").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"second");
        assert_eq!(dir.entries(), vec!["a.txt".to_string()]);
    }

    #[test]
    fn streaming_writer_is_buffered_and_complete() {
        let dir = TestDir::new("atomic-stream");
        let target = dir.path().join("big.bin");
        write_atomic_with(&target, |w| {
            for i in 0..100_000u32 {
                w.write_all(&i.to_le_bytes())?;
            }
            Ok(())
        })
        .unwrap();
        let bytes = fs::read(&target).unwrap();
        assert_eq!(bytes.len(), 400_000);
        assert_eq!(&bytes[4 * 99_999..], &99_999u32.to_le_bytes());
        assert_eq!(dir.entries(), vec!["big.bin".to_string()]);
    }

    #[test]
    fn failing_writer_keeps_old_content_and_removes_temp() {
        let dir = TestDir::new("atomic-fail");
        let target = dir.path().join("keep.txt");
        write_atomic(&target, b"old").unwrap();
        let err = write_atomic_with(&target, |w| {
            w.write_all(&[b'x'; 100_000])?;
            Err(io::Error::other("generator failed"))
        })
        .unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("keep.txt"), "{msg}");
        assert!(msg.contains("generator failed"), "{msg}");
        assert_eq!(fs::read(&target).unwrap(), b"old");
        assert_eq!(dir.entries(), vec!["keep.txt".to_string()]);
    }

    #[test]
    fn missing_directory_is_an_error_naming_the_path() {
        let dir = TestDir::new("atomic-missing");
        let target = dir.path().join("no-such-dir").join("x.txt");
        let err = write_atomic(&target, b"data").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::NotFound);
        assert!(err.to_string().contains("no-such-dir"), "{err}");
    }

    #[test]
    fn path_without_file_name_is_rejected() {
        let err = write_atomic(Path::new("/"), b"data").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
    }

    #[test]
    fn temp_path_persists_or_cleans_up() {
        let dir = TestDir::new("atomic-temppath");
        let target = dir.path().join("plot.png");
        {
            let tmp = TempPath::reserve(&target, ".png").unwrap();
            assert!(tmp.path().to_string_lossy().ends_with(".png"));
            fs::write(tmp.path(), b"abandoned").unwrap();
        }
        assert!(dir.entries().is_empty(), "{:?}", dir.entries());
        let tmp = TempPath::reserve(&target, ".png").unwrap();
        fs::write(tmp.path(), b"kept").unwrap();
        tmp.persist(&target).unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"kept");
        assert_eq!(dir.entries(), vec!["plot.png".to_string()]);
    }

    #[test]
    fn stale_temporary_files_are_recognised_and_removed() {
        let dir = TestDir::new("atomic-stale");
        let target = dir.path().join("frame_00001.vtu");
        write_atomic(&target, b"kept").unwrap();
        let (tmp, file) = TempFile::create(&target, ".png").unwrap();
        drop(file);
        let tmp_name = tmp
            .0
            .path()
            .file_name()
            .unwrap()
            .to_str()
            .unwrap()
            .to_string();
        std::mem::forget(tmp); // as if the process had been killed
        fs::write(dir.path().join(".hidden.txt"), b"not ours").unwrap();
        fs::write(dir.path().join(".a.1.x.tmp"), b"not ours").unwrap();
        assert!(is_temp_name(&tmp_name), "{tmp_name}");
        assert_eq!(remove_stale_temps(dir.path()).unwrap(), 1);
        assert_eq!(
            dir.entries(),
            vec![".a.1.x.tmp", ".hidden.txt", "frame_00001.vtu"]
        );
    }

    #[test]
    fn concurrent_writers_never_expose_partial_content() {
        let dir = TestDir::new("atomic-concurrent");
        let target = dir.path().join("shared.txt");
        let a = vec![b'a'; 200_000];
        let b = vec![b'b'; 300_000];
        write_atomic(&target, &a).unwrap();
        std::thread::scope(|s| {
            for k in 0..2 {
                let (target, a, b) = (&target, &a, &b);
                s.spawn(move || {
                    for _ in 0..20 {
                        write_atomic(target, if k == 0 { a } else { b }).unwrap();
                    }
                });
            }
            let (target, a, b) = (&target, &a, &b);
            s.spawn(move || {
                for _ in 0..200 {
                    let content = fs::read(target).unwrap();
                    assert!(content == *a || content == *b, "partial file observed");
                }
            });
        });
        assert_eq!(dir.entries(), vec!["shared.txt".to_string()]);
    }
}
