//! Host wiring of `kernels/marching_cubes_direct.cl` (Fusion direct, after
//! Flying Edges): count → one scan → triangles, with one host round trip
//! (the scan's partial totals, which size the outputs); where vertices land
//! on grid points also hits → (host sort) → recount → scan → points, the
//! twin check of the listed triangles, and vertex fusion's clean-up only if
//! it would change the mesh; where triangles were dropped, the check that
//! every vertex is still used (near them where they are few), and the
//! compaction of the used ones only if one is not. CPU twin:
//! [`crate::cpu::marching_cubes::mc_direct`].

use super::{Holder, IsoStats, Isosurfacer};
use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::marching_cubes::{McKernel, cell_rows, unused_check_near};
use crate::spec::timing::{Step, Timing};
use crate::stages::vertex_fusion::Grow;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use opencl3::program::Program;

/// The direct-numbering kernels and buffers.
pub(super) struct Direct {
    rows: Kernel,
    count: Kernel,
    hits: Kernel,
    triangles: Kernel,
    points: Kernel,
    recount: Kernel,
    unused_rows: Kernel,
    unused_clear: Kernel,
    unused_mark: Kernel,
    unused_count: Kernel,
    /// Per grid row counts (scanned in place), splits, trims.
    rowc: Buffer<u32>,
    info: Buffer<u32>,
    split: Buffer<u32>,
    trim: Buffer<u32>,
    hit_keys: Grow<u32>,
    /// Kept triangles per cell row where there are hits (scanned in place).
    tcount: Buffer<u32>,
    /// Triangles with a corner on a grid point: (face, a, b, c, in a grid plane).
    side: Grow<u32>,
    side_n: Buffer<u32>,
    /// Marks of the vertices near dropped triangles; the cell rows that
    /// dropped triangles (their count, the unused count, the rows).
    unused: Grow<u32>,
    unused_list: Grow<u32>,
    /// What the check for unused vertices needs of the last extraction
    /// (`None` when it dropped no triangle).
    pub(super) last_drops: Option<Drops>,
    /// The mesh: positions (3 floats per vertex, index space) and faces.
    pub(super) pos: Grow<f32>,
    pub(super) faces: Grow<u32>,
    /// The volume has NaN or infinite voxels (known at upload): direct
    /// numbering then removes the vertices of edges only skipped cells use.
    nonfinite: bool,
}

impl Direct {
    /// The kernels of program `p` (`kernels/marching_cubes_direct.cl`) and
    /// the buffers of a volume of `grid_rows` grid rows.
    pub(super) fn new(gpu: &Gpu, p: &Program, grid_rows: usize, nonfinite: bool) -> Result<Self> {
        Ok(Direct {
            rows: gpu.entry(p, McKernel::DirectRows)?,
            count: gpu.entry(p, McKernel::DirectCount)?,
            hits: gpu.entry(p, McKernel::DirectHits)?,
            triangles: gpu.entry(p, McKernel::DirectTriangles)?,
            points: gpu.entry(p, McKernel::DirectPoints)?,
            recount: gpu.entry(p, McKernel::DirectRecount)?,
            unused_rows: gpu.entry(p, McKernel::DirectUnusedRows)?,
            unused_clear: gpu.entry(p, McKernel::DirectUnusedClear)?,
            unused_mark: gpu.entry(p, McKernel::DirectUnusedMark)?,
            unused_count: gpu.entry(p, McKernel::DirectUnusedCount)?,
            rowc: gpu.buffer::<u32>(4 * grid_rows)?,
            info: gpu.buffer::<u32>(4 * grid_rows)?,
            split: gpu.buffer::<u32>(2 * grid_rows)?,
            trim: gpu.buffer::<u32>(3 * grid_rows)?,
            hit_keys: Grow::new(gpu)?,
            tcount: gpu.buffer::<u32>(grid_rows)?,
            side: Grow::new(gpu)?,
            side_n: gpu.buffer::<u32>(1)?,
            unused: Grow::new(gpu)?,
            unused_list: Grow::new(gpu)?,
            last_drops: None,
            pos: Grow::new(gpu)?,
            faces: Grow::new(gpu)?,
            nonfinite,
        })
    }

    /// Device bytes held now (`grid_rows` grid rows).
    pub(super) fn device_bytes(&self, grid_rows: u64) -> u64 {
        56 * grid_rows
            + self.side.bytes()
            + self.hit_keys.bytes()
            + self.unused.bytes()
            + self.unused_list.bytes()
            + self.pos.bytes()
            + self.faces.bytes()
    }
}

impl Isosurfacer {
    /// Direct numbering of `value = iso` (see the module's description).
    pub(super) fn extract_direct(&mut self, iso: f32, st: &mut IsoStats) -> Result<()> {
        let g = self.gpu.clone();
        let [nx, ny, nz] = self.dims;
        let voxels = nx * ny * nz;
        let gr = ny * nz;
        let d = &mut self.direct;
        let common = [
            Arg::U32(gr as u32),
            Arg::U32(nx as u32),
            Arg::U32(ny as u32),
            Arg::U32(nz as u32),
            buf(&self.vol),
            Arg::F32(iso),
        ];
        // The case table as the direct kernels take it: counts, tris, flat.
        let tables = [buf(&self.counts), buf(&self.tris), buf(&self.flat)];
        let e_rows = launch(
            &g,
            &d.rows,
            gr,
            &[
                Arg::U32(gr as u32),
                Arg::U32(nx as u32),
                buf(&self.vol),
                Arg::F32(iso),
                buf(&d.info),
            ],
        )?;
        let mut a = [&common[..], &tables[..]].concat();
        a.extend([buf(&d.info), buf(&d.rowc), buf(&d.split), buf(&d.trim)]);
        let e_count = launch(&g, &d.count, gr, &a)?;
        let (total, at) = self
            .scan
            .exclusive_at(&d.rowc, &d.rowc, 4 * gr, &[gr, 2 * gr, 3 * gr])
            .map_err(|e| match e {
                Error::InvalidInput { .. } => Error::InvalidArgument(format!(
                    "iso {iso}: the isosurface's vertices and triangles exceed the 32-bit \
                     indices of the device"
                )),
                e => e,
            })?;
        if let Some(e) = &e_rows {
            st.timing.add(Step::McDirectRows, event_ms(e));
        }
        if let Some(e) = &e_count {
            st.timing.add(Step::McDirectCount, event_ms(e));
        }
        st.timing.add(Step::ScanExclusive, self.scan.last_ms());
        let (v, t, h, twins) = (
            at[0] as usize,
            (at[1] - at[0]) as usize,
            (at[2] - at[1]) as usize,
            (total - at[2] as u64) as usize,
        );
        let slots = v + h;
        if 3 * slots as u64 > u32::MAX as u64 || 3 * t as u64 > u32::MAX as u64 {
            return Err(Error::InvalidArgument(format!(
                "iso {iso}: {slots} vertices and {t} triangles exceed the 32-bit indices of \
                 the device (at most {} of each)",
                u32::MAX / 3
            )));
        }
        let cleanup = h > 0 || d.nonfinite;
        let side_cap = side_records(h, t);
        // Twins alone (no hit, a finite volume) can still drop triangles and
        // leave a vertex unused, which takes the compaction's buffers too.
        let need = 4 * voxels as u64
            + crate::spec::vertex_fusion::direct_device_bytes_bound(
                gr,
                v,
                h,
                t,
                side_cap,
                cleanup || twins > 0,
            );
        if need > g.info.global_mem {
            return Err(Error::DeviceUnsupported {
                device: g.info.name.clone(),
                what: format!(
                    "iso {iso} gives {t} triangles; extracting them needs about {need} bytes \
                     of device memory, the device has {}",
                    g.info.global_mem
                ),
            });
        }
        st.soup_triangles = t + twins;
        st.exact_hits = h;
        // Hits: their grid points sorted and made unique (the vertices after
        // the edge vertices), and the triangles that collapse onto them
        // recounted where rows have hits.
        let (mut u, mut tk, mut collapsed) = (0, t, 0);
        if h > 0 {
            d.hit_keys.reserve(&g, h)?;
            let mut a = common.to_vec();
            a.extend([
                buf(&d.rowc),
                buf(&d.trim),
                Arg::U32(at[1]),
                Arg::U32(at[2]),
                buf(&d.hit_keys.buf),
            ]);
            let e = launch(&g, &d.hits, gr, &a)?;
            // Sorted and made unique on the host: the keys come back anyway
            // to size the vertices, and a device sort is a dozen launches.
            let mut keys = vec![0u32; h];
            g.read(&d.hit_keys.buf, &mut keys)?;
            keys.sort_unstable();
            keys.dedup();
            u = keys.len();
            g.write(&mut d.hit_keys.buf, &keys)?;
            if let Some(e) = &e {
                st.timing.add(Step::McDirectHits, event_ms(e));
            }
            let mut a = [&common[..], &tables[..]].concat();
            a.extend([
                buf(&d.rowc),
                buf(&d.trim),
                buf(&d.tcount),
                Arg::U32(u as u32),
                buf(&d.hit_keys.buf),
            ]);
            let e = launch(&g, &d.recount, gr, &a)?;
            tk = self.scan.exclusive(&d.tcount, &d.tcount, gr)? as usize;
            if let Some(e) = &e {
                st.timing.add(Step::McDirectRecount, event_ms(e));
            }
            st.timing.add(Step::ScanExclusive, self.scan.last_ms());
            collapsed = t.checked_sub(tk).ok_or_else(|| Error::DeviceResult {
                what: "triangle recount".into(),
                detail: format!("{tk} kept triangles of {t}"),
            })?;
        }
        let nv = v + u;
        d.pos.reserve(&g, 3 * nv)?;
        d.faces.reserve(&g, 3 * tk)?;
        if h > 0 {
            // Only written where there are hits (a blocking write otherwise
            // would be a second wait of the extraction).
            d.side.reserve(&g, 3 * side_cap)?;
            g.write(&mut d.side_n, &[0])?;
        }
        let (toff, tshift, tbase) = if h > 0 {
            (&d.tcount, 0, 0)
        } else {
            (&d.rowc, gr as u32, v as u32)
        };
        let mut a = [&common[..], &tables[..]].concat();
        a.extend([
            buf(&d.rowc),
            buf(&d.split),
            buf(&d.trim),
            buf(toff),
            Arg::U32(tshift),
            Arg::U32(tbase),
            Arg::U32(v as u32),
            Arg::U32(u as u32),
            buf(&d.hit_keys.buf),
            buf(&d.pos.buf),
            buf(&d.faces.buf),
            Arg::U32(side_cap as u32),
            buf(&d.side.buf),
            buf(&d.side_n),
        ]);
        let e_tri = launch(&g, &d.triangles, gr, &a)?;
        let e_pts = launch(
            &g,
            &d.points,
            u,
            &[
                Arg::U32(u as u32),
                buf(&d.hit_keys.buf),
                Arg::U32(nx as u32),
                Arg::U32(ny as u32),
                Arg::U32(v as u32),
                buf(&d.pos.buf),
            ],
        )?;
        // Does anything remain for vertex fusion's clean-up to do?
        let mut full = d.nonfinite;
        if h > 0 && !full {
            let mut n = [0u32];
            g.read(&d.side_n, &mut n)?;
            let n = n[0] as usize;
            full = n > side_cap || {
                let mut rec = vec![0u32; 3 * n];
                g.read(&d.side.buf, &mut rec)?;
                hit_twins(&rec)
            };
        }
        let dropped = twins + collapsed;
        let drops = Drops {
            vertices: nv,
            hit_points: u,
            recounted: h > 0,
            dropped,
        };
        d.last_drops = (dropped > 0).then_some(drops);
        // Dropped triangles may have been a vertex's only ones: then the
        // vertices still used are compacted (no triangle to drop or cancel).
        let mut used = None;
        if !full && dropped > 0 {
            let mut n = nv;
            let mut all = true;
            if unused_check_near(dropped, cell_rows(self.dims)) {
                let (unused, t) = d.count_unused_near(&g, self.dims, &drops)?;
                Self::add_events(st, &e_tri, &e_pts);
                st.timing.extend(&t);
                all = unused > 0;
                n = nv.checked_sub(unused).ok_or_else(|| Error::DeviceResult {
                    what: "count of unused vertices".into(),
                    detail: format!("{unused} unused of {nv}"),
                })?;
            }
            if all {
                // The marks of every vertex, which the compaction numbers.
                let (m, t) = self.fuser.count_referenced(&d.faces.buf, nv, tk)?;
                if n == nv {
                    Self::add_events(st, &e_tri, &e_pts);
                }
                st.timing.extend(&t);
                debug_assert!(n == nv || n == m, "unused near {} all {}", nv - n, nv - m);
                n = m;
            }
            used = (n < nv).then_some(n);
        } else {
            g.finish()?;
            Self::add_events(st, &e_tri, &e_pts);
        }
        if full {
            let (c, ft) = self.fuser.finish(&d.faces.buf, &d.pos.buf, nv, tk)?;
            st.vertices = c.vertices;
            st.faces = c.faces;
            st.degenerate_dropped = dropped + c.dropped;
            self.result = Some((Holder::Fused, c.vertices, c.faces));
            st.timing.extend(&ft);
        } else if let Some(n) = used {
            let (c, ft) = self
                .fuser
                .compact_referenced(&d.faces.buf, &d.pos.buf, nv, tk, n)?;
            st.vertices = c.vertices;
            st.faces = c.faces;
            st.degenerate_dropped = dropped;
            self.result = Some((Holder::Fused, c.vertices, c.faces));
            st.timing.extend(&ft);
        } else {
            st.vertices = nv;
            st.faces = tk;
            st.degenerate_dropped = dropped;
            self.result = Some((Holder::Direct, nv, tk));
        }
        Ok(())
    }

    /// Adds the kernel times of `mc_direct_triangles` and `mc_direct_points`
    /// (once they have run).
    fn add_events(
        st: &mut IsoStats,
        tri: &Option<opencl3::event::Event>,
        pts: &Option<opencl3::event::Event>,
    ) {
        if let Some(e) = tri {
            st.timing.add(Step::McDirectTriangles, event_ms(e));
        }
        if let Some(e) = pts {
            st.timing.add(Step::McDirectPoints, event_ms(e));
        }
    }
}

/// What the last extraction's triangle pass left, for the check that the
/// dropped triangles left no vertex unused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Drops {
    /// Vertices (edge vertices, then the hit points).
    pub(super) vertices: usize,
    /// Hit points (sorted, unique).
    pub(super) hit_points: usize,
    /// The kept triangles' offsets are the recount's (there were hits),
    /// else the count pass's.
    pub(super) recounted: bool,
    /// Triangles dropped (twins across a face, collapses): at least the
    /// cell rows that dropped some.
    pub(super) dropped: usize,
}

impl Direct {
    /// `mc_direct_unused_rows`, `_clear`, `_mark`, `_count`: how many of the
    /// `nv` vertices the kept triangles no longer use, looked for only in the
    /// grid rows of the cell rows that dropped triangles (every other vertex
    /// keeps the triangles it was made for), after the triangle pass that
    /// left `drops`. Waits for the count.
    pub(super) fn count_unused_near(
        &mut self,
        g: &Gpu,
        dims: [usize; 3],
        drops: &Drops,
    ) -> Result<(usize, Timing)> {
        let [nx, ny, nz] = dims;
        let (nv, u) = (drops.vertices, drops.hit_points);
        let gr = ny * nz;
        let v = nv - u;
        let (toff, tshift, tbase) = if drops.recounted {
            (&self.tcount, 0, 0)
        } else {
            (&self.rowc, gr as u32, v as u32)
        };
        let cap = drops.dropped.min(gr);
        self.unused.reserve(g, nv)?;
        self.unused_list.reserve(g, 2 + cap)?;
        g.zero(&mut self.unused_list.buf, 2)?;
        let (gr32, nx32, ny32, nz32, cap32) = (
            Arg::U32(gr as u32),
            Arg::U32(nx as u32),
            Arg::U32(ny as u32),
            Arg::U32(nz as u32),
            Arg::U32(cap as u32),
        );
        let (off, toff, list, marks) = (
            buf(&self.rowc),
            buf(toff),
            buf(&self.unused_list.buf),
            buf(&self.unused.buf),
        );
        let (tshift, nh, keys) = (
            Arg::U32(tshift),
            Arg::U32(u as u32),
            buf(&self.hit_keys.buf),
        );
        let e_rows = launch(
            g,
            &self.unused_rows,
            gr,
            &[gr32, ny32, nz32, off, toff, tshift, cap32, list],
        )?;
        let e_clear = launch(
            g,
            &self.unused_clear,
            4 * cap,
            &[gr32, nx32, ny32, nz32, off, nh, keys, cap32, list, marks],
        )?;
        let e_mark = launch(
            g,
            &self.unused_mark,
            9 * cap,
            &[
                gr32,
                ny32,
                nz32,
                toff,
                tshift,
                Arg::U32(tbase),
                Arg::U32(nv as u32),
                buf(&self.faces.buf),
                cap32,
                list,
                marks,
            ],
        )?;
        let e_count = launch(
            g,
            &self.unused_count,
            4 * cap,
            &[
                gr32, nx32, ny32, nz32, off, toff, tshift, nh, keys, marks, cap32, list,
            ],
        )?;
        let mut n = [0u32; 2];
        g.read(&self.unused_list.buf, &mut n)?;
        let mut t = Timing::default();
        for e in [&e_rows, &e_clear, &e_mark, &e_count].into_iter().flatten() {
            t.add(Step::McDirectUnused, event_ms(e));
        }
        Ok((n[1] as usize, t))
    }
}

/// True when the triangles with a corner on a grid point that lie in a grid
/// plane (records of `mc_direct_triangles`: three corners each) include an
/// opposite twin pair: the same three vertices, both windings.
fn hit_twins(rec: &[u32]) -> bool {
    let mut seen: std::collections::HashMap<[u32; 3], u8> = Default::default();
    for r in rec.chunks_exact(3) {
        let (set, even) = crate::cpu::vertex_fusion::tri_set([r[0], r[1], r[2]]);
        let w = seen.entry(set).or_default();
        *w |= if even { 1 } else { 2 };
        if *w == 3 {
            return true;
        }
    }
    false
}

/// Room for the list of triangles with a corner on a grid point lying in a
/// grid plane, which the host checks for twins: at most 5 per cell and 4
/// cells per hit edge, and at most every triangle; capped at 2^21 records
/// (24 MB), past which the list overflows and the fusion clean-up runs
/// instead (volumes with that many hits, such as integer data at a voxel
/// value, need it anyway).
fn side_records(hits: usize, triangles: usize) -> usize {
    (20 * hits).min(triangles).min(1 << 21)
}

#[cfg(test)]
mod tests {
    use super::super::Isosurfacer;
    use crate::cpu::marching_cubes as mc;
    use crate::spec::vertex_fusion::Fusion;
    use crate::volume::Volume;

    /// The device's count of unused vertices near the dropped triangles
    /// equals its CPU twin's and the count over every vertex, on volumes of
    /// small integers at an integer iso (collapses everywhere, some leaving
    /// vertices unused) and on smooth fields with a small block of them
    /// (few cell rows drop triangles), whichever check the extraction chose.
    #[test]
    fn unused_vertices_near_dropped_triangles_match_the_twin_and_the_full_count() {
        let gpu = crate::gpu::test_gpu();
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut rnd = move |n: u64| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s % n) as f32
        };
        let (mut some, mut none) = (0, 0);
        for trial in 0..40 {
            let n = if trial % 2 == 0 {
                [5 + trial % 7, 4 + trial % 5, 3 + trial % 4]
            } else {
                [9, 20 + trial % 3, 18]
            };
            let vals: Vec<f32> = (0..n[0] * n[1] * n[2])
                .map(|i| {
                    let (x, y, z) = (i % n[0], i / n[0] % n[1], i / (n[0] * n[1]));
                    if trial % 2 == 0 || (x < 4 && (8..12).contains(&y) && (8..12).contains(&z)) {
                        rnd(4)
                    } else {
                        x as f32 * 0.37 + y as f32 * 0.11 - 1.05
                    }
                })
                .collect();
            let vol = Volume::new(n, vals, "random").unwrap();
            let iso = 2.0;
            let mut iz = Isosurfacer::new(gpu.clone(), &vol).unwrap();
            iz.extract(iso, Fusion::Direct).unwrap();
            let Some(drops) = iz.direct.last_drops else {
                continue;
            };
            let (got, _) = iz.direct.count_unused_near(&gpu, iz.dims, &drops).unwrap();
            let d = mc::mc_direct(&vol, iso);
            let twin = mc::direct_unused_near(n, &d, &mc::mc_direct_count(&vol, iso));
            let mut used = vec![false; d.positions.len()];
            for f in &d.faces {
                if f[0] != f[1] && f[1] != f[2] && f[0] != f[2] {
                    f.iter().for_each(|&v| used[v as usize] = true);
                }
            }
            let all = used.iter().filter(|&&u| !u).count();
            assert_eq!((got, twin), (all, all), "trial {trial} {n:?}");
            if all > 0 {
                some += 1;
            } else {
                none += 1;
            }
        }
        assert!(
            some > 0 && none > 0,
            "unused in {some} trials, none in {none}"
        );
    }

    #[test]
    fn hit_twins_finds_opposite_windings() {
        use super::hit_twins;
        assert!(hit_twins(&[1, 2, 3, 3, 2, 1]));
        assert!(hit_twins(&[1, 2, 3, 4, 5, 6, 2, 1, 3]));
        assert!(hit_twins(&[1, 2, 3, 7, 1, 3, 2, 1, 3]));
        // Same winding (rotations), or other vertices: no twins.
        assert!(!hit_twins(&[1, 2, 3, 2, 3, 1, 3, 1, 2]));
        assert!(!hit_twins(&[1, 2, 3, 3, 2, 4]));
        assert!(!hit_twins(&[]));
    }
}
