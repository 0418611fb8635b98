// Scripted input for `motes view --input FILE`: timed events turned into Input, the same record
// the window fills from a person's keys and mouse.
#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <fstream>
#include <sstream>

#include "motes/viewer.h"

namespace motes::viewer {

void Input::merge(const Input& o) {
  orbit_x += o.orbit_x;
  orbit_y += o.orbit_y;
  pan_x += o.pan_x;
  pan_y += o.pan_y;
  zoom += o.zoom;
  pause = pause || o.pause;
  step = step || o.step;
  reset = reset || o.reset;
  slow_motion = slow_motion || o.slow_motion;
  screenshot = screenshot || o.screenshot;
  record = record || o.record;
  grid_wireframe = grid_wireframe || o.grid_wireframe;
  contact_wireframe = contact_wireframe || o.contact_wireframe;
  shadows = shadows || o.shadows;
  quit = quit || o.quit;
  if (o.grab_start || o.grabbing || o.grab_end) {
    cursor_x = o.cursor_x;
    cursor_y = o.cursor_y;
  }
  grab_start = grab_start || o.grab_start;
  grabbing = grabbing || o.grabbing;
  grab_end = grab_end || o.grab_end;
}

namespace {

struct BadLine : std::runtime_error {
  using std::runtime_error::runtime_error;
};

template <typename T>
T number(const std::string& word, const char* what) {
  T value{};
  const char* end = word.data() + word.size();
  auto [ptr, ec] = std::from_chars(word.data(), end, value);
  if (ec != std::errc() || ptr != end) {
    throw BadLine(fmt::format("{} '{}' is not a number", what, word));
  }
  return value;
}

/// Sets the key's flag in `in`; false for an unknown key name.
bool press_key(const std::string& key, Input& in) {
  std::string k = key;
  std::transform(k.begin(), k.end(), k.begin(), [](unsigned char c) { return std::tolower(c); });
  if (k == "space") {
    in.pause = true;
  } else if (k == "period" || k == ".") {
    in.step = true;
  } else if (k == "r") {
    in.reset = true;
  } else if (k == "s") {
    in.slow_motion = true;
  } else if (k == "p") {
    in.screenshot = true;
  } else if (k == "v") {
    in.record = true;
  } else if (k == "w") {
    in.grid_wireframe = true;
  } else if (k == "c") {
    in.contact_wireframe = true;
  } else if (k == "h") {
    in.shadows = true;
  } else if (k == "q" || k == "escape" || k == "esc") {
    in.quit = true;
  } else {
    return false;
  }
  return true;
}

}  // namespace

Script Script::load(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error(fmt::format("{}: cannot read the input script", path));
  std::stringstream text;
  text << file.rdbuf();
  return parse(text.str(), path);
}

Script Script::parse(const std::string& text, const std::string& name) {
  Script script;
  std::istringstream lines(text);
  int line_number = 0;
  for (std::string line; std::getline(lines, line);) {
    ++line_number;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream in(line);
    std::vector<std::string> w;
    for (std::string word; in >> word;) w.push_back(word);
    if (w.empty()) continue;
    try {
      if (w.size() < 2) throw BadLine("expected 'FRAME EVENT ...'");
      const auto frame = number<std::uint64_t>(w[0], "frame");
      const std::string& what = w[1];
      auto expect_words = [&](std::size_t lo, std::size_t hi, const char* form) {
        if (w.size() < lo || w.size() > hi) throw BadLine(fmt::format("expected '{}'", form));
      };
      Event e;
      e.frame = frame;
      if (what == "key") {
        expect_words(3, 3, "FRAME key NAME");
        if (!press_key(w[2], e.input)) {
          throw BadLine(fmt::format(
              "unknown key '{}' (space, period, r, s, p, v, w, c, h, q, escape)", w[2]));
        }
        script.events_.push_back(e);
      } else if (what == "quit") {
        expect_words(2, 2, "FRAME quit");
        e.input.quit = true;
        script.events_.push_back(e);
      } else if (what == "wheel") {
        expect_words(3, 3, "FRAME wheel STEPS");
        e.input.zoom = number<float>(w[2], "wheel steps");
        script.events_.push_back(e);
      } else if (what == "drag") {
        const char* form = "FRAME drag X0 Y0 X1 Y1 FRAMES [left|right|middle|shift]";
        expect_words(7, 8, form);
        const auto x0 = number<float>(w[2], "x0"), y0 = number<float>(w[3], "y0");
        const auto x1 = number<float>(w[4], "x1"), y1 = number<float>(w[5], "y1");
        const auto n = number<std::uint64_t>(w[6], "frame count");
        if (n == 0) throw BadLine("a drag lasts at least 1 frame");
        const std::string button = w.size() == 8 ? w[7] : "left";
        if (button != "left" && button != "right" && button != "middle" && button != "shift") {
          throw BadLine(fmt::format("unknown button '{}' (left, right, middle, shift)", button));
        }
        if (button == "shift") {
          Event press;
          press.frame = frame;
          press.input.grab_start = press.input.grabbing = true;
          press.input.cursor_x = x0;
          press.input.cursor_y = y0;
          script.events_.push_back(press);
        }
        // Pressed at frame, moved by equal steps over the next n frames (released at the last).
        for (std::uint64_t k = 1; k <= n; ++k) {
          const float a = static_cast<float>(k - 1) / static_cast<float>(n);
          const float b = static_cast<float>(k) / static_cast<float>(n);
          Event m;
          m.frame = frame + k;
          const float dx = (x1 - x0) * (b - a), dy = (y1 - y0) * (b - a);
          if (button == "shift") {
            m.input.grabbing = true;
            m.input.grab_end = k == n;
            m.input.cursor_x = x0 + (x1 - x0) * b;
            m.input.cursor_y = y0 + (y1 - y0) * b;
          } else if (button == "left") {
            m.input.orbit_x = dx;
            m.input.orbit_y = dy;
          } else {
            m.input.pan_x = dx;
            m.input.pan_y = dy;
          }
          script.events_.push_back(m);
        }
      } else {
        throw BadLine(fmt::format("unknown event '{}' (key, drag, wheel, quit)", what));
      }
    } catch (const BadLine& bad) {
      throw std::runtime_error(fmt::format("{}:{}: {}", name, line_number, bad.what()));
    }
  }
  std::stable_sort(script.events_.begin(), script.events_.end(),
                   [](const Event& a, const Event& b) { return a.frame < b.frame; });
  return script;
}

Input Script::at(std::uint64_t frame) const {
  Input in;
  auto it = std::lower_bound(events_.begin(), events_.end(), frame,
                             [](const Event& e, std::uint64_t f) { return e.frame < f; });
  for (; it != events_.end() && it->frame == frame; ++it) in.merge(it->input);
  return in;
}

bool Script::quits() const {
  return std::any_of(events_.begin(), events_.end(), [](const Event& e) { return e.input.quit; });
}

}  // namespace motes::viewer
