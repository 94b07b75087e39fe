#include "drapegen/sim/measures.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace drapegen::sim {
namespace {

constexpr double kPi = std::numbers::pi;

/// Throws std::invalid_argument unless the triangles index the positions and these are finite and small enough
/// that squared distances cannot overflow.
void require_valid_mesh(const ClothMesh& mesh, const char* caller) {
  const Eigen::Index nv = mesh.positions.cols();
  if (mesh.triangles.size() > 0 && (mesh.triangles.minCoeff() < 0 || mesh.triangles.maxCoeff() >= nv)) {
    throw std::invalid_argument(std::string(caller) + ": a triangle refers to a vertex out of range");
  }
  if (!mesh.positions.allFinite()) throw std::invalid_argument(std::string(caller) + ": non-finite position");
  if (nv > 0 && !(mesh.positions.cwiseAbs().maxCoeff() < 1e100)) {
    throw std::invalid_argument(std::string(caller) + ": position beyond 1e100 m");
  }
}

// ---------------------------------------------------------------------------------------------------------------------
// Shadow area.

/// A triangle's projection and the grid rows whose centre lines may cross it.
struct RowSpan {
  std::int64_t first_row = 0, last_row = 0;
  std::array<Eigen::Vector2d, 3> corners;
};

/// Appends the closed x-interval where the line y = yc crosses the triangle, as a range of cell indices whose centres
/// x0 + (i + 1/2) pixel lie in it (slightly widened so that cells on shared edges are never lost to rounding).
void append_cells_on_row(const std::array<Eigen::Vector2d, 3>& corners, double yc, double x0, double pixel,
                         std::int64_t columns, std::vector<std::pair<std::int64_t, std::int64_t>>& cells) {
  constexpr double kSlack = 1e-7;  // in cells
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int k = 0; k < 3; ++k) {
    // Order the endpoints so that both triangles sharing an edge compute bit-identical crossings.
    Eigen::Vector2d p = corners[k], q = corners[(k + 1) % 3];
    if (std::tie(p.y(), p.x()) > std::tie(q.y(), q.x())) std::swap(p, q);
    if (yc < p.y() || yc > q.y()) continue;
    const double x = p.y() == q.y() ? p.x() : p.x() + (yc - p.y()) / (q.y() - p.y()) * (q.x() - p.x());
    const double x_end = p.y() == q.y() ? q.x() : x;
    lo = std::min({lo, x, x_end});
    hi = std::max({hi, x, x_end});
  }
  if (lo > hi) return;
  const auto first = static_cast<std::int64_t>(std::ceil((lo - x0) / pixel - 0.5 - kSlack));
  const auto last = static_cast<std::int64_t>(std::floor((hi - x0) / pixel - 0.5 + kSlack));
  if (first <= last) cells.emplace_back(std::max<std::int64_t>(first, 0), std::min(last, columns - 1));
}

/// The number of distinct cells covered by a set of closed index ranges.
std::int64_t count_union(std::vector<std::pair<std::int64_t, std::int64_t>>& ranges) {
  std::sort(ranges.begin(), ranges.end());
  std::int64_t count = 0, end = -1;  // cells before `end` + 1 are counted
  for (const auto& [first, last] : ranges) {
    const std::int64_t from = std::max(first, end + 1);
    if (last >= from) {
      count += last - from + 1;
      end = last;
    }
  }
  return count;
}

// ---------------------------------------------------------------------------------------------------------------------
// Robust orientation predicates (Shewchuk's filters): +1, -1, or 0 when rounding could have decided the sign.

int orient2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const double left = (a.x() - c.x()) * (b.y() - c.y());
  const double right = (a.y() - c.y()) * (b.x() - c.x());
  const double det = left - right;
  const double bound = 3.3306690738754716e-16 * (std::abs(left) + std::abs(right));
  return det > bound ? 1 : (det < -bound ? -1 : 0);
}

int orient3d(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  const Eigen::Vector3d ad = a - d, bd = b - d, cd = c - d;
  const double bxcy = bd.x() * cd.y(), cxby = cd.x() * bd.y();
  const double cxay = cd.x() * ad.y(), axcy = ad.x() * cd.y();
  const double axby = ad.x() * bd.y(), bxay = bd.x() * ad.y();
  const double det = ad.z() * (bxcy - cxby) + bd.z() * (cxay - axcy) + cd.z() * (axby - bxay);
  const double permanent = (std::abs(bxcy) + std::abs(cxby)) * std::abs(ad.z()) +
                           (std::abs(cxay) + std::abs(axcy)) * std::abs(bd.z()) +
                           (std::abs(axby) + std::abs(bxay)) * std::abs(cd.z());
  const double bound = 7.7715611723761027e-16 * permanent;
  return det > bound ? 1 : (det < -bound ? -1 : 0);
}

// ---------------------------------------------------------------------------------------------------------------------
// Closed segment / triangle intersection tests.

using Triangle = std::array<Eigen::Vector3d, 3>;
using Triangle2 = std::array<Eigen::Vector2d, 3>;

/// For points known to be collinear with segment ab: whether p lies within its bounding box.
bool within_box(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  return p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()) && p.y() >= std::min(a.y(), b.y()) &&
         p.y() <= std::max(a.y(), b.y());
}

bool segments_meet_2d(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& a,
                      const Eigen::Vector2d& b) {
  const int d1 = orient2d(p, q, a), d2 = orient2d(p, q, b), d3 = orient2d(a, b, p), d4 = orient2d(a, b, q);
  if (d1 * d2 < 0 && d3 * d4 < 0) return true;
  return (d1 == 0 && within_box(p, q, a)) || (d2 == 0 && within_box(p, q, b)) || (d3 == 0 && within_box(a, b, p)) ||
         (d4 == 0 && within_box(a, b, q));
}

bool point_in_triangle_2d(const Eigen::Vector2d& p, const Triangle2& t) {
  const int s0 = orient2d(t[0], t[1], p), s1 = orient2d(t[1], t[2], p), s2 = orient2d(t[2], t[0], p);
  return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
}

/// The point without its coordinate `axis` (the other two in cyclic order, keeping orientations).
Eigen::Vector2d drop_axis(const Eigen::Vector3d& p, int axis) {
  return axis == 0 ? Eigen::Vector2d(p.y(), p.z()) : (axis == 1 ? Eigen::Vector2d(p.z(), p.x()) : p.head<2>());
}

Triangle2 project(const Triangle& t, int axis) {
  return {drop_axis(t[0], axis), drop_axis(t[1], axis), drop_axis(t[2], axis)};
}

int dominant_axis(const Eigen::Vector3d& normal) {
  int axis = 0;
  normal.cwiseAbs().maxCoeff(&axis);
  return axis;
}

/// Whether segment pq meets triangle t, both projected from t's plane.
bool segment_meets_triangle_2d(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Triangle2& t) {
  return point_in_triangle_2d(p, t) || point_in_triangle_2d(q, t) || segments_meet_2d(p, q, t[0], t[1]) ||
         segments_meet_2d(p, q, t[1], t[2]) || segments_meet_2d(p, q, t[2], t[0]);
}

/// A triangle with its plane. Points within `tolerance` of the plane count as on it: rounding in the coordinates
/// (say of a flat sheet rotated into a tilted plane) must not turn coplanar contact into crossings.
struct Facet {
  Triangle corners;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit
  double tolerance = 0.0;
  int axis = 2;              // the normal's largest component, dropped for tests within the plane
  bool degenerate = false;   // |cross product| <= 1e-6 longest edge^2: only its edges take part
};

Facet make_facet(const Triangle& corners) {
  Facet facet;
  facet.corners = corners;
  const Eigen::Vector3d n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
  const double longest = std::max({(corners[1] - corners[0]).norm(), (corners[2] - corners[1]).norm(),
                                   (corners[0] - corners[2]).norm()});
  const double magnitude = std::max({corners[0].cwiseAbs().maxCoeff(), corners[1].cwiseAbs().maxCoeff(),
                                     corners[2].cwiseAbs().maxCoeff()});
  facet.degenerate = !(n.norm() > 1e-6 * longest * longest);
  if (facet.degenerate) return facet;
  facet.normal = n.normalized();
  facet.axis = dominant_axis(n);
  // 1e-9 of the size, plus the rounding of the normal and the offsets (relative eps * longest^2 / |n| each).
  facet.tolerance = 1e-9 * longest + 1e-13 * magnitude * longest * longest / n.norm();
  return facet;
}

/// -1, 0 or +1: the side of the facet's plane on which p lies, 0 within the tolerance.
int side_of(const Facet& facet, const Eigen::Vector3d& p) {
  const double distance = facet.normal.dot(p - facet.corners[0]);
  return distance > facet.tolerance ? 1 : (distance < -facet.tolerance ? -1 : 0);
}

/// Whether segment pq meets the non-degenerate facet t; sp, sq are the sides of t's plane where p and q lie.
bool segment_meets_facet(const Eigen::Vector3d& p, const Eigen::Vector3d& q, int sp, int sq, const Facet& t) {
  if (sp * sq > 0) return false;
  const Triangle2 flat = project(t.corners, t.axis);
  // In the plane: a 2D test. One end on it, the other off: only that end can touch.
  if (sp == 0 && sq == 0) return segment_meets_triangle_2d(drop_axis(p, t.axis), drop_axis(q, t.axis), flat);
  if (sp == 0) return point_in_triangle_2d(drop_axis(p, t.axis), flat);
  if (sq == 0) return point_in_triangle_2d(drop_axis(q, t.axis), flat);
  // Ends clearly on either side: the line passes through t iff it turns the same way round all three edges.
  const Triangle& c = t.corners;
  const int s0 = orient3d(p, q, c[0], c[1]), s1 = orient3d(p, q, c[1], c[2]), s2 = orient3d(p, q, c[2], c[0]);
  return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
}

/// Whether any edge of `a` meets the non-degenerate facet `b`; `sides` are a's corners' sides of b's plane.
bool edges_meet(const Triangle& a, const std::array<int, 3>& sides, const Facet& b) {
  for (int k = 0; k < 3; ++k) {
    const int j = (k + 1) % 3;
    if (segment_meets_facet(a[k], a[j], sides[k], sides[j], b)) return true;
  }
  return false;
}

std::array<int, 3> sides_of(const Facet& plane, const Triangle& t) {
  return {side_of(plane, t[0]), side_of(plane, t[1]), side_of(plane, t[2])};
}

bool strictly_one_side(const std::array<int, 3>& sides) {
  return (sides[0] > 0 && sides[1] > 0 && sides[2] > 0) || (sides[0] < 0 && sides[1] < 0 && sides[2] < 0);
}

/// Whether two closed triangles intersect. Two degenerate ones are taken not to.
bool facets_intersect(const Facet& a, const Facet& b) {
  if (a.degenerate && b.degenerate) return false;
  if (a.degenerate) return edges_meet(a.corners, sides_of(b, a.corners), b);
  if (b.degenerate) return edges_meet(b.corners, sides_of(a, b.corners), a);
  const std::array<int, 3> a_sides = sides_of(b, a.corners);
  if (strictly_one_side(a_sides)) return false;
  const std::array<int, 3> b_sides = sides_of(a, b.corners);
  if (strictly_one_side(b_sides)) return false;
  // Two non-coplanar triangles meet iff an edge of one meets the other (the ends of their common segment lie on
  // edges); coplanar ones iff an edge of one crosses the other or lies inside it, which the same tests cover.
  return edges_meet(a.corners, a_sides, b) || edges_meet(b.corners, b_sides, a);
}

// ---------------------------------------------------------------------------------------------------------------------
// Spatial hash for candidate pairs.

/// A uniform grid over the bounding box of the mesh, cells numbered x fastest.
struct Grid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double cell = 1.0;
  std::array<std::int64_t, 3> dims = {1, 1, 1};

  /// Integer coordinates of the cell holding p (a point of the bounding box).
  [[nodiscard]] std::array<std::int64_t, 3> coords(const Eigen::Vector3d& p) const {
    std::array<std::int64_t, 3> c;
    for (int k = 0; k < 3; ++k) {
      c[k] = std::clamp(static_cast<std::int64_t>(std::floor((p[k] - origin[k]) / cell)), std::int64_t{0}, dims[k] - 1);
    }
    return c;
  }
  [[nodiscard]] std::uint64_t key(const std::array<std::int64_t, 3>& c) const {
    return static_cast<std::uint64_t>(c[0] + dims[0] * (c[1] + dims[1] * c[2]));
  }
};

/// Chooses the cell size: the mean triangle extent, doubled until the triangles overlap a bounded number of cells.
/// At least a millionth of the mesh's size, so that cell numbers fit in 64 bits.
Grid make_grid(const std::vector<Eigen::AlignedBox3d>& boxes) {
  Grid grid;
  Eigen::AlignedBox3d all;
  double extent_sum = 0.0;
  for (const auto& box : boxes) {
    all.extend(box);
    extent_sum += box.sizes().maxCoeff();
  }
  grid.origin = all.min();
  const double size = all.sizes().maxCoeff();
  grid.cell = std::max(extent_sum / static_cast<double>(boxes.size()), 1e-6 * size);
  if (!(grid.cell > 0.0)) grid.cell = 1.0;  // every triangle is the same point
  const double budget = 16.0 * static_cast<double>(boxes.size()) + 1024.0;
  while (true) {
    double entries = 0.0;
    for (const auto& box : boxes) {
      const Eigen::Array3d span = ((box.max() - grid.origin) / grid.cell).array().floor() -
                                  ((box.min() - grid.origin) / grid.cell).array().floor() + 1.0;
      entries += span.prod();
    }
    if (entries <= budget) break;
    grid.cell *= 2.0;
  }
  for (int k = 0; k < 3; ++k) grid.dims[k] = static_cast<std::int64_t>(std::floor(all.sizes()[k] / grid.cell)) + 1;
  return grid;
}

/// A triangle listed in one grid cell.
struct CellEntry {
  std::uint64_t cell;
  int triangle;
  friend bool operator<(const CellEntry& a, const CellEntry& b) {
    return a.cell < b.cell || (a.cell == b.cell && a.triangle < b.triangle);
  }
};

/// A triangle's data for the pair loop, gathered per cell.
struct Candidate {
  Eigen::AlignedBox3d box;
  Eigen::Vector3i vertices;
  int triangle;
};

// ---------------------------------------------------------------------------------------------------------------------
// Fold counting.

/// Circular Gaussian smoothing with a standard deviation of `sigma` samples.
std::vector<double> smooth_circular(const std::vector<double>& values, double sigma) {
  const int n = static_cast<int>(values.size());
  if (sigma < 0.25 || n < 3) return values;
  const int radius = std::min(static_cast<int>(std::ceil(3.0 * sigma)), (n - 1) / 2);
  std::vector<double> weights(radius + 1);
  double total = 0.0;
  for (int k = 0; k <= radius; ++k) {
    weights[k] = std::exp(-0.5 * (k / sigma) * (k / sigma));
    total += k == 0 ? weights[k] : 2.0 * weights[k];
  }
  std::vector<double> smoothed(n, 0.0);
  for (int i = 0; i < n; ++i) {
    double sum = weights[0] * values[i];
    for (int k = 1; k <= radius; ++k) sum += weights[k] * (values[(i + k) % n] + values[(i - k + n) % n]);
    smoothed[i] = sum / total;
  }
  return smoothed;
}

/// Prominence of the circular peak whose plateau spans [first, last] (indices modulo n, walking forwards).
double circular_prominence(const std::vector<double>& v, int first, int last) {
  const int n = static_cast<int>(v.size());
  const double height = v[first];
  // Walk away on each side until a strictly higher value or all the way round; the lowest value seen is
  // that side's col.
  auto col = [&](int start, int step) {
    double lowest = height;
    for (int i = 1; i < n; ++i) {
      const double value = v[((start + step * i) % n + n) % n];
      if (value > height) break;
      lowest = std::min(lowest, value);
    }
    return lowest;
  };
  return height - std::max(col(last, +1), col(first, -1));
}

}  // namespace

double projected_area(const ClothMesh& mesh, double pixel) {
  require_valid_mesh(mesh, "projected_area");
  if (!(pixel > 0.0) || !std::isfinite(pixel)) throw std::invalid_argument("projected_area: pixel must be positive");
  if (mesh.triangle_count() == 0 || mesh.positions.cols() == 0) return 0.0;

  const Eigen::Vector2d lower = mesh.positions.topRows<2>().rowwise().minCoeff();
  const Eigen::Vector2d upper = mesh.positions.topRows<2>().rowwise().maxCoeff();
  const Eigen::Vector2d cells = ((upper - lower) / pixel).array().ceil().max(1.0);
  constexpr double kMaxCellsPerSide = 1 << 22;
  if (cells.maxCoeff() > kMaxCellsPerSide) {
    std::array<char, 160> message;
    std::snprintf(message.data(), message.size(), "projected_area: the mesh spans %.3g m, over %.0f pixels of %.3g m",
                  (upper - lower).maxCoeff(), kMaxCellsPerSide, pixel);
    throw std::invalid_argument(message.data());
  }
  const auto columns = static_cast<std::int64_t>(cells.x()), rows = static_cast<std::int64_t>(cells.y());

  // Each triangle with a non-zero shadow, with the rows it may cover.
  std::vector<RowSpan> spans;
  spans.reserve(mesh.triangle_count());
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    RowSpan span;
    for (int k = 0; k < 3; ++k) span.corners[k] = mesh.positions.col(mesh.triangles(k, t)).head<2>();
    const Eigen::Vector2d e1 = span.corners[1] - span.corners[0], e2 = span.corners[2] - span.corners[0];
    if (std::abs(e1.x() * e2.y() - e1.y() * e2.x()) <= 1e-14 * e1.squaredNorm() + 1e-14 * e2.squaredNorm()) continue;
    const double y_min = std::min({span.corners[0].y(), span.corners[1].y(), span.corners[2].y()});
    const double y_max = std::max({span.corners[0].y(), span.corners[1].y(), span.corners[2].y()});
    span.first_row =
        std::max<std::int64_t>(0, static_cast<std::int64_t>(std::ceil((y_min - lower.y()) / pixel - 0.5 - 1e-7)));
    span.last_row = std::min(rows - 1, static_cast<std::int64_t>(std::floor((y_max - lower.y()) / pixel - 0.5 + 1e-7)));
    if (span.first_row <= span.last_row) spans.push_back(span);
  }
  std::sort(spans.begin(), spans.end(), [](const RowSpan& a, const RowSpan& b) { return a.first_row < b.first_row; });

  // Sweep the rows upwards, keeping the triangles that cross the current row.
  std::int64_t covered = 0;
  std::vector<int> active;
  std::vector<std::pair<std::int64_t, std::int64_t>> ranges;
  std::size_t next = 0;
  for (std::int64_t row = 0; row < rows; ++row) {
    if (active.empty()) {
      if (next == spans.size()) break;
      row = std::max(row, spans[next].first_row);
    }
    while (next < spans.size() && spans[next].first_row <= row) active.push_back(static_cast<int>(next++));
    std::erase_if(active, [&](int s) { return spans[s].last_row < row; });
    const double yc = lower.y() + (static_cast<double>(row) + 0.5) * pixel;
    ranges.clear();
    for (const int s : active) append_cells_on_row(spans[s].corners, yc, lower.x(), pixel, columns, ranges);
    covered += count_union(ranges);
  }
  return static_cast<double>(covered) * pixel * pixel;
}

double drape_coefficient(const ClothMesh& mesh, double platform_radius, double pixel) {
  require_valid_mesh(mesh, "drape_coefficient");
  if (mesh.rest.cols() != mesh.positions.cols()) {
    throw std::invalid_argument("drape_coefficient: rest and positions have different vertex counts");
  }
  const double rest_area = rest_triangle_areas(mesh).cwiseAbs().sum();
  const double platform_area = kPi * platform_radius * platform_radius;
  if (!(platform_radius >= 0.0) || !(platform_area < rest_area)) {
    throw std::invalid_argument("drape_coefficient: need 0 <= R and pi R^2 < the specimen's rest area");
  }
  return (projected_area(mesh, pixel) - platform_area) / (rest_area - platform_area);
}

std::vector<double> hem_profile(const ClothMesh& mesh, int bins) {
  require_valid_mesh(mesh, "hem_profile");
  if (bins < 1) throw std::invalid_argument("hem_profile: bins must be at least 1");
  const double width = 2.0 * kPi / bins;
  std::vector<double> profile(bins, 0.0);
  auto raise = [&](std::int64_t bin, double radius) {
    double& slot = profile[static_cast<std::size_t>(((bin % bins) + bins) % bins)];
    slot = std::max(slot, radius);
  };

  // Vertices: the ones used by triangles, in the bin of their azimuth.
  const int nv = static_cast<int>(mesh.positions.cols());
  std::vector<double> azimuth(nv), radius(nv);
  std::vector<bool> used(nv, false);
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) used[mesh.triangles(k, t)] = true;
  }
  for (int i = 0; i < nv; ++i) {
    const double x = mesh.positions(0, i), y = mesh.positions(1, i);
    azimuth[i] = std::atan2(y, x);  // (-pi, pi]
    radius[i] = std::hypot(x, y);
    if (!used[i]) continue;
    const double u = azimuth[i] / width;
    const auto bin = static_cast<std::int64_t>(std::floor(u));
    raise(bin, radius[i]);
    if (u - static_cast<double>(bin) < 1e-9) raise(bin - 1, radius[i]);  // on a bin ray: in both closed wedges
  }

  // Edge crossings with the bin rays psi_k = k * width; ray k bounds bins k - 1 and k.
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    for (int e = 0; e < 3; ++e) {
      const int i = mesh.triangles(e, t), j = mesh.triangles((e + 1) % 3, t);
      if (radius[i] == 0.0 || radius[j] == 0.0) continue;  // a segment from the axis adds nothing beyond its ends
      double sweep = azimuth[j] - azimuth[i];             // the short way round: the segment misses the axis
      if (sweep > kPi) sweep -= 2.0 * kPi;
      if (sweep < -kPi) sweep += 2.0 * kPi;
      const double from = std::min(azimuth[i], azimuth[i] + sweep), to = std::max(azimuth[i], azimuth[i] + sweep);
      const Eigen::Vector2d p = mesh.positions.col(i).head<2>(), d = mesh.positions.col(j).head<2>() - p;
      // Rays within rounding of the ends are included; the range check on s below sorts them out.
      const double last = to / width + 1e-9;
      for (auto k = static_cast<std::int64_t>(std::ceil(from / width - 1e-9)); static_cast<double>(k) <= last; ++k) {
        const double angle = static_cast<double>(k) * width;
        const Eigen::Vector2d ray(std::cos(angle), std::sin(angle));
        const double denominator = ray.x() * d.y() - ray.y() * d.x();
        if (denominator == 0.0) continue;  // parallel: the ends already count
        const double s = -(ray.x() * p.y() - ray.y() * p.x()) / denominator;
        if (s < -1e-12 || s > 1.0 + 1e-12) continue;
        const double distance = ray.dot(p + std::clamp(s, 0.0, 1.0) * d);
        if (distance > 0.0) {
          raise(k, distance);
          raise(k - 1, distance);
        }
      }
    }
  }
  return profile;
}

int count_folds(const std::vector<double>& profile, double min_prominence) {
  for (const double r : profile) {
    if (!std::isfinite(r)) throw std::invalid_argument("count_folds: non-finite profile value");
  }
  const int n = static_cast<int>(profile.size());
  if (n < 3) return 0;
  const std::vector<double> v = smooth_circular(profile, n / 180.0);

  // Start the scan just after a global minimum so that no plateau of a peak wraps past the start.
  const int start = static_cast<int>(std::min_element(v.begin(), v.end()) - v.begin());
  auto at = [&](int i) { return v[(start + i) % n]; };
  int folds = 0;
  for (int i = 1; i < n; ++i) {
    if (!(at(i) > at(i - 1))) continue;
    int last = i;  // end of the plateau starting at i
    while (last + 1 < n && at(last + 1) == at(i)) ++last;
    // at(n) is the minimum again, so a plateau reaching the end is a peak.
    if (last + 1 == n || at(last + 1) < at(i)) {
      if (circular_prominence(v, (start + i) % n, (start + last) % n) >= min_prominence) ++folds;
    }
    i = last;
  }
  return folds;
}

int count_self_intersections(const ClothMesh& mesh) {
  require_valid_mesh(mesh, "count_self_intersections");
  const int nt = mesh.triangle_count();
  if (nt < 2) return 0;
  std::vector<Facet> facets(nt);
  std::vector<Eigen::AlignedBox3d> boxes(nt);
  for (int t = 0; t < nt; ++t) {
    Triangle corners;
    for (int k = 0; k < 3; ++k) {
      corners[k] = mesh.positions.col(mesh.triangles(k, t));
      boxes[t].extend(corners[k]);
    }
    facets[t] = make_facet(corners);
  }
  const Grid grid = make_grid(boxes);

  std::vector<CellEntry> entries;
  entries.reserve(4 * static_cast<std::size_t>(nt));
  for (int t = 0; t < nt; ++t) {
    const auto lo = grid.coords(boxes[t].min()), hi = grid.coords(boxes[t].max());
    for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
      for (std::int64_t y = lo[1]; y <= hi[1]; ++y) {
        for (std::int64_t x = lo[0]; x <= hi[0]; ++x) entries.push_back(CellEntry{grid.key({x, y, z}), t});
      }
    }
  }
  std::sort(entries.begin(), entries.end());

  auto share_vertex = [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
    return (a.array() == b[0]).any() || (a.array() == b[1]).any() || (a.array() == b[2]).any();
  };
  int count = 0;
  std::vector<Candidate> in_cell;
  for (std::size_t begin = 0, end = 0; begin < entries.size(); begin = end) {
    in_cell.clear();
    for (end = begin; end < entries.size() && entries[end].cell == entries[begin].cell; ++end) {
      const int t = entries[end].triangle;
      in_cell.push_back(Candidate{boxes[t], mesh.triangles.col(t), t});
    }
    for (std::size_t i = 0; i < in_cell.size(); ++i) {
      for (std::size_t j = i + 1; j < in_cell.size(); ++j) {
        const Candidate &a = in_cell[i], &b = in_cell[j];
        if (!a.box.intersects(b.box) || share_vertex(a.vertices, b.vertices)) continue;
        // Decide each pair once: in the cell holding the lower corner of the boxes' overlap.
        if (grid.key(grid.coords(a.box.min().cwiseMax(b.box.min()))) != entries[begin].cell) continue;
        if (facets_intersect(facets[a.triangle], facets[b.triangle])) ++count;
      }
    }
  }
  return count;
}

bool lies_face_down(const ClothMesh& mesh) {
  require_valid_mesh(mesh, "lies_face_down");
  double area = 0.0;  // twice the signed projected area
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    const auto a = mesh.positions.col(mesh.triangles(0, t));
    const auto b = mesh.positions.col(mesh.triangles(1, t));
    const auto c = mesh.positions.col(mesh.triangles(2, t));
    area += (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
  }
  return area < 0.0;
}

}  // namespace drapegen::sim
