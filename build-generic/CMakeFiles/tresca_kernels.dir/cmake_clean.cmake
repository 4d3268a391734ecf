file(REMOVE_RECURSE
  "CMakeFiles/tresca_kernels.dir/kernels/boundary_block.cpp.o"
  "CMakeFiles/tresca_kernels.dir/kernels/boundary_block.cpp.o.d"
  "CMakeFiles/tresca_kernels.dir/kernels/contact_maps.cpp.o"
  "CMakeFiles/tresca_kernels.dir/kernels/contact_maps.cpp.o.d"
  "CMakeFiles/tresca_kernels.dir/kernels/elasticity.cpp.o"
  "CMakeFiles/tresca_kernels.dir/kernels/elasticity.cpp.o.d"
  "CMakeFiles/tresca_kernels.dir/kernels/element.cpp.o"
  "CMakeFiles/tresca_kernels.dir/kernels/element.cpp.o.d"
  "CMakeFiles/tresca_kernels.dir/kernels/simd.cpp.o"
  "CMakeFiles/tresca_kernels.dir/kernels/simd.cpp.o.d"
  "CMakeFiles/tresca_kernels.dir/kernels/transfer.cpp.o"
  "CMakeFiles/tresca_kernels.dir/kernels/transfer.cpp.o.d"
  "CMakeFiles/tresca_kernels.dir/kernels/vector_ops.cpp.o"
  "CMakeFiles/tresca_kernels.dir/kernels/vector_ops.cpp.o.d"
  "libtresca_kernels.a"
  "libtresca_kernels.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang CXX)
  include(CMakeFiles/tresca_kernels.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
