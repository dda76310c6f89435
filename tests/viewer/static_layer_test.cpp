// The viewer's cached static layer (GlScene::cache_static): a frame started from the copy of the
// background and static meshes must be the same pixels as a frame drawn in full, from any
// camera (also one below the floor, where the floor hides the cloth: the copy's depth), with the
// cloth moved, in wireframe and at another size. Runs in-process in a GL 3.3 core window
// under xvfb-run (tests/viewer/CMakeLists.txt); without a display it is skipped, and a
// display without a window fails.
#include "hand_scene.hpp"

#include "../../simulator/viewer/src/gl_scene.hpp"

#include <clothsim/view/camera.hpp>

#include <clothsim/scene.hpp>
#include <clothsim/sim.hpp>
#include <clothsim/step.hpp>

#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace {

using clothsim::testing::HandScene;

constexpr int kW = 320, kH = 180;

struct View {
  Eigen::Matrix4f view_proj;
  Eigen::Vector3d eye;
};

// The viewer's own orbit camera around the cloth's middle: yaw, pitch (> 0: from above).
View view_from(double yaw, double pitch, double distance, int w = kW, int h = kH, double fovy = 0.9) {
  clothsim::view::OrbitCamera cam;
  cam.target = Eigen::Vector3d(0.0, 0.6, 0.0);
  cam.yaw = yaw, cam.pitch = pitch, cam.distance = distance, cam.fovy = fovy;
  return {cam.projection(static_cast<double>(w) / h) * cam.view(), cam.eye()};
}

class StaticLayer : public ::testing::Test {
 protected:
  // The window and its context; when there is a display but no window, trouble_ says why.
  static void SetUpTestSuite() {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) return;
    glfwSetErrorCallback([](int code, const char* what) {
      trouble_ = std::string(what ? what : "?") + " (GLFW error " + std::to_string(code) + ")";
    });
    trouble_ = "GLFW cannot start";
    if (!glfwInit()) return;
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    trouble_ = "no GL 3.3 core window";
    window_ = glfwCreateWindow(kW, kH, "static_layer_test", nullptr, nullptr);
    if (!window_) return;
    glfwMakeContextCurrent(window_);
    glewExperimental = GL_TRUE;
    if (glewInit() != GLEW_OK) {
      trouble_ = "GLEW cannot load OpenGL";
      glfwDestroyWindow(window_);
      window_ = nullptr;
      return;
    }
    trouble_.clear();
    while (glGetError() != GL_NO_ERROR) {}
  }
  static void TearDownTestSuite() {
    if (window_) glfwDestroyWindow(window_);
    window_ = nullptr;
    glfwTerminate();
  }

  void SetUp() override {
    // No display: skipped; a display without a window is a failure (the X server's or GL's).
    if (!window_ && trouble_.empty()) GTEST_SKIP() << "no DISPLAY (run under xvfb-run)";
    ASSERT_NE(window_, nullptr) << "DISPLAY=" << std::getenv("DISPLAY") << ": " << trouble_;
    hand_ = std::make_unique<HandScene>();
    model_ = std::make_unique<clothsim::Model>(
        clothsim::build_model(hand_->scene, clothsim::scene_options(hand_->scene)));
    state_ = std::make_unique<clothsim::State>(clothsim::make_state(*model_));
    ws_ = std::make_unique<clothsim::Workspace>(clothsim::make_workspace(*model_));
    gpu_ = std::make_unique<clothsim::view::GlScene>();
    gpu_->init(hand_->scene, *model_);
    gpu_->target.max_samples = 0;
    gpu_->target.to_window = true;
    ASSERT_TRUE(gpu_->target.resize(kW, kH));
    gpu_->upload_state(hand_->scene, *model_, *state_, true);
  }
  void TearDown() override {
    gpu_.reset();  // its GL objects, while the context is current
  }

  std::vector<unsigned char> frame(const View& v, bool cached, const clothsim::view::RenderFlags& flags = {}) {
    gpu_->cache_static = cached;
    gpu_->draw(hand_->scene, *model_, v.view_proj, v.eye, flags);
    std::vector<unsigned char> rgb = gpu_->target.read_rgb();
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
    return rgb;
  }

  static void clear_window_depth() {
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
  }

  // Pixels that differ between two pictures of the same size by more than one level in a
  // channel, or at all in more than 1 in 1000 pixels: llvmpipe rounds a fragment's colour into
  // the window's format and into the layer's RGBA8 one level apart now and then (1 pixel of
  // 57 600 here), and what this test looks for (a missing depth copy, a stale layer) changes
  // whole regions.
  static long differing(const std::vector<unsigned char>& a, const std::vector<unsigned char>& b) {
    if (a.size() != b.size()) return -1;
    long off_by_one = 0, more = 0;
    for (std::size_t i = 0; i < a.size(); i += 3) {
      int worst = 0;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int{a[i + c]} - int{b[i + c]}));
      off_by_one += worst == 1;
      more += worst > 1;
    }
    return static_cast<std::size_t>(off_by_one) * 1000 > a.size() / 3 ? more + off_by_one : more;
  }

  static GLFWwindow* window_;
  static std::string trouble_;
  std::unique_ptr<HandScene> hand_;
  std::unique_ptr<clothsim::Model> model_;
  std::unique_ptr<clothsim::State> state_;
  std::unique_ptr<clothsim::Workspace> ws_;
  std::unique_ptr<clothsim::view::GlScene> gpu_;
};
GLFWwindow* StaticLayer::window_ = nullptr;
std::string StaticLayer::trouble_;

TEST_F(StaticLayer, FramesFromTheLayerAreTheFullDrawsPixels) {
  const View above = view_from(0.6, 0.7, 2.6);
  const auto full = frame(above, false);
  const auto first = frame(above, true);   // draws the layer, then copies it
  const auto second = frame(above, true);  // copies it only
  EXPECT_EQ(gpu_->static_redraws(), 1u);
  EXPECT_EQ(gpu_->cached_frames(), 2u);
  EXPECT_EQ(differing(full, first), 0);
  EXPECT_EQ(differing(full, second), 0);
  // the picture shows both the floor and the cloth (so the comparison says something)
  clothsim::view::RenderFlags hide;
  hide.hide_cloth = true;
  EXPECT_GT(differing(full, frame(above, false, hide)), kW * kH / 20);
}

TEST_F(StaticLayer, TheLayersDepthHidesTheClothBehindTheFloor) {
  // From below the floor, the floor (drawn two-sided) hides the cloth above it: only the
  // copied depth can say so.
  const View below = view_from(0.3, -1.2, 3.5);
  clothsim::view::RenderFlags hide;
  hide.hide_cloth = true;
  const auto without_cloth = frame(below, false, hide);
  clear_window_depth();  // a fresh back buffer: only the copy can hide the cloth
  EXPECT_EQ(differing(frame(below, true), without_cloth), 0);
  clear_window_depth();
  EXPECT_EQ(differing(frame(below, true), without_cloth), 0);
  EXPECT_EQ(differing(frame(below, false), without_cloth), 0);
  EXPECT_EQ(gpu_->cached_frames(), 2u);
}

TEST_F(StaticLayer, ANewCameraDrawsTheLayerAgain) {
  const View a = view_from(0.6, 0.7, 2.6), b = view_from(-2.0, 0.4, 3.0);
  frame(a, true);
  const auto moved = frame(b, true);
  EXPECT_EQ(gpu_->static_redraws(), 2u);
  EXPECT_EQ(differing(moved, frame(b, false)), 0);
  // the same matrix but another eye (the specular highlights follow it)
  View c = b;
  c.eye.x() += 0.5;
  frame(c, true);
  EXPECT_EQ(gpu_->static_redraws(), 3u);
  // the same eye looking elsewhere
  View d = view_from(-2.0, 0.4, 3.0, kW, kH, 0.6);  // a narrower lens
  d.eye = c.eye;
  const auto turned = frame(d, true);
  EXPECT_EQ(gpu_->static_redraws(), 4u);
  EXPECT_EQ(differing(turned, frame(d, false)), 0);
}

TEST_F(StaticLayer, TheClothMovesOverAnUnchangedLayer) {
  const View above = view_from(0.6, 0.7, 2.6);
  const auto before = frame(above, true);
  for (int i = 0; i < 300; ++i) ASSERT_TRUE(clothsim::step(*model_, *state_, *ws_).finite);
  gpu_->upload_state(hand_->scene, *model_, *state_, true);
  const auto after = frame(above, true);
  EXPECT_EQ(gpu_->static_redraws(), 1u);
  EXPECT_GT(differing(before, after), 0);  // the cloth fell
  EXPECT_EQ(differing(after, frame(above, false)), 0);
}

TEST_F(StaticLayer, WireframeAndSizeChangesDrawTheLayerAgain) {
  const View above = view_from(0.6, 0.7, 2.6);
  clothsim::view::RenderFlags wire;
  wire.wireframe = true;
  frame(above, true);
  const auto cached_wire = frame(above, true, wire);
  EXPECT_EQ(gpu_->static_redraws(), 2u);
  EXPECT_EQ(differing(cached_wire, frame(above, false, wire)), 0);

  ASSERT_TRUE(gpu_->target.resize(200, 120));  // a part of the window
  const View small = view_from(0.6, 0.7, 2.6, 200, 120);
  const auto cached_small = frame(small, true);
  EXPECT_EQ(cached_small.size(), 200u * 120u * 3u);
  EXPECT_EQ(gpu_->static_redraws(), 3u);
  EXPECT_EQ(differing(cached_small, frame(small, false)), 0);
}

}  // namespace
