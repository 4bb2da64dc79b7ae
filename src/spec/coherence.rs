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

/// Checks coherence's settings, naming the first one out of its range (as
/// a scene's `[lines]` names it): the lower threshold `low` a fraction in
/// (0, 1] of each threshold, the delay of births `birth` 0, 1 or 2 frames,
/// the band of the signs `band` finite and at least 0.
pub fn check(low: f32, birth: u32, band: f32) -> Result<(), String> {
    if !(low > 0.0 && low <= 1.0) {
        return Err(format!(
            "coherence_low {low} must be a fraction in (0, 1] of each threshold"
        ));
    }
    if birth > 2 {
        return Err(format!("coherence_birth {birth}: give 0, 1 or 2 frames"));
    }
    if !(band.is_finite() && band >= 0.0) {
        return Err(format!(
            "coherence_band {band} must be finite and at least 0"
        ));
    }
    Ok(())
}

/// The family bit added to a segment found but not drawn (its birth
/// delayed, `LINE_UNBORN` of kernels/common/isoline.h); the line stage
/// drops such segments.
pub const LINE_UNBORN: u32 = 0x100;

/// The families whose births are never delayed: contours (which must
/// follow their motion without lag), isophotes and boundaries
/// (`LINE_UNGATED` of kernels/common/isoline.h).
pub const LINE_UNGATED: u32 = (1 << 0) | (1 << 7) | (1 << 11);

/// Chains that keep their identity across the frames of an animation: each
/// frame's chains get ids, a chain taking the id of the previous frame's
/// chain that most of its length lies on (the same faces, the same family;
/// a face holding pieces of several chains counts for the one with most
/// length there) where that is at least half its length, and a new id
/// otherwise. Where two chains claim one id, the one with more length on it
/// keeps it. The first frame (or a frame that does not follow the last one)
/// numbers its chains 0, 1, 2, ... in order. Deterministic: the same chains
/// give the same ids.
#[derive(Clone, Debug, Default)]
pub struct ChainIds {
    /// The frame the ids are of.
    frame: Option<usize>,
    /// Per (face, family), the id of the last frame's chain with the most
    /// length on it, and that length.
    by_face: std::collections::HashMap<(i64, u32), (u32, f64)>,
    /// The next new id.
    next: u32,
}

/// One piece of a chain for [`ChainIds::assign`]: its chain (index), face
/// (`-1`: none), family and length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChainPiece {
    /// The chain's index in its frame.
    pub chain: u32,
    /// The face it lies in (`-1`: none).
    pub face: i64,
    /// Its family or layer code.
    pub family: u32,
    /// Its length.
    pub length: f64,
}

impl ChainIds {
    /// The ids of `chains` chains of `frame` (pieces: `pieces`, in any
    /// order), which follows `follows` in its sequence; one id per chain.
    pub fn assign(
        &mut self,
        frame: usize,
        follows: Option<usize>,
        chains: usize,
        pieces: &[ChainPiece],
    ) -> Vec<u32> {
        if follows.is_none() || self.frame != follows {
            self.by_face.clear();
            self.next = 0;
        }
        // Votes: (chain, previous id, length), summed per chain and id.
        let mut total = vec![0.0f64; chains];
        let mut votes: Vec<(u32, u32, f64)> = Vec::with_capacity(pieces.len());
        for p in pieces {
            total[p.chain as usize] += p.length;
            if let Some(&(id, _)) = self.by_face.get(&(p.face, p.family)) {
                votes.push((p.chain, id, p.length));
            }
        }
        votes.sort_unstable_by_key(|v| (v.0, v.1));
        let mut claims: Vec<(f64, u32, u32)> = Vec::new();
        for run in votes.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)) {
            let (c, id) = (run[0].0, run[0].1);
            let len: f64 = run.iter().map(|v| v.2).sum();
            if len > 0.0 && len >= 0.5 * total[c as usize] {
                claims.push((len, c, id));
            }
        }
        // The longest claims first; ties by chain, then id.
        claims.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut ids: Vec<Option<u32>> = vec![None; chains];
        let mut taken = std::collections::HashSet::new();
        for (_, c, id) in claims {
            if ids[c as usize].is_none() && taken.insert(id) {
                ids[c as usize] = Some(id);
            }
        }
        let ids: Vec<u32> = ids
            .into_iter()
            .map(|id| {
                id.unwrap_or_else(|| {
                    self.next += 1;
                    self.next - 1
                })
            })
            .collect();
        // Each (face, family)'s id: the chain with the most length there
        // (the smaller id on a tie).
        let mut here: Vec<((i64, u32), u32, f64)> = (pieces.iter())
            .map(|p| ((p.face, p.family), ids[p.chain as usize], p.length))
            .collect();
        here.sort_unstable_by_key(|h| (h.0, h.1));
        self.by_face.clear();
        for run in here.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)) {
            let len: f64 = run.iter().map(|h| h.2).sum();
            let e = self.by_face.entry(run[0].0).or_insert((run[0].1, len));
            if len > e.1 {
                *e = (run[0].1, len);
            }
        }
        self.frame = Some(frame);
        ids
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn piece(chain: u32, face: i64, length: f64) -> ChainPiece {
        ChainPiece {
            chain,
            face,
            family: 2,
            length,
        }
    }

    #[test]
    fn chains_keep_their_ids_while_most_of_them_persists() {
        let mut ids = ChainIds::default();
        // Frame 0: two chains on faces 1..4 and 10..13.
        let f0: Vec<ChainPiece> = (1..4)
            .map(|f| piece(0, f, 1.0))
            .chain((10..13).map(|f| piece(1, f, 1.0)))
            .collect();
        assert_eq!(ids.assign(0, None, 2, &f0), vec![0, 1]);
        // Frame 1: listed the other way round, the first one moved by a
        // face (2 of 3 faces kept), a new chain far away.
        let f1: Vec<ChainPiece> = (10..13)
            .map(|f| piece(0, f, 1.0))
            .chain((2..5).map(|f| piece(1, f, 1.0)))
            .chain((50..52).map(|f| piece(2, f, 1.0)))
            .collect();
        assert_eq!(ids.assign(1, Some(0), 3, &f1), vec![1, 0, 2]);
        // Frame 2: chain 1 (id 0) split in two halves: the longer half keeps
        // the id, the other gets a new one; a family change is a new chain.
        let mut f2: Vec<ChainPiece> = vec![piece(0, 2, 1.0), piece(0, 3, 1.0), piece(1, 4, 1.0)];
        f2.push(ChainPiece {
            family: 3,
            ..piece(2, 50, 1.0)
        });
        assert_eq!(ids.assign(2, Some(1), 3, &f2), vec![0, 3, 4]);
        // A frame that does not follow starts afresh.
        assert_eq!(ids.assign(9, Some(8), 3, &f2), vec![0, 1, 2]);
    }
}
