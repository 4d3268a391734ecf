file(REMOVE_RECURSE
  "CMakeFiles/elastic.dir/drivers/elastic.cpp.o"
  "CMakeFiles/elastic.dir/drivers/elastic.cpp.o.d"
  "bin/elastic"
  "bin/elastic.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang CXX)
  include(CMakeFiles/elastic.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
