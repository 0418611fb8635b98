// Render options from text: picture sizes and colour modes.
#include <fmt/format.h>

#include <charconv>
#include <limits>
#include <string_view>

#include "motes/render.h"

namespace motes::render {

namespace {

constexpr int kMinSide = 16;
constexpr int kMaxSide = 16384;

/// A whole decimal number, all of `text`; one too large for an int reads as the largest int (out
/// of the side range, so that the range is what the message says).
bool parse_int(std::string_view text, int& value) {
  if (text.empty()) return false;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec == std::errc::result_out_of_range && ptr == end) {
    value = std::numeric_limits<int>::max();
    return true;
  }
  return ec == std::errc() && ptr == end;
}

}  // namespace

Result<Size> parse_size(const std::string& text) {
  const std::size_t x = text.find('x');
  Size s;
  if (x == std::string::npos || !parse_int(std::string_view(text).substr(0, x), s.width) ||
      !parse_int(std::string_view(text).substr(x + 1), s.height)) {
    return Status::error(
        fmt::format("invalid size '{}': expected WIDTHxHEIGHT in pixels, e.g. 1280x720", text));
  }
  if (s.width < kMinSide || s.height < kMinSide || s.width > kMaxSide || s.height > kMaxSide) {
    return Status::error(fmt::format("invalid size '{}': width and height must be {} to {} pixels",
                                     text, kMinSide, kMaxSide));
  }
  return s;
}

Result<ColorBy> parse_color_by(const std::string& name) {
  if (name == "body") return ColorBy::Body;
  if (name == "speed") return ColorBy::Speed;
  if (name == "kind") return ColorBy::Kind;
  if (name == "height") return ColorBy::Height;
  return Status::error(
      fmt::format("unknown colour mode '{}' (expected one of: {})", name, color_by_names()));
}

const char* color_by_names() { return "body, speed, kind, height"; }

}  // namespace motes::render
