// OFV_POINT_KERNEL: how ofv_core compiles its loops over many points.
#pragma once

// The point kernels are compiled for AVX-512, AVX2 and baseline x86-64,
// picked at run time, with floating-point contraction off: every clone rounds
// every product and sum on its own, as baseline x86-64 does (an FMA would give
// other bits on AVX-512 machines than on the others). With the estimator's
// fixed summation order (spec §4), every machine computes the same bits.
// OFV_NO_AVX512_KERNELS (CMake option OFV_AVX512_KERNELS=OFF) drops the
// AVX-512 clone: an AVX-512 machine then runs what an AVX2-only one runs.
#if defined(OFV_NO_AVX512_KERNELS)
#define OFV_KERNEL_TARGETS "avx2", "default"
#else
#define OFV_KERNEL_TARGETS "avx512f", "avx2", "default"
#endif
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__)
#define OFV_POINT_KERNEL \
  __attribute__((target_clones(OFV_KERNEL_TARGETS), optimize("fp-contract=off")))
#elif defined(__GNUC__) && !defined(__clang__)
#define OFV_POINT_KERNEL __attribute__((optimize("fp-contract=off")))
#else
#define OFV_POINT_KERNEL
#endif
#if defined(__clang__)
#pragma clang fp contract(off)
#endif
