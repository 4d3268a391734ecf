
# Consider dependencies only in project.
set(CMAKE_DEPENDS_IN_PROJECT_ONLY OFF)

# The set of languages for which implicit dependencies are needed:
set(CMAKE_DEPENDS_LANGUAGES
  )

# The set of dependency files which are needed:
set(CMAKE_DEPENDS_DEPENDENCY_FILES
  "/work/main/kernels/boundary_block.cpp" "CMakeFiles/tresca_kernels.dir/kernels/boundary_block.cpp.o" "gcc" "CMakeFiles/tresca_kernels.dir/kernels/boundary_block.cpp.o.d"
  "/work/main/kernels/contact_maps.cpp" "CMakeFiles/tresca_kernels.dir/kernels/contact_maps.cpp.o" "gcc" "CMakeFiles/tresca_kernels.dir/kernels/contact_maps.cpp.o.d"
  "/work/main/kernels/elasticity.cpp" "CMakeFiles/tresca_kernels.dir/kernels/elasticity.cpp.o" "gcc" "CMakeFiles/tresca_kernels.dir/kernels/elasticity.cpp.o.d"
  "/work/main/kernels/element.cpp" "CMakeFiles/tresca_kernels.dir/kernels/element.cpp.o" "gcc" "CMakeFiles/tresca_kernels.dir/kernels/element.cpp.o.d"
  "/work/main/kernels/simd.cpp" "CMakeFiles/tresca_kernels.dir/kernels/simd.cpp.o" "gcc" "CMakeFiles/tresca_kernels.dir/kernels/simd.cpp.o.d"
  "/work/main/kernels/transfer.cpp" "CMakeFiles/tresca_kernels.dir/kernels/transfer.cpp.o" "gcc" "CMakeFiles/tresca_kernels.dir/kernels/transfer.cpp.o.d"
  "/work/main/kernels/vector_ops.cpp" "CMakeFiles/tresca_kernels.dir/kernels/vector_ops.cpp.o" "gcc" "CMakeFiles/tresca_kernels.dir/kernels/vector_ops.cpp.o.d"
  )

# Targets to which this target links.
set(CMAKE_TARGET_LINKED_INFO_FILES
  )

# Fortran module output directory.
set(CMAKE_Fortran_TARGET_MODULE_DIR "")
