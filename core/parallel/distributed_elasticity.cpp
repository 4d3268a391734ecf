#include "core/parallel/distributed_elasticity.hpp"

#include <algorithm>

#include "kernels/vector_ops.hpp"  // worth_threads, kXpayCost (z = d r: the same streams)
#include "core/util/profile.hpp"

#ifdef TRESCA_HAVE_MPI
#include <mpi.h>
#endif

namespace tresca {

namespace {
// the ghost or boundary row j of all planes and components <-> a packed buffer
void pack_row(const GridDims& g, const real* v, index j, real* buf) {
  const index nx = g.nx(), N = g.nodes();
  for (int c = 0; c < 3; ++c)
    for (index iz = 0; iz < g.nz(); ++iz) std::copy_n(v + c * N + g.node(0, j, iz), nx, buf + (c * g.nz() + iz) * nx);
}
void unpack_row(const GridDims& g, const real* buf, index j, real* v) {
  const index nx = g.nx(), N = g.nodes();
  for (int c = 0; c < 3; ++c)
    for (index iz = 0; iz < g.nz(); ++iz) std::copy_n(buf + (c * g.nz() + iz) * nx, nx, v + c * N + g.node(0, j, iz));
}
void fill_row(const GridDims& g, real value, index j, real* v) {
  const index nx = g.nx(), N = g.nodes();
  for (int c = 0; c < 3; ++c)
    for (index iz = 0; iz < g.nz(); ++iz) std::fill_n(v + c * N + g.node(0, j, iz), nx, value);
}
}  // namespace

DistributedElasticity::DistributedElasticity(const Slab& s, unsigned faces, real E, real nu, const Comm& comm)
    : slab_(s), comm_(comm), k_(build_elasticity_stencil(s.local, s.local_faces(faces), E, nu, {s.global.hx(), s.global.hy(), s.global.hz()})) {
  const index row = 3 * s.local.nx() * s.local.nz();
  if (s.lo) send_lo_.resize(row), recv_lo_.resize(row);
  if (s.hi) send_hi_.resize(row), recv_hi_.resize(row);
#ifdef TRESCA_HAVE_MPI
  requests_.resize(4 * sizeof(MPI_Request));
#endif
}

void DistributedElasticity::begin_exchange(const real* x) const {
  pending_ = 0;
  if (!slab_.lo && !slab_.hi) return;
#ifdef TRESCA_HAVE_MPI
  MPI_Request* req = reinterpret_cast<MPI_Request*>(requests_.data());
  const GridDims& g = slab_.local;
  const int n = int(3 * g.nx() * g.nz());
  // tag 0: a row travelling up (from rank r to r + 1), tag 1: down
  if (slab_.lo) MPI_Irecv(recv_lo_.data(), n, MPI_DOUBLE, slab_.rank - 1, 0, MPI_COMM_WORLD, &req[pending_++]);
  if (slab_.hi) MPI_Irecv(recv_hi_.data(), n, MPI_DOUBLE, slab_.rank + 1, 1, MPI_COMM_WORLD, &req[pending_++]);
  if (slab_.lo) {
    pack_row(g, x, slab_.lo, send_lo_.data());
    MPI_Isend(send_lo_.data(), n, MPI_DOUBLE, slab_.rank - 1, 1, MPI_COMM_WORLD, &req[pending_++]);
  }
  if (slab_.hi) {
    pack_row(g, x, slab_.lo + slab_.owned_rows() - 1, send_hi_.data());
    MPI_Isend(send_hi_.data(), n, MPI_DOUBLE, slab_.rank + 1, 0, MPI_COMM_WORLD, &req[pending_++]);
  }
  counts_.exchanges += 1;
  counts_.messages += slab_.lo + slab_.hi;
  counts_.bytes += double(slab_.lo + slab_.hi) * n * sizeof(real);
#else
  (void)x;
#endif
}

void DistributedElasticity::test_exchange() const {
#ifdef TRESCA_HAVE_MPI
  if (pending_ <= 0) return;
  int done = 0;
  MPI_Testall(pending_, reinterpret_cast<MPI_Request*>(requests_.data()), &done, MPI_STATUSES_IGNORE);
  if (done) pending_ = -pending_;  // completed: nothing left to wait for (unpack still due)
#endif
}

void DistributedElasticity::end_exchange(real* x) const {
  if (!slab_.lo && !slab_.hi) return;
#ifdef TRESCA_HAVE_MPI
  const double t0 = wall_time();
  if (pending_ > 0) MPI_Waitall(pending_, reinterpret_cast<MPI_Request*>(requests_.data()), MPI_STATUSES_IGNORE);
  counts_.wait_seconds += wall_time() - t0;
  pending_ = 0;
  const GridDims& g = slab_.local;
  if (slab_.lo) unpack_row(g, recv_lo_.data(), 0, x);
  if (slab_.hi) unpack_row(g, recv_hi_.data(), slab_.lo + slab_.owned_rows(), x);
#else
  (void)x;
#endif
}

void DistributedElasticity::exchange(real* x) const {
  begin_exchange(x);
  end_exchange(x);
}

void DistributedElasticity::apply_rows(const real* x, real* y, index y_begin, index y_end) const {
  if (y_begin >= y_end) return;
  const GridDims& g = slab_.local;
  ScopedTimer t(Kernel::apply, double(g.nx() * (y_end - y_begin) * g.nz()) * kApplyCost);
  elasticity_apply(k_, x, y, RowBlock{0, g.nz(), y_begin, y_end});
}

void DistributedElasticity::apply(const real* x, real* y) const {
  real* xg = const_cast<real*>(x);  // ghost rows only: communication scratch (header)
  const index first = slab_.lo, last = slab_.lo + slab_.owned_rows();  // owned local rows [first, last)
  if (overlap_) {
    begin_exchange(x);
    // rows whose stencils stay inside the owned rows, in chunks with a test
    // of the messages between them: Open MPI moves a large (rendezvous)
    // message only while the rank is inside an MPI call
    const index r0 = first + slab_.lo, r1 = std::max(r0, last - slab_.hi);
    const index chunks = slab_.lo + slab_.hi == 0 ? 1 : std::min<index>(kProgressChunks, std::max<index>(1, r1 - r0));
    for (index c = 0; c < chunks; ++c) {
      apply_rows(x, y, r0 + (r1 - r0) * c / chunks, r0 + (r1 - r0) * (c + 1) / chunks);
      if (c + 1 < chunks) test_exchange();
    }
    end_exchange(xg);
    if (slab_.lo) apply_rows(x, y, first, std::min(first + 1, last));
    if (slab_.hi && last - 1 >= first + slab_.lo) apply_rows(x, y, last - 1, last);
  } else {
    exchange(xg);
    apply_rows(x, y, first, last);
  }
  zero_ghosts(y);
}

void DistributedElasticity::zero_ghosts(real* v) const {
  if (slab_.lo) fill_row(slab_.local, 0, 0, v);
  if (slab_.hi) fill_row(slab_.local, 0, slab_.lo + slab_.owned_rows(), v);
}

void DistributedElasticity::diagonal(real* d) const {
  elasticity_diagonal(k_, d);
  zero_ghosts(d);
}

DistributedJacobi::DistributedJacobi(const DistributedElasticity& K) : inv_(K.size()) {
  K.diagonal(inv_.data());
  for (real& v : inv_) v = v != 0 ? 1 / v : 0;
}

void DistributedJacobi::apply(const real* r, real* z) const {
  const index n = size();
  const real* d = inv_.data();
#pragma omp parallel for simd schedule(static) if (parallel : worth_threads(double(n) * kXpayCost))
  for (index i = 0; i < n; ++i) z[i] = d[i] * r[i];
}

}  // namespace tresca
