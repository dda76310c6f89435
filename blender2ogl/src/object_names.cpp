// OBJ object names: as assimp is given them (encoded) and read back, and pin helpers' names.
#include <string>

#include "prescan.hpp"

namespace b2o::conv {

std::string encode_object_name(const std::string& name) {
  std::string out;
  out.reserve(name.size());
  for (unsigned char c : name) {
    // ('\\': a name ending in one, `o foo\ ` with its trailing spaces cut, would continue the line)
    if (c == ' ' || c == '\t' || c == '\f' || c == '\v' || c == '#' || c == '%' || c == '\\') {
      const char* hex = "0123456789ABCDEF";
      out.push_back('%');
      out.push_back(hex[c >> 4]);
      out.push_back(hex[c & 15]);
    } else {
      out.push_back(static_cast<char>(c));
    }
  }
  return out;
}

std::string decode_object_name(const std::string& name) {
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  std::string out;
  out.reserve(name.size());
  for (std::size_t i = 0; i < name.size(); ++i) {
    if (name[i] == '%' && i + 2 < name.size() && hex(name[i + 1]) >= 0 && hex(name[i + 2]) >= 0) {
      out.push_back(static_cast<char>(hex(name[i + 1]) * 16 + hex(name[i + 2])));
      i += 2;
    } else {
      out.push_back(name[i]);
    }
  }
  return out;
}

bool is_pin_object_name(const std::string& name) {
  auto ends = [&](const char* s) {
    const std::string suffix(s);
    return name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return ends("_pins") || ends(".pins");
}

std::string pin_target_name(const std::string& name) { return name.substr(0, name.size() - 5); }

}  // namespace b2o::conv
