// Convex hulls of small point sets (up to a few thousand points) in the plane and in space, for
// the flow manipulability polytope (flow_polytope.hpp), inside the control cycle: the storage is
// sized once, in the constructor; build() allocates nothing and throws nothing.
//
// 2-D: Andrew's monotone chain. 3-D: Quickhull (C. B. Barber, D. P. Dobkin and H. Huhdanpaa,
// "The quickhull algorithm for convex hulls", ACM TOMS 1996) on a triangle mesh with face
// adjacency: each face keeps the points above it, the furthest of them is added next, the faces
// it sees (grown from one face across neighbours) are replaced by a cone over their horizon.
// Points within the tolerance of a face count as on it (1e-10 of the points' extent): a hull of
// points that are coplanar up to rounding (common here: a box's faces mapped linearly) then has
// no sliver faces, and the volume it leaves out is below the tolerance times the surface.
//
// Why not Qhull (libqhull-dev): it allocates through its own memory manager and reports errors
// by longjmp, neither of which the control cycle may do; for the point counts here a focused
// implementation is small, and tests/dynamics/test_flow_polytope.cpp checks it against brute force.
//
// A point set of lower dimension (all points on a plane, a line, or one point) has volume 0: the
// 3-D hull then gives the polygon in that plane (its area), or the two ends of the segment.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <span>
#include <vector>

namespace craneassist::dynamics {

// Relative tolerance of both hulls: a point this share of the points' extent (largest absolute
// coordinate) above a face or an edge is outside.
inline constexpr double kHullTolerance = 1e-10;

class ConvexHull2 {
 public:
  explicit ConvexHull2(int max_points);

  // The hull of points[0..count). Returns its dimension: 2 (a polygon), 1 (a segment), 0 (a
  // point), -1 (no points).
  int build(std::span<const Eigen::Vector2d> points) noexcept;

  int dimension() const noexcept { return dimension_; }
  double area() const noexcept { return area_; }
  // Indices into the points of the hull's vertices, counterclockwise (a segment: its two ends).
  std::span<const int> vertices() const noexcept {
    return {order_.data(), static_cast<std::size_t>(vertex_count_)};
  }
  // Largest s >= 0 with s u inside the polygon, for the origin inside or on it (0 for a
  // polygon that does not contain the origin in direction u, and for dimension < 2).
  double ray_length(const Eigen::Vector2d& u) const noexcept;
  // The largest distance of p beyond an edge's line (<= 0: inside).
  double outside_distance(const Eigen::Vector2d& p) const noexcept;
  double tolerance() const noexcept { return tolerance_; }

 private:
  int max_points_;
  std::vector<Eigen::Vector2d> points_;  // a copy, so later queries need no caller storage
  std::vector<int> sorted_;
  std::vector<int> order_;  // hull vertices, counterclockwise
  int vertex_count_ = 0;
  int dimension_ = -1;
  double area_ = 0.0;
  double tolerance_ = 0.0;
};

class ConvexHull3 {
 public:
  explicit ConvexHull3(int max_points);

  // The hull of points[0..count). Returns its dimension: 3 (a solid), 2 (flat: a polygon), 1,
  // 0, or -1 (no points).
  int build(std::span<const Eigen::Vector3d> points) noexcept;

  int dimension() const noexcept { return dimension_; }
  double volume() const noexcept { return volume_; }
  // The area of a flat hull (dimension 2) in its plane; 0 otherwise.
  double flat_area() const noexcept { return dimension_ == 2 ? flat_.area() : 0.0; }
  // Indices into the points of the hull's vertices: the polytope's corners, in no particular
  // order (points on its faces and edges are left out); a flat hull's counterclockwise in its
  // plane.
  // Found on the first call after build() (the volume does not need them).
  std::span<const int> vertices() const noexcept;

  // The triangles of a solid hull, outward normals (counterclockwise seen from outside).
  int face_count() const noexcept;
  // Face k (0 <= k < face_count()): vertex indices, unit outward normal n and offset d of its
  // plane n.x = d.
  std::array<int, 3> face(int k) const noexcept;
  Eigen::Vector3d face_normal(int k) const noexcept;
  double face_offset(int k) const noexcept;

  // Largest s >= 0 with s u inside the hull, for the origin inside or on it (a flat hull: 0
  // unless u lies in its plane). The support of the polytope in direction u is
  // max over the vertices of u.x; this is the other question: how far it reaches along u.
  double ray_length(const Eigen::Vector3d& u) const noexcept;
  // The largest distance of p above a face's plane (<= 0: inside) of a solid hull.
  double outside_distance(const Eigen::Vector3d& p) const noexcept;
  double tolerance() const noexcept { return tolerance_; }
  // Points the construction had to leave out because the faces they see did not form a disc
  // (only from rounding on nearly degenerate input); 0 for every input the tests use.
  int skipped_points() const noexcept { return skipped_; }

 private:
  struct Face {
    std::array<int, 3> v{};
    std::array<int, 3> neighbour{};  // across the edge v[k] -> v[(k + 1) % 3]
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    double offset = 0.0;
    int outside = -1;  // first point of the list of points above this face
    int furthest = -1;
    double furthest_distance = 0.0;
    int stamp = 0;  // visit stamp of the current visibility search
    bool visible = false;
    bool alive = false;
  };
  struct HorizonEdge {
    int from = 0, to = 0;  // counterclockwise as in the visible face
    int outer = 0;         // the face beyond it, which stays
  };

  double distance(const Face& f, int point) const noexcept {
    return f.normal.dot(points_[static_cast<std::size_t>(point)]) - f.offset;
  }
  int new_face(int a, int b, int c) noexcept;
  void set_plane(Face& f) noexcept;
  void assign(int point, const int* faces, int face_count) noexcept;
  void push_pending(int face) noexcept;
  bool add_point(int face, int eye) noexcept;
  void build_lower_dimension(int a, int b, int c, int count) noexcept;
  void finish_solid(const Eigen::Vector3d& centre) noexcept;
  void find_corners() const noexcept;

  int max_points_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<Face> faces_;
  std::vector<int> free_faces_;
  int face_high_ = 0, free_count_ = 0;
  std::vector<int> next_outside_;  // per point: the next point of its face's outside list
  std::vector<int> stack_, visible_, new_faces_, orphans_;
  std::vector<HorizonEdge> horizon_;
  std::vector<int> horizon_from_;  // per point: the horizon edge leaving it (-1: none)
  // The corners: a cache vertices() fills (mutable: found on demand, from the mesh).
  mutable std::vector<int> vertices_;
  mutable std::vector<char> is_vertex_;
  mutable std::vector<Eigen::Vector3d> first_normal_, second_normal_;  // per vertex
  mutable int vertex_count_ = 0;
  mutable bool corners_known_ = false;
  std::vector<Eigen::Vector2d> projected_;  // a flat hull's points in its plane
  ConvexHull2 flat_;
  // A flat hull's plane n.x = d and the orthonormal axes e1, e2 in it (2-D coordinates x.e1,
  // x.e2, so the 3-D origin projects to the 2-D origin).
  Eigen::Vector3d flat_normal_ = Eigen::Vector3d::Zero();
  double flat_offset_ = 0.0;
  Eigen::Vector3d flat_e1_ = Eigen::Vector3d::Zero(), flat_e2_ = Eigen::Vector3d::Zero();
  std::vector<int> alive_faces_;  // after build(): the faces of the hull
  int alive_count_ = 0;
  std::vector<int> pending_;  // faces that may have outside points
  int pending_count_ = 0;
  bool pending_overflow_ = false;
  int dimension_ = -1;
  double volume_ = 0.0;
  double tolerance_ = 0.0;
  int stamp_ = 0;
  int skipped_ = 0;
};

}  // namespace craneassist::dynamics
