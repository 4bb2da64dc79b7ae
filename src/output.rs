//! Output files are written whole or not at all, and never over an input.
//!
//! - [`check_outputs`] runs before any work: it refuses an output that is one
//!   of the run's inputs (the same file, compared by device and inode, so a
//!   hard link or another spelling of the path is caught too), two outputs that
//!   name the same file, and an existing output without `force`. The first two
//!   are refused even with `force`: nothing the user gave is overwritten.
//! - [`write_atomic`] writes to a hidden temporary file in the output's own
//!   folder and renames it into place only when the whole file was written, so
//!   a failed or interrupted write leaves the old file (or none) and never a
//!   truncated one. The rename is atomic on POSIX file systems because the
//!   temporary file is on the same file system as its target.
//! - [`install_interrupt_cleanup`] removes the temporary files still being
//!   written when the process receives SIGINT, SIGTERM or SIGHUP, then exits
//!   with the conventional status 128 + signal (130 for Ctrl-C).
//!
//! Below both the writers (`crate::export`, which re-exports this module as
//! `export::output`) and the renderer's PNG writer (`Frame::save_png`), so
//! that neither imports the other for it; it knows only the error type.

use crate::error::{Error, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

/// Temporary files being written now, removed on interruption.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Distinguishes temporary files of one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);
/// Set by the interrupt handler before it cleans up.
static INTERRUPTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// The identity of an existing file: device and inode where the platform has
/// them, else its canonical path.
#[derive(PartialEq, Eq, Debug)]
enum Identity {
    #[cfg(unix)]
    Inode(u64, u64),
    #[cfg_attr(unix, allow(dead_code))]
    Path(PathBuf),
}

fn identity(path: &Path) -> Option<Identity> {
    let meta = std::fs::metadata(path).ok()?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        Some(Identity::Inode(meta.dev(), meta.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = meta;
        path.canonicalize().ok().map(Identity::Path)
    }
}

/// Whether `a` and `b` name one existing file (by device and inode where
/// the platform has them, so hard links and other spellings count).
pub fn same_file(a: &Path, b: &Path) -> bool {
    matches!((identity(a), identity(b)), (Some(x), Some(y)) if x == y)
}

/// Where a path that may not exist yet would be: its folder made canonical
/// (when that folder exists) joined with its file name.
/// Where `path` is: its folder made canonical where it exists, and its name.
pub(crate) fn location(path: &Path) -> PathBuf {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let dir = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
    match path.file_name() {
        Some(name) => dir.join(name),
        None => dir,
    }
}

fn refuse(msg: String) -> Error {
    Error::InvalidArgument(msg)
}

/// Checks a run's outputs before it starts, then creates their folders and
/// checks that each can take a new file.
///
/// `inputs` are every file the run reads (mesh, volume header *and* its
/// detached data files, marked-edge lists, scene files); `outputs` every file
/// it will write. Refused, even with `force`: an output that is an input, and
/// two outputs that are the same file. Refused without `force`: an output that
/// exists. A path of `-` is refused (outputs are files).
pub fn check_outputs(inputs: &[&Path], outputs: &[&Path], force: bool) -> Result<()> {
    let input_ids: Vec<(&Path, Identity)> = inputs
        .iter()
        .filter_map(|p| identity(p).map(|id| (*p, id)))
        .collect();
    let mut seen: Vec<Seen> = Vec::new();
    for &out in outputs {
        let (loc, id) = refuse_output(out, &input_ids, &seen, force)?;
        seen.push((out, loc, id));
    }
    for &out in outputs {
        prepare_folder(out)?;
    }
    Ok(())
}

/// An output already checked: its path, its location and its identity
/// (when it exists).
type Seen<'a> = (&'a Path, PathBuf, Option<Identity>);

/// The checks of [`check_outputs`] on one output against the inputs and
/// the outputs before it; returns its location and identity.
fn refuse_output(
    out: &Path,
    input_ids: &[(&Path, Identity)],
    seen: &[Seen],
    force: bool,
) -> Result<(PathBuf, Option<Identity>)> {
    if out.as_os_str() == "-" {
        return Err(refuse(
            "an output of '-' is not supported: give a file name".to_string(),
        ));
    }
    if out.as_os_str().is_empty() || out.file_name().is_none() {
        return Err(refuse(format!(
            "'{}' is not a file name for an output",
            out.display()
        )));
    }
    let id = identity(out);
    if let Some(id) = &id
        && let Some((inp, _)) = input_ids.iter().find(|(_, i)| i == id)
    {
        let how = if location(out) == location(inp) {
            String::new()
        } else {
            " (the same file under another name)".to_string()
        };
        return Err(refuse(format!(
            "refusing to write {}: it is the input file {}{how}; an input is never overwritten, \
             not even with force = true",
            out.display(),
            inp.display()
        )));
    }
    let loc = location(out);
    if let Some((other, _, _)) = seen
        .iter()
        .find(|(_, l, i)| *l == loc || (id.is_some() && i.as_ref() == id.as_ref()))
    {
        return Err(refuse(format!(
            "{} and {} name the same output file; give each output its own name",
            other.display(),
            out.display()
        )));
    }
    if id.is_some() && !std::fs::metadata(out).map(|m| m.is_file()).unwrap_or(false) {
        return Err(refuse(format!(
            "refusing to write {}: it exists and is not a regular file",
            out.display()
        )));
    }
    if id.is_some() && !force {
        return Err(refuse(format!(
            "{} exists; pass force = true to overwrite it",
            out.display()
        )));
    }
    Ok((loc, id))
}

/// Creates the folder of `out` and checks that it can take a new file.
fn prepare_folder(out: &Path) -> Result<()> {
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        if let Some(file) = dir
            .ancestors()
            .find(|a| a.exists() && !a.is_dir() && !a.as_os_str().is_empty())
        {
            return Err(refuse(format!(
                "cannot write {}: {} is a file, not a folder",
                out.display(),
                file.display()
            )));
        }
        std::fs::create_dir_all(dir).map_err(|source| Error::Write {
            path: dir.to_path_buf(),
            source,
        })?;
    }
    // Each folder must take a new file now, so that a run with several
    // outputs does not write the first and then fail on a later one (a
    // read-only folder, one of /proc or /sys): the probe is the hidden
    // temporary file `write_atomic` would make, removed at once.
    let probe = temp_path(out);
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .map_err(|source| Error::Write {
            path: out.to_path_buf(),
            source,
        })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// The hidden temporary name `write_atomic` uses for `path`.
fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.{}.{n}.partial", std::process::id()))
}

/// Takes a temporary file of [`create_pending`] off the pending list (it
/// was renamed into place, or removed).
fn unlist_pending(path: &Path) {
    let mut list = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    list.retain(|p| p != path);
}

/// Creates the temporary file `path` and lists it as pending, under the
/// lock the interrupt handler holds while it removes them and exits: a
/// file is either listed (and removed by the handler) or never created.
fn create_pending(path: &Path) -> std::io::Result<File> {
    let mut list = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    if interrupted() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::Interrupted,
            "the process is being interrupted",
        ));
    }
    let f = File::create(path)?;
    list.push(path.to_path_buf());
    Ok(f)
}

/// The temporary file of [`write_atomic`]: a file whose written bytes are
/// handed to the disk every 8 MiB (Linux: `sync_file_range` with
/// `SYNC_FILE_RANGE_WRITE`, which starts the write-back and returns), so
/// that the disk works while the rest is encoded and the closing
/// `fdatasync` has little left to wait for.
pub struct OutputFile {
    file: File,
    /// Bytes written so far, and the first of them not yet handed over.
    written: u64,
    handed: u64,
}

impl OutputFile {
    const AHEAD: u64 = 8 << 20;

    fn new(file: File) -> Self {
        OutputFile {
            file,
            written: 0,
            handed: 0,
        }
    }

    /// Empties the file to write it again from its start.
    pub fn restart(&mut self) -> std::io::Result<()> {
        use std::io::{Seek, SeekFrom};
        self.file.set_len(0)?;
        self.file.seek(SeekFrom::Start(0))?;
        (self.written, self.handed) = (0, 0);
        Ok(())
    }

    #[cfg(target_os = "linux")]
    fn hand_over(&mut self) {
        use std::os::fd::AsRawFd;
        // SAFETY: a plain system call on an open descriptor; a failure (a
        // file system without write-back) only leaves the bytes to the
        // closing sync.
        unsafe {
            libc::sync_file_range(
                self.file.as_raw_fd(),
                self.handed as libc::off64_t,
                (self.written - self.handed) as libc::off64_t,
                libc::SYNC_FILE_RANGE_WRITE,
            )
        };
        self.handed = self.written;
    }

    #[cfg(not(target_os = "linux"))]
    fn hand_over(&mut self) {}
}

impl Write for OutputFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.file.write(buf)?;
        self.written += n as u64;
        if self.written - self.handed >= Self::AHEAD {
            self.hand_over();
        }
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

impl std::io::Seek for OutputFile {
    /// (PNG encoders seek back to patch lengths.) What was written before is
    /// left to the closing sync; handing over starts again from here.
    fn seek(&mut self, pos: std::io::SeekFrom) -> std::io::Result<u64> {
        let at = self.file.seek(pos)?;
        (self.written, self.handed) = (at, at);
        Ok(at)
    }
}

/// Writes `path` whole or not at all: `write` fills a buffered temporary file
/// in the same folder, which is renamed onto `path` only when `write` returned
/// `Ok` and every byte reached the file. On any error the temporary file is
/// removed and `path` is left as it was.
///
/// Errors that `write` returns are passed through; I/O errors name `path`.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<OutputFile>) -> Result<()>,
) -> Result<()> {
    let tmp = temp_path(path);
    let err = |source| Error::Write {
        path: path.to_path_buf(),
        source,
    };
    let result = (|| {
        let file = OutputFile::new(create_pending(&tmp).map_err(err)?);
        let mut w = BufWriter::with_capacity(1 << 20, file);
        write(&mut w)?;
        let file = w.into_inner().map_err(|e| err(e.into_error()))?.file;
        // Space is reserved by the write calls, but some file systems report
        // a full disk only when the data is flushed: sync before the rename.
        file.sync_data().map_err(err)?;
        drop(file);
        std::fs::rename(&tmp, path).map_err(err)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    unlist_pending(&tmp);
    result
}

/// [`write_atomic`] for a document already in memory.
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic(path, |w| {
        w.write_all(bytes).map_err(|source| Error::Write {
            path: path.to_path_buf(),
            source,
        })
    })
}

/// Removes the temporary files of unfinished [`write_atomic`] calls when the
/// process is interrupted (SIGINT, SIGTERM, SIGHUP), says so on standard
/// error (files finished before are whole; the one being written is gone;
/// `note` adds what the command leaves unwritten, e.g. a report written at
/// its end), then exits with status 130. Call once, early in `main`; a second
/// call does nothing. A command that finishes while the handler runs still
/// ends with 130 ([`interrupted`]).
pub fn install_interrupt_cleanup(note: &'static str) {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // If a handler cannot be installed (another one exists), writes are
        // still atomic; only a leftover hidden `.partial` file is possible.
        let _ = ctrlc::set_handler(move || {
            // The lock is held until the process exits, so that no
            // temporary file is created after the pending ones are removed.
            let list = PENDING.lock().unwrap_or_else(|e| e.into_inner());
            INTERRUPTED.store(true, Ordering::SeqCst);
            for p in list.iter() {
                let _ = std::fs::remove_file(p);
            }
            eprintln!(
                "interrupted: files finished before the interrupt are whole, the one being \
                 written was removed{note}"
            );
            std::process::exit(130);
        });
    });
}

/// Whether the interrupt handler of [`install_interrupt_cleanup`] has run.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scratch folder, removed on drop unless the test is failing.
    struct Dir(PathBuf);

    impl std::ops::Deref for Dir {
        type Target = Path;
        fn deref(&self) -> &Path {
            &self.0
        }
    }

    impl Drop for Dir {
        fn drop(&mut self) {
            if !std::thread::panicking() {
                let _ = std::fs::remove_dir_all(&self.0);
            }
        }
    }

    fn dir(name: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("shapecue-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Dir(d)
    }

    #[test]
    fn hard_link_to_an_input_is_refused_even_with_force() {
        let d = dir("link");
        let input = d.join("cow.obj");
        std::fs::write(&input, "v 0 0 0\n").unwrap();
        let link = d.join("hard.ply");
        std::fs::hard_link(&input, &link).unwrap();
        let e = check_outputs(&[&input], &[&link], true)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("input file") && e.contains("another name"),
            "{e}"
        );
        // Another spelling of the same path.
        let dotted = d.join(".").join("cow.obj");
        let e = check_outputs(&[&input], &[&dotted], true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("input file"), "{e}");
        assert_eq!(std::fs::read_to_string(&input).unwrap(), "v 0 0 0\n");
    }

    #[test]
    fn two_outputs_naming_one_file_are_refused() {
        let d = dir("twice");
        let a = d.join("o.ply");
        let b = d.join(".").join("o.ply");
        let e = check_outputs(&[], &[&a, &b], true).unwrap_err().to_string();
        assert!(e.contains("same output file"), "{e}");
    }

    #[test]
    fn existing_output_needs_force_and_dash_is_refused() {
        let d = dir("exists");
        let a = d.join("o.json");
        std::fs::write(&a, "{}").unwrap();
        let e = check_outputs(&[], &[&a], false).unwrap_err().to_string();
        assert!(e.contains("force = true"), "{e}");
        check_outputs(&[], &[&a], true).unwrap();
        let e = check_outputs(&[], &[Path::new("-")], true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("'-'"), "{e}");
    }

    #[test]
    fn failed_write_keeps_the_old_file_and_leaves_no_temporary() {
        let d = dir("atomic");
        let a = d.join("o.ply");
        std::fs::write(&a, "old").unwrap();
        let r = write_atomic(&a, |w| {
            w.write_all(b"half of a new").unwrap();
            Err(Error::InvalidArgument("stop".into()))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old");
        let names: Vec<_> = std::fs::read_dir(&*d)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
        write_bytes_atomic(&a, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new");
    }

    #[test]
    fn a_folder_that_takes_no_file_is_refused_before_anything_is_written() {
        // /proc/self takes no new file, even as root: a run whose second
        // output goes there must fail before its first is written.
        let d = dir("probe");
        let first = d.join("first.png");
        let proc = Path::new("/proc/self/x.svg");
        if Path::new("/proc/self").is_dir() {
            let e = check_outputs(&[], &[&first, proc], false)
                .unwrap_err()
                .to_string();
            assert!(e.contains("/proc/self/x.svg"), "{e}");
        }
        check_outputs(&[], &[&first], false).unwrap();
        let names: Vec<_> = std::fs::read_dir(&*d)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert!(names.is_empty(), "the probe was left behind: {names:?}");
    }

    #[test]
    fn a_device_or_folder_is_not_replaced() {
        let d = dir("special");
        let e = check_outputs(&[], &[&d], true).unwrap_err().to_string();
        assert!(e.contains("not a regular file"), "{e}");
        let full = Path::new("/dev/full");
        if full.exists() {
            let e = check_outputs(&[], &[full], true).unwrap_err().to_string();
            assert!(e.contains("not a regular file"), "{e}");
        }
    }
}
