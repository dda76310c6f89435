// The `clothsim` program, compiled once; src/main.cpp binds it to one baked scene.
#pragma once

namespace b2o { struct Scene; }

namespace clothsim {

/// Parses the command line, runs the scene headless (or in the viewer) and returns the
/// exit code: 0 success, 1 the run failed (non-finite state, I/O error), 2 bad input.
int run_app(int argc, char** argv, const b2o::Scene& scene);

}  // namespace clothsim
