// What the .obj and .mtl pre-scans share: the error at a line, number tokens, byte checks.
#ifndef BLENDER2OGL_PRESCAN_TEXT_HPP
#define BLENDER2OGL_PRESCAN_TEXT_HPP
#include <filesystem>
#include <string>
#include <string_view>

namespace b2o::conv {

/// Throws InputError("file:line: what").
[[noreturn]] void fail(const std::filesystem::path& file, std::size_t line, const std::string& what);
/// Refuses a control byte: "binary data (byte 0xNN) in a <in_what>".
[[noreturn]] void fail_binary(const std::filesystem::path& file, std::size_t line, unsigned char c, const char* in_what);
/// Refuses a '\r' that does not end the line.
[[noreturn]] void fail_carriage_return(const std::filesystem::path& file, std::size_t line);

/// A decimal number as OBJ writers produce it: [+-]digits[.digits][(e|E)[+-]digits].
/// `value`: 0 unless the number may leave float range (a long mantissa or an exponent), then
/// the number (infinity when it does leave it).
bool parse_number(std::string_view t, double& value);
/// A whole number of at most 12 characters, with an optional sign.
bool parse_int(std::string_view t, long long& value);
/// A number, or nan/inf spelled out (to report them as such rather than as garbage).
bool is_number_like(std::string_view t);

}  // namespace b2o::conv
#endif
