# motes_embed_text(OUTPUT_CPP SYMBOL INPUT_FILE): a .cpp defining
#   extern const char SYMBOL[]; (NUL-terminated file contents) and regenerating when INPUT changes.
function(motes_embed_text out_cpp symbol input)
  add_custom_command(
    OUTPUT ${out_cpp}
    COMMAND ${CMAKE_COMMAND} -DINPUT=${input} -DOUTPUT=${out_cpp} -DSYMBOL=${symbol}
            -P ${PROJECT_SOURCE_DIR}/cmake/MotesEmbedRun.cmake
    DEPENDS ${input} ${PROJECT_SOURCE_DIR}/cmake/MotesEmbedRun.cmake
    COMMENT "Embedding ${input}")
endfunction()
