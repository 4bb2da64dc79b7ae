//! Lines that hold still on animations: the hysteresis option of the line
//! families over an animation's frames ([`Coherence`]). The kernels' side
//! is in `kernels/common/isoline.h` (held faces test a family against a
//! fraction of its threshold), the twins' in `cpu::feature_lines::Hold`.

/// Whether the line families of an animation hold still from frame to
/// frame: hysteresis over its frames (two thresholds, as Canny's edge
/// detector), each view of the sequence keeping the faces that drew each
/// thresholded family in its previous frame (suggestive contours, ridges,
/// valleys, apparent ridges, principal and suggestive highlights), which
/// test it against [`Coherence::DEFAULT_LOW`] of its threshold. The first
/// frame of a sequence is drawn as without it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Coherence {
    /// On for an animation (more than one frame), off for one pose.
    #[default]
    Auto,
    /// On wherever more than one frame runs.
    On,
    /// Off: every frame's lines found on their own.
    Off,
}

impl Coherence {
    /// Every choice, in `--help` order.
    pub const ALL: [Coherence; 3] = [Coherence::Auto, Coherence::On, Coherence::Off];

    /// The fraction of a family's threshold that a face holding the family
    /// from the previous frame tests against (Canny's lower threshold).
    pub const DEFAULT_LOW: f32 = 0.5;

    /// The frames a line found away from every line of its family waits
    /// before it is drawn (0, 1 or 2).
    pub const DEFAULT_BIRTH: u32 = 1;

    /// The band of the Schmitt trigger on the signs of K and H, in units
    /// of the feature size s: |K| < band / s² and |H| < band / s keep the
    /// sign of the previous frame.
    pub const DEFAULT_BAND: f32 = 0.1;

    /// The name on the command line, in scene files and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Coherence::Auto => "auto",
            Coherence::On => "on",
            Coherence::Off => "off",
        }
    }

    /// Whether a run of `frames` frames holds its lines.
    pub fn holds(self, frames: usize) -> bool {
        match self {
            Coherence::Off => false,
            Coherence::Auto | Coherence::On => frames > 1,
        }
    }
}

crate::spec::named_choice!(Coherence, "coherence");

/// The family bit added to a segment found but not drawn (its birth
/// delayed, `LINE_UNBORN` of kernels/common/isoline.h); the line stage
/// drops such segments.
pub const LINE_UNBORN: u32 = 0x100;

/// The families whose births are never delayed: contours (which must
/// follow their motion without lag), isophotes and boundaries
/// (`LINE_UNGATED` of kernels/common/isoline.h).
pub const LINE_UNGATED: u32 = (1 << 0) | (1 << 7) | (1 << 11);
