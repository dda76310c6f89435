// A small program around run_viewer() for the tests: the hand-filled scene through the real
// scene adapter (build_model) and the real core, with the viewer's test modes on the command line.
#include "hand_scene.hpp"

#include <clothsim/scene.hpp>
#include <clothsim/sim.hpp>
#include <clothsim/viewer.hpp>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <string>

int main(int argc, char** argv) {
  CLI::App app{"viewer_probe: the viewer on a hand-made scene (tests only)"};
  clothsim::ViewerOptions vo;
  bool no_vsync = false, pin = false;
  double dt = 0.0, k_struct = 0.0;
  std::string name = "hand";
  app.add_option("--screenshot", vo.screenshot);
  app.add_option("--frames", vo.frames_dir);
  app.add_option("--fps", vo.fps);
  app.add_option("--seconds", vo.seconds);
  app.add_option("--lookahead", vo.lookahead);
  app.add_option("--width", vo.width);
  app.add_option("--height", vo.height);
  app.add_flag("--paused", vo.paused);
  app.add_flag("--no-vsync", no_vsync);
  app.add_flag("--flat-cloth", vo.flat_cloth);
  app.add_flag("--hide-cloth", vo.hide_cloth);
  app.add_flag("--pin", pin, "pin one corner");
  app.add_option("--dt", dt, "step size (default: the scene's)");
  app.add_option("--k-struct", k_struct, "structural stiffness (default: the scene's)");
  app.add_option("--name", name, "scene name (the window title starts with 'clothsim NAME')");
  bool bad_texture = false;
  app.add_flag("--bad-texture", bad_texture, "give the floor a texture whose bytes are no image");
  app.footer(clothsim::viewer_help_text());
  CLI11_PARSE(app, argc, argv);
  vo.vsync = !no_vsync;
  try {
    clothsim::testing::HandScene hand(12, 1.6f, 1.2f, pin);
    hand.scene.name = name.c_str();
    static const unsigned char junk[] = "not an image";
    const b2o::Texture texture{"junk.png", junk, sizeof junk};
    if (bad_texture) {
      hand.materials.back().diffuse_texture = 0;
      hand.scene.textures = &texture;
      hand.scene.texture_count = 1;
    }
    // (a spring constant is the seed model's: --k-struct makes the probe's cloth the 2016 one)
    clothsim::Options options = k_struct > 0.0 ? clothsim::seed_options() : clothsim::scene_options(hand.scene);
    if (dt > 0.0) options.dt = dt;
    if (k_struct > 0.0) options.k_struct = k_struct;
    const clothsim::Model model = clothsim::build_model(hand.scene, options);
    return clothsim::run_viewer(hand.scene, model, vo);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "viewer_probe: %s\n", e.what());
    return 1;
  }
}
