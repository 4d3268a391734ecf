file(REMOVE_RECURSE
  "CMakeFiles/tresca.dir/drivers/tresca.cpp.o"
  "CMakeFiles/tresca.dir/drivers/tresca.cpp.o.d"
  "bin/tresca"
  "bin/tresca.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang CXX)
  include(CMakeFiles/tresca.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
