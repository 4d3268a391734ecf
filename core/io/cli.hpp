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
// The drivers' runtime defaults, read by libgomp and glibc only when the
// process starts, so if a variable is unset this re-executes the program once
// with it set; a user's own setting is always kept. Call it first in main.
// - OMP_WAIT_POLICY=passive with GOMP_SPINCOUNT=10000 where the cores were
//   free at start (else 0): idle threads spin a few microseconds, then
//   sleep. Faster on an idle machine; with another process on a core,
//   spinning threads take its time, so a run that finds a core busy at
//   start sleeps at once (perf/RESULTS.md §0d). Unless the user set either.
// - GLIBC_TUNABLES=glibc.malloc.hugetlb=1: malloc asks for transparent huge
//   pages (where the kernel's THP mode is "madvise", as on Debian): first
//   touch of the large arrays costs 512x fewer page faults (the setup and
//   the run it saves: perf/RESULTS.md §0d).
// The drivers set these by re-executing themselves (the runtime reads them
// before main), except where the user placed the threads (OMP_PROC_BIND,
// OMP_PLACES, GOMP_CPU_AFFINITY) or the program runs under valgrind: libgomp
// binds the initial thread at start-up, and a re-executed process would
// inherit that one-CPU mask for all its threads (issue 21). Those runs keep
// the environment as given; thread_placement() says where threads run.
void default_runtime_environment(char** argv);
// Where this process's OpenMP threads may run: each thread's allowed CPUs
// (sched_getaffinity, as a list like "0-3,8"), how many distinct CPUs they
// cover, the user's OMP_PROC_BIND / OMP_PLACES (empty if unset), and
// whether the runtime defaults above were applied.
struct ThreadPlacement {
  std::vector<std::string> thread_cpus;
  int cpus = 0;
  std::string proc_bind, places;
  bool defaults_applied = false;
  std::string describe() const;  // one line for the run's header
};
ThreadPlacement thread_placement();
// how idle OpenMP threads wait in this process: "OMP_WAIT_POLICY=...,
// GOMP_SPINCOUNT=..." as the runtime read them (printed and in the JSON)
std::string omp_wait_setting();
// Exits with status 2 and a message (from the first rank) when mpirun
// started this program as several ranks: for the drivers that are not
// distributed (scaling, mg_scaling, roofline), whose N copies would each
// run and write the same thing.
void require_one_rank(const char* program);
// --threads N (else OMP_NUM_THREADS / all cores); returns the thread count in use
int apply_threads(const Args& a);
std::string dims_string(const ProblemSpec& s);

}  // namespace tresca
