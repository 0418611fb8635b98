// PNG files through stb_image_write (Debian: libstb-dev).
#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "motes/render.h"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#include <stb_image_write.h>

namespace motes::render {

namespace {

/// stb calls this with pieces of the encoded file.
void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<unsigned char>*>(context);
  const auto* bytes = static_cast<const unsigned char*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

}  // namespace

Status write_png(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() !=
          3 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height)) {
    return Status::error(fmt::format("cannot write '{}': the image is {}x{} with {} bytes", path,
                                     image.width, image.height, image.rgb.size()));
  }
  // stb deflates with level 8 by default; 5 is about twice as fast for a few per cent more bytes.
  stbi_write_png_compression_level = 5;
  std::vector<unsigned char> png;
  if (stbi_write_png_to_func(append_bytes, &png, image.width, image.height, 3, image.rgb.data(),
                             3 * image.width) == 0) {
    return Status::error(fmt::format("cannot write '{}': PNG encoding failed", path));
  }
  errno = 0;
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) {
    return Status::error(fmt::format("cannot create '{}': {}", path, std::strerror(errno)));
  }
  const bool written = std::fwrite(png.data(), 1, png.size(), file) == png.size();
  const int write_error = errno;
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed) {
    return Status::error(
        fmt::format("cannot write '{}': {}", path, std::strerror(written ? errno : write_error)));
  }
  return Status::ok();
}

}  // namespace motes::render
