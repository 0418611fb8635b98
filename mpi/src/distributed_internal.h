// What the source files of motes::DistributedSimulation share (not installed).
#pragma once

#include <cstdint>
#include <vector>

#include "motes/scene.h"

namespace motes::detail {

/// The scene with only `bodies` (ascending scene body indices; cloths and ropes after the
/// scene's bodies): a rank's local simulation, built at each partition and at a resume.
inline Scene sub_scene(const Scene& scene, const std::vector<std::uint32_t>& bodies) {
  Scene sub;
  sub.source = scene.source;
  sub.settings = scene.settings;
  sub.materials = scene.materials;
  sub.planes = scene.planes;
  sub.camera = scene.camera;
  const std::size_t rigid = scene.bodies.size();
  for (std::uint32_t b : bodies) {
    if (b < rigid) {
      sub.bodies.push_back(scene.bodies[b]);
    } else {
      sub.linked.push_back(scene.linked[b - rigid]);
    }
  }
  return sub;
}

}  // namespace motes::detail
