//! Host wiring of `kernels/marching_cubes_direct.cl` (Fusion direct, after
//! Flying Edges): count → one scan → triangles, with one host round trip
//! (the scan's partial totals, which size the outputs); where vertices land
//! on grid points also hits → (host sort) → recount → scan → points, the
//! twin check of the listed triangles, and vertex fusion's clean-up only if
//! it would change the mesh; where triangles were dropped, the check that
//! every vertex is still used (near them where they are few), and the
//! compaction of the used ones only if one is not. CPU twin:
//! [`crate::cpu::marching_cubes::mc_direct`].

use super::{Holder, IsoStats, Isosurfacer, add_event};
use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::marching_cubes::{McKernel, cell_rows, unused_check_near};
use crate::spec::timing::{Step, Timing};
use crate::stages::scan::Scan;
use crate::stages::vertex_fusion::{Fuser, Grow};
use opencl3::event::Event;
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

/// What the count pass's scan found: the scanned totals at the vertex,
/// triangle and hit boundaries, and the counts they give.
struct Counts {
    /// The exclusive scan at `gr`, `2 gr` and `3 gr`.
    at: Vec<u32>,
    /// Edge vertices.
    v: usize,
    /// Triangles the cells make.
    t: usize,
    /// Vertices that land on a grid point (exact hits).
    h: usize,
    /// Triangles dropped as twins across a cell face.
    twins: usize,
}

/// One direct extraction's device, buffers and the arguments its kernels
/// share; its methods are the family's steps, in the order they run.
struct DirectPass<'a> {
    g: &'a Gpu,
    d: &'a mut Direct,
    scan: &'a mut Scan,
    fuser: &'a mut Fuser,
    dims: [usize; 3],
    iso: f32,
    /// Grid rows.
    gr: usize,
    /// Grid rows, nx, ny, nz, the volume and the iso value.
    common: [Arg; 6],
    /// The case table as the direct kernels take it: counts, tris, flat.
    tables: [Arg; 3],
}

impl Isosurfacer {
    /// Direct numbering of `value = iso` (see the module's description).
    pub(super) fn extract_direct(&mut self, iso: f32, st: &mut IsoStats) -> Result<()> {
        let g = self.gpu.clone();
        let mut p = DirectPass::new(self, &g, iso);
        let e_rows = p.rows()?;
        let e_count = p.count()?;
        let c = p.scan()?;
        add_event(st, Step::McDirectRows, &e_rows);
        add_event(st, Step::McDirectCount, &e_count);
        st.timing.add(Step::ScanExclusive, p.scan.last_ms());
        let side_cap = p.check_room(&c)?;
        st.soup_triangles = c.t + c.twins;
        st.exact_hits = c.h;
        // Hits: their grid points sorted and made unique (the vertices after
        // the edge vertices), and the triangles that collapse onto them
        // recounted where rows have hits.
        let (mut u, mut tk, mut collapsed) = (0, c.t, 0);
        if c.h > 0 {
            u = p.hits(&c, st)?;
            (tk, collapsed) = p.recount(&c, u, st)?;
        }
        let nv = c.v + u;
        let e_tri = p.triangles(&c, u, tk, side_cap)?;
        let e_pts = p.points(c.v, u)?;
        let full = p.needs_cleanup(c.h, side_cap)?;
        let dropped = c.twins + collapsed;
        let drops = Drops {
            vertices: nv,
            hit_points: u,
            recounted: c.h > 0,
            dropped,
        };
        p.d.last_drops = (dropped > 0).then_some(drops);
        let used = if !full && dropped > 0 {
            p.unused(&drops, tk, (&e_tri, &e_pts), st)?
        } else {
            g.finish()?;
            add_events(st, &e_tri, &e_pts);
            None
        };
        let result = p.keep(full, used, &drops, tk, st)?;
        self.result = Some(result);
        Ok(())
    }
}

impl<'a> DirectPass<'a> {
    /// Borrows the direct kernels, the scan and the fuser of `iz` for one
    /// extraction of `value = iso` on `g`.
    fn new(iz: &'a mut Isosurfacer, g: &'a Gpu, iso: f32) -> Self {
        let [nx, ny, nz] = iz.dims;
        let gr = ny * nz;
        DirectPass {
            g,
            common: [
                Arg::U32(gr as u32),
                Arg::U32(nx as u32),
                Arg::U32(ny as u32),
                Arg::U32(nz as u32),
                buf(&iz.vol),
                Arg::F32(iso),
            ],
            tables: [buf(&iz.counts), buf(&iz.tris), buf(&iz.flat)],
            d: &mut iz.direct,
            scan: &mut iz.scan,
            fuser: &mut iz.fuser,
            dims: iz.dims,
            iso,
            gr,
        }
    }

    /// The shared arguments, the case table, then `rest`.
    fn with_tables(&self, rest: &[Arg]) -> Vec<Arg> {
        [&self.common[..], &self.tables[..], rest].concat()
    }

    /// `mc_direct_rows`: each grid row trimmed to where the surface is.
    fn rows(&mut self) -> Result<Option<Event>> {
        // Grid rows, nx, the volume and the iso value.
        let c = &self.common;
        let a = [c[0], c[1], c[4], c[5], buf(&self.d.info)];
        launch(self.g, &self.d.rows, self.gr, &a)
    }

    /// `mc_direct_count`: per grid row, its vertices, triangles, hits and twins.
    fn count(&mut self) -> Result<Option<Event>> {
        let d = &self.d;
        let a = self.with_tables(&[buf(&d.info), buf(&d.rowc), buf(&d.split), buf(&d.trim)]);
        launch(self.g, &d.count, self.gr, &a)
    }

    /// The one scan of the four per-row counts (in place), whose totals at
    /// the boundaries size the outputs: the extraction's host round trip.
    fn scan(&mut self) -> Result<Counts> {
        let (gr, iso, d) = (self.gr, self.iso, &self.d);
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
        Ok(Counts {
            v: at[0] as usize,
            t: (at[1] - at[0]) as usize,
            h: (at[2] - at[1]) as usize,
            twins: (total - at[2] as u64) as usize,
            at,
        })
    }

    /// Refuses counts past the device's 32-bit indices or its memory;
    /// returns the room for the triangles the host checks for twins.
    fn check_room(&self, c: &Counts) -> Result<usize> {
        let (g, iso, t) = (self.g, self.iso, c.t);
        let slots = c.v + c.h;
        if 3 * slots as u64 > u32::MAX as u64 || 3 * t as u64 > u32::MAX as u64 {
            return Err(Error::InvalidArgument(format!(
                "iso {iso}: {slots} vertices and {t} triangles exceed the 32-bit indices of \
                 the device (at most {} of each)",
                u32::MAX / 3
            )));
        }
        let cleanup = c.h > 0 || self.d.nonfinite;
        let side_cap = side_records(c.h, t);
        // Twins alone (no hit, a finite volume) can still drop triangles and
        // leave a vertex unused, which takes the compaction's buffers too.
        let voxels = self.dims.iter().product::<usize>();
        let need = 4 * voxels as u64
            + crate::spec::vertex_fusion::direct_device_bytes_bound(
                self.gr,
                c.v,
                c.h,
                t,
                side_cap,
                cleanup || c.twins > 0,
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
        Ok(side_cap)
    }

    /// `mc_direct_hits`: the grid points that vertices land on, listed, then
    /// sorted and made unique; returns how many.
    fn hits(&mut self, c: &Counts, st: &mut IsoStats) -> Result<usize> {
        let (g, d) = (self.g, &mut *self.d);
        d.hit_keys.reserve(g, c.h)?;
        let mut a = self.common.to_vec();
        a.extend([
            buf(&d.rowc),
            buf(&d.trim),
            Arg::U32(c.at[1]),
            Arg::U32(c.at[2]),
            buf(&d.hit_keys.buf),
        ]);
        let e = launch(g, &d.hits, self.gr, &a)?;
        // Sorted and made unique on the host: the keys come back anyway
        // to size the vertices, and a device sort is a dozen launches.
        let mut keys = vec![0u32; c.h];
        g.read(&d.hit_keys.buf, &mut keys)?;
        keys.sort_unstable();
        keys.dedup();
        g.write(&mut d.hit_keys.buf, &keys)?;
        add_event(st, Step::McDirectHits, &e);
        Ok(keys.len())
    }

    /// `mc_direct_recount` and its scan: the triangles kept where `u` hit
    /// points collapse some; returns (kept, collapsed).
    fn recount(&mut self, c: &Counts, u: usize, st: &mut IsoStats) -> Result<(usize, usize)> {
        let d = &self.d;
        let a = self.with_tables(&[
            buf(&d.rowc),
            buf(&d.trim),
            buf(&d.tcount),
            Arg::U32(u as u32),
            buf(&d.hit_keys.buf),
        ]);
        let e = launch(self.g, &d.recount, self.gr, &a)?;
        let tk = self.scan.exclusive(&d.tcount, &d.tcount, self.gr)? as usize;
        add_event(st, Step::McDirectRecount, &e);
        st.timing.add(Step::ScanExclusive, self.scan.last_ms());
        let t = c.t;
        let collapsed = t.checked_sub(tk).ok_or_else(|| Error::DeviceResult {
            what: "triangle recount".into(),
            detail: format!("{tk} kept triangles of {t}"),
        })?;
        Ok((tk, collapsed))
    }

    /// `mc_direct_triangles`: the `tk` kept triangles with their final
    /// indices and the edge vertices' positions (outputs sized first).
    fn triangles(
        &mut self,
        c: &Counts,
        u: usize,
        tk: usize,
        side_cap: usize,
    ) -> Result<Option<Event>> {
        let (g, gr, v, h) = (self.g, self.gr, c.v, c.h);
        self.d.pos.reserve(g, 3 * (v + u))?;
        self.d.faces.reserve(g, 3 * tk)?;
        if h > 0 {
            // Only written where there are hits (a blocking write otherwise
            // would be a second wait of the extraction).
            self.d.side.reserve(g, 3 * side_cap)?;
            g.write(&mut self.d.side_n, &[0])?;
        }
        let d = &*self.d;
        let (toff, tshift, tbase) = if h > 0 {
            (&d.tcount, 0, 0)
        } else {
            (&d.rowc, gr as u32, v as u32)
        };
        let a = self.with_tables(&[
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
        launch(g, &d.triangles, gr, &a)
    }

    /// `mc_direct_points`: the positions of the `u` hit-point vertices,
    /// after the `v` edge vertices.
    fn points(&mut self, v: usize, u: usize) -> Result<Option<Event>> {
        let [nx, ny, _] = self.dims;
        let d = &self.d;
        launch(
            self.g,
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
        )
    }

    /// Whether anything remains for vertex fusion's clean-up to do: a
    /// non-finite volume, an overflowing list of triangles on grid points
    /// (`h` hits, room for `side_cap`), or twins among them.
    fn needs_cleanup(&self, h: usize, side_cap: usize) -> Result<bool> {
        let (g, d) = (self.g, &self.d);
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
        Ok(full)
    }

    /// `mc_direct_unused_*` (near few dropped triangles) or the fuser's
    /// count over every vertex: dropped triangles may have been a vertex's
    /// only ones; returns the vertices still used when some are not (then
    /// compacted: no triangle to drop or cancel). `events` are the triangle
    /// and point passes', added once they have run.
    fn unused(
        &mut self,
        drops: &Drops,
        tk: usize,
        events: (&Option<Event>, &Option<Event>),
        st: &mut IsoStats,
    ) -> Result<Option<usize>> {
        let (e_tri, e_pts) = events;
        let nv = drops.vertices;
        let mut n = nv;
        let mut all = true;
        if unused_check_near(drops.dropped, cell_rows(self.dims)) {
            let (unused, t) = self.d.count_unused_near(self.g, self.dims, drops)?;
            add_events(st, e_tri, e_pts);
            st.timing.extend(&t);
            all = unused > 0;
            n = nv.checked_sub(unused).ok_or_else(|| Error::DeviceResult {
                what: "count of unused vertices".into(),
                detail: format!("{unused} unused of {nv}"),
            })?;
        }
        if all {
            // The marks of every vertex, which the compaction numbers.
            let (m, t) = self.fuser.count_referenced(&self.d.faces.buf, nv, tk)?;
            if n == nv {
                add_events(st, e_tri, e_pts);
            }
            st.timing.extend(&t);
            debug_assert!(n == nv || n == m, "unused near {} all {}", nv - n, nv - m);
            n = m;
        }
        Ok((n < nv).then_some(n))
    }

    /// The result: fused by the clean-up when `full`, compacted to `used`
    /// vertices, or the direct mesh as it is (`tk` triangles); the stats
    /// say which.
    fn keep(
        &mut self,
        full: bool,
        used: Option<usize>,
        drops: &Drops,
        tk: usize,
        st: &mut IsoStats,
    ) -> Result<(Holder, usize, usize)> {
        let (d, nv, dropped) = (&self.d, drops.vertices, drops.dropped);
        if full {
            let (c, ft) = self.fuser.finish(&d.faces.buf, &d.pos.buf, nv, tk)?;
            st.vertices = c.vertices;
            st.faces = c.faces;
            st.degenerate_dropped = dropped + c.dropped;
            st.timing.extend(&ft);
            Ok((Holder::Fused, c.vertices, c.faces))
        } else if let Some(n) = used {
            let (c, ft) = self
                .fuser
                .compact_referenced(&d.faces.buf, &d.pos.buf, nv, tk, n)?;
            st.vertices = c.vertices;
            st.faces = c.faces;
            st.degenerate_dropped = dropped;
            st.timing.extend(&ft);
            Ok((Holder::Fused, c.vertices, c.faces))
        } else {
            st.vertices = nv;
            st.faces = tk;
            st.degenerate_dropped = dropped;
            Ok((Holder::Direct, nv, tk))
        }
    }
}

/// Adds the kernel times of `mc_direct_triangles` and `mc_direct_points`
/// (once they have run).
fn add_events(st: &mut IsoStats, tri: &Option<Event>, pts: &Option<Event>) {
    add_event(st, Step::McDirectTriangles, tri);
    add_event(st, Step::McDirectPoints, pts);
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

/// The arguments the four kernels of the check for unused vertices share.
struct UnusedArgs {
    /// Grid rows, nx, ny, nz.
    gr: Arg,
    nx: Arg,
    ny: Arg,
    nz: Arg,
    /// The per-row offsets (the count pass's scan).
    off: Arg,
    /// The kept triangles' offsets, their shift and base (the recount's or
    /// the count pass's).
    toff: Arg,
    tshift: Arg,
    tbase: Arg,
    /// Hit points and their sorted keys.
    nh: Arg,
    keys: Arg,
    /// Vertices, and the faces that use them.
    nv: Arg,
    faces: Arg,
    /// Room for cell rows in the list (`cap` as an argument), the list
    /// (its two counts, then the rows) and the vertices' marks.
    cap: usize,
    cap32: Arg,
    list: Arg,
    marks: Arg,
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
        let a = self.unused_args(g, dims, drops)?;
        let (gr, cap) = (dims[1] * dims[2], a.cap);
        let rows = [a.gr, a.ny, a.nz, a.off, a.toff, a.tshift, a.cap32, a.list];
        let e_rows = launch(g, &self.unused_rows, gr, &rows)?;
        let clear = [
            a.gr, a.nx, a.ny, a.nz, a.off, a.nh, a.keys, a.cap32, a.list, a.marks,
        ];
        let e_clear = launch(g, &self.unused_clear, 4 * cap, &clear)?;
        let mark = [
            a.gr, a.ny, a.nz, a.toff, a.tshift, a.tbase, a.nv, a.faces, a.cap32, a.list, a.marks,
        ];
        let e_mark = launch(g, &self.unused_mark, 9 * cap, &mark)?;
        let count = [
            a.gr, a.nx, a.ny, a.nz, a.off, a.toff, a.tshift, a.nh, a.keys, a.marks, a.cap32, a.list,
        ];
        let e_count = launch(g, &self.unused_count, 4 * cap, &count)?;
        let mut n = [0u32; 2];
        g.read(&self.unused_list.buf, &mut n)?;
        let mut t = Timing::default();
        for e in [&e_rows, &e_clear, &e_mark, &e_count].into_iter().flatten() {
            t.add(Step::McDirectUnused, event_ms(e));
        }
        Ok((n[1] as usize, t))
    }

    /// Sizes the marks and the list of cell rows (its counts zeroed) for
    /// the check after the triangle pass that left `drops`, and returns the
    /// arguments its kernels share.
    fn unused_args(&mut self, g: &Gpu, dims: [usize; 3], drops: &Drops) -> Result<UnusedArgs> {
        let [nx, ny, nz] = dims;
        let (nv, u) = (drops.vertices, drops.hit_points);
        let gr = ny * nz;
        let v = nv - u;
        let cap = drops.dropped.min(gr);
        self.unused.reserve(g, nv)?;
        self.unused_list.reserve(g, 2 + cap)?;
        g.zero(&mut self.unused_list.buf, 2)?;
        let (toff, tshift, tbase) = if drops.recounted {
            (&self.tcount, 0, 0)
        } else {
            (&self.rowc, gr as u32, v as u32)
        };
        Ok(UnusedArgs {
            gr: Arg::U32(gr as u32),
            nx: Arg::U32(nx as u32),
            ny: Arg::U32(ny as u32),
            nz: Arg::U32(nz as u32),
            off: buf(&self.rowc),
            toff: buf(toff),
            tshift: Arg::U32(tshift),
            tbase: Arg::U32(tbase),
            nh: Arg::U32(u as u32),
            keys: buf(&self.hit_keys.buf),
            nv: Arg::U32(nv as u32),
            faces: buf(&self.faces.buf),
            cap,
            cap32: Arg::U32(cap as u32),
            list: buf(&self.unused_list.buf),
            marks: buf(&self.unused.buf),
        })
    }
}

/// True when the triangles with a corner on a grid point that lie in a grid
/// plane (records of `mc_direct_triangles`: three corners each) include an
/// opposite twin pair: the same three vertices, both windings.
fn hit_twins(rec: &[u32]) -> bool {
    let mut seen: std::collections::HashMap<[u32; 3], u8> = Default::default();
    for r in rec.chunks_exact(3) {
        let (set, even) = crate::spec::vertex_fusion::tri_set([r[0], r[1], r[2]]);
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
