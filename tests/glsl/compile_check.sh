#!/bin/sh
# Compiles a GLSL compute shader to SPIR-V and validates it. Usage: compile_check.sh SOURCE
# INCLUDE_DIR OUT. Exit 77 (ctest: skipped) when glslangValidator or spirv-val is missing.
set -e
if ! command -v glslangValidator >/dev/null || ! command -v spirv-val >/dev/null; then
  echo "SKIPPED: glslangValidator or spirv-val not found (Debian: glslang-tools, spirv-tools)"
  exit 77
fi
glslangValidator --target-env vulkan1.2 -I"$2" -o "$3" "$1"
spirv-val --target-env vulkan1.2 "$3"
echo "shared headers compile as GLSL and validate as SPIR-V"
