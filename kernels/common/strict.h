// strict.h: the floating-point rules of every shapecue kernel, put first in
// every program (src/gpu/program.rs), so that a kernel computes exactly what
// its CPU twin computes on every conforming device.
// - No contraction: OpenCL C allows a*b+c to be fused into one FMA by default
//   (FP_CONTRACT ON), and GPU compilers and PoCL do fuse, each where its code
//   generator likes. Off, every product and sum is rounded as the twin's.
// - Divide and square root are correctly rounded through the build option
//   -cl-fp32-correctly-rounded-divide-sqrt, which the host adds where the
//   device reports CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT.
// - Built-ins whose result a device may round its own way (dot, length,
//   normalize, cross, distance, mad, fma, native_*, half_*) are not used;
//   tests/gpu.rs checks the sources for them.
// A build in the relaxed mode (SHAPECUE_FP=relaxed, `shapecue report` rows)
// replaces this header with FP_CONTRACT ON and drops the option: what a GPU
// compiler does by default, to show what the rules cost.
#pragma OPENCL FP_CONTRACT OFF
