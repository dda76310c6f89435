// clothsim_params: checks a scene's PARAMS against the options table (options.hpp), so that
// blender2ogl_add_scene() stops the configure on a key or value the simulator would refuse.
// It needs only options.cpp: the build compiles it at configure time, before anything else.
//
//   clothsim_params KEY=VALUE...   exit 0 when every entry is good, else 1 and a line for each
//   clothsim_params --list         the table: name, default, unit, what values it takes
#include <clothsim/options.hpp>

#include <cstdio>
#include <string>
#include <string_view>

namespace {

void list() {
  const clothsim::Options defaults{};
  for (const clothsim::OptionInfo& o : clothsim::option_table()) {
    std::string takes;
    if (o.is_choice) {
      for (std::string_view c : o.choices) (takes.empty() ? takes : takes += ", ") += c;
    } else {
      takes = o.range == clothsim::Range::Positive ? "> 0" : o.range == clothsim::Range::NonNegative ? ">= 0" : "any";
    }
    std::printf("%-12s %-18s %-8s %s\n", std::string(o.name).c_str(), o.text(defaults).c_str(),
                std::string(o.unit).c_str(), takes.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && std::string_view(argv[1]) == "--list") {
    list();
    return 0;
  }
  int bad = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string_view entry = argv[i];
    const auto eq = entry.find('=');
    const std::string why = eq == std::string_view::npos
                                ? "expected KEY=VALUE (e.g. dt=0.002)"
                                : clothsim::check_param(entry.substr(0, eq), entry.substr(eq + 1));
    if (why.empty()) continue;
    std::fprintf(stderr, "  '%s': %s\n", argv[i], why.c_str());
    ++bad;
  }
  if (bad == 0) return 0;
  std::string keys;
  for (const clothsim::OptionInfo& o : clothsim::option_table()) (keys.empty() ? keys : keys += ", ") += o.name;
  std::fprintf(stderr, "Valid keys (underscores, as the simulator reads them): %s\n", keys.c_str());
  return 1;
}
