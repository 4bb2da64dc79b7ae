//! The shared end samples of a plan: ends of one family at one point of
//! one mesh edge or vertex sample once ([`shared_ends`]), made in runs of
//! vertices on the machine's cores with the same result on any number.

use super::{EndPlan, SegPlan, norm, sub};
use crate::spec::feature_lines::{LINE_FREE, Segment};
use crate::spec::visibility::Faces;

/// The samples of one run of keyed ends (numbered from 0), and each end's
/// `(2 × segment + end, sample)`.
type RunSamples = (Vec<EndPlan>, Vec<(u32, u32)>);

/// The key of a segment's end `e` where other ends may meet it: its mesh
/// edge or vertex; `None` for an end inside a face.
fn end_key(s: &Segment, e: usize) -> Option<u64> {
    let [u, v] = s.ends[e];
    if u == LINE_FREE || u == u32::MAX {
        return None;
    }
    Some((u64::from(u.min(v)) << 32) | u64::from(u.max(v)))
}

/// A keyed end ([`end_key`]) with what its shared sample reads of it, so
/// that the samples are made from these in key order (no random reads of
/// the segments' plans).
#[derive(Clone, Copy, Default)]
struct KeyedEnd {
    key: u64,
    /// `2 × segment + end`.
    at: u32,
    /// The segment's family kind: ends of different families never meet.
    family: u32,
    p: [f32; 3],
    offset: f32,
    exclude: Faces,
}

/// The shared end samples of `segs` (setting each one's `end_ids`): ends
/// of one family at one point of one mesh edge or vertex (one key,
/// [`end_key`], and within `tol` of each other: the two faces of an edge
/// round its crossing apart) share one, in the order of the key, then of
/// the segment. Ends of other lines on the same edge (another family, or
/// another isophote level) keep their own, so that a line's visibility does
/// not depend on which other families are drawn. The keyed ends are put in
/// that order by a counting sort on the key's lesser vertex (`n_vertices`
/// of them, checked by the plan), then a sort of each vertex's few.
pub(super) fn shared_ends(
    segments: &[Segment],
    segs: &mut [SegPlan],
    n_vertices: usize,
    tol: f32,
    threads: usize,
) -> Vec<EndPlan> {
    let mut ends = Vec::new();
    let mut start = vec![0u32; n_vertices + 1];
    for (i, s) in segments.iter().enumerate() {
        for e in 0..2 {
            match end_key(s, e) {
                Some(k) => start[(k >> 32) as usize + 1] += 1,
                None => {
                    let sp = &mut segs[i];
                    sp.end_ids[e] = ends.len() as u32;
                    ends.push(EndPlan {
                        p: if e == 0 { sp.a } else { sp.b },
                        exclude: sp.exclude,
                        offset: sp.offset,
                    });
                }
            }
        }
    }
    for v in 0..n_vertices {
        start[v + 1] += start[v];
    }
    let mut keyed = vec![KeyedEnd::default(); start[n_vertices] as usize];
    let mut next = start.clone();
    for (i, (s, sp)) in segments.iter().zip(segs.iter()).enumerate() {
        for e in 0..2 {
            if let Some(key) = end_key(s, e) {
                let at = &mut next[(key >> 32) as usize];
                keyed[*at as usize] = KeyedEnd {
                    key,
                    at: (2 * i + e) as u32,
                    family: s.family,
                    p: if e == 0 { sp.a } else { sp.b },
                    offset: sp.offset,
                    exclude: sp.exclude,
                };
                *at += 1;
            }
        }
    }
    for v in 0..n_vertices {
        keyed[start[v] as usize..start[v + 1] as usize].sort_unstable_by_key(|x| (x.key, x.at));
    }
    // The groups in contiguous runs of vertices, on the machine's cores:
    // each run's samples numbered from 0, then placed after the runs
    // before it, so the samples and their order do not depend on the
    // number of runs.
    let runs = vertex_runs(&start, keyed.len(), threads);
    let parts: Vec<RunSamples> = if runs.len() <= 2 {
        vec![share_run(&keyed, tol)]
    } else {
        std::thread::scope(|scope| {
            let handles: Vec<_> = (runs.windows(2))
                .map(|w| {
                    let run = &keyed[w[0]..w[1]];
                    scope.spawn(move || share_run(run, tol))
                })
                .collect();
            (handles.into_iter())
                .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
                .collect()
        })
    };
    for (run_ends, ids) in parts {
        let base = ends.len() as u32;
        for (at, id) in ids {
            segs[(at / 2) as usize].end_ids[(at % 2) as usize] = base + id;
        }
        ends.extend(run_ends);
    }
    ends
}

/// Bounds of `threads` contiguous runs of the keyed ends (`len` of them,
/// bucketed by vertex at `start`): each run ends at a vertex's bucket
/// start, so that no key is split (fewer runs where buckets are large).
fn vertex_runs(start: &[u32], len: usize, threads: usize) -> Vec<usize> {
    let mut bounds = vec![0usize];
    for t in 1..threads {
        let target = (t * len / threads) as u32;
        let v = start.partition_point(|&s| s < target);
        let b = start.get(v).map_or(len, |&s| s as usize);
        if b > *bounds.last().unwrap_or(&0) && b < len {
            bounds.push(b);
        }
    }
    bounds.push(len);
    bounds
}

/// The shared samples of one run of keyed ends (whole groups of keys, in
/// order), numbered from 0, with each end's `(2 × segment + end, sample)`.
fn share_run(keyed: &[KeyedEnd], tol: f32) -> RunSamples {
    let mut ends = Vec::new();
    let mut ids = Vec::with_capacity(keyed.len());
    let mut point: Vec<KeyedEnd> = Vec::new();
    let mut taken: Vec<bool> = Vec::new();
    for group in keyed.chunk_by(|x, y| x.key == y.key) {
        // The ends of the key at one point of one family, in the order of
        // their first end.
        taken.clear();
        taken.resize(group.len(), false);
        for i in 0..group.len() {
            if taken[i] {
                continue;
            }
            point.clear();
            for j in i..group.len() {
                let (x, y) = (&group[i], &group[j]);
                if !taken[j] && x.family == y.family && dist(x.p, y.p) <= tol {
                    taken[j] = true;
                    point.push(*y);
                }
            }
            share_end(&point, &mut ids, &mut ends);
        }
    }
    (ends, ids)
}

/// The distance between two points.
fn dist(a: [f32; 3], b: [f32; 3]) -> f32 {
    norm(sub(a, b))
}

/// The end sample of one `group` of ends with one key (in order) into
/// `ends` (each end's `(2 × segment + end, sample)` into `ids`), or each
/// end's own where they lie on more than four faces.
fn share_end(group: &[KeyedEnd], ids: &mut Vec<(u32, u32)>, ends: &mut Vec<EndPlan>) {
    let mut set_id = |x: &KeyedEnd, id: usize| ids.push((x.at, id as u32));
    // The faces they lie on, up to five (five: more than a query leaves
    // out).
    let (mut faces, mut n) = ([0u32; 5], 0usize);
    'all: for x in group {
        for &f in x.exclude.iter() {
            if !faces[..n].contains(&f) {
                if n == 5 {
                    break 'all;
                }
                faces[n] = f;
                n += 1;
            }
        }
    }
    faces[..n].sort_unstable();
    if n > 4 {
        // More faces than a query leaves out (ends at a vertex of high
        // valence): each end keeps its own sample and faces.
        for x in group {
            set_id(x, ends.len());
            ends.push(EndPlan {
                p: x.p,
                exclude: x.exclude,
                offset: x.offset,
            });
        }
        return;
    }
    let bits = |x: [f32; 3]| x.map(f32::to_bits);
    let mut end = EndPlan {
        p: group[0].p,
        exclude: Faces::of(&faces[..n]),
        offset: 0.0,
    };
    for x in group {
        set_id(x, ends.len());
        if bits(x.p) < bits(end.p) {
            end.p = x.p;
        }
        end.offset = end.offset.max(x.offset);
    }
    ends.push(end);
}
