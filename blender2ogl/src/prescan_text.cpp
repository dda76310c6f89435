// The pieces of text both pre-scans read: numbers, and the errors they report at a line.
#include "prescan_text.hpp"

#include <cmath>
#include <cstdlib>
#include <limits>

#include "converter.hpp"

namespace b2o::conv {

void fail(const std::filesystem::path& file, std::size_t line, const std::string& what) {
  throw InputError(file.string() + ":" + std::to_string(line) + ": " + what);
}

void fail_binary(const std::filesystem::path& file, std::size_t line, unsigned char c, const char* in_what) {
  const char* hex = "0123456789abcdef";
  fail(file, line, std::string("binary data (byte 0x") + hex[c >> 4] + hex[c & 15] + ") in a " + in_what);
}

void fail_carriage_return(const std::filesystem::path& file, std::size_t line) {
  fail(file, line, "carriage return inside a line (old Mac line endings are not supported)");
}

bool parse_number(std::string_view t, double& value) {
  std::size_t i = 0;
  if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
  std::size_t digits = 0;
  while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i, ++digits;
  if (i < t.size() && t[i] == '.') {
    ++i;
    while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
    std::size_t exp_digits = 0;
    while (i < t.size() && t[i] >= '0' && t[i] <= '9') ++i, ++exp_digits;
    if (exp_digits == 0) return false;
  }
  if (i != t.size()) return false;
  // Only a long mantissa or an exponent can leave float range; assimp reads floats.
  value = 0.0;
  if (t.size() > 30 || t.find_first_of("eE") != std::string_view::npos) {
    const std::string copy(t);
    value = std::strtod(copy.c_str(), nullptr);
    if (std::fabs(value) > static_cast<double>(std::numeric_limits<float>::max()))
      value = std::numeric_limits<double>::infinity();
  }
  return true;
}

bool parse_int(std::string_view t, long long& value) {
  if (t.empty()) return false;
  std::size_t i = (t[0] == '-' || t[0] == '+') ? 1 : 0;
  if (i == t.size() || t.size() > 12) return false;
  long long v = 0;
  for (std::size_t k = i; k < t.size(); ++k) {
    if (t[k] < '0' || t[k] > '9') return false;
    v = v * 10 + (t[k] - '0');
  }
  value = t[0] == '-' ? -v : v;
  return true;
}

bool is_number_like(std::string_view t) {
  double ignored = 0;
  if (parse_number(t, ignored)) return true;
  std::string lower;
  for (char c : t) lower += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return lower.find("nan") != std::string::npos || lower.find("inf") != std::string::npos;
}

}  // namespace b2o::conv
