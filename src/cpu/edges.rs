//! Plain Rust reference of `kernels/edges.cl` (House & Li), with
//! the same step names: [`edges_detect`], [`caps_mh`], [`caps_adjacency`].
//!
//! Inputs are the device's: the packed parameter block
//! ([`EdgeParamBlock`], from [`crate::spec::edges::EdgeParams::pack`]), f32
//! positions and normals,
//! the edge and cap buffers. The arithmetic is f32 in the kernel's order, so
//! outputs agree with the device up to rounding (fused multiply-adds), and
//! classification can differ only for ties (a face seen exactly edge-on).

use crate::spec::edges::{
    EdgeOutput, EdgeParamBlock, KIND_BOUNDARY, KIND_CONTOUR, KIND_CREASE, KIND_DRAWN, MARKER,
};

type P = EdgeParamBlock;

fn clip(p: &P, v: [f32; 3], h: f32) -> [f32; 4] {
    let m = &p.view_proj;
    let r = |row: usize| m[row] * v[0] + m[4 + row] * v[1] + m[8 + row] * v[2] + m[12 + row] * h;
    [r(0), r(1), r(2), r(3)]
}

fn depth_factor(k: f32, w: f32) -> f32 {
    if k > 0.0 { (k / w).max(1.0) } else { 1.0 }
}

fn screen(p: &P, sx: f32, sy: f32, z: f32, w: f32) -> [f32; 4] {
    [sx / p.half_vw * w, sy / p.half_vh * w, z, w]
}

/// Screen points, unit perpendicular and scaled half widths of edge `i0 → i1`.
struct Projected {
    c0: [f32; 4],
    c1: [f32; 4],
    s0: [f32; 2],
    s1: [f32; 2],
    perp: [f32; 2],
    f0: f32,
    f1: f32,
}

fn project(p: &P, a: [f32; 3], b: [f32; 3]) -> Projected {
    let (c0, c1) = (clip(p, a, 1.0), clip(p, b, 1.0));
    let (hvw, hvh, hw) = (p.half_vw, p.half_vh, p.half_width);
    let s0 = [c0[0] / c0[3] * hvw, c0[1] / c0[3] * hvh];
    let s1 = [c1[0] / c1[3] * hvw, c1[1] / c1[3] * hvh];
    let (dx, dy) = (s1[0] - s0[0], s1[1] - s0[1]);
    let len = (dx * dx + dy * dy).sqrt();
    let perp = if len > 0.0 {
        [-dy / len, dx / len]
    } else {
        [0.0, 1.0]
    };
    Projected {
        c0,
        c1,
        s0,
        s1,
        perp,
        f0: hw * depth_factor(p.depth_k, c0[3]),
        f1: hw * depth_factor(p.depth_k, c1[3]),
    }
}

fn at(pos: &[[f32; 3]], i: u32) -> [f32; 3] {
    pos[i as usize]
}

/// `edges_detect`: per edge, the kind bits and the quad (4 vertices) or the
/// marker ×4; half quads for contour-only edges when the parameters ask.
pub fn edges_detect(
    p: &P,
    pos: &[[f32; 3]],
    nrm: &[[f32; 3]],
    edges: &[[u32; 4]],
) -> (Vec<[f32; 4]>, Vec<u32>) {
    let mut out = Vec::with_capacity(4 * edges.len());
    let mut kinds = Vec::with_capacity(edges.len());
    for &[i0, i1, i2, i3] in edges {
        let (v0, v1) = (at(pos, i0), at(pos, i1));
        let k = edge_kind(p, pos, [i0, i1, i2, i3]);
        let pr = project(p, v0, v1);
        let drawn = k != 0 && pr.c0[3] > p.w_min && pr.c1[3] > p.w_min;
        if !drawn {
            kinds.push(k);
            out.extend_from_slice(&[MARKER; 4]);
            continue;
        }
        kinds.push(k | KIND_DRAWN);
        edge_quad(p, &pr, nrm, i0, k, &mut out);
    }
    (out, kinds)
}

/// The kind bits of edge entry `[i0, i1, i2, i3]` (faces i0 i1 i2 and
/// i1 i0 i3, or a boundary where i3 == i0): boundary, contour, crease.
fn edge_kind(p: &P, pos: &[[f32; 3]], [i0, i1, i2, i3]: [u32; 4]) -> u32 {
    let (v0, v1, v2, v3) = (at(pos, i0), at(pos, i1), at(pos, i2), at(pos, i3));
    let u = [v1[0] - v0[0], v1[1] - v0[1], v1[2] - v0[2]];
    let v = [v2[0] - v0[0], v2[1] - v0[1], v2[2] - v0[2]];
    let na = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let w = [v3[0] - v1[0], v3[1] - v1[1], v3[2] - v1[2]];
    let nb = [
        w[1] * u[2] - w[2] * u[1],
        w[2] * u[0] - w[0] * u[2],
        w[0] * u[1] - w[1] * u[0],
    ];
    let mut k = 0;
    if i3 == i0 {
        if p.boundaries != 0.0 {
            k |= KIND_BOUNDARY;
        }
    } else {
        let e = if p.ortho != 0.0 {
            p.view_dir.map(|c| -c)
        } else {
            [p.eye[0] - v0[0], p.eye[1] - v0[1], p.eye[2] - v0[2]]
        };
        let da = na[0] * e[0] + na[1] * e[1] + na[2] * e[2];
        let db = nb[0] * e[0] + nb[1] * e[1] + nb[2] * e[2];
        if p.contours != 0.0 && ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
            k |= KIND_CONTOUR;
        }
        let dn = na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2];
        let la = na[0] * na[0] + na[1] * na[1] + na[2] * na[2];
        let lb = nb[0] * nb[0] + nb[1] * nb[1] + nb[2] * nb[2];
        if dn < p.cos_crease * (la * lb).sqrt() {
            k |= KIND_CREASE;
        }
    }
    k
}

/// The quad of a drawn edge from vertex `i0`, of kind `k`, projected as
/// `pr`, pushed onto `out` (4 vertices); a contour-only edge with half
/// quads extends outward by the full width, on the side the projected
/// normal of i0 points to (vertex 0's normal is read otherwise, as in the
/// kernel, and leaves the quad centred).
fn edge_quad(p: &P, pr: &Projected, nrm: &[[f32; 3]], i0: u32, k: u32, out: &mut Vec<[f32; 4]>) {
    let (s0, s1, q, f0, f1) = (pr.s0, pr.s1, pr.perp, pr.f0, pr.f1);
    let (c0, c1) = (pr.c0, pr.c1);
    // Half quads for contour-only edges: outward by the full width.
    let half = p.half_contours != 0.0 && k == KIND_CONTOUR;
    let n = if half { at(nrm, i0) } else { at(nrm, 0) };
    let d = clip(p, n, 0.0);
    let m = [
        (d[0] * c0[3] - c0[0] * d[3]) * p.half_vw,
        (d[1] * c0[3] - c0[1] * d[3]) * p.half_vh,
    ];
    let g = if m[0] * q[0] + m[1] * q[1] >= 0.0 {
        1.0
    } else {
        -1.0
    };
    let (lo, hi) = if half { (0.0, 2.0 * g) } else { (1.0, 1.0) };
    let mut put = |s: [f32; 2], c: [f32; 4], f: f32, t: f32| {
        out.push(screen(
            p,
            s[0] + q[0] * f * t,
            s[1] + q[1] * f * t,
            c[2],
            c[3],
        ));
    };
    put(s0, c0, f0, -lo);
    put(s1, c1, f1, -lo);
    put(s1, c1, f1, hi);
    put(s0, c0, f0, hi);
}

/// `caps_mh`: McGuire-Hughes half-caps at the i0 and i1 ends of every drawn
/// edge (3 vertices each), the marker ×3 for the others.
pub fn caps_mh(
    p: &P,
    pos: &[[f32; 3]],
    nrm: &[[f32; 3]],
    edges: &[[u32; 4]],
    edge_out: &[[f32; 4]],
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let mut o0 = Vec::with_capacity(3 * edges.len());
    let mut o1 = Vec::with_capacity(3 * edges.len());
    for (e, &[i0, i1, _, _]) in edges.iter().enumerate() {
        if edge_out[4 * e][0].is_nan() {
            o0.extend_from_slice(&[MARKER; 3]);
            o1.extend_from_slice(&[MARKER; 3]);
            continue;
        }
        let pr = project(p, at(pos, i0), at(pos, i1));
        let q = pr.perp;
        for (c, s, n, f, o) in [
            (pr.c0, pr.s0, at(nrm, i0), pr.f0, &mut o0),
            (pr.c1, pr.s1, at(nrm, i1), pr.f1, &mut o1),
        ] {
            let d = clip(p, n, 0.0);
            let mx = (d[0] * c[3] - c[0] * d[3]) * p.half_vw;
            let my = (d[1] * c[3] - c[1] * d[3]) * p.half_vh;
            let l = (mx * mx + my * my).sqrt();
            let msz: f32 = [0, 4, 8, 1, 5, 9, 3, 7, 11]
                .iter()
                .map(|&i| p.view_proj[i].abs())
                .sum();
            let tol =
                1e-4 * msz * (c[0].abs() + c[1].abs() + c[3].abs()) * p.half_vw.max(p.half_vh);
            let m = if l > tol && l > 0.0 {
                [mx / l, my / l]
            } else {
                q
            };
            let g = if m[0] * q[0] + m[1] * q[1] >= 0.0 {
                1.0
            } else {
                -1.0
            };
            o.push(screen(p, s[0], s[1], c[2], c[3]));
            o.push(screen(
                p,
                s[0] + q[0] * g * f,
                s[1] + q[1] * g * f,
                c[2],
                c[3],
            ));
            o.push(screen(p, s[0] + m[0] * f, s[1] + m[1] * f, c[2], c[3]));
        }
    }
    (o0, o1)
}

/// `caps_adjacency`: per cap pair, the quad (sM + mv, sM + p0, sM, sM + p1)
/// when both edges are drawn and not collinear in screen space, else the marker ×4.
pub fn caps_adjacency(
    p: &P,
    edges: &[[u32; 4]],
    caps: &[[u32; 2]],
    edge_out: &[[f32; 4]],
) -> Vec<[f32; 4]> {
    let (hvw, hvh) = (p.half_vw, p.half_vh);
    let mut out = Vec::with_capacity(4 * caps.len());
    for &[e0, e1] in caps {
        let q0 = &edge_out[4 * e0 as usize..4 * e0 as usize + 4];
        let q1 = &edge_out[4 * e1 as usize..4 * e1 as usize + 4];
        let (a, b) = (edges[e0 as usize], edges[e1 as usize]);
        let v = if a[0] == b[0] || a[0] == b[1] {
            a[0]
        } else {
            a[1]
        };
        // Slots at end 0: 0 and 3; at end 1: 1 and 2.
        let ma = if v == a[0] { 0 } else { 1 };
        let fa = 3 - ma;
        let (la, lfa) = (1 - ma, 2 + ma);
        let rb = if v == b[0] { 1 } else { 0 };
        let rfb = 3 - rb;
        let mw = q0[ma][3];
        let sm = [
            0.5 * (q0[ma][0] + q0[fa][0]) / mw * hvw,
            0.5 * (q0[ma][1] + q0[fa][1]) / mw * hvh,
        ];
        let h = [
            0.5 * (q0[fa][0] - q0[ma][0]) / mw * hvw,
            0.5 * (q0[fa][1] - q0[ma][1]) / mw * hvh,
        ];
        let hw = (h[0] * h[0] + h[1] * h[1]).sqrt();
        let lw = q0[la][3];
        let sl = [
            0.5 * (q0[la][0] + q0[lfa][0]) / lw * hvw,
            0.5 * (q0[la][1] + q0[lfa][1]) / lw * hvh,
        ];
        let rw = q1[rb][3];
        let sr = [
            0.5 * (q1[rb][0] + q1[rfb][0]) / rw * hvw,
            0.5 * (q1[rb][1] + q1[rfb][1]) / rw * hvh,
        ];
        let dl = [sl[0] - sm[0], sl[1] - sm[1]];
        let dr = [sr[0] - sm[0], sr[1] - sm[1]];
        let ll = (dl[0] * dl[0] + dl[1] * dl[1]).sqrt();
        let lr = (dr[0] * dr[0] + dr[1] * dr[1]).sqrt();
        let mut ok = !q0[0][0].is_nan() && !q1[0][0].is_nan() && ll > 1e-6 && lr > 1e-6;
        let (ul, ur) = if ok {
            ([dl[0] / ll, dl[1] / ll], [dr[0] / lr, dr[1] / lr])
        } else {
            ([0.0; 2], [0.0; 2])
        };
        let s = [ul[0] + ur[0], ul[1] + ur[1]];
        let ls = (s[0] * s[0] + s[1] * s[1]).sqrt();
        ok = ok && ls > 1e-4;
        if !ok {
            out.extend_from_slice(&[MARKER; 4]);
            continue;
        }
        let mv = [-s[0] / ls, -s[1] / ls];
        let align = |u: [f32; 2]| {
            let q = [-u[1], u[0]];
            let g = if q[0] * mv[0] + q[1] * mv[1] >= 0.0 {
                1.0
            } else {
                -1.0
            };
            [q[0] * g, q[1] * g]
        };
        let (p0, p1) = (align(ul), align(ur));
        let (z, w) = (q0[ma][2], mw);
        out.push(screen(p, sm[0] + mv[0] * hw, sm[1] + mv[1] * hw, z, w));
        out.push(screen(p, sm[0] + p0[0] * hw, sm[1] + p0[1] * hw, z, w));
        out.push(screen(p, sm[0], sm[1], z, w));
        out.push(screen(p, sm[0] + p1[0] * hw, sm[1] + p1[1] * hw, z, w));
    }
    out
}

/// The read-back compaction (`drawn_flags`, one scan, `compact_edges`,
/// `compact_caps`; the device stage's `read_drawn`): of a full output, the
/// edge-out quads and McGuire-Hughes half-caps of the drawn edges
/// (`KIND_DRAWN`) and the adjacency caps that hold geometry (not the
/// marker), each in index order; `kind` in full.
pub fn compact_drawn(full: &EdgeOutput) -> EdgeOutput {
    let drawn = |e: usize| full.kind.get(e).is_some_and(|k| k & KIND_DRAWN != 0);
    let of_edges = |b: &[[f32; 4]], per: usize| -> Vec<[f32; 4]> {
        b.chunks_exact(per)
            .enumerate()
            .filter(|(e, _)| drawn(*e))
            .flat_map(|(_, q)| q.iter().copied())
            .collect()
    };
    EdgeOutput {
        edge_out: of_edges(&full.edge_out, 4),
        kind: full.kind.clone(),
        cap_mh0: of_edges(&full.cap_mh0, 3),
        cap_mh1: of_edges(&full.cap_mh1, 3),
        cap_adj: full
            .cap_adj
            .chunks_exact(4)
            .filter(|q| !q[0][0].is_nan())
            .flat_map(|q| q.iter().copied())
            .collect(),
    }
}

/// The front door's CPU twin of `shapecue::feature_edges`: builds the
/// topology (the cap buffer only for adjacency caps), packs the parameters
/// and runs [`edges_detect`] and the caps of `opts.caps`, returning what the
/// device stage's `read` returns.
///
/// ```
/// use shapecue::mesh::Generated;
/// use shapecue::render::{Placement, framed};
/// use shapecue::spec::edges::{EdgeOptions, KIND_DRAWN};
/// let (_, mesh) = Generated::Torus.mesh(2000);
/// let eye = Placement::At(glam::Vec3::splat(5.0));
/// let view = framed(eye, None, None, 40.0, false, mesh.bounds(), 4.0 / 3.0)?.view(400, 300);
/// let out = shapecue::cpu::edges::feature_edges(&mesh, &view, &EdgeOptions::default())?;
/// assert!(out.count(KIND_DRAWN) > 0);
/// # Ok::<(), shapecue::Error>(())
/// ```
///
/// # Errors
/// Bad parameters ([`crate::spec::edges::EdgeParams::pack`]), a marked edge
/// naming a vertex out of range.
pub fn feature_edges(
    mesh: &crate::mesh::Mesh,
    view: &crate::spec::view::View,
    opts: &crate::spec::edges::EdgeOptions,
) -> crate::Result<crate::spec::edges::EdgeOutput> {
    use crate::mesh::edges::EdgeTopology;
    use crate::spec::edges::CapMode;
    let packed = opts.params(*view)?.pack()?;
    let topo = if opts.caps == CapMode::Adjacency {
        EdgeTopology::new(mesh, &opts.marked, "mesh")?
    } else {
        EdgeTopology::without_caps(mesh, &opts.marked, "mesh")?
    };
    let pos: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.map(|c| c as f32)).collect();
    let nrm = crate::mesh::topology::vertex_normals(mesh);
    let (edge_out, kind) = edges_detect(&packed, &pos, &nrm, &topo.edges);
    let mut out = crate::spec::edges::EdgeOutput {
        edge_out,
        kind,
        ..Default::default()
    };
    match opts.caps {
        CapMode::None => {}
        CapMode::Mh => {
            (out.cap_mh0, out.cap_mh1) = caps_mh(&packed, &pos, &nrm, &topo.edges, &out.edge_out);
        }
        CapMode::Adjacency => {
            out.cap_adj = caps_adjacency(&packed, &topo.edges, &topo.caps, &out.edge_out);
        }
    }
    Ok(out)
}
