// The GL side of the viewer: buffers, textures, shaders, an offscreen multisampled target.
// Needs a current GL 3.3 core context; throws std::runtime_error with a one-line reason.
#pragma once

#include <Eigen/Core>
#include <GL/glew.h>

#include <cstdint>
#include <string>
#include <vector>

namespace b2o { struct Scene; }
namespace clothsim {
struct Model;
struct State;
}

namespace clothsim::view {

struct RenderFlags {
  bool wireframe = false;
  bool springs = false;
  bool flat_cloth = false;
  bool hide_cloth = false;
  std::string overlay;  ///< text drawn top-left (lines split by '\n'); empty: none
  std::int32_t drag_mass = -1;
  Eigen::Vector3d drag_target = Eigen::Vector3d::Zero();
};

/// Where every frame is drawn: a multisampled FBO (4x unless `max_samples` says fewer) resolved
/// into a plain one, which is read for PNGs and blitted to the window; or, with `to_window`,
/// the window's back buffer itself.
class RenderTarget {
 public:
  RenderTarget() = default;
  RenderTarget(const RenderTarget&) = delete;
  RenderTarget& operator=(const RenderTarget&) = delete;
  ~RenderTarget() { release(); }

  bool resize(int w, int h);  ///< false if the FBO is incomplete (sizes <= 0 are ignored)
  void bind_for_drawing() const;
  void resolve() const;
  void blit_to_window() const;
  std::vector<unsigned char> read_rgb() const;  ///< top row first

  int width = 0, height = 0;
  /// Samples per pixel at most, set before resize(): 4 (the GL's limit if lower); 0 (no
  /// multisampling) for an interactive window on a software renderer, where 4x costs ~15 ms a
  /// frame (llvmpipe, 1280x720).
  int max_samples = 4;
  /// Set before resize(): draw straight into the window's back buffer, with no FBO and no
  /// copy (for an interactive window on a software renderer, where each full-frame copy
  /// costs ~2 ms of the simulation's CPU at 1280x720). read_rgb() then reads the back buffer:
  /// call it before the swap.
  bool to_window = false;

 private:
  void release();
  GLuint msaa_fbo_ = 0, msaa_color_ = 0, msaa_depth_ = 0;
  GLuint fbo_ = 0, color_ = 0, depth_ = 0;
};

class GlScene {
 public:
  GlScene() = default;
  GlScene(const GlScene&) = delete;
  GlScene& operator=(const GlScene&) = delete;
  ~GlScene();

  void init(const b2o::Scene& scene, const Model& model);
  /// Copies the cloth's current positions/normals (and the mass positions for springs) to the GPU.
  /// Skipped when the state is not finite: the last good picture stays.
  void upload_state(const b2o::Scene& scene, const Model& model, const State& state, bool springs);
  void draw(const b2o::Scene& scene, const Model& model, const Eigen::Matrix4f& view_proj,
            const Eigen::Vector3d& eye, const RenderFlags& flags);

  RenderTarget target;
  /// Set before drawing, for a target without multisampling (`to_window`): keep the
  /// background and the static meshes (every object that is not cloth) of the last camera in
  /// a colour + depth framebuffer, and start each frame from a copy of it, so that only the
  /// cloth, lines and text are drawn again. Redrawn when the camera, the window's size or
  /// wireframe changes. The same pixels as a full draw (tests/viewer/static_layer_test.cpp);
  /// if the GL refuses the copy (another depth format), every frame is drawn in full.
  bool cache_static = false;
  /// Frames started from the cached layer so far, and times the layer was drawn.
  std::uint64_t cached_frames() const { return cached_frames_; }
  std::uint64_t static_redraws() const { return static_redraws_; }

 private:
  struct MeshUniforms {
    GLint view_proj, eye, kd, ks, ns, has_tex, tex, mode, flat;
  };
  GLuint mesh_prog_ = 0, line_prog_ = 0, bg_prog_ = 0;
  MeshUniforms mu_{};
  GLint line_view_proj_ = -1, line_color_ = -1, line_point_size_ = -1;
  GLuint mesh_vao_ = 0, pos_vbo_ = 0, nrm_vbo_ = 0, uv_vbo_ = 0, ebo_ = 0;
  GLuint spring_vao_ = 0, mass_vbo_ = 0, spring_ebo_ = 0;
  GLuint drag_vao_ = 0, drag_vbo_ = 0;
  GLuint bg_vao_ = 0;
  GLuint text_prog_ = 0, text_vao_ = 0, text_vbo_ = 0, text_ebo_ = 0;
  GLint text_screen_ = -1, text_color_ = -1, text_offset_ = -1;
  void draw_text(const std::string& text);
  void draw_background();
  void begin_meshes(const Eigen::Matrix4f& view_proj, const Eigen::Vector3d& eye, const RenderFlags& flags);
  void draw_objects(const b2o::Scene& scene, const RenderFlags& flags, bool cloth);
  void end_meshes();
  bool static_layer(const b2o::Scene& scene, const Eigen::Matrix4f& view_proj, const Eigen::Vector3d& eye,
                    const RenderFlags& flags);
  void release_layer();
  // The cached static layer (cache_static): its framebuffer and what it was drawn for.
  GLuint layer_fbo_ = 0, layer_color_ = 0, layer_depth_ = 0;
  int layer_w_ = 0, layer_h_ = 0;
  bool layer_valid_ = false, layer_refused_ = false, layer_checked_ = false;
  Eigen::Matrix4f layer_view_proj_ = Eigen::Matrix4f::Zero();
  Eigen::Vector3d layer_eye_ = Eigen::Vector3d::Zero();
  bool layer_wireframe_ = false;
  std::uint64_t cached_frames_ = 0, static_redraws_ = 0;
  std::vector<GLuint> textures_;
  std::size_t structural_springs_ = 0, bend_springs_ = 0;
  bool code_built_cloth_ = false;  // a cloth with no scene mesh: always drawn as springs

  std::vector<float> positions_, normals_, mass_positions_;
  std::vector<double> scratch_;
};

}  // namespace clothsim::view
