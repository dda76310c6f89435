// Generated code compiles without a warning (g++ and clang++, -Werror -pedantic and the
// project's warning set) and reads back, value for value, what the converter holds, which
// equals what assimp reads (import_test). Inputs: the fixtures and assimp's OBJ test models
// (Debian assimp-testmodels); a model the converter refuses must get a clear message.
#include <gtest/gtest.h>

#include <algorithm>

#include "scene_dump.hpp"
#include "support.hpp"

namespace {

using namespace b2o::test;
namespace conv = b2o::conv;

struct Input {
  fs::path file;
  std::string name;
  std::vector<std::string> cloths;
  bool combined = false;
  bool first_object_cloth = false;  // give the first object masses (found after import)
  std::vector<std::pair<std::string, std::string>> params;
};

std::vector<Input> inputs() {
  std::vector<Input> in = {
      {fixture("grid.obj"), "grid", {"Cloth"}, false, false, {{"dt", "0.002"}, {"k_rep", "2000"}, {"integrator", "xpbd"}}},
      {fixture("grid.obj"), "grid_text", {"Cloth"}, true, false, {}},
      {fixture("ngons_crlf.obj"), "ngons", {"class", "Penta Gon"}, false, false, {}},
      {fixture("plain.obj"), "plain", {}, false, false, {}},
      {fixture("odd_names.obj"), "odd_names", {}, false, true, {}},
      {fixture("odd_names.obj"), "odd_text", {}, true, true, {}},
      {fixture("missing_tex.obj"), "int", {"Sheet"}, false, false, {}},  // a keyword as scene name
      // <cstdint>'s macros as object and scene names, a trigraph and UTF-8 in the comments'
      // names, and two scenes whose names differ in case only (their include guards differ too)
      {fixture("macro_names.obj"), "INT64_MAX", {}, true, false, {}},
      {fixture("macro_names.obj"), "ab", {}, false, false, {}},
      {fixture("macro_names.obj"), "Ab", {}, false, false, {}},
  };
  // the project's own scenes, as generated/CMakeLists.txt bakes them
  for (const auto& [scene, cloths] : std::vector<std::pair<std::string, std::vector<std::string>>>{
           {"skirt", {"Skirt"}}, {"dice", {"RollingDie", "Die"}}, {"hanging", {"Cloth"}}}) {
    const fs::path obj = fs::path(B2O_MODELS) / scene / (scene + ".obj");
    if (fs::exists(obj)) in.push_back({obj, "model_" + scene, cloths, false, false, {}});
  }
  std::vector<fs::path> models;
  for (const char* dir : {"/usr/share/assimp/models/OBJ", "/usr/share/assimp/models/invalid"})
    if (fs::is_directory(dir))
      for (const auto& e : fs::directory_iterator(dir))
        if (e.path().extension() == ".obj") models.push_back(e.path());
  std::sort(models.begin(), models.end());
  for (std::size_t i = 0; i < models.size(); ++i)
    in.push_back({models[i], "assimp_" + std::to_string(i), {}, false, true, {}});
  return in;
}

void compile_and_read_back(const std::string& compiler, const std::string& std_flag, const std::string& tag) {
  if (run_command("command -v " + compiler).exit_code != 0) GTEST_SKIP() << compiler << " not installed";
  const fs::path out = scratch("compile_" + tag);
  std::map<std::string, std::string> expected;  // scene -> dump
  std::string main_cpp = "#include <fstream>\n#include \"scene_dump.hpp\"\n";
  std::string body;
  std::size_t refused = 0, accepted_models = 0;
  for (const Input& in : inputs()) {
    conv::Options o;
    o.input = in.file;
    o.name = in.name;
    o.combined = in.combined;
    o.reverse_map = true;
    o.cloth_objects = in.cloths;
    o.params = in.params;
    try {
      conv::Scene s = conv::import_scene(o.input, false, /*allow_missing=*/true);  // plain.obj, missing_tex.obj
      s.name = conv::clean_identifier(o.name);
      if (in.first_object_cloth) o.cloth_objects.push_back(s.objects.front().name);
      conv::Stats stats;
      conv::bake_scene(s, o, stats);
      conv::write_outputs(out, conv::emit_scene(s, o));
      View v;
      make_view(s, v);
      expected[s.name] = dump_scene(v.scene);
      main_cpp += "#include \"" + s.name + ".h\"\n";
      body += "  { std::ofstream f(\"" + s.name + ".dump\", std::ios::binary); f << b2o::test::dump_scene(b2o::gen::" +
              s.name + "::scene);\n    if (b2o::gen::" + s.name + "::vertex_count != b2o::gen::" + s.name +
              "::scene.vertex_count) return 1; }\n";
      if (in.file.string().find("assimp") != std::string::npos) ++accepted_models;
    } catch (const conv::InputError& e) {
      ++refused;
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(in.file.string() + ":", 0), 0u) << "message must start with the file: " << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      ASSERT_NE(in.file.string().find("/usr/share/assimp/"), std::string::npos) << "only assimp's test models may be refused: " << msg;
    }
  }
  main_cpp += "int main() {\n" + body + "  return 0;\n}\n";
  write_file(out / "main.cpp", main_cpp);
  std::string cmd = "cd " + shell_quote(out.string()) + " && " + compiler + " " + std_flag +
                    " -O0 -Wall -Wextra -Wpedantic -pedantic -Werror -Wshadow -Wnon-virtual-dtor -Wold-style-cast"
                    " -Wcast-align -Woverloaded-virtual -Wnull-dereference -Wimplicit-fallthrough"
                    " -I" + shell_quote(B2O_INCLUDE) + " -I" + shell_quote(B2O_TESTS_DIR) + " -I. -o prog *.cpp *.S";
  const auto c = run_command(cmd);
  ASSERT_EQ(c.exit_code, 0) << cmd << "\n" << c.output;
  EXPECT_EQ(c.output, "") << "the compiler said something:\n" << c.output;
  const auto r = run_command("cd " + shell_quote(out.string()) + " && ./prog");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const auto& [name, dump] : expected) {
    const std::string got = read_file(out / (name + ".dump"));
    EXPECT_TRUE(got == dump) << "scene " << name << " reads back differently";
  }
  std::cout << "[ compiled ] " << expected.size() << " scenes (" << accepted_models << " assimp test models), "
            << refused << " refused with a message\n";
  EXPECT_GE(expected.size(), 7u);
}

TEST(Compile, GccReadsBackEveryValue) { compile_and_read_back("g++", "-std=c++17", "gcc"); }
TEST(Compile, ClangReadsBackEveryValue) { compile_and_read_back("clang++", "-std=c++20", "clang"); }

}  // namespace
