# scallop_set_warnings(<target>): warnings per target, never directory-wide.
# -ffp-contract=off keeps results byte-identical whatever the compiler fuses into FMAs
# (manifold does the same for determinism).
function(scallop_set_warnings target)
  target_compile_options(${target} PRIVATE
    $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion -ffp-contract=off>)
  if(SCALLOP_WERROR)
    target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU,Clang>:-Werror>)
  endif()
endfunction()
