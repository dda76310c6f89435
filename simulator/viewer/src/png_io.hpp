// PNG output through stb_image_write (Debian's libstb).
#pragma once

#include <string>
#include <vector>

namespace clothsim::view {

/// Writes 8-bit RGB rows (top row first) to `path` by the output rule of
/// clothsim/output_file.hpp (a regular file through a temporary file and a rename, so a failure
/// leaves nothing half-written; a device in place; a directory refused). Returns an empty
/// string or a one-line error naming the file.
std::string write_png(const std::string& path, int width, int height,
                      const std::vector<unsigned char>& rgb);

}  // namespace clothsim::view
