//! Host wiring of the soup variants of `kernels/marching_cubes.cl` (Fusion
//! hash, edge, none): `mc_classify` → scan → `mc_triangles`, then vertex
//! fusion ([`crate::stages::vertex_fusion`]) or, unfused, `mc_iota`. The soup
//! is sized exactly from the classify counts; the kernels still check a
//! capacity and count what would not fit, so a bug can never write past a
//! buffer. CPU twin: [`crate::cpu::marching_cubes::mc_triangles`].

use super::{Holder, IsoStats, Isosurfacer};
use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::marching_cubes::McKernel;
use crate::spec::marching_cubes::{edge_key_bits, soup_vertices_bound};
use crate::spec::timing::Step;
use crate::spec::vertex_fusion::{Fusion, FusionCounts};
use crate::stages::vertex_fusion::Grow;
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
        let [nx, ny, nz] = self.dims;
        let voxels = nx * ny * nz;
        let s = &mut self.soup;
        let common = [
            Arg::U32(rows as u32),
            Arg::U32(nx as u32),
            Arg::U32(ny as u32),
            buf(&self.vol),
            Arg::F32(iso),
        ];
        let mut a = common.to_vec();
        a.extend([buf(&self.counts), buf(&s.row_tris)]);
        let e_cls = launch(&g, &s.classify, rows, &a)?;
        let tris = self.scan.exclusive(&s.row_tris, &s.row_off, rows)? as usize;
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
        s.pos.reserve(&g, 3 * soup)?;
        if fusion != Fusion::None {
            s.key.reserve(&g, soup)?;
            s.idx.reserve(&g, soup)?;
        }
        g.write(&mut s.counters, &[0, 0])?;
        let mut a = common.to_vec();
        a.extend([
            buf(&self.counts),
            buf(&self.tris),
            buf(&s.row_off),
            Arg::U32(soup as u32),
            Arg::U32(fusion.code()),
            buf(&s.pos.buf),
            buf(&s.key.buf),
            buf(&s.idx.buf),
            buf(&s.counters),
        ]);
        let e_tri = launch(&g, &s.triangles, rows, &a)?;
        let mut c = [0u32; 2];
        g.read(&s.counters, &mut c)?;
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
                s.faces.reserve(&g, soup)?;
                let e = launch(
                    &g,
                    &s.iota,
                    soup,
                    &[Arg::U32(soup as u32), buf(&s.faces.buf)],
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
                    _ => edge_key_bits(voxels).expect("checked by extract"),
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
                self.result = Some((Holder::Fused, vertices, faces));
            }
        }
        Ok(())
    }
}
