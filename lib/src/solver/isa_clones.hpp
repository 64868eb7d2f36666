#pragma once
// Internal: how the vectorised kernels (irls_kernel.cpp, joint_kernel.cpp)
// are compiled for several instruction sets.
//
// CELC_IRLS_ISA_DISPATCH (CMake option): the kernels' loops also
// compiled for AVX-512 and AVX2, the best the CPU has picked when the program
// loads (GCC function multiversioning on x86-64 Linux). The files are
// compiled without floating-point contraction, so every clone computes the same
// numbers. Not when the whole build already targets AVX-512 (nothing better
// to pick, and GCC 12 fails on the clones then).
#if defined(CELC_IRLS_ISA_DISPATCH) && defined(__GNUC__) && !defined(__clang__) && \
    defined(__x86_64__) && defined(__linux__) && !defined(__AVX512F__)
#define CELC_ISA_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
// The passes are inlined into every clone, so that each is compiled for its ISA.
#define CELC_PASS_INLINE inline __attribute__((always_inline))
#else
#define CELC_ISA_CLONES
#define CELC_PASS_INLINE inline
#endif
