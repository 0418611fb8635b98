// Checkpoints: the dynamic state of a Simulation in one binary file.
// Layout: header {magic "MOTESCK1", version, particles, bodies, step, time, payload bytes}, then
// the body positions, orientations, velocities, angular momenta and angular velocities (B vec4
// each, the scene's bodies in the scene's order, as in a Snapshot), the particle positions and
// velocities (N vec4 each, the scene's order), then an FNV-1a 64 hash of the payload.
#include <fmt/format.h>

#include <array>
#include <cstring>
#include <fstream>
#include <vector>

#include "motes/simulation.h"

namespace motes {

namespace {

constexpr std::array<char, 8> kMagic = {'M', 'O', 'T', 'E', 'S', 'C', 'K', '1'};
constexpr std::uint32_t kVersion = 1;

struct Header {
  std::array<char, 8> magic;
  std::uint32_t version;
  std::uint32_t particles;
  std::uint32_t bodies;
  std::uint32_t reserved;
  std::uint64_t step;
  double time;
  std::uint64_t payload_bytes;
};

/// The snapshot's arrays in the order the payload stores them.
std::array<std::vector<shared::vec4>*, 7> payload_arrays(Snapshot& s) {
  return {&s.body_pos,    &s.body_quat,    &s.body_vel,    &s.body_angmom,
          &s.body_angvel, &s.particle_pos, &s.particle_vel};
}

std::uint64_t hash_bytes(const std::vector<unsigned char>& v) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : v) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace

Status Simulation::save_state(const std::string& path) {
  Result<Snapshot> snap = snapshot();
  if (!snap) return snap.status();
  const std::size_t b_bytes = bodies_.size() * 16;
  const std::size_t p_bytes = std::size_t{sizes_.particles} * 16;
  std::vector<unsigned char> payload(5 * b_bytes + 2 * p_bytes);
  std::size_t at = 0;
  for (const std::vector<shared::vec4>* v : payload_arrays(snap.value())) {
    std::memcpy(payload.data() + at, v->data(), v->size() * 16);
    at += v->size() * 16;
  }
  Header h{};
  h.magic = kMagic;
  h.version = kVersion;
  h.particles = sizes_.particles;
  h.bodies = static_cast<std::uint32_t>(bodies_.size());
  h.step = steps_;
  h.time = time_;
  h.payload_bytes = payload.size();
  const std::uint64_t hash = hash_bytes(payload);
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return Status::error(fmt::format("{}: cannot create checkpoint", path));
    out.write(reinterpret_cast<const char*>(&h), sizeof h);
    out.write(reinterpret_cast<const char*>(payload.data()),
              static_cast<std::streamsize>(payload.size()));
    out.write(reinterpret_cast<const char*>(&hash), sizeof hash);
    if (!out.flush()) return Status::error(fmt::format("{}: write failed", tmp));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    return Status::error(fmt::format("{}: cannot rename from {}", path, tmp));
  }
  return Status::ok();
}

Status Simulation::load_state(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::error(fmt::format("{}: cannot open checkpoint", path));
  Header h{};
  if (!in.read(reinterpret_cast<char*>(&h), sizeof h) || h.magic != kMagic) {
    return Status::error(fmt::format("{}: not a motes checkpoint", path));
  }
  if (h.version != kVersion) {
    return Status::error(
        fmt::format("{}: checkpoint version {} (this motes reads {})", path, h.version, kVersion));
  }
  if (h.particles != sizes_.particles || h.bodies != bodies_.size()) {
    return Status::error(fmt::format(
        "{}: checkpoint of {} particles and {} bodies does not fit this scene ({} and {})", path,
        h.particles, h.bodies, sizes_.particles, bodies_.size()));
  }
  const std::size_t b_bytes = bodies_.size() * 16;
  const std::size_t p_bytes = std::size_t{sizes_.particles} * 16;
  if (h.payload_bytes != 5 * b_bytes + 2 * p_bytes) {
    return Status::error(fmt::format("{}: corrupt checkpoint (payload size)", path));
  }
  std::vector<unsigned char> payload(h.payload_bytes);
  std::uint64_t hash = 0;
  if (!in.read(reinterpret_cast<char*>(payload.data()),
               static_cast<std::streamsize>(payload.size())) ||
      !in.read(reinterpret_cast<char*>(&hash), sizeof hash)) {
    return Status::error(fmt::format("{}: truncated checkpoint", path));
  }
  if (hash != hash_bytes(payload)) {
    return Status::error(fmt::format("{}: corrupt checkpoint (hash mismatch)", path));
  }
  Snapshot state;
  std::size_t at = 0;
  for (std::vector<shared::vec4>* v : payload_arrays(state)) {
    const std::size_t bytes =
        v == &state.particle_pos || v == &state.particle_vel ? p_bytes : b_bytes;
    v->resize(bytes / 16);
    std::memcpy(v->data(), payload.data() + at, bytes);
    at += bytes;
  }
  if (Status s = restore(state); !s) return s;
  steps_ = h.step;
  time_ = h.time;
  return Status::ok();
}

}  // namespace motes
