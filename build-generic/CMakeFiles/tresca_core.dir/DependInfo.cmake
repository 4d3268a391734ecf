
# Consider dependencies only in project.
set(CMAKE_DEPENDS_IN_PROJECT_ONLY OFF)

# The set of languages for which implicit dependencies are needed:
set(CMAKE_DEPENDS_LANGUAGES
  )

# The set of dependency files which are needed:
set(CMAKE_DEPENDS_DEPENDENCY_FILES
  "/work/main/core/assembly.cpp" "CMakeFiles/tresca_core.dir/core/assembly.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/assembly.cpp.o.d"
  "/work/main/core/boundary_preconditioner.cpp" "CMakeFiles/tresca_core.dir/core/boundary_preconditioner.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/boundary_preconditioner.cpp.o.d"
  "/work/main/core/cg.cpp" "CMakeFiles/tresca_core.dir/core/cg.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/cg.cpp.o.d"
  "/work/main/core/cli.cpp" "CMakeFiles/tresca_core.dir/core/cli.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/cli.cpp.o.d"
  "/work/main/core/elasticity_operator.cpp" "CMakeFiles/tresca_core.dir/core/elasticity_operator.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/elasticity_operator.cpp.o.d"
  "/work/main/core/interior.cpp" "CMakeFiles/tresca_core.dir/core/interior.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/interior.cpp.o.d"
  "/work/main/core/multigrid.cpp" "CMakeFiles/tresca_core.dir/core/multigrid.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/multigrid.cpp.o.d"
  "/work/main/core/output.cpp" "CMakeFiles/tresca_core.dir/core/output.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/output.cpp.o.d"
  "/work/main/core/problem.cpp" "CMakeFiles/tresca_core.dir/core/problem.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/problem.cpp.o.d"
  "/work/main/core/profile.cpp" "CMakeFiles/tresca_core.dir/core/profile.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/profile.cpp.o.d"
  "/work/main/core/report.cpp" "CMakeFiles/tresca_core.dir/core/report.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/report.cpp.o.d"
  "/work/main/core/run.cpp" "CMakeFiles/tresca_core.dir/core/run.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/run.cpp.o.d"
  "/work/main/core/semismooth.cpp" "CMakeFiles/tresca_core.dir/core/semismooth.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/semismooth.cpp.o.d"
  "/work/main/core/steklov.cpp" "CMakeFiles/tresca_core.dir/core/steklov.cpp.o" "gcc" "CMakeFiles/tresca_core.dir/core/steklov.cpp.o.d"
  )

# Targets to which this target links.
set(CMAKE_TARGET_LINKED_INFO_FILES
  "/work/main/build-generic/CMakeFiles/tresca_kernels.dir/DependInfo.cmake"
  )

# Fortran module output directory.
set(CMAKE_Fortran_TARGET_MODULE_DIR "")
