//! Every `shapecue` example in README.md and in `docs/*.md` runs as written,
//! from a folder laid out like the repository root (the bundled `data/` and
//! `scenes/`), with the built binary first on `PATH`: a user who copies a line
//! gets exit status 0 and the files the line names. Left out: usage synopses
//! (lines with `MESH` or `[--option]` placeholders), `shapecue report`, whose
//! tables take minutes (its topics are tested on tiny sizes in
//! `tests/cli_report.rs`), and `shapecue view` without `--script` (a window
//! that waits for its user). An example that needs a downloaded data set (its
//! line names `../shared/data`, or the scene file it names does) is skipped
//! with a message when the data set is absent, as on a fresh clone.
//! `shapecue view` examples run under Xvfb (`xvfb-run`), and are skipped with
//! a message where it is absent (unless `SHAPECUE_REQUIRE_GL` is set).

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

/// The downloaded data a line needs that is absent: the `../shared/data`
/// paths the line names (relative to the repository root) and those named by
/// the scene files it runs (relative to the scene file), with the data set
/// looked for where the tests look for it.
fn missing_downloads(root: &Path, line: &str) -> Vec<String> {
    let mut missing = Vec::new();
    let shared_absent = !common::shared_data().exists() || !Path::new(SHARED_DATA).exists();
    for word in line.split_whitespace() {
        if word.contains("../shared/data") && (shared_absent || !root.join(word).exists()) {
            missing.push(word.to_string());
        }
        if !word.ends_with(".toml") {
            continue;
        }
        let scene = root.join(word);
        let Ok(text) = std::fs::read_to_string(&scene) else {
            continue;
        };
        for quoted in text.split('"').skip(1).step_by(2) {
            if quoted.contains("shared/data") {
                let p = scene.parent().unwrap().join(quoted);
                if shared_absent || !p.exists() {
                    missing.push(format!("{word} needs {quoted}"));
                }
            }
        }
    }
    missing
}

/// The examples of README.md and of every `docs/*.md` page, each with the
/// page it comes from.
fn all_examples(root: &Path) -> Vec<(String, String)> {
    let mut pages = vec![root.join("README.md")];
    let mut docs: Vec<_> = std::fs::read_dir(root.join("docs"))
        .map(|rd| {
            rd.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "md"))
                .collect()
        })
        .unwrap_or_default();
    docs.sort();
    pages.extend(docs);
    let mut out = Vec::new();
    for page in pages {
        let text = std::fs::read_to_string(&page).unwrap();
        let name = page.strip_prefix(root).unwrap().display().to_string();
        out.extend(examples(&text).into_iter().map(|l| (name.clone(), l)));
    }
    out
}

#[test]
fn every_example_runs_as_written() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let all = all_examples(root);
    assert!(all.len() >= 15, "{all:?}");
    let run: Vec<&(String, String)> = all
        .iter()
        .filter(|(_, l)| {
            // a window without --script waits for its user: not run here
            let interactive = l.starts_with("shapecue view") && !l.contains("--script");
            !(l.contains("MESH")
                || l.contains("[--")
                || l.starts_with("shapecue report")
                || interactive)
        })
        .collect();
    // One folder per page, laid out as the repository root: each page's
    // examples run in order, as a reader of that page would run them.
    let mut folders = std::collections::HashMap::new();
    let mut folder = |page: &str| -> std::path::PathBuf {
        folders
            .entry(page.to_string())
            .or_insert_with(|| {
                let d = scratch("readme");
                for sub in ["data", "scenes"] {
                    std::os::unix::fs::symlink(root.join(sub), d.join(sub)).unwrap();
                }
                d
            })
            .to_path_buf()
    };
    let bin = Path::new(env!("CARGO_BIN_EXE_shapecue")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut skipped = 0;
    for (page, line) in run {
        let missing = missing_downloads(root, line);
        if !missing.is_empty() {
            eprintln!(
                "skipping ({page}: needs downloaded data, absent: {}): {line}",
                missing.join(", ")
            );
            skipped += 1;
            continue;
        }
        let d = folder(page);
        // `shapecue view` opens a window: it runs under Xvfb, and is skipped
        // (with a message) where xvfb-run is absent, unless GL is required.
        let mut cmd = std::process::Command::new("bash");
        if line.starts_with("shapecue view") {
            let xvfb = std::process::Command::new("sh")
                .args(["-c", "command -v xvfb-run"])
                .output()
                .is_ok_and(|o| o.status.success());
            if !xvfb {
                assert!(!common::gl_required(), "{page}: {line} needs xvfb-run");
                eprintln!("skipping ({page}: needs xvfb-run): {line}");
                skipped += 1;
                continue;
            }
            cmd = std::process::Command::new("xvfb-run");
            cmd.args(["-a", "-s", "-screen 0 1280x1024x24", "bash"]);
        }
        let out = cmd
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
            "{page} example failed: {line}\n{}",
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
    eprintln!("{skipped} example(s) skipped (absent downloaded data, or no xvfb-run)");
    for d in folders.values() {
        let _ = std::fs::remove_dir_all(d);
    }
}

/// Every scene under `scenes/` runs on bundled data, or says at its top that
/// it needs a download and names it.
#[test]
fn every_scene_is_bundled_or_names_its_download() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut n = 0;
    for e in std::fs::read_dir(root.join("scenes")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        n += 1;
        let text = std::fs::read_to_string(&p).unwrap();
        let needs_shared = text
            .lines()
            .filter(|l| !l.trim_start().starts_with('#'))
            .any(|l| l.contains("shared/data"));
        if needs_shared {
            assert!(
                text.starts_with("# Needs a download:"),
                "{}: names ../shared/data but does not open with \"# Needs a download:\"",
                p.display()
            );
        } else {
            // Every quoted path it names that looks like a file is in the repository.
            for quoted in text.split('"').skip(1).step_by(2) {
                if quoted.starts_with("../") {
                    assert!(
                        p.parent().unwrap().join(quoted).exists(),
                        "{}: {quoted} is not in the repository",
                        p.display()
                    );
                }
            }
        }
    }
    assert!(n >= 5, "scenes/ has {n} scenes");
}
