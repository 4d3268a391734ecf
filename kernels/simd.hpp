// The vector width of the compilation target, and one vector type per scalar.
//
// Width comes from the compiler's target macros, so one source gives every
// target its native vectors: AVX-512 64 bytes (8 doubles, 16 floats), AVX/AVX2
// 32 bytes, SSE2..SSE4.2 and NEON 16 bytes, anything else 8 bytes (one double:
// plain scalar code). A build can force a width with -DTRESCA_SIMD_BYTES=N
// (for experiments, e.g. showing the cliff when the width exceeds the target's
// registers: tests/test_kernel_speed.cpp catches exactly that).
//
// Vec<T> is a GCC/Clang vector extension of kSimdBytes bytes: unaligned
// (alignment of T) and may_alias, so it can be loaded from and stored to plain
// arrays of T at any offset through reinterpret_cast.
//
// One program holds translation units compiled for different instruction
// sets (kernels/isa.hpp: the compute-bound kernels once per set, chosen at
// run time). Each width's definitions live in an inline namespace of their
// own (simd64, simd32, ...), so the AVX-512 unit's Vec<double> and the
// baseline's are different types, not one name defined twice.
#pragma once
#include <string>

#if !defined(TRESCA_SIMD_BYTES)
#if defined(__AVX512F__)
#define TRESCA_SIMD_BYTES 64
#elif defined(__AVX__)
#define TRESCA_SIMD_BYTES 32
#elif defined(__SSE2__) || defined(__ARM_NEON) || defined(__ALTIVEC__) || defined(__riscv_vector)
#define TRESCA_SIMD_BYTES 16
#else
#define TRESCA_SIMD_BYTES 8
#endif
#endif

#define TRESCA_SIMD_NS_CAT(b) simd##b
#define TRESCA_SIMD_NS(b) TRESCA_SIMD_NS_CAT(b)

namespace tresca {
inline namespace TRESCA_SIMD_NS(TRESCA_SIMD_BYTES) {

constexpr int kSimdBytes = TRESCA_SIMD_BYTES;
static_assert(kSimdBytes == 8 || kSimdBytes == 16 || kSimdBytes == 32 || kSimdBytes == 64,
              "TRESCA_SIMD_BYTES must be 8, 16, 32 or 64");

template <class T>
struct Simd {
  static constexpr int lanes = kSimdBytes / int(sizeof(T));
  typedef T type __attribute__((vector_size(kSimdBytes), aligned(sizeof(T)), may_alias));
};
template <class T>
using Vec = typename Simd<T>::type;

// Instruction set this translation unit was compiled for, from the target
// macros (e.g. "AVX-512F", "AVX2+FMA", "SSE4.2", "NEON", "generic").
constexpr const char* simd_isa() {
#if defined(__AVX512F__)
  return "AVX-512F";
#elif defined(__AVX2__) && defined(__FMA__)
  return "AVX2+FMA";
#elif defined(__AVX2__)
  return "AVX2";
#elif defined(__AVX__)
  return "AVX";
#elif defined(__SSE4_2__)
  return "SSE4.2";
#elif defined(__SSE2__)
  return "SSE2";
#elif defined(__ARM_NEON)
  return "NEON";
#else
  return "generic";
#endif
}

}  // namespace TRESCA_SIMD_NS(TRESCA_SIMD_BYTES)
}  // namespace tresca
