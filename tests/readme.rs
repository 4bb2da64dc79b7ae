//! Every `shapecue` example in README.md runs as written, from a folder laid
//! out like the repository root (the bundled `data/` and `scenes/`), with the
//! built binary first on `PATH`: a user who copies a line from the README
//! gets exit status 0 and the files the line names. Left out: usage synopses
//! (lines with `MESH` or `[--option]` placeholders) and the `--report`
//! tables, which take minutes (the main job prints them).

mod common;

use common::{SHARED_DATA, scratch};
use std::path::Path;

/// The shell lines of the README's code blocks, backslash continuations joined.
fn examples(readme: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_code = false;
    let mut pending = String::new();
    for line in readme.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
            pending.clear();
            continue;
        }
        if !in_code {
            continue;
        }
        let joined = format!("{pending}{line}");
        if let Some(head) = joined.strip_suffix('\\') {
            pending = format!("{head} ");
            continue;
        }
        pending.clear();
        let t = joined.trim().to_string();
        if t.starts_with("shapecue ") {
            out.push(t);
        }
    }
    out
}

#[test]
fn every_readme_example_runs_as_written() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let all = examples(&readme);
    assert!(all.len() >= 15, "{all:?}");
    let run: Vec<&String> = all
        .iter()
        .filter(|l| !(l.contains("MESH") || l.contains("[--") || l.contains("--report")))
        .collect();
    let d = scratch("readme");
    for sub in ["data", "scenes"] {
        std::os::unix::fs::symlink(root.join(sub), d.join(sub)).unwrap();
    }
    let bin = Path::new(env!("CARGO_BIN_EXE_shapecue")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let shared = Path::new(SHARED_DATA).exists();
    for line in run {
        if line.contains("../shared") && !shared {
            eprintln!("skipping (no ../shared/data): {line}");
            continue;
        }
        let out = std::process::Command::new("bash")
            .arg("-c")
            .arg(line)
            .current_dir(&d)
            .env("PATH", &path)
            // `shapecue build-kernels` and the programs' saves go here, not
            // into the user's kernel cache.
            .env("SHAPECUE_CACHE_DIR", d.join("kernel-cache"))
            .output()
            .unwrap();
        if common::cli_gl_missing(&out) {
            continue;
        }
        assert!(
            out.status.success(),
            "README example failed: {line}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        // The files it names with -o / --svg / --stats / --geometry exist.
        let words: Vec<&str> = line.split_whitespace().collect();
        for w in words.windows(2) {
            if ["-o", "--svg", "--stats", "--geometry"].contains(&w[0]) {
                assert!(d.join(w[1]).exists(), "{line}: {} was not written", w[1]);
            }
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}
