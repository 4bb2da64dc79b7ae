//! The commands of the `shapecue` binary, one module each, and what they
//! share: writing to standard output (a closed pipe ends the command
//! quietly), the outputs check, JSON stats, and the one error report.

pub mod alloc;
pub mod curvature;
pub mod devices;
pub mod edges;
pub mod isosurface;
pub mod kernels;
pub mod lines;
pub mod render;
pub mod report;
pub mod strokes;
pub mod view;

use anyhow::Result;
use std::io::Write;
use std::path::Path;

/// `println!` on a locked standard output that returns the I/O error (a
/// closed pipe: `shapecue … | head -1`) instead of panicking; [`fail`] turns
/// a broken pipe into a quiet exit with status 0.
macro_rules! out {
    ($($t:tt)*) => {
        $crate::cli::print(format_args!($($t)*))?
    };
}
pub(crate) use out;

/// Writes one line to standard output (see [`out!`]).
pub fn print(args: std::fmt::Arguments) -> std::io::Result<()> {
    let mut o = std::io::stdout().lock();
    o.write_fmt(args)?;
    o.write_all(b"\n")
}

/// Writes text as is to standard output (see [`out!`]).
pub fn print_str(s: &str) -> std::io::Result<()> {
    let mut o = std::io::stdout().lock();
    o.write_all(s.as_bytes())?;
    o.flush()
}

/// Checks a run's outputs against every file it reads and against each
/// other, before any work ([`shapecue::export::output::check_outputs`]:
/// inputs are compared by inode and are never overwritten, even with
/// `--force`).
pub fn check_outputs<'a>(
    inputs: impl IntoIterator<Item = &'a Path>,
    outputs: impl IntoIterator<Item = &'a Path>,
    force: bool,
) -> Result<()> {
    let inputs: Vec<&Path> = inputs.into_iter().collect();
    let outputs: Vec<&Path> = outputs.into_iter().collect();
    shapecue::export::output::check_outputs(&inputs, &outputs, force)?;
    Ok(())
}

/// Writes a stats document as pretty JSON (atomically) and says so.
pub fn write_json(path: &Path, value: &serde_json::Value) -> Result<()> {
    shapecue::export::output::write_bytes_atomic(
        path,
        (serde_json::to_string_pretty(value)? + "\n").as_bytes(),
    )?;
    out!("wrote {}", path.display());
    Ok(())
}

/// Reports a failed command once and returns its exit code: 0 for a closed
/// standard output (nothing is printed), else the message chain on stderr,
/// each cause printed only if the message before it does not already say it
/// (the library's I/O errors include the OS message), and the code the
/// library's error decides ([`shapecue::Error::exit_code`]: 3 for
/// `--interop on` without a shared route), 4 where `shapecue view` can open
/// no window ([`view::NoDisplay`]), 1 for everything else.
pub fn fail(e: &anyhow::Error) -> i32 {
    let broken_pipe = e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    });
    if broken_pipe {
        return 0;
    }
    let mut msg = String::new();
    let mut prev = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if prev.contains(&text) {
            continue;
        }
        if !msg.is_empty() {
            msg.push_str(": ");
        }
        msg.push_str(&text);
        prev = text;
    }
    eprintln!("error: {}", flag_words(&msg));
    if e.chain()
        .any(|c| c.downcast_ref::<view::NoDisplay>().is_some())
    {
        return view::NO_DISPLAY;
    }
    e.chain()
        .find_map(|c| c.downcast_ref::<shapecue::Error>())
        .map_or(1, shapecue::Error::exit_code)
}

/// The library's option words in a message as this command line's flags
/// (the library names options and values: `force = true`; `interop = on`
/// stays, since it may come from a scene file's `[output]` as well).
fn flag_words(msg: &str) -> String {
    const FLAGS: [(&str, &str); 2] = [
        ("pass force = true", "pass --force"),
        ("not even with force = true", "not even with --force"),
    ];
    FLAGS
        .iter()
        .fold(msg.to_string(), |m, (option, flag)| m.replace(option, flag))
}

/// Says on stderr when a PLY file's vertex properties had to be written as
/// double (a value outside float's range).
pub fn note_double(out: &Path, w: &shapecue::export::ply::PlyWritten) {
    if let Some(why) = &w.double {
        eprintln!(
            "note: {} has double-precision vertex properties: {why}",
            out.display()
        );
    }
}

/// Checks `--width` of drawn lines or edges (`what`: "line", "edge") in an
/// image of `size` pixels: positive, finite and at most the larger side.
pub fn width_arg(width: f32, size: (u32, u32), what: &str) -> anyhow::Result<()> {
    if !(width.is_finite() && width > 0.0) {
        anyhow::bail!("--width {width}: the {what} width must be a positive number of pixels");
    }
    let widest = size.0.max(size.1);
    if width > widest as f32 {
        let px = if widest == 1 { "pixel" } else { "pixels" };
        anyhow::bail!(
            "--width {width}: the {what} width must be at most the image's larger side \
             ({widest} {px})"
        );
    }
    Ok(())
}

/// A point or direction as clap gives it (`--eye 1,2,3`).
pub type Vec3Arg = Option<Vec<f32>>;

/// The camera of `--eye`, `--target`, `--up`, `--fov` and `--ortho` for a
/// `size` image (`lines` and `edges`); the fitted direction is the
/// library's default.
pub fn shot_arg(
    [eye, target, up]: [&Vec3Arg; 3],
    fov: f32,
    ortho: bool,
    size: [u32; 2],
) -> anyhow::Result<shapecue::Shot> {
    shapecue::api::check_fov(fov).map_err(|e| anyhow::anyhow!("--fov: {e}"))?;
    Ok(shapecue::Shot {
        eye: vec3_arg(eye, "eye")?,
        target: vec3_arg(target, "target")?,
        up: vec3_arg(up, "up")?,
        fov_deg: fov,
        ortho,
        size,
        ..Default::default()
    })
}

/// A point or direction given as `X,Y,Z` (`--eye`, `--target`, `--up`,
/// `--light`): three finite numbers, or an error naming the option and what
/// was given.
pub fn vec3_arg(v: &Option<Vec<f32>>, what: &str) -> anyhow::Result<Option<glam::Vec3>> {
    match v {
        None => Ok(None),
        Some(v) if v.len() == 3 && v.iter().all(|c| c.is_finite()) => {
            Ok(Some(glam::Vec3::new(v[0], v[1], v[2])))
        }
        Some(v) => anyhow::bail!(
            "--{what} needs three finite numbers X,Y,Z, got {}",
            v.iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(",")
        ),
    }
}

/// Parses `--size WIDTHxHEIGHT` within the shared image limits
/// ([`shapecue::spec::limits::check_image_size`]).
pub fn size_arg(s: &str) -> anyhow::Result<(u32, u32)> {
    let parsed = s
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse::<u32>().ok()?, h.trim().parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) => {
            shapecue::spec::limits::check_image_size("--size", w, h)?;
            Ok((w, h))
        }
        None => anyhow::bail!(
            "--size {s}: expected WIDTHxHEIGHT with both in 1..={}, e.g. 800x600",
            shapecue::spec::limits::MAX_IMAGE_SIDE
        ),
    }
}

/// The raw-data description that `--dims`, `--type`, `--big-endian`,
/// `--header-bytes` and `--spacing` give, if any (volume inputs).
pub fn raw_spec(
    dims: Option<&[usize]>,
    scalar: Option<&str>,
    big_endian: bool,
    header_bytes: usize,
    spacing: Option<&[f64]>,
) -> anyhow::Result<Option<shapecue::volume::RawSpec>> {
    use shapecue::volume::{RawSpec, ScalarType};
    Ok(match (dims, scalar) {
        (Some(d), Some(t)) => {
            if d.len() != 3 {
                anyhow::bail!("--dims needs three values X,Y,Z, got {}", d.len());
            }
            let scalar: ScalarType = t.parse()?;
            let mut spec = RawSpec::new([d[0], d[1], d[2]], scalar);
            spec.big_endian = big_endian;
            spec.header_bytes = header_bytes;
            if let Some(sp) = spacing {
                if sp.len() != 3 {
                    anyhow::bail!("--spacing needs three values, got {}", sp.len());
                }
                spec.spacing = [sp[0], sp[1], sp[2]];
            }
            Some(spec)
        }
        (None, None) => None,
        _ => anyhow::bail!("raw input needs both --dims and --type"),
    })
}

/// Whether a file name ends in `.ext`, in any case (`x.PNG` is a PNG name).
pub fn has_extension(path: &Path, ext: &str) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Whether a picture output is an SVG (`true`) or a PNG (`false`); any
/// other name is refused (a `.jpg` name would hold PNG bytes). `svg_is`
/// says what the SVG holds, for the message.
pub fn png_or_svg(option: &str, path: &Path, svg_is: &str) -> anyhow::Result<bool> {
    match (has_extension(path, "svg"), has_extension(path, "png")) {
        (true, _) => Ok(true),
        (_, true) => Ok(false),
        _ => anyhow::bail!(
            "{option} {}: give a name ending in .png (a picture) or .svg ({svg_is})",
            path.display()
        ),
    }
}

/// The command-line parser of a library option enum ([`shapecue::spec::Choice`]):
/// its names as clap's possible values, listed bare in `--help`.
pub fn choice<T: shapecue::spec::Choice>() -> impl clap::builder::TypedValueParser<Value = T> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(T::all().iter().map(|v| v.label())).map(|name| {
        *T::all()
            .iter()
            .find(|v| v.label() == name)
            .expect("clap accepts only the listed names")
    })
}
