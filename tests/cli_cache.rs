//! The command line's program cache (`build-kernels`, hits, corrupt and
//! concurrent entries), timed runs, device errors and faults: clear errors
//! that leave nothing behind.

mod common;

use common::{cli, run_cli, scratch};

/// Runs `shapecue curvature` on a small generated sphere (gather variant:
/// bitwise reproducible) with the program cache in `cache` (or off), and
/// returns the stats and the PLY bytes.
fn curvature_cached(
    cache: Option<&std::path::Path>,
    out_dir: &std::path::Path,
    tag: &str,
    extra: &[&str],
) -> (serde_json::Value, Vec<u8>) {
    curvature_cached_saving(cache, out_dir, tag, extra, true)
}

/// [`curvature_cached`], with saving on PoCL (`SHAPECUE_CACHE_POCL=1`) or
/// as an ordinary user runs it (`save_on_pocl` false).
fn curvature_cached_saving(
    cache: Option<&std::path::Path>,
    out_dir: &std::path::Path,
    tag: &str,
    extra: &[&str],
    save_on_pocl: bool,
) -> (serde_json::Value, Vec<u8>) {
    let (ply, json) = (
        out_dir.join(format!("{tag}.ply")),
        out_dir.join(format!("{tag}.json")),
    );
    let mut cmd = cli();
    cmd.args([
        "curvature",
        "--generate",
        "sphere",
        "--resolution",
        "800",
        "--accumulate",
        "gather",
        "-o",
    ])
    .arg(&ply)
    .arg("--stats")
    .arg(&json)
    .args(extra);
    match cache {
        Some(dir) => cmd
            .env("SHAPECUE_CACHE_DIR", dir)
            .env("SHAPECUE_CACHE_POCL", if save_on_pocl { "1" } else { "0" })
            .env_remove("SHAPECUE_NO_CACHE"),
        None => cmd.env("SHAPECUE_NO_CACHE", "1"),
    };
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{tag}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stats = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    (stats, std::fs::read(&ply).unwrap())
}

fn cache_outcome(stats: &serde_json::Value) -> String {
    let p = stats["programs"].as_array().expect("stats list programs");
    assert_eq!(p.len(), 1, "{stats}");
    p[0]["cache"].as_str().unwrap().to_string()
}

fn cache_entries(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    v.sort();
    v
}

fn clbin_entries(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    cache_entries(dir)
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "clbin"))
        .collect()
}

/// The program-binary cache: a miss builds from source and saves one entry,
/// the next process builds from it; a corrupt or truncated entry is
/// detected, rebuilt from source and rewritten, never an error; the output
/// is the same bytes every time; `SHAPECUE_NO_CACHE=1` turns it off.
#[test]
fn program_cache_hits_and_survives_corrupt_and_truncated_files() {
    let d = scratch("progcache");
    let cache = d.join("cache");
    // The first build from source saves the binary (on PoCL only with
    // SHAPECUE_CACHE_POCL=1, which `curvature_cached` sets).
    let (s, reference) = curvature_cached(Some(&cache), &d, "first", &[]);
    assert_eq!(cache_outcome(&s), "miss");
    assert_eq!(s["programs"][0]["saved"], true, "{s}");
    let entries = cache_entries(&cache);
    assert_eq!(entries.len(), 1, "{entries:?}");
    assert!(entries[0].extension().is_some_and(|e| e == "clbin"));
    let (s, ply) = curvature_cached(Some(&cache), &d, "hit", &[]);
    assert_eq!(cache_outcome(&s), "hit");
    assert_eq!(s["programs"][0]["saved"], false);
    assert_eq!(ply, reference, "output from the cached binary differs");

    let good = std::fs::read(&entries[0]).unwrap();
    // One flipped byte in the driver's binary: the checksum catches it.
    let mut bad = good.clone();
    let mid = bad.len() / 2;
    bad[mid] ^= 0x5a;
    std::fs::write(&entries[0], &bad).unwrap();
    let (s, ply) = curvature_cached(Some(&cache), &d, "corrupt", &[]);
    let why = cache_outcome(&s);
    assert!(
        why.starts_with("rejected") && why.contains("checksum"),
        "{why}"
    );
    assert_eq!(ply, reference);
    assert_eq!(
        cache_outcome(&curvature_cached(Some(&cache), &d, "rewritten", &[]).0),
        "hit"
    );

    // Cut short (a crash mid-write of a cache that did not write atomically).
    std::fs::write(&entries[0], &good[..good.len() / 3]).unwrap();
    let (s, ply) = curvature_cached(Some(&cache), &d, "truncated", &[]);
    let why = cache_outcome(&s);
    assert!(
        why.starts_with("rejected") && why.contains("truncated"),
        "{why}"
    );
    assert_eq!(ply, reference);
    // Shorter than the header, and not a cache file at all.
    let junk = [
        &b"SCCL"[..],
        &b"not a cache file, but long enough to hold a header"[..],
    ];
    for (i, junk) in junk.into_iter().enumerate() {
        std::fs::write(&entries[0], junk).unwrap();
        let (s, ply) = curvature_cached(Some(&cache), &d, &format!("junk{i}"), &[]);
        assert!(cache_outcome(&s).starts_with("rejected"), "{s}");
        assert_eq!(ply, reference);
    }
    assert_eq!(
        cache_outcome(&curvature_cached(Some(&cache), &d, "again", &[]).0),
        "hit"
    );
    assert_eq!(
        cache_entries(&cache).len(),
        1,
        "one entry, no temporary files"
    );

    let (s, ply) = curvature_cached(None, &d, "off", &[]);
    assert_eq!(cache_outcome(&s), "off");
    assert_eq!(ply, reference);

    // A cache folder that cannot be created (a file is in the way): built
    // from source, no error.
    let blocked = d.join("a-file");
    std::fs::write(&blocked, b"x").unwrap();
    let (s, ply) = curvature_cached(Some(&blocked.join("cache")), &d, "blocked", &[]);
    assert!(cache_outcome(&s).starts_with("rejected") || cache_outcome(&s) == "miss");
    assert_eq!(ply, reference);
}

/// `shapecue build-kernels` saves the gather program on every runtime
/// (PoCL included, where an ordinary run does not save), says so, and finds
/// it built the second time; a `curvature` process then loads it from the
/// cache and writes the same bytes as one with the cache off. With the
/// cache off it is an error that says why.
#[test]
fn build_kernels_fills_the_cache_that_curvature_then_loads() {
    let d = scratch("build-kernels");
    let cache = d.join("cache");
    let build = |cache_env: Option<&std::path::Path>| {
        let mut cmd = cli();
        cmd.args(["build-kernels", "--accumulate", "gather"])
            .env_remove("SHAPECUE_CACHE_POCL");
        match cache_env {
            Some(dir) => cmd
                .env("SHAPECUE_CACHE_DIR", dir)
                .env_remove("SHAPECUE_NO_CACHE"),
            None => cmd.env("SHAPECUE_NO_CACHE", "1"),
        };
        cmd.output().unwrap()
    };
    let (_, reference) = curvature_cached(None, &d, "reference", &[]);
    // An ordinary run on an empty cache saves nothing on PoCL; elsewhere
    // it saves, and build-kernels then finds the program built.
    let (s, ply) = curvature_cached_saving(Some(&cache), &d, "plain", &[], false);
    assert_eq!(ply, reference);
    let pocl = s["device"]["platform"]
        .as_str()
        .is_some_and(|p| p.contains("Portable Computing Language"));
    if pocl {
        assert_eq!(cache_outcome(&s), "miss");
        assert_eq!(s["programs"][0]["saved"], false, "{s}");
        assert!(clbin_entries(&cache).is_empty());
    }
    let _ = std::fs::remove_dir_all(&cache);

    let out = build(Some(&cache));
    common::assert_succeeded(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("gather f32 exact") && text.contains("saved in"),
        "{text}"
    );
    assert_eq!(clbin_entries(&cache).len(), 1, "{text}");
    let out = build(Some(&cache));
    common::assert_succeeded(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("already built"), "{text}");
    assert_eq!(clbin_entries(&cache).len(), 1);

    let (s, ply) = curvature_cached_saving(Some(&cache), &d, "after", &[], false);
    assert_eq!(cache_outcome(&s), "hit", "{s}");
    assert_eq!(ply, reference, "output from the built kernels differs");

    let out = build(None);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("kernel cache is off"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

/// Processes started together on an empty cache all succeed with the same
/// output, and leave one valid entry that the next process uses.
#[test]
fn concurrent_processes_share_the_program_cache() {
    let d = scratch("progcache-race");
    let cache = d.join("cache");
    let (_, reference) = curvature_cached(None, &d, "reference", &[]);
    let plys: Vec<Vec<u8>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|i| {
                let (cache, d) = (&cache, &d);
                s.spawn(move || curvature_cached(Some(cache), d, &format!("racer{i}"), &[]).1)
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for p in &plys {
        assert_eq!(p, &reference);
    }
    // Each racer saw no entry and saved the same bytes (renamed into place).
    // Within two more processes the entry is there, one file, no leftovers.
    let mut outcomes = Vec::new();
    for i in 0..3 {
        let (s, ply) = curvature_cached(Some(&cache), &d, &format!("after{i}"), &[]);
        assert_eq!(ply, reference);
        outcomes.push(cache_outcome(&s));
        if outcomes.last().is_some_and(|o| o == "hit") {
            break;
        }
    }
    assert_eq!(
        outcomes.last().map(String::as_str),
        Some("hit"),
        "{outcomes:?}"
    );
    let entries = cache_entries(&cache);
    assert_eq!(entries.len(), 1, "{entries:?}");
    assert_eq!(clbin_entries(&cache), entries);
}

/// `--runs N`: the output is written once and is the same as without it;
/// the stats give the count, kernel and wall medians and one median per
/// pass, in the order of `passes`; `--runs 0` is refused.
#[test]
fn curvature_runs_times_the_device_passes() {
    let d = scratch("runs");
    let (plain, reference) = curvature_cached(None, &d, "plain", &[]);
    for key in ["phases_ms", "command_ms", "programs"] {
        assert!(plain.get(key).is_some(), "stats lack {key}: {plain}");
    }
    for phase in [
        "load",
        "device",
        "program_prepare",
        "device_wait",
        "program_build",
        "topology",
        "normalise",
        "upload",
        "first_run",
        "read_back",
        "cache_write",
        "ply_write",
    ] {
        assert!(
            plain["phases_ms"][phase].as_f64().is_some_and(|v| v >= 0.0),
            "phase {phase}: {plain}"
        );
    }
    assert!(plain.get("kernel_median_ms").is_none());
    let (s, ply) = curvature_cached(None, &d, "runs", &["--runs", "3"]);
    assert_eq!(ply, reference, "--runs changed the output");
    assert_eq!(s["runs"], 3);
    for key in [
        "kernel_median_ms",
        "wall_median_ms",
        "kernel_min_ms",
        "wall_min_ms",
    ] {
        assert!(s[key].as_f64().is_some_and(|v| v > 0.0), "{key}: {s}");
    }
    assert!(s["kernel_min_ms"].as_f64() <= s["kernel_median_ms"].as_f64());
    let names = |k: &str| -> Vec<String> {
        s[k].as_array()
            .unwrap()
            .iter()
            .map(|p| p["pass"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(names("passes_median"), names("passes"));
    let out = run_cli(["curvature", "--generate", "sphere", "--runs", "0"]);
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("--runs") && e.contains("1..="), "{e}");
    // The CPU reference times its runs too.
    let (s, _) = curvature_cached(None, &d, "cpu", &["--cpu", "--runs", "2"]);
    assert_eq!(s["runs"], 2);
    assert!(s["wall_median_ms"].as_f64().is_some_and(|v| v > 0.0), "{s}");
}

/// Faults: a write that fails midway (a full disk, simulated with a file
/// size limit, so the write fails with an OS error after the file was
/// opened), a device output, an output whose folder cannot exist, and a
/// device too small for the mesh (`SHAPECUE_DEVICE_MEMORY`): each a clear
/// error naming the file or the bytes, and nothing left behind.
#[test]
fn full_disks_bad_folders_and_small_devices_give_clear_errors_and_leave_nothing() {
    let d = scratch("faults");
    let exe = env!("CARGO_BIN_EXE_shapecue");
    // 16 KiB per file: the PLY of a 10,242-vertex sphere is ~1 MB. The CPU
    // reference computes it, because the limit binds every file the process
    // writes, and PoCL writes the kernel source (~56 KB) to its cache folder
    // when it builds the program, warm cache or not; the PLY writer is the
    // same for both.
    let ply = d.join("o.ply");
    let out = std::process::Command::new("bash")
        .arg("-c")
        .arg(format!(
            "ulimit -f 16; trap '' XFSZ; exec '{exe}' curvature --cpu --generate sphere \
             --resolution 20000 -o '{}'",
            ply.display()
        ))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("o.ply") && err.contains("cannot write"),
        "{err}"
    );
    let left: Vec<_> = std::fs::read_dir(&d).unwrap().collect();
    assert!(left.is_empty(), "nothing left behind: {left:?}");

    let r = run_cli(["curvature", "--generate", "sphere", "-o", "/dev/full"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(
        err.contains("/dev/full") && err.contains("not a regular file"),
        "{err}"
    );

    let blocker = d.join("a-file");
    std::fs::write(&blocker, "mine").unwrap();
    let inside = blocker.join("o.ply");
    let r = run_cli([
        "curvature",
        "--generate",
        "sphere",
        "-o",
        inside.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(
        err.contains("a-file") && err.contains("not a folder"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&blocker).unwrap(), "mine");

    let small = cli()
        .env("SHAPECUE_DEVICE_MEMORY", "1M")
        .args([
            "curvature",
            "--generate",
            "sphere",
            "--resolution",
            "100000",
            "-o",
        ])
        .arg(&ply)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&small.stderr);
    assert!(!small.status.success());
    assert!(
        err.contains("bytes") && err.contains("1048576") && err.contains("SHAPECUE_DEVICE_MEMORY"),
        "{err}"
    );
    assert!(!ply.exists());
    let bad = cli()
        .env("SHAPECUE_DEVICE_MEMORY", "lots")
        .args(["curvature", "--generate", "sphere", "-o"])
        .arg(&ply)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && err.contains("SHAPECUE_DEVICE_MEMORY"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// The device is opened, and the curvature program built, beside the mesh's
/// load: a device that does not exist is still a clear error naming it,
/// with no output written, and an input that cannot be read is reported
/// first, as it was when the device was opened after the load.
#[test]
fn curvature_device_errors_beside_the_load() {
    let d = scratch("device-beside-load");
    let out = d.join("out.ply");
    let o = run_cli([
        "--device".as_ref(),
        "no-such-device".as_ref(),
        "curvature".as_ref(),
        "--generate".as_ref(),
        "sphere".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("'no-such-device'"),
        "{err}"
    );
    assert!(!out.exists(), "nothing written");
    let o = run_cli([
        "--device".as_ref(),
        "no-such-device".as_ref(),
        "curvature".as_ref(),
        d.join("missing.obj").as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("missing.obj") && !err.contains("no-such-device"),
        "{err}"
    );
    assert!(!out.exists(), "nothing written");
}
