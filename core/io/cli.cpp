#include "core/io/cli.hpp"

#include "core/contact/run.hpp"
#include "core/parallel/comm.hpp"
#include "kernels/launch.hpp"
#include "kernels/isa.hpp"

#include <algorithm>
#include <utility>
#include <omp.h>
#include <sched.h>
#include <unistd.h>
#include <fstream>
#include <sys/resource.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace tresca {

namespace {
[[noreturn]] void fail(const std::string& m) { throw std::invalid_argument(m); }
// a user's value inside a one-line message: at most 80 characters of it
std::string quoted(const std::string& v) {
  return "'" + (v.size() > 80 ? v.substr(0, 77) + "..." : v) + "'";
}
}  // namespace

Args::Args(int argc, char** argv, const std::set<std::string>& flags, const std::set<std::string>& switches) {
  for (int i = 1; i < argc; ++i) {
    std::string k = argv[i];
    std::string v;
    const auto eq = k.find('=');
    const bool inline_value = k.rfind("--", 0) == 0 && eq != std::string::npos;
    if (inline_value) {
      v = k.substr(eq + 1);
      k = k.substr(0, eq);
    }
    if (k == "-h") k = "--help";
    if (switches.count(k) || k == "--help" || k == "--version") {
      if (inline_value) fail("option " + k + " takes no value");
      values_[k] = "1";
    } else if (flags.count(k)) {
      if (!inline_value) {
        if (i + 1 >= argc) fail("option " + k + " needs a value");
        v = argv[++i];
        // `--json --quiet` must not write a file named --quiet (a value that
        // really starts with -- can be given as --json=--quiet)
        if (v.rfind("--", 0) == 0) fail("option " + k + " needs a value, not the option '" + v + "'");
      }
      if (v.empty()) fail("option " + k + " needs a value, not an empty one");
      values_[k] = v;
    } else {
      fail("unknown option " + quoted(k) + " (see --help)");
    }
  }
}

bool answered_help_or_version(const Args& a, const char* program, const char* help) {
  if (!a.has("--help") && !a.has("--version")) return false;
  if (Comm::world().rank() == 0) std::fputs(a.has("--help") ? help : version_text(program).c_str(), stdout);
  return true;
}

std::string version_text(const char* program) {
  return std::string(program) + " (tresca-ssn) " TRESCA_VERSION " (" TRESCA_COMMIT ")\nbuild: " + build_info() + "\n";
}

std::string Args::str(const std::string& k, const std::string& def) const {
  auto it = values_.find(k);
  return it == values_.end() ? def : it->second;
}

double Args::real_value(const std::string& k, double def) const {
  if (!has(k)) return def;
  const std::string s = str(k);
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  // ERANGE on underflow (1e-320, a denormal) still gives a usable number; on
  // overflow it gives +-HUGE_VAL, caught as not finite
  if (s.empty() || *end != '\0' || !std::isfinite(v))
    fail("option " + k + ": " + quoted(s) + " is not a finite number");
  return v;
}

long long Args::int_value(const std::string& k, long long def) const {
  if (!has(k)) return def;
  const std::string s = str(k);
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || errno == ERANGE) fail("option " + k + ": " + quoted(s) + " is not an integer");
  return v;
}

Obstacle parse_obstacle(const std::string& text) {
  const auto colon = text.find(':');
  const std::string kind = text.substr(0, colon);
  std::vector<real> v;
  if (colon != std::string::npos) {
    std::istringstream is(text.substr(colon + 1));
    std::string item;
    while (std::getline(is, item, ',')) {
      char* end = nullptr;
      const double x = std::strtod(item.c_str(), &end);
      if (item.empty() || *end) fail("--obstacle '" + text + "': '" + item + "' is not a number");
      v.push_back(x);
    }
  }
  Obstacle o;
  auto need = [&](size_t n, const char* form) {
    if (v.size() != n) fail("--obstacle '" + text + "': expected " + form);
  };
  if (kind == "plane") {
    need(3, "plane:GAP,SLOPE_X,SLOPE_Y");
    o.kind = Obstacle::Kind::plane;
    o.gap = v[0], o.slope_x = v[1], o.slope_y = v[2];
  } else if (kind == "sphere") {
    need(4, "sphere:RADIUS,CX,CY,GAP");
    o.kind = Obstacle::Kind::sphere;
    o.radius = v[0], o.cx = v[1], o.cy = v[2], o.gap = v[3];
  } else if (kind == "cylinder") {
    need(3, "cylinder:RADIUS,CY,GAP (axis along x)");
    o.kind = Obstacle::Kind::cylinder;
    o.radius = v[0], o.cy = v[1], o.gap = v[2];
  } else {
    fail("--obstacle '" + text + "': unknown kind '" + kind + "' (plane, sphere or cylinder)");
  }
  return o;
}

ProblemSpec spec_from_args(const Args& a, int default_level, const ProblemSpec* base) {
  if (a.has("--level") && a.has("--dims")) fail("give either --level or --dims, not both");
  ProblemSpec s = base ? *base : ProblemSpec{};
  if (a.has("--dims")) {
    const std::string d = a.str("--dims");
    long long e[3];
    char x1, x2;
    std::istringstream is(d);
    if (!(is >> e[0] >> x1 >> e[1] >> x2 >> e[2]) || x1 != 'x' || x2 != 'x' || !is.eof() ||
        d.find_first_not_of("0123456789x") != std::string::npos)
      fail("--dims '" + d + "' is malformed (expected EXxEYxEZ, e.g. 16x8x8)");
    if (e[0] < 1 || e[1] < 1 || e[2] < 1) fail("--dims '" + d + "': every element count must be >= 1");
    const ProblemSpec m = spec_for_dims(e[0], e[1], e[2]);
    s.level = m.level, s.ex = m.ex, s.ey = m.ey, s.ez = m.ez;
  } else if (a.has("--level") || !base || base->ex < 1) {
    const ProblemSpec d = spec_for_level(a.int_value("--level", default_level));
    s.level = d.level, s.ex = d.ex, s.ey = d.ey, s.ez = d.ez;
  }
  s.E = a.real_value("--E", s.E);
  s.nu = a.real_value("--nu", s.nu);
  s.phi = a.real_value("--phi", s.phi);
  if (a.has("--obstacle")) {
    if (a.has("--gap")) fail("--gap and --obstacle exclude each other (the obstacle's own gap parameter sets it)");
    s.obstacle = parse_obstacle(a.str("--obstacle"));
  }
  s.obstacle.gap = a.real_value("--gap", s.obstacle.gap);
  s.load_scale = a.real_value("--load-scale", s.load_scale);
  validate(s);
  check_memory(s);
  return s;
}

std::vector<int> parse_level_range(const std::string& s) {
  int a = 0, b = 0;
  char dash = 0;
  std::istringstream is(s);
  if (!(is >> a)) fail("level range '" + s + "' is malformed (expected e.g. 1-8)");
  b = a;
  if (is >> dash) {
    if (dash != '-' || !(is >> b)) fail("level range '" + s + "' is malformed (expected e.g. 1-8)");
  }
  if (!is.eof() && is.peek() != EOF) fail("level range '" + s + "' is malformed (expected e.g. 1-8)");
  if (a > b) fail("level range '" + s + "' must satisfy first <= last");
  spec_for_level(a);  // throws for a level outside the range
  spec_for_level(b);
  std::vector<int> r;
  for (int l = a; l <= b; ++l) r.push_back(l);
  return r;
}

namespace {
// the memory this process may use: physical memory, the address-space limit
// (ulimit -v) and the cgroup's limit (containers), whichever is least
std::pair<double, std::string> memory_limit() {
  std::pair<double, std::string> m{double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE)), "this machine's"};
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY && double(rl.rlim_cur) < m.first)
    m = {double(rl.rlim_cur), "the address-space limit's (ulimit -v)"};
  for (const char* f : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(f);
    double v = 0;
    if (in >> v && v > 0 && v < m.first) m = {v, "the cgroup's memory limit's"};
  }
  return m;
}
}  // namespace

void check_memory(const ProblemSpec& s) {
  // several ranks: the ranks on each machine share its memory; any machine
  // short of it fails the check on every rank (the same message, no hang)
  const Comm& comm = Comm::world();
  const int on_host = comm.ranks_on_this_host();
  const double per_rank = run_memory_per_rank(s), need = per_rank * on_host;
  const auto [have, whose] = memory_limit();
  const bool short_here = have > 0 && need > 0.9 * have;
  std::ostringstream os;
  if (s.level >= 0) os << "level " << s.level << " (";
  os << "mesh " << dims_string(s) << (s.level >= 0 ? ")" : "") << " needs about ";
  if (comm.max(short_here ? 1.0 : 0.0) > 0) {
    if (comm.distributed())
      os << per_rank / 1e9 << " GB per rank on " << comm.size() << " ranks, " << need / 1e9 << " GB for the " << on_host
         << " ranks of one machine, more than " << whose << " " << have / 1e9 << " GB";
    else
      os << need / 1e9 << " GB, more than " << whose << " " << have / 1e9 << " GB";
    fail(os.str());
  }
  // a device run (one rank) holds nearly all of it in the GPU's memory
  const DeviceInfo gpu = launch_on_device() ? device_info() : DeviceInfo{};
  if (gpu.memory_bytes > 0 && per_rank > 0.9 * gpu.memory_bytes) {
    os << per_rank / 1e9 << " GB, nearly all on the device, more than the "
       << (gpu.name.empty() ? std::string("device") : gpu.name) << "'s " << gpu.memory_bytes / 1e9 << " GB";
    fail(os.str());
  }
}

namespace {
// Whether this run's threads find the machine's cores free at start: the
// tasks running besides this one (/proc/loadavg, fewest of five looks 1 ms
// apart, so that a short-lived daemon does not count) plus the threads it
// will start fit in the cores (threads beyond the cores are this run's own
// oversubscription, which thread_placement's warning names, not another
// process's). A snapshot: a process that starts later is not seen.
bool cores_free_at_start() {
  long running = -1;
  for (int look = 0; look < 5; ++look) {
    std::ifstream in("/proc/loadavg");
    double l1, l5, l15;
    long r = 0, total = 0;
    char slash;
    if (!(in >> l1 >> l5 >> l15 >> r >> slash >> total) || r < 1) return false;
    running = running < 0 ? r : std::min(running, r);
    usleep(1000);
  }
  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  long threads = cores;
  if (const char* env = std::getenv("OMP_NUM_THREADS")) threads = std::strtol(env, nullptr, 10);
  return cores > 0 && threads > 0 && (running - 1) + std::min(threads, cores) <= cores;
}
}  // namespace

namespace {
// "0-3,8" from a CPU set
std::string cpu_list(const cpu_set_t& set) {
  std::string out;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (!CPU_ISSET(c, &set)) continue;
    int e = c;
    while (e + 1 < CPU_SETSIZE && CPU_ISSET(e + 1, &set)) ++e;
    if (!out.empty()) out += ",";
    out += std::to_string(c) + (e > c ? "-" + std::to_string(e) : "");
    c = e;
  }
  return out;
}
}  // namespace

ThreadPlacement thread_placement() {
  ThreadPlacement t;
  const int n = omp_get_max_threads();
  t.thread_cpus.assign(n, "");
  std::vector<cpu_set_t> sets(n);
#pragma omp parallel num_threads(n)
  {
    const int i = omp_get_thread_num();
    CPU_ZERO(&sets[i]);
    if (sched_getaffinity(0, sizeof(cpu_set_t), &sets[i]) == 0) t.thread_cpus[i] = cpu_list(sets[i]);
  }
  cpu_set_t all;
  CPU_ZERO(&all);
  for (const cpu_set_t& s : sets) CPU_OR(&all, &all, &s);
  t.cpus = CPU_COUNT(&all);
  if (const char* b = std::getenv("OMP_PROC_BIND")) t.proc_bind = b;
  if (const char* p = std::getenv("OMP_PLACES")) t.places = p;
  return t;
}

std::string ThreadPlacement::describe() const {
  std::ostringstream os;
  os << thread_cpus.size() << " threads on CPUs";
  for (size_t i = 0; i < thread_cpus.size(); ++i) os << (i ? " " : " ") << i << ":{" << thread_cpus[i] << "}";
  if (!proc_bind.empty()) os << ", OMP_PROC_BIND=" << proc_bind;
  if (!places.empty()) os << ", OMP_PLACES=" << places;
  return os.str();
}

void warn_if_cores_busy() {
  if (std::getenv("OMP_WAIT_POLICY") || std::getenv("GOMP_SPINCOUNT") || launched_ranks() > 1) return;
  if (omp_get_max_threads() < 2 || cores_free_at_start()) return;
  std::fprintf(stderr,
               "warning: another process is running on this machine's cores; idle OpenMP threads spin "
               "before they sleep (libgomp's default) and take its time: OMP_WAIT_POLICY=passive makes them "
               "sleep at once (docs/usage.md, Threads)\n");
}

std::string huge_page_setting() {
  const char* t = std::getenv("GLIBC_TUNABLES");
  if (t && std::string(t).find("glibc.malloc.hugetlb=1") != std::string::npos)
    return "huge pages: every allocation (GLIBC_TUNABLES=glibc.malloc.hugetlb=1)";
  return "huge pages: arrays of 1 MiB and more";
}

std::string omp_wait_setting() {
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  const char* spins = std::getenv("GOMP_SPINCOUNT");
  return std::string("OMP_WAIT_POLICY=") + (policy ? policy : "(unset: libgomp's default, spin then sleep)") +
         (spins ? std::string(", GOMP_SPINCOUNT=") + spins : std::string());
}

void require_one_rank(const char* program) {
  const int ranks = launched_ranks();
  if (ranks <= 1) return;
  const char* rank = std::getenv("OMPI_COMM_WORLD_RANK");
  if (!rank) rank = std::getenv("PMI_RANK");
  if (!rank || std::string(rank) == "0")
    std::fprintf(stderr,
                 "%s: started as %d MPI ranks, but %s runs on one rank (tresca, elastic and mpi_apply "
                 "are distributed). Run it as one process, threads with OMP_NUM_THREADS or --threads.\n",
                 program, ranks, program);
  std::exit(2);
}

int apply_threads(const Args& a) {
  // the runtime would try to start them all (OMP_NUM_THREADS=100000 crashed
  // inside libgomp): the same bound as --threads
  if (const char* env = std::getenv("OMP_NUM_THREADS"); env && !a.has("--threads")) {
    char* end = nullptr;
    const long long t = std::strtoll(env, &end, 10);
    if (end == env || (*end != '\0' && *end != ',') || t < 1 || t > 1024)
      fail(std::string("OMP_NUM_THREADS=") + env + " must be a thread count in 1..1024");
  }
  if (a.has("--threads")) {
    const long long t = a.int_value("--threads", 1);
    if (t < 1 || t > 1024) fail("--threads " + std::to_string(t) + " must be in 1..1024");
    omp_set_num_threads(int(t));
  }
  isa();  // a bad TRESCA_ISA stops here, before any output (kernels/isa.hpp)
  return omp_get_max_threads();
}

std::string apply_device(const Args& a, const Comm& comm) {
  const std::string d = a.has("--device") ? a.str("--device") : "cpu";
  if (d != "cpu" && d != "gpu") fail("--device " + d + " must be cpu or gpu");
  if (d == "cpu") return "cpu";
  if (!offload_built()) fail("--device gpu: this build has no device backend (configure with -DTRESCA_OFFLOAD=ON)");
  if (comm.distributed()) fail("--device gpu runs on one rank (started as " + std::to_string(comm.size()) + ")");
  set_launch_on_device(true);
  if (omp_get_num_devices() == 0 && comm.rank() == 0)
    std::fprintf(stderr, "warning: --device gpu, but no GPU is usable: the target regions run on the host\n");
  return "gpu, " + device_description();
}

std::string keep_vcycles_in_range(const ProblemSpec& s, MGOptions& mg) {
  const ProblemScales sc = scales_of(s);
  if (mg.precision != Precision::single_precision || fits_single_precision(sc)) return "";
  mg.precision = Precision::double_precision;
  char text[400];
  std::snprintf(text, sizeof text,
                "the multigrid V-cycles run in double precision: this problem's magnitudes (stiffness %.1e to "
                "%.1e N/m, nodal loads %.1e N, displacements %.1e to %.1e m) are not all within 1e-28 to 1e31, "
                "what single precision holds with room",
                sc.stiffness_min, sc.stiffness_max, sc.force, sc.displacement_min, sc.displacement_max);
  return text;
}

std::string dims_string(const ProblemSpec& s) {
  return std::to_string(s.ex) + "x" + std::to_string(s.ey) + "x" + std::to_string(s.ez);
}

}  // namespace tresca
