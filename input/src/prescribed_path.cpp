#include "craneassist/input/prescribed_path.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <fstream>
#include <ostream>
#include <system_error>
#include <utility>

#include "text_fields.hpp"

namespace craneassist::input {
namespace {

using Limits = PrescribedPathLimits;

constexpr std::array<std::string_view, 4> kColumns = {"t", "x", "y", "z"};
constexpr std::string_view kHeader = "t,x,y,z";
constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";
// Quintic rest-to-rest s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5: peak of ds/dtau, at tau = 1/2.
constexpr double kQuinticPeakRate = 1.875;
// Samples per spline segment for the peak speed and the arc length (even, for Simpson's rule).
constexpr int kSamplesPerSegment = 512;

// ---- text helpers: text_fields.hpp (the replay reader's rules) --------------------------------

using detail::format_number;
using detail::kMaxNumberChars;
using detail::number;
using detail::quoted;
using detail::split_fields;
using detail::trim;

// ---- via-point rules ---------------------------------------------------------------------------

// Empty when t is acceptable after previous (nullptr for the first via point), else the reason.
std::string time_problem(double t, const double* previous) {
  if (!std::isfinite(t)) return "not a finite number";
  if (t < 0.0) return "negative time: " + number(t) + " s";
  if (previous != nullptr) {
    if (!(t > *previous)) {
      return "time not strictly increasing: " + number(t) + " s follows " + number(*previous) +
             " s";
    }
    if (t - *previous < Limits::kMinTimeStepS) {
      return "time step of " + number(t - *previous) + " s after " + number(*previous) +
             " s is below the minimum of " + number(Limits::kMinTimeStepS) + " s";
    }
  }
  return {};
}

std::string coordinate_problem(double c) {
  if (!std::isfinite(c)) return "not a finite number";
  if (std::abs(c) > Limits::kMaxCoordinateM) {
    return "magnitude of " + number(c) + " m exceeds the limit of " +
           number(Limits::kMaxCoordinateM) + " m";
  }
  return {};
}

// ---- parser ------------------------------------------------------------------------------------

class Parser {
 public:
  explicit Parser(std::string_view source_name) : source_(source_name) {}

  void parse(std::string_view text);

  std::vector<double> t_s;
  std::vector<Eigen::Vector3d> p_m;

 private:
  PrescribedPathError error(std::size_t line, std::string_view field, std::string reason) const {
    return PrescribedPathError(source_, line, std::string(field), std::move(reason));
  }
  double parse_field(std::string_view text, std::size_t line, std::string_view field) const;
  void check_header(std::string_view content, std::size_t line) const;
  void parse_row(std::string_view content, std::size_t line);

  std::string source_;
  std::size_t previous_row_line_ = 0;
};

double Parser::parse_field(std::string_view text, std::size_t line, std::string_view field) const {
  double value = 0.0;
  std::string reason;
  if (!detail::parse_number(text, value, reason)) throw error(line, field, std::move(reason));
  return value;
}

void Parser::check_header(std::string_view content, std::size_t line) const {
  std::array<std::string_view, 4> fields;
  bool ok = split_fields(content, fields) == kColumns.size();
  for (std::size_t i = 0; ok && i < kColumns.size(); ++i) ok = fields[i] == kColumns[i];
  if (!ok) {
    throw error(line, "",
                "expected the header '" + std::string(kHeader) + "', got " + quoted(content));
  }
}

void Parser::parse_row(std::string_view content, std::size_t line) {
  std::array<std::string_view, 4> fields;
  const std::size_t count = split_fields(content, fields);
  if (count != kColumns.size()) {
    throw error(line, "",
                "expected 4 fields (" + std::string(kHeader) + "), got " + std::to_string(count));
  }
  if (t_s.size() >= Limits::kMaxViaPoints) {
    throw error(line, "",
                "too many via points (limit " + std::to_string(Limits::kMaxViaPoints) + ")");
  }
  const double t = parse_field(fields[0], line, kColumns[0]);
  std::string problem = time_problem(t, t_s.empty() ? nullptr : &t_s.back());
  if (!problem.empty()) {
    // Past the negative-time check, a problem is one of order: name the previous row's line.
    if (!t_s.empty() && t >= 0.0) {
      problem += " (line " + std::to_string(previous_row_line_) + ")";
    }
    throw error(line, kColumns[0], std::move(problem));
  }
  Eigen::Vector3d p;
  for (Eigen::Index i = 0; i < 3; ++i) {
    const auto column = static_cast<std::size_t>(i + 1);
    p[i] = parse_field(fields[column], line, kColumns[column]);
    problem = coordinate_problem(p[i]);
    if (!problem.empty()) throw error(line, kColumns[column], std::move(problem));
  }
  t_s.push_back(t);
  p_m.push_back(p);
  previous_row_line_ = line;
}

void Parser::parse(std::string_view text) {
  if (text.starts_with(kUtf8Bom)) text.remove_prefix(kUtf8Bom.size());
  bool have_header = false;
  std::size_t line = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view raw = text.substr(pos, end - pos);
    pos = end + 1;
    ++line;
    if (!raw.empty() && raw.back() == '\r') raw.remove_suffix(1);
    const std::string_view content = trim(raw);
    if (content.empty() || content.front() == '#') continue;
    if (!have_header) {
      check_header(content, line);
      have_header = true;
    } else {
      parse_row(content, line);
    }
  }
  // Whole-file problems are reported at the last line (line 1 for an empty file).
  const std::size_t last_line = std::max<std::size_t>(line, 1);
  if (!have_header) {
    throw error(last_line, "",
                "missing header '" + std::string(kHeader) +
                    "' (no line other than comments and blank lines)");
  }
  if (t_s.size() < 2) {
    throw error(last_line, "",
                "a path needs at least 2 via points, got " + std::to_string(t_s.size()));
  }
}

// ---- clamped cubic spline ----------------------------------------------------------------------

// Second derivatives M_i at the knots of the cubic spline through (t_i, p_i) with zero first
// derivative at both ends (all three coordinates at once; tridiagonal, Thomas algorithm; the
// system is strictly diagonally dominant).
std::vector<Eigen::Vector3d> clamped_spline_accelerations(const std::vector<double>& t,
                                                          const std::vector<Eigen::Vector3d>& p) {
  const std::size_t n = t.size();
  std::vector<double> sub(n, 0.0), diag(n, 0.0), super(n, 0.0);
  std::vector<Eigen::Vector3d> rhs(n, Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double h = t[i + 1] - t[i];
    const Eigen::Vector3d slope = (p[i + 1] - p[i]) / h;
    // Segment i contributes to rows i and i + 1.
    diag[i] += 2.0 * h;
    super[i] = h;
    rhs[i] += 6.0 * slope;
    sub[i + 1] = h;
    diag[i + 1] += 2.0 * h;
    rhs[i + 1] -= 6.0 * slope;
  }
  // Forward elimination, back substitution.
  for (std::size_t i = 1; i < n; ++i) {
    const double w = sub[i] / diag[i - 1];
    diag[i] -= w * super[i - 1];
    rhs[i] -= w * rhs[i - 1];
  }
  std::vector<Eigen::Vector3d> m(n);
  m[n - 1] = rhs[n - 1] / diag[n - 1];
  for (std::size_t i = n - 1; i-- > 0;) m[i] = (rhs[i] - super[i] * m[i + 1]) / diag[i];
  return m;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

PrescribedPathError::PrescribedPathError(std::string file, std::size_t line, std::string field,
                                         std::string reason)
    : std::runtime_error(file + ":" + std::to_string(line) + ": " +
                         (field.empty() ? std::string() : "field '" + field + "': ") + reason),
      file_(std::move(file)),
      line_(line),
      field_(std::move(field)),
      reason_(std::move(reason)) {}

PrescribedPath PrescribedPath::from_via_points(std::vector<double> t_s,
                                               std::vector<Eigen::Vector3d> p_m) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("PrescribedPath::from_via_points: " + what);
  };
  if (t_s.size() != p_m.size()) {
    fail(std::to_string(t_s.size()) + " times but " + std::to_string(p_m.size()) + " points");
  }
  if (t_s.size() < 2) fail("a path needs at least 2 via points, got " + std::to_string(t_s.size()));
  if (t_s.size() > Limits::kMaxViaPoints) {
    fail("too many via points (limit " + std::to_string(Limits::kMaxViaPoints) + ")");
  }
  for (std::size_t i = 0; i < t_s.size(); ++i) {
    const std::string problem = time_problem(t_s[i], i == 0 ? nullptr : &t_s[i - 1]);
    if (!problem.empty()) fail("via point " + std::to_string(i) + ": t: " + problem);
    for (Eigen::Index k = 0; k < 3; ++k) {
      const std::string c = coordinate_problem(p_m[i][k]);
      if (!c.empty()) {
        fail("via point " + std::to_string(i) + ": " + std::string(kColumns[k + 1]) + ": " + c);
      }
    }
  }
  return PrescribedPath(std::move(t_s), std::move(p_m));
}

PrescribedPath::PrescribedPath(std::vector<double> t_s, std::vector<Eigen::Vector3d> p_m)
    : t_s_(std::move(t_s)), p_m_(std::move(p_m)) {
  if (t_s_.size() == 2) {
    const double distance_m = (p_m_[1] - p_m_[0]).norm();
    length_m_ = distance_m;
    peak_speed_m_s_ = kQuinticPeakRate * distance_m / duration_s();
    return;
  }
  a_knot_m_s2_ = clamped_spline_accelerations(t_s_, p_m_);
  for (std::size_t i = 0; i + 1 < t_s_.size(); ++i) {
    const double h = t_s_[i + 1] - t_s_[i];
    const double du = h / kSamplesPerSegment;
    // Simpson's rule on the speed for the length; the best sample, refined by golden-section
    // search between its neighbours, for the peak speed.
    double simpson = 0.0;
    int best = 0;
    double best_speed = -1.0;
    for (int k = 0; k <= kSamplesPerSegment; ++k) {
      const double speed = segment_speed(i, k * du);
      const double weight = (k == 0 || k == kSamplesPerSegment) ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0);
      simpson += weight * speed;
      if (speed > best_speed) {
        best_speed = speed;
        best = k;
      }
    }
    length_m_ += simpson * du / 3.0;
    double lo = std::max(0, best - 1) * du, hi = std::min(kSamplesPerSegment, best + 1) * du;
    const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int iteration = 0; iteration < 60; ++iteration) {
      const double a = hi - ratio * (hi - lo), b = lo + ratio * (hi - lo);
      if (segment_speed(i, a) < segment_speed(i, b)) {
        lo = a;
      } else {
        hi = b;
      }
    }
    best_speed = std::max(best_speed, segment_speed(i, 0.5 * (lo + hi)));
    peak_speed_m_s_ = std::max(peak_speed_m_s_, best_speed);
  }
}

PrescribedPathPoint PrescribedPath::segment_point(std::size_t i, double u) const noexcept {
  // On [t_i, t_i+1], u = t - t_i: p = p_i + b u + M_i u^2 / 2 + (M_i+1 - M_i) u^3 / (6 h) with
  // b = (p_i+1 - p_i) / h - h (2 M_i + M_i+1) / 6.
  const double h = t_s_[i + 1] - t_s_[i];
  const Eigen::Vector3d& m0 = a_knot_m_s2_[i];
  const Eigen::Vector3d& m1 = a_knot_m_s2_[i + 1];
  const Eigen::Vector3d jerk = (m1 - m0) / h;
  const Eigen::Vector3d b = (p_m_[i + 1] - p_m_[i]) / h - h * (2.0 * m0 + m1) / 6.0;
  PrescribedPathPoint out;
  out.p_m = p_m_[i] + u * (b + u * (0.5 * m0 + u * jerk / 6.0));
  out.v_m_s = b + u * (m0 + 0.5 * u * jerk);
  out.a_m_s2 = m0 + u * jerk;
  return out;
}

double PrescribedPath::segment_speed(std::size_t i, double u) const noexcept {
  return segment_point(i, u).v_m_s.norm();
}

PrescribedPathPoint PrescribedPath::at(double t_s) const noexcept {
  PrescribedPathPoint out;
  if (std::isnan(t_s) || t_s < t_s_.front()) {
    out.p_m = p_m_.front();
    return out;
  }
  if (t_s > t_s_.back()) {
    out.p_m = p_m_.back();
    return out;
  }
  if (t_s_.size() == 2) {
    // Quintic rest-to-rest: s = 10 tau^3 - 15 tau^4 + 6 tau^5 from 0 to 1.
    const double duration = duration_s();
    const double tau = (t_s - t_s_[0]) / duration;
    const double s = tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau));
    const double ds = 30.0 * tau * tau * (1.0 + tau * (-2.0 + tau)) / duration;
    const double dds = 60.0 * tau * (1.0 + tau * (-3.0 + 2.0 * tau)) / (duration * duration);
    const Eigen::Vector3d delta = p_m_[1] - p_m_[0];
    out.p_m = p_m_[0] + s * delta;
    out.v_m_s = ds * delta;
    out.a_m_s2 = dds * delta;
    return out;
  }
  if (t_s == t_s_.back()) {
    // The end knot: the clamped end condition exactly, the spline's (non-zero) acceleration.
    out = segment_point(t_s_.size() - 2, t_s_.back() - t_s_[t_s_.size() - 2]);
    out.p_m = p_m_.back();
    out.v_m_s.setZero();
    return out;
  }
  // Segment i with t_i <= t < t_i+1.
  const auto after = std::upper_bound(t_s_.begin(), t_s_.end(), t_s);
  const auto i = static_cast<std::size_t>(after - t_s_.begin()) - 1;
  return segment_point(i, t_s - t_s_[i]);
}

PrescribedPath PrescribedPath::parse(std::string_view text, std::string_view source_name) {
  Parser parser(source_name);
  parser.parse(text);
  return PrescribedPath(std::move(parser.t_s), std::move(parser.p_m));
}

PrescribedPath PrescribedPath::load_file(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw PrescribedPathError(name, 0, "", "cannot read file: is a directory");
  }
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int open_errno = errno;
    if (!std::filesystem::exists(path, ec) && !ec) {
      throw PrescribedPathError(name, 0, "", "file not found");
    }
    throw PrescribedPathError(
        name, 0, "",
        "cannot open file" +
            (open_errno != 0 ? ": " + std::generic_category().message(open_errno) : std::string()));
  }
  std::string text;
  std::array<char, 1 << 16> buffer{};
  while (in.read(buffer.data(), static_cast<std::streamsize>(buffer.size())) || in.gcount() > 0) {
    text.append(buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw PrescribedPathError(name, 0, "", "read error");
  return parse(text, name);
}

void write_prescribed_path(std::ostream& out, const PrescribedPath& path,
                           std::string_view comment) {
  std::string line;
  while (!comment.empty()) {
    const std::size_t end = comment.find('\n');
    std::string_view part = comment.substr(0, end);
    if (!part.empty() && part.back() == '\r') part.remove_suffix(1);
    out << '#';
    if (!part.empty()) out << ' ' << part;
    out << '\n';
    if (end == std::string_view::npos) break;
    comment.remove_prefix(end + 1);
  }
  out << kHeader << '\n';
  std::array<char, kMaxNumberChars> buffer{};
  for (std::size_t i = 0; i < path.via_times_s().size(); ++i) {
    line.clear();
    line += format_number(path.via_times_s()[i], buffer);
    for (Eigen::Index k = 0; k < 3; ++k) {
      line += ',';
      line += format_number(path.via_points_m()[i][k], buffer);
    }
    line += '\n';
    out << line;
  }
}

}  // namespace craneassist::input
