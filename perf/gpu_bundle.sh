#!/usr/bin/env bash
# Packs the GPU programs of an offload build, with gcc-12's OpenMP runtime
# and nvptx plugin, for a GPU machine that has no gcc-12-offload-nvptx (the
# test machine: ../shared/device/README.md). Run on Debian from the project
# root:
#   bash perf/gpu_bundle.sh [bundle-dir]          (default .gpu-bundle, git-ignored)
#   (BUNDLE_WARPS="4 16" adds warps-4/ and warps-16/: bench_kernels and tresca
#   built with those team sizes, for run.sh warps)
# then, on the GPU machine, from the project root of the copy that travelled:
#   bash .gpu-bundle/run.sh [STAGE]      (the stages: perf/gpu_run.sh's header)
# where OUT is set, each stage's log and files also land in $OUT.
# run.sh is perf/gpu_run.sh (tested in the offload build on the host,
# perf.gpu_run_smoke); it runs the device tests, the Device* benchmarks,
# roofline --device gpu, the elastic and the contact solves with --device gpu
# against the host's (compared by tests/compare_runs.py, carried too), and
# the large levels; `run.sh first` is one call's worth of all that.
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
cmake --build "$build" -j "$(nproc)" --target test_device bench_kernels tresca elastic roofline device_code_fixture launch_probe > "$build/build.log"
# bench_kernels once more with the vector kernels in the program's device
# image (TRESCA_LAUNCH_LIBRARY=STATIC), for run.sh images
one="$build-one-image"
mkdir -p "$one"
cmake -S . -B "$one" "${configure[@]}" -DTRESCA_LAUNCH_LIBRARY=STATIC > "$one/configure.log"
cmake --build "$one" -j "$(nproc)" --target bench_kernels > "$one/build.log"
rm -rf "$out"
mkdir -p "$out/lib"
cp "$build"/bin/test_device "$build"/bin/bench_kernels "$build"/bin/tresca "$build"/bin/elastic "$build"/bin/roofline \
   "$build"/bin/device_code_fixture "$build"/bin/launch_probe "$out"/
cp "$build"/lib/libtresca_launch.so "$out/lib/"  # (the vector kernels' device image, CMakeLists.txt)
mkdir -p "$out/one-image"
cp "$one"/bin/bench_kernels "$out/one-image/"
lib=/usr/lib/x86_64-linux-gnu
cp -L "$lib"/libgomp.so.1 "$lib"/libgomp-plugin-nvptx.so.1 "$out/lib/"
cp -L "$(ldconfig -p | awk '/libbenchmark\.so\./ {print $NF; exit}')" "$out/lib/"
# the same programs with other team sizes, for run.sh warps (each a build
# of its own: the team size is a build setting, kernels/launch.hpp)
for w in ${BUNDLE_WARPS:-}; do
  wb="$build-warps$w"
  mkdir -p "$wb" "$out/warps-$w/lib"
  cmake -S . -B "$wb" "${configure[@]}" -DTRESCA_DEVICE_WARPS="$w" > "$wb/configure.log"
  cmake --build "$wb" -j "$(nproc)" --target bench_kernels tresca > "$wb/build.log"
  cp "$wb"/bin/bench_kernels "$wb"/bin/tresca "$out/warps-$w/"
  cp "$wb"/lib/libtresca_launch.so "$out/warps-$w/lib/"
done
cp perf/gpu_run.sh "$out/run.sh"
cp tests/compare_runs.py "$out/"
chmod +x "$out/run.sh"
echo "bundle: $out ($(du -sh "$out" | cut -f1)); on the GPU machine: bash $out/run.sh [stage]"
