#include "simd.hpp"

#ifndef TRESCA_ARCH_FLAGS
#define TRESCA_ARCH_FLAGS "(compiler default)"
#endif

namespace tresca {

const char* simd_isa() {
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

std::string build_info() {
  std::string s = std::string("ISA ") + simd_isa() + ", " + std::to_string(8 * kSimdBytes) + "-bit vectors (" +
                  std::to_string(Simd<double>::lanes) + (Simd<double>::lanes == 1 ? " double" : " doubles") + "), " +
                  TRESCA_ARCH_FLAGS;
#if defined(__clang__)
  s += ", Clang " __clang_version__;
#elif defined(__GNUC__)
  s += ", GCC " __VERSION__;
#endif
  return s;
}

}  // namespace tresca
