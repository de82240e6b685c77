// The building blocks of the flow manipulability polytope: the 2-D and 3-D convex hulls
// (convex_hull.hpp) against brute force and known shapes, and the dense simplex (small_lp.hpp)
// against textbook problems (one that cycles without Bland's rule) and brute-force vertex
// enumeration.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include "craneassist/dynamics/convex_hull.hpp"
#include "craneassist/dynamics/small_lp.hpp"

using namespace craneassist::dynamics;

namespace {

std::span<const Eigen::Vector3d> view(const std::vector<Eigen::Vector3d>& p) {
  return {p.data(), p.size()};
}
std::span<const Eigen::Vector2d> view(const std::vector<Eigen::Vector2d>& p) {
  return {p.data(), p.size()};
}

// The volume of the convex hull of p by brute force, independent of the Quickhull mesh: every
// plane through three points with all points on one side is a facet plane; the facet is the 2-D
// hull of the points on it, and the volume is the sum of the pyramids from the centroid.
double brute_force_volume(const std::vector<Eigen::Vector3d>& p, double tol) {
  const int n = static_cast<int>(p.size());
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& x : p) centre += x;
  centre /= n;
  std::vector<std::pair<Eigen::Vector3d, double>> planes;  // seen facet planes (normal, offset)
  double volume = 0.0;
  ConvexHull2 facet(n);
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      for (int k = j + 1; k < n; ++k) {
        Eigen::Vector3d normal = (p[j] - p[i]).cross(p[k] - p[i]);
        if (normal.norm() < 1e-12) continue;
        normal.normalize();
        double offset = normal.dot(p[i]);
        int above = 0, below = 0;
        for (const auto& x : p) {
          const double d = normal.dot(x) - offset;
          above += d > tol;
          below += d < -tol;
        }
        if (above > 0 && below > 0) continue;
        if (above > 0) {
          normal = -normal;
          offset = -offset;
        }
        bool seen = false;
        for (const auto& [m, o] : planes)
          seen = seen || ((m - normal).norm() < 1e-7 && std::abs(o - offset) < 1e-7);
        if (seen) continue;
        planes.emplace_back(normal, offset);
        const Eigen::Vector3d e1 = (p[j] - p[i]).normalized(), e2 = normal.cross(e1);
        std::vector<Eigen::Vector2d> on;
        for (const auto& x : p) {
          if (std::abs(normal.dot(x) - offset) <= tol) on.emplace_back(x.dot(e1), x.dot(e2));
        }
        facet.build(view(on));
        volume += facet.area() * (offset - normal.dot(centre)) / 3.0;
      }
    }
  }
  return volume;
}

// Every edge of the mesh is shared by exactly two faces, once in each direction, and
// F = 2V - 4 (a closed triangulated sphere; V: the mesh's vertices).
void expect_closed_mesh(const ConvexHull3& hull) {
  std::multiset<std::pair<int, int>> edges;
  std::set<int> mesh_vertices;
  for (int f = 0; f < hull.face_count(); ++f) {
    const auto v = hull.face(f);
    for (int k = 0; k < 3; ++k) {
      edges.insert({v[k], v[(k + 1) % 3]});
      mesh_vertices.insert(v[k]);
    }
  }
  // The corners are mesh vertices.
  for (const int v : hull.vertices()) EXPECT_EQ(mesh_vertices.count(v), 1u);
  for (const auto& [a, b] : edges) {
    EXPECT_EQ(edges.count({a, b}), 1u) << a << "->" << b;
    EXPECT_EQ(edges.count({b, a}), 1u) << b << "->" << a;
  }
  EXPECT_EQ(hull.face_count(), 2 * static_cast<int>(mesh_vertices.size()) - 4);
}

}  // namespace

TEST(ConvexHull3, CubeWithPointsOnItsFacesAndInside) {
  // A 5 x 5 x 5 grid in [-1, 1]^3: many coplanar and collinear points, one hull: the 8 corners.
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) {
      for (int k = 0; k < 5; ++k) p.emplace_back(-1 + 0.5 * i, -1 + 0.5 * j, -1 + 0.5 * k);
    }
  }
  ConvexHull3 hull(static_cast<int>(p.size()));
  ASSERT_EQ(hull.build(view(p)), 3);
  EXPECT_NEAR(hull.volume(), 8.0, 1e-12);
  EXPECT_EQ(hull.vertices().size(), 8u);
  for (const int v : hull.vertices()) EXPECT_DOUBLE_EQ(p[v].cwiseAbs().minCoeff(), 1.0);
  EXPECT_EQ(hull.skipped_points(), 0);
  expect_closed_mesh(hull);
  EXPECT_NEAR(hull.ray_length(Eigen::Vector3d(1, 0, 0)), 1.0, 1e-12);
  EXPECT_NEAR(hull.ray_length(Eigen::Vector3d(1, 1, 1).normalized()), std::sqrt(3.0), 1e-12);
}

TEST(ConvexHull3, RandomCloudsAgainstBruteForce) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_int_distribution<int> size(4, 40);
  for (int trial = 0; trial < 60; ++trial) {
    const int n = size(rng);
    std::vector<Eigen::Vector3d> p;
    for (int i = 0; i < n; ++i) {
      Eigen::Vector3d x(normal(rng), normal(rng), normal(rng));
      if (trial % 3 == 1) x.normalize();  // every point on the sphere: all are vertices
      if (trial % 3 == 2) x = x.cwiseProduct(Eigen::Vector3d(3.0, 0.01, 1.0));  // a thin slab
      p.push_back(x);
    }
    ConvexHull3 hull(n);
    ASSERT_EQ(hull.build(view(p)), 3) << trial;
    EXPECT_EQ(hull.skipped_points(), 0) << trial;
    expect_closed_mesh(hull);
    const double tol = hull.tolerance();
    for (const auto& x : p) EXPECT_LE(hull.outside_distance(x), 2 * tol) << trial;
    // Every vertex is extreme: outside the hull of the other points.
    for (const int v : hull.vertices()) {
      std::vector<Eigen::Vector3d> others;
      for (int i = 0; i < n; ++i) {
        if (i != v) others.push_back(p[i]);
      }
      ConvexHull3 rest(n);
      if (rest.build(view(others)) == 3) {
        EXPECT_GT(rest.outside_distance(p[v]), tol) << trial;
      }
    }
    if (trial % 3 == 1) {
      EXPECT_EQ(hull.vertices().size(), static_cast<std::size_t>(n));
    }
    EXPECT_NEAR(hull.volume(), brute_force_volume(p, tol), 1e-9 * hull.volume()) << trial;
  }
}

TEST(ConvexHull3, LinearImageOfABoxWithRounding) {
  // The corners and face centres of a box mapped by a random matrix: the volume is |det| times
  // the box's, whatever the rounding of the coplanar face points.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::Matrix3d m;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m(r, c) = u(rng);
    }
    const Eigen::Vector3d size(0.1 + std::abs(u(rng)), 0.1 + std::abs(u(rng)), 0.3);
    std::vector<Eigen::Vector3d> p;
    for (int i = -2; i <= 2; ++i) {
      for (int j = -2; j <= 2; ++j) {
        for (int k = -2; k <= 2; ++k) {
          p.push_back(m * Eigen::Vector3d(i, j, k).cwiseProduct(size) / 2.0);
        }
      }
    }
    ConvexHull3 hull(static_cast<int>(p.size()));
    ASSERT_EQ(hull.build(view(p)), 3);
    const double expected = std::abs(m.determinant()) * 8.0 * size.prod();
    EXPECT_NEAR(hull.volume(), expected, 1e-9 * expected) << trial;
    EXPECT_EQ(hull.vertices().size(), 8u) << trial;
    EXPECT_EQ(hull.skipped_points(), 0);
    expect_closed_mesh(hull);
  }
}

TEST(ConvexHull3, LowerDimensionsHaveNoVolumeAndNoNan) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d e1 = Eigen::Vector3d(1, 2, 3).normalized();
  const Eigen::Vector3d e2 = e1.unitOrthogonal();
  // A flat square of side 2 (corners and random points inside) in a tilted plane through 0.
  std::vector<Eigen::Vector3d> flat;
  for (const double a : {-1.0, 1.0}) {
    for (const double b : {-1.0, 1.0}) flat.push_back(a * e1 + b * e2);
  }
  for (int i = 0; i < 30; ++i) flat.push_back(u(rng) * e1 + u(rng) * e2);
  ConvexHull3 hull(64);
  EXPECT_EQ(hull.build(view(flat)), 2);
  EXPECT_EQ(hull.volume(), 0.0);
  EXPECT_NEAR(hull.flat_area(), 4.0, 1e-12);
  EXPECT_EQ(hull.vertices().size(), 4u);
  EXPECT_NEAR(hull.ray_length(e1), 1.0, 1e-12);   // in the plane
  EXPECT_EQ(hull.ray_length(e1.cross(e2)), 0.0);  // out of it
  EXPECT_LE(hull.outside_distance(0.5 * e1), hull.tolerance());
  // On a line, one point, none.
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 10; ++i) line.push_back((i - 3.0) * e1);
  EXPECT_EQ(hull.build(view(line)), 1);
  EXPECT_EQ(hull.volume(), 0.0);
  EXPECT_EQ(hull.flat_area(), 0.0);
  ASSERT_EQ(hull.vertices().size(), 2u);
  EXPECT_NEAR((line[hull.vertices()[0]] - line[hull.vertices()[1]]).norm(), 9.0, 1e-12);
  std::vector<Eigen::Vector3d> point(5, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(hull.build(view(point)), 0);
  EXPECT_EQ(hull.volume(), 0.0);
  std::vector<Eigen::Vector3d> zero(5, Eigen::Vector3d::Zero());
  EXPECT_EQ(hull.build(view(zero)), 0);
  EXPECT_FALSE(std::isnan(hull.volume()));
  EXPECT_EQ(hull.build(std::span<const Eigen::Vector3d>()), -1);
  EXPECT_EQ(hull.volume(), 0.0);
}

TEST(ConvexHull2, RegularPolygonsWithInteriorAndEdgePoints) {
  for (int sides = 3; sides <= 12; ++sides) {
    std::vector<Eigen::Vector2d> p;
    for (int k = 0; k < sides; ++k) {
      const double a = 2 * std::numbers::pi * k / sides;
      const Eigen::Vector2d v(std::cos(a), std::sin(a));
      const double b = 2 * std::numbers::pi * (k + 1) / sides;
      p.push_back(v);
      p.push_back(0.5 * (v + Eigen::Vector2d(std::cos(b), std::sin(b))));  // on an edge
      p.push_back(0.3 * v);                                                // inside
    }
    ConvexHull2 hull(static_cast<int>(p.size()));
    ASSERT_EQ(hull.build(view(p)), 2);
    EXPECT_NEAR(hull.area(), 0.5 * sides * std::sin(2 * std::numbers::pi / sides), 1e-12);
    EXPECT_EQ(hull.vertices().size(), static_cast<std::size_t>(sides));
    // Counterclockwise.
    const auto v = hull.vertices();
    for (std::size_t k = 0; k < v.size(); ++k) {
      const Eigen::Vector2d a = p[v[k]], b = p[v[(k + 1) % v.size()]], c = p[v[(k + 2) % v.size()]];
      EXPECT_GT((b - a).x() * (c - b).y() - (b - a).y() * (c - b).x(), 0.0);
    }
    const double inner = std::cos(std::numbers::pi / sides);  // the edges' distance from 0
    EXPECT_NEAR(hull.ray_length(Eigen::Vector2d(std::cos(std::numbers::pi / sides),
                                                std::sin(std::numbers::pi / sides))),
                inner, 1e-12);
  }
}

TEST(ConvexHull2, RandomCloudsAgainstBruteForce) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 3 + trial % 40;
    std::vector<Eigen::Vector2d> p;
    for (int i = 0; i < n; ++i) p.emplace_back(normal(rng), normal(rng));
    ConvexHull2 hull(n);
    ASSERT_EQ(hull.build(view(p)), 2);
    // Brute force: a point is a vertex when some line through it has all others strictly on one
    // side; for points in general position, exactly the points with an edge pair (i, j) such
    // that all others lie left of i -> j.
    std::set<int> brute;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        if (i == j) continue;
        bool all_left = true;
        for (int k = 0; k < n && all_left; ++k) {
          if (k == i || k == j) continue;
          const Eigen::Vector2d a = p[j] - p[i], b = p[k] - p[i];
          all_left = a.x() * b.y() - a.y() * b.x() > 0.0;
        }
        if (all_left) {
          brute.insert(i);
          brute.insert(j);
        }
      }
    }
    const auto v = hull.vertices();
    EXPECT_EQ(std::set<int>(v.begin(), v.end()), brute) << trial;
    double twice = 0.0;  // the brute-force vertices' polygon by angle about their centroid
    std::vector<Eigen::Vector2d> ring;
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (const int i : brute) c += p[i] / static_cast<double>(brute.size());
    for (const int i : brute) ring.push_back(p[i]);
    std::sort(ring.begin(), ring.end(), [&](const auto& a, const auto& b) {
      return std::atan2(a.y() - c.y(), a.x() - c.x()) < std::atan2(b.y() - c.y(), b.x() - c.x());
    });
    for (std::size_t k = 0; k < ring.size(); ++k) {
      const auto& a = ring[k];
      const auto& b = ring[(k + 1) % ring.size()];
      twice += a.x() * b.y() - a.y() * b.x();
    }
    EXPECT_NEAR(hull.area(), 0.5 * twice, 1e-12 * std::abs(twice)) << trial;
    for (const auto& x : p) EXPECT_LE(hull.outside_distance(x), 2 * hull.tolerance());
  }
}

TEST(ConvexHull2, CollinearAndSinglePoints) {
  ConvexHull2 hull(16);
  std::vector<Eigen::Vector2d> line;
  for (int i = 0; i < 7; ++i) line.emplace_back(2.0 * i, -1.0 * i);
  EXPECT_EQ(hull.build(view(line)), 1);
  EXPECT_EQ(hull.area(), 0.0);
  EXPECT_EQ(hull.vertices().size(), 2u);
  std::vector<Eigen::Vector2d> one(4, Eigen::Vector2d(0.5, 0.5));
  EXPECT_EQ(hull.build(view(one)), 0);
  EXPECT_EQ(hull.area(), 0.0);
  EXPECT_EQ(hull.ray_length(Eigen::Vector2d(1, 0)), 0.0);
}

TEST(DenseSimplex, TextbookProblem) {
  // max 3x + 5y: x <= 4, 2y <= 12, 3x + 2y <= 18 -> 36 at (2, 6).
  DenseSimplex lp(3, 2);
  lp.reset(3, 2);
  lp.a(0, 0) = 1;
  lp.b(0) = 4;
  lp.a(1, 1) = 2;
  lp.b(1) = 12;
  lp.a(2, 0) = 3;
  lp.a(2, 1) = 2;
  lp.b(2) = 18;
  lp.c(0) = 3;
  lp.c(1) = 5;
  ASSERT_EQ(lp.solve(), LpStatus::kOptimal);
  EXPECT_NEAR(lp.value(), 36.0, 1e-12);
  EXPECT_NEAR(lp.x(0), 2.0, 1e-12);
  EXPECT_NEAR(lp.x(1), 6.0, 1e-12);
}

TEST(DenseSimplex, BealesCyclingExampleTerminates) {
  // E. M. L. Beale (1955): cycles with the largest-coefficient rule; the optimum is 1.25 at
  // x1 = 1, x3 = 1 (0-based here).
  DenseSimplex lp(3, 4);
  lp.reset(3, 4);
  const double a[3][4] = {{0.25, -8, -1, 9}, {0.5, -12, -0.5, 3}, {0, 0, 1, 0}};
  const double b[3] = {0, 0, 1};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 4; ++j) lp.a(i, j) = a[i][j];
    lp.b(i) = b[i];
  }
  lp.c(0) = 0.75;
  lp.c(1) = -20;
  lp.c(2) = 0.5;
  lp.c(3) = -6;
  ASSERT_EQ(lp.solve(), LpStatus::kOptimal);
  EXPECT_NEAR(lp.value(), 1.25, 1e-12);
  EXPECT_NEAR(lp.x(0), 1.0, 1e-12);
  EXPECT_NEAR(lp.x(2), 1.0, 1e-12);
}

TEST(DenseSimplex, Unbounded) {
  DenseSimplex lp(1, 2);
  lp.reset(1, 2);
  lp.a(0, 0) = 1;
  lp.a(0, 1) = -1;
  lp.b(0) = 1;
  lp.c(1) = 1;
  EXPECT_EQ(lp.solve(), LpStatus::kUnbounded);
}

TEST(DenseSimplex, RandomProblemsAgainstVertexEnumeration) {
  // Every vertex of {A x <= b, x >= 0} is where `cols` of the constraints are tight; the best
  // feasible one is the optimum (bounded: every variable has a positive row).
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.0, 2.0);
  for (int trial = 0; trial < 300; ++trial) {
    const int cols = 2 + trial % 2, rows = 3 + trial % 5;
    Eigen::MatrixXd a(rows + cols, cols);
    Eigen::VectorXd b(rows + cols), c(cols);
    for (int i = 0; i < rows; ++i) {
      for (int j = 0; j < cols; ++j) a(i, j) = u(rng);
      b[i] = trial % 4 == 0 && i == 0 ? 0.0 : pos(rng);  // some degenerate
    }
    for (int j = 0; j < cols; ++j) {  // a box keeps it bounded
      a.row(rows - 1 - j).setZero();
      a(rows - 1 - j, j) = 1.0;
      c[j] = u(rng);
    }
    for (int j = 0; j < cols; ++j) {  // x >= 0 as rows for the enumeration
      a.row(rows + j).setZero();
      a(rows + j, j) = -1.0;
      b[rows + j] = 0.0;
    }
    double best = -1e300;
    std::vector<int> pick(cols);
    const int total = rows + cols;
    std::function<void(int, int)> choose = [&](int from, int depth) {
      if (depth == cols) {
        Eigen::MatrixXd m(cols, cols);
        Eigen::VectorXd r(cols);
        for (int k = 0; k < cols; ++k) {
          m.row(k) = a.row(pick[k]);
          r[k] = b[pick[k]];
        }
        Eigen::FullPivLU<Eigen::MatrixXd> lu(m);
        if (lu.rank() < cols) return;
        const Eigen::VectorXd x = lu.solve(r);
        if (((a * x - b).array() <= 1e-9).all()) best = std::max(best, c.dot(x));
        return;
      }
      for (int i = from; i < total; ++i) {
        pick[depth] = i;
        choose(i + 1, depth + 1);
      }
    };
    choose(0, 0);
    DenseSimplex lp(rows, cols);
    lp.reset(rows, cols);
    for (int i = 0; i < rows; ++i) {
      for (int j = 0; j < cols; ++j) lp.a(i, j) = a(i, j);
      lp.b(i) = b[i];
    }
    for (int j = 0; j < cols; ++j) lp.c(j) = c[j];
    ASSERT_EQ(lp.solve(), LpStatus::kOptimal) << trial;
    EXPECT_NEAR(lp.value(), std::max(best, 0.0), 1e-9) << trial;
  }
}
