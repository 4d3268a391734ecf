// The matrix-free elasticity operator on a rank's slab (slab.hpp), with the
// ghost rows exchanged by non-blocking point-to-point messages overlapped
// with the interior rows of the apply:
//
//   1. pack the first and last owned rows, post MPI_Irecv / MPI_Isend to the
//      neighbours below and above;
//   2. apply K to the owned rows whose stencils do not reach a ghost row,
//      in chunks with MPI_Testall between them (progress of large messages);
//   3. wait, unpack the ghost rows, apply K to the (at most two) owned rows
//      next to them.
//
// Vectors are local-box vectors (slab.hpp): y = K x on the owned rows and 0
// on the ghost rows, so plain local dot products over the whole local
// vector count every global entry once (CGOptions::comm sums them over the
// ranks). The ghost rows of x are communication scratch: apply overwrites
// them with the neighbours' values (x is const in the operator's interface,
// as in CG, but its ghost entries belong to the exchange).
//
// Communication per apply and rank (the model, comm_model.hpp): one message
// to and from each neighbour, 3 nx nz doubles each. With one rank nothing is
// sent and the result is the whole-grid apply, bit for bit.
#pragma once
#include <vector>

#include "core/parallel/comm.hpp"
#include "core/parallel/slab.hpp"
#include "core/solvers/operator.hpp"
#include "kernels/elasticity.hpp"

namespace tresca {

struct HaloCounts {
  long long exchanges = 0, messages = 0;  // messages sent by this rank
  double bytes = 0;                      // bytes sent by this rank
  double wait_seconds = 0;               // time blocked in MPI_Waitall
};

class DistributedElasticity : public LinearOperator {
 public:
  // faces: the global grid's constrained faces
  DistributedElasticity(const Slab& s, unsigned faces, real E, real nu, const Comm& comm = Comm::world());
  index size() const override { return 3 * slab_.local.nodes(); }
  void apply(const real* x, real* y) const override;
  // r = b - K x on the owned rows (fused into the apply), 0 on the ghost rows
  void residual(const real* b, const real* x, real* r) const;
  // the same in single precision (coefficients rounded to float, messages of
  // floats): the multigrid V-cycle's (distributed_multigrid.hpp)
  void apply(const float* x, float* y) const;
  void residual(const float* b, const float* x, float* r) const;
  // y = K x on output planes [z_begin, z_end) of the owned rows only, after
  // a (blocking) exchange of x's ghost rows; other entries of y untouched
  void apply_planes(const real* x, real* y, index z_begin, index z_end) const;
  // ghost rows of x := the neighbours' owned rows (blocking)
  void exchange(real* x) const;
  // diag(K) on the owned rows (1 on constrained dofs), 0 on the ghost rows
  void diagonal(real* d) const;
  // zero the ghost rows of a local vector
  template <class T>
  void zero_ghosts(T* v) const;
  const Slab& slab() const { return slab_; }
  const Comm& comm() const { return comm_; }
  const HaloCounts& counts() const { return counts_; }
  // overlap (default) or exchange first, then apply all rows: for measuring
  void set_overlap(bool on) { overlap_ = on; }

 private:
  template <class T>
  void begin_exchange(const T* x) const;
  template <class T>
  void end_exchange(T* x) const;
  void test_exchange() const;  // lets MPI progress the messages (MPI_Testall)
  static constexpr index kProgressChunks = 8;
  template <class T>
  void apply_rows(const T* x, T* y, index y_begin, index y_end, const T* b) const;
  template <class T>
  void apply_impl(const T* x, T* y, const T* b) const;
  template <class T>
  std::vector<T>* buffers() const;  // send below, send above, receive below, receive above

  Slab slab_;
  const Comm& comm_;
  ElasticityStencil k_;
  ElasticityStencilT<float> kf_;
  bool overlap_ = true;
  mutable HaloCounts counts_;
  mutable std::vector<real> buf_d_[4];
  mutable std::vector<float> buf_s_[4];
  mutable std::vector<char> requests_;  // MPI_Request storage (opaque here)
  mutable int pending_ = 0;  // requests in flight; negative: all completed by a test
};

// z = D^{-1} r on the owned rows (Jacobi), 0 on the ghost rows: the CG
// preconditioner of the distributed phase-1 solve
class DistributedJacobi : public LinearOperator {
 public:
  explicit DistributedJacobi(const DistributedElasticity& K);
  index size() const override { return index(inv_.size()); }
  void apply(const real* r, real* z) const override;

 private:
  std::vector<real> inv_;
};

}  // namespace tresca
