#include "drapegen/diagnosis/hem_profile.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

namespace drapegen::diagnosis {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kBelowTop = -0.005;  // m: points below this belong to the skirt or the cylinder side

int bin_of(double angle, int bins) {
  double a = std::fmod(angle, kTwoPi);
  if (a < 0.0) a += kTwoPi;
  return std::min(bins - 1, static_cast<int>(a / kTwoPi * bins));
}

/// Fills NaN bins by circular linear interpolation between the nearest known bins.
void fill_gaps(std::vector<double>& r) {
  const int n = static_cast<int>(r.size());
  std::vector<int> known;
  for (int k = 0; k < n; ++k)
    if (std::isfinite(r[k])) known.push_back(k);
  if (known.empty() || static_cast<int>(known.size()) == n) return;
  for (std::size_t i = 0; i < known.size(); ++i) {
    const int a = known[i], b = known[(i + 1) % known.size()];
    const int gap = ((b - a) % n + n) % n;
    for (int s = 1; s < gap; ++s) {
      const double t = static_cast<double>(s) / gap;
      r[(a + s) % n] = (1.0 - t) * r[a] + t * r[b];
    }
  }
}

}  // namespace

Eigen::Matrix3Xd back_project(const CaptureView& view) {
  const auto& d = view.depth;
  const Eigen::Isometry3d camera_to_specimen = view.camera.world_to_camera.inverse();
  Eigen::Matrix3Xd points(3, d.foreground_count());
  int n = 0;
  for (int v = 0; v < d.height; ++v) {
    for (int u = 0; u < d.width; ++u) {
      const float z = d.at(u, v);
      if (z <= 0.0f) continue;
      points.col(n++) = camera_to_specimen * (static_cast<double>(z) * view.camera.ray(u, v));
    }
  }
  return points;
}

HemProfile hem_profile_from_points(const Eigen::Matrix3Xd& points, int bins) {
  std::vector<std::vector<double>> radii(bins);
  for (int i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3d p = points.col(i);
    if (!p.allFinite() || p.z() >= kBelowTop) continue;  // a non-finite point has no bin
    radii[bin_of(std::atan2(p.y(), p.x()), bins)].push_back(std::hypot(p.x(), p.y()));
  }
  HemProfile h;
  h.radius.assign(bins, std::numeric_limits<double>::quiet_NaN());
  for (int k = 0; k < bins; ++k) {
    auto& r = radii[k];
    if (r.size() < 3) continue;
    const auto q = static_cast<std::size_t>(0.98 * static_cast<double>(r.size() - 1));
    std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(q), r.end());
    h.radius[k] = r[q];
  }
  fill_gaps(h.radius);
  return h;
}

HemProfile hem_profile_from_mesh(const sim::ClothMesh& mesh, int bins) {
  HemProfile h;
  h.radius.assign(bins, std::numeric_limits<double>::quiet_NaN());
  auto add = [&](const Eigen::Vector3d& p) {
    if (!p.allFinite() || p.z() >= kBelowTop) return;  // a non-finite point has no bin
    double& r = h.radius[bin_of(std::atan2(p.y(), p.x()), bins)];
    const double rp = std::hypot(p.x(), p.y());
    if (!std::isfinite(r) || rp > r) r = rp;
  };
  for (int i = 0; i < mesh.vertex_count(); ++i) add(mesh.positions.col(i));
  // Sample every edge: a coarse mesh's outline passes between its vertices.
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    for (int e = 0; e < 3; ++e) {
      const Eigen::Vector3d a = mesh.positions.col(mesh.triangles(e, t));
      const Eigen::Vector3d b = mesh.positions.col(mesh.triangles((e + 1) % 3, t));
      for (int s = 1; s < 4; ++s) add(a + (b - a) * (s / 4.0));
    }
  }
  fill_gaps(h.radius);
  return h;
}

HemProfile hem_profile_from_capture(const Capture& capture, int bins) {
  std::vector<int> all;
  for (std::size_t v = 0; v < capture.views.size(); ++v) all.push_back(static_cast<int>(v));
  return hem_profile_from_views(capture, all, bins);
}

double spectrum_distance(const HemProfile& a, const HemProfile& b, int max_order) {
  const auto ha = harmonics(a, max_order), hb = harmonics(b, max_order);
  double s = 0.0;
  for (int n = 0; n <= max_order; ++n) s += std::pow(ha[n].amplitude - hb[n].amplitude, 2);
  return std::sqrt(s / (max_order + 1));
}

HemProfile hem_profile_from_views(const Capture& capture, const std::vector<int>& views, int bins) {
  int total = 0;
  std::vector<Eigen::Matrix3Xd> clouds;
  for (int k : views) {
    const auto& v = capture.views.at(static_cast<std::size_t>(k));
    clouds.push_back(back_project(v));
    total += static_cast<int>(clouds.back().cols());
  }
  Eigen::Matrix3Xd all(3, total);
  int at = 0;
  for (const auto& c : clouds) {
    all.middleCols(at, c.cols()) = c;
    at += static_cast<int>(c.cols());
  }
  return hem_profile_from_points(all, bins);
}

HemProfile rotate(const HemProfile& profile, double angle) {
  const int n = profile.bins();
  HemProfile out;
  out.radius.resize(n);
  const double shift = angle / kTwoPi * n;  // bins
  for (int k = 0; k < n; ++k) {
    double src = k - shift;
    src = std::fmod(src, static_cast<double>(n));
    if (src < 0.0) src += n;
    const int i0 = static_cast<int>(std::floor(src)) % n, i1 = (i0 + 1) % n;
    const double t = src - std::floor(src);
    out.radius[k] = (1.0 - t) * profile.radius[i0] + t * profile.radius[i1];
  }
  return out;
}

Alignment align(const HemProfile& model, const HemProfile& target) {
  const int n = model.bins();
  std::vector<double> ssd(n, std::numeric_limits<double>::infinity());
  for (int s = 0; s < n; ++s) {
    double sum = 0.0;
    int count = 0;
    for (int k = 0; k < n; ++k) {
      const double a = model.radius[((k - s) % n + n) % n], b = target.radius[k];
      if (!std::isfinite(a) || !std::isfinite(b)) continue;
      sum += (a - b) * (a - b);
      ++count;
    }
    if (count > 0) ssd[s] = sum / count;
  }
  const int best = static_cast<int>(std::min_element(ssd.begin(), ssd.end()) - ssd.begin());
  double offset = 0.0;
  const double l = ssd[(best + n - 1) % n], c = ssd[best], r = ssd[(best + 1) % n];
  if (std::isfinite(l) && std::isfinite(r) && l + r - 2 * c > 0.0) offset = 0.5 * (l - r) / (l + r - 2 * c);
  double angle = (best + offset) * kTwoPi / n;
  if (angle >= M_PI) angle -= kTwoPi;
  Alignment a;
  a.angle = angle;
  a.rms = std::sqrt(std::max(0.0, c));
  return a;
}

std::vector<Harmonic> harmonics(const HemProfile& profile, int max_order) {
  const int n = profile.bins();
  std::vector<Harmonic> out;
  for (int order = 0; order <= max_order; ++order) {
    std::complex<double> c = 0.0;
    int count = 0;
    for (int k = 0; k < n; ++k) {
      if (!std::isfinite(profile.radius[k])) continue;
      const double theta = (k + 0.5) * kTwoPi / n;
      c += profile.radius[k] * std::exp(std::complex<double>(0.0, -order * theta));
      ++count;
    }
    if (count > 0) c /= static_cast<double>(count);
    out.push_back({order, std::abs(c) * (order == 0 ? 1.0 : 2.0), std::arg(c)});
  }
  return out;
}

HemProfile low_pass(const HemProfile& profile, int max_order) {
  const int n = profile.bins();
  const std::vector<Harmonic> h = harmonics(profile, max_order);
  HemProfile out = profile;
  for (int k = 0; k < n; ++k) {
    if (!std::isfinite(profile.radius[k])) continue;
    const double theta = (k + 0.5) * kTwoPi / n;
    double r = 0.0;
    for (const Harmonic& c : h) r += c.amplitude * std::cos(c.order * theta + c.phase);
    out.radius[k] = r;
  }
  return out;
}

Alignment align_orientation(const HemProfile& model, const HemProfile& target) {
  return align(low_pass(model, kOrientationOrders), low_pass(target, kOrientationOrders));
}

int fold_count(const HemProfile& profile, double prominence) {
  const int n = profile.bins();
  if (n < 8) return 0;
  std::vector<double> s(n, 0.0);
  for (int k = 0; k < n; ++k) {
    double sum = 0.0;
    for (int d = -2; d <= 2; ++d) sum += profile.radius[((k + d) % n + n) % n];
    s[k] = sum / 5.0;
  }
  if (!std::isfinite(s[0])) return 0;
  // Alternating extrema around the circle.
  struct Extremum {
    double value;
    bool maximum;
  };
  std::vector<Extremum> ex;
  for (int k = 0; k < n; ++k) {
    const double prev = s[(k + n - 1) % n], cur = s[k];
    int j = (k + 1) % n;
    while (s[j] == cur && j != k) j = (j + 1) % n;  // plateaus
    const double next = s[j];
    if (cur > prev && cur > next) ex.push_back({cur, true});
    if (cur < prev && cur < next) ex.push_back({cur, false});
  }
  // Remove the adjacent max-min pair of smallest difference while it is below the prominence.
  while (ex.size() >= 2) {
    std::size_t worst = 0;
    double smallest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < ex.size(); ++i) {
      const std::size_t j = (i + 1) % ex.size();
      if (ex[i].maximum == ex[j].maximum) continue;
      const double d = std::abs(ex[i].value - ex[j].value);
      if (d < smallest) {
        smallest = d;
        worst = i;
      }
    }
    if (smallest >= prominence) break;
    const std::size_t j = (worst + 1) % ex.size();
    if (j > worst) {
      ex.erase(ex.begin() + static_cast<std::ptrdiff_t>(j));
      ex.erase(ex.begin() + static_cast<std::ptrdiff_t>(worst));
    } else {
      ex.erase(ex.begin() + static_cast<std::ptrdiff_t>(worst));
      ex.erase(ex.begin() + static_cast<std::ptrdiff_t>(j));
    }
  }
  return static_cast<int>(std::count_if(ex.begin(), ex.end(), [](const Extremum& e) { return e.maximum; }));
}

double enclosed_area(const HemProfile& profile) {
  const int n = profile.bins();
  double a = 0.0;
  for (double r : profile.radius)
    if (std::isfinite(r)) a += 0.5 * r * r * kTwoPi / n;
  return a;
}

double drape_coefficient(const HemProfile& profile, const SpecimenFacts& specimen) {
  const double R = 0.5 * specimen.cylinder_diameter;
  const double disk = M_PI * R * R;
  return (enclosed_area(profile) - disk) / (specimen.size_x * specimen.size_y - disk);
}

double drape_coefficient(const Capture& capture) {
  return drape_coefficient(hem_profile_from_capture(capture), capture.specimen);
}

RadialProfile radial_profile(const Eigen::Matrix3Xd& points, double cylinder_radius) {
  constexpr double kStep = 0.005, kOuter = 0.23;
  const double r0 = cylinder_radius + 0.005;
  const int bins = std::max(1, static_cast<int>((kOuter - r0) / kStep));
  std::vector<double> sum(bins, 0.0);
  RadialProfile p;
  p.count.assign(bins, 0);
  for (int i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3d q = points.col(i);
    if (!q.allFinite() || q.z() >= kBelowTop) continue;
    const double t = (std::hypot(q.x(), q.y()) - r0) / kStep;  // the cylinder side (r ~ R) stays out
    if (!(t >= 0.0 && t < bins)) continue;  // compared before the cast: a far point's t is beyond an int
    const int k = static_cast<int>(t);
    sum[k] += q.z();
    ++p.count[k];
  }
  p.z.assign(bins, std::numeric_limits<double>::quiet_NaN());
  for (int k = 0; k < bins; ++k)
    if (p.count[k] >= 10) p.z[k] = sum[k] / p.count[k];
  return p;
}

double radial_distance(const RadialProfile& a, const RadialProfile& b) {
  double s = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < a.z.size() && k < b.z.size(); ++k) {
    if (!std::isfinite(a.z[k]) || !std::isfinite(b.z[k])) continue;
    s += (a.z[k] - b.z[k]) * (a.z[k] - b.z[k]);
    ++n;
  }
  return n > 0 ? std::sqrt(s / n) : 0.0;
}

}  // namespace drapegen::diagnosis
