//! The format dispatcher: [`load`] picks the reader by the file's extension
//! (or reads headerless samples by a [`RawSpec`]).

use std::path::{Path, PathBuf};

use super::format::{READ, RawSpec};
use super::{Volume, mhd, nrrd, raw, slc, vtk};
use crate::error::{Error, Result};

/// File extensions [`load`] recognises, for messages.
const EXTENSIONS: &str = ".raw (with its dimensions and voxel type given), .nrrd, .nhdr, .mhd, .mha, .vtk, .vti and .slc";

/// Loads a volume. With `raw` given, the file is read as headerless samples
/// whatever its extension; otherwise the format follows the extension
/// (case-insensitive): `.nrrd`/`.nhdr` (NRRD), `.mhd`/`.mha` (MetaImage),
/// `.vtk` (legacy `STRUCTURED_POINTS`), `.vti` (XML ImageData), `.slc`.
///
/// # Errors
///
/// [`Error::Io`] when the file or a data file it names cannot be read,
/// [`Error::UnsupportedFormat`] for an unknown extension, a `.raw` file
/// without `raw`, or a feature shapecue does not read (named in the message),
/// and [`Error::InvalidInput`] for malformed headers and data whose size does
/// not match the header ("expected N bytes (X×Y×Z × T bytes), found M").
pub fn load(path: &Path, raw: Option<&RawSpec>) -> Result<Volume> {
    if let Some(spec) = raw {
        return raw::load(path, spec);
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("nrrd" | "nhdr") => nrrd::load(path),
        Some("mhd" | "mha") => mhd::load(path),
        Some("vtk") => vtk::load_legacy(path),
        Some("vti") => vtk::load_xml(path),
        Some("slc") => slc::load(path),
        Some("raw") => Err(Error::UnsupportedFormat {
            path: path.to_path_buf(),
            problem: "a .raw file has no header: give its dimensions and voxel type \
                      (on the command line --dims and --type), or convert it to NRRD or \
                      MetaImage with a header"
                .into(),
        }),
        Some(other) => Err(Error::UnsupportedFormat {
            path: path.to_path_buf(),
            problem: format!("unknown extension '.{other}' (shapecue reads {EXTENSIONS})"),
        }),
        None if path.is_dir() => Err(Error::UnsupportedFormat {
            path: path.to_path_buf(),
            problem: format!("a folder, not a volume file (shapecue reads {EXTENSIONS})"),
        }),
        None => Err(Error::UnsupportedFormat {
            path: path.to_path_buf(),
            problem: format!("no file extension (shapecue reads {EXTENSIONS})"),
        }),
    }
}

/// [`load`], also returning every file it read: the header and, for NRRD
/// and MetaImage, each detached data file (so that a caller can refuse to
/// write over any of them).
///
/// # Errors
/// As [`load`].
pub fn load_with_files(path: &Path, raw: Option<&RawSpec>) -> Result<(Volume, Vec<PathBuf>)> {
    READ.with(|r| *r.borrow_mut() = Some(Vec::new()));
    let result = load(path, raw);
    let files = READ.with(|r| r.borrow_mut().take()).unwrap_or_default();
    Ok((result?, files))
}
