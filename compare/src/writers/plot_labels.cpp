#include "msfem/compare/writers/plot_labels.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace msfem::compare {
namespace {

constexpr double kMarkerPx = 12.0;  // a labelled point's marker, as an obstacle
// The label's middle against its point's, in lines: just above, just below, then farther out.
constexpr double kRowOffsets[] = {0.5, -0.5, 1.5, -1.5, 2.5, -2.5, 3.5, -3.5, 4.5, -4.5};

bool inside(const double box[4], const LabelMetrics& m) {
  return box[0] >= 0 && box[1] >= 0 && box[2] <= m.area_width_px && box[3] <= m.area_height_px;
}

PlacedLabel candidate(double px, double py, double width, bool right, double row,
                      const LabelMetrics& m) {
  PlacedLabel l;
  l.right_of_point = right;
  l.x_px = right ? px + m.gap_px : px - m.gap_px;
  l.y_px = py + row * m.line_height_px;
  l.box[0] = right ? l.x_px : l.x_px - width;
  l.box[2] = right ? l.x_px + width : l.x_px;
  l.box[1] = l.y_px - 0.5 * m.line_height_px;
  l.box[3] = l.y_px + 0.5 * m.line_height_px;
  l.displaced = std::abs(row) > 1.0;
  return l;
}

}  // namespace

bool boxes_overlap(const double a[4], const double b[4]) {
  return a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
}

std::vector<PlacedLabel> place_labels(const std::vector<std::pair<double, double>>& points_px,
                                      const std::vector<std::string>& texts, const LabelMetrics& m,
                                      const std::vector<std::pair<double, double>>& others) {
  using Box = std::array<double, 4>;
  std::vector<Box> taken;
  std::vector<std::pair<double, double>> markers = points_px;
  markers.insert(markers.end(), others.begin(), others.end());
  for (const auto& [x, y] : markers)
    taken.push_back(
        Box{{x - 0.5 * kMarkerPx, y - 0.5 * kMarkerPx, x + 0.5 * kMarkerPx, y + 0.5 * kMarkerPx}});
  std::vector<PlacedLabel> labels(points_px.size());
  for (std::size_t i = 0; i < points_px.size() && i < texts.size(); ++i) {
    const double width = m.char_width_px * static_cast<double>(texts[i].size());
    for (const double row : kRowOffsets)
      for (const bool right : {true, false}) {
        if (labels[i].placed) break;
        PlacedLabel l = candidate(points_px[i].first, points_px[i].second, width, right, row, m);
        const bool free =
            inside(l.box, m) && std::none_of(taken.begin(), taken.end(), [&](const auto& box) {
              return boxes_overlap(l.box, box.data());
            });
        if (!free) continue;
        l.placed = true;
        taken.push_back(Box{{l.box[0], l.box[1], l.box[2], l.box[3]}});
        labels[i] = l;
      }
  }
  return labels;
}

}  // namespace msfem::compare
