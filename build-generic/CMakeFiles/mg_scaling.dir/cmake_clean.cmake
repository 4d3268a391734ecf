file(REMOVE_RECURSE
  "CMakeFiles/mg_scaling.dir/perf/mg_scaling.cpp.o"
  "CMakeFiles/mg_scaling.dir/perf/mg_scaling.cpp.o.d"
  "bin/mg_scaling"
  "bin/mg_scaling.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang CXX)
  include(CMakeFiles/mg_scaling.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
