file(REMOVE_RECURSE
  "CMakeFiles/scaling.dir/perf/scaling.cpp.o"
  "CMakeFiles/scaling.dir/perf/scaling.cpp.o.d"
  "bin/scaling"
  "bin/scaling.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang CXX)
  include(CMakeFiles/scaling.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
