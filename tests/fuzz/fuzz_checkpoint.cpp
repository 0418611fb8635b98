// Fuzz target: checkpoint bytes -> motes::Simulation::load_state (docs/fuzzing.md).
//
// One Simulation of a small fixed scene (a repeated box, a static box, a free sphere, a rope, a
// cloth and a soft box: every kind of body a checkpoint restores) on the OpenMP backend with one
// thread. Each input is loaded as it is, and again with its checksum made right, so that mutations
// get past it and reach the payload: for versions 2 and 3 the header's file size is set to the
// input's size and the last 8 bytes to the FNV-1a 64 of every byte before them; for version 1 the
// last 8 bytes to the FNV-1a 64 of the bytes between the 48-byte header and them. A state that
// loads is stepped once and checked (check_finite, snapshot, save_state).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "fuzz_targets.h"
#include "motes/devices.h"
#include "motes/simulation.h"

namespace motes::fuzz {

namespace {

// Particle diameter 1 cm, k = 1000 N/m on 1 g particles: t_c = 2.2 ms, dt = 20 us.
constexpr const char* kScene = R"({
  "settings": {"dt": 2e-5, "particle_diameter": 0.01,
               "contact": {"stiffness": 1000, "damping": 20, "tangential": 10, "friction": 0.5}},
  "planes": [{"name": "floor", "normal": [0, 1, 0], "point": [0, 0, 0]}],
  "bodies": [
    {"name": "box", "shape": {"type": "box", "particles": [2, 2, 2]}, "position": [0, 0.03, 0],
     "rotation": {"axis": [0, 0, 1], "degrees": 20},
     "repeat": {"count": 2, "offset": [0.05, 0, 0]}},
    {"name": "wall", "kind": "static", "shape": {"type": "box", "particles": [2, 1, 2]},
     "position": [0, 0.005, 0.1]},
    {"name": "ball", "shape": {"type": "particle"}, "position": [0.2, 0.05, 0],
     "velocity": [0.1, 0, 0]},
    {"name": "rope", "kind": "rope",
     "rope": {"from": [0, 0.2, 0], "to": [0.04, 0.2, 0], "particles": 5, "pin": [0]}},
    {"name": "cloth", "kind": "cloth",
     "cloth": {"corner": [0, 0.3, 0], "edge_u": [0.02, 0, 0], "edge_v": [0, 0, 0.02],
               "particles": [3, 3], "pin": [[0, 0]]}},
    {"name": "jelly", "kind": "soft", "shape": {"type": "box", "particles": [2, 2, 3]},
     "position": [0.1, 0.1, 0], "soft": {"mode": "quadratic", "beta": 0.5, "clusters": [1, 1, 2]}}
  ]
})";

/// Size of a version 1 header: magic, version, particles, bodies, reserved, step, time, payload
/// bytes.
constexpr std::size_t kV1HeaderBytes = 48;
/// Version 2: the header's file size field.
constexpr std::size_t kFileBytesOffset = 16;

/// The simulation every input is loaded into (built once per process).
Simulation& simulation() {
  static const std::unique_ptr<Simulation> sim = [] {
    Result<Scene> scene = load_scene_text(kScene, "fuzz_checkpoint.json", "");
    if (!scene) broken("checkpoint", "the fixed scene does not load:", scene.message());
    DeviceOptions options;
    options.cpu_threads = 1;
    Result<std::unique_ptr<Device>> device = open_device("openmp", -1, options);
    if (!device) broken("checkpoint", "no OpenMP device:", device.message());
    Result<std::unique_ptr<Simulation>> made =
        Simulation::create(scene.value(), std::move(device).value());
    if (!made) broken("checkpoint", "the fixed scene does not build:", made.message());
    return std::move(made).value();
  }();
  return *sim;
}

std::uint64_t fnv1a(const std::uint8_t* data, std::size_t size) {
  std::uint64_t h = 14695981039346656037ull;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= data[i];
    h *= 1099511628211ull;
  }
  return h;
}

/// Loads `path`; a state that loads is stepped and read back.
void load(Simulation& sim, const std::filesystem::path& path) {
  const Status loaded = sim.load_state(path.string());
  if (!loaded) {
    if (loaded.message().empty()) broken("checkpoint", "an error without a message");
    return;
  }
  // A loaded state is one the simulation must be able to go on from, or refuse with a message.
  (void)sim.step(1);
  (void)sim.check_finite();
  const Result<Snapshot> snap = sim.snapshot();
  if (!snap) broken("checkpoint", "snapshot after a load failed:", snap.message());
  if (snap->particle_pos.size() != sim.particle_count()) broken("checkpoint", "snapshot size");
  if (!sim.save_state((work_dir() / "saved.ck").string()))
    broken("checkpoint", "save_state after a load");
}

}  // namespace

int checkpoint(const std::uint8_t* data, std::size_t size) {
  Simulation& sim = simulation();
  const std::filesystem::path path = work_dir() / "state.ck";
  write_file(path, data, size);
  load(sim, path);
  std::uint32_t version = 0;
  if (size >= 12) std::memcpy(&version, data + 8, sizeof version);
  if (version == 1 && size >= kV1HeaderBytes + 8) {
    std::vector<std::uint8_t> fixed(data, data + size);
    const std::uint64_t hash = fnv1a(fixed.data() + kV1HeaderBytes, size - kV1HeaderBytes - 8);
    std::memcpy(fixed.data() + size - 8, &hash, sizeof hash);
    write_file(path, fixed.data(), fixed.size());
    load(sim, path);
  } else if (version != 1 && size >= kFileBytesOffset + 16) {
    std::vector<std::uint8_t> fixed(data, data + size);
    const std::uint64_t bytes = size;
    std::memcpy(fixed.data() + kFileBytesOffset, &bytes, sizeof bytes);
    const std::uint64_t hash = fnv1a(fixed.data(), size - 8);
    std::memcpy(fixed.data() + size - 8, &hash, sizeof hash);
    write_file(path, fixed.data(), fixed.size());
    load(sim, path);
  }
  return 0;
}

void write_checkpoint_seeds(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  Simulation& sim = simulation();
  for (int i = 0; i < 3; ++i) {
    const std::string path = (dir / ("state_" + std::to_string(i) + ".ck")).string();
    if (const Status s = sim.save_state(path); !s)
      broken("checkpoint", "cannot write a seed:", s.message());
    if (const Status s = sim.step(100); !s) broken("checkpoint", "cannot step:", s.message());
  }
  // A version 1 file (the format motes bench's caches may still hold): the snapshot's body and
  // particle arrays after a 48-byte header, then the FNV-1a 64 of those arrays.
  const Result<Snapshot> snap = sim.snapshot();
  if (!snap) broken("checkpoint", "snapshot for a seed:", snap.message());
  std::vector<std::uint8_t> payload;
  for (const std::vector<shared::vec4>* v :
       {&snap->body_pos, &snap->body_quat, &snap->body_vel, &snap->body_angmom, &snap->body_angvel,
        &snap->particle_pos, &snap->particle_vel}) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(v->data());
    payload.insert(payload.end(), p, p + v->size() * sizeof(shared::vec4));
  }
  std::vector<std::uint8_t> file(kV1HeaderBytes, 0);
  const char magic[8] = {'M', 'O', 'T', 'E', 'S', 'C', 'K', '1'};
  const std::uint32_t words[4] = {1, sim.particle_count(), sim.body_count(), 0};
  const std::uint64_t step = sim.steps();
  const double time = sim.time();
  const std::uint64_t payload_bytes = payload.size();
  std::memcpy(file.data(), magic, 8);
  std::memcpy(file.data() + 8, words, 16);
  std::memcpy(file.data() + 24, &step, 8);
  std::memcpy(file.data() + 32, &time, 8);
  std::memcpy(file.data() + 40, &payload_bytes, 8);
  file.insert(file.end(), payload.begin(), payload.end());
  const std::uint64_t hash = fnv1a(payload.data(), payload.size());
  const auto* h = reinterpret_cast<const std::uint8_t*>(&hash);
  file.insert(file.end(), h, h + 8);
  write_file(dir / "state_v1.ck", file.data(), file.size());
}

}  // namespace motes::fuzz

#ifndef MOTES_FUZZ_REPLAY
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  motes::fuzz::write_seeds_if_asked(motes::fuzz::write_checkpoint_seeds);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return motes::fuzz::checkpoint(data, size);
}
#endif
