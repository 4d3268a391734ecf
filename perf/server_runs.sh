#!/usr/bin/env bash
# Issue 21's measurements on a many-core server (the test machine's 16
# cores: ../shared/device/README.md), in stages that each fit in one
# 10-minute command. From the project root, with a build of the project
# (there: bash .device-kit/build.sh /tmp/b):
#   bash perf/server_runs.sh BUILD STAGE
# STAGE:
#   threads   level 12 with all cores as threads (libgomp's default wait,
#             OMP_WAIT_POLICY=active, passive; each placed close on cores)
#             and as MPI ranks: issue 21's "16 threads within 10 % of 16 ranks";
#             then its kernels of 2 % and more with all cores (--profile)
#   scaling   scaling --threads 1,2,4,8,16 on levels 10-12: speed-up and
#             efficiency against the bandwidth-ideal speed-up
#   ranks     scaling --ranks 1,2,4,8,16 on level 12
#   roofline  roofline --level 12 with all cores: every kernel against the triad
#   large     levels 13 and 14 with all cores, then level 15 (memory
#             estimate, progress lines, time, peak memory; where OUT is set,
#             each run's JSON report, its time by kernel, as $OUT/large_L.json)
#   profile   where the threads' time goes: level 12's kernel profile with 1
#             thread and with all cores (with the fork/join census and the
#             memory made), and the price of one parallel region
#   isa       the apply in each instruction-set variant the CPU runs
#             (TRESCA_ISA: kernels/isa.hpp) on 1 thread and all cores,
#             double and float, and level 12 with each: which is faster there
# LEVEL, LEVELS, SWEEP, LARGE and THREADS replace 12, 10-12, 1,2,4,8,16,
# "13 14 15" and the core count (e.g. LEVEL=4 LEVELS=3-4 SWEEP=1,2 LARGE=4
# to try it on 2 cores).
# Each stage prints what it ran (command, date, machine) before its figures:
# paste them into perf/RESULTS.md as they are.
set -euo pipefail
b=${1:?usage: bash perf/server_runs.sh BUILD STAGE}
stage=${2:?usage: bash perf/server_runs.sh BUILD STAGE}
# where OUT is set (the test machine's tool brings back what is under it),
# the stage's output also goes to $OUT/server_STAGE.log
if [[ -n ${OUT:-} && -z ${SERVER_RUNS_LOGGED:-} ]]; then
  SERVER_RUNS_LOGGED=1 bash "$0" "$@" 2>&1 | tee "$OUT/server_$stage.log"
  exit "${PIPESTATUS[0]}"
fi
T=${THREADS:-$(nproc)}
L=${LEVEL:-12} LS=${LEVELS:-10-12}  # (smaller ones try the script out on a small machine)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1  # (the test machine runs as root)
echo "# $(date -u '+%F %H:%M UTC'); $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) CPUs; build $b"
echo "# stage $stage, $T threads or ranks"
run() {  # a command, echoed, then its last TAIL lines (or those matching KEEP)
  echo "\$ $*"
  if [ -n "${KEEP:-}" ]; then
    # (line by line: what a run cut short by the command's time limit printed still comes back)
    { "$@" 2>&1 || echo "(exit status $?)"; } | grep --line-buffered -E "$KEEP|exit status"
  else
    { "$@" 2>&1 || echo "(exit status $?)"; } | tail -n "${TAIL:-3}"
  fi
}
solve='times \[s\]|peak memory|error'  # a solve's lines worth keeping
case $stage in
  threads)
    for wait in default active passive; do
      for rep in 1 2 3; do
        if [ "$wait" = default ]; then w=(env -u OMP_WAIT_POLICY); else w=(env OMP_WAIT_POLICY=$wait); fi
        KEEP=$solve run "${w[@]}" OMP_NUM_THREADS="$T" OMP_PROC_BIND=close OMP_PLACES=cores "$b/bin/tresca" --level "$L" --quiet
      done
    done
    if command -v mpirun > /dev/null; then
      for rep in 1 2 3; do
        KEEP=$solve run mpirun -np "$T" --bind-to core -x OMP_NUM_THREADS=1 "$b/bin/tresca" --level "$L" --quiet
      done
    fi
    # where the threads' time goes: the kernels of 2 % of the run and more,
    # each with its GB/s (issue 21's bandwidth bar), and the serial part
    KEEP="$solve|^kernel +where| (threads|1 thread) +[0-9]+ +[0-9.]+ +([2-9]|[1-9][0-9])\.[0-9]%|^in launches|^one thread" \
      run env OMP_NUM_THREADS="$T" OMP_PROC_BIND=close OMP_PLACES=cores "$b/bin/tresca" --level "$L" --quiet --profile ;;
  scaling)
    TAIL=40 run env OMP_PROC_BIND=close OMP_PLACES=cores "$b/bin/scaling" --levels "$LS" --threads "${SWEEP:-1,2,4,8,16}" ;;
  ranks)
    TAIL=20 run "$b/bin/scaling" --levels "$L-$L" --ranks "${SWEEP:-1,2,4,8,16}" ;;
  roofline)
    TAIL=30 run env OMP_NUM_THREADS="$T" OMP_PROC_BIND=close OMP_PLACES=cores "$b/bin/roofline" --level "$L" ;;
  large)
    for level in ${LARGE:-13 14 15}; do
      report=()
      [ -n "${OUT:-}" ] && report=(--json "$OUT/large_$level.json")
      KEEP="$solve|estimated|converged|nested:|^  it " run env OMP_NUM_THREADS="$T" OMP_PROC_BIND=close OMP_PLACES=cores \
        "$b/bin/tresca" --level "$level" "${report[@]}"
    done ;;
  profile)
    for t in 1 "$T"; do
      TAIL=75 run env OMP_NUM_THREADS="$t" OMP_PROC_BIND=close OMP_PLACES=cores "$b/bin/tresca" --level "$L" --quiet --profile
    done
    KEEP='^(ParallelRegion|VCycle)' run env OMP_NUM_THREADS="$T" OMP_PROC_BIND=close OMP_PLACES=cores \
      "$b/bin/bench_kernels" --benchmark_filter='ParallelRegion|^VCycle/10' ;;
  isa)
    for isa in x86-64-v4 baseline; do
      for t in 1 "$T"; do
        KEEP='^Apply' run env TRESCA_ISA=$isa OMP_NUM_THREADS="$t" OMP_PROC_BIND=close OMP_PLACES=cores \
          "$b/bin/bench_kernels" --benchmark_filter="^Apply(Float)?/$L/" --benchmark_repetitions=3 \
          --benchmark_report_aggregates_only=true
      done
      KEEP="$solve|kernels: ISA" run env TRESCA_ISA=$isa OMP_NUM_THREADS="$T" OMP_PROC_BIND=close OMP_PLACES=cores \
        "$b/bin/tresca" --level "$L"
    done ;;
  *)
    echo "unknown stage '$stage': threads, scaling, ranks, roofline, large, profile or isa" >&2
    exit 2 ;;
esac
