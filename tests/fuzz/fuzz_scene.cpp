// Fuzz target: JSON scene text -> motes::load_scene_text (docs/fuzzing.md).
//
// A scene that parses is loaded with settings.max_particles capped at kCap (an entry point that
// honours a 1e8-particle scene would spend gigabytes and minutes on one input): the cap is
// written into the document, which is then dumped again. Text that does not parse, or that has a
// duplicate key, is loaded as it is (the loader refuses it before building anything). Relative
// mesh paths resolve in a directory holding the meshes the repository's scenes name.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "fuzz_targets.h"
#include "motes/scene.h"

namespace motes::fuzz {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

constexpr int kCap = 5000;

/// work_dir()/scenes, with cube.obj, open_box.obj and garbage.obj in it and beside it and
/// assets/bunny.obj and assets/tablecloth.obj beside it: every mesh path of examples/scenes and
/// tests/data/scenes resolves.
const std::string& base_dir() {
  static const std::string dir = [] {
    const fs::path work = work_dir();
    const fs::path source = MOTES_SOURCE_DIR;
    const fs::path scenes = source / "tests/data/scenes";
    fs::create_directories(work / "scenes");
    fs::create_directories(work / "assets");
    for (const fs::path& to : {work / "scenes", work}) {
      for (const fs::path& from :
           {scenes / "cube.obj", scenes / "open_box.obj", scenes / "bad/garbage.obj"}) {
        fs::copy_file(from, to / from.filename(), fs::copy_options::overwrite_existing);
      }
    }
    for (const char* asset : {"bunny.obj", "tablecloth.obj"}) {
      fs::copy_file(source / "examples/assets" / asset, work / "assets" / asset,
                    fs::copy_options::overwrite_existing);
    }
    return (work / "scenes").string();
  }();
  return dir;
}

/// The text to load: `text` with settings.max_particles at most kCap, when it parses.
std::string capped(const std::string& text) {
  bool duplicate = false;
  std::vector<std::set<std::string>> keys;
  const Json::parser_callback_t check = [&](int /*depth*/, Json::parse_event_t event,
                                            Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
      case Json::parse_event_t::array_start:
        keys.emplace_back();
        break;
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        if (!keys.empty()) keys.pop_back();
        break;
      case Json::parse_event_t::key:
        if (!keys.empty() && !keys.back().insert(parsed.get<std::string>()).second) {
          duplicate = true;
        }
        break;
      case Json::parse_event_t::value:
        break;
    }
    return true;
  };
  Json doc = Json::parse(text, check, /*allow_exceptions=*/false);
  if (doc.is_discarded() || duplicate || !doc.is_object()) return text;
  const auto settings = doc.find("settings");
  if (settings == doc.end()) {
    doc["settings"] = Json::object({{"max_particles", kCap}});
  } else if (settings->is_object()) {
    const auto max = settings->find("max_particles");
    if (max == settings->end() || (max->is_number() && !(max->get<double>() <= kCap))) {
      (*settings)["max_particles"] = kCap;
    }
  }
  return doc.dump(-1, ' ', false, Json::error_handler_t::replace);
}

/// What Simulation::create relies on in a scene that loaded.
void check_invariants(const Scene& scene) {
  const auto finite = [](const Eigen::Vector3d& v) { return v.allFinite(); };
  if (scene.materials.empty()) broken("scene: a loaded scene breaks an invariant:", "no materials");
  const auto material_ok = [&](int m) {
    return m >= 0 && static_cast<std::size_t>(m) < scene.materials.size();
  };
  if (scene.bodies.empty() && scene.linked.empty())
    broken("scene: a loaded scene breaks an invariant:", "no bodies");
  if (scene.particle_count() > static_cast<std::size_t>(kCap))
    broken("scene: a loaded scene breaks an invariant:", "more than max_particles");
  for (const BodySpec& b : scene.bodies) {
    if (!b.shape || b.shape->points.empty())
      broken("scene: a loaded scene breaks an invariant:", "a body without particles");
    if (!(b.shape->diameter > 0.0))
      broken("scene: a loaded scene breaks an invariant:",
             "a body's particle diameter is not positive");
    if (!material_ok(b.material))
      broken("scene: a loaded scene breaks an invariant:", "a body's material index");
    if (!finite(b.position) || !finite(b.velocity) || !finite(b.angular_velocity)) {
      broken("scene: a loaded scene breaks an invariant:",
             "a body's position or velocity is not finite");
    }
    if (!(std::abs(b.rotation.norm() - 1.0) < 1e-6))
      broken("scene: a loaded scene breaks an invariant:", "a body's rotation is not a unit");
    for (const Eigen::Vector3f& p : b.shape->points) {
      if (!p.allFinite())
        broken("scene: a loaded scene breaks an invariant:", "a shape point is not finite");
    }
  }
  for (const LinkedSpec& l : scene.linked) {
    if (l.points.empty() || !(l.diameter > 0.0))
      broken("scene: a loaded scene breaks an invariant:", "an empty cloth or rope");
    if (!material_ok(l.material))
      broken("scene: a loaded scene breaks an invariant:", "a cloth's or rope's material index");
    for (const LinkSpec& link : l.links) {
      if (link.a >= l.points.size() || link.b >= l.points.size())
        broken("scene: a loaded scene breaks an invariant:", "a link's index");
    }
    for (std::uint32_t pin : l.pinned) {
      if (pin >= l.points.size())
        broken("scene: a loaded scene breaks an invariant:", "a pin's index");
    }
    for (const LinkAttachment& a : l.attached) {
      if (a.point >= l.points.size())
        broken("scene: a loaded scene breaks an invariant:", "an attachment's index");
    }
    for (const Eigen::Vector3d& x : l.points) {
      if (!x.allFinite())
        broken("scene: a loaded scene breaks an invariant:", "a cloth or rope point is not finite");
    }
    // A lattice place per point, or none at all for a cloth made from a mesh.
    if (l.lattice.empty() ? l.kind != LinkedKind::Cloth : l.lattice.size() != l.points.size()) {
      broken("scene: a loaded scene breaks an invariant:", "a cloth's or rope's lattice");
    }
  }
  for (const PlaneSpec& p : scene.planes) {
    if (!material_ok(p.material))
      broken("scene: a loaded scene breaks an invariant:", "a plane's material index");
    if (!(std::abs(p.normal.norm() - 1.0) < 1e-9) || !finite(p.point))
      broken("scene: a loaded scene breaks an invariant:", "a plane");
  }
  if (!(scene.settings.dt > 0.0) || scene.settings.substeps < 1)
    broken("scene: a loaded scene breaks an invariant:", "dt or substeps");
}

}  // namespace

int scene(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const Result<Scene> loaded = load_scene_text(capped(text), "fuzz.json", base_dir());
  if (loaded) {
    check_invariants(loaded.value());
  } else if (loaded.message().empty()) {
    broken("scene: a loaded scene breaks an invariant:", "an error without a message");
  }
  return 0;
}

}  // namespace motes::fuzz

#ifndef MOTES_FUZZ_REPLAY
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return motes::fuzz::scene(data, size);
}
#endif
