// Screenshots by the real viewer under Xvfb: the probe (a hand-made scene through the real
// scene adapter, core and viewer) and, when built, the clothsim programs of the baked scenes.
// Run as: xvfb-run -a viewer_screenshot_test --probe=PATH [--program=NAME=PATH ...] --out=DIR
#include "window_driver.hpp"

#include <gtest/gtest.h>

#include <stb/stb_image.h>

#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
using viewer_test::q;
using viewer_test::Result;
using viewer_test::run;

namespace {

std::string g_probe;
std::vector<std::pair<std::string, std::string>> g_programs;  // name, path
fs::path g_out = "viewer_shots";

struct Image {
  int w = 0, h = 0;
  std::vector<unsigned char> rgb;
  bool ok() const { return w > 0; }
  const unsigned char* at(int x, int y) const { return &rgb[3 * (static_cast<std::size_t>(y) * w + x)]; }
};

Image load(const fs::path& file) {
  Image img;
  int channels = 0;
  unsigned char* data = stbi_load(file.c_str(), &img.w, &img.h, &channels, 3);
  if (!data) return Image{};
  img.rgb.assign(data, data + 3 * static_cast<std::size_t>(img.w) * img.h);
  stbi_image_free(data);
  return img;
}

// Pixels of the viewer's flat test colour (kFlatClothRgb = magenta), and their mean row.
struct Flat {
  long count = 0;
  double mean_row = 0.0;
};
Flat flat_pixels(const Image& img) {
  Flat f;
  for (int y = 0; y < img.h; ++y)
    for (int x = 0; x < img.w; ++x) {
      const unsigned char* p = img.at(x, y);
      if (p[0] > 240 && p[1] < 15 && p[2] > 240) {
        ++f.count;
        f.mean_row += y;
      }
    }
  if (f.count) f.mean_row /= static_cast<double>(f.count);
  return f;
}

double fraction_different(const Image& a, const Image& b) {
  if (a.w != b.w || a.h != b.h) return 1.0;
  long diff = 0;
  for (std::size_t i = 0; i < a.rgb.size(); i += 3)
    if (std::abs(a.rgb[i] - b.rgb[i]) + std::abs(a.rgb[i + 1] - b.rgb[i + 1]) + std::abs(a.rgb[i + 2] - b.rgb[i + 2]) > 24)
      ++diff;
  return static_cast<double>(diff) / static_cast<double>(a.w * a.h);
}

// Distinct colours in the picture: a blank or single-colour frame has very few.
std::size_t colour_count(const Image& img) {
  std::vector<bool> seen(1u << 15, false);
  std::size_t n = 0;
  for (std::size_t i = 0; i < img.rgb.size(); i += 3) {
    const unsigned key = (img.rgb[i] >> 3) << 10 | (img.rgb[i + 1] >> 3) << 5 | (img.rgb[i + 2] >> 3);
    if (!seen[key]) {
      seen[key] = true;
      ++n;
    }
  }
  return n;
}

fs::path out(const std::string& name) {
  fs::create_directories(g_out);
  const fs::path p = g_out / name;
  fs::remove_all(p);
  return p;
}

}  // namespace

TEST(ViewerProbe, ClothIsVisibleAndFallsBetweenTwoScreenshots) {
  const fs::path a = out("probe_t0.png"), b = out("probe_t1.png");
  const std::string base = q(g_probe) + " --width 480 --height 270 --flat-cloth --screenshot ";
  const Result r0 = run(base + q(a) + " --seconds 0");
  ASSERT_EQ(r0.code, 0) << r0.output;
  const Result r1 = run(base + q(b) + " --seconds 0.4");
  ASSERT_EQ(r1.code, 0) << r1.output;
  const Image i0 = load(a), i1 = load(b);
  ASSERT_TRUE(i0.ok() && i1.ok());
  EXPECT_EQ(i0.w, 480);
  EXPECT_EQ(i0.h, 270);
  const Flat f0 = flat_pixels(i0), f1 = flat_pixels(i1);
  const double total = 480.0 * 270.0;
  EXPECT_GT(f0.count, 0.005 * total) << "the cloth is not in the picture at t = 0";
  EXPECT_GT(f1.count, 0.005 * total) << "the cloth is not in the picture at t = 0.4";
  EXPECT_GT(f1.mean_row, f0.mean_row + 5.0) << "the cloth did not move down the picture";
  EXPECT_GT(fraction_different(i0, i1), 0.01);
}

TEST(ViewerProbe, LitPictureHasShadingAndHideClothRemovesTheCloth) {
  const fs::path lit = out("probe_lit.png"), hidden = out("probe_hidden.png");
  const std::string base = q(g_probe) + " --width 320 --height 180 --seconds 0.5 ";
  ASSERT_EQ(run(base + "--screenshot " + q(lit)).code, 0);
  ASSERT_EQ(run(base + "--flat-cloth --hide-cloth --screenshot " + q(hidden)).code, 0);
  const Image l = load(lit), h = load(hidden);
  ASSERT_TRUE(l.ok() && h.ok());
  EXPECT_GT(colour_count(l), 25u) << "a lit scene with a gradient background has many colours";
  EXPECT_EQ(flat_pixels(h).count, 0) << "hidden cloth still drawn";
  EXPECT_GT(fraction_different(l, h), 0.02) << "the cloth made no difference to the picture";
}

// A texture the viewer cannot decode (a scene not made by the bake, which refuses one) is a
// warning naming it, and the material is drawn without it: the picture is still made.
TEST(ViewerProbe, UndecodableTextureIsAWarningNotAFailure) {
  const fs::path shot = out("probe_bad_texture.png");
  const Result r = run(q(g_probe) + " --width 320 --height 180 --seconds 0.2 --bad-texture --screenshot " + q(shot));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("texture 'junk.png' cannot be decoded"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("drawn without it"), std::string::npos) << r.output;
  const Image img = load(shot);
  ASSERT_TRUE(img.ok());
  EXPECT_GT(colour_count(img), 25u);
}

TEST(ViewerProbe, FramesWritesTheWholeSequence) {
  const fs::path dir = out("probe_frames");
  const Result r = run(q(g_probe) + " --width 160 --height 90 --flat-cloth --frames " + q(dir) +
                    " --fps 10 --seconds 0.5");
  ASSERT_EQ(r.code, 0) << r.output;
  for (int i = 0; i <= 5; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", i);
    const Image img = load(dir / name);
    ASSERT_TRUE(img.ok()) << name;
    EXPECT_EQ(img.w, 160);
    EXPECT_GT(flat_pixels(img).count, 0) << name;
  }
  EXPECT_FALSE(fs::exists(dir / "frame_00006.png"));
  EXPECT_GT(fraction_different(load(dir / "frame_00000.png"), load(dir / "frame_00005.png")), 0.01);
}

// Ctrl-C during a long --frames run: it stops after the frame in progress, says how many
// frames it wrote, each a whole PNG, and exits 130 (it was killed by the signal, silently).
// The signal is sent once the third frame exists (the shell waits for the file).
TEST(ViewerProbe, InterruptedFramesRunSaysSoAndLeavesWholeFrames) {
  if (g_programs.empty()) GTEST_SKIP() << "no scene program built";
  const fs::path dir = out("interrupted_frames");
  const std::string prog = q(g_programs.front().second);
  const Result r = run("( " + prog + " --width 160 --height 90 --fps 10 --seconds 600 --frames " + q(dir) +
                       " & pid=$!; while [ ! -e " + q(dir / "frame_00002.png") +
                       " ] && kill -0 $pid 2>/dev/null; do sleep 0.05; done; kill -INT $pid; wait $pid; "
                       "echo exit=$? )");
  EXPECT_NE(r.output.find("exit=130"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("clothsim: interrupted at t = "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("frames written (each whole)"), std::string::npos) << r.output;
  long n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    ASSERT_TRUE(load(e.path()).ok()) << e.path();
    ++n;
  }
  EXPECT_GE(n, 3);
  EXPECT_LT(n, 6001);
}

TEST(ViewerProbe, BadInputGivesOneLineErrorAndNoFile) {
  const Result no_seconds = run(q(g_probe) + " --frames " + q(out("never")));
  EXPECT_EQ(no_seconds.code, 1);
  EXPECT_NE(no_seconds.output.find("--seconds"), std::string::npos) << no_seconds.output;
  EXPECT_FALSE(fs::exists(g_out / "never"));

  const fs::path bad = g_out / "no_such_dir" / "x.png";
  const Result unwritable = run(q(g_probe) + " --width 64 --height 64 --screenshot " + q(bad));
  EXPECT_EQ(unwritable.code, 1);
  EXPECT_NE(unwritable.output.find("x.png"), std::string::npos) << unwritable.output;
  EXPECT_FALSE(fs::exists(bad));
  EXPECT_FALSE(fs::exists(bad.string() + ".part"));

  const Result tiny = run(q(g_probe) + " --width 3 --screenshot " + q(out("tiny.png")));
  EXPECT_EQ(tiny.code, 1);
  EXPECT_NE(tiny.output.find("16..8192"), std::string::npos) << tiny.output;
}

// PNGs follow the output rule: a device is written through, never replaced by a regular file
// (our own device nodes, never /dev/null or /dev/full); a full one is an error naming it; a
// directory is refused before the window opens.
TEST(ViewerProbe, PngIntoADeviceIsWrittenThroughAndIntoADirectoryRefused) {
  const fs::path dir = out("devices");
  fs::create_directories(dir);
  if (::mknod((dir / "mynull").c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0 ||
      ::mknod((dir / "myfull").c_str(), S_IFCHR | 0666, makedev(1, 7)) != 0)
    GTEST_SKIP() << "mknod not permitted: " << std::strerror(errno);
  auto is_char_device = [](const fs::path& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
  };
  const std::string base = q(g_probe) + " --width 64 --height 64 ";
  const Result null = run(base + "--screenshot " + q(dir / "mynull"));
  EXPECT_EQ(null.code, 0) << null.output;
  EXPECT_TRUE(is_char_device(dir / "mynull")) << "the device was replaced";

  const Result full = run(base + "--screenshot " + q(dir / "myfull"));
  EXPECT_EQ(full.code, 1) << full.output;
  EXPECT_NE(full.output.find("myfull"), std::string::npos) << full.output;
  EXPECT_NE(full.output.find("No space left"), std::string::npos) << full.output;
  EXPECT_TRUE(is_char_device(dir / "myfull"));

  fs::create_directory(dir / "shot.png");
  const Result folder = run(base + "--screenshot " + q(dir / "shot.png"));
  EXPECT_EQ(folder.code, 1) << folder.output;
  EXPECT_NE(folder.output.find("shot.png' is a directory"), std::string::npos) << folder.output;
  EXPECT_TRUE(fs::is_empty(dir / "shot.png"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 3) << "a temporary file was left";
}

TEST(ViewerProbe, NonFiniteStateIsAnErrorNotAPicture) {
  // Springs so stiff that dt = 0.01 is 15x past the stable limit: the state overflows to
  // inf/NaN within about a second of simulated time.
  const std::string blow_up = q(g_probe) + " --k-struct 1e6 --width 64 --height 64 --seconds 30 ";
  const fs::path shot = out("nan.png");
  const Result r = run(blow_up + "--screenshot " + q(shot));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("non-finite"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(shot));
  // In a window, a timed run stops at the blow-up and exits 1.
  const Result w = run(blow_up + "--no-vsync");
  EXPECT_EQ(w.code, 1) << w.output;
  EXPECT_NE(w.output.find("(state non-finite)"), std::string::npos) << w.output;
  // The look-ahead meets the blow-up ahead of the picture: the picture still plays the finite
  // states up to it (not closing at once, with no frame of them), then the run fails.
  const std::size_t at = w.output.find(" frames in ");
  ASSERT_NE(at, std::string::npos) << w.output;
  const std::size_t from = w.output.rfind(' ', at - 1) + 1;
  EXPECT_GE(std::stol(w.output.substr(from, at - from)), 5) << w.output;
}

TEST(ViewerProbe, NoDisplayIsAClearErrorNotACrash) {
  const Result r = run("env -u DISPLAY -u WAYLAND_DISPLAY " + q(g_probe) + " --screenshot " + q(out("nodisplay.png")));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("xvfb-run"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(g_out / "nodisplay.png"));
}

TEST(ViewerProbe, WindowRunsInRealTimeUntilTheRequestedTimeAndClosesCleanly) {
  // A visible window (on Xvfb), the real-time loop, closed by the program at t = 0.3 s.
  const Result r = run(q(g_probe) + " --width 320 --height 180 --no-vsync --seconds 0.3");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("closed at t = 0.30 s after 30 steps"), std::string::npos) << r.output;
  // The look-ahead (on by default) says what it did; without it, the same end.
  EXPECT_NE(r.output.find("look-ahead"), std::string::npos) << r.output;
  const Result off = run(q(g_probe) + " --width 320 --height 180 --no-vsync --seconds 0.3 --lookahead 0");
  EXPECT_EQ(off.code, 0) << off.output;
  EXPECT_NE(off.output.find("closed at t = 0.30 s after 30 steps"), std::string::npos) << off.output;
  EXPECT_EQ(off.output.find("look-ahead"), std::string::npos) << off.output;
  // A short look-ahead (a ring of 17 states) and a run whose last step leaves a state off the
  // ring's spacing (the ring's room for it: StateRing.KeepsEveryNthStateAndATimedRunsLast).
  const Result tight = run(q(g_probe) + " --width 320 --height 180 --no-vsync --seconds 0.31 --lookahead 0.3");
  EXPECT_EQ(tight.code, 0) << tight.output;
  EXPECT_NE(tight.output.find("closed at t = 0.31 s after 31 steps"), std::string::npos) << tight.output;
}

// Keys and mouse through the X server to the focused window: N twice while paused, S
// (springs), a left drag that grabs the cloth, P while dragging (before the steps pull the
// point to the cursor), then H, P and Q. Each P's picture shows the input before it only.
TEST(ViewerProbe, KeysAndDragReachTheWindow) {
  if (run("command -v xdotool").code != 0) GTEST_SKIP() << "xdotool not installed (cmake/install-deps.sh)";
  // Where the cloth is at t = 0 in a 320x240 picture (the window shows the same view).
  const fs::path where = out("keys_where.png");
  ASSERT_EQ(run(q(g_probe) + " --width 320 --height 240 --flat-cloth --screenshot " + q(where)).code, 0);
  const Image w0 = load(where);
  ASSERT_TRUE(w0.ok());
  long cx = 0, cy = 0, count = 0;
  for (int y = 0; y < w0.h; ++y)
    for (int x = 0; x < w0.w; ++x)
      if (w0.at(x, y)[0] > 240 && w0.at(x, y)[1] < 15 && w0.at(x, y)[2] > 240) {
        cx += x;
        cy += y;
        ++count;
      }
  ASSERT_GT(count, 50);
  cx /= count;
  cy /= count;
  ASSERT_EQ(w0.at(static_cast<int>(cx), static_cast<int>(cy))[1], 0) << "the centroid is not on the cloth";

  const fs::path dir = out("keys");
  fs::create_directories(dir);
  viewer_test::Program probe({g_probe, "--name", "keystest", "--width", "320", "--height", "240", "--paused",
                              "--flat-cloth"}, dir);
  std::string id, title;
  ASSERT_EQ(viewer_test::wait_for_window(probe, "^clothsim keystest ", id), "");
  ASSERT_EQ(viewer_test::focus_window(probe, id), "");
  const auto move = [&](long x, long y) { return "mousemove --window " + id + ' ' + std::to_string(x) + ' ' + std::to_string(y); };
  ASSERT_EQ(viewer_test::xdo(move(cx, cy) + " mousedown 1 " + move(cx + 40, cy - 30) + " key s p n n mouseup 1"), "");
  ASSERT_EQ(viewer_test::xdo("getwindowname " + id, &title), "");
  ASSERT_EQ(viewer_test::xdo("key h p q"), "");
  Result r = probe.wait(30.0);
  r.output += title;
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("after 2 steps"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("wrote clothsim_0000.png"), std::string::npos) << r.output;
  // The title: scene, time, rates, state and the keys.
  for (const char* part : {"clothsim keystest | 320x240 | t ", "steps/s", "ms/step", "real time", "paused", "Space pause"})
    EXPECT_NE(r.output.find(part), std::string::npos) << part << " not in the title: " << r.output;
  const Image shot = load(dir / "clothsim_0000.png");
  ASSERT_TRUE(shot.ok()) << r.output;
  EXPECT_EQ(shot.w, 320);
  long yellow = 0, red = 0, green = 0;
  for (std::size_t i = 0; i < shot.rgb.size(); i += 3) {
    const int R = shot.rgb[i], G = shot.rgb[i + 1], B = shot.rgb[i + 2];
    if (R > 220 && G > 180 && G < 240 && B < 90) ++yellow;  // the drag line
    if (R > 170 && G < 60 && B < 60) ++red;                 // structural springs
    if (G > 110 && R < 60 && B < 60) ++green;               // bend springs
  }
  EXPECT_GT(yellow, 5) << "no drag line: the press did not grab the cloth";
  EXPECT_GT(red, 20) << "springs not shown";
  EXPECT_GT(green, 20) << "bend springs not shown";
  // The text overlay (white on a dark shadow, top left), and H hides it.
  auto white_on_top = [](const Image& img) {
    long n = 0;
    for (int y = 0; y < std::min(img.h, 40); ++y)
      for (int x = 0; x < img.w; ++x)
        if (img.at(x, y)[0] == 255 && img.at(x, y)[1] == 255 && img.at(x, y)[2] == 255) ++n;
    return n;
  };
  EXPECT_GT(white_on_top(shot), 50) << "no overlay text";
  const Image hidden = load(dir / "clothsim_0001.png");
  ASSERT_TRUE(hidden.ok()) << r.output;
  EXPECT_EQ(white_on_top(hidden), 0) << "H did not hide the overlay";
}

// A window made larger by the X server (as a window manager would): the picture takes the new
// size, which the title shows once the viewer has it.
TEST(ViewerProbe, ResizingTheWindowResizesThePicture) {
  if (run("command -v xdotool").code != 0) GTEST_SKIP() << "xdotool not installed (cmake/install-deps.sh)";
  const fs::path dir = out("resize");
  fs::create_directories(dir);
  viewer_test::Program probe({g_probe, "--name", "resizetest", "--width", "320", "--height", "240", "--paused",
                              "--flat-cloth"}, dir);
  std::string id, resized;
  ASSERT_EQ(viewer_test::wait_for_window(probe, "^clothsim resizetest ", id), "");
  ASSERT_EQ(viewer_test::focus_window(probe, id), "");
  ASSERT_EQ(viewer_test::xdo("windowsize " + id + " 480 200"), "");
  ASSERT_EQ(viewer_test::wait_for_window(probe, "^clothsim resizetest [|] 480x200 ", resized), "");
  ASSERT_EQ(viewer_test::xdo("key p q"), "");
  const Result r = probe.wait(30.0);
  EXPECT_EQ(r.code, 0) << r.output;
  const Image shot = load(dir / "clothsim_0000.png");
  ASSERT_TRUE(shot.ok()) << r.output;
  EXPECT_EQ(shot.w, 480);
  EXPECT_EQ(shot.h, 200);
  EXPECT_GT(flat_pixels(shot).count, 200) << "the cloth is not in the resized picture";
}

// The real programs: screenshots at t = 0 and t = T with the cloth in the flat test colour
// (CLOTHSIM_VIEWER_TEST=flat-cloth), and once as the user sees it.
class RealProgram : public ::testing::TestWithParam<std::pair<std::string, std::string>> {};

TEST_P(RealProgram, ScreenshotsShowTheClothMoving) {
  const auto& [name, path] = GetParam();
  const fs::path a = out(name + "_t0.png"), b = out(name + "_t2.png"), lit = out(name + "_lit.png");
  const std::string flat = "env CLOTHSIM_VIEWER_TEST=flat-cloth " + q(path) + " --width 480 --height 270 --screenshot ";
  const Result r0 = run(flat + q(a));  // no --seconds: the picture at t = 0
  ASSERT_EQ(r0.code, 0) << r0.output;
  const Result r1 = run(flat + q(b) + " --seconds 2");
  ASSERT_EQ(r1.code, 0) << r1.output;
  const Result r2 = run(q(path) + " --width 480 --height 270 --seconds 2 --screenshot " + q(lit));
  ASSERT_EQ(r2.code, 0) << r2.output;
  const Image i0 = load(a), i1 = load(b), il = load(lit);
  ASSERT_TRUE(i0.ok() && i1.ok() && il.ok());
  const double total = 480.0 * 270.0;
  EXPECT_GT(flat_pixels(i0).count, 0.005 * total) << name << ": no cloth at t = 0";
  EXPECT_GT(flat_pixels(i1).count, 0.005 * total) << name << ": no cloth at t = 2";
  EXPECT_GT(fraction_different(i0, i1), 0.005) << name << ": the pictures at t = 0 and 2 are the same";
  EXPECT_EQ(flat_pixels(il).count, 0) << name << ": the test colour leaked into the normal view";
  EXPECT_GT(colour_count(il), 50u);
}

TEST_P(RealProgram, WindowCountsStepsOfDtWhenSubstepping) {
  // The closing line counts steps of the user's dt, as the headless summary does.
  const auto& [name, path] = GetParam();
  const Result r = run(q(path) + " --width 320 --height 180 --no-vsync --substeps 2 --steps 10");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("after 10 steps of 2 substeps each"), std::string::npos) << name << ": " << r.output;
}

INSTANTIATE_TEST_SUITE_P(Scenes, RealProgram, ::testing::ValuesIn(g_programs),
                         [](const auto& p) { return p.param.first; });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(RealProgram);

int main(int argc, char** argv) {
  // Our arguments first: the parameterised suite reads g_programs when gtest initialises.
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--gtest", 0) == 0) continue;
    if (a.rfind("--probe=", 0) == 0) g_probe = a.substr(8);
    else if (a.rfind("--out=", 0) == 0) g_out = a.substr(6);
    else if (a.rfind("--program=", 0) == 0) {
      const std::string v = a.substr(10);
      const auto eq = v.find('=');
      if (eq == std::string::npos) {
        std::fprintf(stderr, "viewer_screenshot_test: --program wants NAME=PATH, got '%s'\n", v.c_str());
        return 2;
      }
      g_programs.emplace_back(v.substr(0, eq), v.substr(eq + 1));
    } else {
      std::fprintf(stderr, "viewer_screenshot_test: unknown argument '%s'\n", a.c_str());
      return 2;
    }
  }
  if (g_probe.empty()) {
    std::fprintf(stderr, "viewer_screenshot_test: --probe=PATH is required\n");
    return 2;
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
