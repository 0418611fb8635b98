// Reading a scene's JSON with every error naming the file, the JSON pointer path and the reason.
// Private to the scene loader (scene_load.cpp, scene_shape.cpp).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

namespace motes::scene_detail {

// Insertion-ordered, so "unknown key" reports the first one in the file and materials keep the
// file's order.
using Json = nlohmann::ordered_json;

/// Parses scene text; a syntax error or a duplicate key throws Error "SOURCE:LINE:COLUMN: reason"
/// (or "SOURCE: /path: duplicate key" where the parser gives no position).
Json parse_scene_json(const std::string& text, const std::string& source);

/// What a number may be, beyond finite and within float range.
enum class Sign { Any, NonNegative, Positive };

/// One value of the document and its JSON pointer. Getters check the type and range and throw
/// Error "SOURCE: /json/pointer: reason" on anything wrong.
class Node {
 public:
  Node(const Json& json, std::string path, const std::string& source)
      : json_(&json), path_(std::move(path)), source_(&source) {}

  [[nodiscard]] const Json& json() const { return *json_; }
  /// JSON pointer of this value ("" for the whole document, shown as "/").
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] const std::string& source() const { return *source_; }

  /// Throws Error "SOURCE: PATH: reason".
  [[noreturn]] void fail(std::string_view reason) const;

  /// Checks this is an object whose keys are all in `allowed`; otherwise names the first unknown
  /// key and lists the allowed ones.
  void expect_object(std::initializer_list<std::string_view> allowed) const;
  [[nodiscard]] bool has(std::string_view key) const;
  /// The member `key` (an object is expected); fails naming the missing key.
  [[nodiscard]] Node at(std::string_view key) const;
  [[nodiscard]] std::optional<Node> find(std::string_view key) const;
  /// Array elements (expect_array first).
  void expect_array() const;
  [[nodiscard]] std::size_t size() const { return json_->size(); }
  [[nodiscard]] Node at(std::size_t index) const;

  /// A finite number within float range (|x| <= 3.4e38; positive values >= 1.2e-38).
  [[nodiscard]] double number(Sign sign = Sign::Any) const;
  /// An integer (written with or without a fraction of zero) in [lo, hi].
  [[nodiscard]] std::int64_t integer(std::int64_t lo, std::int64_t hi) const;
  [[nodiscard]] bool boolean() const;
  /// A non-empty string.
  [[nodiscard]] std::string string() const;
  /// An array of exactly three numbers.
  [[nodiscard]] Eigen::Vector3d vec3(Sign sign = Sign::Any) const;
  /// An array of exactly three integers in [lo, hi].
  [[nodiscard]] Eigen::Matrix<std::int64_t, 3, 1> int3(std::int64_t lo, std::int64_t hi) const;

 private:
  const Json* json_;
  std::string path_;
  const std::string* source_;
};

/// Short description of a value for messages: a number as written, a quoted string (cut after
/// 40 characters), "an object", "an array", "true", "null"...
std::string describe(const Json& value);
/// Escapes a key for a JSON pointer (RFC 6901: "~" -> "~0", "/" -> "~1").
std::string pointer_token(std::string_view key);

}  // namespace motes::scene_detail
