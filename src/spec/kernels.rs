//! Kernel identity, typed: each kernel family names the entry points of its
//! kernel file once, in an enum declared with [`kernel_entries!`] beside the
//! family's other spec types (`spec::ao::AoKernel`, ...). The host wiring
//! creates kernels from those enums (`Gpu::entry`), never from strings, and
//! the timing steps ([`super::timing::Step::kernel`]) name theirs through
//! them, so a renamed entry point is one edit.

/// An entry point of a kernel file.
pub trait KernelEntry: Copy + std::fmt::Debug {
    /// The entry point's name in the kernel file (`<prefix>_<step>`).
    fn entry(self) -> &'static str;
}

/// Declares a family's kernel enum: one variant per entry point, each with
/// the entry point's name, and [`KernelEntry`] for it; `ALL` lists them.
macro_rules! kernel_entries {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident {
            $( $(#[$vmeta:meta])* $variant:ident = $entry:literal ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        $vis enum $name {
            $( $(#[$vmeta])* $variant ),+
        }

        impl $name {
            /// Every entry point of the family, in the kernel file's order.
            pub const ALL: &'static [$name] = &[$($name::$variant),+];

            /// The entry point's name (as [`crate::spec::kernels::KernelEntry::entry`], usable in `const`).
            pub const fn name(self) -> &'static str {
                match self {
                    $($name::$variant => $entry),+
                }
            }
        }

        impl $crate::spec::kernels::KernelEntry for $name {
            fn entry(self) -> &'static str {
                self.name()
            }
        }
    };
}
pub(crate) use kernel_entries;
