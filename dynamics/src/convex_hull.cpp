#include "craneassist/dynamics/convex_hull.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace craneassist::dynamics {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// A mesh vertex is a corner of the polytope when three of its faces' unit normals span a volume
// (determinant) above this; nearly coplanar faces from rounding stay far below it.
constexpr double kCornerSine = 1e-7;

std::size_t at(int i) {
  return static_cast<std::size_t>(i);
}

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Distance of p from the segment [a, b].
template <class V>
double segment_distance(const V& p, const V& a, const V& b) {
  const V d = b - a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * d)).norm();
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// 2-D

ConvexHull2::ConvexHull2(int max_points)
    : max_points_(std::max(max_points, 1)),
      points_(at(max_points_)),
      sorted_(at(max_points_)),
      order_(at(2 * max_points_ + 1)) {}

int ConvexHull2::build(std::span<const Eigen::Vector2d> points) noexcept {
  const int n = std::min(static_cast<int>(points.size()), max_points_);
  vertex_count_ = 0;
  area_ = 0.0;
  dimension_ = -1;
  if (n == 0) return dimension_;
  double scale = 0.0;
  for (int i = 0; i < n; ++i) {
    points_[at(i)] = points[at(i)];
    sorted_[at(i)] = i;
    scale = std::max(scale, points[at(i)].cwiseAbs().maxCoeff());
  }
  tolerance_ = kHullTolerance * scale;
  // std::sort works in place: no allocation.
  std::sort(sorted_.begin(), sorted_.begin() + n, [&](int a, int b) {
    const auto &p = points_[at(a)], &q = points_[at(b)];
    return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y());
  });
  // The last vertex a stays only where the chain o -> a -> b turns left by more than the
  // tolerance (a further than that from the line o b), so collinear points are left out.
  auto keeps = [&](int o, int a, int b) {
    const Eigen::Vector2d ob = points_[at(b)] - points_[at(o)];
    return cross2(points_[at(a)] - points_[at(o)], ob) > tolerance_ * ob.norm();
  };
  int k = 0;
  for (int s = 0; s < n; ++s) {  // lower chain, left to right
    const int i = sorted_[at(s)];
    while (k >= 2 && !keeps(order_[at(k - 2)], order_[at(k - 1)], i)) --k;
    order_[at(k++)] = i;
  }
  const int lower = k + 1;
  for (int s = n - 2; s >= 0; --s) {  // upper chain, right to left
    const int i = sorted_[at(s)];
    while (k >= lower && !keeps(order_[at(k - 2)], order_[at(k - 1)], i)) --k;
    order_[at(k++)] = i;
  }
  // Counterclockwise; the last point repeats the first.
  vertex_count_ = std::max(k - 1, 1);
  if (vertex_count_ >= 3) {
    double twice = 0.0;
    for (int v = 0; v < vertex_count_; ++v) {
      twice += cross2(points_[at(order_[at(v)])], points_[at(order_[at((v + 1) % vertex_count_)])]);
    }
    area_ = 0.5 * twice;
    dimension_ = 2;
  } else {
    // All points on a line: its two ends (the extremes of the sort), or one point.
    const Eigen::Vector2d& first = points_[at(sorted_[0])];
    const Eigen::Vector2d& last = points_[at(sorted_[at(n - 1)])];
    order_[0] = sorted_[0];
    order_[1] = sorted_[at(n - 1)];
    const bool one_point = (last - first).norm() <= tolerance_;
    vertex_count_ = one_point ? 1 : 2;
    dimension_ = one_point ? 0 : 1;
  }
  return dimension_;
}

double ConvexHull2::ray_length(const Eigen::Vector2d& u) const noexcept {
  if (dimension_ < 2) return 0.0;
  double s = kInf;
  for (int v = 0; v < vertex_count_; ++v) {
    const Eigen::Vector2d& a = points_[at(order_[at(v)])];
    const Eigen::Vector2d& b = points_[at(order_[at((v + 1) % vertex_count_)])];
    const Eigen::Vector2d normal = Eigen::Vector2d(b.y() - a.y(), a.x() - b.x()).normalized();
    const double along = normal.dot(u);
    if (along > 1e-300) s = std::min(s, std::max(normal.dot(a), 0.0) / along);
  }
  return std::isfinite(s) ? s : 0.0;
}

double ConvexHull2::outside_distance(const Eigen::Vector2d& p) const noexcept {
  if (dimension_ < 0) return kInf;
  if (dimension_ < 2) {
    return segment_distance(p, points_[at(order_[0])], points_[at(order_[at(vertex_count_ - 1)])]);
  }
  double worst = -kInf;
  for (int v = 0; v < vertex_count_; ++v) {
    const Eigen::Vector2d& a = points_[at(order_[at(v)])];
    const Eigen::Vector2d& b = points_[at(order_[at((v + 1) % vertex_count_)])];
    const Eigen::Vector2d normal = Eigen::Vector2d(b.y() - a.y(), a.x() - b.x()).normalized();
    worst = std::max(worst, normal.dot(p - a));
  }
  return worst;
}

// ---------------------------------------------------------------------------------------------
// 3-D

ConvexHull3::ConvexHull3(int max_points)
    : max_points_(std::max(max_points, 4)),
      points_(at(max_points_)),
      // A closed triangle mesh on V vertices has 2V - 4 faces; the visible faces are freed
      // before the cone over their horizon is made, so this never runs out.
      faces_(at(2 * max_points_ + 8)),
      free_faces_(faces_.size()),
      next_outside_(at(max_points_)),
      stack_(faces_.size()),
      visible_(faces_.size()),
      new_faces_(at(max_points_)),
      orphans_(at(max_points_)),
      horizon_(at(max_points_)),
      horizon_from_(at(max_points_), -1),
      vertices_(at(max_points_)),
      is_vertex_(at(max_points_)),
      first_normal_(at(max_points_)),
      second_normal_(at(max_points_)),
      projected_(at(max_points_)),
      flat_(max_points_),
      alive_faces_(faces_.size()),
      pending_(faces_.size()) {}

int ConvexHull3::new_face(int a, int b, int c) noexcept {
  int index;
  if (free_count_ > 0) {
    index = free_faces_[at(--free_count_)];
  } else if (face_high_ < static_cast<int>(faces_.size())) {
    index = face_high_++;
  } else {
    return -1;
  }
  Face& f = faces_[at(index)];
  f = Face{};
  f.v = {a, b, c};
  f.neighbour = {-1, -1, -1};
  f.alive = true;
  set_plane(f);
  return index;
}

void ConvexHull3::set_plane(Face& f) noexcept {
  const Eigen::Vector3d& a = points_[at(f.v[0])];
  const Eigen::Vector3d& b = points_[at(f.v[1])];
  const Eigen::Vector3d& c = points_[at(f.v[2])];
  Eigen::Vector3d n = (b - a).cross(c - a);
  const double len = n.norm();
  f.normal = len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
  f.offset = f.normal.dot((a + b + c) / 3.0);
}

void ConvexHull3::push_pending(int face) noexcept {
  if (pending_count_ < static_cast<int>(pending_.size())) {
    pending_[at(pending_count_++)] = face;
  } else {
    pending_overflow_ = true;
  }
}

void ConvexHull3::assign(int point, const int* faces, int face_count) noexcept {
  for (int k = 0; k < face_count; ++k) {
    Face& f = faces_[at(faces[k])];
    const double d = distance(f, point);
    if (d > tolerance_) {
      if (f.outside < 0) push_pending(faces[k]);
      next_outside_[at(point)] = f.outside;
      f.outside = point;
      if (f.furthest < 0 || d > f.furthest_distance) {
        f.furthest = point;
        f.furthest_distance = d;
      }
      return;
    }
  }
  // Inside (or within the tolerance of) the hull so far: never a vertex.
}

int ConvexHull3::build(std::span<const Eigen::Vector3d> points) noexcept {
  const int n = std::min(static_cast<int>(points.size()), max_points_);
  face_high_ = free_count_ = 0;
  alive_count_ = vertex_count_ = 0;
  volume_ = 0.0;
  skipped_ = 0;
  stamp_ = 0;  // every face of this build starts at stamp 0 (new_face)
  pending_count_ = 0;
  pending_overflow_ = false;
  dimension_ = -1;
  if (n == 0) return dimension_;
  double scale = 0.0;
  for (int i = 0; i < n; ++i) {
    points_[at(i)] = points[at(i)];
    scale = std::max(scale, points[at(i)].cwiseAbs().maxCoeff());
  }
  tolerance_ = kHullTolerance * scale;
  const auto& p = points_;

  // The initial simplex: the two furthest apart of the six axis extremes, the point furthest
  // from their line, the point furthest from the plane of the three.
  std::array<int, 6> extreme{};
  for (int axis = 0; axis < 3; ++axis) {
    int lo = 0, hi = 0;
    for (int i = 1; i < n; ++i) {
      if (p[at(i)][axis] < p[at(lo)][axis]) lo = i;
      if (p[at(i)][axis] > p[at(hi)][axis]) hi = i;
    }
    extreme[at(2 * axis)] = lo;
    extreme[at(2 * axis + 1)] = hi;
  }
  int a = extreme[0], b = extreme[1];
  double best = -1.0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i + 1; j < 6; ++j) {
      const double d = (p[at(extreme[at(i)])] - p[at(extreme[at(j)])]).norm();
      if (d > best) {
        best = d;
        a = extreme[at(i)];
        b = extreme[at(j)];
      }
    }
  }
  if (best <= tolerance_) {
    dimension_ = 0;
    vertices_[0] = a;
    vertex_count_ = 1;
    return dimension_;
  }
  const Eigen::Vector3d dir = (p[at(b)] - p[at(a)]).normalized();
  int c = a;
  best = -1.0;
  for (int i = 0; i < n; ++i) {
    const double d = (p[at(i)] - p[at(a)]).cross(dir).norm();
    if (d > best) {
      best = d;
      c = i;
    }
  }
  if (best <= tolerance_) {
    build_lower_dimension(a, b, -1, n);
    return dimension_;
  }
  const Eigen::Vector3d normal = (p[at(b)] - p[at(a)]).cross(p[at(c)] - p[at(a)]).normalized();
  int d = a;
  best = -1.0;
  for (int i = 0; i < n; ++i) {
    const double h = std::abs(normal.dot(p[at(i)] - p[at(a)]));
    if (h > best) {
      best = h;
      d = i;
    }
  }
  if (best <= tolerance_) {
    build_lower_dimension(a, b, c, n);
    return dimension_;
  }

  // The tetrahedron, outward faces: d lies below the plane of (a, b, c).
  if (normal.dot(p[at(d)] - p[at(a)]) > 0.0) std::swap(b, c);
  const std::array<std::array<int, 3>, 4> tetra{{{a, b, c}, {a, d, b}, {b, d, c}, {c, d, a}}};
  std::array<int, 4> start{};
  for (int k = 0; k < 4; ++k)
    start[at(k)] = new_face(tetra[at(k)][0], tetra[at(k)][1], tetra[at(k)][2]);
  // Neighbours: the face holding each edge reversed.
  for (int f = 0; f < 4; ++f) {
    Face& face = faces_[at(start[at(f)])];
    for (int k = 0; k < 3; ++k) {
      const int from = face.v[at(k)], to = face.v[at((k + 1) % 3)];
      for (int g = 0; g < 4; ++g) {
        const Face& other = faces_[at(start[at(g)])];
        for (int m = 0; m < 3; ++m) {
          if (other.v[at(m)] == to && other.v[at((m + 1) % 3)] == from) {
            face.neighbour[at(k)] = start[at(g)];
          }
        }
      }
    }
  }
  const Eigen::Vector3d centre = (p[at(a)] + p[at(b)] + p[at(c)] + p[at(d)]) / 4.0;
  for (int i = 0; i < n; ++i) {
    if (i != a && i != b && i != c && i != d) assign(i, start.data(), 4);
  }

  // Add the furthest outside point of a face with outside points until none has any. The faces
  // wait on a stack (assign() pushes a face when it gets its first point); should the stack
  // ever fill, a scan over all faces refills it.
  for (;;) {
    while (pending_count_ > 0) {
      const int f = pending_[at(--pending_count_)];
      const Face& face = faces_[at(f)];
      if (!face.alive || face.outside < 0) continue;
      if (!add_point(f, face.furthest) && skipped_ > n) break;  // no progress: give up
      if (faces_[at(f)].alive && faces_[at(f)].outside >= 0) push_pending(f);  // eye skipped
    }
    if (!pending_overflow_ || skipped_ > n) break;
    pending_overflow_ = false;
    for (int f = 0; f < face_high_; ++f) {
      if (faces_[at(f)].alive && faces_[at(f)].outside >= 0) push_pending(f);
    }
  }
  finish_solid(centre);
  return dimension_;
}

bool ConvexHull3::add_point(int first, int eye) noexcept {
  // The faces the eye sees, grown across neighbours from the first.
  ++stamp_;
  int top = 0, visible = 0;
  faces_[at(first)].stamp = stamp_;
  faces_[at(first)].visible = true;
  stack_[at(top++)] = first;
  while (top > 0) {
    const int f = stack_[at(--top)];
    visible_[at(visible++)] = f;
    for (const int g : faces_[at(f)].neighbour) {
      Face& other = faces_[at(g)];
      if (other.stamp == stamp_) continue;
      other.stamp = stamp_;
      other.visible = distance(other, eye) > tolerance_;
      if (other.visible) stack_[at(top++)] = g;
    }
  }
  // A face left out but surrounded by visible ones (rounding) would make a hole in the region.
  for (int k = 0; k < visible; ++k) {
    for (const int g : faces_[at(visible_[at(k)])].neighbour) {
      Face& other = faces_[at(g)];
      if (other.visible) continue;
      bool surrounded = true;
      for (const int h : other.neighbour) {
        surrounded = surrounded && faces_[at(h)].stamp == stamp_ && faces_[at(h)].visible;
      }
      if (surrounded) {
        other.visible = true;
        visible_[at(visible++)] = g;
      }
    }
  }

  // The horizon: edges of visible faces whose neighbour is not visible, chained into one loop.
  int edges = 0;
  bool simple = true;
  for (int k = 0; k < visible && simple; ++k) {
    const Face& f = faces_[at(visible_[at(k)])];
    for (int e = 0; e < 3; ++e) {
      const Face& other = faces_[at(f.neighbour[at(e)])];
      if (other.stamp == stamp_ && other.visible) continue;
      if (edges >= static_cast<int>(horizon_.size())) {
        simple = false;
        break;
      }
      horizon_[at(edges)] = {f.v[at(e)], f.v[at((e + 1) % 3)], f.neighbour[at(e)]};
      if (horizon_from_[at(f.v[at(e)])] >= 0) simple = false;  // a vertex twice: not a loop
      horizon_from_[at(f.v[at(e)])] = edges;
      ++edges;
    }
  }
  int loop = 0;
  if (simple && edges >= 3) {
    int e = 0;
    do {
      stack_[at(loop++)] = e;
      e = horizon_from_[at(horizon_[at(e)].to)];
    } while (e > 0 && loop <= edges);
    simple = e == 0 && loop == edges;
  } else {
    simple = false;
  }
  for (int k = 0; k < edges; ++k) horizon_from_[at(horizon_[at(k)].from)] = -1;
  if (!simple) {
    // Leave the eye out: take it off the first face's list.
    Face& f = faces_[at(first)];
    int* link = &f.outside;
    while (*link >= 0 && *link != eye) link = &next_outside_[at(*link)];
    if (*link == eye) *link = next_outside_[at(eye)];
    f.furthest = -1;
    f.furthest_distance = 0.0;
    for (int q = f.outside; q >= 0; q = next_outside_[at(q)]) {
      const double d = distance(f, q);
      if (f.furthest < 0 || d > f.furthest_distance) {
        f.furthest = q;
        f.furthest_distance = d;
      }
    }
    ++skipped_;
    return false;
  }

  // The points above the visible faces must find new faces; the visible faces go.
  int orphans = 0;
  for (int k = 0; k < visible; ++k) {
    Face& f = faces_[at(visible_[at(k)])];
    for (int q = f.outside; q >= 0; q = next_outside_[at(q)]) {
      if (q != eye) orphans_[at(orphans++)] = q;
    }
    f.alive = false;
    f.visible = false;
    free_faces_[at(free_count_++)] = visible_[at(k)];
  }
  // The cone from the eye over the horizon, in loop order: face j holds edge j and the eye; its
  // neighbours are the outer face and the cone faces before and after it.
  for (int j = 0; j < loop; ++j) {
    const HorizonEdge& e = horizon_[at(stack_[at(j)])];
    const int nf = new_face(e.from, e.to, eye);
    if (nf < 0) {  // cannot happen with the sizes of the constructor
      skipped_ = max_points_ + 1;
      return false;
    }
    faces_[at(nf)].neighbour[0] = e.outer;
    Face& outer = faces_[at(e.outer)];
    for (int m = 0; m < 3; ++m) {
      if (outer.v[at(m)] == e.to && outer.v[at((m + 1) % 3)] == e.from) {
        outer.neighbour[at(m)] = nf;
      }
    }
    new_faces_[at(j)] = nf;
  }
  for (int j = 0; j < loop; ++j) {
    Face& f = faces_[at(new_faces_[at(j)])];
    f.neighbour[1] = new_faces_[at((j + 1) % loop)];
    f.neighbour[2] = new_faces_[at((j + loop - 1) % loop)];
  }
  for (int k = 0; k < orphans; ++k) assign(orphans_[at(k)], new_faces_.data(), loop);
  return true;
}

void ConvexHull3::finish_solid(const Eigen::Vector3d& centre) noexcept {
  double six_volume = 0.0;
  for (int f = 0; f < face_high_; ++f) {
    const Face& face = faces_[at(f)];
    if (!face.alive) continue;
    alive_faces_[at(alive_count_++)] = f;
    const Eigen::Vector3d a = points_[at(face.v[0])] - centre;
    const Eigen::Vector3d b = points_[at(face.v[1])] - centre;
    const Eigen::Vector3d c = points_[at(face.v[2])] - centre;
    six_volume += a.dot(b.cross(c));
  }
  volume_ = six_volume / 6.0;
  dimension_ = 3;

  corners_known_ = false;  // vertices() finds them when asked
}

std::span<const int> ConvexHull3::vertices() const noexcept {
  if (dimension_ == 3 && !corners_known_) find_corners();
  return {vertices_.data(), static_cast<std::size_t>(vertex_count_)};
}

void ConvexHull3::find_corners() const noexcept {
  // A mesh vertex can lie on a flat face or a straight edge of the polytope (it was outside the
  // hull when it was added, and points added later made its faces coplanar): its faces then
  // have normals in at most two directions. A corner of the polytope has three independent
  // ones. Two passes over the faces: each vertex's first normal and the one most across it,
  // then whether any third normal leaves their plane.
  vertex_count_ = 0;
  std::fill(is_vertex_.begin(), is_vertex_.end(), 0);  // 0 none, 1 in the mesh, 2 a corner
  for (int k = 0; k < alive_count_; ++k) {
    const Face& face = faces_[at(alive_faces_[at(k)])];
    for (const int v : face.v) {
      if (is_vertex_[at(v)] == 0) {
        is_vertex_[at(v)] = 1;
        first_normal_[at(v)] = face.normal;
        second_normal_[at(v)] = face.normal;
      } else {
        const double across = first_normal_[at(v)].cross(face.normal).squaredNorm();
        if (across > first_normal_[at(v)].cross(second_normal_[at(v)]).squaredNorm()) {
          second_normal_[at(v)] = face.normal;
        }
      }
    }
  }
  for (int k = 0; k < alive_count_; ++k) {
    const Face& face = faces_[at(alive_faces_[at(k)])];
    for (const int v : face.v) {
      if (is_vertex_[at(v)] != 1) continue;
      const Eigen::Vector3d plane = first_normal_[at(v)].cross(second_normal_[at(v)]);
      if (std::abs(plane.dot(face.normal)) > kCornerSine) {
        is_vertex_[at(v)] = 2;
        vertices_[at(vertex_count_++)] = v;
      }
    }
  }
  corners_known_ = true;
}

void ConvexHull3::build_lower_dimension(int a, int b, int c, int count) noexcept {
  const auto& p = points_;
  if (c < 0) {
    // On a line: its two extremes along it.
    const Eigen::Vector3d dir = (p[at(b)] - p[at(a)]).normalized();
    int lo = 0, hi = 0;
    for (int i = 1; i < count; ++i) {
      if (p[at(i)].dot(dir) < p[at(lo)].dot(dir)) lo = i;
      if (p[at(i)].dot(dir) > p[at(hi)].dot(dir)) hi = i;
    }
    vertices_[0] = lo;
    vertices_[1] = hi;
    vertex_count_ = 2;
    dimension_ = 1;
    return;
  }
  // In a plane: the polygon in 2-D coordinates on orthonormal axes of the plane.
  flat_normal_ = (p[at(b)] - p[at(a)]).cross(p[at(c)] - p[at(a)]).normalized();
  flat_offset_ = flat_normal_.dot(p[at(a)]);
  flat_e1_ = (p[at(b)] - p[at(a)]).normalized();
  flat_e2_ = flat_normal_.cross(flat_e1_);
  for (int i = 0; i < count; ++i) {
    projected_[at(i)] = Eigen::Vector2d(p[at(i)].dot(flat_e1_), p[at(i)].dot(flat_e2_));
  }
  flat_.build(std::span<const Eigen::Vector2d>(projected_.data(), at(count)));
  const auto v = flat_.vertices();
  vertex_count_ = static_cast<int>(v.size());
  std::copy(v.begin(), v.end(), vertices_.begin());
  dimension_ = 2;
}

int ConvexHull3::face_count() const noexcept {
  return dimension_ == 3 ? alive_count_ : 0;
}

std::array<int, 3> ConvexHull3::face(int k) const noexcept {
  return faces_[at(alive_faces_[at(k)])].v;
}

Eigen::Vector3d ConvexHull3::face_normal(int k) const noexcept {
  return faces_[at(alive_faces_[at(k)])].normal;
}

double ConvexHull3::face_offset(int k) const noexcept {
  return faces_[at(alive_faces_[at(k)])].offset;
}

double ConvexHull3::ray_length(const Eigen::Vector3d& u) const noexcept {
  if (dimension_ == 2) {
    // Along the plane only, and only a plane through the origin.
    const double scale = std::max(u.norm(), 1e-300);
    if (std::abs(flat_normal_.dot(u)) > 1e-9 * scale || std::abs(flat_offset_) > tolerance_) {
      return 0.0;
    }
    return flat_.ray_length(Eigen::Vector2d(u.dot(flat_e1_), u.dot(flat_e2_)));
  }
  if (dimension_ != 3) return 0.0;
  double s = kInf;
  for (int k = 0; k < alive_count_; ++k) {
    const Face& f = faces_[at(alive_faces_[at(k)])];
    const double along = f.normal.dot(u);
    if (along > 1e-300) s = std::min(s, std::max(f.offset, 0.0) / along);
  }
  return std::isfinite(s) ? s : 0.0;
}

double ConvexHull3::outside_distance(const Eigen::Vector3d& x) const noexcept {
  switch (dimension_) {
    case 3: {
      double worst = -kInf;
      for (int k = 0; k < alive_count_; ++k) {
        const Face& f = faces_[at(alive_faces_[at(k)])];
        worst = std::max(worst, f.normal.dot(x) - f.offset);
      }
      return worst;
    }
    case 2:
      return std::max(std::abs(flat_normal_.dot(x) - flat_offset_),
                      flat_.outside_distance(Eigen::Vector2d(x.dot(flat_e1_), x.dot(flat_e2_))));
    case 1:
      return segment_distance(x, points_[at(vertices_[0])], points_[at(vertices_[1])]);
    case 0:
      return (x - points_[at(vertices_[0])]).norm();
    default:
      return kInf;
  }
}

}  // namespace craneassist::dynamics
