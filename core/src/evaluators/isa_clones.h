// Internal to core: FREP_CLONES compiles a lane-loop kernel for several x86 ISA levels
// (target_clones) and picks one at run time. With -ffp-contract=off (CMakeLists.txt) every clone
// gives the same bits as the others and as the scalar evaluators. Not under ThreadSanitizer: the
// clones' ifunc resolver runs while the loader relocates, before TSan's runtime starts, and
// GCC instruments it, so the program crashes before main (tests/sanitize/run_sanitizers.sh).
#pragma once

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_THREAD__)
#define FREP_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define FREP_CLONES
#endif
