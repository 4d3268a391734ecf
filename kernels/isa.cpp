#include "isa.hpp"

#include <cstdlib>
#include <stdexcept>

#include "simd.hpp"

#ifndef TRESCA_ARCH_FLAGS
#define TRESCA_ARCH_FLAGS "(compiler default)"
#endif

namespace tresca {

// the variants CMake compiled kernels/elasticity_isa.cpp for (TRESCA_ISA_*)
namespace isa_baseline {
extern const IsaKernels kernels;
}
#ifdef TRESCA_ISA_X86_64_V4
namespace isa_x86_64_v4 {
extern const IsaKernels kernels;
}
#endif

namespace {

const IsaKernels* g_set = nullptr;  // set_isa's

// TRESCA_ISA, or the widest variant this processor runs
const IsaKernels* choose() {
  const std::vector<const IsaKernels*>& runs = isa_variants();
  const char* e = std::getenv("TRESCA_ISA");
  if (e == nullptr || *e == '\0') return runs.front();
  for (const IsaKernels* v : runs)
    if (std::string(e) == v->id) return v;
  std::string known = "baseline";
#ifdef TRESCA_ISA_X86_64_V4
  known = "x86-64-v4 (AVX-512, where the processor has it), " + known;
#endif
  throw std::invalid_argument(std::string("TRESCA_ISA=") + e + " is not a variant this build and processor run: " +
                              known);
}

}  // namespace

const std::vector<const IsaKernels*>& isa_variants() {
  static const std::vector<const IsaKernels*> runs = [] {
    std::vector<const IsaKernels*> v;
#ifdef TRESCA_ISA_X86_64_V4
    __builtin_cpu_init();
    // (valgrind's CPUID says no AVX-512: there the baseline runs)
    if (__builtin_cpu_supports("x86-64-v4")) v.push_back(&isa_x86_64_v4::kernels);
#endif
    v.push_back(&isa_baseline::kernels);
    return v;
  }();
  return runs;
}

const IsaKernels& isa() {
  static const IsaKernels* chosen = choose();  // (a throw leaves it unset: the next call throws again)
  return g_set ? *g_set : *chosen;
}

void set_isa(const IsaKernels& v) { g_set = &v; }

std::string build_info() {
  const IsaKernels& k = isa();
  const int lanes = k.vector_bytes / int(sizeof(double));
  std::string s = std::string("ISA ") + k.name + " (" + k.id + " variant";
  if (std::string(k.name) != simd_isa()) s += std::string("; the rest ") + simd_isa();
  s += ")";
  s += ", " + std::to_string(8 * k.vector_bytes) + "-bit vectors (" + std::to_string(lanes) +
       (lanes == 1 ? " double" : " doubles") + "), " + TRESCA_ARCH_FLAGS;
#if defined(__clang__)
  s += ", Clang " __clang_version__;
#elif defined(__GNUC__)
  s += ", GCC " __VERSION__;
#endif
  return s;
}

}  // namespace tresca
