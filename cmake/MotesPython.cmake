# The Python module (python/): MOTES_WITH_PYTHON=AUTO builds it when Python 3 with its headers
# and pybind11 are found (Debian: python3-dev, python3-pybind11), ON requires them. Not in
# sanitizer builds: an ASan-instrumented module cannot load into an uninstrumented interpreter.
# Debian's /usr/bin/python3 is used unless Python3_EXECUTABLE names another interpreter.
set(MOTES_PYTHON OFF)
set(MOTES_PYTHON_STATUS "not built: MOTES_WITH_PYTHON=OFF")
if(NOT MOTES_WITH_PYTHON MATCHES "^(AUTO|ON|OFF)$")
  message(FATAL_ERROR "MOTES_WITH_PYTHON must be AUTO, ON or OFF (got '${MOTES_WITH_PYTHON}')")
endif()
if(MOTES_SANITIZE AND NOT MOTES_WITH_PYTHON STREQUAL "OFF")
  set(MOTES_PYTHON_STATUS "not built: a sanitizer build")
elseif(NOT MOTES_WITH_PYTHON STREQUAL "OFF")
  if(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
    set(Python3_EXECUTABLE /usr/bin/python3)
  endif()
  find_package(Python3 COMPONENTS Interpreter Development.Module)
  if(Python3_FOUND)
    execute_process(COMMAND ${Python3_EXECUTABLE} -c "import pybind11; print(pybind11.get_cmake_dir())"
                    OUTPUT_VARIABLE motes_pybind11_dir OUTPUT_STRIP_TRAILING_WHITESPACE
                    ERROR_QUIET)
    find_package(pybind11 CONFIG QUIET HINTS ${motes_pybind11_dir})
  endif()
  if(Python3_FOUND AND pybind11_FOUND)
    set(MOTES_PYTHON ON)
    set(MOTES_PYTHON_STATUS "built for ${Python3_EXECUTABLE} (${Python3_VERSION})")
    add_subdirectory(python)
  else()
    set(MOTES_PYTHON_STATUS
        "not built: needs Python 3 with its headers and pybind11 (Debian: python3-dev python3-pybind11)")
    if(MOTES_WITH_PYTHON STREQUAL "ON")
      message(FATAL_ERROR "MOTES_WITH_PYTHON=ON but ${MOTES_PYTHON_STATUS}")
    endif()
  endif()
endif()
