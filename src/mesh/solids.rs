//! Closed solids for the edges stage's oracles, benches and cap-quality table
//! (the shapes of House & Li's memory table): cube, capped cylinder, cone.

use super::Mesh;
use std::f64::consts::PI;

/// The cube [-s/2, s/2]³ with 8 shared vertices and 12 triangles,
/// counter-clockwise seen from outside (18 edges: 12 creases, 6 face diagonals).
pub fn cube(s: f64) -> Mesh {
    let h = 0.5 * s;
    let positions = (0..8)
        .map(|i| {
            [
                if i & 1 != 0 { h } else { -h },
                if i & 2 != 0 { h } else { -h },
                if i & 4 != 0 { h } else { -h },
            ]
        })
        .collect();
    let quads: [[u32; 4]; 6] = [
        [0, 2, 3, 1], // z−
        [4, 5, 7, 6], // z+
        [0, 1, 5, 4], // y−
        [2, 6, 7, 3], // y+
        [0, 4, 6, 2], // x−
        [1, 3, 7, 5], // x+
    ];
    let faces = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    Mesh {
        positions,
        faces,
        normals: None,
    }
}

/// A closed cylinder along z, radius `r`, height `h`, centred at the origin:
/// `n` segments around, one ring at each end, and a centre vertex per cap.
pub fn capped_cylinder(r: f64, h: f64, n: usize) -> Mesh {
    let n = n.max(3);
    let mut positions = Vec::with_capacity(2 * n + 2);
    for z in [-0.5 * h, 0.5 * h] {
        for i in 0..n {
            let u = 2.0 * PI * i as f64 / n as f64;
            positions.push([r * u.cos(), r * u.sin(), z]);
        }
    }
    let (bot, top) = (2 * n as u32, 2 * n as u32 + 1);
    positions.push([0.0, 0.0, -0.5 * h]);
    positions.push([0.0, 0.0, 0.5 * h]);
    let mut faces = Vec::with_capacity(4 * n);
    for i in 0..n as u32 {
        let j = (i + 1) % n as u32;
        let (a, b, c, d) = (i, j, n as u32 + j, n as u32 + i);
        faces.push([a, b, c]);
        faces.push([a, c, d]);
        faces.push([bot, b, a]);
        faces.push([top, d, c]);
    }
    Mesh {
        positions,
        faces,
        normals: None,
    }
}

/// A closed cone along z: base disc of radius `r` at z = −h/2 (with a centre
/// vertex), apex at z = +h/2, `n` segments around.
pub fn cone(r: f64, h: f64, n: usize) -> Mesh {
    let n = n.max(3);
    let mut positions: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let u = 2.0 * PI * i as f64 / n as f64;
            [r * u.cos(), r * u.sin(), -0.5 * h]
        })
        .collect();
    let (bot, apex) = (n as u32, n as u32 + 1);
    positions.push([0.0, 0.0, -0.5 * h]);
    positions.push([0.0, 0.0, 0.5 * h]);
    let mut faces = Vec::with_capacity(2 * n);
    for i in 0..n as u32 {
        let j = (i + 1) % n as u32;
        faces.push([i, j, apex]);
        faces.push([bot, j, i]);
    }
    Mesh {
        positions,
        faces,
        normals: None,
    }
}

/// `mesh` moved and scaled so that its bounding box is centred at the origin
/// with a largest side of 1 ("unit-sized at the origin", as in House & Li's tables).
pub fn unit_sized(mesh: &Mesh) -> Mesh {
    let (lo, hi) = mesh.bounds();
    let c = [
        0.5 * (lo[0] + hi[0]),
        0.5 * (lo[1] + hi[1]),
        0.5 * (lo[2] + hi[2]),
    ];
    let ext = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(hi[2] - lo[2]);
    let s = if ext > 0.0 && ext.is_finite() {
        1.0 / ext
    } else {
        1.0
    };
    mesh.map_positions(|p| [(p[0] - c[0]) * s, (p[1] - c[1]) * s, (p[2] - c[2]) * s])
}
