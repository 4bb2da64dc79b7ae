//! The spec layer: types that the host wiring (`stages`), the CPU twins
//! (`cpu`), the planner and the file formats share, in the role
//! `vello_encoding` plays for vello. Per stage family: constants, option
//! enums, output types, `#[repr(C)]` parameter structs mirrored in
//! `kernels/<family>.cl`, and the `*_bound` functions that size every
//! variable output.
//!
//! This module imports nothing from `gpu`, `stages`, `cpu`, `render` or
//! `scene` (CI checks it), so a CPU twin or the planner can use it without
//! the device.

pub mod ao;
pub mod bvh;
pub mod cameras;
pub mod chains;
pub mod coherence;
pub mod curvature;
pub mod edges;
pub mod feature_lines;
pub mod interop;
pub mod intersections;
pub mod kernels;
pub mod limits;
pub mod marching_cubes;
pub mod mesh_sdf;
pub mod radix_sort;
pub mod scan;
pub mod sdf_lines;
pub mod skinning;
mod step_entries;
pub mod timing;
pub mod vertex_fusion;
pub mod view;
pub mod visibility;
pub mod visibility_plan;

/// An option enum named by words (`atomic`, `gather`, ...): every choice and
/// its name, the same on the command line, in scene files and in stats.
/// The command line builds its parsers from this (the library knows no
/// command-line parser).
pub trait Choice: Copy + PartialEq + Send + Sync + 'static {
    /// Every choice, in the order `--help` lists them.
    fn all() -> &'static [Self];
    /// The choice's name.
    fn label(self) -> &'static str;
}

/// [`Choice`] for an option enum with an `ALL` array of its variants and a
/// `name()`; for one whose parsing is its own (case-insensitive, or with its
/// own message), beside its `FromStr`.
macro_rules! choice {
    ($t:ty) => {
        impl $crate::spec::Choice for $t {
            fn all() -> &'static [Self] {
                &<$t>::ALL
            }
            fn label(self) -> &'static str {
                <$t>::name(self)
            }
        }
    };
}
pub(crate) use choice;

/// [`Choice`], `Display` and `FromStr` by `name()` for an option enum with an
/// `ALL` array of its variants; `$what` names the option in the parse error.
macro_rules! named_choice {
    ($t:ty, $what:literal) => {
        $crate::spec::choice!($t);

        impl std::fmt::Display for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl std::str::FromStr for $t {
            type Err = $crate::error::Error;
            fn from_str(s: &str) -> std::result::Result<$t, $crate::error::Error> {
                <$t>::ALL
                    .into_iter()
                    .find(|v| v.name() == s)
                    .ok_or_else(|| {
                        let names: Vec<&str> = <$t>::ALL.iter().map(|v| v.name()).collect();
                        $crate::error::Error::InvalidArgument(format!(
                            "unknown {} {s:?}: expected {}",
                            $what,
                            names.join(", ")
                        ))
                    })
            }
        }
    };
}
pub(crate) use named_choice;
