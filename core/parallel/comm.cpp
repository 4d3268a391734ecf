#include "core/parallel/comm.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <type_traits>

#ifdef TRESCA_HAVE_MPI
#include <mpi.h>
#endif

namespace tresca {

namespace {
Comm& world_instance() {
  static Comm c;
  return c;
}
}  // namespace

const Comm& Comm::world() { return world_instance(); }
const Comm& Comm::self() {
  static const Comm c;
  return c;
}

CommCounters& comm_counters() {
  static CommCounters c;
  return c;
}

#ifdef TRESCA_HAVE_MPI
namespace {
bool session_started = false;
// started by an MPI launcher (mpirun / mpiexec, with any rank count)
bool launched_by_mpi() { return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK"); }
}  // namespace
#endif

MpiSession::MpiSession(int& argc, char**& argv) {
#ifdef TRESCA_HAVE_MPI
  // a plain run is one rank without MPI: Open MPI's singleton start-up
  // spawns a daemon, a fixed cost on every run
  if (!launched_by_mpi()) return;
  session_started = true;
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  if (provided < MPI_THREAD_FUNNELED) throw std::runtime_error("MPI does not provide MPI_THREAD_FUNNELED");
  Comm& c = world_instance();
  MPI_Comm_rank(MPI_COMM_WORLD, &c.rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &c.size_);
#else
  (void)argc;
  (void)argv;
#endif
}

MpiSession::~MpiSession() {
#ifdef TRESCA_HAVE_MPI
  if (session_started) MPI_Finalize();
#endif
}

real Comm::sum(real local) const {
  sum(&local, 1);
  return local;
}

void Comm::sum(real* values, int n) const {
#ifdef TRESCA_HAVE_MPI
  if (size_ > 1) {
    MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    comm_counters().allreduces += 1;
  }
#else
  (void)values;
  (void)n;
#endif
}

double Comm::max(double local) const {
#ifdef TRESCA_HAVE_MPI
  if (size_ > 1) {
    double global = 0;
    MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    comm_counters().allreduces += 1;
    return global;
  }
#endif
  return local;
}

void Comm::allgather(real* v, const std::vector<int>& counts, const std::vector<int>& displs) const {
#ifdef TRESCA_HAVE_MPI
  if (size_ > 1) {
    MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, v, counts.data(), displs.data(), MPI_DOUBLE, MPI_COMM_WORLD);
    comm_counters().collectives += 1;
    comm_counters().bytes += double(counts[rank_]) * sizeof(real) * (size_ - 1);
  }
#else
  (void)v;
  (void)counts;
  (void)displs;
#endif
}

template <class T>
void Comm::broadcast(T* v, int n, int root) const {
#ifdef TRESCA_HAVE_MPI
  if (size_ > 1) {
    MPI_Bcast(v, n, std::is_same<T, float>::value ? MPI_FLOAT : MPI_DOUBLE, root, MPI_COMM_WORLD);
    comm_counters().collectives += 1;
    if (rank_ == root) comm_counters().bytes += double(n) * sizeof(T) * (size_ - 1);
  }
#else
  (void)v;
  (void)n;
  (void)root;
#endif
}
template void Comm::broadcast<real>(real*, int, int) const;
template void Comm::broadcast<float>(float*, int, int) const;

int Comm::ranks_on_this_host() const {
#ifdef TRESCA_HAVE_MPI
  if (size_ > 1) {
    MPI_Comm host;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &host);
    int n = 1;
    MPI_Comm_size(host, &n);
    MPI_Comm_free(&host);
    return n;
  }
#endif
  return 1;
}

void Comm::barrier() const {
#ifdef TRESCA_HAVE_MPI
  if (size_ > 1) MPI_Barrier(MPI_COMM_WORLD);
#endif
}

int launched_ranks() {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    if (const char* v = std::getenv(var)) {
      const int n = std::atoi(v);
      if (n > 0) return n;
    }
  }
  return 1;
}

}  // namespace tresca
