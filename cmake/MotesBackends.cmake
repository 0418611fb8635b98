# Decides which backends are built, from MOTES_WITH_{OPENMP,CUDA,VULKAN} = AUTO|ON|OFF.
foreach(opt MOTES_WITH_OPENMP MOTES_WITH_CUDA MOTES_WITH_VULKAN)
  if(NOT ${opt} MATCHES "^(AUTO|ON|OFF)$")
    message(FATAL_ERROR "${opt} must be AUTO, ON or OFF (got '${${opt}}')")
  endif()
endforeach()

# The CPU backend is always built; OpenMP gives it threads.
set(MOTES_OPENMP_THREADS OFF)
if(NOT MOTES_WITH_OPENMP STREQUAL "OFF")
  find_package(OpenMP COMPONENTS CXX)
  if(OpenMP_CXX_FOUND)
    set(MOTES_OPENMP_THREADS ON)
  elseif(MOTES_WITH_OPENMP STREQUAL "ON")
    message(FATAL_ERROR "MOTES_WITH_OPENMP=ON but the compiler has no OpenMP")
  endif()
endif()

# CUDA and Vulkan backends are not part of this version yet (see docs/architecture.md); the
# registry reports them as not built. ON asks for something that does not exist: refuse clearly.
set(MOTES_CUDA_STATUS "not built (the CUDA backend is not implemented in this version)")
set(MOTES_VULKAN_STATUS "not built (the Vulkan backend is not implemented in this version)")
foreach(b CUDA VULKAN)
  if(MOTES_WITH_${b} STREQUAL "ON")
    message(FATAL_ERROR "MOTES_WITH_${b}=ON: the ${b} backend is not implemented in this version "
                        "of motes; use AUTO or OFF")
  endif()
endforeach()
