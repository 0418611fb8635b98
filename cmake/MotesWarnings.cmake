# Warnings for every motes target: motes_target_warnings(TARGET).
function(motes_target_warnings target)
  target_compile_options(${target} PRIVATE
    $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
      -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Wunused -Woverloaded-virtual
      -Wnull-dereference -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough>
    # clang (the sanitizer build) also counts double{f} and a float passed to printf as implicit
    # promotions; GCC's check, which the release build applies, is the project's.
    $<$<AND:$<COMPILE_LANGUAGE:CXX>,$<CXX_COMPILER_ID:Clang>>:-Wno-double-promotion>)
  if(MOTES_WERROR)
    target_compile_options(${target} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:-Werror>)
  endif()
  if(MOTES_SANITIZE)
    # GCC 12 (CI's sanitizer build is clang's, but GCC builds one too) reports false
    # maybe-uninitialized warnings inside libstdc++ (std::regex, std::function) once the
    # sanitizers instrument them. Line tables only (-g1): the reports name files and
    # lines, and full debug information made the instrumented build a third slower.
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer
                                             -fno-sanitize-recover=all
                                             $<$<CXX_COMPILER_ID:GNU>:-Wno-maybe-uninitialized>
                                             $<$<COMPILE_LANGUAGE:CXX>:-g1>)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
    # Executables keep every shared library loaded until exit, so that LeakSanitizer can name the
    # library of an allocation (tests/sanitizers/keep_libraries_loaded.cpp says why). The symbol
    # must be in the dynamic table: the Vulkan loader, which calls dlclose, is itself dlopen'ed.
    get_target_property(type ${target} TYPE)
    if(type STREQUAL "EXECUTABLE")
      target_sources(${target} PRIVATE
                     ${PROJECT_SOURCE_DIR}/tests/sanitizers/keep_libraries_loaded.cpp)
      target_link_options(${target} PRIVATE LINKER:--export-dynamic-symbol=dlclose)
    endif()
  endif()
  if(MOTES_STRICT_FP)
    target_compile_options(${target} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:-ffp-contract=off>)
  endif()
endfunction()

# A part of libmotes (an object library whose objects go into it) or libmotes_render:
# position-independent code, symbols hidden unless a public header declares them
# (core/include/motes/api.h), the warnings.
function(motes_library_part target)
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON
                                             CXX_VISIBILITY_PRESET hidden
                                             CUDA_VISIBILITY_PRESET hidden
                                             VISIBILITY_INLINES_HIDDEN ON)
  motes_target_warnings(${target})
endfunction()
