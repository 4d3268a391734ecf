file(REMOVE_RECURSE
  "CMakeFiles/bench_kernels.dir/perf/bench_kernels.cpp.o"
  "CMakeFiles/bench_kernels.dir/perf/bench_kernels.cpp.o.d"
  "bin/bench_kernels"
  "bin/bench_kernels.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang CXX)
  include(CMakeFiles/bench_kernels.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
