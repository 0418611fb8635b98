// Checkpoints: everything that defines the future of a run, in one file that
// Simulation::save_state writes and Simulation::load_state reads (docs/reliability.md, "Checkpoint
// and resume"), and what a checkpoint says about the run it came from, readable without a
// Simulation (motes resume).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "motes/api.h"
#include "motes/output.h"
#include "motes/status.h"

MOTES_API_BEGIN
namespace motes {

/// The checkpoint format this motes writes (3: sections named by buffer_name). load_state also
/// reads version 2 (sections numbered by the Buffer enum of its day; the same bits) and version 1
/// (bodies and particles only, as `motes bench` cached them; the lists are then rebuilt, so not a
/// bitwise resume).
constexpr std::uint32_t kCheckpointVersion = 3;

/// The run a checkpoint belongs to, as the caller describes it (the motes command fills it; a
/// library user may leave it empty). Stored in the checkpoint, read back by read_checkpoint_info.
struct CheckpointRun {
  std::string scene_path;              ///< the scene file as given; empty: the built-in scene
  std::string scene_file;              ///< the same, absolute (what motes resume loads)
  std::uint64_t scene_hash = 0;        ///< scene_file_hash() of its bytes when the run started
  std::string output_dir;              ///< absolute output directory of the frames
  std::string output_format;           ///< "vtu", "csv" or "none"
  std::uint64_t every = 1;             ///< a frame every `every` steps (frame 0 at step 0)
  std::uint64_t total_steps = 0;       ///< the step at which the run was to end
  std::uint64_t checkpoint_every = 0;  ///< 0: only the last checkpoint of an interrupted run
  std::string checkpoint_dir;          ///< absolute directory of the checkpoints
  SeriesState series;                  ///< the frames written before this checkpoint
  /// Bytes the caller keeps with the state: one rank's part of a checkpoint set over MPI ranks
  /// (motes/distributed.h). Empty in a single process's checkpoint, whose run record then ends,
  /// byte for byte, where it ended before this field existed.
  std::vector<unsigned char> extension;
};

/// What a checkpoint file says, from its header and run record (read_checkpoint_info).
struct CheckpointInfo {
  std::uint32_t version = 0;
  std::uint64_t step = 0;
  double time = 0.0;
  std::uint32_t particles = 0;
  std::uint32_t bodies = 0;      ///< the scene's bodies, cloths and ropes
  std::uint64_t setup_hash = 0;  ///< Simulation's fingerprint of everything fixed at creation
  std::string backend;           ///< the backend that wrote it ("openmp", "vulkan", "cuda")
  std::uint64_t file_bytes = 0;  ///< the file's size
  std::uint64_t checksum = 0;    ///< its last 8 bytes: FNV-1a 64 of every byte before them
  CheckpointRun run;
};

/// Reads and checks a whole checkpoint file (magic, version, size, checksum) and returns its
/// header and run record. Errors name the file and the reason: not a checkpoint, another
/// version, truncated, corrupt (checksum).
Result<CheckpointInfo> read_checkpoint_info(const std::string& path);

/// A run record as a checkpoint stores it: `backend` (the backend that wrote the state), then
/// `run`. For files that describe a run beside checkpoints (the manifest of a checkpoint set over
/// MPI ranks).
std::vector<unsigned char> encode_checkpoint_run(const std::string& backend,
                                                 const CheckpointRun& run);
/// Reads what encode_checkpoint_run wrote; false unless the bytes are exactly one record.
bool decode_checkpoint_run(const unsigned char* data, std::size_t bytes, std::string& backend,
                           CheckpointRun& run);

/// FNV-1a 64 of a file's bytes (the scene hash of a checkpoint); errors name the file.
Result<std::uint64_t> scene_file_hash(const std::string& path);
/// FNV-1a 64 of some bytes (the built-in scene's text, for example).
std::uint64_t fnv1a64(const void* data, std::size_t bytes,
                      std::uint64_t seed = 14695981039346656037ull);

}  // namespace motes
MOTES_API_END
