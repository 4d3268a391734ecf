#include "core/parallel/row_fetch.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "kernels/transfer.hpp"

#ifdef TRESCA_HAVE_MPI
#include <mpi.h>
#endif

namespace tresca {

RowFetch::RowFetch(const Slab& s, index a, index b, const Comm& comm) : s_(s), comm_(comm), a_(a), b_(b) {
  const bool none = a == 0 && b == 0;  // this rank takes part but wants nothing
  if (!none && (!(0 <= a && a < b && b <= s.global.ny()) || b - a < 2))
    throw std::invalid_argument("RowFetch: rows [" + std::to_string(a) + ", " + std::to_string(b) + ") of " +
                                std::to_string(s.global.ny()));
  box_ = none ? GridDims{} : rows_box(s.global, a, b);
  const int P = comm.size();
  std::vector<long long> mine = {(long long)a, (long long)b, (long long)s.y_begin, (long long)s.y_end};
  std::vector<long long> all(4 * size_t(P));
#ifdef TRESCA_HAVE_MPI
  if (P > 1)
    MPI_Allgather(mine.data(), 4, MPI_LONG_LONG, all.data(), 4, MPI_LONG_LONG, MPI_COMM_WORLD);
  else
#endif
    all = mine;
  const index plane_row = 3 * s.global.nx() * s.global.nz();  // doubles per row
  send_lo_.resize(P), send_hi_.resize(P), recv_lo_.resize(P), recv_hi_.resize(P);
  send_counts_.assign(P, 0), send_displs_.assign(P, 0), recv_counts_.assign(P, 0), recv_displs_.assign(P, 0);
  int so = 0, ro = 0;
  for (int q = 0; q < P; ++q) {
    // q wants [all[4q], all[4q+1]); I own [y_begin, y_end)
    send_lo_[q] = std::max<index>(index(all[4 * q]), s.y_begin);
    send_hi_[q] = std::max(send_lo_[q], std::min<index>(index(all[4 * q + 1]), s.y_end));
    // I want [a, b); q owns [all[4q+2], all[4q+3])
    recv_lo_[q] = std::max<index>(a, index(all[4 * q + 2]));
    recv_hi_[q] = std::max(recv_lo_[q], std::min<index>(b, index(all[4 * q + 3])));
    send_counts_[q] = int((send_hi_[q] - send_lo_[q]) * plane_row);
    recv_counts_[q] = int((recv_hi_[q] - recv_lo_[q]) * plane_row);
    send_displs_[q] = so;
    recv_displs_[q] = ro;
    so += send_counts_[q];
    ro += recv_counts_[q];
    if (q != comm.rank()) bytes_ += double(send_counts_[q]) * sizeof(real);
  }
  if (ro != int((b - a) * plane_row)) throw std::logic_error("RowFetch: the owners do not cover the rows");
  send_total_ = so;
  recv_total_ = ro;
}

template <class T>
void RowFetch::fetch(const T* local, T* out) const {
  const int P = comm_.size();
  std::vector<T>& send = [&]() -> std::vector<T>& {
    if constexpr (std::is_same<T, float>::value) return send_s_; else return send_d_;
  }();
  std::vector<T>& recv = [&]() -> std::vector<T>& {
    if constexpr (std::is_same<T, float>::value) return recv_s_; else return recv_d_;
  }();
  send.resize(send_total_);
  recv.resize(recv_total_);
  for (int q = 0; q < P; ++q)
    if (send_counts_[q])
      rows_to_buffer(s_.local, local, s_.local_row(send_lo_[q]), s_.local_row(send_hi_[q]), send.data() + send_displs_[q]);
#ifdef TRESCA_HAVE_MPI
  if (P > 1) {
    const MPI_Datatype type = std::is_same<T, float>::value ? MPI_FLOAT : MPI_DOUBLE;
    MPI_Alltoallv(send.data(), send_counts_.data(), send_displs_.data(), type, recv.data(), recv_counts_.data(),
                  recv_displs_.data(), type, MPI_COMM_WORLD);
    for (int q = 0; q < P; ++q)
      if (q != comm_.rank() && send_counts_[q]) {
        comm_counters().messages += 1;
        comm_counters().bytes += double(send_counts_[q]) * sizeof(T);
      }
  } else
#endif
    std::copy(send.begin(), send.end(), recv.begin());
  for (int q = 0; q < P; ++q)
    if (recv_counts_[q]) buffer_to_rows(box_, recv.data() + recv_displs_[q], recv_lo_[q] - a_, recv_hi_[q] - a_, out);
}
template void RowFetch::fetch<real>(const real*, real*) const;
template void RowFetch::fetch<float>(const float*, float*) const;

void prolongate_slabs(const Slab& coarse, const real* uc, const Slab& fine, real* uf, const Comm& comm) {
  const Transfer T = build_transfer(fine.global, coarse.global);
  const Interp1D& Y = T.axis[1];
  const index f0 = fine.y_begin - fine.lo, f1 = fine.y_end + fine.hi, nyc = coarse.global.ny();
  if (coarse.ranks == 1) {  // the coarse vector is whole here
    prolongate(f0 == 0 && f1 == fine.global.ny() ? T : slice_rows(T, f0, f1, 0, nyc), 3, uc, uf);
    return;
  }
  index ca = nyc, cb = 0;
  for (index i = f0; i < f1; ++i) ca = std::min(ca, Y.j0[i]), cb = std::max(cb, Y.j0[i] + 2);
  cb = std::min(cb, nyc);
  ca = std::min(ca, cb - 2);
  const RowFetch fetch(coarse, ca, cb, comm);
  std::vector<real> rows(fetch.size());
  fetch.fetch(uc, rows.data());
  prolongate(slice_rows(T, f0, f1, ca, cb), 3, rows.data(), uf);
}

}  // namespace tresca
