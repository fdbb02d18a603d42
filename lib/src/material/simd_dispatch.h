// Function multiversioning for the batched (structure-of-arrays) kernels
// (internal).
//
// DIFFPD_SIMD_CLONES before a function compiles it for x86-64-v4 (AVX-512),
// x86-64-v3 (AVX2 + FMA) and the build's baseline; the loader picks the
// widest the machine has. The rest of the library keeps the baseline
// instruction set, so binaries stay portable and Eigen's alignment (an ABI
// matter for code linking the library) does not depend on the machine.
//
// Everything a cloned function calls in its hot loops must be marked
// DIFFPD_SIMD_INLINE: a call from a wide-vector clone into a baseline (SSE)
// function runs it with the upper vector halves dirty, which slows every later
// SSE instruction of the process (measured: the whole local step 1.8x slower).
#pragma once

#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
#define DIFFPD_SIMD_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define DIFFPD_SIMD_CLONES
#endif

#if defined(__GNUC__)
#define DIFFPD_SIMD_INLINE inline __attribute__((always_inline))
#else
#define DIFFPD_SIMD_INLINE inline
#endif
