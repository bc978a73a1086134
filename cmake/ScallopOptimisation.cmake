# scallop_light_optimisation(target): -O1 in the optimised build types, for targets whose own
# code is glue or checks: the CLI (option parsing, the jobs' wiring), the Python bindings and
# the tests. Their compile time is template instantiation (CLI11, pybind11, GoogleTest,
# nlohmann-json) optimised at -O3: the tests alone were 57% of a full build's compile time,
# and -O1 compiles them about 2.5 times faster (paths_cli_test.cpp: 41 s at -O3, 14 s at
# -O1). The work they call, and its speed, is in the libraries, which keep the build type's
# level; the benchmarks keep it too. GCC's -Wmaybe-uninitialized misfires at -O1 on
# std::optional (GCC 12: a `const std::optional<CadFormat>` set by a conditional, read only
# when engaged, in apps/surface_options.cpp), so these targets leave it off; the libraries,
# where the geometry is, keep it at -O3.
function(scallop_light_optimisation target)
  set(optimised $<CONFIG:Release,RelWithDebInfo,MinSizeRel>)
  target_compile_options(${target} PRIVATE
    $<$<AND:$<CXX_COMPILER_ID:GNU,Clang>,${optimised}>:-O1>
    $<$<AND:$<CXX_COMPILER_ID:GNU>,${optimised}>:-Wno-maybe-uninitialized>)
endfunction()
