#include "drapegen/renderer/software_renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace drapegen::renderer {
namespace {

using Point = SoftwareRenderer::ImagePoint;

/// For coverage, image positions are snapped to 1/256 px (as llvmpipe does) and edge functions are exact 64-bit
/// integers. Within the guard band (|u|, |v| <= 2^20 px, a little more after rounding) differences stay below 2^30
/// units and products below 2^60; geometry beyond it is clipped away first.
constexpr int kSubpixelBits = 8;
constexpr std::int64_t kOne = std::int64_t{1} << kSubpixelBits;
constexpr double kGuardBand = 1 << 20;

/// A camera-space half-space n . x + d >= 0.
struct ClipPlane {
  Eigen::Vector3d n;
  double d = 0.0;
  [[nodiscard]] double at(const Eigen::Vector3d& x) const { return n.dot(x) + d; }
};

/// What a drawn triangle must lie in: in front of the near plane and within the guard band.
std::array<ClipPlane, 5> clip_volume(const Eigen::Matrix3d& K, double near) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ(), ku = K.row(0).transpose(), kv = K.row(1).transpose();
  return {ClipPlane{z, -near}, ClipPlane{kGuardBand * z + ku}, ClipPlane{kGuardBand * z - ku},
          ClipPlane{kGuardBand * z + kv}, ClipPlane{kGuardBand * z - kv}};
}

std::int64_t snap(double x) {
  const double scaled = x * static_cast<double>(kOne);
  return static_cast<std::int64_t>(scaled + (scaled >= 0.0 ? 0.5 : -0.5));
}

/// (u, v, 1/z) of a camera-space point in front of the camera.
Eigen::Vector3d project(const Eigen::Vector3d& x, const Eigen::Matrix3d& K) {
  const double inverse_z = 1.0 / x.z();
  return {(K(0, 0) * x.x() + K(0, 1) * x.y()) * inverse_z + K(0, 2),
          (K(1, 0) * x.x() + K(1, 1) * x.y()) * inverse_z + K(1, 2), inverse_z};
}

/// Makes `p` the image point of a projected point within the guard band (in place: building a Point and copying it
/// costs a store-forwarding stall per vertex).
void set_image_point(Point& p, const Eigen::Vector3d& projected) {
  p.clipped = false;
  p.u = snap(projected.x());
  p.v = snap(projected.y());
  p.exact_u = projected.x();
  p.exact_v = projected.y();
  p.inverse_z = projected.z();
}

// Arithmetic shifts round towards -infinity (C++20): the pixel centres (integer coordinates) at or below and at or
// above a snapped coordinate.
int floor_px(std::int64_t x) { return static_cast<int>(x >> kSubpixelBits); }
int ceil_px(std::int64_t x) { return static_cast<int>(-((-x) >> kSubpixelBits)); }

using Centres = SoftwareRenderer::Centres;

/// The pixel centres of the image in the bounding box of the snapped points (a, b, c).
Centres centres_in_box(const Point& a, const Point& b, const Point& c, int width, int height) {
  return {std::max(ceil_px(std::min({a.u, b.u, c.u})), 0), std::min(floor_px(std::max({a.u, b.u, c.u})), width - 1),
          std::max(ceil_px(std::min({a.v, b.v, c.v})), 0), std::min(floor_px(std::max({a.v, b.v, c.v})), height - 1)};
}

/// The edge p -> q of a triangle with positive area as its edge function at pixel centres, stepped along rows and
/// columns in exact integers: the triangle on the other side of the edge gets exactly the opposite value, so no
/// pixel centre is inside both or neither. A centre exactly on the edge belongs to the triangle for which the edge
/// is a top or left edge (OpenGL's rule): `value` is the edge function minus 1 unless the edge is top or left, so
/// inside means value >= 0.
struct Edge {
  std::int64_t step_u = 0, step_v = 0;
  std::int64_t row = 0;    // at the start of the current row
  std::int64_t value = 0;  // at the current pixel centre

  Edge(const Point& p, const Point& q, int u0, int v0) {
    const std::int64_t du = q.u - p.u, dv = q.v - p.v;
    step_u = -dv * kOne;
    step_v = du * kOne;
    const bool top_left = dv < 0 || (dv == 0 && du > 0);
    row = du * (v0 * kOne - p.v) - dv * (u0 * kOne - p.u) - (top_left ? 0 : 1);
  }
};

/// The weight of the vertex opposite p -> q at x = (u, v): twice the area of the exact image triangle (p, q, x), or 0
/// where x is outside that edge of the exact triangle (a pixel the snapped triangle covers and the exact one just
/// misses): the depth stays within the triangle's.
double weight(const Point& p, const Point& q, double u, double v) {
  return std::max((q.exact_u - p.exact_u) * (v - p.exact_v) - (q.exact_v - p.exact_v) * (u - p.exact_u), 0.0);
}

/// The depth and triangle buffers of one render. Depth 0 is empty; GL_LESS: the first of equal depths stays.
struct Target {
  DepthImage& image;
  std::vector<int>& triangle_of;  // per pixel, the triangle seen (valid where depth > 0)
  DepthRange range;
  PixelBox written;

  /// Covers the pixel centres inside the image triangle (a, b, c) with triangle `id`; the depth of a pixel is the
  /// perspective-correct interpolation of camera z (1/z is linear in the image) over the exact (unsnapped)
  /// triangle, in double precision.
  void triangle(const Point& a, const Point& b, const Point& c, int id) {
    const Centres box = centres_in_box(a, b, c, image.width, image.height);
    if (!box.empty()) triangle(a, b, c, box, id);
  }

  /// The same, given the pixel centres of the image in the triangle's bounding box (not empty).
  void triangle(const Point& a, const Point& b_in, const Point& c_in, const Centres& box, int id) {
    const Point *pb = &b_in, *pc = &c_in;
    const int lo_u = box.lo_u, hi_u = box.hi_u, lo_v = box.lo_v, hi_v = box.hi_v;
    const std::int64_t area = (pb->u - a.u) * (pc->v - a.v) - (pb->v - a.v) * (pc->u - a.u);
    if (area == 0) return;  // no fragments, as in OpenGL
    if (area < 0) std::swap(pb, pc);
    const Point &b = *pb, &c = *pc;
    std::array<Edge, 3> edges = {Edge(b, c, lo_u, lo_v), Edge(c, a, lo_u, lo_v), Edge(a, b, lo_u, lo_v)};
    auto visit = [&](int u, int v) {
      if ((edges[0].value | edges[1].value | edges[2].value) < 0) return;
      const double wa = weight(b, c, u, v), wb = weight(c, a, u, v), wc = weight(a, b, u, v);
      fragment(u, v, (wa + wb + wc) / (wa * a.inverse_z + wb * b.inverse_z + wc * c.inverse_z), id);
    };
    if (lo_u == hi_u && lo_v == hi_v) {  // most drape triangles: one pixel centre in the box
      for (Edge& e : edges) e.value = e.row;
      visit(lo_u, lo_v);
      return;
    }
    for (int v = lo_v; v <= hi_v; ++v) {
      for (Edge& e : edges) e.value = e.row;
      for (int u = lo_u; u <= hi_u; ++u) {
        visit(u, v);
        for (Edge& e : edges) e.value += e.step_u;
      }
      for (Edge& e : edges) e.row += e.step_v;
    }
  }

  void fragment(int u, int v, double z, int id) {
    if (!(z >= range.near && z <= range.far)) return;
    const std::size_t i = static_cast<std::size_t>(v) * image.width + u;
    const float zf = static_cast<float>(z);
    if (image.depth[i] != 0.0f && !(zf < image.depth[i])) return;
    image.depth[i] = zf;
    triangle_of[i] = id;
    written.add(u, v, u, v);
  }
};

/// Clips the camera-space triangle (a, b, c) to the clip volume (Sutherland-Hodgman): a convex polygon of up to 8
/// vertices, in `out`; returns their number.
int clip(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
         const std::array<ClipPlane, 5>& volume, std::array<Eigen::Vector3d, 8>& out) {
  std::array<Eigen::Vector3d, 8> in = {a, b, c};
  int n = 3;
  for (const ClipPlane& plane : volume) {
    int m = 0;
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d &p = in[k], &q = in[(k + 1) % n];
      const double fp = plane.at(p), fq = plane.at(q);
      if (fp >= 0.0) out[m++] = p;
      if ((fp >= 0.0) != (fq >= 0.0)) out[m++] = p + fp / (fp - fq) * (q - p);
    }
    n = m;
    if (n < 3) return 0;
    in = out;
  }
  return n;
}

}  // namespace

SoftwareRenderer::SoftwareRenderer(DepthRange range) : range_(range) {}

sim::Status SoftwareRenderer::set_scene(const TriangleMesh& mesh) {
  if (sim::Status s = validate(mesh); !s) return s;
  scene_ = mesh;
  return {};
}

std::string SoftwareRenderer::name() const { return "drapegen software rasteriser"; }

sim::Expected<DepthImage> SoftwareRenderer::render(const Camera& camera, const Eigen::Isometry3d& model) {
  if (sim::Status s = check_view(camera, model); !s) return s.error();
  if (scene_.triangles.empty()) return sim::Error{"no scene to render (call set_scene first)"};
  if (!(range_.near > 0.0 && range_.far > range_.near)) return sim::Error{"renderer: need 0 < near < far"};
  const int W = camera.intrinsics.width, H = camera.intrinsics.height;
  const Eigen::Matrix3d& K = camera.intrinsics.K;
  const Eigen::Isometry3d to_camera = camera.world_to_camera * model;
  const Eigen::Matrix3d R = to_camera.linear();
  const Eigen::Vector3d t = to_camera.translation();
  const std::size_t nv = scene_.vertices.size();
  eye_.resize(nv);
  points_.resize(nv);
  centres_.resize(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    const Eigen::Vector3d x = R * scene_.vertices[i].cast<double>() + t;
    eye_[i] = x;
    Point& p = points_[i];
    p.clipped = true;
    // A vertex to be clipped gets the whole image, so that its triangles are always candidates.
    centres_[i] = Centres{0, W - 1, 0, H - 1};
    if (!(x.z() >= range_.near)) continue;
    const Eigen::Vector3d projected = project(x, K);
    if (std::abs(projected.x()) <= kGuardBand && std::abs(projected.y()) <= kGuardBand) {
      set_image_point(p, projected);
      centres_[i] = Centres{std::max(ceil_px(p.u), 0), std::min(floor_px(p.u), W - 1), std::max(ceil_px(p.v), 0),
                            std::min(floor_px(p.v), H - 1)};
    }
  }

  DepthImage image(W, H);
  triangle_of_.resize(image.depth.size());
  Target target{image, triangle_of_, range_, {}};
  const auto volume = clip_volume(K, range_.near);
  std::array<Eigen::Vector3d, 8> polygon;
  // Back faces of closed surfaces are hidden unless the near plane cuts them open (then none is skipped).
  int closed_from = scene_.closed_from >= 0 ? scene_.closed_from : scene_.triangle_count();
  for (int id = closed_from; id < scene_.triangle_count(); ++id) {
    for (int k : scene_.triangles[id]) {
      if (!(eye_[k].z() >= range_.near)) closed_from = scene_.triangle_count();
    }
  }
  // First the triangles whose bounding box holds a pixel centre of the image (a third of the drape's hold none), in
  // their order, without a branch per triangle (the per-vertex centres make the box); then only these are set up.
  candidates_.resize(scene_.triangles.size());
  int candidate_count = 0;
  for (int id = 0; id < scene_.triangle_count(); ++id) {
    const std::array<int, 3>& tri = scene_.triangles[id];
    const Centres &a = centres_[tri[0]], &b = centres_[tri[1]], &c = centres_[tri[2]];
    Candidate& candidate = candidates_[candidate_count];
    candidate.id = id;
    candidate.box = {std::min({a.lo_u, b.lo_u, c.lo_u}), std::max({a.hi_u, b.hi_u, c.hi_u}),
                     std::min({a.lo_v, b.lo_v, c.lo_v}), std::max({a.hi_v, b.hi_v, c.hi_v})};
    candidate_count += !candidate.box.empty();
  }
  for (int k = 0; k < candidate_count; ++k) {
    const int id = candidates_[k].id;
    const std::array<int, 3>& tri = scene_.triangles[id];
    if (id >= closed_from) {  // a back face (its normal points away from the camera)
      const Eigen::Vector3d& p = eye_[tri[0]];
      if ((eye_[tri[1]] - p).cross(eye_[tri[2]] - p).dot(p) >= 0.0) continue;
    }
    const Point &a = points_[tri[0]], &b = points_[tri[1]], &c = points_[tri[2]];
    if (!(a.clipped || b.clipped || c.clipped)) {
      target.triangle(a, b, c, candidates_[k].box, id);
      continue;
    }
    const int n = clip(eye_[tri[0]], eye_[tri[1]], eye_[tri[2]], volume, polygon);
    if (n == 0) continue;
    std::array<Point, 8> points;
    for (int k = 0; k < n; ++k) set_image_point(points[k], project(polygon[k], K));
    for (int k = 1; k + 1 < n; ++k) target.triangle(points[0], points[k], points[k + 1], id);
  }

  // Incidence cosine of the triangle seen: |n . d| / (|n| |d|) for the pixel's ray d, capped at 1 (rounding).
  image.incidence.assign(image.depth.size(), 0.0f);
  const Eigen::Matrix3d K_inverse = K.inverse();
  for (int v = target.written.v0; v <= target.written.v1; ++v) {
    for (int u = target.written.u0; u <= target.written.u1; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * W + u;
      if (image.depth[i] == 0.0f) continue;
      const std::array<int, 3>& tri = scene_.triangles[triangle_of_[i]];
      const Eigen::Vector3d n = (eye_[tri[1]] - eye_[tri[0]]).cross(eye_[tri[2]] - eye_[tri[0]]);
      const Eigen::Vector3d d = K_inverse * Eigen::Vector3d(u, v, 1.0);
      const double denominator = std::sqrt(n.squaredNorm() * d.squaredNorm());
      if (denominator > 0.0) image.incidence[i] = static_cast<float>(std::min(std::abs(n.dot(d)) / denominator, 1.0));
    }
  }
  return image;
}

}  // namespace drapegen::renderer
