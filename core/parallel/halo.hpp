// The ghost rows of a rank's slab vectors (slab.hpp): one node row below and
// one above, copies of the neighbouring ranks' first and last owned rows,
// which the elasticity stencil reads. exchange(x) makes x's ghost rows
// current (HPCG's ExchangeHalo): it posts one receive and one send per
// neighbour (3 nx nz values each: all components and planes of one row),
// waits, and writes x's ghost rows, nothing else. A slab without neighbours
// (one rank, or a level every rank holds whole) sends nothing.
//
// Communication per exchange and rank (comm_model.hpp): one message to and
// from each neighbour. Overlapping it with the interior rows of the apply
// saved at most 1 % of an apply on shared memory (perf/RESULTS.md §0g), so
// the exchange is blocking and explicit.
#pragma once
#include <vector>

#include "core/parallel/slab.hpp"

namespace tresca {

struct HaloCounts {
  long long exchanges = 0, messages = 0;  // messages sent by this rank
  double bytes = 0;                      // bytes sent by this rank
  double wait_seconds = 0;               // time blocked in MPI_Waitall
};

class Halo {
 public:
  Halo() = default;
  explicit Halo(const Slab& s);
  // ghost rows of x := the neighbours' owned rows next to them (blocking);
  // T = double or float
  template <class T>
  void exchange(T* x) const;
  // ghost rows of v := 0
  template <class T>
  void zero_ghosts(T* v) const;
  bool empty() const { return !slab_.lo && !slab_.hi; }
  const HaloCounts& counts() const { return counts_; }

 private:
  template <class T>
  std::vector<T>* buffers() const;  // send below, send above, receive below, receive above

  Slab slab_;
  mutable HaloCounts counts_;
  mutable std::vector<double> buf_d_[4];
  mutable std::vector<float> buf_s_[4];
};

}  // namespace tresca
