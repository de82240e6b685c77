// Prescribed tip paths (input/prescribed_path.hpp): the quintic line and the clamped cubic spline,
// their derivatives, the strict reader and the writer.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "allocation_counter.hpp"
#include "craneassist/input/prescribed_path.hpp"
#include "file_error_checks.hpp"
#include "thrown_error.hpp"

namespace craneassist::input {
namespace {

namespace fs = std::filesystem;

constexpr const char* kSource = "bad_path.csv";

// A spline through 5 via points with uneven time steps, turning in 3-D.
PrescribedPath spline_path() {
  return PrescribedPath::from_via_points(
      {1.0, 2.5, 5.0, 6.0, 9.0},
      {{3.0, 1.0, 0.0}, {3.5, 2.0, 0.5}, {5.0, 1.5, 1.0}, {5.5, 0.5, 2.5}, {6.0, -1.0, 2.0}});
}

PrescribedPath line_path() {
  return PrescribedPath::from_via_points({2.0, 12.0}, {{3.0, 1.5, 0.0}, {6.2, 1.5, -0.4}});
}

// Largest sampled speed (every dt_s), an independent check of peak_speed_m_s().
double sampled_peak_speed(const PrescribedPath& path, double dt_s) {
  double peak = 0.0;
  for (double t = path.start_time_s(); t <= path.end_time_s(); t += dt_s) {
    peak = std::max(peak, path.at(t).v_m_s.norm());
  }
  return peak;
}

FileError parse_error(std::string_view text) {
  return test::thrown_error<FileError>([&] { PrescribedPath::parse(text, kSource); },
                                       "accepted:\n" + std::string(text));
}

// Checks line, field, that the reason contains reason_part, and the what() layout.
void expect_rejected(std::string_view text, std::size_t line, std::string_view field,
                     std::string_view reason_part) {
  SCOPED_TRACE(std::string("text:\n") + std::string(text));
  test::expect_file_error(parse_error(text), kSource, line, field, reason_part);
}

// ---- quintic line ------------------------------------------------------------------------------

TEST(PrescribedPathQuintic, EndConditionsAndTimes) {
  const PrescribedPath path = line_path();
  EXPECT_EQ(path.interpolation(), PrescribedPath::Interpolation::kQuinticLine);
  EXPECT_EQ(path.start_time_s(), 2.0);
  EXPECT_EQ(path.end_time_s(), 12.0);
  EXPECT_EQ(path.duration_s(), 10.0);
  for (const double t : {2.0, 12.0}) {
    const PrescribedPathPoint p = path.at(t);
    const Eigen::Vector3d expected = t == 2.0 ? Eigen::Vector3d(3.0, 1.5, 0.0)  // start
                                              : Eigen::Vector3d(6.2, 1.5, -0.4);
    EXPECT_LT((p.p_m - expected).norm(), 1e-12) << t;
    EXPECT_LT(p.v_m_s.norm(), 1e-12) << t;
    EXPECT_LT(p.a_m_s2.norm(), 1e-12) << t;
  }
  // Just inside the ends the motion starts and stops smoothly: v ~ t^2, a ~ t.
  EXPECT_LT(path.at(2.0 + 1e-3).v_m_s.norm(), 1e-6);
  EXPECT_LT(path.at(12.0 - 1e-3).a_m_s2.norm(), 1e-3);
  EXPECT_GT(path.at(2.0 + 1e-3).a_m_s2.norm(), 0.0);
}

TEST(PrescribedPathQuintic, PeakSpeedIs1875LengthOverDuration) {
  const PrescribedPath path = line_path();
  const double length_m = std::hypot(3.2, 0.4);
  EXPECT_NEAR(path.length_m(), length_m, 1e-12);
  EXPECT_NEAR(path.peak_speed_m_s(), 1.875 * length_m / 10.0, 1e-12);
  // At mid-time, half-way, at the peak speed, not accelerating.
  const PrescribedPathPoint mid = path.at(7.0);
  EXPECT_LT((mid.p_m - Eigen::Vector3d(4.6, 1.5, -0.2)).norm(), 1e-12);
  EXPECT_NEAR(mid.v_m_s.norm(), path.peak_speed_m_s(), 1e-12);
  EXPECT_LT(mid.a_m_s2.norm(), 1e-12);
  EXPECT_NEAR(sampled_peak_speed(path, 1e-3), path.peak_speed_m_s(), 1e-6);
}

TEST(PrescribedPathQuintic, StaysOnTheLineAndMovesForward) {
  const PrescribedPath path = line_path();
  const Eigen::Vector3d start(3.0, 1.5, 0.0);
  const Eigen::Vector3d direction = Eigen::Vector3d(3.2, 0.0, -0.4).normalized();
  double previous_s = -1.0;
  for (double t = 2.0; t <= 12.0; t += 0.01) {
    const PrescribedPathPoint p = path.at(t);
    const Eigen::Vector3d offset = p.p_m - start;
    const double s = offset.dot(direction);
    EXPECT_LT((offset - s * direction).norm(), 1e-12) << t;
    EXPECT_GE(s, previous_s) << t;
    EXPECT_GE(p.v_m_s.dot(direction), -1e-15) << t;
    previous_s = s;
  }
}

// ---- clamped cubic spline ----------------------------------------------------------------------

TEST(PrescribedPathSpline, PassesTheViaPointsWithZeroEndVelocity) {
  const PrescribedPath path = spline_path();
  EXPECT_EQ(path.interpolation(), PrescribedPath::Interpolation::kClampedCubicSpline);
  ASSERT_EQ(path.via_times_s().size(), 5u);
  for (std::size_t i = 0; i < path.via_times_s().size(); ++i) {
    EXPECT_LT((path.at(path.via_times_s()[i]).p_m - path.via_points_m()[i]).norm(), 1e-12) << i;
  }
  EXPECT_EQ(path.at(1.0).v_m_s.norm(), 0.0);
  EXPECT_EQ(path.at(9.0).v_m_s.norm(), 0.0);
  // Zero end velocity is a property of the spline itself, not only of the end points.
  EXPECT_LT(path.at(1.0 + 1e-6).v_m_s.norm(), 1e-5);
  EXPECT_LT(path.at(9.0 - 1e-6).v_m_s.norm(), 1e-5);
  // Interior via points are passed at speed.
  EXPECT_GT(path.at(5.0).v_m_s.norm(), 0.1);
}

TEST(PrescribedPathSpline, SecondDerivativeContinuousAtInteriorKnots) {
  const PrescribedPath path = spline_path();
  constexpr double kH = 1e-7;
  for (std::size_t i = 1; i + 1 < path.via_times_s().size(); ++i) {
    const double t = path.via_times_s()[i];
    const PrescribedPathPoint before = path.at(t - kH);
    const PrescribedPathPoint after = path.at(t + kH);
    // Over 2 h, p, v and a change by O(h) when continuous; a jump would be O(1).
    EXPECT_LT((after.p_m - before.p_m).norm(), 1e-5) << i;
    EXPECT_LT((after.v_m_s - before.v_m_s).norm(), 1e-5) << i;
    EXPECT_LT((after.a_m_s2 - before.a_m_s2).norm(), 1e-5) << i;
  }
  // The third derivative does jump at the knots (it is a cubic spline, not one polynomial).
  const auto jerk = [&](double t) -> Eigen::Vector3d {
    return (path.at(t + 1e-4).a_m_s2 - path.at(t).a_m_s2) / 1e-4;
  };
  EXPECT_GT((jerk(5.0) - jerk(5.0 - 2e-4)).norm(), 1e-2);
}

TEST(PrescribedPathSpline, SplineMeetsItsEndConditionsWithThreeViaPoints) {
  const PrescribedPath path =
      PrescribedPath::from_via_points({0.0, 1.0, 3.0}, {{1, 1, 1}, {2, 1, 1}, {2, 2, 1}});
  EXPECT_EQ(path.interpolation(), PrescribedPath::Interpolation::kClampedCubicSpline);
  EXPECT_LT((path.at(1.0).p_m - Eigen::Vector3d(2, 1, 1)).norm(), 1e-12);
  EXPECT_LT(path.at(1e-6).v_m_s.norm(), 1e-5);
  EXPECT_LT(path.at(3.0 - 1e-6).v_m_s.norm(), 1e-5);
}

TEST(PrescribedPathSpline, PeakSpeedAndLengthMatchFineSampling) {
  const PrescribedPath path = spline_path();
  const double sampled = sampled_peak_speed(path, 1e-4);
  EXPECT_GE(path.peak_speed_m_s(), sampled - 1e-12);
  EXPECT_NEAR(path.peak_speed_m_s(), sampled, 1e-6);
  double polyline_m = 0.0;
  Eigen::Vector3d previous = path.at(path.start_time_s()).p_m;
  for (int k = 1; k <= 80'000; ++k) {
    const Eigen::Vector3d p = path.at(path.start_time_s() + path.duration_s() * k / 80'000.0).p_m;
    polyline_m += (p - previous).norm();
    previous = p;
  }
  EXPECT_NEAR(path.length_m(), polyline_m, 1e-6);
  // Longer than the via-point polygon, as a curve through them must be.
  double polygon_m = 0.0;
  for (std::size_t i = 0; i + 1 < path.via_points_m().size(); ++i) {
    polygon_m += (path.via_points_m()[i + 1] - path.via_points_m()[i]).norm();
  }
  EXPECT_GE(path.length_m(), polygon_m);
}

// ---- both kinds --------------------------------------------------------------------------------

// v and a are the time derivatives of p and v: central differences at random times.
TEST(PrescribedPath, VelocityAndAccelerationAreDerivatives) {
  std::mt19937 rng(7);
  for (const PrescribedPath& path : {line_path(), spline_path()}) {
    std::uniform_real_distribution<double> time(path.start_time_s() + 0.01,
                                                path.end_time_s() - 0.01);
    constexpr double kH = 1e-5;
    for (int k = 0; k < 200; ++k) {
      const double t = time(rng);
      const PrescribedPathPoint p = path.at(t);
      const Eigen::Vector3d v_fd = (path.at(t + kH).p_m - path.at(t - kH).p_m) / (2 * kH);
      const Eigen::Vector3d a_fd = (path.at(t + kH).v_m_s - path.at(t - kH).v_m_s) / (2 * kH);
      EXPECT_LT((p.v_m_s - v_fd).norm(), 1e-7) << t;
      EXPECT_LT((p.a_m_s2 - a_fd).norm(), 1e-6) << t;
    }
  }
}

TEST(PrescribedPath, RestsOutsideItsTimeRange) {
  for (const PrescribedPath& path : {line_path(), spline_path()}) {
    for (const double t :
         {-1.0, path.start_time_s() - 1e-9, -std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::quiet_NaN()}) {
      const PrescribedPathPoint p = path.at(t);
      EXPECT_EQ(p.p_m, path.via_points_m().front()) << t;
      EXPECT_EQ(p.v_m_s, Eigen::Vector3d::Zero()) << t;
      EXPECT_EQ(p.a_m_s2, Eigen::Vector3d::Zero()) << t;
    }
    for (const double t :
         {path.end_time_s() + 1e-9, 1e9, std::numeric_limits<double>::infinity()}) {
      const PrescribedPathPoint p = path.at(t);
      EXPECT_EQ(p.p_m, path.via_points_m().back()) << t;
      EXPECT_EQ(p.v_m_s, Eigen::Vector3d::Zero()) << t;
      EXPECT_EQ(p.a_m_s2, Eigen::Vector3d::Zero()) << t;
    }
  }
}

TEST(PrescribedPath, SamplingDoesNotAllocate) {
  const PrescribedPath path = spline_path();
  static_assert(noexcept(path.at(0.0)));
  double sum = 0.0;
  const long before = craneassist::test::heap_allocations();
  for (double t = 0.0; t < 10.0; t += 0.01) sum += path.at(t).p_m.sum();
  EXPECT_EQ(craneassist::test::heap_allocations(), before);
  EXPECT_TRUE(std::isfinite(sum));
}

TEST(PrescribedPath, FromViaPointsRejectsBadInput) {
  using V = Eigen::Vector3d;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const auto rejects = [](std::vector<double> t, std::vector<V> p, std::string_view part) {
    try {
      PrescribedPath::from_via_points(std::move(t), std::move(p));
      ADD_FAILURE() << "accepted (" << part << ")";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  rejects({0.0, 1.0}, {V::Zero()}, "2 times but 1 points");
  rejects({0.0}, {V::Zero()}, "at least 2 via points, got 1");
  rejects({}, {}, "at least 2 via points, got 0");
  rejects({-0.5, 1.0}, {V::Zero(), V::Ones()}, "via point 0: t: negative time");
  rejects({0.0, 1.0, 1.0}, {V::Zero(), V::Ones(), V::Zero()},
          "via point 2: t: time not strictly increasing");
  rejects({0.0, 2.0, 1.0}, {V::Zero(), V::Ones(), V::Zero()}, "not strictly increasing");
  rejects({0.0, 1e-4}, {V::Zero(), V::Ones()}, "below the minimum of 0.001 s");
  rejects({0.0, nan}, {V::Zero(), V::Ones()}, "via point 1: t: not a finite number");
  rejects({0.0, inf}, {V::Zero(), V::Ones()}, "not a finite number");
  rejects({0.0, 1.0}, {V::Zero(), V(0, nan, 0)}, "via point 1: y: not a finite number");
  rejects({0.0, 1.0}, {V(0, 0, -100.5), V::Ones()}, "via point 0: z: magnitude of -100.5 m");
  // The limits themselves are accepted.
  EXPECT_NO_THROW(PrescribedPath::from_via_points({0.0, 1e-3}, {V::Zero(), V(100, -100, 0)}));
  // A path may stand still (zero length).
  const PrescribedPath still = PrescribedPath::from_via_points({0.0, 1.0}, {V::Ones(), V::Ones()});
  EXPECT_EQ(still.peak_speed_m_s(), 0.0);
  EXPECT_EQ(still.length_m(), 0.0);
}

// ---- reader ------------------------------------------------------------------------------------

TEST(PrescribedPathReader, ReadsTheDocumentedExample) {
  const PrescribedPath path = PrescribedPath::parse(
      "# comment\nt,x,y,z\n0.0, 3.0, 1.5, 0.0\n10.0, 6.2, 1.5, 0.0\n", kSource);
  EXPECT_EQ(path.interpolation(), PrescribedPath::Interpolation::kQuinticLine);
  EXPECT_EQ(path.via_times_s(), (std::vector<double>{0.0, 10.0}));
  EXPECT_EQ(path.via_points_m()[1], Eigen::Vector3d(6.2, 1.5, 0.0));
  EXPECT_NEAR(path.peak_speed_m_s(), 0.6, 1e-12);
}

TEST(PrescribedPathReader, CrlfBomCommentsBlankLinesAndSpacing) {
  const std::string plain = "t,x,y,z\n0,1,2,3\n1.5,2,2,3\n4,2,-1.25,0\n";
  const std::string messy =
      "\xEF\xBB\xBF# a path\r\n\r\n  # indented comment\r\n \t t , x\t, y ,z \r\n"
      "0, 1, 2, 3\r\n\t\r\n# between rows\r\n1.5 ,2,2 ,3\r\n  4,\t2,-1.25,0";
  const PrescribedPath a = PrescribedPath::parse(plain, kSource);
  const PrescribedPath b = PrescribedPath::parse(messy, kSource);
  EXPECT_EQ(a.via_times_s(), b.via_times_s());
  EXPECT_EQ(a.via_points_m(), b.via_points_m());
  EXPECT_EQ(b.via_points_m()[2], Eigen::Vector3d(2, -1.25, 0));
}

TEST(PrescribedPathReader, ErrorsNameFileLineAndField) {
  expect_rejected("t,x,y,z\n0,1,2,3\n1,1,0.1x,3\n", 3, "y", "not a number: '0.1x'");
  expect_rejected("t,x,y,z\n0,1,2,3\n1,,2,3\n", 3, "x", "missing value");
  expect_rejected("t,x,y,z\n0,1,2,3\n1,1,2\n", 3, "", "expected 4 fields (t,x,y,z), got 3");
  expect_rejected("t,x,y,z\n0,1,2,3\n1,1,2,3,4\n", 3, "", "got 5");
  expect_rejected("# c\nt,v_x,v_y,v_z\n0,1,2,3\n", 2, "", "expected the header 't,x,y,z'");
  expect_rejected("t,x,y\n", 1, "", "expected the header 't,x,y,z', got 't,x,y'");
  expect_rejected("T,X,Y,Z\n", 1, "", "expected the header");
  expect_rejected("t,x,y,z\n0,1,2,nan\n1,1,2,3\n", 2, "z", "not a finite number: 'nan'");
  expect_rejected("t,x,y,z\n0,inf,2,3\n1,1,2,3\n", 2, "x", "not a finite number: 'inf'");
  expect_rejected("t,x,y,z\n0,1e400,2,3\n1,1,2,3\n", 2, "x", "number out of range: '1e400'");
  expect_rejected("t,x,y,z\n+1,1,2,3\n2,1,2,3\n", 2, "t", "not a number: '+1'");
  expect_rejected("t,x,y,z\n0,1 m,2,3\n2,1,2,3\n", 2, "x", "not a number: '1 m'");
  expect_rejected("t,x,y,z\n0,1,2,3 # end\n2,1,2,3\n", 2, "z", "not a number");
  expect_rejected("t,x,y,z\n-0.5,1,2,3\n2,1,2,3\n", 2, "t", "negative time: '-0.5'");
  expect_rejected("t,x,y,z\n0,1,2,3\n\n2,1,2,3\n1.5,1,2,3\n", 5, "t",
                  "time not strictly increasing: 1.5 s follows 2 s (line 4)");
  expect_rejected("t,x,y,z\n0,1,2,3\n0,1,2,3\n", 3, "t",
                  "not strictly increasing: 0 s follows 0 s");
  expect_rejected("t,x,y,z\n0,1,2,3\n0.0005,1,2,3\n", 3, "t",
                  "time step of 5e-04 s after 0 s is below the minimum of 0.001 s (line 2)");
  expect_rejected("t,x,y,z\n0,1,2,3\n1,1,-120,3\n", 3, "y",
                  "magnitude of -120 m exceeds the limit of 100 m");
  expect_rejected("t,x,y,z\n0,1,2,3\n# only one via point\n", 3, "",
                  "a path needs at least 2 via points, got 1");
  expect_rejected("t,x,y,z\n", 1, "", "no data rows after the header");
  expect_rejected("# nothing\n\n", 2, "", "missing header 't,x,y,z'");
  expect_rejected("", 1, "", "missing header");
  expect_rejected("t,x,y,z\n0,1,2,\x01\n", 2, "z", "not a number: '\\x01'");
  // Exactly at the limits is accepted.
  EXPECT_NO_THROW(PrescribedPath::parse("t,x,y,z\n0,100,-100,0\n0.001,0,0,0\n", kSource));
  // The message layout, as users see it.
  EXPECT_STREQ(parse_error("t,x,y,z\n0,1,2,3\n1,1,0.1x,3\n").what(),
               "bad_path.csv:3: field 'y': not a number: '0.1x'");
}

TEST(PrescribedPathReader, LoadFile) {
  const fs::path path =
      fs::temp_directory_path() /
      ("craneassist_test_path_" + std::to_string(std::random_device{}()) + ".csv");
  {
    std::ofstream out(path, std::ios::binary);
    out << "t,x,y,z\r\n0,1,2,3\r\n2,1,2,4\r\n";
  }
  const PrescribedPath loaded = PrescribedPath::load_file(path);
  EXPECT_EQ(loaded.end_time_s(), 2.0);
  {
    std::ofstream out(path, std::ios::binary);
    out << "t,x,y,z\n0,1,2,3\n2,1,2,abc\n";
  }
  try {
    PrescribedPath::load_file(path);
    ADD_FAILURE() << "accepted";
  } catch (const FileError& e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ":3: field 'z': not a number: 'abc'");
  }
  fs::remove(path);
  try {
    PrescribedPath::load_file(path);
    ADD_FAILURE() << "accepted";
  } catch (const FileError& e) {
    EXPECT_EQ(e.line(), 0u);
    EXPECT_EQ(e.reason(), "file not found");
  }
  try {
    PrescribedPath::load_file(fs::temp_directory_path());
    ADD_FAILURE() << "accepted";
  } catch (const FileError& e) {
    EXPECT_EQ(e.reason(), "cannot read file: is a directory");
  }
}

// ---- writer ------------------------------------------------------------------------------------

TEST(PrescribedPathWriter, RoundTripsBitExactlyWithComment) {
  const PrescribedPath path = PrescribedPath::from_via_points(
      {0.1, 1.0 / 3.0, 2.0}, {{1.0 / 7.0, -2.5e-7, 3.0}, {0.0, 1e-300, -99.99}, {1, 2, 3}});
  std::ostringstream out;
  write_prescribed_path(out, path, "two lines\nof comment\r\n\nend");
  const std::string text = out.str();
  EXPECT_EQ(text.substr(0, text.find("t,x,y,z")), "# two lines\n# of comment\n#\n# end\n");
  const PrescribedPath back = PrescribedPath::parse(text, "written.csv");
  EXPECT_EQ(back.via_times_s(), path.via_times_s());
  EXPECT_EQ(back.via_points_m(), path.via_points_m());

  std::ostringstream bare;
  write_prescribed_path(bare, line_path());
  EXPECT_EQ(bare.str(), "t,x,y,z\n2,3,1.5,0\n12,6.2,1.5,-0.4\n");
}

}  // namespace
}  // namespace craneassist::input
