use shapecue::gpu::{Gpu, KernelFile};
fn main() {
    let gpu = Gpu::new(None).unwrap();
    let full = include_str!("../kernels/curvature.cl");
    // keep the helper section and only a few kernels
    let cut = full.find("// Sums the corners").unwrap();
    let helpers = &full[..cut];
    let extra = r#"
__kernel void t_tri(uint nf, __global const REAL *pos, __global const uint *faces, __global REAL *out)
{
    GID_OR_RETURN(nf);
    Tri t = load_tri(pos, faces, gid);
    out[gid] = t.e0.x + t.e1.y + t.psum;
}
__kernel void t_deg(uint nf, __global const REAL *pos, __global const uint *faces, __global REAL *out)
{
    GID_OR_RETURN(nf);
    Tri t = load_tri(pos, faces, gid);
    out[gid] = tri_degenerate(t) ? 0 : 1;
}
__kernel void t_st3(uint nf, __global const REAL *pos, __global const uint *faces, __global REAL *out)
{
    GID_OR_RETURN(nf);
    V3 a = ld3(pos, gid);
    st_corner(out, nf, gid, 0, true, v4(a.x, a.y, a.z, 1));
    st_corner(out, nf, gid, 1, true, v4(a.y, a.y, a.z, 1));
    st_corner(out, nf, gid, 2, true, v4(a.z, a.y, a.z, 1));
}
__kernel void t_st1(uint nf, __global const REAL *pos, __global const uint *faces, __global REAL *out)
{
    GID_OR_RETURN(nf);
    V3 a = ld3(pos, gid);
    out[3 * gid] = a.x; out[3 * gid + 1] = a.y; out[3 * gid + 2] = a.z;
    out[3 * nf + 3 * gid] = a.x; out[3 * nf + 3 * gid + 1] = a.y; out[3 * nf + 3 * gid + 2] = a.z;
}
"#;
    let src: &'static str = Box::leak(format!("{helpers}{extra}").into_boxed_str());
    let f = KernelFile { name: "probe.cl", source: src, headers: shapecue::gpu::COMMON_HEADERS };
    let p = gpu.program(&f, "").unwrap();
    let n = 1000usize;
    let mut a = gpu.buffer::<f32>(4 * n).unwrap();
    gpu.write(&mut a, &vec![1.0f32; 4 * n]).unwrap();
    let b = gpu.buffer::<f32>(12 * n).unwrap();
    let c = gpu.buffer::<f32>(4 * n).unwrap();
    use shapecue::gpu::{launch, buf, Arg};
    let mut fb = gpu.buffer::<u32>(3 * n).unwrap();
    gpu.write(&mut fb, &(0..3 * n as u32).map(|i| i % 300).collect::<Vec<_>>()).unwrap();
    for k in ["t_tri", "t_deg", "t_st3", "t_st1"] {
        let kk = gpu.kernel(&p, k).unwrap();
        launch(&gpu, &kk, n, &[Arg::U32(n as u32), buf(&a), buf(&fb), buf(&b)]).unwrap();
    }
    gpu.finish().unwrap();
}
