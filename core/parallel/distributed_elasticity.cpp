#include "core/parallel/distributed_elasticity.hpp"

#include <algorithm>
#include <type_traits>

#include "kernels/vector_ops.hpp"  // worth_threads, kXpayCost (z = d r: the same streams)
#include "core/util/profile.hpp"

#ifdef TRESCA_HAVE_MPI
#include <mpi.h>
#endif

namespace tresca {

namespace {
template <class T>
void fill_row(const GridDims& g, T value, index j, T* v) {
  const index nx = g.nx(), N = g.nodes();
  for (int c = 0; c < 3; ++c)
    for (index iz = 0; iz < g.nz(); ++iz) std::fill_n(v + c * N + g.node(0, j, iz), nx, value);
}
#ifdef TRESCA_HAVE_MPI
template <class T>
MPI_Datatype mpi_type() {
  return sizeof(T) == sizeof(double) ? MPI_DOUBLE : MPI_FLOAT;
}
#endif
}  // namespace

template <>
std::vector<real>* DistributedElasticity::buffers<real>() const {
  return buf_d_;
}
template <>
std::vector<float>* DistributedElasticity::buffers<float>() const {
  return buf_s_;
}

DistributedElasticity::DistributedElasticity(const Slab& s, unsigned faces, real E, real nu, const Comm& comm)
    : slab_(s),
      comm_(comm),
      k_(build_elasticity_stencil(s.local, s.local_faces(faces), E, nu, {s.global.hx(), s.global.hy(), s.global.hz()})),
      kf_(stencil_in_precision<float>(k_)) {
  const index row = 3 * s.local.nx() * s.local.nz();
  for (int i = 0; i < 4; ++i)
    if ((i % 2 == 0 && s.lo) || (i % 2 == 1 && s.hi)) buf_d_[i].resize(row), buf_s_[i].resize(row);
#ifdef TRESCA_HAVE_MPI
  requests_.resize(4 * sizeof(MPI_Request));
#endif
}

template <class T>
void DistributedElasticity::begin_exchange(const T* x) const {
  pending_ = 0;
  if (!slab_.lo && !slab_.hi) return;
#ifdef TRESCA_HAVE_MPI
  MPI_Request* req = reinterpret_cast<MPI_Request*>(requests_.data());
  const GridDims& g = slab_.local;
  const int n = int(3 * g.nx() * g.nz());
  std::vector<T>* buf = buffers<T>();  // send below, send above, receive below, receive above
  const MPI_Datatype type = mpi_type<T>();
  // tag 0: a row travelling up (from rank r to r + 1), tag 1: down
  if (slab_.lo) MPI_Irecv(buf[2].data(), n, type, slab_.rank - 1, 0, MPI_COMM_WORLD, &req[pending_++]);
  if (slab_.hi) MPI_Irecv(buf[3].data(), n, type, slab_.rank + 1, 1, MPI_COMM_WORLD, &req[pending_++]);
  if (slab_.lo) {
    rows_to_buffer(g, x, slab_.lo, slab_.lo + 1, buf[0].data());
    MPI_Isend(buf[0].data(), n, type, slab_.rank - 1, 1, MPI_COMM_WORLD, &req[pending_++]);
  }
  if (slab_.hi) {
    rows_to_buffer(g, x, slab_.lo + slab_.owned_rows() - 1, slab_.lo + slab_.owned_rows(), buf[1].data());
    MPI_Isend(buf[1].data(), n, type, slab_.rank + 1, 0, MPI_COMM_WORLD, &req[pending_++]);
  }
  counts_.exchanges += 1;
  counts_.messages += slab_.lo + slab_.hi;
  counts_.bytes += double(slab_.lo + slab_.hi) * n * sizeof(T);
  comm_counters().messages += slab_.lo + slab_.hi;
  comm_counters().bytes += double(slab_.lo + slab_.hi) * n * sizeof(T);
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

template <class T>
void DistributedElasticity::end_exchange(T* x) const {
  if (!slab_.lo && !slab_.hi) return;
#ifdef TRESCA_HAVE_MPI
  const double t0 = wall_time();
  if (pending_ > 0) MPI_Waitall(pending_, reinterpret_cast<MPI_Request*>(requests_.data()), MPI_STATUSES_IGNORE);
  counts_.wait_seconds += wall_time() - t0;
  pending_ = 0;
  const GridDims& g = slab_.local;
  const std::vector<T>* buf = buffers<T>();
  if (slab_.lo) buffer_to_rows(g, buf[2].data(), 0, 1, x);
  if (slab_.hi) buffer_to_rows(g, buf[3].data(), slab_.lo + slab_.owned_rows(), slab_.lo + slab_.owned_rows() + 1, x);
#else
  (void)x;
#endif
}

void DistributedElasticity::exchange(real* x) const {
  begin_exchange(x);
  end_exchange(x);
}

template <class T>
void DistributedElasticity::apply_rows(const T* x, T* y, index y_begin, index y_end, const T* b) const {
  if (y_begin >= y_end) return;
  const GridDims& g = slab_.local;
  ScopedTimer t(Kernel::apply, double(g.nx() * (y_end - y_begin) * g.nz()) * in_precision<T>(b ? kResidualCost : kApplyCost));
  if constexpr (std::is_same<T, float>::value)
    elasticity_apply(kf_, x, y, RowBlock{0, g.nz(), y_begin, y_end}, b);
  else
    elasticity_apply(k_, x, y, RowBlock{0, g.nz(), y_begin, y_end}, b);
}

void DistributedElasticity::apply(const real* x, real* y) const { apply_impl<real>(x, y, nullptr); }
void DistributedElasticity::residual(const real* b, const real* x, real* r) const { apply_impl<real>(x, r, b); }
void DistributedElasticity::apply(const float* x, float* y) const { apply_impl<float>(x, y, nullptr); }
void DistributedElasticity::residual(const float* b, const float* x, float* r) const { apply_impl<float>(x, r, b); }

template <class T>
void DistributedElasticity::apply_impl(const T* x, T* y, const T* b) const {
  T* xg = const_cast<T*>(x);  // ghost rows only: communication scratch (header)
  const index first = slab_.lo, last = slab_.lo + slab_.owned_rows();  // owned local rows [first, last)
  if (overlap_) {
    begin_exchange(x);
    // rows whose stencils stay inside the owned rows, in chunks with a test
    // of the messages between them: Open MPI moves a large (rendezvous)
    // message only while the rank is inside an MPI call
    const index r0 = first + slab_.lo, r1 = std::max(r0, last - slab_.hi);
    const index chunks = slab_.lo + slab_.hi == 0 ? 1 : std::min<index>(kProgressChunks, std::max<index>(1, r1 - r0));
    for (index c = 0; c < chunks; ++c) {
      apply_rows(x, y, r0 + (r1 - r0) * c / chunks, r0 + (r1 - r0) * (c + 1) / chunks, b);
      if (c + 1 < chunks) test_exchange();
    }
    end_exchange(xg);
    if (slab_.lo) apply_rows(x, y, first, std::min(first + 1, last), b);
    if (slab_.hi && last - 1 >= first + slab_.lo) apply_rows(x, y, last - 1, last, b);
  } else {
    begin_exchange(x);
    end_exchange(xg);
    apply_rows(x, y, first, last, b);
  }
  zero_ghosts(y);
}

void DistributedElasticity::apply_planes(const real* x, real* y, index z_begin, index z_end) const {
  exchange(const_cast<real*>(x));  // ghost rows only (header)
  const GridDims& g = slab_.local;
  ScopedTimer t(Kernel::apply, double(g.nx() * slab_.owned_rows() * (z_end - z_begin)) * kApplyCost);
  elasticity_apply(k_, x, y, RowBlock{z_begin, z_end, slab_.lo, slab_.lo + slab_.owned_rows()});
}

template <class T>
void DistributedElasticity::zero_ghosts(T* v) const {
  if (slab_.lo) fill_row(slab_.local, T(0), 0, v);
  if (slab_.hi) fill_row(slab_.local, T(0), slab_.lo + slab_.owned_rows(), v);
}
template void DistributedElasticity::zero_ghosts<real>(real*) const;
template void DistributedElasticity::zero_ghosts<float>(float*) const;

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
