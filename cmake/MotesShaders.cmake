# motes_add_shaders(TARGET OUT_CPP SHADER...): compiles each GLSL compute shader to SPIR-V with
# glslangValidator (--target-env vulkan1.2, one command per shader, a depfile for its #includes),
# validates it with spirv-val, and embeds them all in OUT_CPP as a table looked up by name
# (backends/vulkan/vulkan_shaders.h). No SPIR-V is committed.
function(motes_add_shaders out_cpp)
  set(spv_files "")
  set(spv_dir ${CMAKE_CURRENT_BINARY_DIR}/spirv)
  file(MAKE_DIRECTORY ${spv_dir})
  foreach(src ${ARGN})
    get_filename_component(name ${src} NAME_WE)
    set(spv ${spv_dir}/${name}.spv)
    add_custom_command(
      OUTPUT ${spv}
      COMMAND ${MOTES_GLSLANG} --target-env vulkan1.2 --quiet -I${PROJECT_SOURCE_DIR}/shaders
              --depfile ${spv}.d -o ${spv} ${src}
      COMMAND ${MOTES_SPIRV_VAL} --target-env vulkan1.2 ${spv}
      DEPENDS ${src}
      DEPFILE ${spv}.d
      COMMENT "Compiling shader ${name}.comp to SPIR-V"
      VERBATIM)
    list(APPEND spv_files ${spv})
  endforeach()
  add_custom_command(
    OUTPUT ${out_cpp}
    COMMAND ${CMAKE_COMMAND} "-DINPUTS=${spv_files}" -DOUTPUT=${out_cpp}
            -P ${PROJECT_SOURCE_DIR}/cmake/MotesShadersEmbed.cmake
    DEPENDS ${spv_files} ${PROJECT_SOURCE_DIR}/cmake/MotesShadersEmbed.cmake
    COMMENT "Embedding the SPIR-V shaders"
    VERBATIM)
endfunction()
