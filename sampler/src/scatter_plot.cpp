#include "drapegen/sampler/scatter_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fmt/format.h>
#include <map>

#include "drapegen/storage/png.hpp"

namespace drapegen::sampler {
namespace {

struct Rgb {
  unsigned char r, g, b;
};
constexpr Rgb kBlue{31, 119, 180}, kOrange{255, 127, 14}, kBlack{0, 0, 0}, kGrey{200, 200, 200};

/// 5 x 7 glyphs (one 5-bit row each, top first) for the characters the plot writes.
const std::map<char, std::array<unsigned char, 7>>& glyphs() {
  static const std::map<char, std::array<unsigned char, 7>> g = {
      {'0', {14, 17, 19, 21, 25, 17, 14}}, {'1', {4, 12, 4, 4, 4, 4, 14}},     {'2', {14, 17, 1, 2, 4, 8, 31}},
      {'3', {30, 1, 1, 14, 1, 1, 30}},     {'4', {2, 6, 10, 18, 31, 2, 2}},    {'5', {31, 16, 30, 1, 1, 17, 14}},
      {'6', {6, 8, 16, 30, 17, 17, 14}},   {'7', {31, 1, 2, 4, 8, 8, 8}},      {'8', {14, 17, 17, 14, 17, 17, 14}},
      {'9', {14, 17, 17, 15, 1, 2, 12}},   {'-', {0, 0, 0, 31, 0, 0, 0}},      {'_', {0, 0, 0, 0, 0, 0, 31}},
      {'a', {0, 0, 14, 1, 15, 17, 15}},    {'b', {16, 16, 22, 25, 17, 17, 30}}, {'d', {1, 1, 13, 19, 17, 17, 15}},
      {'e', {0, 0, 14, 17, 31, 16, 14}},   {'f', {6, 9, 8, 28, 8, 8, 8}},      {'g', {0, 0, 15, 17, 15, 1, 14}},
      {'h', {16, 16, 22, 25, 17, 17, 17}}, {'i', {4, 0, 12, 4, 4, 4, 14}},     {'l', {12, 4, 4, 4, 4, 4, 14}},
      {'m', {0, 0, 26, 21, 21, 17, 17}},   {'n', {0, 0, 22, 25, 17, 17, 17}},  {'p', {0, 0, 30, 17, 30, 16, 16}},
      {'r', {0, 0, 22, 25, 16, 16, 16}},   {'s', {0, 0, 14, 16, 14, 1, 30}},   {'t', {8, 8, 28, 8, 8, 9, 6}},
      {'u', {0, 0, 17, 17, 17, 19, 13}},   {'w', {0, 0, 17, 17, 21, 21, 10}},  {'(', {2, 4, 8, 8, 8, 4, 2}},
      {')', {8, 4, 2, 2, 2, 4, 8}},        {'|', {4, 4, 4, 4, 4, 4, 4}},       {'k', {16, 16, 18, 20, 24, 20, 18}},
      {'o', {0, 0, 14, 17, 17, 17, 14}},   {'c', {0, 0, 14, 16, 16, 17, 14}},  {'v', {0, 0, 17, 17, 17, 10, 4}},
      {' ', {0, 0, 0, 0, 0, 0, 0}},        {'.', {0, 0, 0, 0, 0, 12, 12}},     {'=', {0, 0, 31, 0, 31, 0, 0}},
  };
  return g;
}

class Canvas {
 public:
  Canvas(int w, int h) : w_(w), h_(h), pixels_(static_cast<std::size_t>(w) * h * 3, 255) {}
  void set(int x, int y, Rgb c) {
    if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
    unsigned char* p = &pixels_[(static_cast<std::size_t>(y) * w_ + x) * 3];
    p[0] = c.r, p[1] = c.g, p[2] = c.b;
  }
  void square(int cx, int cy, int half, Rgb c) {
    for (int y = cy - half; y <= cy + half; ++y) {
      for (int x = cx - half; x <= cx + half; ++x) set(x, y, c);
    }
  }
  void hline(int x0, int x1, int y, Rgb c) {
    for (int x = x0; x <= x1; ++x) set(x, y, c);
  }
  void vline(int x, int y0, int y1, Rgb c) {
    for (int y = y0; y <= y1; ++y) set(x, y, c);
  }
  /// Text with 2x scaled glyphs, top-left at (x, y); returns the width drawn.
  int text(int x, int y, const std::string& s, Rgb c) {
    const int scale = 2;
    int cx = x;
    for (char ch : s) {
      const auto it = glyphs().find(ch);
      if (it != glyphs().end()) {
        for (int row = 0; row < 7; ++row) {
          for (int col = 0; col < 5; ++col) {
            if (it->second[row] & (16 >> col)) {
              for (int dy = 0; dy < scale; ++dy) {
                for (int dx = 0; dx < scale; ++dx) set(cx + col * scale + dx, y + row * scale + dy, c);
              }
            }
          }
        }
      }
      cx += 6 * scale;
    }
    return cx - x;
  }
  static int text_width(const std::string& s) { return static_cast<int>(s.size()) * 12; }
  const std::vector<unsigned char>& pixels() const { return pixels_; }
  int width() const { return w_; }
  int height() const { return h_; }

 private:
  int w_, h_;
  std::vector<unsigned char> pixels_;
};


}  // namespace

sim::Status write_scatter_png(const std::string& path, const ScatterPlotSpec& spec,
                              const std::vector<Features>& generated, const std::vector<Features>& measured) {
  if (spec.x_feature < 0 || spec.x_feature >= kFeatureCount || spec.y_feature < 0 || spec.y_feature >= kFeatureCount) {
    return sim::Error{"plot features must be 0..5"};
  }
  if (spec.width < 200 || spec.height < 200 || spec.width > 8000 || spec.height > 8000) {
    return sim::Error{"plot size must be 200..8000 pixels"};
  }
  // Axis ranges: whole numbers around every finite point.
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const auto* set : {&generated, &measured}) {
    for (const Features& f : *set) {
      const double x = f[spec.x_feature], y = f[spec.y_feature];
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  }
  if (!(x0 <= x1 && y0 <= y1)) return sim::Error{"nothing to plot"};
  x0 = std::floor(x0), x1 = std::ceil(x1) + (std::ceil(x1) == std::floor(x0) ? 1 : 0);
  y0 = std::floor(y0), y1 = std::ceil(y1) + (std::ceil(y1) == std::floor(y0) ? 1 : 0);
  Canvas c(spec.width, spec.height);
  const int left = 70, right = spec.width - 20, top = 50, bottom = spec.height - 60;
  auto px = [&](double x) { return left + static_cast<int>(std::lround((x - x0) / (x1 - x0) * (right - left))); };
  auto py = [&](double y) { return bottom - static_cast<int>(std::lround((y - y0) / (y1 - y0) * (bottom - top))); };
  // Ticks and labels at whole numbers (at most ~12 per axis).
  const int x_step = std::max(1, static_cast<int>(std::ceil((x1 - x0) / 12))),
            y_step = std::max(1, static_cast<int>(std::ceil((y1 - y0) / 12)));
  for (double t = x0; t <= x1; t += x_step) {
    c.vline(px(t), top, bottom, kGrey);
    const std::string label = fmt::format("{:.0f}", t);
    c.text(px(t) - Canvas::text_width(label) / 2, bottom + 8, label, kBlack);
  }
  for (double t = y0; t <= y1; t += y_step) {
    c.hline(left, right, py(t), kGrey);
    const std::string label = fmt::format("{:.0f}", t);
    c.text(left - 8 - Canvas::text_width(label), py(t) - 7, label, kBlack);
  }
  for (const Features& f : generated) {
    if (std::isfinite(f[spec.x_feature]) && std::isfinite(f[spec.y_feature])) {
      c.square(px(f[spec.x_feature]), py(f[spec.y_feature]), 1, kBlue);
    }
  }
  for (const Features& f : measured) c.square(px(f[spec.x_feature]), py(f[spec.y_feature]), 2, kOrange);
  c.hline(left, right, top, kBlack), c.hline(left, right, bottom, kBlack);
  c.vline(left, top, bottom, kBlack), c.vline(right, top, bottom, kBlack);
  const std::string x_name = std::string("sign ln|") + kFeatureNames[spec.x_feature] + "|";
  const std::string y_name = std::string("sign ln|") + kFeatureNames[spec.y_feature] + "|";
  c.text((left + right) / 2 - Canvas::text_width(x_name) / 2, bottom + 32, x_name, kBlack);
  c.text(left, 14, y_name, kBlack);
  int lx = right - Canvas::text_width("generated") - 240;
  c.square(lx, 21, 3, kBlue);
  lx += 10 + c.text(lx + 10, 14, fmt::format("generated {}", generated.size()), kBlack);
  c.square(lx + 20, 21, 3, kOrange);
  c.text(lx + 30, 14, fmt::format("measured {}", measured.size()), kBlack);
  return storage::write_png_rgb(path, c.width(), c.height(), c.pixels());
}

}  // namespace drapegen::sampler
