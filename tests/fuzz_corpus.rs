//! Replays the fuzz corpus (`fuzz/corpus/<target>/`) and the inputs that
//! once crashed a loader (`fuzz/regressions/<target>/`) through the same
//! harness the cargo-fuzz targets use (`fuzz/src/lib.rs`), so the ordinary
//! test suite checks every loader against them without cargo-fuzz: each
//! input must give `Ok` or a clean error (no panic), quickly.
//!
//! The seeds (`seed-*`, written by `fuzz/seeds.py`) are valid files by
//! construction and must load.

#[path = "../fuzz/src/lib.rs"]
#[allow(dead_code)]
mod harness;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The most one input may take (a release build reads each in well under a
/// millisecond; the bound is loose for debug builds and busy machines).
const PER_INPUT: Duration = Duration::from_secs(5);

/// `fuzz/<root>/<target>/`: a target's corpus or regression inputs.
fn folder(root: &str, target: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz")
        .join(root)
        .join(target)
}

/// The bytes of the crash input `name` of `target` (`fuzz/regressions/`).
fn regression(target: &str, name: &str) -> Vec<u8> {
    std::fs::read(folder("regressions", target).join(name)).expect("read a regression input")
}

fn inputs(root: &str, target: &str) -> Vec<PathBuf> {
    let dir = folder(root, target);
    let mut files: Vec<PathBuf> = match std::fs::read_dir(&dir) {
        Ok(rd) => rd
            .map(|e| e.expect("read the corpus folder").path())
            .collect(),
        Err(_) => Vec::new(),
    };
    files.sort();
    files
}

fn replay(root: &str) -> usize {
    let ws = harness::Workspace::new();
    let mut n = 0;
    for target in harness::TARGETS {
        for file in inputs(root, target) {
            let data = std::fs::read(&file).expect("read a corpus file");
            let start = Instant::now();
            let result = std::panic::catch_unwind(|| harness::run(target, &data, &ws));
            let took = start.elapsed();
            let shown = file.display();
            let result = result.unwrap_or_else(|_| panic!("{shown}: the {target} loader panicked"));
            assert!(took < PER_INPUT, "{shown}: took {took:?}");
            let seed = file
                .file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("seed-"));
            if seed {
                assert!(result.is_ok(), "{shown}: a seed must load: {result:?}");
            }
            if let Err(e) = &result {
                assert!(!e.is_empty(), "{shown}: empty error message");
            }
            n += 1;
        }
    }
    n
}

#[test]
fn corpus_replays_without_panics() {
    let n = replay("corpus");
    assert!(n >= harness::TARGETS.len(), "only {n} corpus files found");
}

#[test]
fn crash_inputs_replay_without_panics() {
    replay("regressions");
}

// ---------------------------------------------------------------------------
// Memory bounds: a header that lies about its size allocates no more than
// the file it came in can justify.
// ---------------------------------------------------------------------------

mod counting {
    //! A global allocator that records, per thread, the most bytes held at
    //! once since the last [`reset`].
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::cell::Cell;

    pub struct Counting;

    thread_local! {
        static NOW: Cell<usize> = const { Cell::new(0) };
        static PEAK: Cell<usize> = const { Cell::new(0) };
    }

    fn add(n: usize) {
        let now = NOW.with(|c| {
            let v = c.get().saturating_add(n);
            c.set(v);
            v
        });
        PEAK.with(|p| p.set(p.get().max(now)));
    }

    fn sub(n: usize) {
        NOW.with(|c| c.set(c.get().saturating_sub(n)));
    }

    unsafe impl GlobalAlloc for Counting {
        unsafe fn alloc(&self, l: Layout) -> *mut u8 {
            add(l.size());
            unsafe { System.alloc(l) }
        }
        unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
            add(l.size());
            unsafe { System.alloc_zeroed(l) }
        }
        unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
            sub(l.size());
            unsafe { System.dealloc(p, l) }
        }
        unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
            add(new);
            sub(l.size());
            unsafe { System.realloc(p, l, new) }
        }
    }

    /// Starts a new measurement on this thread.
    pub fn reset() {
        let now = NOW.with(Cell::get);
        PEAK.with(|p| p.set(now));
    }

    /// The most bytes held at once on this thread since [`reset`], above
    /// what was held then.
    pub fn peak_since(base: usize) -> usize {
        PEAK.with(Cell::get).saturating_sub(base)
    }

    /// The bytes this thread holds now.
    pub fn now() -> usize {
        NOW.with(Cell::get)
    }
}

#[global_allocator]
static ALLOC: counting::Counting = counting::Counting;

/// Fixed allowance for paths, messages, parser state and buffered reads.
const SLACK: usize = 1 << 20;

/// Loads `data` through `target` and returns the error and the peak bytes
/// allocated while loading.
fn lying(target: &str, data: &[u8], ws: &harness::Workspace) -> (String, usize) {
    let base = counting::now();
    counting::reset();
    let result = harness::run(target, data, ws);
    let peak = counting::peak_since(base);
    let e = result.expect_err("a lying header must be refused");
    (e, peak)
}

fn gz(data: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

fn zl(data: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

/// Every format, with a header claiming about a gigabyte (or far more) of
/// samples or elements in a file of a few hundred bytes: refused with a
/// message naming the problem, allocating at most a small multiple of the
/// file size (the largest expansion a format allows: 64× for SLC's
/// run-length slices, 1032× for deflate) plus a fixed allowance.
#[test]
fn lying_headers_allocate_no_more_than_the_file_justifies() {
    let ws = harness::Workspace::new();
    let zeros = gz(&[0u8; 4096]);
    let zblock = zl(&[0u8; 4096]);
    let mut vti_zlib = Vec::new();
    for h in [1u32, 1 << 30, 1 << 30, zblock.len() as u32] {
        vti_zlib.extend(h.to_le_bytes());
    }
    vti_zlib.extend(&zblock);
    let b64 = |b: &[u8]| {
        use base64::Engine as _;
        base64::engine::general_purpose::STANDARD.encode(b)
    };
    let vti = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" \
         compressor=\"vtkZLibDataCompressor\">\n<ImageData WholeExtent=\"0 1023 0 1023 0 255\" \
         Origin=\"0 0 0\" Spacing=\"1 1 1\">\n<Piece Extent=\"0 1023 0 1023 0 255\">\n\
         <PointData Scalars=\"s\">\n<DataArray type=\"Float32\" Name=\"s\" format=\"binary\">\
         {}</DataArray>\n</PointData>\n</Piece>\n</ImageData>\n</VTKFile>\n",
        b64(&vti_zlib)
    );
    let mut nrrd_gz = b"NRRD0004\ntype: float\ndimension: 3\nsizes: 1024 1024 256\n\
        endian: little\nencoding: gzip\n\n"
        .to_vec();
    nrrd_gz.extend(&zeros);
    let mut mha_z = b"NDims = 3\nDimSize = 1024 1024 256\nElementType = MET_FLOAT\n\
        CompressedData = True\nElementDataFile = LOCAL\n"
        .to_vec();
    mha_z.extend(zl(&[0u8; 4096]));
    let mut raw = vec![0xff; 6];
    raw.extend([6, 0]);
    raw.extend([0u8; 64]);
    let cases: Vec<(&str, Vec<u8>, usize, &str)> =
        vec![
        (
            "ply",
            b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\n\
              property float x\nproperty float y\nproperty float z\nelement face 1000000000\n\
              property list uchar int vertex_indices\nend_header\n\0\0\0\0\0\0\0\0\0\0\0\0"
                .to_vec(),
            1,
            "vertex 1",
        ),
        (
            "ply",
            b"ply\nformat ascii 1.0\nelement vertex 1000000000\nproperty float x\n\
              property float y\nproperty float z\nend_header\n0 0 0\n"
                .to_vec(),
            1,
            "vertex 1",
        ),
        (
            "off",
            b"OFF\n1000000000 1000000000 0\n0 0 0\n".to_vec(),
            1,
            "vertex 1",
        ),
        (
            "nrrd",
            b"NRRD0004\ntype: float\ndimension: 3\nsizes: 1024 1024 256\nendian: little\n\
              encoding: raw\n\n\0\0\0\0"
                .to_vec(),
            1,
            "expected 1073741824 bytes",
        ),
        ("nrrd", nrrd_gz, MAX_DEFLATE, "deflate expands at most"),
        (
            "nrrd",
            b"NRRD0004\ntype: float\ndimension: 3\nsizes: 1024 1024 256\nencoding: ascii\n\n1 2 3"
                .to_vec(),
            1,
            "expected 268435456 values, found 3",
        ),
        (
            "nhdr",
            b"NRRD0004\ntype: float\ndimension: 3\nsizes: 1024 1024 256\nendian: little\n\
              encoding: raw\ndata file: d.raw\n"
                .to_vec(),
            1,
            "found 64",
        ),
        (
            "mhd",
            b"NDims = 3\nDimSize = 1024 1024 256\nElementType = MET_FLOAT\n\
              ElementDataFile = d.raw\n"
                .to_vec(),
            1,
            "found 64",
        ),
        ("mha", mha_z, MAX_DEFLATE, "deflate expands at most"),
        (
            "vtk",
            b"# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\n\
              DIMENSIONS 1024 1024 256\nSPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 268435456\n\
              SCALARS s float 1\nLOOKUP_TABLE default\n\0\0\0\0"
                .to_vec(),
            1,
            "expected 1073741824 bytes",
        ),
        (
            "vtk",
            b"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\n\
              DIMENSIONS 1024 1024 256\nSPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 268435456\n\
              SCALARS s float 1\nLOOKUP_TABLE default\n1 2 3\n"
                .to_vec(),
            1,
            "found 3",
        ),
        ("vti", vti.into_bytes(), MAX_DEFLATE, "deflate expands at most"),
        (
            "slc",
            b"11111\n1024 1024 1024 8\n1 1 1\n0 0 0 1\n0 0 X\n4 X\x7f\x00\x7f\x00".to_vec(),
            64,
            "slice 0",
        ),
        ("raw", raw, 1, "expected"),
    ];
    for (target, data, ratio, needle) in cases {
        let (e, peak) = lying(target, &data, &ws);
        assert!(e.contains(needle), "{target}: {e}");
        assert!(
            e.contains("in."),
            "{target}: the message names the file: {e}"
        );
        let bound = SLACK + ratio * data.len();
        assert!(
            peak <= bound,
            "{target}: {peak} bytes allocated for a {}-byte file (bound {bound}): {e}",
            data.len()
        );
    }
}

/// Deflate's largest expansion, as the loaders assume it.
const MAX_DEFLATE: usize = 1032;

/// A scratch folder of its own for one test.
fn scratch(tag: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("shapecue-fuzz-corpus-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Loads `header` with the allocation counter on: the result (the error's
/// text) and the peak bytes held while loading.
fn load_counted(header: &Path) -> (Result<shapecue::volume::Volume, String>, usize) {
    let base = counting::now();
    counting::reset();
    let r = shapecue::volume::load(header, None).map_err(|e| e.to_string());
    (r, counting::peak_since(base))
}

/// Samples of the 64×64×64 uchar grid of the headers below, one byte each.
const GRID: usize = 64 * 64 * 64;

/// NRRD and MetaImage headers of a 64×64×64 uchar grid in `data`, with
/// `extra` header lines (a byte skip, a compression).
fn detached_headers(dir: &Path, data: &str, nrrd_extra: &str, mhd_extra: &str) -> [PathBuf; 2] {
    let nhdr = dir.join("v.nhdr");
    std::fs::write(
        &nhdr,
        format!(
            "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 64 64 64\n{nrrd_extra}\
             data file: {data}\n"
        ),
    )
    .unwrap();
    let mhd = dir.join("v.mhd");
    std::fs::write(
        &mhd,
        format!(
            "NDims = 3\nDimSize = 64 64 64\nElementType = MET_UCHAR\n{mhd_extra}\
             ElementDataFile = {data}\n"
        ),
    )
    .unwrap();
    [nhdr, mhd]
}

/// A detached raw data file is sized from its metadata before it is read:
/// one ten times larger than the header says is refused unread (or, with
/// the data at the end of the file, only its last bytes are read); a
/// smaller one is refused naming the file, the bytes expected and its size.
#[test]
fn detached_raw_data_files_are_sized_before_reading() {
    let dir = scratch("detached-raw");
    let big = dir.join("big.raw");
    std::fs::write(&big, vec![7u8; 10 * GRID]).unwrap();
    let small = dir.join("small.raw");
    std::fs::write(&small, vec![7u8; 1000]).unwrap();
    for header in detached_headers(&dir, "big.raw", "encoding: raw\n", "") {
        let (r, peak) = load_counted(&header);
        let e = r.expect_err("a data file ten times too large");
        for needle in [
            big.display().to_string(),
            format!("expected {GRID} bytes"),
            format!("found {}", 10 * GRID),
        ] {
            assert!(e.contains(&needle), "{needle:?} not in {e}");
        }
        assert!(peak <= SLACK, "{peak} bytes held to refuse it: {e}");
    }
    for header in detached_headers(&dir, "small.raw", "encoding: raw\n", "") {
        let (r, _) = load_counted(&header);
        let e = r.expect_err("a data file too small");
        for needle in [
            small.display().to_string(),
            format!("expected {GRID} bytes"),
            "found 1000".into(),
            "the file has 1000 bytes".into(),
        ] {
            assert!(e.contains(&needle), "{needle:?} not in {e}");
        }
    }
    // The data at the end: only the last bytes are read. The bound holds
    // the samples once as bytes and once as f32 values.
    for header in detached_headers(
        &dir,
        "big.raw",
        "encoding: raw\nbyte skip: -1\n",
        "HeaderSize = -1\n",
    ) {
        let (r, peak) = load_counted(&header);
        let v = r.unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(v.values.len(), GRID);
        assert!(v.values.iter().all(|&x| x == 7.0));
        let bound = SLACK + 5 * GRID;
        assert!(peak <= bound, "{peak} bytes held (bound {bound})");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A gzip (NRRD) or zlib (MetaImage) data file that inflates to
/// gigabytes (3000 members or flushes of a megabyte of zeros each, about
/// 3 MB on disk) is read as a stream and inflated one byte past what the
/// header calls for, then refused.
#[test]
fn detached_gzip_bomb_stops_at_the_header_size() {
    let dir = scratch("detached-gzip");
    let member = gz(&vec![0u8; 1 << 20]);
    let bomb: Vec<u8> = std::iter::repeat_n(member.as_slice(), 3000)
        .flatten()
        .copied()
        .collect();
    assert!(bomb.len() > 2 * SLACK, "{} bytes", bomb.len());
    std::fs::write(dir.join("bomb.gz"), &bomb).unwrap();
    let [nhdr, _] = detached_headers(&dir, "bomb.gz", "encoding: gzip\n", "");
    let (r, peak) = load_counted(&nhdr);
    let e = r.expect_err("more data than the header calls for");
    assert!(
        e.contains("bomb.gz") && e.contains(&format!("more than the {GRID} bytes")),
        "{e}"
    );
    let bound = SLACK + 4 * GRID;
    assert!(peak <= bound, "{peak} bytes held (bound {bound}): {e}");
    // MetaImage's zlib: one stream of 3000 sync-flushed megabytes of zeros
    // (each flush after the first compresses to the same bytes).
    let mut c = flate2::Compress::new(flate2::Compression::best(), true);
    let mut flushed = || {
        let zeros = vec![0u8; 1 << 20];
        let mut out = Vec::with_capacity(1 << 16);
        let before = c.total_in();
        c.compress_vec(&zeros, &mut out, flate2::FlushCompress::Sync)
            .unwrap();
        assert_eq!(c.total_in() - before, zeros.len() as u64);
        out
    };
    let first = flushed();
    let next = flushed();
    assert_eq!(flushed(), next);
    let mut zbomb = first;
    for _ in 0..3000 {
        zbomb.extend_from_slice(&next);
    }
    assert!(zbomb.len() > 2 * SLACK, "{} bytes", zbomb.len());
    std::fs::write(dir.join("bomb.z"), &zbomb).unwrap();
    let [_, mhd] = detached_headers(&dir, "bomb.z", "", "CompressedData = True\n");
    let (r, peak) = load_counted(&mhd);
    let e = r.expect_err("more data than the header calls for");
    assert!(
        e.contains("bomb.z") && e.contains(&format!("more than the {GRID} bytes")),
        "{e}"
    );
    assert!(peak <= bound, "{peak} bytes held (bound {bound}): {e}");
    // The same data, as many bytes as the header says: loads.
    std::fs::write(dir.join("ok.gz"), gz(&vec![3u8; GRID])).unwrap();
    let [nhdr, _] = detached_headers(&dir, "ok.gz", "encoding: gzip\n", "");
    let v = shapecue::volume::load(&nhdr, None).unwrap();
    assert!(v.values.iter().all(|&x| x == 3.0));
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------
// Inputs the fuzzer (or reading for it) found, one test each
// ---------------------------------------------------------------------------

/// Runs `target` on `data` in its own thread and fails if it takes more
/// than ten seconds (a hang fails the test instead of stalling the suite).
fn within_deadline(target: &'static str, data: Vec<u8>) -> Result<String, String> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let ws = harness::Workspace::new();
        let _ = tx.send(harness::run(target, &data, &ws));
    });
    rx.recv_timeout(Duration::from_secs(10))
        .unwrap_or_else(|e| panic!("{target}: no answer within 10 s ({e})"))
}

/// A binary PLY element without properties takes no bytes, so a huge
/// count of them looped for ever without reading anything.
#[test]
fn binary_ply_element_without_properties_does_not_hang() {
    let mut f = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nelement nothing 99999999999999\n\
        element face 1\nproperty list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for v in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        f.extend(v.iter().flat_map(|c| c.to_le_bytes()));
    }
    f.push(3);
    f.extend([0i32, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
    let r = within_deadline("ply", f);
    assert_eq!(r.as_deref(), Ok("3 vertices (3 welded), 1 faces"));
}

/// A NRRD data file pattern whose bounds are far apart overflowed
/// `max - min` (a panic in debug builds; in release, the wrong message).
#[test]
fn nrrd_pattern_with_far_apart_bounds_is_refused_by_count() {
    let h = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\
             data file: d%d.raw -1 9223372036854775807 1 2\n";
    let e = within_deadline("nhdr", h.as_bytes().to_vec()).unwrap_err();
    assert!(e.contains("more than the grid has slices (2)"), "{e}");
}

/// The glTF seed that names `d.bin`, as text.
fn gltf_seed() -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/gltf/seed-file-buffer.gltf");
    std::fs::read_to_string(p).expect("the glTF seed")
}

/// A primitive whose POSITION names a missing accessor panicked inside the
/// glTF crate's validation.
#[test]
fn gltf_position_naming_a_missing_accessor_is_an_error() {
    let f =
        r#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}"#;
    let e = within_deadline("gltf", f.as_bytes().to_vec()).unwrap_err();
    assert!(
        e.contains("mesh 0 primitive 0") && e.contains("accessor 0") && e.contains("0 accessors"),
        "{e}"
    );
}

/// An accessor whose type does not fit its role (inverse bind matrices
/// that are not MAT4, say) made the glTF crate's reader panic.
#[test]
fn gltf_accessor_of_the_wrong_type_is_an_error() {
    let seed = gltf_seed();
    for (from, to, role) in [
        ("\"MAT4\"", "\"SCALAR\"", "inverse bind matrices"),
        (
            "\"count\": 3, \"type\": \"VEC3\"",
            "\"count\": 3, \"type\": \"VEC2\"",
            "POSITION",
        ),
        (
            "\"count\": 2, \"type\": \"VEC4\"",
            "\"count\": 2, \"type\": \"VEC3\"",
            "keyframe values",
        ),
    ] {
        assert!(seed.contains(from), "{from}");
        let f = seed.replacen(from, to, 1);
        let e = within_deadline("gltf", f.into_bytes()).unwrap_err();
        assert!(e.contains(role) && e.contains("accessor"), "{role}: {e}");
    }
}

/// A GLB header declaring gigabytes made the glTF crate allocate them
/// before reading the (tiny) file.
#[test]
fn glb_header_longer_than_the_file_is_refused_before_allocating() {
    let ws = harness::Workspace::new();
    let mut f = b"glTF".to_vec();
    f.extend(2u32.to_le_bytes());
    f.extend(0xF000_0000u32.to_le_bytes());
    f.extend(b"\x10\0\0\0JSON{\"asset\":{}}   ");
    let (e, peak) = lying("glb", &f, &ws);
    assert!(
        e.contains("GLB header") && e.contains("4026531840 bytes"),
        "{e}"
    );
    assert!(
        peak <= SLACK,
        "{peak} bytes allocated for a {}-byte file",
        f.len()
    );
}

/// A GLB header declaring less than its own 12 bytes made the glTF crate
/// subtract past zero (a panic where overflow checks are on, as in debug
/// builds; found by fuzzing a `.gltf` file that holds GLB bytes).
#[test]
fn glb_header_shorter_than_itself_is_refused() {
    let crash = regression("gltf", "crash-05c2f3a58e6fd23d203c88b640cdcb60ab19a3cb");
    for (target, bytes) in [
        ("gltf", crash),
        ("glb", {
            let mut f = b"glTF".to_vec();
            f.extend(2u32.to_le_bytes());
            f.extend(7u32.to_le_bytes());
            f.extend(b"\x10\0\0\0JSON{\"asset\":{}}   ");
            f
        }),
    ] {
        let e = within_deadline(target, bytes).unwrap_err();
        assert!(
            e.contains("GLB header") && e.contains("less than its own 12"),
            "{target}: {e}"
        );
    }
}

/// Keyframe times that do not increase (here out of order) made sampling
/// index before the first keyframe (an overflow, then an index past the
/// end); found by fuzzing. They are refused at load, naming the keyframe.
#[test]
fn glb_keyframe_times_out_of_order_are_refused() {
    let crash = regression("glb", "crash-cd2c750fd97f431336a35a5b7a4da73f14aa937f");
    let e = within_deadline("glb", crash).unwrap_err();
    assert!(
        e.contains("keyframe") && e.contains("previous keyframe"),
        "{e}"
    );
}

/// An animation channel with an unknown target path made the glTF crate
/// unwrap an invalid value (a panic in release builds too); found by
/// fuzzing. Channels are checked before the import, naming the channel.
#[test]
fn gltf_channel_with_an_invalid_target_path_is_refused() {
    let crash = regression("gltf", "crash-ad027746a4b599dd95ef4de9821ce8d7d444e9eb");
    let e = within_deadline("gltf", crash).unwrap_err();
    assert!(e.contains("animation") && e.contains("channel"), "{e}");
}
