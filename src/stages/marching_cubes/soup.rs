//! Host wiring of the soup variants of `kernels/marching_cubes.cl` (Fusion
//! hash, edge, none): `mc_classify` → scan → `mc_triangles`, then vertex
//! fusion ([`crate::stages::vertex_fusion`]) or, unfused, `mc_iota`. The soup
//! is sized exactly from the classify counts; the kernels still check a
//! capacity and count what would not fit, so a bug can never write past a
//! buffer. CPU twin: [`crate::cpu::marching_cubes::mc_triangles`].

use super::{Holder, IsoStats, Isosurfacer, add_event};
use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, launch};
use crate::spec::marching_cubes::McKernel;
use crate::spec::marching_cubes::{edge_key_bits, soup_vertices_bound};
use crate::spec::timing::Step;
use crate::spec::vertex_fusion::{Fusion, FusionCounts};
use crate::stages::scan::Scan;
use crate::stages::vertex_fusion::{Fuser, Grow};
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use opencl3::program::Program;

/// The soup kernels and buffers.
pub(super) struct Soup {
    classify: Kernel,
    triangles: Kernel,
    iota: Kernel,
    row_tris: Buffer<u32>,
    row_off: Buffer<u32>,
    counters: Buffer<u32>,
    /// Soup positions (3 floats per soup vertex, index space).
    pub(super) pos: Grow<f32>,
    key: Grow<u32>,
    idx: Grow<u32>,
    /// Faces of the unfused soup (`mc_iota`).
    pub(super) faces: Grow<u32>,
}

impl Soup {
    /// The kernels of program `p` (`kernels/marching_cubes.cl`) and the
    /// buffers of a volume of `rows` cell rows.
    pub(super) fn new(gpu: &Gpu, p: &Program, rows: usize) -> Result<Self> {
        Ok(Soup {
            classify: gpu.entry(p, McKernel::Classify)?,
            triangles: gpu.entry(p, McKernel::Triangles)?,
            iota: gpu.entry(p, McKernel::Iota)?,
            row_tris: gpu.buffer::<u32>(rows)?,
            row_off: gpu.buffer::<u32>(rows)?,
            counters: gpu.buffer::<u32>(2)?,
            pos: Grow::new(gpu)?,
            key: Grow::new(gpu)?,
            idx: Grow::new(gpu)?,
            faces: Grow::new(gpu)?,
        })
    }

    /// Device bytes held now (`rows` cell rows).
    pub(super) fn device_bytes(&self, rows: u64) -> u64 {
        8 * rows + self.pos.bytes() + self.key.bytes() + self.idx.bytes() + self.faces.bytes()
    }
}

/// One soup extraction's device, buffers and the arguments its kernels
/// share; its methods are the family's steps, in the order they run.
struct SoupPass<'a> {
    g: &'a Gpu,
    s: &'a mut Soup,
    scan: &'a mut Scan,
    fuser: &'a mut Fuser,
    iso: f32,
    fusion: Fusion,
    /// Cell rows (at least one) and voxels.
    rows: usize,
    voxels: usize,
    /// Cell rows, nx, ny, the volume and the iso value.
    common: [Arg; 5],
    /// The case table's triangle counts and triangles.
    counts: Arg,
    tris: Arg,
}

impl Isosurfacer {
    /// The soup of `value = iso`, then fused by `fusion` (hash or edge) or
    /// left unfused (none); `rows` cell rows, at least one.
    pub(super) fn extract_soup(
        &mut self,
        iso: f32,
        fusion: Fusion,
        rows: usize,
        st: &mut IsoStats,
    ) -> Result<()> {
        let g = self.gpu.clone();
        let mut p = SoupPass::new(self, &g, iso, fusion, rows);
        let e_cls = p.classify()?;
        let tris = p.scan()?;
        add_event(st, Step::McClassify, &e_cls);
        st.timing.add(Step::ScanExclusive, p.scan.last_ms());
        let soup = p.check_room(tris)?;
        p.triangles(soup, st)?;
        st.soup_triangles = tris;
        st.soup_vertices = soup;
        let result = match fusion {
            Fusion::None => p.iota(soup, tris, st)?,
            _ => p.fuse(soup, st)?,
        };
        self.result = Some(result);
        Ok(())
    }
}

impl<'a> SoupPass<'a> {
    /// Borrows the soup kernels, the scan and the fuser of `iz` for one
    /// extraction of `value = iso` over `rows` cell rows on `g`.
    fn new(iz: &'a mut Isosurfacer, g: &'a Gpu, iso: f32, fusion: Fusion, rows: usize) -> Self {
        let [nx, ny, nz] = iz.dims;
        SoupPass {
            g,
            common: [
                Arg::U32(rows as u32),
                Arg::U32(nx as u32),
                Arg::U32(ny as u32),
                buf(&iz.vol),
                Arg::F32(iso),
            ],
            counts: buf(&iz.counts),
            tris: buf(&iz.tris),
            s: &mut iz.soup,
            scan: &mut iz.scan,
            fuser: &mut iz.fuser,
            iso,
            fusion,
            rows,
            voxels: nx * ny * nz,
        }
    }

    /// `mc_classify`: the triangles of each cell row.
    fn classify(&mut self) -> Result<Option<Event>> {
        let mut a = self.common.to_vec();
        a.extend([self.counts, buf(&self.s.row_tris)]);
        launch(self.g, &self.s.classify, self.rows, &a)
    }

    /// The scan of the row counts into row offsets; returns the triangles.
    fn scan(&mut self) -> Result<usize> {
        let s = &self.s;
        Ok(self.scan.exclusive(&s.row_tris, &s.row_off, self.rows)? as usize)
    }

    /// Refuses `tris` triangles past the 32-bit soup index or the device's
    /// memory; returns the soup's vertices.
    fn check_room(&self, tris: usize) -> Result<usize> {
        let (g, iso) = (self.g, self.iso);
        let soup = soup_vertices_bound(tris);
        if soup as u64 > u32::MAX as u64 {
            return Err(Error::InvalidArgument(format!(
                "iso {iso}: {tris} triangles exceed the 32-bit soup index"
            )));
        }
        let need = crate::spec::marching_cubes::device_bytes_bound(self.voxels, self.rows, soup);
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
        Ok(soup)
    }

    /// `mc_triangles`: the soup of `soup` vertices, each with its key
    /// (buffers sized first); waits for it and refuses one that overflowed.
    fn triangles(&mut self, soup: usize, st: &mut IsoStats) -> Result<()> {
        let (g, fusion) = (self.g, self.fusion);
        let s = &mut *self.s;
        s.pos.reserve(g, 3 * soup)?;
        if fusion != Fusion::None {
            s.key.reserve(g, soup)?;
            s.idx.reserve(g, soup)?;
        }
        g.write(&mut s.counters, &[0, 0])?;
        let mut a = self.common.to_vec();
        a.extend([
            self.counts,
            self.tris,
            buf(&s.row_off),
            Arg::U32(soup as u32),
            Arg::U32(fusion.code()),
            buf(&s.pos.buf),
            buf(&s.key.buf),
            buf(&s.idx.buf),
            buf(&s.counters),
        ]);
        let e_tri = launch(g, &s.triangles, self.rows, &a)?;
        let mut c = [0u32; 2];
        g.read(&s.counters, &mut c)?;
        add_event(st, Step::McTriangles, &e_tri);
        if c[0] != 0 {
            return Err(Error::InvalidArgument(format!(
                "internal: mc_triangles produced {} more soup vertices than mc_classify counted \
                 ({soup}); nothing was written past the buffer",
                c[0]
            )));
        }
        Ok(())
    }

    /// `mc_iota`: the unfused soup's faces, `tris` of them over `soup`
    /// vertices; returns the result.
    fn iota(
        &mut self,
        soup: usize,
        tris: usize,
        st: &mut IsoStats,
    ) -> Result<(Holder, usize, usize)> {
        let (g, s) = (self.g, &mut *self.s);
        s.faces.reserve(g, soup)?;
        let a = [Arg::U32(soup as u32), buf(&s.faces.buf)];
        let e = launch(g, &s.iota, soup, &a)?;
        g.finish()?;
        add_event(st, Step::McIota, &e);
        st.vertices = soup;
        st.faces = tris;
        Ok((Holder::Soup, soup, tris))
    }

    /// Vertex fusion of the soup's `soup` vertices by their keys (hash or
    /// edge); returns the result.
    fn fuse(&mut self, soup: usize, st: &mut IsoStats) -> Result<(Holder, usize, usize)> {
        let key_bits = match self.fusion {
            Fusion::Hash => 32,
            _ => edge_key_bits(self.voxels).expect("checked by extract"),
        };
        let s = &mut *self.s;
        let (
            FusionCounts {
                vertices,
                faces,
                dropped,
            },
            ft,
        ) = self.fuser.fuse(
            self.fusion,
            &mut s.key.buf,
            &mut s.idx.buf,
            &s.pos.buf,
            soup,
            key_bits,
        )?;
        st.vertices = vertices;
        st.faces = faces;
        st.degenerate_dropped = dropped;
        st.timing.extend(&ft);
        Ok((Holder::Fused, vertices, faces))
    }
}
