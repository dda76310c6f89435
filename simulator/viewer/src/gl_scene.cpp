#include "gl_scene.hpp"

#include <blender2ogl/scene_types.h>
#include <clothsim/sim.hpp>
#include <clothsim/view/cloth_mesh.hpp>
#include <clothsim/viewer.hpp>

#include <stb/stb_easy_font.h>
#include <stb/stb_image.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

namespace clothsim::view {

namespace {

const char* kMeshVs = R"(#version 330 core
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_nrm;
layout(location = 2) in vec2 a_uv;
uniform mat4 u_view_proj;
out vec3 v_pos;
out vec3 v_nrm;
out vec2 v_uv;
void main() {
  v_pos = a_pos;
  v_nrm = a_nrm;
  v_uv = a_uv;
  gl_Position = u_view_proj * vec4(a_pos, 1.0);
}
)";

// Blinn-Phong with a key, a head and a fill light; two-sided: back faces use the flipped normal.
const char* kMeshFs = R"(#version 330 core
in vec3 v_pos;
in vec3 v_nrm;
in vec2 v_uv;
uniform vec3 u_eye;
uniform vec3 u_kd;
uniform vec3 u_ks;
uniform float u_ns;
uniform bool u_has_tex;
uniform sampler2D u_tex;
uniform int u_mode;      // 0 lit, 1 flat colour
uniform vec3 u_flat;
out vec4 o_color;
vec3 light(vec3 n, vec3 v, vec3 l, vec3 base, float strength) {
  float d = max(dot(n, l), 0.0);
  vec3 h = normalize(l + v);
  float s = d > 0.0 ? pow(max(dot(n, h), 0.0), max(u_ns, 1.0)) : 0.0;
  return strength * (base * d + 0.5 * u_ks * s);
}
void main() {
  if (u_mode == 1) { o_color = vec4(u_flat, 1.0); return; }
  vec3 base = u_has_tex ? texture(u_tex, v_uv).rgb : u_kd;
  vec3 n = normalize(v_nrm);
  if (!gl_FrontFacing) n = -n;
  vec3 v = normalize(u_eye - v_pos);
  vec3 c = 0.2 * base;
  c += light(n, v, normalize(vec3(0.35, 0.9, 0.45)), base, 0.65);  // key, from above
  c += light(n, v, v, base, 0.35);                                    // headlight: what faces you is lit
  c += light(n, v, normalize(vec3(-0.6, 0.3, -0.5)), base, 0.2);    // fill
  o_color = vec4(min(c, vec3(1.0)), 1.0);
}
)";

const char* kLineVs = R"(#version 330 core
layout(location = 0) in vec3 a_pos;
uniform mat4 u_view_proj;
uniform float u_point_size;
void main() {
  gl_Position = u_view_proj * vec4(a_pos, 1.0);
  gl_PointSize = u_point_size;
}
)";

const char* kLineFs = R"(#version 330 core
uniform vec3 u_color;
out vec4 o_color;
void main() { o_color = vec4(u_color, 1.0); }
)";

// A full-screen triangle with a sky-to-ground gradient.
const char* kBgVs = R"(#version 330 core
out float v_y;
void main() {
  vec2 p = vec2((gl_VertexID == 1) ? 3.0 : -1.0, (gl_VertexID == 2) ? 3.0 : -1.0);
  v_y = 0.5 * (p.y + 1.0);
  gl_Position = vec4(p, 0.999, 1.0);
}
)";

const char* kBgFs = R"(#version 330 core
in float v_y;
out vec4 o_color;
void main() {
  vec3 ground = vec3(0.80, 0.79, 0.74), sky = vec3(0.55, 0.66, 0.82);
  o_color = vec4(mix(ground, sky, smoothstep(0.0, 1.0, v_y)), 1.0);
}
)";

// Text quads from stb_easy_font, in pixels (y down), scaled up on large windows.
const char* kTextVs = R"(#version 330 core
layout(location = 0) in vec2 a_pos;
uniform vec2 u_screen;
uniform vec2 u_offset;
uniform float u_scale;
void main() {
  vec2 p = u_scale * a_pos + u_offset;
  gl_Position = vec4(2.0 * p.x / u_screen.x - 1.0, 1.0 - 2.0 * p.y / u_screen.y, 0.0, 1.0);
}
)";

GLuint compile(GLenum kind, const char* src, const char* what) {
  const GLuint s = glCreateShader(kind);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    glDeleteShader(s);
    for (char& c : log) if (c == '\n') c = ' ';
    throw std::runtime_error(std::string("the ") + what + " shader does not compile: " + log);
  }
  return s;
}

GLuint program(const char* vs, const char* fs, const char* what) {
  const GLuint v = compile(GL_VERTEX_SHADER, vs, what);
  const GLuint f = compile(GL_FRAGMENT_SHADER, fs, what);
  const GLuint p = glCreateProgram();
  glAttachShader(p, v);
  glAttachShader(p, f);
  glLinkProgram(p);
  glDeleteShader(v);
  glDeleteShader(f);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetProgramInfoLog(p, sizeof log, nullptr, log);
    glDeleteProgram(p);
    for (char& c : log) if (c == '\n') c = ' ';
    throw std::runtime_error(std::string("the ") + what + " shader does not link: " + log);
  }
  return p;
}

GLuint load_texture(const b2o::Texture& t, const char* scene_name) {
  int w = 0, h = 0, channels = 0;
  stbi_uc* pixels = stbi_load_from_memory(t.bytes, static_cast<int>(t.size), &w, &h, &channels, 4);
  if (!pixels) {  // (the bake decodes every texture it writes; a scene made otherwise may not)
    std::fprintf(stderr, "clothsim: warning: scene '%s': texture '%s' cannot be decoded (%s); drawn without it\n",
                 scene_name, t.name ? t.name : "?", stbi_failure_reason());
    return 0;
  }
  // Images are stored top row first; GL and OBJ texture coordinates start at the bottom.
  const std::size_t row = static_cast<std::size_t>(w) * 4;
  std::vector<unsigned char> flipped(row * static_cast<std::size_t>(h));
  for (int y = 0; y < h; ++y)
    std::memcpy(flipped.data() + row * static_cast<std::size_t>(h - 1 - y), pixels + row * static_cast<std::size_t>(y), row);
  stbi_image_free(pixels);
  GLuint id = 0;
  glGenTextures(1, &id);
  glBindTexture(GL_TEXTURE_2D, id);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, flipped.data());
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  return id;
}

const void* byte_offset(std::size_t bytes) { return reinterpret_cast<const void*>(bytes); }

}  // namespace

// --- RenderTarget ---------------------------------------------------------------------------

void RenderTarget::release() {
  const GLuint fbos[] = {msaa_fbo_, fbo_};
  const GLuint rbs[] = {msaa_color_, msaa_depth_, color_, depth_};
  if (msaa_fbo_ || fbo_) glDeleteFramebuffers(2, fbos);
  if (msaa_color_ || color_) glDeleteRenderbuffers(4, rbs);
  msaa_fbo_ = msaa_color_ = msaa_depth_ = fbo_ = color_ = depth_ = 0;
}

bool RenderTarget::resize(int w, int h) {
  if (w <= 0 || h <= 0) return true;  // minimised: keep the old target
  if (to_window) {  // the window's own buffers follow its size
    width = w;
    height = h;
    return true;
  }
  if (w == width && h == height && fbo_) return true;
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
  if (w > max_size || h > max_size) return false;
  release();
  width = w;
  height = h;
  GLint gl_max = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &gl_max);
  const GLsizei samples = std::max(0, std::min(max_samples, static_cast<int>(gl_max)));
  auto make = [&](GLuint& fbo, GLuint& color, GLuint& depth, GLsizei n) {
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glGenRenderbuffers(1, &color);
    glBindRenderbuffer(GL_RENDERBUFFER, color);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, n, GL_RGBA8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
    glGenRenderbuffers(1, &depth);
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, n, GL_DEPTH24_STENCIL8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, depth);
    return glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  };
  bool ok = make(msaa_fbo_, msaa_color_, msaa_depth_, samples);
  ok = make(fbo_, color_, depth_, 0) && ok;
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return ok;
}

void RenderTarget::bind_for_drawing() const {
  glBindFramebuffer(GL_FRAMEBUFFER, to_window ? 0 : msaa_fbo_);
  glViewport(0, 0, width, height);
}

void RenderTarget::resolve() const {
  if (to_window) return;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, msaa_fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_);
  glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void RenderTarget::blit_to_window() const {
  if (to_window) return;  // drawn there
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

std::vector<unsigned char> RenderTarget::read_rgb() const {
  const std::size_t row = static_cast<std::size_t>(width) * 3;
  std::vector<unsigned char> bottom_up(row * static_cast<std::size_t>(height)), top_down(bottom_up.size());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, to_window ? 0 : fbo_);
  glReadBuffer(to_window ? GL_BACK : GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, bottom_up.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  for (int y = 0; y < height; ++y)  // GL's first row is the bottom one; PNG's the top one
    std::memcpy(top_down.data() + row * static_cast<std::size_t>(y),
                bottom_up.data() + row * static_cast<std::size_t>(height - 1 - y), row);
  return top_down;
}

// --- GlScene --------------------------------------------------------------------------------

GlScene::~GlScene() {
  glDeleteProgram(mesh_prog_);
  glDeleteProgram(line_prog_);
  glDeleteProgram(bg_prog_);
  glDeleteProgram(text_prog_);
  const GLuint text_bufs[] = {text_vbo_, text_ebo_};
  glDeleteBuffers(2, text_bufs);
  glDeleteVertexArrays(1, &text_vao_);
  const GLuint bufs[] = {pos_vbo_, nrm_vbo_, uv_vbo_, ebo_, mass_vbo_, spring_ebo_, drag_vbo_};
  glDeleteBuffers(7, bufs);
  const GLuint vaos[] = {mesh_vao_, spring_vao_, drag_vao_, bg_vao_};
  glDeleteVertexArrays(4, vaos);
  if (!textures_.empty()) glDeleteTextures(static_cast<GLsizei>(textures_.size()), textures_.data());
  release_layer();
}

void GlScene::init(const b2o::Scene& scene, const Model& model) {
  mesh_prog_ = program(kMeshVs, kMeshFs, "mesh");
  line_prog_ = program(kLineVs, kLineFs, "line");
  bg_prog_ = program(kBgVs, kBgFs, "background");
  mu_ = {glGetUniformLocation(mesh_prog_, "u_view_proj"), glGetUniformLocation(mesh_prog_, "u_eye"),
         glGetUniformLocation(mesh_prog_, "u_kd"),        glGetUniformLocation(mesh_prog_, "u_ks"),
         glGetUniformLocation(mesh_prog_, "u_ns"),        glGetUniformLocation(mesh_prog_, "u_has_tex"),
         glGetUniformLocation(mesh_prog_, "u_tex"),       glGetUniformLocation(mesh_prog_, "u_mode"),
         glGetUniformLocation(mesh_prog_, "u_flat")};
  line_view_proj_ = glGetUniformLocation(line_prog_, "u_view_proj");
  line_color_ = glGetUniformLocation(line_prog_, "u_color");
  line_point_size_ = glGetUniformLocation(line_prog_, "u_point_size");

  for (std::uint32_t t = 0; t < scene.texture_count; ++t)
    textures_.push_back(load_texture(scene.textures[t], scene.name ? scene.name : "?"));

  // The mesh: positions and normals change for cloth vertices, texcoords never.
  const std::size_t nv = scene.vertex_count;
  positions_.assign(scene.positions, scene.positions + 3 * nv);
  normals_.assign(scene.normals, scene.normals + 3 * nv);
  glGenVertexArrays(1, &mesh_vao_);
  glBindVertexArray(mesh_vao_);
  auto attribute = [](GLuint& vbo, GLuint loc, int comps, const float* data, std::size_t count, GLenum usage) {
    glGenBuffers(1, &vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(count * comps * sizeof(float)), data, usage);
    glEnableVertexAttribArray(loc);
    glVertexAttribPointer(loc, comps, GL_FLOAT, GL_FALSE, 0, nullptr);
  };
  attribute(pos_vbo_, 0, 3, positions_.data(), nv, GL_DYNAMIC_DRAW);
  attribute(nrm_vbo_, 1, 3, normals_.data(), nv, GL_DYNAMIC_DRAW);
  attribute(uv_vbo_, 2, 2, scene.texcoords, nv, GL_STATIC_DRAW);
  glGenBuffers(1, &ebo_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo_);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(scene.index_count * sizeof(std::uint32_t)),
               scene.indices, GL_STATIC_DRAW);

  // Springs: lines between mass positions, structural first, then bend.
  std::vector<std::uint32_t> lines;
  lines.reserve(2 * model.spring_count());
  auto add_kind = [&](bool structural) {
    for (std::size_t s = 0; s < model.spring_count(); ++s)
      if ((model.spring_kind[s] == 0) == structural) {
        lines.push_back(model.spring_a[s]);
        lines.push_back(model.spring_b[s]);
      }
  };
  add_kind(true);
  structural_springs_ = lines.size() / 2;
  add_kind(false);
  bend_springs_ = lines.size() / 2 - structural_springs_;
  for (const ClothRange& r : model.cloths) code_built_cloth_ = code_built_cloth_ || r.scene_cloth < 0;
  mass_positions_.assign(3 * model.mass_count(), 0.0f);
  glGenVertexArrays(1, &spring_vao_);
  glBindVertexArray(spring_vao_);
  attribute(mass_vbo_, 0, 3, mass_positions_.data(), model.mass_count(), GL_DYNAMIC_DRAW);
  glGenBuffers(1, &spring_ebo_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, spring_ebo_);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(lines.size() * sizeof(std::uint32_t)),
               lines.data(), GL_STATIC_DRAW);

  glGenVertexArrays(1, &drag_vao_);
  glBindVertexArray(drag_vao_);
  attribute(drag_vbo_, 0, 3, nullptr, 2, GL_DYNAMIC_DRAW);

  text_prog_ = program(kTextVs, kLineFs, "text");
  text_screen_ = glGetUniformLocation(text_prog_, "u_screen");
  text_color_ = glGetUniformLocation(text_prog_, "u_color");
  text_offset_ = glGetUniformLocation(text_prog_, "u_offset");
  glGenVertexArrays(1, &text_vao_);
  glBindVertexArray(text_vao_);
  glGenBuffers(1, &text_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, text_vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 16, nullptr);  // x, y of stb's (x, y, z, rgba)
  glGenBuffers(1, &text_ebo_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, text_ebo_);

  glGenVertexArrays(1, &bg_vao_);  // core profiles draw nothing without a bound VAO
  glBindVertexArray(0);
}

void GlScene::upload_state(const b2o::Scene& scene, const Model& model, const State& state,
                           bool springs) {
  if (!update_cloth_vertices(scene, model, state, positions_, normals_, scratch_)) return;
  glBindVertexArray(0);
  for (const ClothRange& r : model.cloths) {
    if (r.scene_cloth < 0) continue;
    const b2o::Object& obj = scene.objects[scene.cloths[r.scene_cloth].object];
    const auto offset = static_cast<GLintptr>(obj.first_vertex * 3 * sizeof(float));
    const auto bytes = static_cast<GLsizeiptr>(obj.vertex_count * 3 * sizeof(float));
    glBindBuffer(GL_ARRAY_BUFFER, pos_vbo_);
    glBufferSubData(GL_ARRAY_BUFFER, offset, bytes, positions_.data() + obj.first_vertex * 3);
    glBindBuffer(GL_ARRAY_BUFFER, nrm_vbo_);
    glBufferSubData(GL_ARRAY_BUFFER, offset, bytes, normals_.data() + obj.first_vertex * 3);
  }
  if (springs || code_built_cloth_) {
    for (std::size_t i = 0; i < mass_positions_.size(); ++i)
      mass_positions_[i] = static_cast<float>(state.x.data()[i]);
    glBindBuffer(GL_ARRAY_BUFFER, mass_vbo_);
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(mass_positions_.size() * sizeof(float)),
                    mass_positions_.data());
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

void GlScene::draw_background() {
  glDisable(GL_DEPTH_TEST);
  glUseProgram(bg_prog_);
  glBindVertexArray(bg_vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
}

void GlScene::begin_meshes(const Eigen::Matrix4f& view_proj, const Eigen::Vector3d& eye, const RenderFlags& flags) {
  glDisable(GL_CULL_FACE);  // cloth has two sides; colliders are closed or seen from above
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  // Meshes are pushed back a little so that spring lines on them stay visible.
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.0f, 1.0f);
  glPolygonMode(GL_FRONT_AND_BACK, flags.wireframe ? GL_LINE : GL_FILL);
  glUseProgram(mesh_prog_);
  glUniformMatrix4fv(mu_.view_proj, 1, GL_FALSE, view_proj.data());
  glUniform3f(mu_.eye, static_cast<float>(eye.x()), static_cast<float>(eye.y()), static_cast<float>(eye.z()));
  glUniform1i(mu_.tex, 0);
  glUniform3f(mu_.flat, kFlatClothRgb[0] / 255.0f, kFlatClothRgb[1] / 255.0f, kFlatClothRgb[2] / 255.0f);
  glActiveTexture(GL_TEXTURE0);
  glBindVertexArray(mesh_vao_);
}

void GlScene::end_meshes() {
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glDisable(GL_POLYGON_OFFSET_FILL);
}

// The static objects (cloth false) or the cloths (cloth true), in the scene's order.
void GlScene::draw_objects(const b2o::Scene& scene, const RenderFlags& flags, bool cloth) {
  auto draw_range = [&](std::uint32_t first_index, std::uint32_t count, std::int32_t material) {
    if (material >= 0 && static_cast<std::uint32_t>(material) < scene.material_count) {
      const b2o::Material& m = scene.materials[material];
      glUniform3fv(mu_.kd, 1, m.diffuse);
      glUniform3fv(mu_.ks, 1, m.specular);
      glUniform1f(mu_.ns, m.shininess);
      const bool tex = m.diffuse_texture >= 0 && static_cast<std::size_t>(m.diffuse_texture) < textures_.size() &&
                       textures_[static_cast<std::size_t>(m.diffuse_texture)] != 0;
      glUniform1i(mu_.has_tex, tex ? 1 : 0);
      if (tex) glBindTexture(GL_TEXTURE_2D, textures_[static_cast<std::size_t>(m.diffuse_texture)]);
    } else {  // no material: a neutral grey
      glUniform3f(mu_.kd, 0.7f, 0.7f, 0.7f);
      glUniform3f(mu_.ks, 0.2f, 0.2f, 0.2f);
      glUniform1f(mu_.ns, 20.0f);
      glUniform1i(mu_.has_tex, 0);
    }
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                   byte_offset(std::size_t{first_index} * sizeof(std::uint32_t)));
  };
  if (cloth && flags.hide_cloth) return;
  glUniform1i(mu_.mode, cloth && flags.flat_cloth ? 1 : 0);
  for (std::uint32_t o = 0; o < scene.object_count; ++o) {
    const b2o::Object& obj = scene.objects[o];
    if ((obj.cloth != b2o::kNone) != cloth) continue;
    if (obj.submesh_count == 0) {
      draw_range(obj.first_index, obj.index_count, b2o::kNone);
      continue;
    }
    for (std::uint32_t s = obj.first_submesh; s < obj.first_submesh + obj.submesh_count; ++s)
      draw_range(scene.submeshes[s].first_index, scene.submeshes[s].index_count, scene.submeshes[s].material);
  }
}

void GlScene::release_layer() {
  if (layer_fbo_) glDeleteFramebuffers(1, &layer_fbo_);
  const GLuint rbs[] = {layer_color_, layer_depth_};
  if (layer_color_ || layer_depth_) glDeleteRenderbuffers(2, rbs);
  layer_fbo_ = layer_color_ = layer_depth_ = 0;
  layer_w_ = layer_h_ = 0;
  layer_valid_ = false;
}

// Copies the static layer (background and static meshes, drawn again first if the camera,
// the size or wireframe changed) into the bound target, colour and depth; false if there is
// none to copy (off, or the GL refused it), and then nothing was drawn.
bool GlScene::static_layer(const b2o::Scene& scene, const Eigen::Matrix4f& view_proj, const Eigen::Vector3d& eye,
                           const RenderFlags& flags) {
  if (!cache_static || layer_refused_ || !target.to_window || target.width <= 0 || target.height <= 0) return false;
  if (layer_w_ != target.width || layer_h_ != target.height) {
    release_layer();
    glGenFramebuffers(1, &layer_fbo_);
    glBindFramebuffer(GL_FRAMEBUFFER, layer_fbo_);
    glGenRenderbuffers(1, &layer_color_);
    glBindRenderbuffer(GL_RENDERBUFFER, layer_color_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, target.width, target.height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, layer_color_);
    glGenRenderbuffers(1, &layer_depth_);
    glBindRenderbuffer(GL_RENDERBUFFER, layer_depth_);
    // the window's format (GLFW's default 24 + 8 bits): a depth copy needs the same on both sides
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, target.width, target.height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, layer_depth_);
    const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    target.bind_for_drawing();
    if (!complete) {
      release_layer();
      layer_refused_ = true;
      return false;
    }
    layer_w_ = target.width;
    layer_h_ = target.height;
  }
  if (!layer_valid_ || flags.wireframe != layer_wireframe_ || !(view_proj == layer_view_proj_) || eye != layer_eye_) {
    glBindFramebuffer(GL_FRAMEBUFFER, layer_fbo_);
    glViewport(0, 0, layer_w_, layer_h_);
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    draw_background();
    begin_meshes(view_proj, eye, flags);
    draw_objects(scene, flags, false);
    end_meshes();
    layer_valid_ = true;
    layer_view_proj_ = view_proj;
    layer_eye_ = eye;
    layer_wireframe_ = flags.wireframe;
    ++static_redraws_;
  }
  if (!layer_checked_) while (glGetError() != GL_NO_ERROR) {}
  glBindFramebuffer(GL_READ_FRAMEBUFFER, layer_fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glBlitFramebuffer(0, 0, layer_w_, layer_h_, 0, 0, layer_w_, layer_h_, GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT,
                    GL_NEAREST);
  target.bind_for_drawing();
  if (!layer_checked_) {  // once: a window whose depth format differs refuses the copy
    layer_checked_ = true;
    if (glGetError() != GL_NO_ERROR) {
      release_layer();
      layer_refused_ = true;
      return false;
    }
  }
  ++cached_frames_;
  return true;
}

void GlScene::draw(const b2o::Scene& scene, const Model& model, const Eigen::Matrix4f& view_proj,
                   const Eigen::Vector3d& eye, const RenderFlags& flags) {
  const bool from_layer = static_layer(scene, view_proj, eye, flags);
  target.bind_for_drawing();
  if (!from_layer) {
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    draw_background();
  }
  begin_meshes(view_proj, eye, flags);
  if (!from_layer) draw_objects(scene, flags, false);
  draw_objects(scene, flags, true);
  end_meshes();

  glUseProgram(line_prog_);
  glUniformMatrix4fv(line_view_proj_, 1, GL_FALSE, view_proj.data());
  glUniform1f(line_point_size_, 1.0f);
  if ((flags.springs || code_built_cloth_) && !flags.hide_cloth) {
    glBindVertexArray(spring_vao_);
    glUniform3f(line_color_, 0.85f, 0.1f, 0.1f);  // structural red, bend green: the report's fig. 3
    glDrawElements(GL_LINES, static_cast<GLsizei>(2 * structural_springs_), GL_UNSIGNED_INT, nullptr);
    glUniform3f(line_color_, 0.1f, 0.6f, 0.1f);
    glDrawElements(GL_LINES, static_cast<GLsizei>(2 * bend_springs_), GL_UNSIGNED_INT,
                   byte_offset(2 * structural_springs_ * sizeof(std::uint32_t)));
  }
  if (flags.drag_mass >= 0 && static_cast<std::size_t>(flags.drag_mass) < model.mass_count()) {
    // The pull as a line from the grabbed point (as last drawn) to the cursor.
    const std::size_t m = static_cast<std::size_t>(flags.drag_mass);
    const float line[6] = {mass_positions_[3 * m], mass_positions_[3 * m + 1], mass_positions_[3 * m + 2],
                           static_cast<float>(flags.drag_target.x()), static_cast<float>(flags.drag_target.y()),
                           static_cast<float>(flags.drag_target.z())};
    glBindVertexArray(drag_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, drag_vbo_);
    glBufferSubData(GL_ARRAY_BUFFER, 0, sizeof line, line);
    glUniform3f(line_color_, 1.0f, 0.85f, 0.1f);
    glDisable(GL_DEPTH_TEST);
    glDrawArrays(GL_LINES, 0, 2);
    // Core profiles have no wide lines: the two ends as squares, so the pull is easy to see.
    glEnable(GL_PROGRAM_POINT_SIZE);
    glUniform1f(line_point_size_, 7.0f);
    glDrawArrays(GL_POINTS, 0, 2);
    glDisable(GL_PROGRAM_POINT_SIZE);
    glEnable(GL_DEPTH_TEST);
  }
  if (!flags.overlay.empty()) draw_text(flags.overlay);
  glBindVertexArray(0);
  target.resolve();
}

void GlScene::draw_text(const std::string& text) {
  static std::vector<char> quads(16 * 4 * 4000);  // stb_easy_font: 4 vertices of 16 bytes per quad
  std::string copy = text;                         // stb wants a mutable char*
  const int n = stb_easy_font_print(0.0f, 0.0f, copy.data(), nullptr, quads.data(), static_cast<int>(quads.size()));
  std::vector<std::uint32_t> tris;
  tris.reserve(6 * static_cast<std::size_t>(n));
  for (std::uint32_t q = 0; q < static_cast<std::uint32_t>(n); ++q)
    tris.insert(tris.end(), {4 * q, 4 * q + 1, 4 * q + 2, 4 * q, 4 * q + 2, 4 * q + 3});
  glDisable(GL_DEPTH_TEST);
  glUseProgram(text_prog_);
  glBindVertexArray(text_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, text_vbo_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(64 * static_cast<std::size_t>(n)), quads.data(), GL_STREAM_DRAW);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(tris.size() * sizeof(std::uint32_t)), tris.data(),
               GL_STREAM_DRAW);
  glUniform2f(text_screen_, static_cast<float>(target.width), static_cast<float>(target.height));
  glUniform1f(glGetUniformLocation(text_prog_, "u_scale"), target.width >= 900 ? 2.0f : 1.0f);
  // A dark shadow one pixel off, then the text: readable on sky and on cloth.
  const float shadow[3] = {0.05f, 0.05f, 0.1f}, ink[3] = {1.0f, 1.0f, 1.0f};
  for (int pass = 0; pass < 2; ++pass) {
    glUniform2f(text_offset_, pass == 0 ? 11.0f : 10.0f, pass == 0 ? 11.0f : 10.0f);
    glUniform3fv(text_color_, 1, pass == 0 ? shadow : ink);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(tris.size()), GL_UNSIGNED_INT, nullptr);
  }
  glEnable(GL_DEPTH_TEST);
}

}  // namespace clothsim::view
