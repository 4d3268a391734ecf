file(REMOVE_RECURSE
  "CMakeFiles/tresca_core.dir/core/assembly.cpp.o"
  "CMakeFiles/tresca_core.dir/core/assembly.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/boundary_preconditioner.cpp.o"
  "CMakeFiles/tresca_core.dir/core/boundary_preconditioner.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/cg.cpp.o"
  "CMakeFiles/tresca_core.dir/core/cg.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/cli.cpp.o"
  "CMakeFiles/tresca_core.dir/core/cli.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/elasticity_operator.cpp.o"
  "CMakeFiles/tresca_core.dir/core/elasticity_operator.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/interior.cpp.o"
  "CMakeFiles/tresca_core.dir/core/interior.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/multigrid.cpp.o"
  "CMakeFiles/tresca_core.dir/core/multigrid.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/output.cpp.o"
  "CMakeFiles/tresca_core.dir/core/output.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/problem.cpp.o"
  "CMakeFiles/tresca_core.dir/core/problem.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/profile.cpp.o"
  "CMakeFiles/tresca_core.dir/core/profile.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/report.cpp.o"
  "CMakeFiles/tresca_core.dir/core/report.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/run.cpp.o"
  "CMakeFiles/tresca_core.dir/core/run.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/semismooth.cpp.o"
  "CMakeFiles/tresca_core.dir/core/semismooth.cpp.o.d"
  "CMakeFiles/tresca_core.dir/core/steklov.cpp.o"
  "CMakeFiles/tresca_core.dir/core/steklov.cpp.o.d"
  "libtresca_core.a"
  "libtresca_core.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang CXX)
  include(CMakeFiles/tresca_core.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
