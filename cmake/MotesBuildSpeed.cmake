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

# In a sanitizer build, executables that only drive the library (the test executables, the
# command line) are compiled with -O1 (but in Debug): their own code is a negligible part of any
# run (the kernels, the oracle and the writers keep the build type's optimization), while
# instrumenting their large test bodies and CLI11's templates at -O2 was most of that build's
# compile time (the command line's files took 47 s each). GCC 12 reports false -Warray-bounds
# inside libstdc++'s std::string operator+ at -O1, so that warning is off for these targets in
# that build only (the release build checks every file with it).
function(motes_driver_optimization target)
  if(MOTES_SANITIZE)
    set(lang_not_debug "$<AND:$<COMPILE_LANGUAGE:CXX>,$<NOT:$<CONFIG:Debug>>>")
    target_compile_options(${target} PRIVATE "$<${lang_not_debug}:-O1>"
                                             "$<${lang_not_debug}:-Wno-array-bounds>")
  endif()
endfunction()
