// skinning.cl: linear blend skinning (Griffin et al. 2012: the mesh is deformed on the
// device each frame from keyframe joint matrices), p' = Σ w_i M_{j_i} p with
// up to four influences. Host: src/stages/skinning.rs; CPU twin:
// src/cpu/skinning.rs.
// Shared with the host (src/spec/skinning.rs): 4 influences per vertex
// (INFLUENCES), 16 floats per joint matrix (MATRIX_FLOATS).
//   skin_lbs   per vertex   skinned position
// Buffers (V vertices, J joints):
//   rest float[3V]; joints uint[4V]; weights float[4V] (normalized, or all 0:
//   the vertex keeps its rest position); mats float[16J] column-major joint
//   matrices (global joint transform × inverse bind); out float[3V].
// Scalar code with indexed loads (PoCL vectorises it across work-items).

__kernel void skin_lbs(uint nv, __global const float *rest, __global const uint *joints,
                       __global const float *weights, __global const float *mats,
                       __global float *out)
{
    GID_OR_RETURN(nv);
    const float px = rest[3 * gid], py = rest[3 * gid + 1], pz = rest[3 * gid + 2];
    float ox = 0.0f, oy = 0.0f, oz = 0.0f, wsum = 0.0f;
    for (uint k = 0; k < 4; ++k) {
        const float w = weights[4 * gid + k];
        const uint j = joints[4 * gid + k];
        const uint b = 16 * j;
        // A zero weight contributes nothing; its joint index is still valid (checked on load).
        ox += w * (mats[b] * px + mats[b + 4] * py + mats[b + 8] * pz + mats[b + 12]);
        oy += w * (mats[b + 1] * px + mats[b + 5] * py + mats[b + 9] * pz + mats[b + 13]);
        oz += w * (mats[b + 2] * px + mats[b + 6] * py + mats[b + 10] * pz + mats[b + 14]);
        wsum += w;
    }
    const bool keep = wsum == 0.0f;
    out[3 * gid] = keep ? px : ox;
    out[3 * gid + 1] = keep ? py : oy;
    out[3 * gid + 2] = keep ? pz : oz;
}
