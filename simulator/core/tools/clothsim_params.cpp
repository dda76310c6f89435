// clothsim_params: checks a scene's PARAMS against the options table (options.hpp), so that
// blender2ogl_add_scene() stops the configure on a key or value the simulator would refuse.
// It needs only options.cpp: the build compiles it at configure time, before anything else.
//
//   clothsim_params [--colliders N] KEY=VALUE...
//       exit 0 when every entry is good and they go together (one model's options, friction
//       only with colliders when N is given), else 1 and a line for each problem
//   clothsim_params --list         the table: name, default, unit, what values it takes
#include <clothsim/options.hpp>

#include <cstdio>
#include <cstdlib>
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

// The entries together (each one good): options of one model, static friction at least the
// kinetic one, friction keys only where there are colliders. Empty, or why.
std::string check_together(int first, int argc, char** argv, long colliders) {
  clothsim::Options o;
  bool seed = false;
  for (int i = first; i < argc; ++i) {
    const std::string_view entry = argv[i];
    const std::string_view key = entry.substr(0, entry.find('='));
    const clothsim::OptionInfo* row = clothsim::find_option(key);
    row->set(o, entry.substr(key.size() + 1));
    seed |= row->group == clothsim::OptionGroup::Seed;
    if (colliders == 0 && (key == "friction" || key == "static_friction"))
      return std::string(1, '\'').append(entry).append("': the scene has no colliders (every object is cloth): friction acts on nothing");
  }
  if (std::string why = clothsim::validate_options(o); !why.empty()) return why;
  try {
    clothsim::resolve_options(o, seed);
  } catch (const clothsim::ModelMismatch& e) {
    return e.what();
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && std::string_view(argv[1]) == "--list") {
    list();
    return 0;
  }
  int first = 1;
  long colliders = -1;  // (unknown)
  if (argc >= 3 && std::string_view(argv[1]) == "--colliders") {
    char* end = nullptr;
    colliders = std::strtol(argv[2], &end, 10);
    if (*argv[2] == '\0' || *end != '\0' || colliders < 0) {
      std::fprintf(stderr, "  --colliders takes a count, got '%s'\n", argv[2]);
      return 1;
    }
    first = 3;
  }
  int bad = 0;
  for (int i = first; i < argc; ++i) {
    const std::string_view entry = argv[i];
    const auto eq = entry.find('=');
    const std::string why = eq == std::string_view::npos
                                ? "expected KEY=VALUE (e.g. dt=0.002)"
                                : clothsim::check_param(entry.substr(0, eq), entry.substr(eq + 1));
    if (why.empty()) continue;
    std::fprintf(stderr, "  '%s': %s\n", argv[i], why.c_str());
    ++bad;
  }
  if (bad == 0) {
    const std::string why = check_together(first, argc, argv, colliders);
    if (why.empty()) return 0;
    std::fprintf(stderr, "  %s\n", why.c_str());
    return 1;
  }
  std::string keys;
  for (const clothsim::OptionInfo& o : clothsim::option_table()) (keys.empty() ? keys : keys += ", ") += o.name;
  std::fprintf(stderr, "Valid keys (underscores, as the simulator reads them): %s\n", keys.c_str());
  return 1;
}
