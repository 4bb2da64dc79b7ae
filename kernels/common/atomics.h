// atomics.h: floating-point atomic add built on compare-and-swap, as the
// one-ring sums of Griffin et al. need (OpenCL 1.2 has no float atomics).
// float: atomic_cmpxchg on the 32-bit pattern (core 1.1+);
// double: atom_cmpxchg on the 64-bit pattern (cl_khr_int64_base_atomics).
// With -DSC_NATIVE_ATOMICS (built as OpenCL C 3.0): the device's own float
// atomic add (cl_ext_float_atomics), relaxed, device scope. The host checks
// the device's global-add capability for the precision first
// (CL_DEVICE_SINGLE/DOUBLE_FP_ATOMIC_CAPABILITIES_EXT); Intel's CPU compiler
// does not define the extension's __opencl_c_ext_fp*_global_atomic_add
// feature macros, so they are not tested here.
// With -DSC_PTX_ATOMICS (NVIDIA's CUDA platform without the extension): the
// paper's CUDA atomicAdd as inline PTX, red.global.add (f64: sm_60 and later).
#ifdef SC_PTX_ATOMICS
#ifdef SC_DOUBLE
inline void atomic_add_real(volatile __global REAL *p, REAL v)
{
    asm volatile("red.global.add.f64 [%0], %1;" ::"l"(p), "d"(v) : "memory");
}
#else
inline void atomic_add_real(volatile __global REAL *p, REAL v)
{
    asm volatile("red.global.add.f32 [%0], %1;" ::"l"(p), "f"(v) : "memory");
}
#endif
#elif defined(SC_NATIVE_ATOMICS)
#ifdef SC_DOUBLE
inline void atomic_add_real(volatile __global REAL *p, REAL v)
{
    atomic_fetch_add_explicit((volatile __global atomic_double *)p, v, memory_order_relaxed,
                              memory_scope_device);
}
#else
inline void atomic_add_real(volatile __global REAL *p, REAL v)
{
    atomic_fetch_add_explicit((volatile __global atomic_float *)p, v, memory_order_relaxed,
                              memory_scope_device);
}
#endif
#elif defined(SC_DOUBLE)
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable
inline void atomic_add_real(volatile __global REAL *p, REAL v)
{
    union { ulong u; double f; } old_v, new_v;
    do {
        old_v.f = *p;
        new_v.f = old_v.f + v;
    } while (atom_cmpxchg((volatile __global ulong *)p, old_v.u, new_v.u) != old_v.u);
}
#else
inline void atomic_add_real(volatile __global REAL *p, REAL v)
{
    union { uint u; float f; } old_v, new_v;
    do {
        old_v.f = *p;
        new_v.f = old_v.f + v;
    } while (atomic_cmpxchg((volatile __global uint *)p, old_v.u, new_v.u) != old_v.u);
}
#endif

// With -DSC_PAIR_ADDS (float compare-and-swap accumulation on a device with
// cl_khr_int64_base_atomics): two adjacent floats, p 8-byte aligned, added in
// one 64-bit compare-and-swap. Each float gets the same rounded sum as from
// its own add; the pair only halves the locked operations, which bound the
// atomic scheme on CPU devices.
#ifdef SC_PAIR_ADDS
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable
inline void atomic_add_pair(volatile __global float *p, float a, float b)
{
    union { ulong u; float2 f; } old_v, new_v;
    do {
        old_v.u = *(volatile __global ulong *)p;
        new_v.f = old_v.f + (float2)(a, b);
    } while (atom_cmpxchg((volatile __global ulong *)p, old_v.u, new_v.u) != old_v.u);
}
#endif
