#include "png_io.hpp"

#include <clothsim/output_file.hpp>

#include <stb/stb_image_write.h>

namespace clothsim::view {

std::string write_png(const std::string& path, int width, int height,
                      const std::vector<unsigned char>& rgb) {
  if (rgb.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3)
    return path + ": internal error: image buffer has the wrong size";
  // Encoded in memory, then written by the output rule (a device is written in place, a
  // regular file replaced through a temporary file, a directory refused).
  std::string png;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), static_cast<std::size_t>(size));
  };
  if (!stbi_write_png_to_func(append, &png, width, height, 3, rgb.data(), width * 3))
    return path + ": cannot encode the PNG";
  return io::write_output_file(path, png);
}

}  // namespace clothsim::view
