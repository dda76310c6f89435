// One executable per baked scene: CMake defines CLOTHSIM_SCENE_NAME and CLOTHSIM_SCENE_HEADER.
#include "app.hpp"

#include CLOTHSIM_SCENE_HEADER

int main(int argc, char** argv) {
  return clothsim::run_app(argc, argv, b2o::gen::CLOTHSIM_SCENE_NAME::scene);
}
