// Fuzz target: the frame readers of `motes render` (render/src/frames_read*.cpp) through
// motes::render::FrameReader (docs/fuzzing.md). The first byte picks what the rest is (modulo 3):
// 0 a particles.csv, 1 a .vtu file, 2 a .pvd collection then, after the first NUL byte, the file
// particles_000000.vtu beside it. Every frame is read (at most 64), then the first one again
// after rewind().
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz_targets.h"
#include "motes/devices.h"
#include "motes/output.h"
#include "motes/render_output.h"
#include "motes/simulation.h"

namespace motes::fuzz {

namespace {

namespace fs = std::filesystem;

/// Reads one frame; false at the end or on an error (which must say why).
bool read_frame(render::FrameReader& reader) {
  Snapshot frame;
  const Result<bool> got = reader.next(frame);
  if (!got) {
    if (got.message().empty()) broken("frames", "an error without a message");
    return false;
  }
  if (!got.value()) return false;
  const std::size_t n = frame.particle_pos.size();
  if (frame.particle_vel.size() != n || frame.particle_body.size() != n) {
    broken("frames", "a frame whose arrays differ in length");
  }
  return true;
}

}  // namespace

int frames(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const fs::path dir = [] {
    fs::create_directories(work_dir() / "frames");
    return work_dir() / "frames";
  }();
  const std::uint8_t* rest = data + 1;
  const std::size_t rest_size = size - 1;
  fs::path path;
  switch (data[0] % 3) {
    case 0:
      path = dir / "particles.csv";
      write_file(path, rest, rest_size);
      break;
    case 1:
      path = dir / "frame.vtu";
      write_file(path, rest, rest_size);
      break;
    default: {
      const std::uint8_t* nul = std::find(rest, rest + rest_size, std::uint8_t{0});
      const auto pvd_size = static_cast<std::size_t>(nul - rest);
      path = dir / "particles.pvd";
      write_file(path, rest, pvd_size);
      const std::size_t vtu_at = std::min(pvd_size + 1, rest_size);
      write_file(dir / "particles_000000.vtu", rest + vtu_at, rest_size - vtu_at);
      break;
    }
  }
  Result<std::unique_ptr<render::FrameReader>> opened = render::FrameReader::open(path.string());
  if (!opened) {
    if (opened.message().empty()) broken("frames", "an error without a message");
    return 0;
  }
  render::FrameReader& reader = *opened.value();
  for (int i = 0; i < 64 && read_frame(reader); ++i) {
  }
  if (const Status s = reader.rewind(); !s) {
    if (s.message().empty()) broken("frames", "an error without a message");
    return 0;
  }
  (void)read_frame(reader);
  return 0;
}

void write_frame_seeds(const fs::path& dir) {
  fs::create_directories(dir);
  // Two boxes of 2 x 2 x 2 particles falling onto a rope: 20 particles, 3 frames.
  constexpr const char* kFramesScene = R"({
    "settings": {"dt": 2e-5, "contact": {"stiffness": 1000, "damping": 20}},
    "planes": [{"normal": [0, 1, 0]}],
    "bodies": [
      {"name": "box", "shape": {"type": "box", "particles": [2, 2, 2]}, "position": [0, 0.05, 0],
       "repeat": {"count": 2, "offset": [0.05, 0, 0]}},
      {"name": "rope", "kind": "rope", "rope": {"from": [0, 0.02, 0], "to": [0.03, 0.02, 0],
       "particles": 4}}
    ]
  })";
  Result<Scene> scene = load_scene_text(kFramesScene, "fuzz_frames.json", "");
  if (!scene) broken("frames", "the seed scene does not load:", scene.message());
  DeviceOptions options;
  options.cpu_threads = 1;
  Result<std::unique_ptr<Device>> device = open_device("openmp", -1, options);
  if (!device) broken("frames", "no OpenMP device:", device.message());
  Result<std::unique_ptr<Simulation>> sim =
      Simulation::create(scene.value(), std::move(device).value());
  if (!sim) broken("frames", "the seed scene does not build:", sim.message());
  const fs::path out = dir / "run";
  Result<std::unique_ptr<FrameWriter>> vtu = open_vtu_writer((out / "vtu").string());
  Result<std::unique_ptr<FrameWriter>> csv = open_csv_writer((out / "csv").string());
  if (!vtu || !csv) broken("frames", "cannot open the writers");
  for (int frame = 0; frame < 3; ++frame) {
    Result<Snapshot> snap = sim.value()->snapshot();
    if (!snap || !vtu.value()->write_frame(snap.value()) ||
        !csv.value()->write_frame(snap.value()) || !sim.value()->step(200)) {
      broken("frames", "cannot write a frame");
    }
  }
  if (!vtu.value()->finish() || !csv.value()->finish())
    broken("frames", "cannot finish the writers");
  const auto bytes = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  };
  const auto seed = [&](const std::string& name, char kind, const std::string& text) {
    const std::string content = kind + text;
    write_file(dir / name, content.data(), content.size());
  };
  seed("particles.csv", '\0', bytes(out / "csv/particles.csv"));
  seed("particles_000000.vtu", '\1', bytes(out / "vtu/particles_000000.vtu"));
  seed("particles_000002.vtu", '\1', bytes(out / "vtu/particles_000002.vtu"));
  seed("bodies_000001.vtu", '\1', bytes(out / "vtu/bodies_000001.vtu"));
  seed("particles.pvd", '\2',
       bytes(out / "vtu/particles.pvd") + '\0' + bytes(out / "vtu/particles_000001.vtu"));
  fs::remove_all(out);
}

}  // namespace motes::fuzz

#ifndef MOTES_FUZZ_REPLAY
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  motes::fuzz::write_seeds_if_asked(motes::fuzz::write_frame_seeds);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return motes::fuzz::frames(data, size);
}
#endif
