// The simulator's options: one table, from which the Options struct, the command line, its
// help, the validation, the JSON report, a scene's baked PARAMS and the build-time check of
// those PARAMS are all derived (after MuJoCo's mjxmacro.h). Adding an option is one row here
// plus the code that uses it (docs/architecture.md shows the diff of one).
//
// This header depends on the standard library only (the build-time PARAMS check compiles it
// alone).
#pragma once

#include <clothsim/materials.hpp>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <span>
#include <string>
#include <string_view>

// REAL(name, default, range, unit, group, seed alias, help)
//   name     the field, the PARAMS key and the report key; the flag is --name with '-' for '_'
//   default  a number, or kAuto ("auto"): the material's value, or one the simulator derives
//   range    Positive (> 0), NonNegative (>= 0) or Finite
//   group    Any (every model), Material (a material's quantity), Seed (the 2016 program's
//            per-vertex model: giving one of them without a material selects it)
//   seed alias: the 2016 program's single-dash option ("" when it had none)
// CHOICE(name, type, default, group, seed alias, help): "auto" or one of the names of the
// type's own list.
#define CLOTHSIM_OPTIONS(REAL, CHOICE)                                                                   \
  REAL(dt, 0.01, Positive, "s", Any, "step", "Step size h")                                              \
  CHOICE(material, Material, Auto, Any, "",                                                              \
         "Cloth material (auto: cotton, or seed when an option of the seed model is given)")              \
  REAL(density, kAuto, Positive, "kg/m^2", Material, "", "Mass per area of cloth")                       \
  REAL(stretch, kAuto, Positive, "N/m", Material, "", "Stretch stiffness, a membrane modulus")           \
  REAL(bend, kAuto, NonNegative, "N m", Material, "", "Bending stiffness")                               \
  REAL(drag, kAuto, NonNegative, "1/s", Material, "", "Velocity damping per kilogram")                   \
  REAL(thickness, kAuto, Positive, "m", Material, "", "Distance the cloth keeps from colliders")         \
  REAL(strain_limit, kAuto, NonNegative, "", Material, "",                                               \
       "Strain at which the cloth stops stretching (0: none)")                                          \
  REAL(air_density, 1.2, NonNegative, "kg/m^3", Material, "",                                            \
       "Density of the air, whose drag on the cloth's faces slows a falling sheet (0: none)")           \
  REAL(friction, kAuto, NonNegative, "", Any, "", "Kinetic friction coefficient against colliders")      \
  REAL(static_friction, kAuto, NonNegative, "", Any, "", "Static friction coefficient (at least friction)") \
  REAL(mass, 0.1, Positive, "kg", Seed, "mass", "Mass per point")                                        \
  REAL(k_struct, 400.0, NonNegative, "N/m", Seed, "stiff", "Structural spring stiffness")                \
  REAL(k_bend, 50.0, NonNegative, "N/m", Seed, "wstiff", "Bend spring stiffness")                        \
  REAL(damping, 0.1, NonNegative, "N s/m", Seed, "damp", "Damping gamma of report eq. 6")                \
  REAL(epsilon, 0.1, Positive, "m", Seed, "", "Collision band epsilon of report eq. 12")                 \
  REAL(k_rep, 600.0, NonNegative, "N/m", Seed, "", "Penalty stiffness k_rep of report eq. 12")           \
  REAL(gravity_x, 0.0, Finite, "m/s^2", Any, "", "Gravity, x component")                                 \
  REAL(gravity_y, -9.81, Finite, "m/s^2", Any, "", "Gravity, y component (Blender's OBJ export is Y up)")\
  REAL(gravity_z, 0.0, Finite, "m/s^2", Any, "", "Gravity, z component")                                 \
  REAL(pin_spin, 0.0, Finite, "rad/s", Any, "",                                                         \
       "Turn rate of each pin group about the axis from its cloth's centre through it (0: pins stay put)") \
  CHOICE(integrator, Integrator, Auto, Any, "",                                                          \
         "Time integrator (auto: xpbd for a material, symplectic-euler for the seed model)")              \
  CHOICE(self_collision, Switch, Auto, Any, "",                                                          \
         "Contact of the cloths with themselves and each other, no layer passing through another "        \
         "(auto: on for a material, off for the seed model)")

// The time integrators, the seed's first: I(enumerator, name, order, force evaluations per
// step, what it is). integrators.hpp says more about each.
#define CLOTHSIM_INTEGRATORS(I)                                                                   \
  I(SymplecticEuler, "symplectic-euler", 1, 1, "report eqs. 1-7: x += h v; v += h f(x)/m")        \
  I(ExplicitEuler, "explicit-euler", 1, 1, "forward Euler: energy grows")                         \
  I(Verlet, "verlet", 2, 1, "leapfrog (drift-kick-drift): symplectic")                            \
  I(Midpoint, "midpoint", 2, 2, "explicit midpoint (RK2)")                                        \
  I(RK4, "rk4", 4, 4, "classic Runge-Kutta")                                                      \
  I(ImplicitEuler, "implicit-euler", 1, 1, "Baraff & Witkin 1998: one Newton step, CG")           \
  I(FastMassSpring, "fast-mass-spring", 1, 1, "Liu et al. 2013: local/global, prefactored solve") \
  I(XPBD, "xpbd", 1, 1, "Macklin et al. 2016/2019: compliant springs, one pass per step")

namespace clothsim {

/// A time integrator; Auto is resolved when the Model is built (resolve_options()).
enum class Integrator : std::uint8_t {
  Auto,
#define CLOTHSIM_ENUMERATOR(e, ...) e,
  CLOTHSIM_INTEGRATORS(CLOTHSIM_ENUMERATOR)
#undef CLOTHSIM_ENUMERATOR
};

/// A feature that is on or off; Auto is decided when the Model is built (resolve_options()).
enum class Switch : std::uint8_t { Auto, Off, On };

/// The default of an option the material or the simulator fills in ("auto").
inline constexpr double kAuto = __builtin_nan("");

/// Numbers a user sets; the seed model's defaults are the 2016 report's. Fields: the table above.
struct Options {
#define CLOTHSIM_REAL_FIELD(name, def, ...) double name = def;
#define CLOTHSIM_CHOICE_FIELD(name, type, def, ...) type name = type::def;
  CLOTHSIM_OPTIONS(CLOTHSIM_REAL_FIELD, CLOTHSIM_CHOICE_FIELD)
#undef CLOTHSIM_REAL_FIELD
#undef CLOTHSIM_CHOICE_FIELD
};

/// The values a REAL option may take.
enum class Range : std::uint8_t { Positive, NonNegative, Finite };
/// Which model an option belongs to (the group column of the table).
enum class OptionGroup : std::uint8_t { Any, Material, Seed };

/// One row of the table, as the generic code (command line, help, report, PARAMS) reads it.
struct OptionInfo {
  std::string_view name;        ///< field, PARAMS key and report key
  std::string_view unit;        ///< "" for a choice
  std::string_view seed_alias;  ///< the 2016 program's option without its '-', or ""
  std::string_view help;
  bool is_choice = false;
  OptionGroup group = OptionGroup::Any;
  bool autoable = false;                      ///< takes "auto" (its default is kAuto or Auto)
  Range range = Range::Finite;                ///< REAL options only
  std::span<const std::string_view> choices;  ///< CHOICE options only: the names
  /// Sets the option from text (a decimal number, or one of the choices); empty, or a
  /// one-line reason worded to follow the option's name or flag ("must be a finite number > 0
  /// (got -1)", "takes a decimal number, got 'x'", "unknown 'y' (known: ...)").
  std::string (*set)(Options&, std::string_view text) = nullptr;
  /// The value as text (a number with 17 significant digits at most, as short as reads back).
  std::string (*text)(const Options&) = nullptr;
  /// The value of a REAL option (NaN for a choice, or "auto").
  double (*value)(const Options&) = nullptr;
  /// Whether the option holds "auto".
  bool (*is_auto)(const Options&) = nullptr;

  /// The command-line flag: "--" + name with '_' as '-'.
  std::string flag() const;
};

/// Every option, in the table's order.
std::span<const OptionInfo> option_table();

/// The row named `name` (a PARAMS key, e.g. "k_struct"), or nullptr.
const OptionInfo* find_option(std::string_view name);

/// For a name that is no option: " (did you mean k_struct?)" when it looks like one (hyphens
/// for underscores, another case, cut short or too long), else "".
std::string option_hint(std::string_view name);

/// Checks one baked parameter KEY=VALUE against the table; empty, or one line saying what is
/// wrong with it (an unknown key with a hint, or why the option refuses the value).
std::string check_param(std::string_view key, std::string_view value);

/// Empty when every option is in its range, else a one-line reason naming the first that is not.
std::string validate_options(const Options& options);

/// An option set for the model it does not belong to (resolve_options()).
struct ModelMismatch : std::invalid_argument {
  ModelMismatch(std::string option_name, const std::string& what)
      : std::invalid_argument(what), option(std::move(option_name)) {}
  std::string option;  ///< its name (a PARAMS key)
};

/// The material and the integrator with "auto" decided: Auto material is Cotton, or Seed when
/// `seed_given` (an option of the seed group was given); every auto Material-group quantity
/// and friction take the preset's values (friction 0 for the seed model, as in 2016; a friction
/// given alone keeps the preset's static-to-kinetic ratio, and static friction is at least the
/// kinetic one); an auto integrator is XPBD for a material and symplectic Euler for the seed model; auto
/// self-collision is on for a material and off for the seed model. Throws
/// ModelMismatch when an option of one model is set (not auto, not its default) for the
/// other: its message names the option and the model that takes it.
Options resolve_options(Options options, bool seed_given);

/// Whether an option of the seed group holds another value than its default.
bool seed_options_set(const Options& options);

/// The materials, the seed model last: "cotton, silk, denim, leather, rubber, seed".
std::string material_names();

/// The text of a number as the report and help show it: the shortest that reads back exactly.
std::string number_text(double value);

/// Reads a decimal number: all of `text` but spaces around it, no hexadecimal, "inf" or "nan",
/// nothing out of a double's range. Empty, or why not ("takes a decimal number, got 'x'"),
/// worded to follow an option's name.
std::string parse_number(std::string_view text, double& value);

/// The 2016 program's per-vertex model with its defaults (material seed): mass per point,
/// spring constants, the penalty band of report eq. 12.
inline Options seed_options();

/// Whether `o` uses the 2016 program's per-vertex model (material seed).
inline bool is_seed(const Options& o) { return o.material == Material::Seed; }

inline Options seed_options() {
  Options o;
  o.material = Material::Seed;
  return o;
}

/// The time integrators, in the table's order (not Auto).
std::span<const Integrator> all_integrators();
/// The command-line name, e.g. "symplectic-euler".
const char* to_string(Integrator method);
/// A command-line name (also "leapfrog", "velocity-verlet", "rk2", "baraff-witkin", "liu");
/// std::nullopt when unknown.
std::optional<Integrator> parse_integrator(std::string_view name);
/// "symplectic-euler, explicit-euler, ..." for error messages and --help.
std::string integrator_names();
/// Order of accuracy the theory gives (global error ~ h^order).
int integrator_order(Integrator method);
/// Force-stage evaluations per step (the implicit ones: one, plus their solves).
int force_evaluations(Integrator method);

}  // namespace clothsim
