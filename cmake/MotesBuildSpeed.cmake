# Build time. CI builds motes from a clean clone four times on a 2-core machine (the build, the
# installed package's lean build, the sanitizer build, the fuzz build); the README's "Tests"
# paragraph has the stage times measured before and after these settings.

# Precompiled headers: the large third-party headers (CLI11, GoogleTest, nlohmann/json, fmt,
# Eigen) parsed once per target instead of once per source file. CLI11 alone takes about 6 s per
# file and every file of the command line includes it. Only for targets whose sources are all
# C++ (never a CUDA target); MOTES_PCH=OFF builds without them (which checks that every file
# includes what it uses).
option(MOTES_PCH "Precompile the large third-party headers" ON)

function(motes_precompile target)
  if(MOTES_PCH)
    target_precompile_headers(${target} PRIVATE ${ARGN})
  endif()
endfunction()

# Executables that only drive the library (the test executables, the command line):
# - Unity builds: their sources are compiled eight to a translation unit. Each file instantiates
#   the same templates (GoogleTest's, CLI11's, json's, fmt's, Eigen's) and emits the same inline
#   functions; a unity batch does that once. Measured in the sanitizer build: 619 s of CPU in
#   separate files, 336 s in batches. Names at namespace scope (anonymous namespaces included)
#   must therefore be unique across a target's files: shared helpers live in tests/unit/
#   test_support.h, tests/mpi/mpi_support.h and cli/cli_util.h.
# - In a sanitizer build they are compiled at -O0 (in every configuration but Debug, which is
#   -O0 anyway): their own code is a negligible part of any run (the kernels, the oracle and the
#   writers keep the build type's optimization), while instrumenting their large test bodies and
#   CLI11's templates with optimization was most of that build's compile time (the command line's
#   files took 47 s each at -O2). The whole sanitizer test stage took 4 % longer at -O0 than at -O1.
#   One cost of it: an inline function (Eigen's templates) that the library's optimized code calls
#   rather than inlines runs the executable's -O0 copy, as the linker keeps the first copy and the
#   test objects come first. clang's sanitized code inlines Eigen less than GCC's: the exact winding
#   number took 4 us a triangle there (tests/unit/test_winding_number.cpp is sized for it).
#   The release build keeps them optimized: at -O0 there too (tried in session 38, 2-core VM) the
#   test executables compiled in 202 CPU s instead of 366, but their tests took 1,768 test-seconds
#   instead of 1,638 (939 s of the stage instead of 872): no gain.
#   CI's sanitizer build is clang's (scripts/test.sh); built with GCC 12, which reports false
#   -Warray-bounds inside libstdc++'s std::string operator+ at low optimization, that warning is
#   off for these targets (the release build checks every file with it).
function(motes_driver_settings target)
  set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
  if(MOTES_SANITIZE)
    set(lang_not_debug "$<AND:$<COMPILE_LANGUAGE:CXX>,$<NOT:$<CONFIG:Debug>>>")
    target_compile_options(${target} PRIVATE "$<${lang_not_debug}:-O0>"
                                             "$<$<CXX_COMPILER_ID:GNU>:-Wno-array-bounds>")
  endif()
endfunction()
