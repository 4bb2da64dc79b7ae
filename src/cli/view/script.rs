//! `shapecue view --script FILE`: camera moves, cue switches, slider sets,
//! frame steps and screenshots, one command a line (`#` starts a comment).
//! The whole file is read and checked before the window opens; the window
//! closes after the last command. See docs/viewer.md for the commands.

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// One script command.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// Turn the eye about the target (degrees: yaw about up, pitch towards it).
    Orbit(f32, f32),
    /// Move across the view (fractions of the view height).
    Pan(f32, f32),
    /// Distance to the target times this factor.
    Zoom(f32),
    /// Back to the scene's view.
    Reset,
    /// A cue on, off, or toggled (`None`).
    Cue(String, Option<bool>),
    /// A slider or choice.
    Set(String, String),
    /// Frame position: absolute, or a step.
    Frame(FrameMove),
    /// Wait for the frame of the current state.
    Wait,
    /// Save the current frame as PNG.
    Screenshot(PathBuf),
    /// Save the lines of the current frame as SVG.
    Svg(PathBuf),
    /// Print the passes that ran for the current frame.
    Passes,
    /// Save the whole window (controls and frame) as PNG.
    Capture(PathBuf),
}

/// A frame move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrameMove {
    /// The frame at this position of the scene's frames.
    To(usize),
    /// This many frames on (negative: back).
    By(i64),
}

/// A script: its commands with their line numbers.
pub struct Script {
    pub path: PathBuf,
    pub commands: Vec<(usize, Command)>,
}

impl Command {
    /// Whether the command needs the frame of the state before it runs.
    pub fn needs_frame(&self) -> bool {
        matches!(
            self,
            Command::Wait
                | Command::Screenshot(_)
                | Command::Svg(_)
                | Command::Passes
                | Command::Capture(_)
        )
    }
}

fn num<T: std::str::FromStr>(word: Option<&str>, what: &str) -> Result<T> {
    let w = word.with_context(|| format!("missing {what}"))?;
    w.parse()
        .map_err(|_| anyhow::anyhow!("{what} {w} is not a number"))
}

fn finite(v: f32, what: &str) -> Result<f32> {
    if !v.is_finite() {
        bail!("{what} must be finite");
    }
    Ok(v)
}

/// A file name of a writing command, whose extension must say what is
/// written (any case): PNG for `screenshot` and `capture`, SVG for `svg`.
fn named(p: PathBuf, cmd: &str, ext: &str) -> Result<PathBuf> {
    if !crate::cli::has_extension(&p, ext) {
        bail!(
            "{cmd} {}: it writes {}; give a name ending in .{ext}",
            p.display(),
            ext.to_ascii_uppercase()
        );
    }
    Ok(p)
}

/// Parses one line (without its comment); `None` for an empty line.
fn parse_line(line: &str, base: &Path) -> Result<Option<Command>> {
    let mut w = line.split_whitespace();
    let Some(cmd) = w.next() else {
        return Ok(None);
    };
    let path = |w: Option<&str>| -> Result<PathBuf> {
        let p = w.context("missing file name")?;
        Ok(base.join(p))
    };
    let c = match cmd {
        "orbit" => Command::Orbit(
            finite(num(w.next(), "yaw")?, "yaw")?,
            finite(num(w.next(), "pitch")?, "pitch")?,
        ),
        "pan" => Command::Pan(
            finite(num(w.next(), "dx")?, "dx")?,
            finite(num(w.next(), "dy")?, "dy")?,
        ),
        "zoom" => {
            let f: f32 = num(w.next(), "factor")?;
            if !(f > 0.0 && f.is_finite()) {
                bail!("zoom factor {f} must be > 0");
            }
            Command::Zoom(f)
        }
        "reset" => Command::Reset,
        "cue" => {
            let name = w.next().context("missing cue name")?.to_string();
            let on = match w.next() {
                Some("on") => Some(true),
                Some("off") => Some(false),
                Some("toggle") | None => None,
                Some(o) => bail!("cue {name} {o}: expected on, off or toggle"),
            };
            Command::Cue(name, on)
        }
        "set" => {
            let k = w.next().context("missing slider name")?.to_string();
            let v = w.next().context("missing value")?.to_string();
            Command::Set(k, v)
        }
        "frame" => Command::Frame(match w.next() {
            Some("next") => FrameMove::By(1),
            Some("prev") => FrameMove::By(-1),
            Some(s) if s.starts_with('+') || s.starts_with('-') => {
                FrameMove::By(num(Some(s.trim_start_matches('+')), "frame step")?)
            }
            s => FrameMove::To(num(s, "frame")?),
        }),
        "wait" => Command::Wait,
        "screenshot" => Command::Screenshot(named(path(w.next())?, "screenshot", "png")?),
        "svg" => Command::Svg(named(path(w.next())?, "svg", "svg")?),
        "passes" => Command::Passes,
        "capture" => Command::Capture(named(path(w.next())?, "capture", "png")?),
        other => bail!(
            "unknown command {other} (orbit, pan, zoom, reset, cue, set, frame, wait, \
             screenshot, svg, passes, capture)"
        ),
    };
    if let Some(extra) = w.next() {
        bail!("unexpected {extra} after the command");
    }
    Ok(Some(c))
}

impl Script {
    /// The files the script writes, with the command of each (`screenshot`,
    /// `svg`, `capture`), in script order.
    pub fn outputs(&self) -> Vec<(usize, &'static str, &Path)> {
        self.commands
            .iter()
            .filter_map(|(line, c)| match c {
                Command::Screenshot(p) => Some((*line, "screenshot", p.as_path())),
                Command::Svg(p) => Some((*line, "svg", p.as_path())),
                Command::Capture(p) => Some((*line, "capture", p.as_path())),
                _ => None,
            })
            .collect()
    }

    /// Reads and checks a script; file names in it are relative to the
    /// current folder.
    pub fn load(path: &Path) -> Result<Script> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read the script {}", path.display()))?;
        let mut commands = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("");
            if let Some(c) = parse_line(line, Path::new(""))
                .with_context(|| format!("{} line {}", path.display(), i + 1))?
            {
                commands.push((i + 1, c));
            }
        }
        Ok(Script {
            path: path.to_path_buf(),
            commands,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The script grammar fuzzed as the loaders are (fuzz/): lines made of
    /// the grammar's own words, numbers at the edges of f32, file names and
    /// stray bytes, from a fixed generator. No line panics; what parses
    /// holds only finite, valid values; every refusal is a message in words
    /// that the script loader prefixes with the file and line.
    #[test]
    fn the_grammar_survives_generated_lines() {
        const WORDS: [&str; 40] = [
            "orbit",
            "pan",
            "zoom",
            "reset",
            "cue",
            "set",
            "frame",
            "wait",
            "screenshot",
            "svg",
            "passes",
            "capture",
            "on",
            "off",
            "toggle",
            "next",
            "prev",
            "+3",
            "-2",
            "1e30",
            "-1e-30",
            "nan",
            "inf",
            "-inf",
            "0",
            "-0",
            "3.5",
            "a.png",
            "b.SVG",
            "c",
            "#",
            "\u{0}",
            "é",
            "99999999999999999999",
            "contours",
            "iso",
            "0x10",
            "1_000",
            "../x.png",
            "\t",
        ];
        let mut q: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = |n: usize| {
            q ^= q << 13;
            q ^= q >> 7;
            q ^= q << 17;
            (q % n as u64) as usize
        };
        let dir = std::env::temp_dir().join(format!("shapecue-script-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for case in 0..20_000 {
            let line: String = if case % 5 == 4 {
                let bytes: Vec<u8> = (0..next(24)).map(|_| next(256) as u8).collect();
                String::from_utf8_lossy(&bytes).into_owned()
            } else {
                (0..1 + next(5))
                    .map(|_| WORDS[next(WORDS.len())])
                    .collect::<Vec<_>>()
                    .join(if next(3) == 0 { "  " } else { " " })
            };
            match parse_line(&line, Path::new("")) {
                Ok(Some(Command::Zoom(f))) => assert!(f > 0.0 && f.is_finite(), "{line:?}"),
                Ok(Some(Command::Orbit(a, b) | Command::Pan(a, b))) => {
                    assert!(a.is_finite() && b.is_finite(), "{line:?}")
                }
                Ok(Some(Command::Screenshot(p) | Command::Capture(p))) => {
                    assert!(p.to_string_lossy().to_ascii_lowercase().ends_with(".png"))
                }
                Ok(Some(Command::Svg(p))) => {
                    assert!(p.to_string_lossy().to_ascii_lowercase().ends_with(".svg"))
                }
                Ok(_) => {}
                Err(e) => {
                    let m = e.to_string();
                    assert!(
                        !m.is_empty() && !m.contains("Err(") && !m.contains("Some("),
                        "{m}"
                    );
                }
            }
            if case % 1000 == 0 {
                // Whole files: an error names the script and the line.
                let f = dir.join("s.txt");
                std::fs::write(&f, format!("reset\n{line}\nwait\n")).unwrap();
                if let Err(e) = Script::load(&f) {
                    let m = format!("{e:#}");
                    assert!(m.contains("s.txt line 2"), "{m}");
                }
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn parses_every_command() {
        let p = |s: &str| parse_line(s, Path::new("")).unwrap().unwrap();
        assert_eq!(p("orbit 30 -10"), Command::Orbit(30.0, -10.0));
        assert_eq!(
            p("cue contours off"),
            Command::Cue("contours".into(), Some(false))
        );
        assert_eq!(p("frame +2"), Command::Frame(FrameMove::By(2)));
        assert_eq!(p("frame 3"), Command::Frame(FrameMove::To(3)));
        assert_eq!(p("screenshot a.png"), Command::Screenshot("a.png".into()));
        assert!(parse_line("zoom 0", Path::new("")).is_err());
        assert!(parse_line("orbit 1", Path::new("")).is_err());
        assert!(parse_line("fly 1 2", Path::new("")).is_err());
        assert!(parse_line("reset now", Path::new("")).is_err());
        assert_eq!(parse_line("   ", Path::new("")).unwrap(), None);
        // The extension says what is written, in any case.
        assert_eq!(p("screenshot A.PNG"), Command::Screenshot("A.PNG".into()));
        assert_eq!(p("svg lines.Svg"), Command::Svg("lines.Svg".into()));
        for bad in [
            "screenshot out.jpg",
            "screenshot in.obj",
            "svg a.png",
            "capture w",
            "capture w.svg",
        ] {
            let e = parse_line(bad, Path::new("")).unwrap_err().to_string();
            assert!(e.contains("give a name ending in"), "{bad}: {e}");
        }
    }
}
