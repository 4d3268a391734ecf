// Minimal command-line parsing shared by the drivers. Every error is a
// std::invalid_argument whose message names the offending flag or value;
// drivers print it on one line and exit with status 2.
#pragma once
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/fem/problem.hpp"

namespace tresca {

class Comm;
struct MGOptions;

class Args {
 public:
  // flags: options taking a value ("--level"); switches: options without
  // ("--quiet"). Every driver also takes -h / --help and --version
  // (answered_help_or_version).
  Args(int argc, char** argv, const std::set<std::string>& flags, const std::set<std::string>& switches);
  bool has(const std::string& k) const { return values_.count(k) > 0; }
  std::string str(const std::string& k, const std::string& def = "") const;
  double real_value(const std::string& k, double def) const;
  long long int_value(const std::string& k, long long def) const;

 private:
  std::map<std::string, std::string> values_;
};

// -h / --help: prints `help` (the driver's full usage); --version: the
// program, the project's version and commit, and the build (ISA, vector
// width, compiler and its target options). True if either was asked: the
// driver then exits with status 0.
bool answered_help_or_version(const Args& a, const char* program, const char* help);
std::string version_text(const char* program);

// "--level L" or "--dims AxBxC" (exactly one; default level), plus --E, --nu, --phi.
// the problem from the command line, over `base` (a problem file's) when
// given: --level/--dims, --E, --nu, --phi, --gap, --obstacle, --load-scale
// override it; without a mesh in either, default_level
ProblemSpec spec_from_args(const Args& a, int default_level, const ProblemSpec* base = nullptr);
// "plane:GAP,SLOPE_X,SLOPE_Y" | "sphere:RADIUS,CX,CY,GAP" | "cylinder:RADIUS,CY,GAP" (problem.hpp: Obstacle)
Obstacle parse_obstacle(const std::string& text);
// "A-B" or "A" → inclusive range of levels
std::vector<int> parse_level_range(const std::string& s);
// throws if the estimated memory of a run exceeds the machine's physical memory
void check_memory(const ProblemSpec& s);
// The drivers run in the environment they are given: they set no runtime
// variable and never re-execute themselves, so a user's OpenMP and MPI
// placement (OMP_PROC_BIND, OMP_PLACES, mpirun's binding) and tools such as
// valgrind see the program as started. Large arrays get transparent huge
// pages from their own allocator (Field, kernels/launch.hpp), not from
// GLIBC_TUNABLES. How idle threads wait is libgomp's to decide from
// OMP_WAIT_POLICY / GOMP_SPINCOUNT, read before main; warn_if_cores_busy
// says when the libgomp default (spin, then sleep) would take the time of
// another process running on this machine's cores (docs/usage.md).
// The drivers call it once their options are read, before the work.
void warn_if_cores_busy();
// Where this process's OpenMP threads may run: each thread's allowed CPUs
// (sched_getaffinity, as a list like "0-3,8"), how many distinct CPUs they
// cover and the user's OMP_PROC_BIND / OMP_PLACES (empty if unset).
struct ThreadPlacement {
  std::vector<std::string> thread_cpus;
  int cpus = 0;
  std::string proc_bind, places;
  std::string describe() const;  // one line for the run's header
};
ThreadPlacement thread_placement();
// how idle OpenMP threads wait in this process: "OMP_WAIT_POLICY=...,
// GOMP_SPINCOUNT=..." as the runtime read them (printed and in the JSON)
std::string omp_wait_setting();
// which allocations get transparent huge pages in this process: the large
// arrays (Field) always; every malloc where GLIBC_TUNABLES has
// glibc.malloc.hugetlb=1 (the launcher line of docs/usage.md)
std::string huge_page_setting();
// Exits with status 2 and a message (from the first rank) when mpirun
// started this program as several ranks: for the drivers that are not
// distributed (scaling, mg_scaling, roofline), whose N copies would each
// run and write the same thing.
void require_one_rank(const char* program);
// --threads N (else OMP_NUM_THREADS / all cores); returns the thread count in use
int apply_threads(const Args& a);
// --device cpu|gpu (default cpu): with gpu, the launches and the Fields made
// from here on go to the offload device (kernels/launch.hpp); a bad input
// error without an offload build (configure with -DTRESCA_OFFLOAD=ON) or on
// several ranks. Returns what runs the kernels, for the run's header: "cpu",
// or the device (with a warning on stderr where no GPU is present and the
// target regions run on the host).
std::string apply_device(const Args& a, const Comm& comm);
std::string dims_string(const ProblemSpec& s);
// The drivers' V-cycles in single precision only where it holds the
// magnitudes of s (problem.hpp: fits_single_precision): elsewhere (E = 1e40
// Pa, loads scaled by 1e-40) mg's single precision becomes double, and the
// returned note for the user says why; empty where nothing changed
std::string keep_vcycles_in_range(const ProblemSpec& s, MGOptions& mg);

}  // namespace tresca
