#include "png_io.hpp"

#include <stb/stb_image_write.h>

#include <cstdio>
#include <filesystem>
#include <system_error>

namespace clothsim::view {

std::string write_png(const std::string& path, int width, int height,
                      const std::vector<unsigned char>& rgb) {
  if (rgb.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3)
    return path + ": internal error: image buffer has the wrong size";
  const std::string tmp = path + ".part";
  if (!stbi_write_png(tmp.c_str(), width, height, 3, rgb.data(), width * 3)) {
    std::remove(tmp.c_str());
    return path + ": cannot write the PNG (does the directory exist and is it writable?)";
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    return path + ": cannot write the PNG: " + ec.message();
  }
  return {};
}

}  // namespace clothsim::view
