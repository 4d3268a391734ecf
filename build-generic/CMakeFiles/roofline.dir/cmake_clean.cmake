file(REMOVE_RECURSE
  "CMakeFiles/roofline.dir/perf/roofline.cpp.o"
  "CMakeFiles/roofline.dir/perf/roofline.cpp.o.d"
  "bin/roofline"
  "bin/roofline.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang CXX)
  include(CMakeFiles/roofline.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
