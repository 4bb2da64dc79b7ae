//! Host wiring of `kernels/marching_cubes.cl` and the isosurface pipeline:
//! the volume is uploaded once; each extraction runs `mc_classify` → scan →
//! `mc_triangles` and then vertex fusion ([`crate::stages::vertex_fusion`]),
//! leaving the indexed mesh on the device (for the curvature passes) until
//! the caller reads it. CPU twin: [`crate::cpu::marching_cubes`]; shared
//! case table, layout, bounds and options: [`crate::spec::marching_cubes`].
//!
//! Memory: the soup is sized exactly from the classify counts; the kernels
//! still check a capacity and count what would not fit, so a bug can never
//! write past a buffer. A volume or an output that the device cannot hold is
//! a clear error naming the bytes needed.

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, kernel_file, launch};
use crate::mesh::Mesh;
use crate::spec::curvature::{CurvatureOptions, Normalization};
use crate::spec::marching_cubes::{cell_rows, edge_key_bits, soup_vertices_bound, table};
use crate::spec::timing::{Step, Timing};
use crate::spec::vertex_fusion::{Fusion, FusionCounts};
use crate::stages::curvature::CurvatureEstimator;
use crate::stages::scan::Scan;
use crate::stages::vertex_fusion::{Fuser, Grow, build_options};
use crate::volume::Volume;
use opencl3::kernel::Kernel;
use opencl3::memory::{Buffer, CL_MEM_READ_ONLY};
use std::sync::Arc;
use std::time::Instant;

/// What one extraction did and how long each pass took.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct IsoStats {
    /// The fusion variant.
    pub fusion: &'static str,
    /// The iso value.
    pub iso: f32,
    /// Voxels in the volume.
    pub voxels: usize,
    /// Triangles emitted by the cells (before fusion drops any): the soup's
    /// triangles, or those of direct numbering.
    pub soup_triangles: usize,
    /// Soup vertices (3 per triangle: vertices before fusion); 0 for direct
    /// numbering, which makes no soup.
    pub soup_vertices: usize,
    /// Direct numbering: vertices that rounded onto a grid point (iso equal
    /// to voxel values), which alone make the clean-up passes run.
    pub exact_hits: usize,
    /// Vertices after fusion.
    pub vertices: usize,
    /// Faces after fusion.
    pub faces: usize,
    /// Triangles dropped because two fused corners coincide (iso equal to voxel values).
    pub degenerate_dropped: usize,
    /// Kernel ms per step (`mc_classify`, the row scan, `mc_triangles`,
    /// `mc_iota` or the fusion steps), their sum, and the wall time of the
    /// extraction (volume already on the device).
    pub timing: Timing,
    /// Device bytes held after the extraction (volume, soup, scratch, outputs).
    pub device_bytes: u64,
}

/// Positions in voxel index space and faces, as read back from the device.
pub type IndexSpaceMesh = (Vec<[f32; 3]>, Vec<[u32; 3]>);

/// Which buffers hold the current result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Holder {
    Soup,
    Fused,
    Direct,
}

/// Extracts isosurfaces of one volume on the device.
pub struct Isosurfacer {
    gpu: Arc<Gpu>,
    dims: [usize; 3],
    /// World units per voxel step.
    pub spacing: [f64; 3],
    /// World position of voxel (0, 0, 0).
    pub origin: [f64; 3],
    vol: Buffer<f32>,
    counts: Buffer<u8>,
    tris: Buffer<u8>,
    flat: Buffer<u8>,
    classify: Kernel,
    triangles: Kernel,
    iota: Kernel,
    gradient: Kernel,
    direct_rows: Kernel,
    direct_count: Kernel,
    direct_hits: Kernel,
    direct_triangles: Kernel,
    direct_points: Kernel,
    direct_recount: Kernel,
    scan: Scan,
    fuser: Fuser,
    row_tris: Buffer<u32>,
    row_off: Buffer<u32>,
    counters: Buffer<u32>,
    pos: Grow<f32>,
    key: Grow<u32>,
    idx: Grow<u32>,
    soup_faces: Grow<u32>,
    /// Direct numbering: per grid row counts (scanned in place), splits, trims.
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
    dpos: Grow<f32>,
    dfaces: Grow<u32>,
    /// The volume has NaN or infinite voxels (known at upload): direct
    /// numbering then removes the vertices of edges only skipped cells use.
    nonfinite: bool,
    result: Option<(Holder, usize, usize)>,
}

impl Isosurfacer {
    /// Uploads `vol` to the device (once) and builds the kernels. Errors if
    /// the device cannot hold the volume, naming the bytes.
    pub fn new(gpu: Arc<Gpu>, vol: &Volume) -> Result<Self> {
        Self::with_hash_mask(gpu, vol, None)
    }

    /// Like [`Isosurfacer::new`], with the position hash masked to
    /// `collide_mask` (tests: forces hash collisions; fusion stays exact).
    #[doc(hidden)]
    pub fn with_hash_mask(gpu: Arc<Gpu>, vol: &Volume, collide_mask: Option<u32>) -> Result<Self> {
        let bytes = vol.bytes();
        if bytes > gpu.info.max_alloc || bytes > gpu.info.global_mem {
            return Err(Error::DeviceUnsupported {
                device: gpu.info.name.clone(),
                what: format!(
                    "the volume needs {bytes} bytes of device memory ({}×{}×{} f32); the device \
                     allows {} bytes in one buffer and has {} bytes",
                    vol.dims[0], vol.dims[1], vol.dims[2], gpu.info.max_alloc, gpu.info.global_mem
                ),
            });
        }
        let n = vol.voxel_count();
        if vol.dims.iter().any(|&d| d > u32::MAX as usize) || n as u64 >= (1u64 << 32) {
            return Err(Error::InvalidArgument(format!(
                "volume of {n} voxels: at most 2^32 − 1 voxels"
            )));
        }
        let file = kernel_file("marching_cubes").expect("marching_cubes kernels are embedded");
        let p = gpu.program(&file, &build_options(collide_mask))?;
        let mut volb = gpu.buffer_flags::<f32>(n, CL_MEM_READ_ONLY)?;
        gpu.write(&mut volb, &vol.values)?;
        let t = table();
        let mut counts = gpu.buffer_flags::<u8>(256, CL_MEM_READ_ONLY)?;
        gpu.write(&mut counts, &t.counts)?;
        let mut tris = gpu.buffer_flags::<u8>(256 * 16, CL_MEM_READ_ONLY)?;
        gpu.write(&mut tris, t.tris.as_flattened())?;
        let mut flat = gpu.buffer_flags::<u8>(256, CL_MEM_READ_ONLY)?;
        gpu.write(&mut flat, &t.flat)?;
        let rows = cell_rows(vol.dims);
        let grid_rows = vol.dims[1] * vol.dims[2];
        Ok(Isosurfacer {
            dims: vol.dims,
            spacing: vol.spacing,
            origin: vol.origin,
            vol: volb,
            counts,
            tris,
            flat,
            classify: gpu.kernel(&p, "mc_classify")?,
            triangles: gpu.kernel(&p, "mc_triangles")?,
            iota: gpu.kernel(&p, "mc_iota")?,
            gradient: gpu.kernel(&p, "mc_gradient_normals")?,
            direct_rows: gpu.kernel(&p, "mc_direct_rows")?,
            direct_count: gpu.kernel(&p, "mc_direct_count")?,
            direct_hits: gpu.kernel(&p, "mc_direct_hits")?,
            direct_triangles: gpu.kernel(&p, "mc_direct_triangles")?,
            direct_points: gpu.kernel(&p, "mc_direct_points")?,
            direct_recount: gpu.kernel(&p, "mc_direct_recount")?,
            scan: Scan::new(gpu.clone())?,
            fuser: Fuser::new(gpu.clone())?,
            row_tris: gpu.buffer::<u32>(rows)?,
            row_off: gpu.buffer::<u32>(rows)?,
            counters: gpu.buffer::<u32>(2)?,
            pos: Grow::new(&gpu)?,
            key: Grow::new(&gpu)?,
            idx: Grow::new(&gpu)?,
            soup_faces: Grow::new(&gpu)?,
            rowc: gpu.buffer::<u32>(4 * grid_rows)?,
            info: gpu.buffer::<u32>(4 * grid_rows)?,
            split: gpu.buffer::<u32>(2 * grid_rows)?,
            trim: gpu.buffer::<u32>(2 * grid_rows)?,
            hit_keys: Grow::new(&gpu)?,
            tcount: gpu.buffer::<u32>(grid_rows)?,
            side: Grow::new(&gpu)?,
            side_n: gpu.buffer::<u32>(1)?,
            dpos: Grow::new(&gpu)?,
            dfaces: Grow::new(&gpu)?,
            nonfinite: vol.values.iter().any(|v| !v.is_finite()),
            result: None,
            gpu,
        })
    }

    /// The device.
    pub fn gpu(&self) -> &Arc<Gpu> {
        &self.gpu
    }

    /// Voxels per axis.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Device bytes held now.
    pub fn device_bytes(&self) -> u64 {
        let rows = cell_rows(self.dims) as u64;
        4 * (self.dims.iter().product::<usize>() as u64)
            + 8 * rows
            + self.pos.bytes()
            + self.key.bytes()
            + self.idx.bytes()
            + self.soup_faces.bytes()
            + 52 * (self.dims[1] * self.dims[2]) as u64
            + self.side.bytes()
            + self.hit_keys.bytes()
            + self.dpos.bytes()
            + self.dfaces.bytes()
            + self.fuser.device_bytes()
    }

    /// Extracts the surface `value = iso` with the given fusion; the result
    /// stays on the device (see [`Isosurfacer::read`], [`Isosurfacer::device_mesh`]).
    pub fn extract(&mut self, iso: f32, fusion: Fusion) -> Result<IsoStats> {
        if !iso.is_finite() {
            return Err(Error::InvalidArgument(format!(
                "iso value must be finite, got {iso}"
            )));
        }
        let g = self.gpu.clone();
        let t0 = Instant::now();
        let [nx, ny, nz] = self.dims;
        let voxels = nx * ny * nz;
        let mut st = IsoStats {
            fusion: fusion.name(),
            iso,
            voxels,
            ..Default::default()
        };
        self.result = None;
        let rows = cell_rows(self.dims);
        if rows == 0 || nx < 2 {
            st.device_bytes = self.device_bytes();
            self.result = Some((Holder::Soup, 0, 0));
            return Ok(st);
        }
        if fusion == Fusion::Edge && edge_key_bits(voxels).is_none() {
            return Err(Error::InvalidArgument(format!(
                "--fusion edge keys vertices by 4 × voxel index in 32 bits: at most 2^30 voxels, \
                 this volume has {voxels}; use --fusion direct or hash"
            )));
        }
        if fusion == Fusion::Direct {
            self.extract_direct(iso, &mut st)?;
            st.timing.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
            st.device_bytes = self.device_bytes();
            return Ok(st);
        }
        let common = [
            Arg::U32(rows as u32),
            Arg::U32(nx as u32),
            Arg::U32(ny as u32),
            buf(&self.vol),
            Arg::F32(iso),
        ];
        let mut a = common.to_vec();
        a.extend([buf(&self.counts), buf(&self.row_tris)]);
        let e_cls = launch(&g, &self.classify, rows, &a)?;
        let tris = self.scan.exclusive(&self.row_tris, &self.row_off, rows)? as usize;
        if let Some(e) = &e_cls {
            st.timing.add(Step::McClassify, event_ms(e));
        }
        st.timing.add(Step::ScanExclusive, self.scan.last_ms());
        let soup = soup_vertices_bound(tris);
        if soup as u64 > u32::MAX as u64 {
            return Err(Error::InvalidArgument(format!(
                "iso {iso}: {tris} triangles exceed the 32-bit soup index"
            )));
        }
        let need = crate::spec::marching_cubes::device_bytes_bound(voxels, rows, soup);
        if need > g.info.global_mem {
            return Err(Error::DeviceUnsupported {
                device: g.info.name.clone(),
                what: format!(
                    "iso {iso} gives {tris} triangles; extracting and fusing them needs about \
                     {need} bytes of device memory, the device has {}",
                    g.info.global_mem
                ),
            });
        }
        self.pos.reserve(&g, 3 * soup)?;
        if fusion != Fusion::None {
            self.key.reserve(&g, soup)?;
            self.idx.reserve(&g, soup)?;
        }
        g.write(&mut self.counters, &[0, 0])?;
        let mut a = common.to_vec();
        a.extend([
            buf(&self.counts),
            buf(&self.tris),
            buf(&self.row_off),
            Arg::U32(soup as u32),
            Arg::U32(fusion.code()),
            buf(&self.pos.buf),
            buf(&self.key.buf),
            buf(&self.idx.buf),
            buf(&self.counters),
        ]);
        let e_tri = launch(&g, &self.triangles, rows, &a)?;
        let mut c = [0u32; 2];
        g.read(&self.counters, &mut c)?;
        if let Some(e) = &e_tri {
            st.timing.add(Step::McTriangles, event_ms(e));
        }
        if c[0] != 0 {
            return Err(Error::InvalidArgument(format!(
                "internal: mc_triangles produced {} more soup vertices than mc_classify counted \
                 ({soup}); nothing was written past the buffer",
                c[0]
            )));
        }
        st.soup_triangles = tris;
        st.soup_vertices = soup;
        match fusion {
            Fusion::None => {
                self.soup_faces.reserve(&g, soup)?;
                let e = launch(
                    &g,
                    &self.iota,
                    soup,
                    &[Arg::U32(soup as u32), buf(&self.soup_faces.buf)],
                )?;
                g.finish()?;
                if let Some(e) = &e {
                    st.timing.add(Step::McIota, event_ms(e));
                }
                st.vertices = soup;
                st.faces = tris;
                self.result = Some((Holder::Soup, soup, tris));
            }
            _ => {
                let key_bits = match fusion {
                    Fusion::Hash => 32,
                    _ => edge_key_bits(voxels).expect("checked above"),
                };
                let (
                    FusionCounts {
                        vertices,
                        faces,
                        dropped,
                    },
                    ft,
                ) = self.fuser.fuse(
                    fusion,
                    &mut self.key.buf,
                    &mut self.idx.buf,
                    &self.pos.buf,
                    soup,
                    key_bits,
                )?;
                st.vertices = vertices;
                st.faces = faces;
                st.degenerate_dropped = dropped;
                st.timing.extend(&ft);
                self.result = Some((Holder::Fused, vertices, faces));
            }
        }
        st.timing.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        st.device_bytes = self.device_bytes();
        Ok(st)
    }

    /// Direct numbering (see `kernels/marching_cubes.cl`): count → one scan
    /// → triangles, with one host round trip (the scan's partial totals,
    /// which size the outputs); where vertices land on grid points also
    /// hits → (host sort) → recount → scan → points, the twin check of the
    /// listed triangles, and the clean-up only if it would change the mesh.
    fn extract_direct(&mut self, iso: f32, st: &mut IsoStats) -> Result<()> {
        let g = self.gpu.clone();
        let [nx, ny, nz] = self.dims;
        let voxels = nx * ny * nz;
        let gr = ny * nz;
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
            &self.direct_rows,
            gr,
            &[
                Arg::U32(gr as u32),
                Arg::U32(nx as u32),
                buf(&self.vol),
                Arg::F32(iso),
                buf(&self.info),
            ],
        )?;
        let mut a = [&common[..], &tables[..]].concat();
        a.extend([
            buf(&self.info),
            buf(&self.rowc),
            buf(&self.split),
            buf(&self.trim),
        ]);
        let e_count = launch(&g, &self.direct_count, gr, &a)?;
        let (total, at) = self
            .scan
            .exclusive_at(&self.rowc, &self.rowc, 4 * gr, &[gr, 2 * gr, 3 * gr])
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
        let cleanup = h > 0 || self.nonfinite;
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
            self.hit_keys.reserve(&g, h)?;
            let mut a = common.to_vec();
            a.extend([
                buf(&self.rowc),
                buf(&self.trim),
                Arg::U32(at[1]),
                Arg::U32(at[2]),
                buf(&self.hit_keys.buf),
            ]);
            let e = launch(&g, &self.direct_hits, gr, &a)?;
            // Sorted and made unique on the host: the keys come back anyway
            // to size the vertices, and a device sort is a dozen launches.
            let mut keys = vec![0u32; h];
            g.read(&self.hit_keys.buf, &mut keys)?;
            keys.sort_unstable();
            keys.dedup();
            u = keys.len();
            g.write(&mut self.hit_keys.buf, &keys)?;
            if let Some(e) = &e {
                st.timing.add(Step::McDirectHits, event_ms(e));
            }
            let mut a = [&common[..], &tables[..]].concat();
            a.extend([buf(&self.rowc), buf(&self.trim), buf(&self.tcount)]);
            let e = launch(&g, &self.direct_recount, gr, &a)?;
            tk = self.scan.exclusive(&self.tcount, &self.tcount, gr)? as usize;
            if let Some(e) = &e {
                st.timing.add(Step::McDirectRecount, event_ms(e));
            }
            st.timing.add(Step::ScanExclusive, self.scan.last_ms());
            collapsed = t - tk;
        }
        let nv = v + u;
        self.dpos.reserve(&g, 3 * nv)?;
        self.dfaces.reserve(&g, 3 * tk)?;
        if h > 0 {
            // Only written where there are hits (a blocking write otherwise
            // would be a second wait of the extraction).
            self.side.reserve(&g, 5 * side_cap)?;
            g.write(&mut self.side_n, &[0])?;
        }
        let (toff, tshift, tbase) = if h > 0 {
            (&self.tcount, 0, 0)
        } else {
            (&self.rowc, gr as u32, v as u32)
        };
        let mut a = [&common[..], &tables[..]].concat();
        a.extend([
            buf(&self.rowc),
            buf(&self.split),
            buf(&self.trim),
            buf(toff),
            Arg::U32(tshift),
            Arg::U32(tbase),
            Arg::U32(v as u32),
            Arg::U32(u as u32),
            buf(&self.hit_keys.buf),
            buf(&self.dpos.buf),
            buf(&self.dfaces.buf),
            Arg::U32(side_cap as u32),
            buf(&self.side.buf),
            buf(&self.side_n),
        ]);
        let e_tri = launch(&g, &self.direct_triangles, gr, &a)?;
        let e_pts = launch(
            &g,
            &self.direct_points,
            u,
            &[
                Arg::U32(u as u32),
                buf(&self.hit_keys.buf),
                Arg::U32(nx as u32),
                Arg::U32(ny as u32),
                Arg::U32(v as u32),
                buf(&self.dpos.buf),
            ],
        )?;
        // Does anything remain for vertex fusion's clean-up to do?
        let mut full = self.nonfinite;
        if h > 0 && !full {
            let mut n = [0u32];
            g.read(&self.side_n, &mut n)?;
            let n = n[0] as usize;
            full = n > side_cap || {
                let mut rec = vec![0u32; 5 * n];
                g.read(&self.side.buf, &mut rec)?;
                hit_twins(&rec)
            };
        }
        if !full && (collapsed > 0 || twins > 0) {
            // Dropped triangles may have been a vertex's only ones.
            full = self.fuser.count_referenced(&self.dfaces.buf, nv, tk)? < nv;
        }
        let dropped = twins + collapsed;
        if full {
            let (c, ft) = self
                .fuser
                .finish(&self.dfaces.buf, &self.dpos.buf, nv, tk)?;
            st.vertices = c.vertices;
            st.faces = c.faces;
            st.degenerate_dropped = dropped + c.dropped;
            self.result = Some((Holder::Fused, c.vertices, c.faces));
            Self::add_events(st, &e_tri, &e_pts);
            st.timing.extend(&ft);
        } else {
            g.finish()?;
            st.vertices = nv;
            st.faces = tk;
            st.degenerate_dropped = dropped;
            self.result = Some((Holder::Direct, nv, tk));
            Self::add_events(st, &e_tri, &e_pts);
        }
        Ok(())
    }

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

    /// The current result on the device: (positions: 3 floats per vertex in
    /// index space, faces: 3 indices each, vertex count, face count).
    pub fn device_mesh(&self) -> Option<(&Buffer<f32>, &Buffer<u32>, usize, usize)> {
        let (h, nv, nf) = self.result?;
        Some(match h {
            Holder::Soup => (&self.pos.buf, &self.soup_faces.buf, nv, nf),
            Holder::Fused => (&self.fuser.out_pos.buf, &self.fuser.out_faces.buf, nv, nf),
            Holder::Direct => (&self.dpos.buf, &self.dfaces.buf, nv, nf),
        })
    }

    /// Unit normals of the current result's vertices from the volume
    /// gradient (trilinear interpolation of central differences, world
    /// units), computed on the device into a new buffer of 3 floats per
    /// vertex; (0,0,0) where the gradient vanishes. CPU twin:
    /// [`crate::cpu::marching_cubes::gradient_normals`].
    pub fn gradient_normals(&self) -> Result<Buffer<f32>> {
        let Some((pos, _, nv, _)) = self.device_mesh() else {
            return Err(Error::InvalidArgument("no isosurface extracted yet".into()));
        };
        let out = self.gpu.buffer::<f32>(3 * nv)?;
        let [nx, ny, nz] = self.dims;
        launch(
            &self.gpu,
            &self.gradient,
            nv,
            &[
                Arg::U32(nv as u32),
                buf(pos),
                buf(&self.vol),
                Arg::U32(nx as u32),
                Arg::U32(ny as u32),
                Arg::U32(nz as u32),
                Arg::F32(self.spacing[0] as f32),
                Arg::F32(self.spacing[1] as f32),
                Arg::F32(self.spacing[2] as f32),
                buf(&out),
            ],
        )?;
        self.gpu.finish()?;
        Ok(out)
    }

    /// Reads the current result: positions in index space and faces.
    pub fn read_index_space(&self) -> Result<IndexSpaceMesh> {
        let Some((p, f, nv, nf)) = self.device_mesh() else {
            return Ok((Vec::new(), Vec::new()));
        };
        let mut pos = vec![[0f32; 3]; nv];
        let mut faces = vec![[0u32; 3]; nf];
        self.gpu.read(p, pos.as_flattened_mut())?;
        self.gpu.read(f, faces.as_flattened_mut())?;
        Ok((pos, faces))
    }

    /// Reads the current result as a mesh in world coordinates
    /// (origin + spacing ⊙ p, in f64).
    pub fn read(&self) -> Result<Mesh> {
        let (pos, faces) = self.read_index_space()?;
        Ok(self.world_mesh(&pos, faces))
    }

    /// A mesh in world coordinates (origin + spacing ⊙ p, in f64) from
    /// index-space positions read with [`Isosurfacer::read_index_space`].
    pub fn world_mesh(&self, pos: &[[f32; 3]], faces: Vec<[u32; 3]>) -> Mesh {
        Mesh {
            positions: pos
                .iter()
                .map(|p| std::array::from_fn(|i| self.origin[i] + self.spacing[i] * p[i] as f64))
                .collect(),
            faces,
        }
    }
}

use crate::spec::marching_cubes::IsoNormals;

/// Curvature of the current isosurface, computed without a host round trip:
/// the fused faces and positions are copied device to device into a
/// [`crate::stages::curvature::CurvatureEstimator`] (atomic accumulation),
/// positions mapped to world units and normalized on the device, vertex
/// normals from the mesh or the volume gradient. Returns the estimator after
/// its run (read the field with its `read`) and the run's timing.
pub fn curvature(
    iso: &Isosurfacer,
    opts: CurvatureOptions,
    normals: IsoNormals,
) -> Result<(CurvatureEstimator, Timing)> {
    let Some((pos, faces, nv, nf)) = iso.device_mesh() else {
        return Err(Error::InvalidArgument("no isosurface extracted yet".into()));
    };
    let mut est = CurvatureEstimator::from_device(iso.gpu.clone(), nv, faces, nf, opts)?;
    // Normalize by the volume's box: centre and half diagonal (world units).
    let d = iso.dims;
    let center: [f64; 3] =
        std::array::from_fn(|i| iso.origin[i] + 0.5 * iso.spacing[i] * (d[i] as f64 - 1.0));
    let half = (0..3)
        .map(|i| (0.5 * iso.spacing[i] * (d[i] as f64 - 1.0)).powi(2))
        .sum::<f64>()
        .sqrt();
    let norm = Normalization {
        center,
        scale: if half > 0.0 { half } else { 1.0 },
    };
    est.set_positions_device(pos, iso.spacing, iso.origin, norm)?;
    if normals == IsoNormals::Gradient {
        est.set_normal_override(Some(iso.gradient_normals()?));
    }
    let timing = est.run()?;
    Ok((est, timing))
}

/// True when triangles with a corner on a grid point (records of
/// `mc_direct_triangles`: face, three corners, 1 if in a grid plane) include
/// an opposite twin pair: the same three vertices, both windings.
fn hit_twins(rec: &[u32]) -> bool {
    let mut seen: std::collections::HashMap<[u32; 3], u8> = Default::default();
    for r in rec.chunks_exact(5).filter(|r| r[4] != 0) {
        let (set, even) = crate::cpu::vertex_fusion::tri_set([r[1], r[2], r[3]]);
        let w = seen.entry(set).or_default();
        *w |= if even { 1 } else { 2 };
        if *w == 3 {
            return true;
        }
    }
    false
}

/// Room for the list of triangles with a corner on a grid point, which the
/// host checks for twins: at most 5 per cell and 4 cells per hit edge, and
/// at most every triangle; capped at 2^21 records (40 MB), past which the
/// list overflows and the fusion clean-up runs instead (volumes with that
/// many hits, such as integer data at a voxel value, need it anyway).
fn side_records(hits: usize, triangles: usize) -> usize {
    (20 * hits).min(triangles).min(1 << 21)
}

#[cfg(test)]
mod tests {
    #[test]
    fn hit_twins_finds_opposite_windings_in_grid_planes_only() {
        use super::hit_twins;
        assert!(hit_twins(&[0, 1, 2, 3, 1, 9, 3, 2, 1, 1]));
        assert!(hit_twins(&[0, 1, 2, 3, 1, 9, 2, 1, 3, 0, 7, 1, 3, 2, 1]));
        // Same winding (rotations), or not in a grid plane: no twins.
        assert!(!hit_twins(&[0, 1, 2, 3, 1, 9, 2, 3, 1, 1]));
        assert!(!hit_twins(&[0, 1, 2, 3, 1, 9, 3, 2, 1, 0]));
    }
}
