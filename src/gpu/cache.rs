//! shapecue's own cache of built OpenCL programs (`CL_PROGRAM_BINARIES`), so
//! that no runtime recompiles the kernels in every process.
//!
//! A program built from source is saved by [`crate::gpu::Gpu::persist_programs`]
//! (called when the [`crate::gpu::Gpu`] is dropped, or earlier by the CLI):
//! after the process's kernel launches, so a runtime that puts the code it
//! compiled at the first launch into its binary (PoCL serialises its whole
//! kernel cache folder, work-group-size variants included) has it saved too.
//! Later processes create the program from that binary.
//!
//! - **When:** at the first build from source of a key, on every runtime but
//!   PoCL ([`saves`]). Intel's CPU runtime returns its binary quickly and
//!   has no cache of its own (each process compiled the curvature program
//!   anew), so the cache turns every later process's build into a load.
//!   PoCL has its own kernel cache, and asking it for a program's binary
//!   compiles every kernel of the program for any work-group size (seconds
//!   for `kernels/curvature.cl`'s 16 kernels), so on PoCL shapecue saves
//!   only in `shapecue build-kernels` ([`crate::gpu::Gpu::save_every_build`])
//!   or with `SHAPECUE_CACHE_POCL=1`. docs/performance.md has the figures.
//! - **Where:** `$SHAPECUE_CACHE_DIR`, else `$XDG_CACHE_HOME/shapecue`, else
//!   `~/.cache/shapecue`; `SHAPECUE_NO_CACHE=1` turns the cache off.
//! - **Key:** a 128-bit FNV-1a hash of the assembled kernel text, the full
//!   build options, the platform (name and version), the device (name and
//!   version), the driver version and [`FORMAT_VERSION`]; the file is
//!   `<key in hex>.clbin`. Any change of source, options, device or driver
//!   is a different file.
//! - **File:** a 48-byte header (magic, format version, payload length, the
//!   key again, a CRC-32 of the payload) and the driver's binary. A file
//!   that is short, long, for another key or fails its checksum is ignored
//!   and rebuilt from source (and rewritten); a binary the driver refuses is
//!   too. The cache never makes a build fail.
//! - **Concurrency:** written to a temporary file in the same folder and
//!   renamed over the entry, so a reader sees the old file, the new one or
//!   none, never a half-written one; processes racing to write the same
//!   entry write the same bytes.

use std::io::Write;
use std::path::{Path, PathBuf};

/// The file format's version (in the header and the key).
pub const FORMAT_VERSION: u32 = 1;
/// The first 8 bytes of every cache file.
pub const MAGIC: &[u8; 8] = b"SCCLBIN\0";
/// Header length in bytes: magic 8, version 4, flags 4, payload length 8,
/// key 16, CRC-32 of the payload 4, reserved 4.
pub const HEADER_LEN: usize = 48;

/// The cache folder from the environment, or `None` when the cache is off
/// (`SHAPECUE_NO_CACHE` set to anything but empty or `0`) or no folder is
/// known (no `SHAPECUE_CACHE_DIR`, `XDG_CACHE_HOME` or `HOME`).
pub fn cache_dir() -> Option<PathBuf> {
    let var = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty());
    if var("SHAPECUE_NO_CACHE").is_some_and(|v| v != "0") {
        return None;
    }
    if let Some(d) = var("SHAPECUE_CACHE_DIR") {
        return Some(PathBuf::from(d));
    }
    if let Some(d) = var("XDG_CACHE_HOME") {
        return Some(PathBuf::from(d).join("shapecue"));
    }
    var("HOME").map(|h| PathBuf::from(h).join(".cache").join("shapecue"))
}

/// 128-bit FNV-1a over `parts`, each prefixed by its length so that part
/// boundaries count (`("ab", "c")` and `("a", "bc")` differ).
pub fn key(parts: &[&[u8]]) -> u128 {
    const OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
    const PRIME: u128 = 0x0000000001000000000000000000013B;
    let mut h = OFFSET;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= u128::from(b);
            h = h.wrapping_mul(PRIME);
        }
    };
    eat(&FORMAT_VERSION.to_le_bytes());
    for p in parts {
        eat(&(p.len() as u64).to_le_bytes());
        eat(p);
    }
    h
}

/// The file of `key` in `dir`.
pub fn entry_path(dir: &Path, key: u128) -> PathBuf {
    dir.join(format!("{key:032x}.clbin"))
}

/// Why a cache file was not used.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Reject {
    /// No file (the usual first run).
    Missing,
    /// The file could not be read (named with the OS message).
    Unreadable(String),
    /// Shorter than its header, or its payload length disagrees with the file.
    Truncated,
    /// Wrong magic, version or key.
    Foreign,
    /// The payload's CRC-32 does not match the header.
    Checksum,
}

impl std::fmt::Display for Reject {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Reject::Missing => f.write_str("no cached binary"),
            Reject::Unreadable(e) => write!(f, "cached binary unreadable: {e}"),
            Reject::Truncated => f.write_str("cached binary truncated"),
            Reject::Foreign => f.write_str("cached binary of another format or key"),
            Reject::Checksum => f.write_str("cached binary fails its checksum"),
        }
    }
}

/// The bytes of a cache file holding `payload` under `key`.
pub fn encode(key: u128, payload: &[u8]) -> Vec<u8> {
    let mut v = Vec::with_capacity(HEADER_LEN + payload.len());
    v.extend_from_slice(MAGIC);
    v.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    v.extend_from_slice(&0u32.to_le_bytes());
    v.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    v.extend_from_slice(&key.to_le_bytes());
    v.extend_from_slice(&crc32fast::hash(payload).to_le_bytes());
    v.extend_from_slice(&0u32.to_le_bytes());
    debug_assert_eq!(v.len(), HEADER_LEN);
    v.extend_from_slice(payload);
    v
}

/// The payload of a cache file's bytes, checked against `key`, its length
/// and its checksum.
pub fn decode(key: u128, bytes: &[u8]) -> Result<&[u8], Reject> {
    if bytes.len() < HEADER_LEN {
        return Err(Reject::Truncated);
    }
    let (h, payload) = bytes.split_at(HEADER_LEN);
    let u32_at = |o: usize| u32::from_le_bytes(h[o..o + 4].try_into().expect("4 bytes"));
    let len = u64::from_le_bytes(h[16..24].try_into().expect("8 bytes"));
    let file_key = u128::from_le_bytes(h[24..40].try_into().expect("16 bytes"));
    if &h[..8] != MAGIC || u32_at(8) != FORMAT_VERSION || file_key != key {
        return Err(Reject::Foreign);
    }
    if len != payload.len() as u64 {
        return Err(Reject::Truncated);
    }
    if crc32fast::hash(payload) != u32_at(40) {
        return Err(Reject::Checksum);
    }
    Ok(payload)
}

/// Whether programs built from source on this platform are saved. Not on
/// PoCL unless `SHAPECUE_CACHE_POCL=1`: PoCL keeps a cache of its own
/// (`POCL_CACHE_DIR`, by default `~/.cache/pocl`), so it does not recompile
/// in every process anyway, and asking it for a program's binary compiles
/// every kernel of the program for any work-group size (seconds for
/// `kernels/curvature.cl`), a cost a user would
/// meet on an ordinary run (`shapecue build-kernels` saves anyway, through
/// [`crate::gpu::Gpu::save_every_build`]). Entries that exist are used on
/// every platform.
pub fn saves(platform: &str) -> bool {
    let pocl = platform.contains("Portable Computing Language") || platform.contains("PoCL");
    !pocl || std::env::var("SHAPECUE_CACHE_POCL").is_ok_and(|v| v == "1")
}

/// Reads and checks the entry of `key` in `dir`.
pub fn load(dir: &Path, key: u128) -> Result<Vec<u8>, Reject> {
    let path = entry_path(dir, key);
    let bytes = match std::fs::read(&path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(Reject::Missing),
        Err(e) => return Err(Reject::Unreadable(e.to_string())),
    };
    decode(key, &bytes).map(<[u8]>::to_vec)
}

/// Writes the entry of `key` in `dir` (creating the folder): a temporary
/// file named after the process, the thread and the time, then a rename
/// over the entry. On error the temporary file is removed.
pub fn store(dir: &Path, key: u128, payload: &[u8]) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let tid = format!("{:?}", std::thread::current().id());
    let tid: String = tid.chars().filter(char::is_ascii_digit).collect();
    let tmp = dir.join(format!(
        ".{key:032x}.{}.{tid}.{nanos}.tmp",
        std::process::id()
    ));
    let res = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(&encode(key, payload))?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, entry_path(dir, key))
    })();
    if res.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    res
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmpdir(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("shapecue-cache-unit-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn key_depends_on_every_part_and_its_boundaries() {
        let k = key(&[b"ab", b"c"]);
        assert_ne!(k, key(&[b"a", b"bc"]));
        assert_ne!(k, key(&[b"ab", b"d"]));
        assert_eq!(k, key(&[b"ab", b"c"]));
        assert!(saves("Intel(R) OpenCL"));
    }

    #[test]
    fn round_trip_and_every_kind_of_damage_is_detected() {
        let payload: Vec<u8> = (0..1000u32).map(|i| (i * 7) as u8).collect();
        let bytes = encode(42, &payload);
        assert_eq!(decode(42, &bytes).unwrap(), &payload[..]);
        assert_eq!(decode(43, &bytes), Err(Reject::Foreign));
        // Truncated anywhere: inside the header or the payload.
        for cut in [0, 10, HEADER_LEN - 1, HEADER_LEN, bytes.len() - 1] {
            assert_eq!(
                decode(42, &bytes[..cut]),
                Err(Reject::Truncated),
                "cut {cut}"
            );
        }
        // Too long (an append).
        let mut long = bytes.clone();
        long.push(0);
        assert_eq!(decode(42, &long), Err(Reject::Truncated));
        // One flipped bit in the payload, or in the checksum.
        for at in [HEADER_LEN, HEADER_LEN + 500, bytes.len() - 1, 40] {
            let mut bad = bytes.clone();
            bad[at] ^= 0x10;
            assert_eq!(decode(42, &bad), Err(Reject::Checksum), "byte {at}");
        }
        let mut bad = bytes.clone();
        bad[0] = b'X';
        assert_eq!(decode(42, &bad), Err(Reject::Foreign));
    }

    #[test]
    fn store_then_load_and_missing_entries() {
        let d = tmpdir("store");
        assert_eq!(load(&d, 7), Err(Reject::Missing));
        store(&d, 7, b"binary").unwrap();
        assert_eq!(load(&d, 7).unwrap(), b"binary");
        // Overwriting replaces the entry whole.
        store(&d, 7, b"another binary").unwrap();
        assert_eq!(load(&d, 7).unwrap(), b"another binary");
        std::fs::write(entry_path(&d, 7), b"SCCLBIN\0 garbage").unwrap();
        assert_eq!(load(&d, 7), Err(Reject::Truncated));
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn concurrent_writers_and_readers_never_see_a_partial_file() {
        let d = tmpdir("race");
        let payload: Vec<u8> = (0..200_000u32).map(|i| (i % 251) as u8).collect();
        std::thread::scope(|s| {
            for _ in 0..8 {
                s.spawn(|| {
                    for _ in 0..10 {
                        store(&d, 9, &payload).unwrap();
                        match load(&d, 9) {
                            Ok(p) => assert_eq!(p, payload),
                            Err(e) => panic!("reader saw {e}"),
                        }
                    }
                });
            }
        });
        assert_eq!(load(&d, 9).unwrap(), payload);
        // No temporary file is left behind.
        let left: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(left.is_empty(), "{left:?}");
        let _ = std::fs::remove_dir_all(&d);
    }
}
