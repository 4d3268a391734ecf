
# Consider dependencies only in project.
set(CMAKE_DEPENDS_IN_PROJECT_ONLY OFF)

# The set of languages for which implicit dependencies are needed:
set(CMAKE_DEPENDS_LANGUAGES
  )

# The set of dependency files which are needed:
set(CMAKE_DEPENDS_DEPENDENCY_FILES
  "/work/main/perf/scaling.cpp" "CMakeFiles/scaling.dir/perf/scaling.cpp.o" "gcc" "CMakeFiles/scaling.dir/perf/scaling.cpp.o.d"
  )

# Targets to which this target links.
set(CMAKE_TARGET_LINKED_INFO_FILES
  "/work/main/build-generic/CMakeFiles/tresca_core.dir/DependInfo.cmake"
  "/work/main/build-generic/CMakeFiles/tresca_kernels.dir/DependInfo.cmake"
  )

# Fortran module output directory.
set(CMAKE_Fortran_TARGET_MODULE_DIR "")
