// Where a kernel runs and where its vectors live: the one place that decides.
//
// Every kernel in kernels/ states its work as its name, an index range, its
// modelled Cost and a body (a lambda over plain pointers), and hands them to one of
// the launchers below; no kernel starts threads itself. This is the seam of
// the backends (in the spirit of a `parallel_for` over an index range):
//
//   - host (this file): OpenMP threads when the modelled work is worth it
//     (worth_threads, types.hpp), each thread its share of the nodes by one
//     partition for every kernel (below: host_share), so every sweep gives
//     a thread the nodes whose pages it touched first;
//   - the `_ref` twins are plain serial loops beside each kernel (the
//     independent oracle of the tests, not a backend);
//   - the device (a TRESCA_OFFLOAD build, below): a second branch inside
//     the same launchers, `omp target teams distribute parallel for [simd]`
//     over the same bodies. Nothing above kernels/ names OpenMP's loop
//     constructs.
//
// Field<T> (field.hpp) is the storage of everything the linear machinery
// sweeps: the operators' stencils and diagonals, every multigrid level's
// vectors, the Krylov vectors; it lives where the launches run.
#pragma once
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <initializer_list>
#include <string>
#include <type_traits>
#include <vector>

#include "field.hpp"
#include "types.hpp"

namespace tresca {

// The device backend (a build with TRESCA_OFFLOAD, CMake option of that
// name: g++-12 with gcc-12-offload-nvptx). While launch_on_device() is
// true, every launcher below runs its body as an OpenMP target region on
// the default device, over the data() of device Fields (field.hpp: new
// Fields are made there meanwhile); without a GPU the target regions run on
// the host, through the same code path. Without TRESCA_OFFLOAD,
// launch_on_device() is false and set_launch_on_device refuses true.
bool launch_on_device();
void set_launch_on_device(bool on);  // throws std::invalid_argument if the build has no offload
bool offload_built();                // whether this build has TRESCA_OFFLOAD
// "device 0 of 1 (OpenMP offload: NVIDIA H200, 150.1 GB), 8 warps a team,
// multigrid levels and coarser meshes under 32768 nodes on the host, sums
// a block a warp",
// "none: target regions run on the host, 8 warps a team, ..." or "none
// (built without offload)"
std::string device_description();
// The GPU's name and memory ("NVIDIA H100 80GB HBM3", 85e9 bytes), asked of
// the CUDA driver that libgomp's nvptx plugin runs on (libcuda.so.1, opened
// at run time: no link to it) for the default device; empty and 0 where no
// device is present, the build has no offload or the driver does not answer.
struct DeviceInfo {
  std::string name;
  double memory_bytes = 0;
};
DeviceInfo device_info();

// Warps a team of every device launch: the thread_limit of its target region
// (GCC's nvptx backend maps an OpenMP thread to a warp, its simd lanes to the
// warp's 32 lanes). libgomp then starts as many teams as the GPU's registers
// hold at once: floor(registers an SM / (registers a thread x 32 x warps)) a
// multiprocessor, so fewer warps a team can fit more warps an SM where the
// kernels' register count is not a divisor (perf/offload_registers.py,
// RESULTS.md §0n). A thread's registers are those of the heaviest body in
// the kernel's device image: this file's launch.cpp and the vector kernels
// are a shared library of their own in an offload build, an image apart
// from the apply's (CMakeLists.txt, tresca_launch; RESULTS.md §0z). A
// build setting (CMake TRESCA_DEVICE_WARPS, 1..32; default 8, libgomp's
// own): a thread_limit known only at run time is a firstprivate value of
// the target region, which maps it, and every mapping allocates device
// memory, which in GCC 12's libgomp costs a launch about 1.5 ms (RESULTS.md
// §0zg). device_warps() is that value; it throws std::invalid_argument
// where the environment's TRESCA_DEVICE_WARPS asks for another (or for a
// count outside 1..32).
//
// With the default the regions name no team size at all (TRESCA_TEAM_SIZE
// is empty) and libgomp's nvptx plugin starts its own 8 warps a team (read
// in its binary: a thread count <= 0 becomes 8): the same teams. Any
// thread_limit clause makes GOMP_teams4, in every team on the device,
// allocate a task for its ICVs with the device's malloc and free it at the
// end (libgomp's nvptx PTX: gomp_new_icv), and on an H200 every launch then
// cost about 4 us a team, serialised: 1.3 ms for the vector kernels' 396
// teams, 0.8 ms for the apply's 132, 12 ms for 3168 teams of one warp
// (RESULTS.md §0zm; the same teams without a clause: to be measured,
// `run.sh launch`).
#ifndef TRESCA_DEVICE_WARPS
#define TRESCA_DEVICE_WARPS 8
#endif
constexpr int kDeviceWarps = TRESCA_DEVICE_WARPS;
static_assert(kDeviceWarps >= 1 && kDeviceWarps <= 32, "TRESCA_DEVICE_WARPS: a warp count in 1..32");
#if TRESCA_DEVICE_WARPS == 8
#define TRESCA_TEAM_SIZE
#else
#define TRESCA_TEAM_SIZE thread_limit(TRESCA_DEVICE_WARPS)
#endif
int device_warps();

// In a device run, the multigrid levels (the finest aside) and the nested
// iteration's coarser meshes with fewer nodes than this run on the host
// (GridHierarchy, core/multigrid; solve_coarser_mesh, core/contact/run.cpp):
// a host sweep of a few ten thousand nodes is modelled to cost about what
// one target region's launch does (perf/RESULTS.md §0w, §0y; to be measured
// on a GPU). A level's right-hand side and correction cross once a V-cycle,
// a coarser mesh's solution once. From TRESCA_DEVICE_MIN_NODES (a count
// >= 0; 0: every level and mesh on the device), read once, in a device run
// only; default 32768. Throws std::invalid_argument for any other value.
index device_min_nodes();

// A choice in the device form of the deterministic sums, open at run time
// as an A/B for the test machine until it has measured it (perf/RESULTS.md
// §0zh; the apply's choices were settled in §0zm): in sum_over_blocks (dot
// products, the fused CG updates) a block of 4096 entries summed by one
// warp across its lanes (TRESCA_DEVICE_WARP_SUMS=1, the default), or by a
// team, which opens a parallel region for each block and combines its
// warps' sums (0). Each block's sum is fixed by the choice, whatever the
// number of teams; the two differ in rounding. Read once;
// std::invalid_argument for any other value.
bool device_warp_sums();

// Launches (and new Fields) are the host's inside this scope, and where
// they were before after it: for builders that fill Fields entry by entry
// and then move what they made to space_before() (build_elasticity_stencil,
// build_transfer), and for work that belongs on the host in a device run
// (the coarse multigrid levels: `when` true for those, false for the
// others). A builder called inside another's scope builds on the host, and
// the outer one moves the whole.
class HostLaunches {
 public:
  explicit HostLaunches(bool when = true) : was_(launch_on_device()) {
    if (when) set_launch_on_device(false);
  }
  ~HostLaunches() { set_launch_on_device(was_); }
  HostLaunches(const HostLaunches&) = delete;
  HostLaunches& operator=(const HostLaunches&) = delete;
  // where the launches ran before: where what the scope builds belongs
  Space space_before() const { return was_ ? Space::device : Space::host; }

 private:
  bool was_;
};

// Every device launch and copy runs inside a DeviceRegion: where no GPU is
// present and TRESCA_DEVICE_GUARD=1, device memory is open to the host
// only meanwhile, and host Field memory is closed while a launch runs (the
// tests' check that a device solve never reads device memory on the host,
// nor host memory in a kernel: either would fail on a GPU and pass in the
// host fallback); otherwise it costs nothing. A copy opens both.
class DeviceRegion {
 public:
  explicit DeviceRegion(bool copy = false);
  ~DeviceRegion();
  DeviceRegion(const DeviceRegion&) = delete;
  DeviceRegion& operator=(const DeviceRegion&) = delete;

 private:
  bool copy_;
};
bool device_guarded();  // whether that guard is on

// scratch for a device launch: `bytes` of device memory, kept and reused
// from launch to launch (one launch at a time), one buffer for each use:
// the blocks' workers' (for_each_block_with_scratch), and the partial sums
// of sum_over_blocks
enum class Scratch { blocks, sums };
void* device_scratch(Scratch use, std::size_t bytes);
// the blocks' scratch on the device: at most kScratchTeams teams of
// kDeviceWarps workers, each with its own slice
constexpr int kScratchTeams = 1024;

// The launches so far, by where they ran: the fork/join census of
// `--profile` and bench_kernels. A threaded launch is one OpenMP parallel
// region (a fork, a join and its barrier); a one-thread launch ran on the
// calling thread, its work below worth_threads; a device launch is one
// target region. The seconds are wall time on the calling thread from each
// launch's start to its end (a target region's end waits for the device):
// what is neither threaded nor on the device ran on one host thread
// (one-thread launches, and the code between launches), the part that more
// threads do not shorten. The threaded launches are also counted by their
// modelled work (bytes + flops), in decades from kParallelWork: where small
// regions cost more than their work, fork/join and waking the threads is
// what they pay for.
struct LaunchCounts {
  long long threaded = 0, one_thread = 0, device = 0;
  double threaded_seconds = 0, one_thread_seconds = 0, device_seconds = 0;
  static constexpr int kSizes = 3;  // work below 10x, 100x kParallelWork, and more
  long long by_size[kSizes] = {};
  double by_size_seconds[kSizes] = {}, by_size_work[kSizes] = {};
};
LaunchCounts launch_counts();

// The same launches by kernel: every launcher names its kernel ("axpy",
// "apply (float)"; the name of a template kernel's float variant ends in
// " (float)", precision_name below), and each kernel's launches are kept
// by where they ran, with their wall time and modelled traffic: the
// `--profile` table "launches by kernel", in which every launch of a run
// appears (the rows above it time the solvers' phases, this one the
// kernels, on the host and on the device alike). Copies between host and
// device memory (space_copy) are counted here too, as the kernel "copy
// host to device" (or back), ran `copy`.
enum class Ran : int { threaded, one_thread, device, copy, count };
const char* to_string(Ran r);  // "threads", "1 thread", "device", "copy"
struct KernelLaunches {
  std::string kernel;
  Ran ran = Ran::threaded;
  long long calls = 0;
  double seconds = 0, bytes = 0, flops = 0;  // (bytes and flops: the calls' modelled Cost, summed)
};
// every (kernel, where) with a launch since the program started, in the
// order of their first launch
std::vector<KernelLaunches> launches_by_kernel();
// a template kernel's name in the census: its float variant's says so
template <class T>
constexpr const char* precision_name(const char* as_double, const char* as_float) {
  return std::is_same_v<T, float> ? as_float : as_double;
}

namespace detail {
inline long long now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
// one launch (or copy) of `kernel` that ran where `ran` says and took ns:
// in launch_counts (a threaded one in its size class too) and in
// launches_by_kernel
void count_launch(const char* kernel, Ran ran, Cost work, long long ns);
// One host launch of a kernel: whether it starts threads
// (worth_threads(work)), counted as what it is and timed until it goes out
// of scope. Host launches are made from the driver's thread only (none
// nests in another).
class HostLaunch {
 public:
  HostLaunch(const char* kernel, Cost work)
      : threads(worth_threads(work)), kernel_(kernel), work_(work), t0_(now_ns()) {}
  ~HostLaunch() { count_launch(kernel_, threads ? Ran::threaded : Ran::one_thread, work_, now_ns() - t0_); }
  HostLaunch(const HostLaunch&) = delete;
  HostLaunch& operator=(const HostLaunch&) = delete;
  const bool threads;

 private:
  const char* kernel_;
  Cost work_;
  long long t0_;
};
// bytes between the host's and the device's memory (omp_target_memcpy),
// not counted as a copy: part of the launch that makes it (a reduction's
// partial sums; space_copy counts the Fields' copies)
void copy_between(Space to_space, void* to, Space from_space, const void* from, std::size_t bytes);
// One device launch (a target region), counted and timed likewise.
class DeviceLaunch {
 public:
  DeviceLaunch(const char* kernel, Cost work) : kernel_(kernel), work_(work), t0_(now_ns()) {}
  ~DeviceLaunch() { count_launch(kernel_, Ran::device, work_, now_ns() - t0_); }
  DeviceLaunch(const DeviceLaunch&) = delete;
  DeviceLaunch& operator=(const DeviceLaunch&) = delete;

 private:
  const char* kernel_;
  Cost work_;
  long long t0_;
};
}  // namespace detail

// The host's one partition of a launch among its w workers: worker t owns
// the same nodes in every kernel, and so the memory it touched first (a
// fresh Field's pages are touched by the same rule, launch.cpp), which on a
// server with several NUMA nodes is memory on its own socket. Every 3D
// vector is three components of N nodes, component-major (grid.hpp), and a
// grid's node rows (iy, iz) hold its nodes in order, so:
//   - a range of n entries (or of blocks of them), a launch over one index,
//     is cut into thirds, and worker t takes the t-th w-th of each third
//     (entry_share): of a vector, its nodes' entries in every component;
//   - a range of node rows, a launch over (iz, iy), is taken in order, and
//     worker t takes the t-th w-th of the rows (host_share): the same nodes,
//     up to one row at each end.
// Shares differ by at most one entry or row (no idle worker, whatever n).
struct Share {
  index begin, end;
};
inline Share host_share(index n, index t, index w) { return {n * t / w, n * (t + 1) / w}; }
constexpr index kThirds = 3;
inline Share entry_share(index n, index third, index t, index w) {
  const index a = n * third / kThirds, b = n * (third + 1) / kThirds;
  const Share s = host_share(b - a, t, w);
  return {a + s.begin, a + s.end};
}

namespace detail {
// body(t, w) on each of the w workers of a host launch (one unless threads)
template <class Body>
inline void on_host_workers(bool threads, const Body& body) {
  if (!threads) {  // (a parallel region of one thread still costs the runtime's team set-up: 0.2 us)
    body(index(0), index(1));
    return;
  }
#pragma omp parallel
  body(index(omp_get_thread_num()), index(omp_get_num_threads()));
}
// body(i0, i1) for each nonempty run of worker t's entries of [0, n)
template <class Body>
inline void for_entry_runs(index n, index t, index w, const Body& body) {
  for (index c = 0; c < kThirds; ++c) {
    const Share s = entry_share(n, c, t, w);
    if (s.begin < s.end) body(s.begin, s.end);
  }
}
// body(j, i) for worker t's node rows of an n1 x n0 range (j slow, i fast)
template <class Body>
inline void for_row_share(index n1, index n0, index t, index w, const Body& body) {
  const Share s = host_share(n1 * n0, t, w);
  for (index k = s.begin; k < s.end; ++k) body(k / n0, k % n0);
}
}  // namespace detail

#ifdef TRESCA_OFFLOAD
// What a target region takes from the host: its ranges, its scratch and its
// body (a lambda's captures: device pointers and scalars), in a variable of
// the device image, `tresca_device_args`, sent before each launch by
// `target update` (one small copy to the device), so that the region maps
// nothing. Two reasons, both met on an H200 (RESULTS.md §0zf; the first
// traced in libgomp's binary, §0zg):
//   - a target region with any map clause, even an implicit firstprivate
//     one, allocates device memory for the addresses of what it maps, and
//     libgomp's nvptx plugin (GCC 12) frees its cached per-warp stacks at
//     every allocation when they exceed 128 MiB, as they do (128 KiB a
//     warp, thousands of warps: 0.14 GB for the program's kernels at 8
//     warps an SM, 0.4 GB for the vector kernels'): every launch then
//     allocated them anew and cost 1.5 ms, the whole solve's time;
//   - GCC 12 attaches a mapped lambda's pointer captures: device pointers
//     (omp_target_alloc's, not in libgomp's table) arrived as NULL.
// One copy per translation unit (internal linkage), in its own device image
// (a program's and libtresca_launch.so's are images apart, CMakeLists.txt).
namespace detail {
// under the device guard (TRESCA_DEVICE_GUARD=1), std::logic_error where a
// device launch's body holds an address in the host's malloc heap (a
// std::vector's or an Eigen vector's data: an illegal address on a GPU,
// which the host fallback reads without complaint)
void check_device_body(const char* kernel, const void* body, std::size_t bytes);
constexpr std::size_t kDeviceBodyBytes = 512;
constexpr int kDeviceArgSizes = 4;
struct DeviceArgs {
  index n[kDeviceArgSizes];  // the launch's sizes
  void* pool;
  alignas(16) unsigned char body[kDeviceBodyBytes];
};
}  // namespace detail
#pragma omp declare target
static detail::DeviceArgs tresca_device_args;
#pragma omp end declare target
namespace detail {
// sends a launch's ranges, scratch and body to the device
template <class Body>
inline void send_to_device(const char* kernel, const Body& body, std::initializer_list<index> sizes,
                           void* pool = nullptr) {
  static_assert(std::is_trivially_copyable<Body>::value, "a device body holds device pointers and scalars");
  static_assert(sizeof(Body) <= kDeviceBodyBytes, "a device body larger than kDeviceBodyBytes");
  TRESCA_ASSERT(sizes.size() <= std::size_t(kDeviceArgSizes));
  check_device_body(kernel, &body, sizeof(Body));
  std::copy(sizes.begin(), sizes.end(), tresca_device_args.n);
  tresca_device_args.pool = pool;
  std::memcpy(tresca_device_args.body, &body, sizeof(Body));
#pragma omp target update to(tresca_device_args)
}
// the body sent, in a target region
template <class Body>
inline const Body& sent_body() {
  return *reinterpret_cast<const Body*>(tresca_device_args.body);
}
// body(i) for every i in [0, n) as one target region, across the teams'
// threads and their lanes, wherever the launches run
template <class Body>
inline void device_entries(const char* kernel, index n, Cost per_entry, const Body& body) {
  const DeviceLaunch launch(kernel, double(n) * per_entry);
  DeviceRegion region;
  send_to_device(kernel, body, {n});
#pragma omp target teams distribute parallel for simd TRESCA_TEAM_SIZE
  for (index i = 0; i < tresca_device_args.n[0]; ++i) sent_body<Body>()(i);
}
}  // namespace detail
#endif

// body(i) for every i in [0, n), independent entries vectorised across i.
template <class Body>
inline void for_each_entry(const char* kernel, index n, Cost per_entry, const Body& body) {
#ifdef TRESCA_OFFLOAD
  if (launch_on_device()) {
    detail::device_entries(kernel, n, per_entry, body);
    return;
  }
#endif
  const detail::HostLaunch launch(kernel, double(n) * per_entry);
  detail::on_host_workers(launch.threads, [&](index t, index w) {
    const Body b = body;  // (each worker's own copy: its captures in registers, not reloaded after every store)
    detail::for_entry_runs(n, t, w, [&](index i0, index i1) {
#pragma omp simd
      for (index i = i0; i < i1; ++i) b(i);
    });
  });
}

// Before a loop inside a block's body whose iterations a GPU warp's lanes
// should share (in a device body a loop without `omp simd` runs on one
// lane) but which the CPU runs faster as scalar code (indirect reads: as
// AVX-512 gathers the transfers took 35 % longer, RESULTS.md §0n):
// `omp simd` in an offload build only.
#ifdef TRESCA_OFFLOAD
#define TRESCA_DEVICE_LANES _Pragma("omp simd")
#else
#define TRESCA_DEVICE_LANES
#endif

// body(b) for every block b in [0, n) on the host's threads only, for a
// kernel whose device form is another function (the banded apply: its
// device form is elasticity_apply_rows). Its body stays out of the device
// image: there the most register-hungry body sets the registers, and so the
// occupancy, of every kernel (perf/offload_registers.py, RESULTS.md §0n).
template <class Body>
inline void for_each_host_block(const char* kernel, index n, Cost work, const Body& body) {
  const detail::HostLaunch launch(kernel, work);
  detail::on_host_workers(launch.threads, [&](index t, index w) {
    detail::for_entry_runs(n, t, w, [&](index b0, index b1) {
      for (index b = b0; b < b1; ++b) body(b);
    });
  });
}

// body(s) once on each host worker, s its share of n node rows (host_share),
// for a kernel that sweeps its rows in an order of its own (the banded
// apply's cache bands, kernels/elasticity.cpp). Host only, like the above.
template <class Body>
inline void for_each_host_share(const char* kernel, index n, Cost work, const Body& body) {
  const detail::HostLaunch launch(kernel, work);
  detail::on_host_workers(launch.threads, [&](index t, index w) { body(host_share(n, t, w)); });
}

// body(b) for every block b in [0, n): independent blocks of work (rows,
// bands of rows), each vectorised inside by its own body. `work` is the
// whole launch's modelled cost.
template <class Body>
inline void for_each_block(const char* kernel, index n, Cost work, const Body& body) {
#ifdef TRESCA_OFFLOAD
  if (launch_on_device()) {
    const detail::DeviceLaunch launch(kernel, work);
    DeviceRegion region;
    detail::send_to_device(kernel, body, {n});
#pragma omp target teams distribute parallel for TRESCA_TEAM_SIZE
    for (index i = 0; i < tresca_device_args.n[0]; ++i) detail::sent_body<Body>()(i);
    return;
  }
#endif
  for_each_host_block(kernel, n, work, body);
}

// body(j, i) for every block of an n1 x n0 range (j slow, i fast).
template <class Body>
inline void for_each_block(const char* kernel, index n1, index n0, Cost work, const Body& body) {
#ifdef TRESCA_OFFLOAD
  if (launch_on_device()) {  // one block per (team) thread; the body's own `omp simd` loops in its lanes
    const detail::DeviceLaunch launch(kernel, work);
    DeviceRegion region;
    detail::send_to_device(kernel, body, {n1, n0});
    // a team's warps take its rows in turn, so that at any time they sweep
    // neighbouring rows, whose inputs overlap in the multiprocessor's cache
    // (1.35x the apply's speed of contiguous runs a warp on an H200,
    // RESULTS.md §0zm)
#pragma omp target teams distribute parallel for collapse(2) TRESCA_TEAM_SIZE schedule(static, 1)
    for (index j = 0; j < tresca_device_args.n[0]; ++j)
      for (index i = 0; i < tresca_device_args.n[1]; ++i) detail::sent_body<Body>()(j, i);
    return;
  }
#endif
  const detail::HostLaunch launch(kernel, work);
  detail::on_host_workers(launch.threads,
                          [&](index t, index w) { detail::for_row_share(n1, n0, t, w, body); });
}

// body(c, j, i, scratch) for every block of n2 fields' n1 x n0 ranges
// (the three components of a vector: c), with `scratch` entries of T
// private to each worker for the launch (allocated once per launch, not per
// block). Each host thread takes the same share of the n1 x n0 rows in
// every field (its share of the nodes, for_row_share) and sweeps the fields
// one after the other: what a block reads of its neighbours' rows is still
// in the caches when they come (the transfers' rows of one component, not
// three: 15-35 % faster at levels 12 and 13 on 2 cores, RESULTS.md §0zc).
template <class T, class Body>
inline void for_each_block_with_scratch(const char* kernel, index n2, index n1, index n0, index scratch, Cost work,
                                        const Body& body) {
#ifdef TRESCA_OFFLOAD
  if (launch_on_device()) {  // each (team, thread) its slice of one scratch buffer
    const detail::DeviceLaunch launch(kernel, work);
    void* pool = device_scratch(Scratch::blocks, std::size_t(kScratchTeams) * kDeviceWarps * scratch * sizeof(T));
    DeviceRegion region;
    // (the sizes, then each worker's slice of the pool: `scratch` entries)
    detail::send_to_device(kernel, body, {n2, n1, n0, scratch}, pool);
#pragma omp target teams distribute parallel for collapse(3) num_teams(kScratchTeams) TRESCA_TEAM_SIZE
    for (index c = 0; c < tresca_device_args.n[0]; ++c)
      for (index j = 0; j < tresca_device_args.n[1]; ++j)
        for (index i = 0; i < tresca_device_args.n[2]; ++i)
          detail::sent_body<Body>()(c, j, i,
                                    static_cast<T*>(tresca_device_args.pool) +
                                        (index(omp_get_team_num()) * kDeviceWarps + omp_get_thread_num()) *
                                            tresca_device_args.n[3]);
    return;
  }
#endif
  const detail::HostLaunch launch(kernel, work);
  detail::on_host_workers(launch.threads, [&](index t, index w) {
    std::vector<T> buffer(scratch);
    T* s = buffer.data();
    for (index c = 0; c < n2; ++c) detail::for_row_share(n1, n0, t, w, [&](index j, index i) { body(c, j, i, s); });
  });
}

// Sum of block(i0, i1) over the fixed blocks [b*width, (b+1)*width) of
// [0, n): the blocks in parallel, their sums added in order afterwards, so
// the result is bitwise the same for any number of workers. Each caller's
// block is a loop over plain pointers (the CPU's explicit vectors,
// simd.hpp). entry(i) is the same sum's term of one entry, the device's
// form, in one of two ways (device_warp_sums()): a warp per block, its
// entries across the warp's lanes, or a team per block, its entries across
// the team's warps and lanes (a parallel region a block). Either reads
// memory coalesced, where one lane walking a block of 4096 would not.
template <class Block, class Entry>
inline real sum_over_blocks(const char* kernel, index n, index width, Cost per_entry, const Block& block,
                            const Entry& entry) {
  const index nb = (n + width - 1) / width;
  constexpr index kStack = 256;
  real stack[kStack];
  std::vector<real> heap;
  real* part = stack;
  if (nb > kStack) {
    heap.resize(nb);
    part = heap.data();
  }
  (void)entry;  // (the host's form is block)
#ifdef TRESCA_OFFLOAD
  if (launch_on_device()) {
    const detail::DeviceLaunch launch(kernel, double(n) * per_entry);
    void* sums = device_scratch(Scratch::sums, std::size_t(nb) * sizeof(real));
    {
      DeviceRegion region;
      detail::send_to_device(kernel, entry, {n, width, nb}, sums);
      if (device_warp_sums()) {  // a warp a block, its entries across the lanes
#pragma omp target teams distribute parallel for TRESCA_TEAM_SIZE
        for (index b = 0; b < tresca_device_args.n[2]; ++b) {
          const index all = tresca_device_args.n[0], w = tresca_device_args.n[1];
          const index i1 = b + 1 < tresca_device_args.n[2] ? (b + 1) * w : all;
          const Entry& e = detail::sent_body<Entry>();
          real s = 0;
#pragma omp simd reduction(+ : s)
          for (index i = b * w; i < i1; ++i) s += e(i);
          static_cast<real*>(tresca_device_args.pool)[b] = s;
        }
      } else {  // a team a block, its entries across the team's warps and lanes
#pragma omp target teams distribute TRESCA_TEAM_SIZE
        for (index b = 0; b < tresca_device_args.n[2]; ++b) {
          const index all = tresca_device_args.n[0], w = tresca_device_args.n[1];
          const index i1 = b + 1 < tresca_device_args.n[2] ? (b + 1) * w : all;
          const Entry& e = detail::sent_body<Entry>();
          real s = 0;
#pragma omp parallel for simd reduction(+ : s)
          for (index i = b * w; i < i1; ++i) s += e(i);
          static_cast<real*>(tresca_device_args.pool)[b] = s;
        }
      }
    }
    detail::copy_between(Space::host, part, Space::device, sums, std::size_t(nb) * sizeof(real));
  } else
#endif
  {
    // each block on the worker that owns its first entry
    const detail::HostLaunch launch(kernel, double(n) * per_entry);
    detail::on_host_workers(launch.threads, [&](index t, index w) {
      detail::for_entry_runs(n, t, w, [&](index i0, index i1) {
        for (index b = (i0 + width - 1) / width; b * width < i1; ++b)
          part[b] = block(b * width, std::min(n, (b + 1) * width));
      });
    });
  }
  real s = 0;
  for (index b = 0; b < nb; ++b) s += part[b];
  return s;
}

// Sum of entry(i) over [0, n) by sum_over_blocks (deterministic, both
// forms from the one term): for sums whose term is not worth an explicit
// vector block (counts, reductions over contact nodes).
template <class Entry>
inline real sum_over_entries(const char* kernel, index n, Cost per_entry, const Entry& entry) {
  constexpr index kWidth = 4096;
  return sum_over_blocks(
      kernel, n, kWidth, per_entry,
      [&](index i0, index i1) {
        real s = 0;
        for (index i = i0; i < i1; ++i) s += entry(i);
        return s;
      },
      entry);
}

}  // namespace tresca
