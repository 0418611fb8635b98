// The fuzz targets' entry points (docs/fuzzing.md). Each tests/fuzz/fuzz_*.cpp defines one and,
// in the fuzz build, the LLVMFuzzerTestOneInput that calls it; the unit tests compile the same
// files with MOTES_FUZZ_REPLAY and replay tests/data/fuzz-regressions/<target>/* through them
// (tests/unit/test_fuzz_regressions.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace motes::fuzz {

/// JSON scene text -> load_scene_text (settings.max_particles capped so every run is small).
int scene(const std::uint8_t* data, std::size_t size);
/// First byte (modulo 5): the file's format for load_mesh (0 obj, 1 ply, 2 stl, 3 off), or 4: a
/// mesh built from the bytes without assimp; the mesh is then voxelized (a target count of 50,
/// and a lattice of 8 cells across).
int mesh(const std::uint8_t* data, std::size_t size);
/// A checkpoint file for a small fixed scene, read by Simulation::load_state as it is and again
/// with its trailing hash made right; a state that loads is stepped once.
int checkpoint(const std::uint8_t* data, std::size_t size);
/// First byte: 0 a particles.csv, 1 a .vtu file, 2 a .pvd then, after a NUL byte, the .vtu file
/// particles_000000.vtu next to it (modulo 3); every frame is read through FrameReader.
int frames(const std::uint8_t* data, std::size_t size);

/// Checkpoint and frame seeds (valid files from a small simulation), written into `dir` (created
/// if missing).
void write_checkpoint_seeds(const std::filesystem::path& dir);
void write_frame_seeds(const std::filesystem::path& dir);

/// A broken invariant: "motes fuzz TARGET: WHAT MESSAGE" on stderr, then abort (libFuzzer keeps the
/// input; the unit tests' replay fails).
[[noreturn]] inline void broken(const char* target, const char* what,
                                const std::string& message = {}) {
  std::fprintf(stderr, "motes fuzz %s: %s %s\n", target, what, message.c_str());
  std::abort();
}

/// A directory of this process for the files the targets write (removed at exit).
inline const std::filesystem::path& work_dir() {
  struct Dir {
    std::filesystem::path path;
    Dir() {
      std::string name = (std::filesystem::temp_directory_path() / "motes-fuzz-XXXXXX").string();
      if (mkdtemp(name.data()) == nullptr) {
        std::perror("motes fuzz: mkdtemp");
        std::abort();
      }
      path = name;
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
    Dir(const Dir&) = delete;
    Dir& operator=(const Dir&) = delete;
  };
  static const Dir dir;
  return dir.path;
}

/// Writes `size` bytes to `path` (replacing it); aborts when it cannot (not the input's fault).
inline void write_file(const std::filesystem::path& path, const void* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out.flush()) {
    std::fprintf(stderr, "motes fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
}

/// In the fuzz build: when MOTES_FUZZ_WRITE_SEEDS names a directory, `write` fills it and the
/// process exits (scripts/fuzz.sh seeds the checkpoint and frame targets so).
template <typename Write>
void write_seeds_if_asked(Write write) {
  if (const char* dir = std::getenv("MOTES_FUZZ_WRITE_SEEDS"); dir != nullptr && *dir != '\0') {
    write(std::filesystem::path(dir));
    std::exit(0);
  }
}

}  // namespace motes::fuzz
