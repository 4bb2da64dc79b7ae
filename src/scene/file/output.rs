//! `[output]` checked: where the images go, their size, formats, MSAA,
//! background and the feature edges' interop mode. Errors without a key of their own name the `[output]` line.

use super::raw::OutputSpec;
use super::{Checker, Table, color};
use crate::error::{Error, Result};
use crate::spec::interop::InteropMode;
use crate::spec::visibility::VisibilityMethod;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// `[output]`, resolved.
pub(super) struct OutputPart {
    /// Output folder.
    pub out_dir: PathBuf,
    /// File prefix.
    pub prefix: String,
    /// Image size.
    pub size: [u32; 2],
    /// Write PNG images.
    pub png: bool,
    /// Write SVG line drawings.
    pub svg: bool,
    /// Write the line pieces as NPZ.
    pub npz: bool,
    /// MSAA samples.
    pub msaa: u32,
    /// Background.
    pub background: [f32; 3],
    /// How the edges frame's buffers reach GL.
    pub interop: InteropMode,
    /// How an SVG's hidden lines are found.
    pub visibility: VisibilityMethod,
}

/// Checks `[output]` (absent: the defaults) of the scene called `name`.
pub(super) fn resolve(
    ck: &Checker<'_>,
    output: Option<Spanned<OutputSpec>>,
    name: &str,
) -> Result<OutputPart> {
    let (out, span) = match output {
        Some(o) => {
            let s = o.span();
            (o.into_inner(), s)
        }
        None => (OutputSpec::default(), 0..0),
    };
    let t = Table { ck, span };
    let size = t.size(&out)?;
    let msaa = out.msaa.unwrap_or(4);
    if ![0, 2, 4, 8].contains(&msaa) {
        return Err(t.err(format!("output.msaa {msaa} must be 0, 2, 4 or 8")));
    }
    let [png, svg, npz] = t.formats(&out)?;
    let background =
        color(out.background, [1.0, 1.0, 1.0], "output.background").map_err(|p| t.err(p))?;
    let interop = match &out.interop {
        None => InteropMode::Off,
        Some(m) => (m.get_ref().parse())
            .map_err(|e: Error| ck.err(m.span(), format!("output.interop: {e}")))?,
    };
    let visibility = match &out.visibility {
        None => VisibilityMethod::Exact,
        Some(m) => (m.get_ref().parse())
            .map_err(|e: Error| ck.err(m.span(), format!("output.visibility: {e}")))?,
    };
    let prefix = out.name.clone().unwrap_or_else(|| name.to_string());
    if prefix.is_empty() || prefix.contains(['/', '\\']) {
        return Err(t.err(format!(
            "output.name {prefix:?} must be a non-empty file name prefix"
        )));
    }
    Ok(OutputPart {
        out_dir: out
            .dir
            .map(PathBuf::from)
            .unwrap_or_else(|| Path::new("out").join(name)),
        prefix,
        size,
        png,
        svg,
        npz,
        msaa,
        background,
        interop,
        visibility,
    })
}

impl Table<'_> {
    /// `size`, within the image size limits.
    fn size(&self, out: &OutputSpec) -> Result<[u32; 2]> {
        let size = out.size.unwrap_or([640, 480]);
        if let Err(err) = crate::spec::limits::check_image_size("output.size", size[0], size[1]) {
            let msg = err.to_string();
            return Err(self.err(
                msg.strip_prefix("invalid argument: ")
                    .unwrap_or(&msg)
                    .to_string(),
            ));
        }
        Ok(size)
    }

    /// `formats`: whether to write PNG, SVG and NPZ (default: PNG only).
    fn formats(&self, out: &OutputSpec) -> Result<[bool; 3]> {
        let Some(f) = &out.formats else {
            return Ok([true, false, false]);
        };
        let mut on = [false; 3];
        for x in f.get_ref() {
            match x.as_str() {
                "png" => on[0] = true,
                "svg" => on[1] = true,
                "npz" => on[2] = true,
                other => {
                    return Err(self.ck.err(
                        f.span(),
                        format!("output format {other:?}: expected png, svg or npz"),
                    ));
                }
            }
        }
        if on == [false; 3] {
            return Err(self.ck.err(f.span(), "output.formats is empty"));
        }
        Ok(on)
    }
}
