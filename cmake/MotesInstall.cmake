# `cmake --install BUILD --prefix P`: the motes command, libmotes and libmotes_render (static or
# shared, BUILD_SHARED_LIBS), the public headers only (docs/api.md), the CMake package
# (find_package(motes 0.2) -> motes::motes, motes::render) and motes.pc for pkg-config.
include(CMakePackageConfigHelpers)

set(MOTES_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/motes)

install(TARGETS motes motes_render EXPORT motesTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS motes_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# The public API: the headers of core/include/motes (not the backends' internal
# kernel_queue.h), render's, and the physics headers they include (shared/*.h, found through
# include/motes on the include path).
install(FILES
        core/include/motes/api.h core/include/motes/checkpoint.h core/include/motes/cloth.h
        core/include/motes/decomposition.h core/include/motes/devices.h core/include/motes/energy.h
        core/include/motes/fluid.h
        core/include/motes/output.h
        core/include/motes/scene.h core/include/motes/shapes.h core/include/motes/simulation.h
        core/include/motes/status.h core/include/motes/workloads.h
        render/include/motes/render.h render/include/motes/render_output.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/motes)
if(MOTES_VULKAN)
  install(FILES backends/vulkan/include/motes/vulkan_interop.h
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/motes)
endif()
if(MOTES_CUDA)
  install(FILES backends/cuda/include/motes/cuda_interop.h
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/motes)
endif()
install(FILES core/include/motes/backend/device.h core/include/motes/backend/kernels.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/motes/backend)
file(GLOB MOTES_SHARED_HEADERS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/shaders/shared/*.h)
install(FILES ${MOTES_SHARED_HEADERS} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/motes/shared)

install(EXPORT motesTargets NAMESPACE motes:: DESTINATION ${MOTES_CMAKE_DIR})
set(MOTES_PACKAGE_STATIC OFF)
if(NOT BUILD_SHARED_LIBS)
  set(MOTES_PACKAGE_STATIC ON)
endif()
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/motesConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/motesConfig.cmake
                              INSTALL_DESTINATION ${MOTES_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/motesConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/motesConfig.cmake ${PROJECT_BINARY_DIR}/motesConfigVersion.cmake
        DESTINATION ${MOTES_CMAKE_DIR})

# pkg-config: the flags of a shared libmotes, and what a static one needs besides (Libs.private).
set(MOTES_PC_PRIVATE "-lassimp -lfmt")
if(MOTES_OPENMP_THREADS)
  string(APPEND MOTES_PC_PRIVATE " -fopenmp")
endif()
if(MOTES_VULKAN)
  string(APPEND MOTES_PC_PRIVATE " -ldl")
endif()
if(MOTES_CUDA)
  string(APPEND MOTES_PC_PRIVATE " -L${CUDAToolkit_LIBRARY_DIR} -lcudart_static -lrt -lpthread -ldl")
endif()
# The prefix is found from where the .pc file lies (${pcfiledir}/.., once per level of
# LIBDIR/pkgconfig), so that an install to any --prefix works without reconfiguring.
file(RELATIVE_PATH MOTES_PC_TO_PREFIX "/p/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/p")
string(REGEX REPLACE "/$" "" MOTES_PC_TO_PREFIX "${MOTES_PC_TO_PREFIX}")
configure_file(${PROJECT_SOURCE_DIR}/cmake/motes.pc.in ${PROJECT_BINARY_DIR}/motes.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/motes.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
