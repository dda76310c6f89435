// ColliderSet's construction: add_object() checks and copies the meshes; build() drops
// degenerate triangles, stores the kept ones in blocks of 4 slots and builds each object's
// binary tree of oriented boxes (build_node()), collapsed to 4-wide nodes (collapse()).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "collider.hpp"
#include "kernel.hpp"

namespace clothsim {

using detail::kBlock;

std::uint32_t ColliderSet::add_object(std::string name, const Eigen::Matrix3Xd& vertices,
                                      std::span<const std::uint32_t> indices) {
  if (built_)
    throw std::logic_error("collider '" + name + "': add_object() after build()");
  if (indices.size() % 3 != 0)
    throw std::invalid_argument("collider '" + name + "': index count " +
                                std::to_string(indices.size()) + " is not a multiple of 3");
  for (Eigen::Index i = 0; i < vertices.cols(); ++i)
    if (!vertices.col(i).allFinite())
      throw std::invalid_argument("collider '" + name + "': vertex " + std::to_string(i) +
                                  " is not finite");
  for (std::size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= static_cast<std::uint64_t>(vertices.cols()))
      throw std::invalid_argument("collider '" + name + "': triangle " + std::to_string(i / 3) +
                                  " uses vertex " + std::to_string(indices[i]) + " of " +
                                  std::to_string(vertices.cols()));
  if (indices.size() / 3 > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw std::invalid_argument("collider '" + name + "': too many triangles");
  Object o;
  o.name = std::move(name);
  o.vertices = vertices;
  o.indices.assign(indices.begin(), indices.end());
  objects_.push_back(std::move(o));
  return static_cast<std::uint32_t>(objects_.size() - 1);
}

std::uint32_t ColliderSet::add_object(
    std::string name, const Eigen::Matrix3Xd& vertices,
    const Eigen::Matrix<std::uint32_t, 3, Eigen::Dynamic>& triangles) {
  return add_object(std::move(name), vertices,
                    std::span<const std::uint32_t>(triangles.data(),
                                                   static_cast<std::size_t>(triangles.size())));
}

std::size_t ColliderSet::triangle_count(std::size_t o) const {
  return objects_.at(o).kept;
}

void ColliderSet::triangle(std::size_t o, std::size_t t, Eigen::Vector3d& a, Eigen::Vector3d& b,
                           Eigen::Vector3d& c) const {
  const Object& ob = objects_.at(o);
  if (t >= ob.indices.size() / 3) throw std::out_of_range("collider triangle index out of range");
  a = ob.vertices.col(ob.indices[3 * t]);
  b = ob.vertices.col(ob.indices[3 * t + 1]);
  c = ob.vertices.col(ob.indices[3 * t + 2]);
}

void ColliderSet::build() {
  if (built_) throw std::logic_error("ColliderSet::build() called twice");
  std::size_t total = 0;
  for (const Object& o : objects_) total += o.indices.size() / 3;
  if (total >= (std::size_t{1} << 28))  // leaf triangle slots are packed in 29 bits
    throw std::invalid_argument("colliders: " + std::to_string(total) +
                                " triangles, at most 2^28 supported");
  tri_.reserve(12 * 2 * total);
  orig_.reserve(2 * total);
  nodes_.reserve(total / 2 + 2 * objects_.size() + 1);
  nodes4_.reserve(total / 6 + objects_.size() + 1);

  lo_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  hi_ = -lo_;
  double max_pad = 0.0;
  for (Object& ob : objects_) {
    const std::size_t nt = ob.indices.size() / 3;
    ob.input_to_kept.assign(nt, -1);
    std::vector<std::uint32_t> kept;
    kept.reserve(nt);
    double scale = 1e-300;
    for (std::size_t t = 0; t < nt; ++t) {
      Eigen::Vector3d a, b, c;
      triangle(static_cast<std::size_t>(&ob - objects_.data()), t, a, b, c);
      if (triangle_is_degenerate(a, b, c)) {
        ++ob.degenerate;
        continue;
      }
      kept.push_back(static_cast<std::uint32_t>(t));
      scale = std::max({scale, a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff(),
                        c.cwiseAbs().maxCoeff()});
    }
    ob.tri_begin = static_cast<std::uint32_t>(orig_.size());
    ob.tri_end = ob.tri_begin;
    if (kept.empty()) continue;

    // Per kept triangle: corners and centroid, then a median-split BVH over a permutation.
    std::vector<double> corners(9 * kept.size()), cent(3 * kept.size());
    for (std::size_t i = 0; i < kept.size(); ++i) {
      const std::uint32_t t = kept[i];
      for (std::size_t j = 0; j < 3; ++j)
        for (std::size_t k = 0; k < 3; ++k) {
          const double x = ob.vertices(static_cast<Eigen::Index>(k), ob.indices[3 * t + j]);
          corners[9 * i + 3 * j + k] = x;
          cent[3 * i + k] += x / 3.0;
          lo_[static_cast<Eigen::Index>(k)] = std::min(lo_[static_cast<Eigen::Index>(k)], x);
          hi_[static_cast<Eigen::Index>(k)] = std::max(hi_[static_cast<Eigen::Index>(k)], x);
          if (i == 0 && j == 0) ob.lo[static_cast<Eigen::Index>(k)] = ob.hi[static_cast<Eigen::Index>(k)] = x;
          ob.lo[static_cast<Eigen::Index>(k)] = std::min(ob.lo[static_cast<Eigen::Index>(k)], x);
          ob.hi[static_cast<Eigen::Index>(k)] = std::max(ob.hi[static_cast<Eigen::Index>(k)], x);
        }
    }
    std::vector<std::uint32_t> perm(kept.size());
    for (std::size_t i = 0; i < perm.size(); ++i) perm[i] = static_cast<std::uint32_t>(i);
    // Pad: many orders of magnitude above double rounding in the kernel (~1e-15 scale).
    const double pad = 1e-9 * scale;
    max_pad = std::max(max_pad, pad);
    ob.lo.array() -= pad;
    ob.hi.array() += pad;
    ob.scale = scale;
    ob.root = build_node(0, static_cast<std::uint32_t>(perm.size()), cent, perm, corners, pad);

    // Store the triangles leaf by leaf, each leaf in its own block of 4 slots (384 bytes, one
    // contiguous run per leaf; unused slots have orig_ = -1). Leaves get global slots.
    for (std::size_t ni = ob.root; ni < nodes_.size(); ++ni) {
      Node& leaf = nodes_[ni];
      if (!leaf.leaf()) continue;
      const std::uint32_t first = leaf.index(), count = leaf.count();
      const auto slot0 = static_cast<std::uint32_t>(orig_.size());
      tri_.resize(tri_.size() + kBlock * 12, 0.0);
      orig_.resize(orig_.size() + kBlock, -1);
      for (std::uint32_t j = 0; j < count; ++j) {
        const std::uint32_t t = kept[perm[first + j]];
        const Eigen::Vector3d a = ob.vertices.col(ob.indices[3 * t]);
        const Eigen::Vector3d ab = ob.vertices.col(ob.indices[3 * t + 1]) - a;
        const Eigen::Vector3d ac = ob.vertices.col(ob.indices[3 * t + 2]) - a;
        const Eigen::Vector3d n = detail::unit_normal(ab, ac);
        const double comp[12] = {a.x(),  a.y(),  a.z(),  ab.x(), ab.y(), ab.z(),
                                 ac.x(), ac.y(), ac.z(), n.x(),  n.y(),  n.z()};
        for (std::size_t k = 0; k < 12; ++k) tri_[12 * slot0 + kBlock * k + j] = comp[k];
        ob.input_to_kept[t] = static_cast<std::int32_t>(slot0 + j);
        orig_[slot0 + j] = static_cast<std::int32_t>(t);
      }
      leaf.packed = (slot0 << 3) | count;
    }
    ob.tri_end = static_cast<std::uint32_t>(orig_.size());
    ob.kept = kept.size();
    kept_total_ += kept.size();
    ob.root4 = nodes_[ob.root].leaf() ? nodes_[ob.root].packed : collapse(ob.root) << 3;
  }
  // Queries need only each root's box and the 4-wide tree.
  for (Object& ob : objects_)
    if (ob.tri_end > ob.tri_begin) ob.root_box = nodes_[ob.root];
  // Clearances are computed when first needed (clear_at(), eclear_at()): NaN until then.
  clear_.assign(orig_.size(), std::numeric_limits<float>::quiet_NaN());
  eclear_.assign(3 * orig_.size(), std::numeric_limits<float>::quiet_NaN());
  adj_.assign(3 * orig_.size(), -1);
  for (std::size_t o = 0; o < objects_.size(); ++o)
    if (objects_[o].tri_end > objects_[o].tri_begin) compute_adjacency(o);
  adj_.shrink_to_fit();
  nodes_.clear();
  nodes_.shrink_to_fit();
  nodes4_.shrink_to_fit();
  tri_.shrink_to_fit();
  orig_.shrink_to_fit();
  // Padded, so the early-out never rejects what a query would find.
  lo_.array() -= max_pad;
  hi_.array() += max_pad;
  if (orig_.empty()) lo_.setZero(), hi_.setZero();
  built_ = true;
}

namespace {

float round_up(double v) {
  auto f = static_cast<float>(v);
  if (static_cast<double>(f) < v) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

// Half extents of the corners about centre c along float axes a (rows), padded, rounded up.
void extents(const float a[9], const float c[3], const std::vector<double>& corners,
             const std::vector<std::uint32_t>& perm, std::uint32_t begin, std::uint32_t end,
             double pad, float h[3]) {
  double m[3] = {0.0, 0.0, 0.0};
  for (std::uint32_t i = begin; i < end; ++i)
    for (std::size_t j = 0; j < 3; ++j) {
      const double* v = &corners[9 * perm[i] + 3 * j];
      const double q[3] = {v[0] - static_cast<double>(c[0]), v[1] - static_cast<double>(c[1]),
                           v[2] - static_cast<double>(c[2])};
      for (int k = 0; k < 3; ++k)
        m[k] = std::max(m[k], std::abs(static_cast<double>(a[3 * k]) * q[0] +
                                       static_cast<double>(a[3 * k + 1]) * q[1] +
                                       static_cast<double>(a[3 * k + 2]) * q[2]));
    }
  for (int k = 0; k < 3; ++k) h[k] = round_up(m[k] + pad);
}

// |A|_2 <= 1 + 1e-6 for the float axes, as box_dist_sq() assumes.
bool nearly_orthonormal(const float a[9]) {
  Eigen::Matrix3d A;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) A(r, k) = static_cast<double>(a[3 * r + k]);
  return ((A * A.transpose()) - Eigen::Matrix3d::Identity()).norm() < 1e-6;
}

}  // namespace

std::uint32_t ColliderSet::build_node(std::uint32_t begin, std::uint32_t end,
                                      std::vector<double>& cent, std::vector<std::uint32_t>& perm,
                                      const std::vector<double>& corners, double pad) {
  const auto self = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back(Node{});
  // Axis-aligned box, and an oriented one: normal = area-weighted mean normal, first tangent =
  // the principal direction of the corners in that plane. Keep the smaller volume.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()),
                  hi = -lo, clo = lo, chi = hi, area = Eigen::Vector3d::Zero(),
                  mean = Eigen::Vector3d::Zero();
  for (std::uint32_t i = begin; i < end; ++i) {
    const double* v = &corners[9 * perm[i]];
    const Eigen::Vector3d A(v[0], v[1], v[2]), B(v[3], v[4], v[5]), C(v[6], v[7], v[8]);
    lo = lo.cwiseMin(A).cwiseMin(B).cwiseMin(C);
    hi = hi.cwiseMax(A).cwiseMax(B).cwiseMax(C);
    area += (B - A).cross(C - A);
    mean += A + B + C;
    const Eigen::Vector3d c(cent[3 * perm[i]], cent[3 * perm[i] + 1], cent[3 * perm[i] + 2]);
    clo = clo.cwiseMin(c);
    chi = chi.cwiseMax(c);
  }
  mean /= 3.0 * (end - begin);

  Node best{};
  for (int k = 0; k < 3; ++k) {
    best.c[k] = static_cast<float>(0.5 * (lo[k] + hi[k]));
    best.a[4 * k] = 1.0f;
  }
  extents(best.a, best.c, corners, perm, begin, end, pad, best.h);
  if (area.norm() > 0.0) {
    const Eigen::Vector3d n = area.normalized();
    Eigen::Vector3d u = n.unitOrthogonal(), w = n.cross(u);
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (std::uint32_t i = begin; i < end; ++i)
      for (std::size_t j = 0; j < 3; ++j) {
        const double* v = &corners[9 * perm[i] + 3 * j];
        const Eigen::Vector3d q = Eigen::Vector3d(v[0], v[1], v[2]) - mean;
        const Eigen::Vector2d r(q.dot(u), q.dot(w));
        cov += r * r.transpose();
      }
    const double angle = 0.5 * std::atan2(2.0 * cov(0, 1), cov(0, 0) - cov(1, 1));
    const Eigen::Vector3d u2 = std::cos(angle) * u + std::sin(angle) * w;
    const Eigen::Vector3d w2 = n.cross(u2);
    Node o{};
    for (int k = 0; k < 3; ++k) {
      o.a[k] = static_cast<float>(n[k]);
      o.a[3 + k] = static_cast<float>(u2[k]);
      o.a[6 + k] = static_cast<float>(w2[k]);
    }
    // Centre: the middle of the corners' span along each axis.
    Eigen::Vector3d tmin = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()),
                    tmax = -tmin;
    const Eigen::Matrix3d R = (Eigen::Matrix3d() << n.transpose(), u2.transpose(), w2.transpose()).finished();
    for (std::uint32_t i = begin; i < end; ++i)
      for (std::size_t j = 0; j < 3; ++j) {
        const double* v = &corners[9 * perm[i] + 3 * j];
        const Eigen::Vector3d t = R * Eigen::Vector3d(v[0], v[1], v[2]);
        tmin = tmin.cwiseMin(t);
        tmax = tmax.cwiseMax(t);
      }
    const Eigen::Vector3d centre = R.transpose() * (0.5 * (tmin + tmax));
    for (int k = 0; k < 3; ++k) o.c[k] = static_cast<float>(centre[k]);
    extents(o.a, o.c, corners, perm, begin, end, pad, o.h);
    const auto volume = [](const Node& x) {
      return static_cast<double>(x.h[0]) * static_cast<double>(x.h[1]) * static_cast<double>(x.h[2]);
    };
    if (nearly_orthonormal(o.a) && volume(o) < volume(best)) best = o;
  }

  constexpr std::uint32_t kLeafSize = kBlock;  // a leaf fills at most one block of slots
  if (end - begin <= kLeafSize) {
    best.packed = (begin << 3) | (end - begin);  // local slot, made global by build()
    nodes_[self] = best;
    return self;
  }
  // Split near the median along the longest centroid extent; ties in position broken by index so the
  // tree does not depend on the standard library's nth_element.
  int axis = 0;
  const Eigen::Vector3d ext = chi - clo;
  if (ext[1] > ext[axis]) axis = 1;
  if (ext[2] > ext[axis]) axis = 2;
  // Left gets a multiple of the leaf size, so leaves are full (blocks of 4 slots well used).
  const std::uint32_t mid = begin + kLeafSize * ((end - begin + 2 * kLeafSize - 1) / (2 * kLeafSize));
  std::nth_element(perm.begin() + begin, perm.begin() + mid, perm.begin() + end,
                   [&](std::uint32_t x, std::uint32_t y) {
                     const double cx = cent[3 * x + static_cast<std::uint32_t>(axis)];
                     const double cy = cent[3 * y + static_cast<std::uint32_t>(axis)];
                     return cx < cy || (cx == cy && x < y);
                   });
  build_node(begin, mid, cent, perm, corners, pad);  // left = self + 1
  const std::uint32_t right = build_node(mid, end, cent, perm, corners, pad);
  best.packed = right << 3;
  nodes_[self] = best;
  return self;
}

std::uint32_t ColliderSet::collapse(std::uint32_t b) {
  // Open the inner child with the largest box until there are 4 children (or only leaves).
  std::uint32_t kids[4] = {b + 1, nodes_[b].index(), 0, 0};
  std::uint32_t n = 2;
  const auto size = [&](std::uint32_t i) {
    const Node& x = nodes_[i];
    return static_cast<double>(x.h[0]) + static_cast<double>(x.h[1]) + static_cast<double>(x.h[2]);
  };
  while (n < 4) {
    int open = -1;
    for (std::uint32_t k = 0; k < n; ++k)
      if (!nodes_[kids[k]].leaf() && (open < 0 || size(kids[k]) > size(kids[open])))
        open = static_cast<int>(k);
    if (open < 0) break;
    const std::uint32_t i = kids[open];
    kids[open] = i + 1;
    kids[n++] = nodes_[i].index();
  }
  const auto self = static_cast<std::uint32_t>(nodes4_.size());
  nodes4_.push_back(Node4{});
  Node4 q{};
  for (std::uint32_t k = 0; k < 4; ++k) {
    if (k >= n) {  // an empty lane: an inverted box, infinitely far
      for (int j = 0; j < 3; ++j) q.h[j][k] = -std::numeric_limits<float>::max();
      q.child[k] = 0;
      continue;
    }
    const Node& x = nodes_[kids[k]];
    for (int j = 0; j < 3; ++j) q.c[j][k] = x.c[j], q.h[j][k] = x.h[j];
    for (int j = 0; j < 9; ++j) q.a[j][k] = x.a[j];
    q.child[k] = x.leaf() ? x.packed : collapse(kids[k]) << 3;
  }
  nodes4_[self] = q;
  return self;
}

}  // namespace clothsim
