#include "launch.hpp"

#include <dlfcn.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>

namespace tresca {

namespace {
constexpr std::size_t kHugePage = std::size_t(2) << 20;
constexpr std::size_t kHugeFrom = std::size_t(1) << 20;
}  // namespace

namespace {
bool on_device = false;
int device() { return omp_get_num_devices() > 0 ? omp_get_default_device() : omp_get_initial_device(); }
}  // namespace

bool offload_built() {
#ifdef TRESCA_OFFLOAD
  return true;
#else
  return false;
#endif
}

bool launch_on_device() { return on_device; }

namespace {
// the census: a slot per kernel name with its counts by where they ran, and
// the threaded launches by size class; LaunchCounts' totals are the slots'
// sums. All under one lock (launches come from the driver's thread; the
// lock keeps a stray one from another safe).
struct KernelSlot {
  const char* kernel;
  long long calls[int(Ran::count)] = {};
  long long ns[int(Ran::count)] = {};
  double bytes[int(Ran::count)] = {}, flops[int(Ran::count)] = {};
};
struct Census {
  std::mutex mutex;
  std::vector<KernelSlot> slots;
  long long by_size[LaunchCounts::kSizes] = {}, ns_by_size[LaunchCounts::kSizes] = {};
  double work_by_size[LaunchCounts::kSizes] = {};
};
Census& census() {
  static Census c;
  return c;
}
}  // namespace

const char* to_string(Ran r) {
  static const char* names[] = {"threads", "1 thread", "device", "copy"};
  return names[int(r)];
}

void detail::count_launch(const char* kernel, Ran ran, Cost work, long long ns) {
  Census& c = census();
  const std::lock_guard<std::mutex> lock(c.mutex);
  // a name is a string literal: the same pointer (every slot compared by
  // pointer first, no string compare on a launch's usual path), or the same
  // text where two translation units each hold a copy of it
  auto s = std::find_if(c.slots.begin(), c.slots.end(), [&](const KernelSlot& k) { return k.kernel == kernel; });
  if (s == c.slots.end())
    s = std::find_if(c.slots.begin(), c.slots.end(),
                     [&](const KernelSlot& k) { return !std::strcmp(k.kernel, kernel); });
  if (s == c.slots.end()) s = c.slots.insert(c.slots.end(), KernelSlot{kernel});
  const int r = int(ran);
  s->calls[r] += 1;
  s->ns[r] += ns;
  s->bytes[r] += work.bytes;
  s->flops[r] += work.flops;
  if (ran == Ran::threaded) {
    const double w = work.bytes + work.flops;
    const int k = w < 10 * kParallelWork ? 0 : w < 100 * kParallelWork ? 1 : 2;
    static_assert(LaunchCounts::kSizes == 3, "the size classes above");
    c.by_size[k] += 1;
    c.ns_by_size[k] += ns;
    c.work_by_size[k] += w;
  }
}

std::vector<KernelLaunches> launches_by_kernel() {
  Census& c = census();
  const std::lock_guard<std::mutex> lock(c.mutex);
  std::vector<KernelLaunches> out;
  for (const KernelSlot& s : c.slots)
    for (int r = 0; r < int(Ran::count); ++r)
      if (s.calls[r] > 0) out.push_back({s.kernel, Ran(r), s.calls[r], 1e-9 * double(s.ns[r]), s.bytes[r], s.flops[r]});
  return out;
}

LaunchCounts launch_counts() {
  Census& c = census();
  const std::lock_guard<std::mutex> lock(c.mutex);
  LaunchCounts t;
  long long ns[3] = {};  // (threaded, one_thread, device; copies are no launch)
  for (const KernelSlot& s : c.slots) {
    t.threaded += s.calls[int(Ran::threaded)];
    t.one_thread += s.calls[int(Ran::one_thread)];
    t.device += s.calls[int(Ran::device)];
    for (int r = 0; r < 3; ++r) ns[r] += s.ns[r];
  }
  t.threaded_seconds = 1e-9 * double(ns[int(Ran::threaded)]);
  t.one_thread_seconds = 1e-9 * double(ns[int(Ran::one_thread)]);
  t.device_seconds = 1e-9 * double(ns[int(Ran::device)]);
  for (int k = 0; k < LaunchCounts::kSizes; ++k) {
    t.by_size[k] = c.by_size[k];
    t.by_size_seconds[k] = 1e-9 * double(c.ns_by_size[k]);
    t.by_size_work[k] = c.work_by_size[k];
  }
  return t;
}

void set_launch_on_device(bool on) {
  if (on && !offload_built())
    throw std::invalid_argument("this build has no device backend (configure with -DTRESCA_OFFLOAD=ON)");
  if (on) {  // a bad TRESCA_DEVICE_* setting stops here, before any launch
    device_warps();
    device_min_nodes();
    device_warp_sums();
  }
  on_device = on;
}

namespace {
// The integer setting in environment variable `name`: `fallback` where it
// is unset or empty, else a whole number in [lo, hi], or std::invalid_argument
// saying "NAME=value must be <what>"
long long setting(const char* name, long long fallback, long long lo, long long hi, const char* what) {
  const char* e = std::getenv(name);
  if (e == nullptr || *e == '\0') return fallback;
  char* end = nullptr;
  const long long v = std::strtoll(e, &end, 10);
  if (*end != '\0' || v < lo || v > hi)
    throw std::invalid_argument(std::string(name) + "=" + e + " must be " + what);
  return v;
}

// A choice between two forms, a or b, in environment variable `name`
// (`fallback` where unset): either value, or std::invalid_argument
// saying "NAME=value must be a or b"
int one_of(const char* name, int fallback, int a, int b) {
  const std::string what = std::to_string(a) + " or " + std::to_string(b);
  const int v = int(setting(name, fallback, std::min(a, b), std::max(a, b), what.c_str()));
  if (v != a && v != b) throw std::invalid_argument(std::string(name) + "=" + std::to_string(v) + " must be " + what);
  return v;
}
}  // namespace

int device_warps() {
  static const int warps = [] {
    const int asked = int(setting("TRESCA_DEVICE_WARPS", kDeviceWarps, 1, 32, "a warp count in 1..32"));
    if (asked != kDeviceWarps)
      throw std::invalid_argument(
          "TRESCA_DEVICE_WARPS=" + std::to_string(asked) + ": this build's device teams have " +
          std::to_string(kDeviceWarps) +
          " warps; the team size is a build setting (cmake -DTRESCA_DEVICE_WARPS=" + std::to_string(asked) +
          "): read at run time it cost every launch a device "
          "allocation (perf/RESULTS.md §0zg)");
    return asked;
  }();
  return warps;
}

index device_min_nodes() {
  static const index nodes = index(setting("TRESCA_DEVICE_MIN_NODES", 32768, 0,
                                           std::numeric_limits<long long>::max(), "a node count >= 0"));
  return nodes;
}

bool device_warp_sums() {
  static const bool on = one_of("TRESCA_DEVICE_WARP_SUMS", 1, 0, 1) == 1;
  return on;
}

namespace {
// The guard (TRESCA_DEVICE_GUARD=1 where no GPU is present): device memory
// is mapped PROT_NONE and opened only while a target region or a copy runs,
// so a host read or write through a device pointer (which the host fallback
// would otherwise let pass) stops the program with SIGSEGV; and host Field
// memory is closed while a target region runs, so a kernel that reads a
// host array (an illegal address on a GPU) stops it too.
//
// Each side's blocks come from one reserved address range, so opening or
// closing them is one mprotect whatever their number (a contact solve has
// hundreds of Fields); a freed block is emptied (its pages zero again) and
// reused by the next block of its size.
struct Arena {
  char* base = nullptr;
  std::size_t reserved = std::size_t(64) << 30, used = 0;  // [base, base + used): blocks handed out so far
  int prot = PROT_NONE;                                     // every block's protection now
  std::map<void*, std::size_t> blocks;                      // live blocks
  std::multimap<std::size_t, void*> freed;                  // freed blocks by size
  explicit Arena(int initial) : prot(initial) {
    void* p = mmap(nullptr, reserved, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (p == MAP_FAILED) throw std::runtime_error("device guard: cannot reserve its address range");
    base = static_cast<char*>(p);
  }
  void protect(int to) {
    prot = to;
    if (used > 0 && mprotect(base, used, to) != 0) throw std::runtime_error("device guard: mprotect failed");
  }
  void* allocate(std::size_t size) {
    void* p;
    auto it = freed.find(size);
    if (it != freed.end()) {
      p = it->second;
      freed.erase(it);
    } else {
      if (used + size > reserved) throw std::bad_alloc();
      p = base + used;
      used += size;
      if (prot != PROT_NONE && mprotect(p, size, prot) != 0) throw std::runtime_error("device guard: mprotect failed");
    }
    blocks[p] = size;
    return p;
  }
  bool release(void* p) {
    auto it = blocks.find(p);
    if (it == blocks.end()) return false;
    madvise(p, it->second, MADV_DONTNEED);
    freed.emplace(it->second, p);
    blocks.erase(it);
    return true;
  }
};
struct Guard {
  bool on = false;
  int open = 0, launches = 0;  // nesting depth of the regions, and of the launches among them, running now
  std::unique_ptr<Arena> device, host;
  std::uintptr_t heap_begin = 0;  // where malloc's main heap starts (its end: sbrk(0))
  Guard() {
    const char* e = std::getenv("TRESCA_DEVICE_GUARD");
    on = e && std::string(e) == "1" && omp_get_num_devices() == 0;
    if (!on) return;
    device = std::make_unique<Arena>(PROT_NONE);
    host = std::make_unique<Arena>(PROT_READ | PROT_WRITE);
    heap_begin = std::uintptr_t(sbrk(0));
    if (FILE* f = std::fopen("/proc/self/maps", "r")) {
      char line[512];
      unsigned long a = 0, b = 0;
      while (std::fgets(line, sizeof line, f))
        if (std::strstr(line, "[heap]") && std::sscanf(line, "%lx-%lx", &a, &b) == 2) heap_begin = a;
      std::fclose(f);
    }
  }
};
Guard& guard() {
  static Guard g;
  return g;
}
std::size_t page_rounded(std::size_t bytes) {
  const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
  return std::max<std::size_t>(page, (bytes + page - 1) / page * page);
}

void* device_allocate(std::size_t bytes) {
  Guard& g = guard();
  if (g.on) return g.device->allocate(page_rounded(bytes));
  void* p = omp_target_alloc(bytes, device());
  if (!p && bytes) throw std::bad_alloc();
  return p;
}

void device_release(void* p) noexcept {
  Guard& g = guard();
  if (g.on && g.device->release(p)) return;
  omp_target_free(p, device());
}

void* host_allocate(std::size_t bytes) {
  if (guard().on) return guard().host->allocate(page_rounded(bytes));
  if (bytes < kHugeFrom) return ::operator new(bytes);
  const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  void* p = std::aligned_alloc(kHugePage, rounded);
  if (!p) throw std::bad_alloc();
  madvise(p, rounded, MADV_HUGEPAGE);  // advice only: where THP is off it fails harmlessly
  return p;
}

int device_of(Space s) { return s == Space::device ? device() : omp_get_initial_device(); }
}  // namespace

const char* to_string(Space s) { return s == Space::device ? "device" : "host"; }

Space launch_space() { return on_device ? Space::device : Space::host; }

namespace {
void* raw_allocate(Space s, std::size_t bytes) {
  return s == Space::device ? device_allocate(bytes) : host_allocate(bytes);
}

void raw_free(Space s, void* p, std::size_t bytes) noexcept {
  if (s == Space::device)
    device_release(p);
  else if (guard().on && guard().host->release(p))
    return;
  else if (bytes < kHugeFrom)
    ::operator delete(p);
  else
    std::free(p);
}

// The blocks Fields gave back, kept for the next Field of the same size: a
// solve makes and drops the same vectors again and again (Lanczos and CG
// temporaries, each multigrid build's work vectors, each Newton step's), and
// a fresh block costs page faults and the kernel's zeroing of every page, on
// one thread (on this VM about 1.5 GB/s: a quarter of a level-12 solve,
// RESULTS.md §0o); on a GPU each fresh block is a cudaMalloc. Large host
// blocks and all device blocks are kept; small host blocks come from malloc,
// which keeps them itself.
//
// The memory held (live blocks + kept ones) never passes the most the live
// blocks ever needed plus a slack, the largest block or a 16th of that
// peak, whichever is more: before a fresh block is made, kept blocks are
// given back, oldest first, until it fits. The slack is what lets a
// solve's temporaries of different sizes, made and dropped in turn, be
// kept: with the live peak alone as the bound each evicted the one before
// (every contact Newton step made about 50 fresh blocks on the device and
// its one or two largest vectors on the host; RESULTS.md §0t).
class BlockCache {
 public:
  explicit BlockCache(Space s) : space_(s) {}
  void* allocate(std::size_t bytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.requests;
    for (std::size_t k = kept_.size(); k-- > 0;)  // the newest of this size: likeliest in cache
      if (kept_[k].bytes == bytes) {
        void* p = kept_[k].p;
        kept_.erase(kept_.begin() + std::ptrdiff_t(k));
        kept_bytes_ -= bytes;
        live_ += bytes;
        ++stats_.reused;
        stats_.reused_bytes += double(bytes);
        return p;
      }
    peak_ = std::max(peak_, live_ + bytes);
    largest_ = std::max(largest_, bytes);
    while (!kept_.empty() && live_ + kept_bytes_ + bytes > held_limit()) give_back_oldest();
    void* p;
    try {
      p = raw_allocate(space_, bytes);
    } catch (const std::bad_alloc&) {
      while (!kept_.empty()) give_back_oldest();
      p = raw_allocate(space_, bytes);
    }
    live_ += bytes;
    return p;
  }
  void release(void* p, std::size_t bytes) noexcept {
    std::lock_guard<std::mutex> lock(mutex_);
    live_ -= bytes;
    try {
      kept_.push_back({bytes, p});
      kept_bytes_ += bytes;
    } catch (...) {
      raw_free(space_, p, bytes);
    }
  }
  BlockReuse stats() {
    std::lock_guard<std::mutex> lock(mutex_);
    BlockReuse r = stats_;
    r.kept_bytes = double(kept_bytes_);
    r.live_bytes = double(live_);
    r.peak_bytes = double(peak_);
    r.held_limit_bytes = double(held_limit());
    return r;
  }

 private:
  struct Block {
    std::size_t bytes;
    void* p;
  };
  std::size_t held_limit() const { return peak_ + std::max(largest_, peak_ / 16); }
  void give_back_oldest() noexcept {
    raw_free(space_, kept_.front().p, kept_.front().bytes);
    kept_bytes_ -= kept_.front().bytes;
    kept_.erase(kept_.begin());
  }
  Space space_;
  std::mutex mutex_;
  std::vector<Block> kept_;  // oldest first
  std::size_t live_ = 0, kept_bytes_ = 0, peak_ = 0, largest_ = 0;
  BlockReuse stats_;
};

// never destroyed: Fields with static storage may outlive any other static
BlockCache& block_cache(Space s) {
  static BlockCache* host = new BlockCache(Space::host);
  static BlockCache* device = new BlockCache(Space::device);
  return s == Space::device ? *device : *host;
}
bool kept_when_freed(Space s, std::size_t bytes) { return s == Space::device || bytes >= kHugeFrom; }
}  // namespace

void* space_allocate(Space s, std::size_t bytes) {
  return kept_when_freed(s, bytes) ? block_cache(s).allocate(bytes) : raw_allocate(s, bytes);
}

void space_free(Space s, void* p, std::size_t bytes) noexcept {
  if (!p) return;
  if (kept_when_freed(s, bytes))
    block_cache(s).release(p, bytes);
  else
    raw_free(s, p, bytes);
}

BlockReuse block_reuse(Space s) { return block_cache(s).stats(); }

namespace {
// piece(begin, size) over [0, bytes), each host worker its shares of the
// entries (entry_share over the bytes: of a 3D vector, the nodes it sweeps
// in every kernel later): a fresh block's first touch, and its page faults,
// on every thread instead of one, and each page on the thread (and the
// NUMA node) that will use it. Small ranges stay on the calling thread.
template <class Piece>
void by_host_shares(const char* kernel, std::size_t bytes, const Piece& piece) {
  const detail::HostLaunch launch(kernel, Cost{double(bytes), 0});
  detail::on_host_workers(launch.threads, [&](index t, index w) {
    detail::for_entry_runs(index(bytes), t, w,
                           [&](index b0, index b1) { piece(std::size_t(b0), std::size_t(b1 - b0)); });
  });
}
}  // namespace

void detail::copy_between(Space to_space, void* to, Space from_space, const void* from, std::size_t bytes) {
  DeviceRegion region(true);
  if (omp_target_memcpy(to, from, bytes, 0, 0, device_of(to_space), device_of(from_space)) != 0)
    throw std::runtime_error(std::string("copying ") + std::to_string(bytes) + " bytes from the " +
                             to_string(from_space) + " to the " + to_string(to_space) + " failed");
}

void space_copy(Space to_space, void* to, Space from_space, const void* from, std::size_t bytes) {
  if (bytes == 0) return;
  if (to_space == Space::host && from_space == Space::host) {
    by_host_shares("copy (host memory)", bytes, [&](std::size_t b, std::size_t n) {
      std::memcpy(static_cast<char*>(to) + b, static_cast<const char*>(from) + b, n);
    });
    return;
  }
  const long long t0 = detail::now_ns();
  detail::copy_between(to_space, to, from_space, from, bytes);
  const char* kernel = from_space == Space::host ? "copy host to device"
                       : to_space == Space::host ? "copy device to host"
                                                 : "copy device to device";
  detail::count_launch(kernel, Ran::copy, Cost{double(bytes), 0}, detail::now_ns() - t0);
}

void space_zero(Space s, void* p, std::size_t bytes) {
  if (bytes == 0) return;
#ifdef TRESCA_OFFLOAD
  if (s == Space::device) {
    // 8-byte words (a block's start is aligned), then the bytes left
    const index words = index(bytes / 8), n = words + index(bytes % 8);
    std::uint64_t* w = static_cast<std::uint64_t*>(p);
    unsigned char* tail = static_cast<unsigned char*>(p) + 8 * words;
    detail::device_entries("zero (device memory)", n, Cost{double(bytes) / double(n), 0}, [=](index i) {
      if (i < words)
        w[i] = 0;
      else
        tail[i - words] = 0;
    });
    return;
  }
#endif
  if (s == Space::device) {  // without offload, "device" memory is the host's
    DeviceRegion region;
    std::memset(p, 0, bytes);
    return;
  }
  by_host_shares("zero (host memory)", bytes,
                 [&](std::size_t b, std::size_t n) { std::memset(static_cast<char*>(p) + b, 0, n); });
}

bool device_guarded() { return guard().on; }

#ifdef TRESCA_OFFLOAD
// Where the guard cannot close what a body reads (a std::vector's data is
// not a Field), it reads the body: each 8-byte word that holds an address
// aligned as malloc returns them is compared with malloc's main heap,
// where small host arrays live. (A closure's padding may hold stale stack
// or library addresses, so only the heap's range is asked about. It may
// hold a stale heap address too: a body that captured two empty tag
// objects, a byte and seven of padding each, failed the check with
// nothing but device arrays in it (contact_maps.cpp, RESULTS.md §0zr);
// bodies take such choices as constants, not captures.)
void detail::check_device_body(const char* kernel, const void* body, std::size_t bytes) {
  const Guard& g = guard();
  if (!g.on) return;
  const std::uintptr_t end = std::uintptr_t(sbrk(0));
  const unsigned char* b = static_cast<const unsigned char*>(body);
  for (std::size_t k = 0; k + sizeof(std::uintptr_t) <= bytes; k += sizeof(std::uintptr_t)) {
    std::uintptr_t w;
    std::memcpy(&w, b + k, sizeof w);
    if (w % alignof(std::max_align_t) == 0 && w >= g.heap_begin && w < end)
      throw std::logic_error(std::string("device guard: the device launch '") + kernel +
                             "' was given an address in the host's heap (a host array that is not a Field), "
                             "which a GPU cannot read");
  }
}
#endif

DeviceRegion::DeviceRegion(bool copy) : copy_(copy) {
  Guard& g = guard();
  if (!g.on) return;
  if (g.open++ == 0) g.device->protect(PROT_READ | PROT_WRITE);
  if (!copy_ && g.launches++ == 0) g.host->protect(PROT_NONE);
}

DeviceRegion::~DeviceRegion() {
  Guard& g = guard();
  if (!g.on) return;
  if (!copy_ && --g.launches == 0) g.host->protect(PROT_READ | PROT_WRITE);
  if (--g.open == 0) g.device->protect(PROT_NONE);
}

void field_read_on_host(Space s) {
  throw std::logic_error(std::string("a Field in ") + to_string(s) +
                         " memory was read or written on the host (kernels/field.hpp)");
}

void* device_scratch(Scratch use, std::size_t bytes) {
  // grown, never shrunk; the process's exit releases them
  static void* p[2] = {};  // (by Scratch: blocks, sums)
  static std::size_t have[2] = {};
  const int k = int(use);
  if (bytes > have[k]) {
    if (p[k]) device_release(p[k]);
    p[k] = device_allocate(bytes);
    have[k] = bytes;
  }
  return p[k];
}

namespace {
// The default device's name and memory from the CUDA driver API. libgomp
// numbers the nvptx devices as CUDA does (the only offload target built),
// so OpenMP's default device is CUDA's ordinal of that number. Four stable
// entry points, looked up by name: CUresult is an int, CUdevice an int.
DeviceInfo ask_cuda_driver(int ordinal) {
  DeviceInfo info;
  void* cuda = dlopen("libcuda.so.1", RTLD_LAZY | RTLD_LOCAL);
  if (!cuda) return info;
  using Init = int (*)(unsigned);
  using Get = int (*)(int*, int);
  using Name = int (*)(char*, int, int);
  using TotalMem = int (*)(std::size_t*, int);
  const auto init = reinterpret_cast<Init>(dlsym(cuda, "cuInit"));
  const auto get = reinterpret_cast<Get>(dlsym(cuda, "cuDeviceGet"));
  const auto name = reinterpret_cast<Name>(dlsym(cuda, "cuDeviceGetName"));
  const auto total = reinterpret_cast<TotalMem>(dlsym(cuda, "cuDeviceTotalMem_v2"));
  int dev = 0;
  char text[256] = {};
  std::size_t bytes = 0;
  if (init && get && name && total && init(0) == 0 && get(&dev, ordinal) == 0) {
    if (name(text, int(sizeof text) - 1, dev) == 0) info.name = text;
    if (total(&bytes, dev) == 0) info.memory_bytes = double(bytes);
  }
  dlclose(cuda);
  return info;
}
}  // namespace

DeviceInfo device_info() {
  if (!offload_built() || omp_get_num_devices() == 0) return {};
  static const DeviceInfo info = ask_cuda_driver(omp_get_default_device());
  return info;
}

std::string device_description() {
  if (!offload_built()) return "none (built without offload)";
  const int n = omp_get_num_devices();
  const std::string teams = ", " + std::to_string(kDeviceWarps) +
                            " warps a team, multigrid levels and coarser meshes under " +
                            std::to_string(device_min_nodes()) + " nodes on the host, sums a block a " +
                            (device_warp_sums() ? "warp" : "team");
  if (n == 0) return "none: target regions run on the host" + teams;
  const DeviceInfo info = device_info();
  char what[320] = "";
  if (!info.name.empty()) std::snprintf(what, sizeof what, ": %s, %.1f GB", info.name.c_str(), info.memory_bytes / 1e9);
  return "device " + std::to_string(omp_get_default_device()) + " of " + std::to_string(n) + " (OpenMP offload" + what +
         ")" + teams;
}

}  // namespace tresca
