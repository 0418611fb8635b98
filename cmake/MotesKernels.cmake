# The kernel families, read from the one list of them (core/include/motes/backend/kernels.h), and
# each backend's source files from their names: backends/BACKEND/NAME.EXT for every family.
set(MOTES_KERNELS_HEADER ${PROJECT_SOURCE_DIR}/core/include/motes/backend/kernels.h)
set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
                                                       ${MOTES_KERNELS_HEADER})
# (Read whole: the list's lines end in backslashes, which file(STRINGS) would join.)
file(READ ${MOTES_KERNELS_HEADER} _motes_kernels_text)
string(REGEX MATCHALL "\n *X\\([A-Za-z]+, [a-z_]+," _motes_kernel_entries "${_motes_kernels_text}")
set(MOTES_KERNEL_FAMILIES)
foreach(_entry IN LISTS _motes_kernel_entries)
  string(REGEX REPLACE "^\n *X\\([A-Za-z]+, ([a-z_]+),$" "\\1" _name "${_entry}")
  list(APPEND MOTES_KERNEL_FAMILIES ${_name})
endforeach()
if(NOT MOTES_KERNEL_FAMILIES)
  message(FATAL_ERROR "${MOTES_KERNELS_HEADER}: no kernel family found in MOTES_KERNELS")
endif()

# motes_family_sources(<var> <extension> [<directory>]): the file of every family
# (<directory>/NAME<extension>, the current source directory by default), each required to exist.
function(motes_family_sources out extension)
  set(dir ${CMAKE_CURRENT_SOURCE_DIR})
  if(ARGC GREATER 2)
    set(dir ${ARGV2})
  endif()
  set(files)
  foreach(name IN LISTS MOTES_KERNEL_FAMILIES)
    set(file ${dir}/${name}${extension})
    if(NOT EXISTS ${file})
      message(FATAL_ERROR "kernel family ${name} (${MOTES_KERNELS_HEADER}) has no ${file}")
    endif()
    list(APPEND files ${file})
  endforeach()
  set(${out} ${files} PARENT_SCOPE)
endfunction()
