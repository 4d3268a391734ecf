#!/usr/bin/env bash
# Packs the GPU programs of an offload build, with gcc-12's OpenMP runtime
# and nvptx plugin, for a GPU machine that has no gcc-12-offload-nvptx (the
# test machine: ../shared/device/README.md). Run on Debian from the project
# root:
#   bash perf/gpu_bundle.sh [bundle-dir]          (default .gpu-bundle, git-ignored)
# then, on the GPU machine, from the project root of the copy that travelled:
#   bash .gpu-bundle/run.sh [STAGE]      (the stages: run.sh's own header)
# where OUT is set, each stage's log and files also land in $OUT.
# which runs the device tests, the Device* benchmarks (BENCH=regex), roofline
# --device gpu at level 13, the elastic and the contact solves with --device
# gpu against the host's, and the large levels (run.sh's own header).
# The bundle's build has no MPI (fewer libraries to carry) and x86-64-v3
# (AVX2) as the baseline of its host code; its apply takes the x86-64-v4
# (AVX-512) variant where the host CPU has it (kernels/isa.hpp), so its host
# figures are the CPU's apply at full width.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-.gpu-bundle}
build=${BUILD_DIR:-build-gpu-bundle}
configure=(-DCMAKE_BUILD_TYPE=Release -DTRESCA_OFFLOAD=ON -DCMAKE_CXX_COMPILER=g++-12
           -DTRESCA_MPI=OFF -DTRESCA_NATIVE=OFF -DTRESCA_ARCH=x86-64-v3)
mkdir -p "$build"
cmake -S . -B "$build" "${configure[@]}" > "$build/configure.log"
cmake --build "$build" -j "$(nproc)" --target test_device bench_kernels tresca elastic roofline > "$build/build.log"
# bench_kernels once more with the vector kernels in the program's device
# image (TRESCA_LAUNCH_LIBRARY=STATIC), for run.sh images
one="$build-one-image"
mkdir -p "$one"
cmake -S . -B "$one" "${configure[@]}" -DTRESCA_LAUNCH_LIBRARY=STATIC > "$one/configure.log"
cmake --build "$one" -j "$(nproc)" --target bench_kernels > "$one/build.log"
rm -rf "$out"
mkdir -p "$out/lib"
cp "$build"/bin/test_device "$build"/bin/bench_kernels "$build"/bin/tresca "$build"/bin/elastic "$build"/bin/roofline "$out"/
cp "$build"/lib/libtresca_launch.so "$out/lib/"  # (the vector kernels' device image, CMakeLists.txt)
mkdir -p "$out/one-image"
cp "$one"/bin/bench_kernels "$out/one-image/"
lib=/usr/lib/x86_64-linux-gnu
cp -L "$lib"/libgomp.so.1 "$lib"/libgomp-plugin-nvptx.so.1 "$out/lib/"
cp -L "$(ldconfig -p | awk '/libbenchmark\.so\./ {print $NF; exit}')" "$out/lib/"
cat > "$out/run.sh" <<'RUN'
#!/usr/bin/env bash
# The device checks and benchmarks of the bundle (perf/gpu_bundle.sh), in
# stages that each fit a 10-minute command:
#   run.sh tests    the device tests (a run without a usable GPU fails:
#                   Device.PresentWhereRequired; GCC 12 falls back to the
#                   host even with OMP_TARGET_OFFLOAD=MANDATORY)
#   run.sh bench    the Device* benchmarks and roofline --device gpu at level 13
#                   (DeviceAxpy/1024 and DeviceDot/1024: what one launch costs;
#                   contact's --profile says how many launches a solve makes)
#   run.sh elastic  the MG-CG solve, GPU then CPU, levels 10, 12, 13
#   run.sh contact  tresca, GPU then CPU, levels 8 and 12 and Coulomb 0.8 at
#                   level 10: the contact values' largest difference relative
#                   to their largest value (issue 22: <= 1e-10)
#   run.sh large    tresca --device gpu at levels 13, 14 and 15
#   run.sh warps    the team size (TRESCA_DEVICE_WARPS 1, 2, 4, 8, 16): the
#                   level-13 apply, V-cycle and vector benchmarks and a
#                   level-12 contact solve with each (perf/offload_registers.py
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
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export OMP_TARGET_OFFLOAD=${OMP_TARGET_OFFLOAD:-MANDATORY} TRESCA_REQUIRE_DEVICE=1
stage=${1:-all}
case $stage in
  tests|bench|elastic|contact|large|warps|cut|images|why|all) ;;
  *) echo "run.sh: unknown stage '$stage' (tests, bench, elastic, contact, large, warps, cut, images, why, all)" >&2
     exit 2 ;;
esac
out=${TMPDIR:-/tmp}/tresca-gpu-run/$stage  # the stage's CSV and JSON files
mkdir -p "$out"
# Where OUT is set (the test machine's tool brings back what is under it):
# the stage's output also goes to $OUT/run_STAGE.log, and its CSV and JSON
# files to $OUT/run_STAGE.files.tgz, two files a stage (the tool returns 8)
if [[ -n ${OUT:-} && -z ${RUN_SH_LOGGED:-} ]]; then
  set +e
  RUN_SH_LOGGED=1 bash "$0" "$stage" 2>&1 | tee "$OUT/run_$stage.log"
  rc=${PIPESTATUS[0]}
  tar czf "$OUT/run_$stage.files.tgz" -C "$out" .
  exit "$rc"
fi
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader 2>/dev/null || echo "no nvidia-smi"
# largest |a - b| over the columns ux, uy, uz, lambda of two contact CSVs,
# relative to the largest |a| of each column
compare() {
  paste -d, "$1" "$2" | awk -F, 'NR == 1 { n = NF / 2; for (i = 1; i <= n; ++i) col[$i] = i; next }
    { for (c in want) { i = col[c]; d = $i - $(i + n); if (d < 0) d = -d; a = $i < 0 ? -$i : $i;
        if (d > diff[c]) diff[c] = d; if (a > big[c]) big[c] = a } }
    BEGIN { want["ux"]; want["uy"]; want["uz"]; want["lambda"] }
    END { worst = 0; for (c in want) { r = big[c] > 0 ? diff[c] / big[c] : diff[c]; printf "%s %.2e  ", c, r;
          if (r > worst) worst = r } printf "-> largest %.2e (%s)\n", worst, worst <= 1e-10 ? "ok" : "ABOVE 1e-10" }'
}
contact() {  # level, then tresca options
  local level=$1; shift
  "$here/tresca" --level "$level" "$@" --device gpu --profile --contact-csv "$out/gpu_$level.csv" --json "$out/gpu_$level.json"
  "$here/tresca" --level "$level" "$@" --quiet --contact-csv "$out/cpu_$level.csv" --json "$out/cpu_$level.json"
  local f  # this mesh's Newton steps and inner iterations (the first of each key: not a nested level's)
  for f in gpu cpu; do
    echo "$f: $(grep -m1 -o '"newton_iterations": *[0-9]*' "$out/${f}_$level.json")," \
         "$(grep -m1 -o '"inner_iterations": *[0-9]*' "$out/${f}_$level.json")"
  done
  echo "level $level $*: GPU against CPU: $(compare "$out/gpu_$level.csv" "$out/cpu_$level.csv")"
}
if [[ $stage == tests || $stage == all ]]; then
  "$here/test_device"
fi
if [[ $stage == bench || $stage == all ]]; then
  "$here/bench_kernels" --benchmark_filter="${BENCH:-Device}" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
  "$here/roofline" --level 13 --device gpu
fi
if [[ $stage == elastic || $stage == all ]]; then
  for level in 10 12 13; do
    "$here/elastic" --level "$level" --device gpu
    "$here/elastic" --level "$level"
  done
fi
if [[ $stage == contact || $stage == all ]]; then
  contact 8
  contact 12
  contact 10 --coulomb 0.8
fi
if [[ $stage == warps ]]; then
  for w in 1 2 4 8 16; do
    echo "== TRESCA_DEVICE_WARPS=$w"
    TRESCA_DEVICE_WARPS=$w "$here/bench_kernels" --benchmark_filter='Device(Apply|ApplyFloat|VCycle)/13|Device(Dot|CgUpdate)/134217728' \
      --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
    TRESCA_DEVICE_WARPS=$w "$here/tresca" --level 12 --device gpu --quiet --json "$out/warps_$w.json"
  done
fi
if [[ $stage == cut ]]; then
  for m in 0 8192 32768 131072 524288; do
    echo "== TRESCA_DEVICE_MIN_NODES=$m"
    TRESCA_DEVICE_MIN_NODES=$m "$here/bench_kernels" --benchmark_filter='DeviceVCycle/(10|12)' \
      --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
    TRESCA_DEVICE_MIN_NODES=$m "$here/tresca" --level 12 --device gpu --profile --json "$out/cut_$m.json" |
      grep -E 'nested:|^times|host levels|^launches|on the device:'
  done
fi
if [[ $stage == images ]]; then
  for round in 1 2; do
    for b in "$here" "$here/one-image"; do
      echo "== $b/bench_kernels (round $round)"
      "$b/bench_kernels" --benchmark_filter='Device(Axpy|Dot|CgUpdate)/(1024|134217728)|DeviceVCycle/12' \
        --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
    done
  done
fi
if [[ $stage == why ]]; then
  filter='Device(Apply|ApplyFloat)/12|Device(Axpy|Dot|CgUpdate)/16777216'
  echo "== launches as libgomp makes them (count, kernel, geometry)"
  GOMP_DEBUG=1 "$here/bench_kernels" --benchmark_filter="$filter" --benchmark_min_time=0.01 2>&1 |
    sed -nE 's/.*kernel ([^:]*): launch (.*)/\1 \2/p' | sort | uniq -c | sort -rn | head -30
  ncu=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1 || true)
  if [[ -z $ncu ]]; then
    echo "no ncu (Nsight Compute): no kernel reports"
  else
    for k in 'elasticity_apply_rowsIdE' 'elasticity_apply_rowsIfE' 'NS_4axpyE' 'NS_3dotIdEE' 'NS_9cg_updateE'; do
      echo "== ncu: the first kernel whose mangled name matches $k"
      "$ncu" --clock-control none --kernel-name-base mangled --kernel-name "regex:$k" --launch-skip 2 --launch-count 1 \
        --section SpeedOfLight --section Occupancy --section LaunchStats --section MemoryWorkloadAnalysis \
        "$here/bench_kernels" --benchmark_filter="$filter" --benchmark_min_time=0.01 2>&1 |
        grep -vE '^(Device|-----|Benchmark|Run on|CPU Caches|  L[123]|Load Average|\*\*\*)' | head -80
    done
  fi
fi
if [[ $stage == large ]]; then
  for level in 13 14 15; do
    "$here/tresca" --level "$level" --device gpu --profile --json "$out/gpu_$level.json"
  done
fi
RUN
chmod +x "$out/run.sh"
echo "bundle: $out ($(du -sh "$out" | cut -f1)); on the GPU machine: bash $out/run.sh [stage]"
