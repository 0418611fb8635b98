// The sanitizer stage (scripts/test.sh) runs every test again, built with AddressSanitizer and
// UndefinedBehaviorSanitizer: it looks for memory errors and undefined behaviour along the code
// paths, which a run's first steps already take. tests/CMakeLists.txt defines
// MOTES_TEST_SANITIZED in every test executable of that build; the long tests run a shorter while
// there (fewer seeds, steps or frames) and check their physics over the whole run in the first
// stage only.
#pragma once

namespace motes_test {

#ifdef MOTES_TEST_SANITIZED
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

/// `all`, or in the sanitizer build `sanitized` (when it is less).
template <class T>
constexpr T sanitized_or(T all, T sanitized) {
  return kSanitized && sanitized < all ? sanitized : all;
}

}  // namespace motes_test
