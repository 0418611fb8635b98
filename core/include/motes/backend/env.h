// A whole number from the environment, for the variables that set a size or limit of the core or
// a backend (docs/cli.md's environment table): unset or empty is no value; anything but digits
// (a sign, a space, a suffix) or a number beyond 64 bits is refused, naming the variable and the
// value. Internal, not installed (like bytes.h).
#pragma once

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>

#include "motes/status.h"

namespace motes {

/// The value of environment variable `name`; nullopt when it is unset or empty. Not a whole
/// number: the error "NAME: 'VALUE' is not `what`".
inline Result<std::optional<std::uint64_t>> env_whole_number(const char* name,
                                                             const std::string& what) {
  const char* value = std::getenv(name);
  if (value == nullptr || *value == '\0') return std::optional<std::uint64_t>{};
  char* end = nullptr;
  errno = 0;
  const unsigned long long n = std::strtoull(value, &end, 10);
  if (*value < '0' || *value > '9' || end == nullptr || *end != '\0' || errno == ERANGE) {
    return Status::error(std::string(name) + ": '" + value + "' is not " + what);
  }
  return std::optional<std::uint64_t>{static_cast<std::uint64_t>(n)};
}

}  // namespace motes
