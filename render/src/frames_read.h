// Private to motes_render: the two kinds of FrameReader (frames_read_vtu.cpp, frames_read_csv.cpp).
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "motes/render_output.h"

namespace motes::render::detail {

/// VTU frames in the given order (each with the .pvd's time when known).
Result<std::unique_ptr<FrameReader>> open_vtu_frames(std::string source,
                                                     std::vector<std::string> files);
/// The frames of a particles.csv file.
Result<std::unique_ptr<FrameReader>> open_csv_frames(const std::string& path, double radius);
/// The files a .pvd collection lists, in order, with paths relative to the .pvd's directory.
Result<std::vector<std::string>> read_pvd(const std::string& path);

/// The value of attribute `name` in the XML tag `tag` (the text from '<' to '>'), or empty.
std::string attribute(const std::string& tag, const std::string& name);
/// Half the typical (median of a sample) distance from a particle to its nearest neighbour.
float typical_radius(const std::vector<shared::vec4>& particles);

}  // namespace motes::render::detail
