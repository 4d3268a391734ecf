#include "core/parallel/halo.hpp"

#include <algorithm>

#include "core/parallel/comm.hpp"
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
}  // namespace

template <>
std::vector<double>* Halo::buffers<double>() const {
  return buf_d_;
}
template <>
std::vector<float>* Halo::buffers<float>() const {
  return buf_s_;
}

Halo::Halo(const Slab& s) : slab_(s) {}

template <class T>
void Halo::exchange(T* x) const {
  if (empty()) return;
#ifdef TRESCA_HAVE_MPI
  const GridDims& g = slab_.local;
  const int n = int(3 * g.nx() * g.nz());
  std::vector<T>* buf = buffers<T>();
  for (int i = 0; i < 4; ++i) buf[i].resize(n);
  const MPI_Datatype type = sizeof(T) == sizeof(double) ? MPI_DOUBLE : MPI_FLOAT;
  const index first = slab_.lo, last = slab_.lo + slab_.owned_rows();  // owned local rows [first, last)
  MPI_Request req[4];
  int pending = 0;
  // tag 0: a row travelling up (from rank r to r + 1), tag 1: down
  if (slab_.lo) MPI_Irecv(buf[2].data(), n, type, slab_.rank - 1, 0, MPI_COMM_WORLD, &req[pending++]);
  if (slab_.hi) MPI_Irecv(buf[3].data(), n, type, slab_.rank + 1, 1, MPI_COMM_WORLD, &req[pending++]);
  if (slab_.lo) {
    rows_to_buffer(g, x, first, first + 1, buf[0].data());
    MPI_Isend(buf[0].data(), n, type, slab_.rank - 1, 1, MPI_COMM_WORLD, &req[pending++]);
  }
  if (slab_.hi) {
    rows_to_buffer(g, x, last - 1, last, buf[1].data());
    MPI_Isend(buf[1].data(), n, type, slab_.rank + 1, 0, MPI_COMM_WORLD, &req[pending++]);
  }
  const double t0 = wall_time();
  MPI_Waitall(pending, req, MPI_STATUSES_IGNORE);
  counts_.wait_seconds += wall_time() - t0;
  if (slab_.lo) buffer_to_rows(g, buf[2].data(), 0, 1, x);
  if (slab_.hi) buffer_to_rows(g, buf[3].data(), last, last + 1, x);
  const int sent = slab_.lo + slab_.hi;
  counts_.exchanges += 1;
  counts_.messages += sent;
  counts_.bytes += double(sent) * n * sizeof(T);
  comm_counters().messages += sent;
  comm_counters().bytes += double(sent) * n * sizeof(T);
#else
  (void)x;
#endif
}
template void Halo::exchange<double>(double*) const;
template void Halo::exchange<float>(float*) const;

template <class T>
void Halo::zero_ghosts(T* v) const {
  if (slab_.lo) fill_row(slab_.local, T(0), 0, v);
  if (slab_.hi) fill_row(slab_.local, T(0), slab_.lo + slab_.owned_rows(), v);
}
template void Halo::zero_ghosts<double>(double*) const;
template void Halo::zero_ghosts<float>(float*) const;

}  // namespace tresca
