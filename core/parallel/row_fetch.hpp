// Fetching a range of node rows of a y-slab-distributed vector (slab.hpp)
// onto one rank: the multigrid transfers between non-nested levels need
// rows that neighbouring ranks own (the coarse rows a fine slab
// interpolates from, the fine rows a coarse slab restricts from), and the
// rank that runs the agglomerated coarse levels needs all of them.
//
// Each rank asks for one contiguous range [a, b) of the global rows; the
// ranges are exchanged once (MPI_Allgather) when the fetch is set up, and
// every fetch is one MPI_Alltoallv of the intersections with the owners'
// rows (3 components, all planes). One rank: a copy.
#pragma once
#include <vector>

#include "core/parallel/comm.hpp"
#include "core/parallel/slab.hpp"

namespace tresca {

class RowFetch {
 public:
  // s: this rank's slab of the distributed vector; rows [a, b) wanted here
  // (a = b = 0: none, the rank only sends; e.g. a gather onto one rank)
  RowFetch(const Slab& s, index a, index b, const Comm& comm = Comm::world());
  // the box of the fetched rows: the global grid's x and z, rows [a, b)
  const GridDims& box() const { return box_; }
  // entries of the fetched vector (3 components; 0 when nothing is wanted)
  index size() const { return a_ == b_ ? 0 : 3 * box_.nodes(); }
  index first_row() const { return a_; }
  // out (3 * box().nodes()) := rows [a, b) of the distributed vector whose
  // local part (slab's local box) is `local`
  // (T = double or float)
  template <class T>
  void fetch(const T* local, T* out) const;
  double bytes_per_fetch() const { return bytes_; }

 private:
  Slab s_;
  const Comm& comm_;
  index a_, b_;
  GridDims box_;
  // per rank q: rows [send_lo, send_hi) of mine go to q, rows [recv_lo, recv_hi) of my box come from q
  std::vector<index> send_lo_, send_hi_, recv_lo_, recv_hi_;
  std::vector<int> send_counts_, send_displs_, recv_counts_, recv_displs_;
  mutable std::vector<real> send_d_, recv_d_;
  mutable std::vector<float> send_s_, recv_s_;
  int send_total_ = 0, recv_total_ = 0;
  double bytes_ = 0;
};

// uf = P uc between two meshes of one box (trilinear, build_transfer), each
// a 3-component vector on its slab (a slab of one rank: the whole grid,
// held by every rank): the coarse rows the fine slab's rows interpolate
// from are fetched from their owners. Collective over comm. The nested
// iteration's warm starts on several ranks (run.cpp).
void prolongate_slabs(const Slab& coarse, const real* uc, const Slab& fine, real* uf, const Comm& comm = Comm::world());

}  // namespace tresca
