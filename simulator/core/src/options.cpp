// The options table (options.hpp) turned into rows the generic code reads, and the choice of
// model and integrator an "auto" leaves to the simulator.
#include <clothsim/options.hpp>

#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <string>

namespace clothsim {

namespace {

// Choice names, "auto" first (the enumerators' order).
constexpr std::string_view kIntegratorNames[] = {
    "auto",
#define CLOTHSIM_NAME(e, name, ...) name,
    CLOTHSIM_INTEGRATORS(CLOTHSIM_NAME)
#undef CLOTHSIM_NAME
};
constexpr Integrator kIntegrators[] = {
#define CLOTHSIM_VALUE(e, ...) Integrator::e,
    CLOTHSIM_INTEGRATORS(CLOTHSIM_VALUE)
#undef CLOTHSIM_VALUE
};
constexpr std::string_view kMaterialNames[] = {
    "auto",
#define CLOTHSIM_NAME(e, name, ...) name,
    CLOTHSIM_MATERIALS(CLOTHSIM_NAME)
#undef CLOTHSIM_NAME
    "seed",
};

constexpr std::string_view kSwitchNames[] = {"auto", "off", "on"};

// The names of a choice type ("auto" first) and its parser.
template <class T>
struct Choices;
template <>
struct Choices<Integrator> {
  static std::span<const std::string_view> names() { return kIntegratorNames; }
  static std::optional<Integrator> parse(std::string_view text) {
    return text == "auto" ? std::optional(Integrator::Auto) : parse_integrator(text);
  }
  static std::string_view label(Integrator v) { return kIntegratorNames[static_cast<std::size_t>(v)]; }
};
template <>
struct Choices<Material> {
  static std::span<const std::string_view> names() { return kMaterialNames; }
  static std::optional<Material> parse(std::string_view text) {
    for (std::size_t i = 0; i < std::size(kMaterialNames); ++i)
      if (text == kMaterialNames[i]) return static_cast<Material>(i);
    return std::nullopt;
  }
  static std::string_view label(Material v) { return kMaterialNames[static_cast<std::size_t>(v)]; }
};

template <>
struct Choices<Switch> {
  static std::span<const std::string_view> names() { return kSwitchNames; }
  static std::optional<Switch> parse(std::string_view text) {
    for (std::size_t i = 0; i < std::size(kSwitchNames); ++i)
      if (text == kSwitchNames[i]) return static_cast<Switch>(i);
    return std::nullopt;
  }
  static std::string_view label(Switch v) { return kSwitchNames[static_cast<std::size_t>(v)]; }
};

std::string joined(std::span<const std::string_view> names) {
  std::string out;
  for (std::string_view n : names) (out.empty() ? out : out += ", ") += n;
  return out;
}

std::string range_words(Range r, bool autoable) {
  std::string w;
  switch (r) {
    case Range::Positive: w = "a finite number > 0"; break;
    case Range::NonNegative: w = "a finite number >= 0"; break;
    case Range::Finite: w = "a finite number"; break;
  }
  return autoable ? w + " or auto" : w;
}

bool in_range(double v, Range r) {
  if (!std::isfinite(v)) return false;
  return r == Range::Finite || (r == Range::Positive ? v > 0.0 : v >= 0.0);
}

// A value as the user wrote it, cut for an error message.
std::string shown(std::string_view text) {
  return text.size() > 40 ? std::string(text.substr(0, 40)) + "..." : std::string(text);
}

}  // namespace

std::string parse_number(std::string_view text, double& v) {
  const auto first = text.find_first_not_of(" \t"), last = text.find_last_not_of(" \t");
  if (first == std::string_view::npos) return "needs a number, got an empty value";
  const std::string s(text.substr(first, last + 1 - first));
  char* end = nullptr;
  errno = 0;
  v = std::strtod(s.c_str(), &end);
  if (s.find_first_not_of("0123456789+-.eE") != std::string::npos || end != s.c_str() + s.size())
    return "takes a decimal number, got '" + shown(text) + "'";
  // overflow (+-HUGE_VAL), or a number that is not 0 read as 0 (a subnormal is a double)
  if (errno == ERANGE && std::abs(v) > 1.0) return "is out of a double's range (got " + shown(s) + ")";
  if (errno == ERANGE && v == 0.0) return "is too small for a double (got " + shown(s) + "; write 0)";
  return {};
}

namespace {

template <double Options::*Field, Range R, bool Autoable>
std::string set_real(Options& o, std::string_view text) {
  if (Autoable && text == "auto") {
    o.*Field = kAuto;
    return {};
  }
  double v = 0.0;
  if (std::string why = parse_number(text, v); !why.empty()) return why;
  if (!in_range(v, R)) return "must be " + range_words(R, Autoable) + " (got " + shown(text) + ")";
  o.*Field = v;
  return {};
}

template <class T, T Options::*Field>
std::string set_choice(Options& o, std::string_view text) {
  if (const auto v = Choices<T>::parse(text)) {
    o.*Field = *v;
    return {};
  }
  return "unknown '" + shown(text) + "' (known: " + joined(Choices<T>::names()) + ")";
}

std::string real_text(double v) { return std::isnan(v) ? std::string("auto") : number_text(v); }

const std::array kTable = {
#define CLOTHSIM_REAL_ROW(field, def, range, unit, group, alias, help)                                         \
  OptionInfo{#field,                                                                                           \
             unit,                                                                                             \
             alias,                                                                                            \
             help,                                                                                             \
             false,                                                                                            \
             OptionGroup::group,                                                                               \
             std::isnan(def),                                                                                  \
             Range::range,                                                                                     \
             {},                                                                                               \
             [](Options& o, std::string_view t) {                                                              \
               return set_real<&Options::field, Range::range, __builtin_isnan(def)>(o, t);                     \
             },                                                                                                \
             [](const Options& o) { return real_text(o.field); },                                              \
             [](const Options& o) { return o.field; },                                                         \
             [](const Options& o) { return std::isnan(o.field); }},
#define CLOTHSIM_CHOICE_ROW(field, type, def, group, alias, help)                                              \
  OptionInfo{#field,                                                                                           \
             "",                                                                                               \
             alias,                                                                                            \
             help,                                                                                             \
             true,                                                                                             \
             OptionGroup::group,                                                                               \
             type::def == type::Auto,                                                                          \
             Range::Finite,                                                                                    \
             Choices<type>::names(),                                                                           \
             [](Options& o, std::string_view t) { return set_choice<type, &Options::field>(o, t); },           \
             [](const Options& o) { return std::string(Choices<type>::label(o.field)); },                      \
             [](const Options&) { return std::nan(""); },                                                      \
             [](const Options& o) { return o.field == type::Auto; }},
    CLOTHSIM_OPTIONS(CLOTHSIM_REAL_ROW, CLOTHSIM_CHOICE_ROW)
#undef CLOTHSIM_REAL_ROW
#undef CLOTHSIM_CHOICE_ROW
};

}  // namespace

std::string OptionInfo::flag() const {
  std::string f = "--" + std::string(name);
  for (char& c : f)
    if (c == '_') c = '-';
  return f;
}

std::span<const OptionInfo> option_table() { return kTable; }

const OptionInfo* find_option(std::string_view name) {
  for (const OptionInfo& o : kTable)
    if (o.name == name) return &o;
  return nullptr;
}

std::string option_hint(std::string_view name) {
  std::string fixed(name);
  for (char& c : fixed) c = c == '-' ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  std::string hints;
  for (const OptionInfo& o : kTable) {
    const bool same = o.name == fixed;
    const bool cut = fixed.size() > 1 && o.name.substr(0, fixed.size()) == fixed;
    const bool long_ = o.name.size() > 1 && std::string_view(fixed).substr(0, o.name.size()) == o.name;
    if (same || (find_option(fixed) == nullptr && (cut || long_))) (hints.empty() ? hints : hints += " or ") += o.name;
  }
  return hints.empty() ? std::string() : " (did you mean " + hints + "?)";
}

std::string check_param(std::string_view key, std::string_view value) {
  const OptionInfo* o = find_option(key);
  if (!o) {
    std::string why(1, '\'');  // (built in steps: g++ 12 warns falsely on "'" + std::string)
    return why.append(key).append("' is not a scene parameter").append(option_hint(key));
  }
  Options scratch;
  if (std::string why = o->set(scratch, value); !why.empty()) return std::string(key) + " " + why;
  return {};
}

std::string validate_options(const Options& options) {
  for (const OptionInfo& o : kTable) {
    if (o.is_choice || (o.autoable && o.is_auto(options)) || in_range(o.value(options), o.range)) continue;
    return std::string(o.name) + " must be " + range_words(o.range, o.autoable) + " (got " +
           number_text(o.value(options)) + ")";
  }
  if (!std::isnan(options.friction) && !std::isnan(options.static_friction) &&
      options.static_friction < options.friction)
    return "static_friction must be at least friction (got " + number_text(options.static_friction) + " < " +
           number_text(options.friction) + ")";
  return {};
}

// The names of a group's options, comma-separated, in the table's order.
std::string group_names(OptionGroup group) {
  std::string names;
  for (const OptionInfo& row : kTable)
    if (row.group == group) (names.empty() ? names : names += ", ") += row.name;
  return names;
}

Options resolve_options(Options o, bool seed_given) {
  if (o.material == Material::Auto) o.material = seed_given ? Material::Seed : Material::Cotton;
  const bool seed = is_seed(o);
  const Options defaults{};
  for (const OptionInfo& row : kTable) {
    // an option of the other model, set to something else than its default
    const OptionGroup other = seed ? OptionGroup::Material : OptionGroup::Seed;
    if (row.group != other || row.text(o) == row.text(defaults)) continue;
    throw ModelMismatch(std::string(row.name),
                        std::string(row.name) + " belongs to " +
                            (seed ? "a material's cloth (the seed model takes " + group_names(OptionGroup::Seed) + ")"
                                  : "the seed model (material seed); material " +
                                        std::string(Choices<Material>::label(o.material)) + " takes " +
                                        group_names(OptionGroup::Material)));
  }
  if (const MaterialPreset* p = material_preset(o.material)) {
    // a friction given alone keeps the preset's ratio of static to kinetic friction
    if (std::isnan(o.static_friction) && !std::isnan(o.friction))
      o.static_friction = o.friction * (p->static_friction / p->friction);
    for (auto [field, value] : {std::pair{&Options::density, p->density}, {&Options::stretch, p->stretch},
                                {&Options::bend, p->bend}, {&Options::drag, p->drag},
                                {&Options::thickness, p->thickness}, {&Options::friction, p->friction},
                                {&Options::strain_limit, p->strain_limit},
                                {&Options::static_friction, p->static_friction}})
      if (std::isnan(o.*field)) o.*field = value;
  } else {  // the 2016 program: frictionless
    if (std::isnan(o.friction)) o.friction = 0.0;
  }
  // static friction at least the kinetic one (given alone, friction sets both)
  if (std::isnan(o.static_friction) || o.static_friction < o.friction) o.static_friction = o.friction;
  if (o.integrator == Integrator::Auto) o.integrator = seed ? Integrator::SymplecticEuler : Integrator::XPBD;
  if (o.self_collision == Switch::Auto) o.self_collision = seed ? Switch::Off : Switch::On;
  return o;
}

bool seed_options_set(const Options& o) {
  const Options defaults{};
  for (const OptionInfo& row : kTable)
    if (row.group == OptionGroup::Seed && row.text(o) != row.text(defaults)) return true;
  return false;
}

std::string material_names() { return joined(std::span(kMaterialNames).subspan(1)); }

std::string number_text(double value) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, value);
  return std::string(buf, r.ptr);
}

std::span<const Integrator> all_integrators() { return kIntegrators; }

const char* to_string(Integrator method) {
  const auto i = static_cast<std::size_t>(method);
  return i < std::size(kIntegratorNames) ? kIntegratorNames[i].data() : "unknown";
}

std::optional<Integrator> parse_integrator(std::string_view name) {
  for (Integrator m : kIntegrators)
    if (name == to_string(m)) return m;
  if (name == "leapfrog" || name == "velocity-verlet") return Integrator::Verlet;
  if (name == "rk2") return Integrator::Midpoint;
  if (name == "baraff-witkin") return Integrator::ImplicitEuler;
  if (name == "liu") return Integrator::FastMassSpring;
  return std::nullopt;
}

std::string integrator_names() { return joined(std::span(kIntegratorNames).subspan(1)); }

int integrator_order(Integrator method) {
  constexpr int order[] = {
      1,
#define CLOTHSIM_ORDER(e, name, ord, ...) ord,
      CLOTHSIM_INTEGRATORS(CLOTHSIM_ORDER)
#undef CLOTHSIM_ORDER
  };
  return order[static_cast<std::size_t>(method)];
}

int force_evaluations(Integrator method) {
  constexpr int forces[] = {
      1,
#define CLOTHSIM_FORCES(e, name, ord, f, ...) f,
      CLOTHSIM_INTEGRATORS(CLOTHSIM_FORCES)
#undef CLOTHSIM_FORCES
  };
  return forces[static_cast<std::size_t>(method)];
}

}  // namespace clothsim
