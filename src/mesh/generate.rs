//! Procedural meshes with known curvature: the analytic oracles of the tests,
//! the generated inputs of the benches, and the bundled data of the README's
//! main job (so it needs no downloaded file).

use super::Mesh;
use std::f64::consts::PI;

fn grid_faces(nu: usize, nv: usize, wrap_u: bool, wrap_v: bool) -> Vec<[u32; 3]> {
    // Vertex (i, j) = i * nv + j; quads split along the (i,j)-(i+1,j+1) diagonal,
    // counter-clockwise when (u, v) is a right-handed tangent frame.
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    let iu = if wrap_u { nu } else { nu - 1 };
    let iv = if wrap_v { nv } else { nv - 1 };
    let mut faces = Vec::with_capacity(2 * iu * iv);
    for i in 0..iu {
        for j in 0..iv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            faces.push([a, b, c]);
            faces.push([a, c, d]);
        }
    }
    faces
}

/// A torus around the z axis with major radius `big_r` and tube radius `r`,
/// `nu` segments around the axis and `nv` around the tube; closed, genus 1,
/// outward normals.
pub fn torus(big_r: f64, r: f64, nu: usize, nv: usize) -> Mesh {
    let nu = nu.max(3);
    let nv = nv.max(3);
    let mut positions = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let u = 2.0 * PI * i as f64 / nu as f64;
        for j in 0..nv {
            let v = 2.0 * PI * j as f64 / nv as f64;
            let rr = big_r + r * v.cos();
            positions.push([rr * u.cos(), rr * u.sin(), r * v.sin()]);
        }
    }
    Mesh {
        positions,
        faces: grid_faces(nu, nv, true, true),
        normals: None,
    }
}

/// Analytic principal curvatures (k1 ≥ k2) of [`torus`] at point `p` on it.
pub fn torus_curvature(big_r: f64, r: f64, p: [f64; 3]) -> (f64, f64) {
    let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
    let v = p[2].atan2(rho - big_r);
    let a = 1.0 / r;
    let b = v.cos() / (big_r + r * v.cos());
    (a.max(b), a.min(b))
}

/// An open cylinder of radius `r` and height `h` along z, centred at the
/// origin: `nu` segments around, `nv` rings along. Boundary at both ends.
pub fn cylinder(r: f64, h: f64, nu: usize, nv: usize) -> Mesh {
    let nu = nu.max(3);
    let nv = nv.max(2);
    let mut positions = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let u = 2.0 * PI * i as f64 / nu as f64;
        for j in 0..nv {
            let z = -0.5 * h + h * j as f64 / (nv - 1) as f64;
            positions.push([r * u.cos(), r * u.sin(), z]);
        }
    }
    Mesh {
        positions,
        faces: grid_faces(nu, nv, true, false),
        normals: None,
    }
}

/// A flat square grid in the z = 0 plane, `n` × `n` vertices over `[-s/2, s/2]²`.
pub fn plane(n: usize, s: f64) -> Mesh {
    let n = n.max(2);
    let mut positions = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let x = -0.5 * s + s * i as f64 / (n - 1) as f64;
            let y = -0.5 * s + s * j as f64 / (n - 1) as f64;
            positions.push([x, y, 0.0]);
        }
    }
    Mesh {
        positions,
        faces: grid_faces(n, n, false, false),
        normals: None,
    }
}

/// A geodesic sphere of radius `r`: an icosahedron subdivided `level` times
/// and projected onto the sphere (10·4^level + 2 vertices).
pub fn icosphere(r: f64, level: u32) -> Mesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let norm = |p: [f64; 3]| {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [p[0] / l, p[1] / l, p[2] / l]
    };
    for p in positions.iter_mut() {
        *p = norm(*p);
    }
    for _ in 0..level {
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::with_capacity(faces.len() * 4);
        let mut midpoint = |a: u32, b: u32, positions: &mut Vec<[f64; 3]>| -> u32 {
            let key = (a.min(b), a.max(b));
            *mid.entry(key).or_insert_with(|| {
                let (pa, pb) = (positions[a as usize], positions[b as usize]);
                positions.push(norm([pa[0] + pb[0], pa[1] + pb[1], pa[2] + pb[2]]));
                (positions.len() - 1) as u32
            })
        };
        for f in &faces {
            let ab = midpoint(f[0], f[1], &mut positions);
            let bc = midpoint(f[1], f[2], &mut positions);
            let ca = midpoint(f[2], f[0], &mut positions);
            next.push([f[0], ab, ca]);
            next.push([f[1], bc, ab]);
            next.push([f[2], ca, bc]);
            next.push([ab, bc, ca]);
        }
        faces = next;
    }
    for p in positions.iter_mut() {
        *p = [p[0] * r, p[1] * r, p[2] * r];
    }
    Mesh {
        positions,
        faces,
        normals: None,
    }
}

/// An ellipsoid with semi-axes `a`, `b`, `c` (an [`icosphere`] scaled per axis).
pub fn ellipsoid(a: f64, b: f64, c: f64, level: u32) -> Mesh {
    icosphere(1.0, level).map_positions(|p| [p[0] * a, p[1] * b, p[2] * c])
}

/// Analytic principal curvatures (k1 ≥ k2) of the ellipsoid x²/a²+y²/b²+z²/c² = 1
/// at a point `p` on it (outward normals, so both are positive).
pub fn ellipsoid_curvature(a: f64, b: f64, c: f64, p: [f64; 3]) -> (f64, f64) {
    let [x, y, z] = p;
    let h = x * x / a.powi(4) + y * y / b.powi(4) + z * z / c.powi(4);
    let abc2 = (a * b * c).powi(2);
    let gauss = 1.0 / (abc2 * h * h);
    let mean = (a * a + b * b + c * c - x * x - y * y - z * z) / (2.0 * abc2 * h.powf(1.5));
    let disc = (mean * mean - gauss).max(0.0).sqrt();
    (mean + disc, mean - disc)
}

/// Small deterministic pseudo-random numbers (SplitMix64), so generated test
/// meshes are the same on every machine without a `rand` dependency.
pub fn splitmix(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// An [`icosphere`] whose vertices are moved by up to `amount` × the mean edge
/// length in random directions: an irregular mesh with no symmetry to hide
/// behind.
pub fn jittered_sphere(r: f64, level: u32, amount: f64, seed: u64) -> Mesh {
    let m = icosphere(r, level);
    let edge = r * 1.1 / (1u64 << level) as f64; // icosahedron edge 1.05 r, halved per level
    let mut s = seed;
    m.map_positions(|p| {
        let d = [
            splitmix(&mut s) - 0.5,
            splitmix(&mut s) - 0.5,
            splitmix(&mut s) - 0.5,
        ];
        let k = 2.0 * amount * edge;
        [p[0] + k * d[0], p[1] + k * d[1], p[2] + k * d[2]]
    })
}

/// Torus grid resolution (nu, nv) with nu = 2·nv giving about `n` vertices.
pub fn torus_resolution_for(n: usize) -> (usize, usize) {
    let nv = ((n as f64 / 2.0).sqrt().round() as usize).max(3);
    (2 * nv, nv)
}

/// An ellipsoid with semi-axes `a`, `b`, `c` on a latitude–longitude grid:
/// `nu` segments around z, `nv` latitude bands (poles are single vertices).
/// Its regular parametrization is what the convergence tests need; an
/// [`ellipsoid`] built from a scaled geodesic sphere is irregular, and
/// normal-based estimators do not converge on it.
pub fn uv_ellipsoid(a: f64, b: f64, c: f64, nu: usize, nv: usize) -> Mesh {
    let nu = nu.max(3);
    let nv = nv.max(2);
    let mut positions = vec![[0.0, 0.0, c]];
    for j in 1..nv {
        let th = PI * j as f64 / nv as f64;
        for i in 0..nu {
            let ph = 2.0 * PI * i as f64 / nu as f64;
            positions.push([
                a * th.sin() * ph.cos(),
                b * th.sin() * ph.sin(),
                c * th.cos(),
            ]);
        }
    }
    positions.push([0.0, 0.0, -c]);
    let south = (positions.len() - 1) as u32;
    let ring = |j: usize, i: usize| (1 + (j - 1) * nu + (i % nu)) as u32;
    let mut faces = Vec::new();
    for i in 0..nu {
        faces.push([0, ring(1, i), ring(1, i + 1)]);
        faces.push([south, ring(nv - 1, i + 1), ring(nv - 1, i)]);
    }
    for j in 1..nv - 1 {
        for i in 0..nu {
            let (p, q, r, s) = (
                ring(j, i),
                ring(j + 1, i),
                ring(j + 1, i + 1),
                ring(j, i + 1),
            );
            faces.push([p, q, r]);
            faces.push([p, r, s]);
        }
    }
    Mesh {
        positions,
        faces,
        normals: None,
    }
}

/// A generated mesh with analytic curvature, as the CLI's `--generate` and
/// scene files name it ([`Generated::name`]); [`Generated::mesh`] builds it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Generated {
    /// Torus R = 1, r = 0.4.
    Torus,
    /// Icosphere of radius 1.
    Sphere,
    /// Subdivided ellipsoid with semi-axes (1.5, 1, 0.6).
    Ellipsoid,
    /// Open cylinder of radius 1 and height 2.
    Cylinder,
    /// Square plane of side 2.
    Plane,
}

impl Generated {
    /// Every kind, in the order of `--help` and [`GENERATED_NAMES`].
    pub const ALL: [Generated; 5] = [
        Generated::Torus,
        Generated::Sphere,
        Generated::Ellipsoid,
        Generated::Cylinder,
        Generated::Plane,
    ];

    /// The name on the command line and in scene files.
    pub const fn name(self) -> &'static str {
        match self {
            Generated::Torus => "torus",
            Generated::Sphere => "sphere",
            Generated::Ellipsoid => "ellipsoid",
            Generated::Cylinder => "cylinder",
            Generated::Plane => "plane",
        }
    }

    /// The mesh with about `n` vertices, and a description with its
    /// parameters: the torus R=1 r=0.4, an icosphere and an ellipsoid
    /// (1.5, 1, 0.6) at the subdivision level nearest below `n` vertices, a
    /// cylinder and a plane of √n × √n.
    pub fn mesh(self, n: usize) -> (String, Mesh) {
        let level = {
            let mut l = 0;
            while 10 * 4usize.pow(l + 1) + 2 <= n && l < 10 {
                l += 1;
            }
            l
        };
        match self {
            Generated::Torus => {
                let (nu, nv) = torus_resolution_for(n);
                (
                    format!("torus R=1 r=0.4 {nu}x{nv}"),
                    torus(1.0, 0.4, nu, nv),
                )
            }
            Generated::Sphere => (format!("icosphere level {level}"), icosphere(1.0, level)),
            Generated::Ellipsoid => (
                format!("ellipsoid 1.5,1,0.6 level {level}"),
                ellipsoid(1.5, 1.0, 0.6, level),
            ),
            Generated::Cylinder => {
                let k = ((n as f64).sqrt() as usize).max(3);
                (format!("cylinder {k}x{k}"), cylinder(1.0, 2.0, k, k))
            }
            Generated::Plane => {
                let k = ((n as f64).sqrt() as usize).max(2);
                (format!("plane {k}x{k}"), plane(k, 2.0))
            }
        }
    }
}

crate::spec::named_choice!(Generated, "generated mesh");

/// The names [`generated_by_name`] knows (those of [`Generated`]).
pub const GENERATED_NAMES: [&str; 5] = [
    Generated::Torus.name(),
    Generated::Sphere.name(),
    Generated::Ellipsoid.name(),
    Generated::Cylinder.name(),
    Generated::Plane.name(),
];

/// A generated mesh by name ([`GENERATED_NAMES`]) with about `n` vertices, and a
/// description with its parameters (see [`Generated::mesh`]). `None` for an
/// unknown name.
pub fn generated_by_name(kind: &str, n: usize) -> Option<(String, Mesh)> {
    kind.parse::<Generated>().ok().map(|g| g.mesh(n))
}

#[cfg(test)]
mod names {
    use super::Generated;
    use crate::spec::Choice;

    /// `name()`, `Display`, `FromStr` and the command line's names agree
    /// (the spec's option enums are checked in the spec; the generated
    /// meshes are data).
    #[test]
    fn generated_names_agree() {
        assert_eq!(Generated::ALL.len(), Generated::all().len());
        for (v, cli) in Generated::ALL.iter().zip(Generated::all()) {
            assert_eq!(cli.label(), v.name());
            assert_eq!(v.to_string(), v.name());
            assert_eq!(v.name().parse::<Generated>().ok(), Some(*v));
        }
        assert!("no such mesh".parse::<Generated>().is_err());
    }
}
