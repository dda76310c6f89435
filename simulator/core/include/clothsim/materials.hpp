// Cloth materials in SI units, independent of the mesh: the presets a user picks by name
// (`--material silk`, `PARAMS material=silk`). Their sources are in docs/physics.md
// ("Materials"); any single quantity overrides its preset (`--density 0.2`).
//
// This header depends on nothing (the build-time PARAMS check compiles it).
#pragma once

// M(enumerator, name, density kg/m^2, stretch N/m, bend N m, drag 1/s, thickness m,
//   friction, static friction, strain limit)
//   density    mass per area of cloth
//   stretch    membrane stretch modulus (force per width per strain)
//   bend       bending rigidity (moment per width per curvature)
//   drag       velocity damping per kilogram (air and internal losses, lumped)
//   thickness  the distance the cloth keeps from colliders
//   friction   Coulomb coefficients against colliders: kinetic, static
//   strain limit  the strain at which the yarns are straight and the cloth stops stretching
//              (the knee of a woven cloth's load curve); 0: none (rubber stretches on)
#define CLOTHSIM_MATERIALS(M)                                                 \
  M(Cotton, "cotton", 0.15, 12000.0, 7.0e-6, 0.5, 0.0003, 0.35, 0.45, 0.05)   \
  M(Silk, "silk", 0.06, 6000.0, 2.0e-6, 1.0, 0.0001, 0.20, 0.25, 0.06)        \
  M(Denim, "denim", 0.40, 15000.0, 5.0e-5, 0.3, 0.0008, 0.45, 0.55, 0.04)     \
  M(Leather, "leather", 0.90, 40000.0, 5.0e-4, 0.2, 0.0010, 0.50, 0.60, 0.03) \
  M(Rubber, "rubber", 0.50, 750.0, 1.6e-5, 0.2, 0.0005, 0.90, 1.10, 0.0)

namespace clothsim {

/// A cloth's material: one of the presets, or the 2016 program's per-vertex model (Seed:
/// mass per point and spring constants, the options of the "seed" group). Auto is Cotton,
/// or Seed when one of the seed group's options is given.
enum class Material : unsigned char {
  Auto,
#define CLOTHSIM_MATERIAL_ENUMERATOR(e, ...) e,
  CLOTHSIM_MATERIALS(CLOTHSIM_MATERIAL_ENUMERATOR)
#undef CLOTHSIM_MATERIAL_ENUMERATOR
  Seed,
};

/// A preset's quantities (the M columns above).
struct MaterialPreset {
  const char* name;
  double density, stretch, bend, drag, thickness, friction, static_friction, strain_limit;
};

/// The preset of a material (Cotton's for Auto; Seed has none: nullptr).
inline const MaterialPreset* material_preset(Material m) {
  static constexpr MaterialPreset kPresets[] = {
#define CLOTHSIM_MATERIAL_ROW(e, name, ...) {name, __VA_ARGS__},
      CLOTHSIM_MATERIALS(CLOTHSIM_MATERIAL_ROW)
#undef CLOTHSIM_MATERIAL_ROW
  };
  if (m == Material::Seed) return nullptr;
  return &kPresets[m == Material::Auto ? 0 : static_cast<int>(m) - 1];
}

}  // namespace clothsim
