// names: object and scene names -> distinct, stable C++ identifiers.
#include <array>
#include <set>
#include <string_view>

#include "converter.hpp"

namespace b2o::conv {
namespace {

constexpr std::array<std::string_view, 107> kReserved = {
    "alignas", "alignof", "and", "and_eq", "asm", "auto", "bitand", "bitor", "bool", "break", "case", "catch",
    "char", "char8_t", "char16_t", "char32_t", "class", "compl", "concept", "const", "consteval", "constexpr",
    "constinit", "const_cast", "continue", "co_await", "co_return", "co_yield", "decltype", "default", "delete",
    "do", "double", "dynamic_cast", "else", "enum", "explicit", "export", "extern", "false", "float", "for",
    "friend", "goto", "if", "inline", "int", "long", "mutable", "namespace", "new", "noexcept", "not", "not_eq",
    "nullptr", "operator", "or", "or_eq", "private", "protected", "public", "register", "reinterpret_cast",
    "requires", "return", "short", "signed", "sizeof", "static", "static_assert", "static_cast", "struct",
    "switch", "template", "this", "thread_local", "throw", "true", "try", "typedef", "typeid", "typename",
    "union", "unsigned", "using", "virtual", "void", "volatile", "wchar_t", "while", "xor", "xor_eq",
    // names that would clash with macros, the generated API or the namespaces it names
    // (a scene namespace b2o::gen::std would hide ::std for the code inside it)
    "assert", "errno", "NULL", "scene", "std", "b2o", "gen",
    // macros GCC and Clang predefine in the GNU dialects (gnu++20, CMake's default, and the
    // preprocessor of the scene's .S file): linux and unix on Linux, the others on other targets
    "linux", "unix", "i386", "sun", "vax", "mips", "sparc"};

// The object-like macros of <cstdint> (the generated header includes it): INT32_MAX,
// SIZE_MAX, UINT_LEAST8_MAX, PTRDIFF_WIDTH (glibc defines the *_WIDTH ones in the GNU
// dialects), ... An object or scene of that name would make `inline constexpr std::uint32_t
// SIZE_MAX = ...`, which does not compile. (The function-like INT8_C ... expand only before '('.)
bool stdint_macro(std::string_view id) {
  const auto cut = [&](std::string_view prefix) {
    if (id.substr(0, prefix.size()) != prefix) return false;
    id.remove_prefix(prefix.size());
    return true;
  };
  std::string_view tail = id;
  if (const std::size_t us = id.rfind('_'); us != std::string_view::npos) tail = id.substr(us + 1);
  else return false;
  if (tail != "MIN" && tail != "MAX" && tail != "WIDTH") return false;
  id.remove_suffix(tail.size() + 1);
  for (std::string_view whole : {"SIZE", "PTRDIFF", "SIG_ATOMIC", "WCHAR", "WINT"})
    if (id == whole) return true;
  cut("U");
  if (!cut("INT")) return false;
  if (id == "PTR" || id == "MAX") return true;
  if (!cut("_LEAST")) cut("_FAST");
  return id == "8" || id == "16" || id == "32" || id == "64";
}

}  // namespace

std::string clean_identifier(const std::string& name) {
  std::string id;
  for (unsigned char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
    const char ch = ok ? static_cast<char>(c) : '_';
    // no "__" (reserved) and no leading '_'
    if (ch == '_' && (id.empty() || id.back() == '_')) continue;
    id += ch;
  }
  while (!id.empty() && id.back() == '_') id.pop_back();
  if (id.empty()) id = "unnamed";
  if (id[0] >= '0' && id[0] <= '9') id = "o" + id;
  for (auto k : kReserved)
    if (id == k) return id + "_";
  if (stdint_macro(id)) return id + "_";
  return id;
}

void assign_identifiers(Scene& scene) {
  std::set<std::string> taken;
  for (Object& o : scene.objects) {
    const std::string base = clean_identifier(o.name);
    std::string id = base;
    const std::string sep = base.back() == '_' ? "" : "_";  // never "__"
    for (int n = 2; taken.count(id) != 0; ++n) id = base + sep + std::to_string(n);
    taken.insert(id);
    o.identifier = id;
  }
}

}  // namespace b2o::conv
