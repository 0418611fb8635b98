// Scene JSON reading: syntax errors with line and column, duplicate keys, typed and range-checked
// getters whose errors carry the JSON pointer path.
#include "scene_json.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <vector>

#include "motes/status.h"

namespace motes::scene_detail {

namespace {

constexpr double kFloatMax = static_cast<double>(std::numeric_limits<float>::max());
constexpr double kFloatMin = static_cast<double>(std::numeric_limits<float>::min());

/// 1-based line and column (in characters, UTF-8 aware) of byte `index` of `text`.
std::string line_column(const std::string& text, std::size_t index) {
  index = std::min(index, text.size());
  std::size_t line = 1;
  std::size_t line_start = 0;
  for (std::size_t i = 0; i < index; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  std::size_t column = 1;
  for (std::size_t i = line_start; i < index; ++i) {
    // UTF-8 continuation bytes (10xxxxxx) do not start a character.
    if ((static_cast<unsigned char>(text[i]) & 0xC0u) != 0x80u) ++column;
  }
  return fmt::format("{}:{}", line, column);
}

bool is_number_char(char c) {
  return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.' || c == 'e' || c == 'E';
}

/// Start of the JSON token (string, number, literal or punctuation) that covers byte `index`:
/// nlohmann reports the last character it read, which is the end of the offending token.
std::size_t token_start(const std::string& text, std::size_t index) {
  std::size_t i = 0;
  while (i < text.size() && i <= index) {
    const char c = text[i];
    std::size_t end = i + 1;
    if (c == '"') {
      while (end < text.size() && text[end] != '"') end += text[end] == '\\' ? 2 : 1;
      end = std::min(end + 1, text.size());
    } else if (c == '-' || (c >= '0' && c <= '9')) {
      while (end < text.size() && is_number_char(text[end])) ++end;
    } else if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z')) {
      while (end < text.size() &&
             ((text[end] >= 'a' && text[end] <= 'z') || (text[end] >= 'A' && text[end] <= 'Z'))) {
        ++end;
      }
    }
    if (index < end) return i;
    i = end;
  }
  return index;
}

/// The reason of a nlohmann parse error without its "[json.exception...] parse error at line L,
/// column C: " prefix (the position is recomputed by line_column).
std::string parse_error_reason(const std::string& what) {
  std::size_t at = what.find("parse error");
  if (at == std::string::npos) return what;
  at = what.find(": ", at);
  if (at == std::string::npos) return what;
  return what.substr(at + 2);
}

/// Byte index of the number literal `token` in `text` outside strings, or npos.
std::size_t find_number_literal(const std::string& text, const std::string& token) {
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
      continue;
    }
    if (text.compare(i, token.size(), token) == 0 && (i == 0 || !is_number_char(text[i - 1])) &&
        (i + token.size() == text.size() || !is_number_char(text[i + token.size()]))) {
      return i;
    }
  }
  return std::string::npos;
}

/// Tracks where the parser is, so a duplicate key can be reported with its JSON pointer.
class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(const std::string& source) : source_(source) {}

  bool operator()(int /*depth*/, nlohmann::json::parse_event_t event, Json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    switch (event) {
      case Event::object_start:
      case Event::array_start:
        begin_element();
        frames_.push_back(Frame{event == Event::array_start, -1, {}, {}});
        break;
      case Event::object_end:
      case Event::array_end:
        if (!frames_.empty()) frames_.pop_back();
        break;
      case Event::key: {
        Frame& top = frames_.back();
        const std::string key = parsed.get<std::string>();
        if (!top.keys.insert(key).second) {
          throw Error(fmt::format("{}: {}/{}: duplicate key \"{}\"", source_, container_path(),
                                  pointer_token(key), key));
        }
        top.key = key;
        break;
      }
      case Event::value:
        begin_element();
        break;
    }
    return true;
  }

 private:
  struct Frame {
    bool array = false;
    long index = -1;
    std::string key;
    std::set<std::string> keys;
  };

  void begin_element() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }

  // Pointer of the innermost container (the top frame).
  [[nodiscard]] std::string container_path() const {
    std::string path;
    for (std::size_t i = 0; i + 1 < frames_.size(); ++i) {
      const Frame& f = frames_[i];
      path.push_back('/');
      path.append(f.array ? std::to_string(f.index) : pointer_token(f.key));
    }
    return path;
  }

  const std::string& source_;
  std::vector<Frame> frames_;
};

std::string sign_word(Sign sign) {
  switch (sign) {
    case Sign::Any:
      return "a number";
    case Sign::NonNegative:
      return "a non-negative number";
    case Sign::Positive:
      return "a positive number";
  }
  return "a number";
}

std::string range_words(std::int64_t lo, std::int64_t hi) {
  if (hi == std::numeric_limits<std::int64_t>::max()) return fmt::format("an integer >= {}", lo);
  return fmt::format("an integer from {} to {}", lo, hi);
}

}  // namespace

Json parse_scene_json(const std::string& text, const std::string& source) {
  try {
    return Json::parse(text, DuplicateKeyCheck(source));
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is the 1-based position of the last character read; report its token's start.
    const std::size_t index = token_start(text, e.byte > 0 ? e.byte - 1 : 0);
    throw Error(
        fmt::format("{}:{}: {}", source, line_column(text, index), parse_error_reason(e.what())));
  } catch (const nlohmann::json::out_of_range& e) {
    // A number beyond double range ("1e400"): nlohmann names the literal but not its position.
    const std::string what = e.what();
    const std::size_t open = what.find('\'');
    const std::size_t close = what.rfind('\'');
    if (open != std::string::npos && close > open) {
      const std::string token = what.substr(open + 1, close - open - 1);
      const std::size_t at = find_number_literal(text, token);
      if (at != std::string::npos) {
        throw Error(fmt::format("{}:{}: number {} is out of range (too large for a double)", source,
                                line_column(text, at), token));
      }
    }
    throw Error(fmt::format("{}: {}", source, what));
  } catch (const nlohmann::json::exception& e) {
    throw Error(fmt::format("{}: {}", source, e.what()));
  }
}

std::string pointer_token(std::string_view key) {
  std::string out;
  for (char c : key) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  return out;
}

std::string describe(const Json& value) {
  switch (value.type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::boolean:
      return value.get<bool>() ? "true" : "false";
    case Json::value_t::number_integer:
      return std::to_string(value.get<std::int64_t>());
    case Json::value_t::number_unsigned:
      return std::to_string(value.get<std::uint64_t>());
    case Json::value_t::number_float:
      return fmt::format("{}", value.get<double>());
    case Json::value_t::string: {
      std::string s = value.get<std::string>();
      if (s.size() > 40) s = s.substr(0, 40) + "...";
      return Json(s).dump();
    }
    case Json::value_t::object:
      return "an object";
    case Json::value_t::array:
      return value.size() == 1 ? "an array of 1 value"
                               : fmt::format("an array of {} values", value.size());
    default:
      return "an unsupported value";
  }
}

void Node::fail(std::string_view reason) const {
  throw Error(fmt::format("{}: {}: {}", *source_, path_.empty() ? "/" : path_, reason));
}

void Node::expect_object(std::initializer_list<std::string_view> allowed) const {
  if (!json_->is_object()) fail(fmt::format("must be an object, got {}", describe(*json_)));
  for (const auto& item : json_->items()) {
    const std::string& key = item.key();
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      Node(item.value(), path_ + "/" + pointer_token(key), *source_)
          .fail(fmt::format("unknown key \"{}\" (allowed: {})", key, fmt::join(allowed, ", ")));
    }
  }
}

bool Node::has(std::string_view key) const { return json_->is_object() && json_->contains(key); }

Node Node::at(std::string_view key) const {
  if (!json_->is_object()) fail(fmt::format("must be an object, got {}", describe(*json_)));
  auto it = json_->find(key);
  if (it == json_->end()) fail(fmt::format("missing required key \"{}\"", key));
  return Node(*it, path_ + "/" + pointer_token(key), *source_);
}

std::optional<Node> Node::find(std::string_view key) const {
  if (!has(key)) return std::nullopt;
  return at(key);
}

void Node::expect_array() const {
  if (!json_->is_array()) fail(fmt::format("must be an array, got {}", describe(*json_)));
}

Node Node::at(std::size_t index) const {
  return Node((*json_)[index], fmt::format("{}/{}", path_, index), *source_);
}

double Node::number(Sign sign) const {
  if (!json_->is_number())
    fail(fmt::format("must be {}, got {}", sign_word(sign), describe(*json_)));
  const double v = json_->get<double>();
  if (!std::isfinite(v)) fail(fmt::format("must be {}, got a non-finite value", sign_word(sign)));
  if (std::abs(v) > kFloatMax) {
    fail(fmt::format("out of range: {} does not fit in a 32-bit float (largest magnitude {:.8g})",
                     describe(*json_), kFloatMax));
  }
  if ((sign == Sign::Positive && !(v > 0.0)) || (sign == Sign::NonNegative && v < 0.0)) {
    fail(fmt::format("must be {}, got {}", sign_word(sign), describe(*json_)));
  }
  if (sign == Sign::Positive && v < kFloatMin) {
    fail(fmt::format("out of range: {} is too small for a 32-bit float (smallest {:.8g})",
                     describe(*json_), kFloatMin));
  }
  return v;
}

std::int64_t Node::integer(std::int64_t lo, std::int64_t hi) const {
  const auto bad = [&] {
    fail(fmt::format("must be {}, got {}", range_words(lo, hi), describe(*json_)));
  };
  if (json_->is_number_unsigned()) {
    const std::uint64_t u = json_->get<std::uint64_t>();
    if ((lo > 0 && u < static_cast<std::uint64_t>(lo)) || u > static_cast<std::uint64_t>(hi)) {
      bad();
    }
    return static_cast<std::int64_t>(u);
  }
  if (json_->is_number_integer()) {
    const std::int64_t i = json_->get<std::int64_t>();
    if (i < lo || i > hi) bad();
    return i;
  }
  if (json_->is_number_float()) {
    // 1e6 or 3.0 are integers written as floats: accept them when whole and in range.
    const double v = json_->get<double>();
    if (!std::isfinite(v) || v != std::floor(v) || v < static_cast<double>(lo) ||
        v > static_cast<double>(hi)) {
      bad();
    }
    return static_cast<std::int64_t>(v);
  }
  bad();
  return 0;  // not reached
}

bool Node::boolean() const {
  if (!json_->is_boolean()) fail(fmt::format("must be true or false, got {}", describe(*json_)));
  return json_->get<bool>();
}

std::string Node::string() const {
  if (!json_->is_string()) fail(fmt::format("must be a string, got {}", describe(*json_)));
  std::string s = json_->get<std::string>();
  if (s.empty()) fail("must not be empty");
  return s;
}

Eigen::Vector3d Node::vec3(Sign sign) const {
  if (!json_->is_array() || json_->size() != 3) {
    fail(fmt::format("must be an array of 3 numbers [x, y, z], got {}", describe(*json_)));
  }
  return {at(std::size_t{0}).number(sign), at(std::size_t{1}).number(sign),
          at(std::size_t{2}).number(sign)};
}

Eigen::Matrix<std::int64_t, 3, 1> Node::int3(std::int64_t lo, std::int64_t hi) const {
  if (!json_->is_array() || json_->size() != 3) {
    fail(fmt::format("must be an array of 3 integers, got {}", describe(*json_)));
  }
  return {at(std::size_t{0}).integer(lo, hi), at(std::size_t{1}).integer(lo, hi),
          at(std::size_t{2}).integer(lo, hi)};
}

}  // namespace motes::scene_detail
