// Prescribed tip paths (input::PrescribedPath, docs/path-format.md): any bytes are rejected with
// a FileError or give a path whose via points keep the rules; the interpolation gives finite
// states everywhere; written back with write_prescribed_path it parses to the same via points.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string_view>

#include "craneassist/input/prescribed_path.hpp"
#include "fuzz_check.hpp"

using craneassist::input::FileError;
using craneassist::input::PrescribedPath;
using craneassist::input::PrescribedPathLimits;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const PrescribedPath path = PrescribedPath::parse(text, "fuzz.csv");
    const auto& t = path.via_times_s();
    const auto& p = path.via_points_m();
    FUZZ_CHECK(t.size() >= 2 && t.size() == p.size(), "at least two via points");
    for (std::size_t i = 0; i < t.size(); ++i) {
      FUZZ_CHECK(std::isfinite(t[i]) && t[i] >= 0.0, "time finite, >= 0");
      FUZZ_CHECK(i == 0 || t[i] - t[i - 1] >= PrescribedPathLimits::kMinTimeStepS,
                 "via times at least the minimum step apart");
      FUZZ_CHECK(
          p[i].allFinite() && p[i].cwiseAbs().maxCoeff() <= PrescribedPathLimits::kMaxCoordinateM,
          "coordinates finite, within the limit");
    }
    FUZZ_CHECK(std::isfinite(path.peak_speed_m_s()) && path.peak_speed_m_s() >= 0.0, "peak speed");
    FUZZ_CHECK(std::isfinite(path.length_m()) && path.length_m() >= 0.0, "length");

    // The tip state at the via points, between them, outside the path and at odd times.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < t.size(); ++i) {
      for (double dt : {0.0, 0.25, 0.5}) {
        const double at = i + 1 < t.size() ? t[i] + dt * (t[i + 1] - t[i]) : t[i] + dt;
        const auto point = path.at(at);
        FUZZ_CHECK(point.p_m.allFinite() && point.v_m_s.allFinite() && point.a_m_s2.allFinite(),
                   "the tip state is finite");
      }
    }
    for (double at : {-1.0, nan, inf, -inf}) {
      const auto point = path.at(at);
      FUZZ_CHECK(point.p_m.allFinite() && point.v_m_s.allFinite(), "finite outside the path");
    }

    // Written back, it reads the same.
    std::ostringstream out;
    craneassist::input::write_prescribed_path(out, path, "fuzz\nround trip");
    const PrescribedPath again = PrescribedPath::parse(out.str(), "written.csv");
    FUZZ_CHECK(again.via_times_s().size() == t.size(), "round trip keeps the via point count");
    for (std::size_t i = 0; i < t.size(); ++i) {
      FUZZ_CHECK(same_bits(again.via_times_s()[i], t[i]), "round trip keeps the times");
      for (int k = 0; k < 3; ++k) {
        FUZZ_CHECK(same_bits(again.via_points_m()[i][k], p[i][k]), "round trip keeps the points");
      }
    }
  } catch (const FileError& e) {
    FUZZ_CHECK(e.file() == "fuzz.csv", "the error names the file");
  }
  return 0;
}
