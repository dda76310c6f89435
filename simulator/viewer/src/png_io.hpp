// PNG output through stb_image_write (Debian's libstb).
#pragma once

#include <string>
#include <vector>

namespace clothsim::view {

/// Writes 8-bit RGB rows (top row first) to `path` via a temporary file and a rename, so a
/// failure leaves nothing half-written. Returns an empty string or a one-line error.
std::string write_png(const std::string& path, int width, int height,
                      const std::vector<unsigned char>& rgb);

}  // namespace clothsim::view
