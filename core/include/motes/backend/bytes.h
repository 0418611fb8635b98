// Fields of the checkpoint formats, written to and read from byte vectors in the machine's byte
// order: a single process's run record (core/src/checkpoint.cpp) and the rank files and manifest
// of checkpoint sets over MPI ranks (mpi/src/distributed_checkpoint.cpp). Internal, not
// installed (like kernel_queue.h).
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

namespace motes::detail {

/// Appends fields: plain values, length-prefixed (uint32) strings and lists.
class ByteWriter {
 public:
  template <typename T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    raw(&v, sizeof v);
  }
  void raw(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    bytes.insert(bytes.end(), c, c + n);
  }
  void str(const std::string& s) {
    put(static_cast<std::uint32_t>(s.size()));
    raw(s.data(), s.size());
  }
  template <typename T>
  void list(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    put(static_cast<std::uint32_t>(v.size()));
    raw(v.data(), v.size() * sizeof(T));
  }
  std::vector<unsigned char> bytes;
};

/// Reads them back, bounded by the bytes given: a read past the end sets `bad`, reads nothing
/// and gives zeros or empty values (a damaged file is refused, never read out of bounds).
class ByteReader {
 public:
  ByteReader(const unsigned char* p, std::size_t n) : p_(p), n_(n) {}
  template <typename T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T v{};
    raw(&v, sizeof v);
    return v;
  }
  void raw(void* out, std::size_t n) {
    if (bad || n > n_ - at_) {
      bad = true;
      return;
    }
    // `out` may be an empty vector's data(): a null pointer, which memcpy must not get.
    if (n == 0) return;
    std::memcpy(out, p_ + at_, n);
    at_ += n;
  }
  std::string str() {
    const auto n = get<std::uint32_t>();
    if (bad || n > left()) {
      bad = true;
      return {};
    }
    std::string s(reinterpret_cast<const char*>(p_ + at_), n);
    at_ += n;
    return s;
  }
  template <typename T>
  std::vector<T> list() {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto n = get<std::uint32_t>();
    if (bad || n > left() / sizeof(T)) {
      bad = true;
      return {};
    }
    std::vector<T> v(n);
    raw(v.data(), v.size() * sizeof(T));
    return v;
  }
  [[nodiscard]] std::size_t left() const { return n_ - at_; }
  [[nodiscard]] std::size_t at() const { return at_; }
  bool bad = false;

 private:
  const unsigned char* p_;
  std::size_t n_;
  std::size_t at_ = 0;
};

}  // namespace motes::detail
