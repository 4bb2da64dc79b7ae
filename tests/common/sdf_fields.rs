//! Fields for the curvature-directed stroke tests (`sdf_lines`): a field
//! sampled on a grid over [-1, 1]³, fixed sampling options, and the checks
//! of a run's output.

use shapecue::spec::sdf_lines::{Sampling, SdfLineOptions, SdfLinesOutput};
use shapecue::volume::Volume;

/// A field sampled on `res³` points over [-1, 1]³.
pub fn field(res: usize, f: impl Fn([f64; 3]) -> f64) -> Volume {
    let n = (res - 1) as f64;
    let c = |i: usize| (2.0 * i as f64 - n) / n;
    let mut v = Vec::with_capacity(res * res * res);
    for z in 0..res {
        for y in 0..res {
            for x in 0..res {
                v.push(f([c(x), c(y), c(z)]) as f32);
            }
        }
    }
    Volume {
        dims: [res; 3],
        spacing: [2.0 / n; 3],
        origin: [-1.0; 3],
        values: v,
    }
}

pub fn fixed(h_vox: f64, res: usize) -> SdfLineOptions {
    SdfLineOptions {
        sampling: Sampling::Fixed(h_vox * 2.0 / (res - 1) as f64),
        ..Default::default()
    }
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn local(vol: &Volume, p: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|a| p[a] - vol.origin[a])
}

pub fn all_finite(out: &SdfLinesOutput) -> bool {
    out.seeds
        .iter()
        .all(|s| s.p.iter().chain(&s.n).chain(&s.d1).all(|c| c.is_finite()) && s.k1.is_finite())
        && out.strokes.iter().all(|s| {
            s.points
                .iter()
                .chain(&s.normals)
                .chain(&s.strip)
                .flatten()
                .chain(&s.widths)
                .all(|c| c.is_finite())
        })
}
