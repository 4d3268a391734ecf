// The ranks of a run: MPI_COMM_WORLD when the build has MPI (CMake option
// TRESCA_MPI, macro TRESCA_HAVE_MPI), otherwise one rank. OpenMP threads run
// inside each rank (MPI_THREAD_FUNNELED: only the thread that called
// MpiSession talks to MPI).
//
// Reductions: each rank sums its own entries in a fixed order (the
// kernels' blocked sums, independent of the thread count), then
// MPI_Allreduce combines the ranks' partial sums; with one rank the result
// is the local sum itself, bit for bit.
#pragma once
#include <vector>

#include "core/util/reduction.hpp"
#include "kernels/types.hpp"

namespace tresca {

class Comm : public Reduction {
 public:
  // the world of this process: MPI_COMM_WORLD if MPI is initialised, else one rank
  static const Comm& world();
  // this rank alone (size 1, nothing is ever sent): the whole problem on
  // every rank, e.g. a grid too small to split
  static const Comm& self();
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool distributed() const { return size_ > 1; }
  real sum(real local) const override;
  void sum(real* values, int n) const;  // in place, element by element
  double max(double local) const;
  // in place: rank q's part v[displs[q] .. displs[q] + counts[q]) to every rank
  void allgather(real* v, const std::vector<int>& counts, const std::vector<int>& displs) const;
  void barrier() const;
  // v[0..n) of rank `root` to every rank
  // (T = double or float)
  template <class T>
  void broadcast(T* v, int n, int root = 0) const;
  // how many ranks run on this rank's machine (MPI_COMM_TYPE_SHARED)
  int ranks_on_this_host() const;

 private:
  int rank_ = 0, size_ = 1;
  friend class MpiSession;
};

// What this rank has sent since the start: point-to-point messages and
// bytes (ghost exchanges, row fetches counted per peer), allreduces, and
// other collectives (allgathers, broadcasts). Counted where they are posted;
// one rank: zeros.
struct CommCounters {
  long long messages = 0, allreduces = 0, collectives = 0;
  double bytes = 0;
};
CommCounters& comm_counters();

// MPI_Init_thread / MPI_Finalize around main (RAII), when an MPI launcher
// (mpirun, mpiexec) started the program; otherwise, and without MPI,
// nothing: one rank.
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
};

// How many ranks the process launcher started, from its environment
// (Open MPI, MPICH), whether or not this build has MPI: lets a
// program that is not distributed refuse to run as several copies of itself.
int launched_ranks();

}  // namespace tresca
