#!/usr/bin/env bash
# The device checks and benchmarks of the GPU bundle (perf/gpu_bundle.sh
# copies this file to .gpu-bundle/run.sh, beside the programs), in stages
# that each fit a 10-minute command:
#   run.sh first    one call for a session with the 15-minute lease, the
#                   most decisive first, each step under a timeout and all
#                   of them within FIRST_BUDGET seconds (default 420): tests,
#                   what a launch costs (launch), the level-13 apply, V-cycle
#                   and vector benchmarks,
#                   contact (levels 8 and 12, Coulomb), level 14 on the GPU,
#                   the kernels' forms, roofline, level 15, why; then a summary of the lines that
#                   answer issue 22's bars (where the device tests find no
#                   GPU, only that, and exit status 1)
#   run.sh tests    the device tests (a run without a usable GPU fails:
#                   Device.PresentWhereRequired; GCC 12 falls back to the
#                   host even with OMP_TARGET_OFFLOAD=MANDATORY), after
#                   tests/device_code_fixture.cpp, GCC 12's miscompiled
#                   pattern (its line says WRONG on a GPU); a device test
#                   that fails on a GPU runs again under compute-sanitizer,
#                   and with the sums' other form (where it passes so,
#                   `first` runs its other steps with that)
#   run.sh launch   what each form of an OpenMP target region costs with
#                   this libgomp, apart from our kernels (launch_probe: an
#                   empty region, an axpy of 1024 and of VEC_SIZE entries;
#                   RESULTS.md §0zm), and the teams and warps libgomp gives
#                   each (GOMP_DEBUG=1)
#   run.sh bench    the Device* benchmarks (BENCH=regex) and roofline
#                   --device gpu at level 13 (DeviceAxpy/1024 and
#                   DeviceDot/1024: what one launch costs)
#   run.sh elastic  the MG-CG solve, GPU then CPU, levels 10, 12, 13
#   run.sh contact  tresca, GPU then CPU, levels 8 and 12 and Coulomb 0.8 at
#                   level 10, compared by compare_runs.py: contact values
#                   within 1e-10 of each column's largest, same contact and
#                   stick sets, same Newton and Krylov iterations (issue 22)
#   run.sh large    tresca --device gpu at levels 13, 14 and 15
#   run.sh forms    the device sums' two forms (kernels/launch.hpp), in
#                   alternating rounds: the dot and the CG update at 2^27
#                   entries under TRESCA_DEVICE_WARP_SUMS 1 or 0 (a block a
#                   warp or a team; RESULTS.md §0zh; the apply's forms were
#                   settled in §0zm)
#   run.sh warps    the team size (a build setting, TRESCA_DEVICE_WARPS: the
#                   bundle's and each warps-N/ that gpu_bundle.sh built with
#                   BUNDLE_WARPS="N ..."): the level-13 apply, V-cycle and
#                   vector benchmarks and a level-12 contact solve with each (perf/offload_registers.py
#                   predicts the occupancy of each image; RESULTS.md §0n, §0z)
#   run.sh cut      where the multigrid and the nested iteration leave the
#                   device (TRESCA_DEVICE_MIN_NODES 0, 8192, 32768, 131072,
#                   524288: smaller levels and coarser meshes on the host):
#                   the level-10 and level-12 V-cycles and a level-12 contact
#                   solve with each (RESULTS.md §0w, §0y)
#   run.sh images   the vector kernels in a device image of their own (this
#                   build: libtresca_launch.so) against in the program's
#                   (one-image/bench_kernels), alternating: axpy, dot, the CG
#                   update and the level-12 V-cycle (RESULTS.md §0z)
#   run.sh why      why a kernel runs as fast as it does (issue 22, item 6):
#                   the launch geometry libgomp picks for each kernel
#                   (GOMP_DEBUG=1: teams, warps) and, where Nsight Compute is
#                   installed, its report on the apply (double, float), axpy,
#                   dot and the CG update: registers, occupancy, waves,
#                   memory throughput (ncu --clock-control none)
#   run.sh all      tests, bench, elastic, contact (about 10 minutes)
# Where OUT is set, each stage's log goes to $OUT/run_STAGE.log and its CSV
# and JSON files to $OUT/run_STAGE.files.tgz (two files a stage; the device
# tool brings back 8).
#
# The sizes are knobs, so that the whole script can be tried where there is
# no GPU (the offload build's test perf.gpu_run_smoke, with its target regions
# on the host): BENCH_LEVEL (13), VEC_SIZE (134217728), CONTACT_LEVELS
# ("8 12"), COULOMB_LEVEL (10), ELASTIC_LEVELS ("10 12 13"), LARGE_LEVELS
# ("13 14 15"), BENCH_ARGS (extra bench_kernels options), and first's
# FIRST_BUDGET (420 s), FIRST_LARGE (14), FIRST_LARGEST (15); TRESCA_BIN is
# where the programs are (default: beside this script), COMPARE the
# compare_runs.py to use (default: beside this script, else tests/).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${TRESCA_BIN:-$here}
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export OMP_TARGET_OFFLOAD=${OMP_TARGET_OFFLOAD:-MANDATORY} TRESCA_REQUIRE_DEVICE=${TRESCA_REQUIRE_DEVICE:-1}
stage=${1:-all}
stages="first tests launch bench elastic contact large forms warps cut images why all"
if [[ " $stages " != *" $stage "* ]]; then
  echo "run.sh: unknown stage '$stage' (${stages// /, })" >&2
  exit 2
fi
L=${BENCH_LEVEL:-13} V=${VEC_SIZE:-134217728}
read -r -a bench_args <<< "${BENCH_ARGS:-}"
compare_py=${COMPARE:-$here/compare_runs.py}
[[ -f $compare_py ]] || compare_py=$here/../tests/compare_runs.py
base=${TMPDIR:-/tmp}/tresca-gpu-run
out=$base/$stage  # the stage's CSV and JSON files (and first's logs)
# a stage run by hand starts afresh, `first` with all of its steps' folders
# (a step keeps what an earlier step of the same stage wrote: 4-large's
# level 14 beside 7-largest's level 15)
if [[ -z ${RUN_SH_NESTED:-} ]]; then
  if [[ $stage == first ]]; then rm -rf "$base"; else rm -rf "$out"; fi
fi
mkdir -p "$out"
if [[ -n ${OUT:-} && -z ${RUN_SH_LOGGED:-} ]]; then
  set +e
  RUN_SH_LOGGED=1 bash "$0" "$stage" 2>&1 | tee "$OUT/run_$stage.log"
  rc=${PIPESTATUS[0]}
  tar czf "$OUT/run_$stage.files.tgz" -C "$base" .
  exit "$rc"
fi
if [[ -z ${RUN_SH_NESTED:-} ]]; then
  echo "# run.sh $stage, $(date -u '+%F %H:%M UTC'); $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) CPUs"
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader 2>/dev/null || echo "no nvidia-smi"
fi
# the device sums' other form (kernels/launch.hpp): the fallback of `first`
# where the default fails a device test that this passes
earlier_forms="TRESCA_DEVICE_WARP_SUMS=0"
bench() {  # a benchmark filter
  "$bin/bench_kernels" --benchmark_filter="$1" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
    "${bench_args[@]}"
}
solve() {  # tresca's options: the run, named first; a failed one says so and the stage goes on
  echo "== tresca $*"
  "$bin/tresca" "$@" || echo "(exit status $?)"
}
contact() {  # level, then tresca options: GPU, then CPU, then their comparison
  local level=$1; shift
  local opts="$*"
  local name="$level${opts:+_${opts//[^a-z0-9.]/}}"  # (e.g. 10_coulomb0.8)
  solve --level "$level" "$@" --device gpu --profile --contact-csv "$out/gpu_$name.csv" --json "$out/gpu_$name.json"
  solve --level "$level" "$@" --quiet --contact-csv "$out/cpu_$name.csv" --json "$out/cpu_$name.json"
  echo "== level $level $*: GPU against CPU"
  python3 "$compare_py" "$out/gpu_$name.csv" "$out/gpu_$name.json" "$out/cpu_$name.csv" "$out/cpu_$name.json" \
    1e-10 krylov || true
}
# the stages of `first`: a stage under a timeout, with its knobs, skipped
# when less than MIN seconds of the budget are left
deadline=$((SECONDS + ${FIRST_BUDGET:-420}))
step() {  # MAX MIN LABEL STAGE [VAR=value...]: the stage's output also in $out/LABEL.log
  local max=$1 min=$2 label=$3 name=$4; shift 4
  local left=$((deadline - SECONDS))
  if ((left < min)); then
    echo "== first: $label skipped ($left s of the budget left, it needs $min)"
    return 0
  fi
  ((max > left)) && max=$left
  echo "== first: $label (at most $max s)"
  local t0=$SECONDS rc=0
  env "$@" RUN_SH_NESTED=1 timeout -k 10 "$max" bash "$0" "$name" 2>&1 | tee "$out/$label.log" || rc=$?
  echo "== first: $label ended after $((SECONDS - t0)) s, exit status $rc$( ((rc == 124)) && echo ' (timed out)')"
}
if [[ $stage == first ]]; then
  step 150 30 1-tests tests
  if grep -q 'FAILED.*Device.PresentWhereRequired' "$out/1-tests.log" 2>/dev/null; then
    # the target regions would run on the host (GCC 12 falls back even when
    # told not to): the other steps would measure that, not a GPU
    echo "== first: no usable GPU (Device.PresentWhereRequired failed): the other steps are not run"
    deadline=$SECONDS no_gpu=1
  fi
  if [[ -f $base/tests/earlier_forms_pass ]]; then
    echo "== first: the default forms fail device tests that the earlier forms pass: the other steps run with $earlier_forms"
    # shellcheck disable=SC2086 # (its assignments, split on purpose)
    export $earlier_forms
  fi
  step 40 15 2-launch launch
  step 120 30 2-bench bench BENCH="Device(Apply|ApplyFloat|VCycle|RestrictProlong)/$L/|Device(Dot|Axpy|CgUpdate)/$V/|Device(Axpy|Dot)/1024/" NO_ROOFLINE=1
  step 150 60 3-contact contact
  step 90 30 4-large large LARGE_LEVELS="${FIRST_LARGE:-14}"
  step 120 40 5-forms forms FORMS_ROUNDS=1
  step 60 20 6-roofline bench BENCH=none
  step 150 60 7-largest large LARGE_LEVELS="${FIRST_LARGEST:-15}"
  step 60 20 8-why why
  # the lines that answer issue 22's bars, step by step: tests passed, the
  # benchmarks' medians, each solve's verdict, work and times, GPU against
  # CPU, the roofline's device triad and kernels, each GPU solve's kernels
  # and copies of 5 % of its time and more, and every failure
  echo "== summary (whole logs above, and in run_first.log where OUT is set)"
  keep='^\[ +(PASSED|FAILED) +\]|_median|^== |largest difference|sets equal|iterations .* vs|same solution|DIFFERENT'
  keep+='|^(converged|not converged)|^work: .*peak|^times \[s\]|^# device|^apply y = Kx|^(apply \(float\)|dot|axpy|cg_update) +[0-9]|^V-cycle \('
  keep+='|exit status [1-9]|error|refused|^fixture:|^Device[A-Za-z]+/[0-9]+: '
  keep+='|^(target |teams |\.\.\. ).* [0-9.]+ +[0-9.]+ +[0-9.]+$'  # (launch_probe's rows)
  keep+='| (device|copy) +[0-9]+ +[0-9.]+ +([5-9]|[1-9][0-9])\.[0-9]%|^in launches:'  # (kernels of 5 % and more)
  for f in "$out"/*.log; do
    echo "-- ${f##*/}"
    grep -E "$keep" "$f" || true
  done
  exit "${no_gpu:-0}"
fi
if [[ $stage == tests || $stage == all ]]; then
  # the body GCC 12 miscompiles for the GPU (tests/check_device_code.py):
  # WRONG on a GPU shows the bug the check keeps out of the kernels
  [[ ! -x $bin/device_code_fixture ]] || "$bin/device_code_fixture" || true
  set +e
  "$bin/test_device" 2>&1 | tee "$out/test_device.log"
  rc=${PIPESTATUS[0]}
  set -e
  # a device test that fails on a GPU again under compute-sanitizer (memcheck:
  # the first illegal accesses and the kernels that made them), where it is
  sanitizer=$(command -v compute-sanitizer || ls /usr/local/cuda/bin/compute-sanitizer 2>/dev/null || true)
  failed=$(sed -nE 's/^\[  FAILED  \] (Device[A-Za-z]*\.[A-Za-z]+) \(.*/\1/p' "$out/test_device.log" |
           grep -v PresentWhereRequired | paste -sd: || true)
  # a test that ended the program (libgomp exits on an illegal address, so
  # gtest never writes FAILED): the last one started
  if [[ -z $failed && $rc != 0 ]]; then
    failed=$(sed -nE 's/^\[ RUN      \] (Device[A-Za-z]*\.[A-Za-z]+)$/\1/p' "$out/test_device.log" | tail -1)
    [[ -z $failed ]] || echo "== $failed ended the program (exit status $rc)"
  fi
  if [[ -n $failed && -n $sanitizer ]] && nvidia-smi > /dev/null 2>&1; then
    echo "== compute-sanitizer --tool memcheck on $failed"
    timeout -k 5 ${SANITIZER_SECONDS:-90} "$sanitizer" --tool memcheck --print-limit 12 "$bin/test_device" \
      --gtest_filter="$failed" 2>&1 | grep -vE '^\[ +(RUN|OK) ' | head -80 || true
  fi
  # the same tests with the kernels' earlier forms (RESULTS.md §0zh): where
  # they pass so, `first` runs its other steps with those forms
  if [[ -n $failed ]]; then
    echo "== the failing tests again with the earlier forms: $earlier_forms"
    # shellcheck disable=SC2086 # (its assignments, split on purpose)
    env $earlier_forms "$bin/test_device" --gtest_filter="$failed" > "$out/earlier_forms.log" 2>&1 && earlier=0 ||
      earlier=$?
    grep -E '^\[ +(PASSED|FAILED) +\]' "$out/earlier_forms.log" || true
    if ((earlier == 0)); then
      touch "$out/earlier_forms_pass"
      echo "== they pass with the earlier forms: a new form is at fault"
    fi
  fi
  ((rc == 0)) || exit "$rc"
fi
if [[ $stage == bench || $stage == all ]]; then
  [[ ${BENCH:-} == none ]] || bench "${BENCH:-Device}"
  [[ -n ${NO_ROOFLINE:-} ]] || "$bin/roofline" --level "$L" --device gpu
fi
if [[ $stage == elastic || $stage == all ]]; then
  for level in ${ELASTIC_LEVELS:-10 12 13}; do
    "$bin/elastic" --level "$level" --device gpu
    "$bin/elastic" --level "$level"
  done
fi
if [[ $stage == contact || $stage == all ]]; then
  for level in ${CONTACT_LEVELS:-8 12}; do
    contact "$level"
  done
  contact "${COULOMB_LEVEL:-10}" --coulomb 0.8
fi
if [[ $stage == warps ]]; then
  # the team size is a build setting (kernels/launch.hpp): the bundle's own
  # programs, and those built with other sizes (gpu_bundle.sh BUNDLE_WARPS)
  for b in "$bin" "$here"/warps-*; do
    [[ -x $b/bench_kernels ]] || continue
    (  # each build with its own libtresca_launch.so (the bundle's is already on the path)
      [[ ! -d $b/lib ]] || export LD_LIBRARY_PATH="$b/lib:$LD_LIBRARY_PATH"
      echo "== $b: $("$b/tresca" --level 1 --device gpu 2>&1 | grep -o '[0-9]* warps a team' | head -1)"
      "$b/bench_kernels" --benchmark_filter="Device(Apply|ApplyFloat|VCycle)/$L/|Device(Dot|CgUpdate)/$V/" \
        --benchmark_repetitions=3 --benchmark_report_aggregates_only=true "${bench_args[@]}"
      "$b/tresca" --level 12 --device gpu --quiet --json "$out/warps_${b##*/}.json"
    )
  done
fi
if [[ $stage == cut ]]; then
  for m in 0 8192 32768 131072 524288; do
    echo "== TRESCA_DEVICE_MIN_NODES=$m"
    TRESCA_DEVICE_MIN_NODES=$m bench 'DeviceVCycle/(10|12)/'
    TRESCA_DEVICE_MIN_NODES=$m "$bin/tresca" --level 12 --device gpu --profile --json "$out/cut_$m.json" |
      grep -E 'nested:|^times|host levels|^launches|on the device:'
  done
fi
if [[ $stage == images ]]; then
  for round in 1 2; do
    for b in "$bin" "$here/one-image"; do
      echo "== $b/bench_kernels (round $round)"
      "$b/bench_kernels" --benchmark_filter="Device(Axpy|Dot|CgUpdate)/(1024|$V)/|DeviceVCycle/12/" \
        --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
    done
  done
fi
if [[ $stage == launch ]]; then
  "$bin/launch_probe" "$V"
  echo "== launch: the teams and warps libgomp gives each region (GOMP_DEBUG=1; its calls, the region)"
  GOMP_DEBUG=1 "$bin/launch_probe" 1024 2>&1 | sed -nE 's/.*kernel ([^:]*): launch (.*)/\1 \2/p' |
    sed -E 's/_ZN12_GLOBAL__N_1//' | sort | uniq -c | sort -rn | head -20
fi
if [[ $stage == forms ]]; then
  mkdir -p "$out"
  for round in $(seq "${FORMS_ROUNDS:-2}"); do
    for sums in 1 0; do
      echo "== forms: TRESCA_DEVICE_WARP_SUMS=$sums (round $round)"
      TRESCA_DEVICE_WARP_SUMS=$sums bench "Device(Dot|CgUpdate)/$V/"
    done
  done | tee "$out/forms.log"
  # the verdict: each benchmark's forms, fastest first (DoF/s, the mean of
  # the rounds' medians)
  echo "== forms: the verdict (DoF/s, fastest first)"
  awk '
    function num(v) {  # 4.89G/s -> 4.89e9
      sub(/\/s$/, "", v)
      m = substr(v, length(v)); x = v + 0
      return m == "k" ? x * 1e3 : m == "M" ? x * 1e6 : m == "G" ? x * 1e9 : m == "T" ? x * 1e12 : x
    }
    /^== forms: / {
      form = $0; sub(/^== forms: /, "", form); sub(/ \(round [0-9]+\)$/, "", form); gsub(/TRESCA_DEVICE_/, "", form)
      next
    }
    /_median/ {
      name = $1; sub(/\/real_time_median$/, "", name)
      for (i = 2; i <= NF; i++) if ($i ~ /^DoF\/s=/) { v = $i; sub(/^DoF\/s=/, "", v) }
      key = name SUBSEP form
      if (!(key in n)) { order[name] = order[name] SUBSEP form; if (!(name in seen)) { seen[name] = 1; names[++nn] = name } }
      sum[key] += num(v); n[key]++
    }
    END {
      for (k = 1; k <= nn; k++) {
        name = names[k]; m = split(substr(order[name], 2), forms, SUBSEP)
        for (i = 1; i <= m; i++) rate[i] = sum[name SUBSEP forms[i]] / n[name SUBSEP forms[i]]
        for (i = 1; i <= m; i++)  # (a few forms: a selection sort)
          for (j = i + 1; j <= m; j++)
            if (rate[j] > rate[i]) { t = rate[i]; rate[i] = rate[j]; rate[j] = t; f = forms[i]; forms[i] = forms[j]; forms[j] = f }
        printf "%s:", name
        for (i = 1; i <= m; i++) printf "%s %s %.3g", (i > 1 ? ";" : ""), forms[i], rate[i]
        printf "\n"
      }
    }' "$out/forms.log"
fi
if [[ $stage == why ]]; then
  filter='Device(Apply|ApplyFloat)/12/|Device(Axpy|Dot|CgUpdate)/16777216/'
  echo "== launches as libgomp makes them (count, kernel, geometry)"
  GOMP_DEBUG=1 "$bin/bench_kernels" --benchmark_filter="$filter" --benchmark_min_time=0.01 2>&1 |
    sed -nE 's/.*kernel ([^:]*): launch (.*)/\1 \2/p' | sort | uniq -c | sort -rn | head -30
  ncu=$(command -v ncu || ls /usr/local/cuda/bin/ncu /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1 || true)
  if [[ -z $ncu ]]; then
    echo "no ncu (Nsight Compute): no kernel reports"
  else
    for k in 'elasticity_apply_rowsIdE' 'elasticity_apply_rowsIfE' 'NS_4axpyE' 'NS_3dotIdEE' 'NS_9cg_updateE'; do
      echo "== ncu: the first kernel whose mangled name matches $k"
      "$ncu" --clock-control none --kernel-name-base mangled --kernel-name "regex:$k" --launch-skip 2 --launch-count 1 \
        --section SpeedOfLight --section Occupancy --section LaunchStats --section MemoryWorkloadAnalysis \
        --section WarpStateStats --section SchedulerStats \
        "$bin/bench_kernels" --benchmark_filter="$filter" --benchmark_min_time=0.01 2>&1 |
        grep -vE '^(Device|-----|Benchmark|Run on|CPU Caches|  L[123]|Load Average|\*\*\*)' | head -120
    done
  fi
fi
if [[ $stage == large ]]; then
  for level in ${LARGE_LEVELS:-13 14 15}; do
    solve --level "$level" --device gpu --profile --json "$out/gpu_$level.json"
  done
fi
