#!/usr/bin/env bash
# Packs the GPU programs of an offload build, with gcc-12's OpenMP runtime
# and nvptx plugin, for a GPU machine that has no gcc-12-offload-nvptx (the
# test machine: ../shared/device/README.md). Run on Debian from the project
# root:
#   bash perf/gpu_bundle.sh [bundle-dir]          (default .gpu-bundle, git-ignored)
# then, on the GPU machine, from the project root of the copy that travelled:
#   bash .gpu-bundle/run.sh [benchmark regex]     (default: every Device benchmark)
# which runs the device tests, the Device* benchmarks, roofline --device
# gpu at level 13 and the elastic solve with --device gpu at levels 10, 12
# and 13 against the host's.
# The bundle's build has no MPI (fewer libraries to carry) and targets
# x86-64-v3 (AVX2) for its host code: its host figures are not the CPU's best.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-.gpu-bundle}
build=${BUILD_DIR:-build-gpu-bundle}
mkdir -p "$build"
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DTRESCA_OFFLOAD=ON -DCMAKE_CXX_COMPILER=g++-12 \
      -DTRESCA_MPI=OFF -DTRESCA_NATIVE=OFF -DTRESCA_ARCH=x86-64-v3 > "$build/configure.log"
cmake --build "$build" -j "$(nproc)" --target test_device bench_kernels tresca elastic roofline > "$build/build.log"
rm -rf "$out"
mkdir -p "$out/lib"
cp "$build"/bin/test_device "$build"/bin/bench_kernels "$build"/bin/tresca "$build"/bin/elastic "$build"/bin/roofline "$out"/
lib=/usr/lib/x86_64-linux-gnu
cp -L "$lib"/libgomp.so.1 "$lib"/libgomp-plugin-nvptx.so.1 "$out/lib/"
cp -L "$(ldconfig -p | awk '/libbenchmark\.so\./ {print $NF; exit}')" "$out/lib/"
cat > "$out/run.sh" <<'RUN'
#!/usr/bin/env bash
# The device checks and benchmarks of the bundle (perf/gpu_bundle.sh). A
# run without a usable GPU fails (test Device.PresentWhereRequired: GCC 12
# falls back to the host even with OMP_TARGET_OFFLOAD=MANDATORY).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export OMP_TARGET_OFFLOAD=${OMP_TARGET_OFFLOAD:-MANDATORY} TRESCA_REQUIRE_DEVICE=1
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader 2>/dev/null || echo "no nvidia-smi"
"$here/test_device"
"$here/bench_kernels" --benchmark_filter="${1:-Device}" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
"$here/roofline" --level 13 --device gpu
for level in 10 12 13; do
  "$here/elastic" --level "$level" --device gpu
  "$here/elastic" --level "$level"
done
RUN
chmod +x "$out/run.sh"
echo "bundle: $out ($(du -sh "$out" | cut -f1)); on the GPU machine: bash $out/run.sh"
