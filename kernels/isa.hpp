// Instruction-set dispatch: one program, each machine's widest vectors.
//
// The one compute-bound kernel, the elasticity apply (153 FMAs a node: on a
// CPU it runs at a fraction of the memory bandwidth, RESULTS.md), is
// compiled once per instruction set (kernels/elasticity_isa.cpp, a
// translation unit built several times with its own -march), and the
// program picks at start the widest variant the processor runs. Everything
// else (memory-bound vector updates, transfers, the contact level) is
// compiled once for the build's baseline, which on x86-64 never holds
// AVX-512. So:
//   - one binary runs anywhere its baseline runs, with AVX-512 where the
//     processor has it (a bundle built here for another machine included);
//   - under valgrind, which hides AVX-512 from CPUID and cannot decode it,
//     the same binary takes its baseline variant: `valgrind build/bin/tresca`
//     runs;
//   - TRESCA_ISA=baseline (or x86-64-v4) chooses by hand, for measurements;
//     a variant the processor cannot run is refused.
// tests/check_isa.py holds the line: no AVX-512 instruction outside the
// variants' own functions.
#pragma once
#include <string>
#include <vector>

#include "elasticity.hpp"
#include "types.hpp"

namespace tresca {

// the independent FMA chains a thread of IsaKernels::fma_chains_* keeps
constexpr int kFmaChains = 12;

// One instruction set's compiled variants of the compute-bound kernels.
struct IsaKernels {
  const char* id;    // "x86-64-v4", "baseline": TRESCA_ISA's values
  const char* name;  // the instruction set its unit was compiled for: "AVX-512F", "AVX2+FMA", ...
  int vector_bytes;  // its vectors (simd.hpp)
  // an apply of x (apply_out.hpp: K x, b - K x or a Chebyshev step) over the
  // node rows of `rows`, serially: the banded apply's work for one band
  // (elasticity.cpp launches the bands)
  void (*apply_band_d)(const StencilView<double>&, const double* x, const ApplyOut<double>& out, const RowBlock& rows);
  void (*apply_band_f)(const StencilView<float>&, const float* x, const ApplyOut<float>& out, const RowBlock& rows);
  // `iterations` rounds of kFmaChains independent FMA chains of this set's vectors on
  // every thread (perf/roofline's flop peak); returns a sum to check
  double (*fma_chains_d)(long iterations);
  double (*fma_chains_f)(long iterations);
};

// The variants this program holds that this processor runs, widest first
// (the baseline last, always there).
const std::vector<const IsaKernels*>& isa_variants();
// The variant in use: TRESCA_ISA if set, else the widest this processor
// runs. Throws std::invalid_argument for an unknown TRESCA_ISA or one this
// processor (or this build) cannot run.
const IsaKernels& isa();
// use v from now on (tests and benchmarks: each variant in turn)
void set_isa(const IsaKernels& v);

template <class T>
auto isa_apply_band(const IsaKernels& v) {
  if constexpr (sizeof(T) == sizeof(float))
    return v.apply_band_f;
  else
    return v.apply_band_d;
}

// One line tying a measurement to its build: the kernels' instruction set
// and vectors, the baseline the rest was compiled for, the -march flags
// CMake passed for the baseline, compiler; e.g. "ISA AVX-512F (x86-64-v4
// variant; the rest AVX2+FMA), 512-bit vectors (8 doubles), -march=native
// -mno-avx512f, GCC 12.2.0", or "ISA AVX2+FMA (baseline variant), ...".
std::string build_info();

}  // namespace tresca
