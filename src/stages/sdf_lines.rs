//! Host wiring of `kernels/sdf_lines.cl`: curvature-directed strokes on a
//! scalar volume, every step on the device (see the kernel file's header for
//! the steps and buffers). The volume and its gradient stay on the device;
//! each [`SdfLines::run`] chains dense samples → Poisson-disk thinning →
//! curvature at the seeds → κ1 range → tracing → strips and reads back only
//! the counts, then the seeds and strokes. CPU twin:
//! [`crate::cpu::sdf_lines`], with the same output type.
//!
//! Bounds: the dense samples are appended with a counter into a buffer that
//! grows (re-running the step) up to the caller's bound; the Poisson grid,
//! the traced points and the strip vertices are sized by the bound functions
//! of [`crate::spec::sdf_lines`]; exceeding a bound is an error that names
//! the count. Nothing is ever written past a buffer (kernels check
//! capacities and count what did not fit).

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::sdf_lines::SdflKernel;
use crate::spec::sdf_lines::*;
use crate::stages::kernel_files;
use crate::stages::scan::Scan;
use crate::volume::Volume;
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::{Buffer, CL_MEM_READ_ONLY};
use std::sync::Arc;
use std::time::Instant;

/// Initial capacity of the dense-sample buffer (grown up to the bound).
const DENSE_START: usize = 1 << 20;

struct Kernels {
    dense: Kernel,
    cell_count: Kernel,
    cell_fill: Kernel,
    thin_phase: Kernel,
    thin_flags: Kernel,
    thin_compact: Kernel,
    gradient: Kernel,
    curvature: Kernel,
    range: Kernel,
    trace: Kernel,
    strips: Kernel,
}

/// Seeds on the device after a thinning.
struct SeedBufs {
    count: usize,
    pos: Buffer<f32>,
}

/// The Poisson grid of one thinning: `d` dense samples, `nc` cells
/// (`grid` per axis); each sample's cell, the cells' counts (later the kept
/// flags), offsets, fill cursors and sample lists, and each cell's kept
/// sample.
struct Cells {
    d: usize,
    nc: usize,
    grid: [u32; 4],
    cell: Buffer<u32>,
    count: Buffer<u32>,
    off: Buffer<u32>,
    fill: Buffer<u32>,
    items: Buffer<u32>,
    kept: Buffer<u32>,
}

impl Cells {
    /// The buffers, counts and fill cursors zeroed, no sample kept.
    fn new(g: &Gpu, d: usize, nc: usize, grid: [u32; 4]) -> Result<Self> {
        let (cell, mut count, off) = (g.buffer(d)?, g.buffer(nc)?, g.buffer(nc)?);
        let (mut fill, items, mut kept) = (g.buffer(nc)?, g.buffer(d)?, g.buffer(nc)?);
        g.zero(&mut count, nc)?;
        g.zero(&mut fill, nc)?;
        fill_u32(g, &mut kept, nc, NONE)?;
        Ok(Cells {
            d,
            nc,
            grid,
            cell,
            count,
            off,
            fill,
            items,
            kept,
        })
    }
}

/// The traced strokes on the device: points and normals (4 floats per
/// slot, `slots` of them), per stroke its first point, count and centre
/// (`meta`, 4 each), width, strip vertices and their offsets.
struct Traced {
    slots: usize,
    pts: Buffer<f32>,
    nrm: Buffer<f32>,
    meta: Buffer<u32>,
    wid: Buffer<f32>,
    nverts: Buffer<u32>,
    voff: Buffer<u32>,
}

/// The strokes' strips on the device (4 floats per vertex) and their
/// vertex count.
struct Strips {
    strip: Buffer<f32>,
    nv: usize,
}

/// Curvature-directed strokes of one volume on the device.
pub struct SdfLines {
    gpu: Arc<Gpu>,
    opts: SdfLineOptions,
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    dense_bound: usize,
    k: Kernels,
    scan: Scan,
    vol: Buffer<f32>,
    grad: Option<Buffer<f32>>,
    params: Buffer<SdflParams>,
    dense_pos: Buffer<f32>,
    dense_key: Buffer<u32>,
    dense_cap: usize,
    dense_count: Option<usize>,
    counter: Buffer<u32>,
    ms: StepMs,
}

fn ms(events: &[Event]) -> f64 {
    events.iter().map(event_ms).sum()
}

impl SdfLines {
    /// Uploads `vol` and builds the kernels.
    ///
    /// # Errors
    ///
    /// Invalid options (non-finite iso), a volume of 2³²/3 voxels or more, or
    /// one the device cannot hold, or an OpenCL failure.
    pub fn new(gpu: Arc<Gpu>, vol: &Volume, opts: &SdfLineOptions) -> Result<SdfLines> {
        let dense_bound = check_for(vol.dims, opts)?;
        let p = gpu.program(&kernel_files::SDF_LINES, "")?;
        let kernel = |k: SdflKernel| gpu.entry(&p, k);
        let k = Kernels {
            dense: kernel(SdflKernel::Dense)?,
            cell_count: kernel(SdflKernel::CellCount)?,
            cell_fill: kernel(SdflKernel::CellFill)?,
            thin_phase: kernel(SdflKernel::ThinPhase)?,
            thin_flags: kernel(SdflKernel::ThinFlags)?,
            thin_compact: kernel(SdflKernel::ThinCompact)?,
            gradient: kernel(SdflKernel::Gradient)?,
            curvature: kernel(SdflKernel::Curvature)?,
            range: kernel(SdflKernel::Range)?,
            trace: kernel(SdflKernel::Trace)?,
            strips: kernel(SdflKernel::Strips)?,
        };
        let mut volb = gpu.buffer_flags::<f32>(vol.voxel_count(), CL_MEM_READ_ONLY)?;
        gpu.write(&mut volb, &vol.values)?;
        let cap = DENSE_START.min(dense_bound).max(1);
        Ok(SdfLines {
            opts: opts.clone(),
            dims: vol.dims,
            spacing: vol.spacing,
            origin: vol.origin,
            dense_bound,
            k,
            scan: Scan::new(gpu.clone())?,
            vol: volb,
            grad: None,
            params: gpu.buffer(1)?,
            dense_pos: gpu.buffer(3 * cap)?,
            dense_key: gpu.buffer(cap)?,
            dense_cap: cap,
            dense_count: None,
            counter: gpu.buffer(2)?,
            ms: StepMs::default(),
            gpu,
        })
    }

    /// The device.
    pub fn gpu(&self) -> &Arc<Gpu> {
        &self.gpu
    }

    fn set_params(&mut self, p: &SdflParams) -> Result<()> {
        self.gpu.write(&mut self.params, std::slice::from_ref(p))
    }

    fn base_params(&self, res: &Resolved) -> SdflParams {
        params_for(self.dims, self.spacing, &self.opts, res)
    }

    fn n_voxels(&self) -> usize {
        self.dims.iter().product()
    }

    /// `sdfl_dense` (once per instance; grows its buffer up to the bound).
    fn ensure_dense(&mut self) -> Result<usize> {
        if let Some(n) = self.dense_count {
            return Ok(n);
        }
        let res = resolve(&self.opts, self.spacing, voxel_size(self.spacing))?;
        let p = self.base_params(&res);
        self.set_params(&p)?;
        let n = self.n_voxels();
        loop {
            self.gpu.zero(&mut self.counter, 1)?;
            let ev = launch(
                &self.gpu,
                &self.k.dense,
                n,
                &[
                    Arg::U32(n as u32),
                    buf(&self.params),
                    buf(&self.vol),
                    Arg::U32(self.dense_cap as u32),
                    buf(&self.dense_pos),
                    buf(&self.dense_key),
                    buf(&self.counter),
                ],
            )?;
            let mut c = [0u32; 1];
            self.gpu.read(&self.counter, &mut c)?;
            self.ms.dense += ev.as_ref().map(event_ms).unwrap_or(0.0);
            let count = c[0] as usize;
            if count > self.dense_bound {
                return Err(dense_overflow(count, self.dense_bound));
            }
            if count <= self.dense_cap {
                self.dense_count = Some(count);
                return Ok(count);
            }
            self.dense_cap = count;
            self.dense_pos = self.gpu.buffer(3 * count)?;
            self.dense_key = self.gpu.buffer(count)?;
        }
    }

    /// The dense surface samples (device order, which is not fixed: sort by
    /// key to compare).
    ///
    /// # Errors
    ///
    /// More samples than the bound (naming the count), or an OpenCL failure.
    pub fn dense(&mut self) -> Result<Vec<DenseSample>> {
        let n = self.ensure_dense()?;
        let mut pos = vec![0f32; 3 * n];
        let mut key = vec![0u32; n];
        self.gpu.read(&self.dense_pos, &mut pos)?;
        self.gpu.read(&self.dense_key, &mut key)?;
        Ok((0..n)
            .map(|i| DenseSample {
                p: [pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]],
                key: key[i],
            })
            .collect())
    }

    /// Poisson-disk thinning with spacing `r`: seed positions on the device.
    fn thin_device(&mut self, r: f64) -> Result<SeedBufs> {
        let d = self.ensure_dense()?;
        let (p, nc) = self.thin_params(r)?;
        let c = Cells::new(&self.gpu, d, nc, p.cells)?;
        let mut events = Vec::new();
        let mut scan_ms = self.cell_bins(&c, &mut events)?;
        self.thin_phases(&c, &mut events)?;
        let (seeds, ms2) = self.thin_compact(&c, &mut events)?;
        scan_ms += ms2;
        self.gpu.finish()?;
        self.ms.thin += ms(&events) + scan_ms;
        Ok(seeds)
    }

    /// The parameters of a thinning with spacing `r` (written to the
    /// device) and its count of Poisson grid cells.
    fn thin_params(&mut self, r: f64) -> Result<(SdflParams, usize)> {
        let res = resolve(
            &SdfLineOptions {
                spacing: Some(r),
                ..self.opts.clone()
            },
            self.spacing,
            voxel_size(self.spacing),
        )?;
        let p = self.base_params(&res);
        let nc = cell_count(&p, self.opts.max_cells, r)?;
        self.set_params(&p)?;
        Ok((p, nc))
    }

    /// `sdfl_cell_count`, the scan of the counts and `sdfl_cell_fill`: the
    /// dense samples binned into the cells; returns the scan's ms.
    fn cell_bins(&mut self, c: &Cells, events: &mut Vec<Event>) -> Result<f64> {
        let (g, d) = (&self.gpu, Arg::U32(c.d as u32));
        let a = [
            d,
            buf(&self.params),
            buf(&self.dense_pos),
            buf(&c.cell),
            buf(&c.count),
        ];
        events.extend(launch(g, &self.k.cell_count, c.d, &a)?);
        self.scan.exclusive(&c.count, &c.off, c.nc)?;
        let scan_ms = self.scan.last_ms();
        let a = [d, buf(&c.cell), buf(&c.off), buf(&c.fill), buf(&c.items)];
        events.extend(launch(g, &self.k.cell_fill, c.d, &a)?);
        Ok(scan_ms)
    }

    /// `sdfl_thin_phase`, 27 times: the cells of one phase of the 3 × 3 × 3
    /// pattern at a time keep their samples.
    fn thin_phases(&mut self, c: &Cells, events: &mut Vec<Event>) -> Result<()> {
        let cells = c.grid;
        for phase in 0..27u32 {
            let (px, py, pz) = (phase % 3, phase / 3 % 3, phase / 9);
            let per = |g: u32, o: u32| (g.saturating_sub(o)).div_ceil(3) as usize;
            let n = per(cells[0], px) * per(cells[1], py) * per(cells[2], pz);
            events.extend(launch(
                &self.gpu,
                &self.k.thin_phase,
                n,
                &[
                    Arg::U32(n as u32),
                    buf(&self.params),
                    Arg::U32(px),
                    Arg::U32(py),
                    Arg::U32(pz),
                    buf(&self.dense_pos),
                    buf(&self.dense_key),
                    buf(&c.off),
                    buf(&c.count),
                    buf(&c.items),
                    buf(&c.kept),
                ],
            )?);
        }
        Ok(())
    }

    /// `sdfl_thin_flags`, their scan and `sdfl_thin_compact`: the kept
    /// samples listed as seeds; returns them and the scan's ms.
    fn thin_compact(&mut self, c: &Cells, events: &mut Vec<Event>) -> Result<(SeedBufs, f64)> {
        let (g, nc) = (self.gpu.clone(), c.nc);
        // Flags into `count` (no longer needed), offsets into `off`.
        let a = [Arg::U32(nc as u32), buf(&c.kept), buf(&c.count)];
        events.extend(launch(&g, &self.k.thin_flags, nc, &a)?);
        let s = self.scan.exclusive(&c.count, &c.off, nc)? as usize;
        let scan_ms = self.scan.last_ms();
        let seeds = g.buffer::<u32>(s)?;
        let pos = g.buffer::<f32>(3 * s)?;
        events.extend(launch(
            &g,
            &self.k.thin_compact,
            nc,
            &[
                Arg::U32(nc as u32),
                buf(&c.kept),
                buf(&c.off),
                buf(&self.dense_pos),
                buf(&seeds),
                buf(&pos),
            ],
        )?);
        Ok((SeedBufs { count: s, pos }, scan_ms))
    }

    /// Kept sample positions (local world) for spacing `r`, in cell order.
    ///
    /// # Errors
    ///
    /// A bound exceeded (naming the count) or an OpenCL failure.
    pub fn thin(&mut self, r: f64) -> Result<Vec<[f32; 3]>> {
        let s = self.thin_device(r)?;
        let mut v = vec![0f32; 3 * s.count];
        self.gpu.read(&s.pos, &mut v)?;
        Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
    }

    fn ensure_gradient(&mut self) -> Result<()> {
        if self.grad.is_some() {
            return Ok(());
        }
        let n = self.n_voxels();
        let res = resolve(&self.opts, self.spacing, voxel_size(self.spacing))?;
        let p = self.base_params(&res);
        self.set_params(&p)?;
        let grad = self.gpu.buffer::<f32>(3 * n)?;
        let ev = launch(
            &self.gpu,
            &self.k.gradient,
            n,
            &[
                Arg::U32(n as u32),
                buf(&self.params),
                buf(&self.vol),
                buf(&grad),
            ],
        )?;
        self.gpu.finish()?;
        self.ms.gradient += ev.as_ref().map(event_ms).unwrap_or(0.0);
        self.grad = Some(grad);
        Ok(())
    }

    /// The gradient volume (world units, raw values), per voxel.
    ///
    /// # Errors
    ///
    /// An OpenCL failure.
    pub fn gradient(&mut self) -> Result<Vec<[f32; 3]>> {
        self.ensure_gradient()?;
        let mut v = vec![0f32; 3 * self.n_voxels()];
        self.gpu
            .read(self.grad.as_ref().expect("gradient"), &mut v)?;
        Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
    }

    /// `sdfl_curvature` at points already on the device; returns the event.
    fn curvature_device(&mut self, pts: &Buffer<f32>, n: usize, h: f64) -> Result<Buffer<f32>> {
        self.ensure_gradient()?;
        let out = self.gpu.buffer::<f32>(9 * n)?;
        let ev = launch(
            &self.gpu,
            &self.k.curvature,
            n,
            &[
                Arg::U32(n as u32),
                buf(&self.params),
                buf(self.grad.as_ref().expect("gradient")),
                Arg::F32(h as f32),
                buf(pts),
                buf(&out),
            ],
        )?;
        self.gpu.finish()?;
        self.ms.curvature += ev.as_ref().map(event_ms).unwrap_or(0.0);
        Ok(out)
    }

    /// Principal curvatures and directions at local world points with
    /// sampling distance `h` (world units).
    ///
    /// # Errors
    ///
    /// An OpenCL failure.
    pub fn curvature_at(&mut self, pts: &[[f32; 3]], h: f64) -> Result<Vec<Principal>> {
        let res = resolve(&self.opts, self.spacing, h)?;
        let p = self.base_params(&res);
        self.set_params(&p)?;
        let mut b = self.gpu.buffer::<f32>(3 * pts.len())?;
        self.gpu.write(&mut b, pts.as_flattened())?;
        let out = self.curvature_device(&b, pts.len(), h)?;
        read_principal(&self.gpu, &out, pts.len())
    }

    /// Runs every step and reads the seeds and strokes back (world units).
    ///
    /// # Errors
    ///
    /// Invalid options, a bound exceeded (the message names the count), or
    /// an OpenCL failure.
    pub fn run(&mut self) -> Result<SdfLinesOutput> {
        let t0 = Instant::now();
        self.ms = StepMs::default();
        let dense = self.ensure_dense()?;
        self.ensure_gradient()?;
        let (h, sweep) = self.sampling_distance()?;
        let res = resolve(&self.opts, self.spacing, h)?;
        let seeds = self.thin_device(res.spacing)?;
        let s = seeds.count;
        check_points(s, &res, self.opts.max_points)?;
        let p = self.base_params(&res);
        self.set_params(&p)?;
        let curv = self.curvature_device(&seeds.pos, s, h)?;
        let range = self.range(&curv, s)?;
        let kk = res.points_per_stroke();
        let traced = self.trace(&seeds, &curv, &range, kk)?;
        let strips = self.strips(&traced, s, kk)?;
        // Read back.
        let (lo, hi) = read_range(&self.gpu, &range)?;
        let mut out = self.read_strokes(&seeds, &curv, &traced, &strips, kk)?;
        out.stats = stats(dense, &out, res, sweep, lo, hi);
        let mut t = self.ms;
        t.total =
            t.dense + t.thin + t.gradient + t.curvature + t.range + t.trace + t.strips + t.sweep;
        out.stats.timing = t.timing(t0.elapsed().as_secs_f64() * 1e3);
        Ok(out)
    }

    /// The Hessian sampling distance: the fixed one, or the candidate whose
    /// κ1 varies least over the seeds of a provisional thinning (the sweep,
    /// returned too, its time counted apart from the run's own steps).
    fn sampling_distance(&mut self) -> Result<(f64, Vec<CvPoint>)> {
        let candidates = sampling_candidates(&self.opts.sampling, self.spacing);
        let mut sweep = Vec::new();
        if let Sampling::Fixed(h) = self.opts.sampling {
            return Ok((h, sweep));
        }
        let before = (self.ms.thin, self.ms.curvature);
        let r0 = self
            .opts
            .spacing
            .unwrap_or(PROVISIONAL_SPACING_VOXELS * voxel_size(self.spacing));
        let s = self.thin_device(r0)?;
        for &hc in &candidates {
            let res = resolve(&self.opts, self.spacing, hc)?;
            let p = self.base_params(&res);
            self.set_params(&p)?;
            let out = self.curvature_device(&s.pos, s.count, hc)?;
            let c = read_principal(&self.gpu, &out, s.count)?;
            let (cv, n) = coefficient_of_variation(c.iter().filter(|c| c.valid).map(|c| c.k1));
            sweep.push(CvPoint {
                distance: hc,
                cv,
                seeds: n,
            });
        }
        self.ms.sweep = (self.ms.thin - before.0) + (self.ms.curvature - before.1);
        self.ms.thin = before.0;
        self.ms.curvature = before.1;
        let h = pick_sampling(&sweep).unwrap_or(candidates[0]);
        Ok((h, sweep))
    }

    /// `sdfl_range`: the κ1 range over the `s` seeds' curvatures `curv`, as
    /// two order-preserving keys.
    fn range(&mut self, curv: &Buffer<f32>, s: usize) -> Result<Buffer<u32>> {
        let g = &self.gpu;
        let mut range = g.buffer::<u32>(2)?;
        g.write(&mut range, &[u32::MAX, 0])?;
        let ev = launch(
            g,
            &self.k.range,
            s,
            &[Arg::U32(s as u32), buf(curv), buf(&range)],
        )?;
        g.finish()?;
        self.ms.range = ev.as_ref().map(event_ms).unwrap_or(0.0);
        Ok(range)
    }

    /// `sdfl_trace`: a stroke of up to `kk` points from each seed.
    fn trace(
        &mut self,
        seeds: &SeedBufs,
        curv: &Buffer<f32>,
        range: &Buffer<u32>,
        kk: usize,
    ) -> Result<Traced> {
        let (g, s) = (&self.gpu, seeds.count);
        let slots = stroke_points_bound(s, kk);
        let t = Traced {
            slots,
            pts: g.buffer::<f32>(4 * slots)?,
            nrm: g.buffer::<f32>(4 * slots)?,
            meta: g.buffer::<u32>(4 * s)?,
            wid: g.buffer::<f32>(s)?,
            nverts: g.buffer::<u32>(s)?,
            voff: g.buffer::<u32>(s)?,
        };
        let ev = launch(
            g,
            &self.k.trace,
            s,
            &[
                Arg::U32(s as u32),
                buf(&self.params),
                buf(&self.vol),
                buf(self.grad.as_ref().expect("gradient")),
                buf(&seeds.pos),
                buf(curv),
                buf(range),
                buf(&t.pts),
                buf(&t.nrm),
                buf(&t.meta),
                buf(&t.wid),
                buf(&t.nverts),
            ],
        )?;
        g.finish()?;
        self.ms.trace = ev.as_ref().map(event_ms).unwrap_or(0.0);
        Ok(t)
    }

    /// The scan of the strokes' strip vertices and `sdfl_strips`: a strip
    /// of two vertices per point of each of the `s` strokes (`kk` points at
    /// most); refuses strips past their bound.
    fn strips(&mut self, t: &Traced, s: usize, kk: usize) -> Result<Strips> {
        let g = self.gpu.clone();
        let nv = self.scan.exclusive(&t.nverts, &t.voff, s)? as usize;
        self.ms.strips = self.scan.last_ms();
        let cap = strip_vertices_bound(s, kk);
        let strip = g.buffer::<f32>(4 * cap.max(1))?;
        let mut overflow = g.buffer::<u32>(1)?;
        g.zero(&mut overflow, 1)?;
        let ev = launch(
            &g,
            &self.k.strips,
            s,
            &[
                Arg::U32(s as u32),
                buf(&self.params),
                buf(&t.pts),
                buf(&t.nrm),
                buf(&t.meta),
                buf(&t.wid),
                buf(&t.nverts),
                buf(&t.voff),
                Arg::U32(cap as u32),
                buf(&strip),
                buf(&overflow),
            ],
        )?;
        g.finish()?;
        self.ms.strips += ev.as_ref().map(event_ms).unwrap_or(0.0);
        let mut of = [0u32];
        g.read(&overflow, &mut of)?;
        if of[0] > 0 || nv > cap {
            return Err(Error::InvalidArgument(format!(
                "curvature-directed strokes: {nv} strip vertices exceed the bound of {cap}"
            )));
        }
        Ok(Strips { strip, nv })
    }

    /// Reads the seeds (with their curvatures `curv`) and the strokes of at
    /// most `kk` points back, in world units.
    fn read_strokes(
        &self,
        seeds: &SeedBufs,
        curv: &Buffer<f32>,
        t: &Traced,
        strips: &Strips,
        kk: usize,
    ) -> Result<SdfLinesOutput> {
        let (g, s, nv) = (&self.gpu, seeds.count, strips.nv);
        let c = read_principal(g, curv, s)?;
        let mut sp = vec![0f32; 3 * s];
        g.read(&seeds.pos, &mut sp)?;
        let mut m = vec![0u32; 4 * s];
        g.read(&t.meta, &mut m)?;
        let mut pv = vec![0f32; 4 * t.slots];
        let mut nvv = vec![0f32; 4 * t.slots];
        g.read(&t.pts, &mut pv)?;
        g.read(&t.nrm, &mut nvv)?;
        let mut sv = vec![0f32; 4 * nv];
        g.read(&strips.strip, &mut sv)?;
        let mut vo = vec![0u32; s];
        g.read(&t.voff, &mut vo)?;
        let o = self.origin;
        let world = |q: &[f32]| -> [f64; 3] { std::array::from_fn(|a| q[a] as f64 + o[a]) };
        let v3 = |q: &[f32]| -> [f64; 3] { std::array::from_fn(|a| q[a] as f64) };
        let mut out = SdfLinesOutput::default();
        for i in 0..s {
            out.seeds.push(Seed {
                p: world(&sp[3 * i..]),
                n: c[i].n,
                k1: c[i].k1,
                k2: c[i].k2,
                d1: c[i].d1,
                valid: c[i].valid,
            });
            let (first, count, nb) = (m[4 * i] as usize, m[4 * i + 1] as usize, m[4 * i + 2]);
            if count < 2 {
                continue;
            }
            let base = i * kk + first;
            let mut st = Stroke {
                seed: i,
                centre: nb as usize,
                ..Default::default()
            };
            for j in 0..count {
                let q = 4 * (base + j);
                st.points.push(world(&pv[q..]));
                st.normals.push(v3(&nvv[q..]));
            }
            let vb = vo[i] as usize;
            for j in 0..2 * count {
                st.strip.push(world(&sv[4 * (vb + j)..]));
            }
            st.widths = (0..count)
                .map(|j| sv[4 * (vb + 2 * j) + 3] as f64)
                .collect();
            out.strokes.push(st);
        }
        Ok(out)
    }
}

/// The κ1 range the seeds span, from `sdfl_range`'s two keys ((0, 0) when
/// no seed had a valid curvature).
fn read_range(g: &Gpu, range: &Buffer<u32>) -> Result<(f64, f64)> {
    let mut rg = [0u32; 2];
    g.read(range, &mut rg)?;
    Ok(if rg[0] <= rg[1] {
        (unordered(rg[0]) as f64, unordered(rg[1]) as f64)
    } else {
        (0.0, 0.0)
    })
}

/// Inverse of the kernel's order-preserving float → uint map.
fn unordered(k: u32) -> f32 {
    f32::from_bits(if k & 0x8000_0000 != 0 {
        k & 0x7FFF_FFFF
    } else {
        !k
    })
}

fn fill_u32(gpu: &Gpu, b: &mut Buffer<u32>, n: usize, v: u32) -> Result<()> {
    if n == 0 {
        return Ok(());
    }
    // SAFETY: the pattern is copied at enqueue time; n is within the buffer.
    unsafe { gpu.queue().enqueue_fill_buffer(b, &[v], 0, 4 * n, &[]) }
        .map(|_| ())
        .map_err(|e| Error::cl("clEnqueueFillBuffer", e))
}

fn read_principal(gpu: &Gpu, b: &Buffer<f32>, n: usize) -> Result<Vec<Principal>> {
    let mut v = vec![0f32; 9 * n];
    gpu.read(b, &mut v)?;
    Ok(v.chunks_exact(9)
        .map(|c| Principal {
            n: [c[0] as f64, c[1] as f64, c[2] as f64],
            k1: c[3] as f64,
            k2: c[4] as f64,
            d1: [c[5] as f64, c[6] as f64, c[7] as f64],
            valid: c[8] != 0.0,
        })
        .collect())
}

/// `sdfl_principal_probe`: the device's principal curvature function on
/// given gradients and row-major Hessians (tests).
///
/// # Errors
///
/// An OpenCL failure.
pub fn principal_probe(gpu: &Gpu, g: &[[f32; 3]], h: &[[f32; 9]]) -> Result<Vec<Principal>> {
    let p = gpu.program(&kernel_files::SDF_LINES, "")?;
    let k = gpu.entry(&p, SdflKernel::PrincipalProbe)?;
    let n = g.len().min(h.len());
    let mut gb = gpu.buffer::<f32>(3 * n)?;
    let mut hb = gpu.buffer::<f32>(9 * n)?;
    gpu.write(&mut gb, g[..n].as_flattened())?;
    gpu.write(&mut hb, h[..n].as_flattened())?;
    let out = gpu.buffer::<f32>(9 * n)?;
    launch(
        gpu,
        &k,
        n,
        &[Arg::U32(n as u32), buf(&gb), buf(&hb), buf(&out)],
    )?;
    read_principal(gpu, &out, n)
}

/// `sdfl_probe`: `sizeof(SdflParams)` and the offsets of `iso`, `length`
/// and `seed` on the device (tests check them against the Rust layout).
///
/// # Errors
///
/// An OpenCL failure.
pub fn layout_probe(gpu: &Gpu) -> Result<[u32; 4]> {
    let p = gpu.program(&kernel_files::SDF_LINES, "")?;
    let k = gpu.entry(&p, SdflKernel::Probe)?;
    let out = gpu.buffer::<u32>(4)?;
    launch(gpu, &k, 1, &[buf(&out)])?;
    let mut v = [0u32; 4];
    gpu.read(&out, &mut v)?;
    Ok(v)
}
