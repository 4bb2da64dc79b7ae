// real.h: the floating-point type of a program build.
// Built with -DSC_DOUBLE for double precision (needs cl_khr_fp64); float otherwise.
// Buffers hold plain REAL arrays; 3-vectors are read and written with
// vload3/vstore3 (never a float3 inside a buffer struct: it is 16 bytes).
#ifdef SC_DOUBLE
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double REAL;
typedef double3 REAL3;
typedef double4 REAL4;
#define RL(x) ((double)(x))
#else
typedef float REAL;
typedef float3 REAL3;
typedef float4 REAL4;
#define RL(x) ((float)(x))
#endif

// Kernel guard for 1-D launches whose global size is padded to the work-group size.
#define GID_OR_RETURN(n)                 \
    const uint gid = (uint)get_global_id(0); \
    if (gid >= (n)) return;

// Helpers called several times per kernel are forced inline: PoCL's inliner
// leaves the larger ones (cost above its threshold) as calls returning
// structs through the stack (see kernels/common/curvature_face.h).
#define SC_INLINE inline __attribute__((always_inline))
