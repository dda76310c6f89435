// The interactive window's keys and mouse: GLFW's events, in order, to the viewer's state
// and camera (a drag sets State::drag, which the core's step() pulls by).
#include "viewer_impl.hpp"

#include <clothsim/view/cloth_mesh.hpp>

#include <GL/glew.h>
#include <GLFW/glfw3.h>

#include <algorithm>

namespace clothsim {

// P saves the picture as of its press: the input after it waits until the screenshot is
// taken (a Q right after P still gets its picture; a drag released after P is in it).
void Viewer::input(const Input& e) {
  if (screenshot_request_ || !deferred_.empty()) deferred_.push_back(e);
  else apply(e);
}

// One event to the handler of its kind.
void Viewer::apply(const Input& e) {
  switch (e.kind) {
    case Input::Key: on_key(e.code, e.action); break;
    case Input::Button: on_button(e.code, e.action, e.mods); break;
    case Input::Cursor: on_cursor(e.x, e.y); break;
    case Input::Scroll: camera_.zoom(e.y); break;
  }
}

// After a screenshot: the input that waited for it, in order, up to the next P.
void Viewer::replay_deferred() {
  while (!deferred_.empty() && !screenshot_request_) {
    const Input e = deferred_.front();
    deferred_.pop_front();
    apply(e);
  }
}

// A key press (or its repeat): see viewer_help_text().
void Viewer::on_key(int key, int action) {
  switch (key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q: glfwSetWindowShouldClose(window_, GLFW_TRUE); break;
    case GLFW_KEY_SPACE:
      if (action == GLFW_PRESS && !non_finite_) {
        if (!paused_) take_back_shown();  // paused where the picture is
        paused_ = !paused_;
      }
      break;
    case GLFW_KEY_N:
    case GLFW_KEY_PERIOD:
      if (!non_finite_) {
        take_back_shown();
        paused_ = true;
        // One step of the user's dt, all its substeps: the state stays on a whole step, as
        // every count the viewer shows is of whole steps of dt.
        pending_steps_ += std::max(opt_.substeps, 1);
      }
      break;
    case GLFW_KEY_R:
      if (in_playback_) ring_->clear();  // what was computed ahead is of the old run
      in_playback_ = false;
      preroll_next_ = true;
      failure_.clear();
      state_ = make_state(model_);
      stats_reset_ = true;
      dragging_ = false;
      non_finite_ = false;
      gpu_.upload_state(scene_, model_, state_, true);
      break;
    case GLFW_KEY_W:
      if (action == GLFW_PRESS) wireframe_ = !wireframe_;
      break;
    case GLFW_KEY_S:
      if (action == GLFW_PRESS) show_springs_ = !show_springs_;
      break;
    case GLFW_KEY_P:
      if (action == GLFW_PRESS) screenshot_request_ = true;
      break;
    case GLFW_KEY_H:
      if (action == GLFW_PRESS) show_overlay_ = !show_overlay_;
      break;
    default: break;
  }
  update_title();
}

// The ray through the cursor from the camera.
view::Ray Viewer::cursor_ray() const {
  int ww = 0, wh = 0;
  glfwGetWindowSize(window_, &ww, &wh);
  return camera_.ray(cursor_x_, cursor_y_, ww, wh);
}

// A press starts a pan, an orbit or (left, on the cloth) a drag of the mass under the cursor;
// a release ends it.
void Viewer::on_button(int button, int action, int mods) {
  if (action == GLFW_RELEASE) {
    mode_ = Mouse::None;
    if (dragging_) {
      dragging_ = false;
      state_.drag = Drag{};
    }
    return;
  }
  if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_SHIFT)) mode_ = Mouse::Pan;
  else if (button == GLFW_MOUSE_BUTTON_MIDDLE) mode_ = Mouse::Pan;
  else if (button == GLFW_MOUSE_BUTTON_RIGHT) mode_ = Mouse::Orbit;
  else if (button == GLFW_MOUSE_BUTTON_LEFT) {
    const view::Ray ray = cursor_ray();
    // (on the state on screen; a grab takes it back from the look-ahead and pulls from there)
    const view::Pick pick =
        view::pick_mass(scene_, model_, in_playback_ ? ring_->front() : state_, ray, 0.02 * camera_.distance);
    if (pick.mass >= 0 && !non_finite_) {
      take_back_shown();
      dragging_ = true;
      mode_ = Mouse::Drag;
      drag_depth_ = (ray.origin + pick.t * ray.dir - camera_.eye()).dot(camera_.forward());
      state_.drag.mass = pick.mass;
      state_.drag.k = pull_stiffness(model_, static_cast<std::size_t>(pick.mass), h());
      state_.drag.reach = drag_reach_;          // a far target pulls like one two springs away
      update_drag_target();
    } else {
      mode_ = Mouse::Orbit;
    }
  }
}

// The dragged mass's target: the point under the cursor at the depth it was grabbed.
void Viewer::update_drag_target() {
  if (!dragging_) return;
  Eigen::Vector3d target;
  if (view::point_at_depth(cursor_ray(), camera_.eye(), camera_.forward(), drag_depth_, target))
    state_.drag.target = target;
}

// The cursor moved: orbit, pan or drag, as the pressed button says.
void Viewer::on_cursor(double x, double y) {
  const double dx = x - cursor_x_, dy = y - cursor_y_;
  cursor_x_ = x;
  cursor_y_ = y;
  int fh = 0;
  glfwGetWindowSize(window_, nullptr, &fh);
  switch (mode_) {
    case Mouse::Orbit: camera_.orbit(dx, dy); break;
    case Mouse::Pan: camera_.pan(dx, dy, fh); break;
    case Mouse::Drag: update_drag_target(); break;
    case Mouse::None: break;
  }
}

}  // namespace clothsim
