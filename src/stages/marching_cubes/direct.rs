//! Host wiring of `kernels/marching_cubes_direct.cl` (Fusion direct, after
//! Flying Edges): count → one scan → triangles, with one host round trip
//! (the scan's partial totals, which size the outputs); where vertices land
//! on grid points also hits → (host sort) → recount → scan → points, the
//! twin check of the listed triangles, and vertex fusion's clean-up only if
//! it would change the mesh. CPU twin:
//! [`crate::cpu::marching_cubes::mc_direct`].

use super::{Holder, IsoStats, Isosurfacer};
use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::marching_cubes::McKernel;
use crate::spec::timing::Step;
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
            rowc: gpu.buffer::<u32>(4 * grid_rows)?,
            info: gpu.buffer::<u32>(4 * grid_rows)?,
            split: gpu.buffer::<u32>(2 * grid_rows)?,
            trim: gpu.buffer::<u32>(3 * grid_rows)?,
            hit_keys: Grow::new(gpu)?,
            tcount: gpu.buffer::<u32>(grid_rows)?,
            side: Grow::new(gpu)?,
            side_n: gpu.buffer::<u32>(1)?,
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
        let need = 4 * voxels as u64
            + crate::spec::vertex_fusion::direct_device_bytes_bound(gr, v, h, t, side_cap, cleanup);
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
            collapsed = t - tk;
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
        // Dropped triangles may have been a vertex's only ones: then the
        // vertices still used are compacted (no triangle to drop or cancel).
        let mut used = None;
        if !full && (collapsed > 0 || twins > 0) {
            let (n, t) = self.fuser.count_referenced(&d.faces.buf, nv, tk)?;
            Self::add_events(st, &e_tri, &e_pts);
            st.timing.extend(&t);
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

    /// Adds the kernel times of `mc_direct_triangles` and `mc_direct_points`.
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
