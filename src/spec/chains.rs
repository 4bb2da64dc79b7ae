//! Chains of the `visibility` family: the visible (or hidden) pieces of a
//! view's line segments joined into the longest polylines across faces, as
//! Blender's Line Art chains its lines. A host step after the device's
//! classification (joining is a walk over a few thousand pieces; no kernel).
//!
//! Pieces meet where they share an end key ([`EndKey`]): the mesh edge a
//! line crosses (the same key in the two faces beside it, however the two
//! crossings round), the mesh vertex a feature edge ends at, or for an end
//! inside a face (a line's own test cut it, or an intersection line) its
//! position on a grid of about a millionth of the scene's size. An end where visibility changes inside a segment is a cut
//! ([`EndKey::Cut`]) that no other piece shares: a chain ends there.
//!
//! The walk: the pieces are first put in a canonical order (by layer, then
//! keys), so the chains do not depend on the input order; chains start at
//! ends not shared by exactly two pieces of their layer and visibility,
//! then closed loops remain. At a branch (three or more pieces at one end,
//! as at a corner of feature edges) a chain goes on along the first unused
//! piece in canonical order and the others start chains of their own.

use crate::spec::feature_lines::{LINE_FREE, Segment};
use crate::spec::visibility::Pieces;

/// How a piece's end is matched with others'.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum EndKey {
    /// On a mesh edge (its two vertices, smaller first).
    Edge(u32, u32),
    /// At a mesh vertex.
    Vertex(u32),
    /// Inside a face, by position ([`point_key`]).
    Point([i64; 3]),
    /// Where a segment's visibility changes (segment, bits of `t`): shared
    /// by no other piece.
    Cut(u32, u32),
}

impl EndKey {
    /// A code equal for equal keys, cheap to sort: exact for an edge, a
    /// vertex and a cut; a position's by a 64-bit hash (two positions share
    /// one with a chance of about 2⁻⁶⁴).
    pub fn code(self) -> u128 {
        let (tag, payload): (u128, u128) = match self {
            EndKey::Edge(u, v) => (0, (u128::from(u) << 32) | u128::from(v)),
            EndKey::Vertex(v) => (1, u128::from(v)),
            EndKey::Cut(s, t) => (2, (u128::from(s) << 32) | u128::from(t)),
            EndKey::Point(p) => {
                // SplitMix64 steps over the three coordinates.
                let mix = |mut z: u64| {
                    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
                    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
                    z ^ (z >> 31)
                };
                let h = p.iter().fold(0x9e37_79b9_7f4a_7c15u64, |h, &c| {
                    mix(h ^ (c as u64).wrapping_add(0x9e37_79b9_7f4a_7c15))
                });
                (3, u128::from(h))
            }
        };
        (tag << 120) | payload
    }
}

/// The key of an end inside a face: each coordinate rounded to a grid of
/// `scale × 2⁻²⁰` (`scale` the scene's size), so that ends computed apart
/// from the same point (f32 rounding, about `scale × 2⁻²⁴`) meet, unless
/// they straddle a grid line.
pub fn point_key(p: [f32; 3], scale: f32) -> EndKey {
    let step = (f64::from(scale.abs().max(f32::MIN_POSITIVE))) * 2f64.powi(-20);
    EndKey::Point(p.map(|c| (f64::from(c) / step).round() as i64))
}

/// The key of segment `s`'s own end `e` (0: `s.0`, 1: `s.1`): the mesh
/// edge or vertex it lies on, or for an end inside a face its
/// [`point_key`] at the scene size `scale`.
pub fn end_key(s: &Segment, e: usize, scale: f32) -> EndKey {
    let [u, v] = s.ends[e];
    let p = if e == 0 { s.a } else { s.b };
    if u == LINE_FREE || u == u32::MAX {
        point_key(p, scale)
    } else if u == v {
        EndKey::Vertex(u)
    } else {
        EndKey::Edge(u.min(v), u.max(v))
    }
}

/// The pieces to chain of `segments` split into `pieces` (per segment, its
/// `(t0, t1, visible)` parts): an end at the segment's own end takes its
/// [`end_key`], an end inside the segment (where its visibility changes)
/// a [`EndKey::Cut`].
pub fn chain_pieces(segments: &[Segment], pieces: &[Pieces], scale: f32) -> Vec<ChainPiece> {
    let mut out = Vec::new();
    for (i, (s, ps)) in segments.iter().zip(pieces).enumerate() {
        let key = |t: f32, e: usize| {
            if t == [0.0, 1.0][e] {
                end_key(s, e, scale)
            } else {
                EndKey::Cut(i as u32, t.to_bits())
            }
        };
        for &(t0, t1, visible) in ps {
            out.push(ChainPiece {
                layer: s.family,
                visible,
                seg: i as u32,
                t: [t0, t1],
                keys: [key(t0, 0), key(t1, 1)],
            });
        }
    }
    out
}

/// A piece to chain: part `[t0, t1]` of segment `seg`, in `layer` (a
/// family, or the feature edges), visible or hidden, with its end keys.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChainPiece {
    /// The layer it is drawn in; only pieces of one layer and visibility join.
    pub layer: u32,
    /// Visible or hidden.
    pub visible: bool,
    /// The segment it is part of.
    pub seg: u32,
    /// Its part of the segment.
    pub t: [f32; 2],
    /// Its end keys (at `t0` and at `t1`).
    pub keys: [EndKey; 2],
}

/// A chain: pieces in walking order, each with whether it is walked from
/// `t1` to `t0`.
#[derive(Clone, Debug, PartialEq)]
pub struct Chain {
    /// The layer of its pieces.
    pub layer: u32,
    /// Visible or hidden.
    pub visible: bool,
    /// Indices into the pieces given to [`chain`], and reversed flags.
    pub pieces: Vec<(u32, bool)>,
}

/// The ends of the pieces grouped by where they meet: groups in the order
/// of (layer and visibility, key's code), each group's members `(piece,
/// end)` in the pieces' canonical order (then first end first).
struct Ends {
    /// The members of every group, group after group.
    members: Vec<(u32, u8)>,
    /// The group of each piece's end (`2 × piece + end`).
    group_of: Vec<u32>,
    /// Each group's first index into `members`, and one past the last group.
    start: Vec<u32>,
}

impl Ends {
    /// The groups of the ends of `pieces` (no members yet: see
    /// [`Ends::fill`]). One sort of packed 128-bit keys: the layer and
    /// visibility's dense rank, the code's tag and 64-bit payload
    /// ([`EndKey::code`]), and the end's index.
    fn group(pieces: &[ChainPiece]) -> Ends {
        // The few layer-and-visibility values, each once, in order.
        let mut lv: Vec<u64> = Vec::new();
        for p in pieces {
            let x = layer_vis(p);
            if lv.last() != Some(&x) && !lv.contains(&x) {
                lv.push(x);
            }
        }
        lv.sort_unstable();
        let lv_rank = |p: &ChainPiece| lv.binary_search(&layer_vis(p)).unwrap_or(0) as u128;
        let keys: Vec<u128> = (pieces.iter().enumerate())
            .flat_map(|(i, p)| {
                let r = lv_rank(p);
                (0..2).map(move |e| {
                    let c = p.keys[e].code();
                    let (tag, payload) = (c >> 120, c & u128::from(u64::MAX));
                    (r << 98) | (tag << 96) | (payload << 32) | (2 * i + e) as u128
                })
            })
            .collect();
        let keys = sort_on_cores(keys);
        let mut group_of = vec![0u32; keys.len()];
        let mut start = Vec::new();
        for (k, x) in keys.iter().enumerate() {
            if k == 0 || keys[k - 1] >> 32 != x >> 32 {
                start.push(k as u32);
            }
            group_of[(x & 0xffff_ffff) as usize] = (start.len() - 1) as u32;
        }
        start.push(keys.len() as u32);
        Ends {
            members: Vec::new(),
            group_of,
            start,
        }
    }

    /// Puts the ends into their groups, pieces in `order` (then first end
    /// first).
    fn fill(&mut self, order: &[u32]) {
        let mut next = self.start.clone();
        self.members = vec![(0, 0); self.group_of.len()];
        for &i in order {
            for e in 0..2u8 {
                let g = self.group_of[2 * i as usize + e as usize] as usize;
                self.members[next[g] as usize] = (i, e);
                next[g] += 1;
            }
        }
    }

    /// The members of the group of piece `i`'s end `e`: `(piece, end)`.
    fn at(&self, i: u32, e: usize) -> impl Iterator<Item = (u32, usize)> + '_ {
        let g = self.group_of[2 * i as usize + e] as usize;
        let (a, b) = (self.start[g] as usize, self.start[g + 1] as usize);
        self.members[a..b].iter().map(|x| (x.0, x.1 as usize))
    }

    fn degree(&self, i: u32, e: usize) -> usize {
        let g = self.group_of[2 * i as usize + e] as usize;
        (self.start[g + 1] - self.start[g]) as usize
    }
}

/// A piece's layer and visibility in one sort key.
fn layer_vis(p: &ChainPiece) -> u64 {
    (u64::from(p.layer) << 1) | u64::from(p.visible)
}

/// Joins `pieces` into chains (see the module note). Every piece is in
/// exactly one chain.
///
/// The canonical order is (layer and visibility, the lesser end key's
/// code, the greater's, segment, `t0`); the groups' ranks stand for the
/// first three (a group's rank follows its layer, visibility and code), so
/// it is one sort of 128-bit keys.
pub fn chain(pieces: &[ChainPiece]) -> Vec<Chain> {
    let mut ends = Ends::group(pieces);
    let keyed: Vec<(u128, u32)> = (pieces.iter().enumerate())
        .map(|(i, p)| {
            let g = |e: usize| u128::from(ends.group_of[2 * i + e]);
            let (a, b) = (g(0), g(1));
            let key = (a.min(b) << 96)
                | (a.max(b) << 64)
                | (u128::from(p.seg) << 32)
                | u128::from(p.t[0].to_bits());
            (key, i as u32)
        })
        .collect();
    let keyed = sort_on_cores(keyed);
    let order: Vec<u32> = keyed.into_iter().map(|k| k.1).collect();
    ends.fill(&order);
    let mut used = vec![false; pieces.len()];
    let mut out = Vec::new();
    for &i in &order {
        for end in 0..2 {
            if !used[i as usize] && ends.degree(i, end) != 2 {
                out.push(walk(pieces, &ends, &mut used, i, end));
            }
        }
    }
    for &i in &order {
        if !used[i as usize] {
            out.push(walk(pieces, &ends, &mut used, i, 0));
        }
    }
    out
}

/// The chain from piece `first`, leaving it by the end opposite `from`.
fn walk(pieces: &[ChainPiece], ends: &Ends, used: &mut [bool], first: u32, from: usize) -> Chain {
    let p = &pieces[first as usize];
    used[first as usize] = true;
    let mut c = Chain {
        layer: p.layer,
        visible: p.visible,
        pieces: vec![(first, from == 1)],
    };
    let (mut at, mut tip) = (first, 1 - from);
    loop {
        // The first unused piece at the tip, entered at its matching end
        // (the first, for a loop of one piece).
        let next = ends.at(at, tip).find(|&(j, _)| !used[j as usize]);
        let Some((j, entered)) = next else { break };
        used[j as usize] = true;
        c.pieces.push((j, entered == 1));
        (at, tip) = (j, 1 - entered);
    }
    c
}

/// Keys per thread below which [`sort_on_cores`] sorts on one thread.
const KEYS_PER_THREAD: usize = 32768;

/// `keys` sorted: in runs on the machine's cores, then merged. Equal keys
/// are the same bits, so the result is the one sorted order, whatever the
/// number of runs.
fn sort_on_cores<T: Ord + Copy + Send>(mut keys: Vec<T>) -> Vec<T> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = (keys.len() / KEYS_PER_THREAD).clamp(1, cores.min(8));
    sort_in_runs(&mut keys, threads)
}

/// [`sort_on_cores`] in `threads` runs.
fn sort_in_runs<T: Ord + Copy + Send>(keys: &mut Vec<T>, threads: usize) -> Vec<T> {
    if threads <= 1 || keys.len() < 2 {
        keys.sort_unstable();
        return std::mem::take(keys);
    }
    let chunk = keys.len().div_ceil(threads);
    std::thread::scope(|scope| {
        for run in keys.chunks_mut(chunk) {
            scope.spawn(move || run.sort_unstable());
        }
    });
    let mut runs: Vec<Vec<T>> = keys.chunks(chunk).map(<[T]>::to_vec).collect();
    while runs.len() > 1 {
        let mut next = Vec::with_capacity(runs.len().div_ceil(2));
        let mut it = runs.into_iter();
        while let Some(a) = it.next() {
            next.push(match it.next() {
                Some(b) => merge(&a, &b),
                None => a,
            });
        }
        runs = next;
    }
    runs.pop().unwrap_or_default()
}

/// Two sorted runs merged into one.
fn merge<T: Ord + Copy>(a: &[T], b: &[T]) -> Vec<T> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if b[j] < a[i] {
            out.push(b[j]);
            j += 1;
        } else {
            out.push(a[i]);
            i += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

/// Mean pieces per chain (0 for none).
pub fn mean_length<'a>(chains: impl IntoIterator<Item = &'a Chain>) -> f64 {
    let (n, pieces) =
        (chains.into_iter()).fold((0usize, 0usize), |(n, p), c| (n + 1, p + c.pieces.len()));
    if n == 0 {
        0.0
    } else {
        pieces as f64 / n as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_sorted_in_runs_are_sorted_whatever_the_runs() {
        // A scrambled sequence with repeats.
        let keys: Vec<u128> = (0..100_003u128)
            .map(|i| (i * 7_919 + 13) % 65_537)
            .collect();
        let mut want = keys.clone();
        want.sort_unstable();
        for threads in [1, 2, 3, 5, 8] {
            assert_eq!(sort_in_runs(&mut keys.clone(), threads), want, "{threads}");
        }
        assert!(sort_in_runs(&mut Vec::<u128>::new(), 4).is_empty());
    }

    fn piece(seg: u32, a: EndKey, b: EndKey) -> ChainPiece {
        ChainPiece {
            layer: 0,
            visible: true,
            seg,
            t: [0.0, 1.0],
            keys: [a, b],
        }
    }

    #[test]
    fn pieces_sharing_mesh_edges_form_one_chain_whatever_their_order() {
        let e = EndKey::Edge;
        let ps = vec![
            piece(0, e(2, 3), e(1, 2)),
            piece(1, e(0, 1), e(1, 2)),
            piece(2, e(2, 3), e(3, 4)),
        ];
        let c = chain(&ps);
        assert_eq!(c.len(), 1, "{c:?}");
        assert_eq!(c[0].pieces.len(), 3);
        let mut rev = ps.clone();
        rev.reverse();
        let c2 = chain(&rev);
        assert_eq!(c2.len(), 1);
        // Same segments in the same walking order.
        let segs = |c: &Chain, ps: &[ChainPiece]| -> Vec<u32> {
            c.pieces.iter().map(|&(i, _)| ps[i as usize].seg).collect()
        };
        assert_eq!(segs(&c[0], &ps), segs(&c2[0], &rev));
        assert_eq!(mean_length(&c), 3.0);
    }

    #[test]
    fn cuts_layers_and_visibility_end_chains() {
        let e = EndKey::Edge;
        let mut hidden = piece(1, e(1, 2), EndKey::Cut(1, 0));
        hidden.visible = false;
        let mut other_layer = piece(2, e(1, 2), e(5, 6));
        other_layer.layer = 1;
        let ps = vec![piece(0, e(0, 1), e(1, 2)), hidden, other_layer];
        let c = chain(&ps);
        assert_eq!(c.len(), 3, "{c:?}");
        assert!(c.iter().all(|c| c.pieces.len() == 1));
    }

    #[test]
    fn a_loop_is_one_chain_and_a_branch_starts_another() {
        let v = EndKey::Vertex;
        let square = vec![
            piece(0, v(0), v(1)),
            piece(1, v(1), v(2)),
            piece(2, v(2), v(3)),
            piece(3, v(3), v(0)),
        ];
        let c = chain(&square);
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].pieces.len(), 4);
        let y = vec![
            piece(0, v(0), v(9)),
            piece(1, v(9), v(1)),
            piece(2, v(9), v(2)),
        ];
        let c = chain(&y);
        assert_eq!(c.len(), 2, "{c:?}");
        assert_eq!(c.iter().map(|c| c.pieces.len()).sum::<usize>(), 3);
    }

    #[test]
    fn walking_order_reverses_pieces_entered_at_their_second_end() {
        let v = EndKey::Vertex;
        let ps = vec![piece(0, v(0), v(1)), piece(1, v(2), v(1))];
        let c = chain(&ps);
        assert_eq!(c.len(), 1);
        // From the free end of one piece, through vertex 1, into the other
        // piece at its second end.
        let flags: Vec<bool> = c[0].pieces.iter().map(|p| p.1).collect();
        assert_eq!(flags.iter().filter(|&&r| r).count(), 1, "{c:?}");
    }

    #[test]
    fn point_keys_meet_for_nearly_equal_points_only() {
        let a = point_key([1.0, 2.0, 3.0], 8.0);
        let b = point_key([1.0 + 1e-7, 2.0, 3.0 - 1e-7], 8.0);
        let far = point_key([1.001, 2.0, 3.0], 8.0);
        assert_eq!(a, b);
        assert_ne!(a, far);
    }
}
