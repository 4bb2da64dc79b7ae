//! CPU reference of `kernels/skinning.cl`: linear blend skinning with up to
//! four influences, `p' = Σ w_i M_{j_i} p` (f32, like the kernel). A vertex
//! whose weights are all zero keeps its rest position. Layout of joints,
//! weights and matrices: [`crate::spec::skinning`].

use crate::spec::skinning::{INFLUENCES, MATRIX_FLOATS};

/// `skin_lbs`: skinned positions from rest positions, joints, weights and
/// column-major joint matrices (16 floats each).
pub fn skin_lbs(
    rest: &[[f32; 3]],
    joints: &[[u32; INFLUENCES]],
    weights: &[[f32; INFLUENCES]],
    mats: &[f32],
) -> Vec<[f32; 3]> {
    rest.iter()
        .zip(joints)
        .zip(weights)
        .map(|((p, j), w)| {
            if w.iter().all(|&x| x == 0.0) {
                return *p;
            }
            let mut o = [0.0f32; 3];
            for k in 0..INFLUENCES {
                if w[k] == 0.0 {
                    continue;
                }
                let b = MATRIX_FLOATS * j[k] as usize;
                let m = &mats[b..b + MATRIX_FLOATS];
                for r in 0..3 {
                    let v = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
                    o[r] += w[k] * v;
                }
            }
            o
        })
        .collect()
}
