// Embedding motes: load a scene, list the devices, pick a backend, step, print the bodies' poses.
// Usage: motes_embed SCENE.json [BACKEND (auto)] [STEPS (100)]
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "motes/devices.h"
#include "motes/simulation.h"

namespace {

int fail(const std::string& message) {
  std::fprintf(stderr, "%s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCENE.json [BACKEND] [STEPS]\n", argv[0]);
    return 2;
  }
  const std::string backend = argc > 2 ? argv[2] : "auto";
  const auto steps = static_cast<std::uint64_t>(argc > 3 ? std::strtol(argv[3], nullptr, 10) : 100);

  for (const motes::BackendReport& r : motes::list_backends()) {
    for (const motes::DeviceInfo& d : r.devices) {
      std::printf("device %s %d: %s\n", d.backend.c_str(), d.index, d.name.c_str());
    }
    if (r.devices.empty())
      std::printf("backend %s: %s\n", r.backend.c_str(), r.unavailable_reason.c_str());
  }

  motes::Result<motes::Scene> scene = motes::load_scene_file(argv[1]);
  if (!scene) return fail(scene.message());
  motes::Result<std::unique_ptr<motes::Device>> device = motes::open_device(backend);
  if (!device) return fail(device.message());
  auto sim = motes::Simulation::create(scene.value(), std::move(device).value());
  if (!sim) return fail(sim.message());
  if (motes::Status s = sim.value()->step(steps); !s) return fail(s.message());
  motes::Result<motes::Snapshot> state = sim.value()->snapshot();  // positions, poses, velocities
  if (!state) return fail(state.message());

  std::printf("%s: %llu steps on %s, t = %g s\n", argv[1], static_cast<unsigned long long>(steps),
              sim.value()->device().info().backend.c_str(), state->time);
  for (std::size_t b = 0; b < state->body_pos.size(); ++b) {
    const auto& x = state->body_pos[b];
    const auto& q = state->body_quat[b];
    std::printf("body %zu %s: position %.9g %.9g %.9g orientation %.9g %.9g %.9g %.9g\n", b,
                sim.value()->bodies()[b].name.c_str(), x.x, x.y, x.z, q.x, q.y, q.z, q.w);
  }
  return 0;
}
