#pragma once
// Where the Pareto plot's labels go: beside their points, inside the plot area, no two overlapping
// and none on a point's marker. gnuplot places a label where it is told and lets labels overprint,
// so the plot computes each label's box itself from the text's length (pure geometry, in pixels of
// the plot area with its origin at the bottom left).

#include <string>
#include <vector>

namespace msfem::compare {

struct LabelMetrics {
  double area_width_px = 0.0, area_height_px = 0.0;  ///< the plot area (inside the axes)
  double char_width_px = 7.0;  ///< the label font's average glyph, rounded up (6.2 measured)
  double line_height_px = 14.0;
  double gap_px = 8.0;  ///< between a point and its label
};

struct PlacedLabel {
  bool placed = false;            ///< false: no free place near the point; the label is left out
  bool right_of_point = true;     ///< text to the right of the point, left-aligned (else mirrored)
  double x_px = 0.0, y_px = 0.0;  ///< the text's anchor: its left (or right) end, vertical middle
  double box[4] = {0, 0, 0, 0};   ///< x0, y0, x1, y1
  bool displaced = false;         ///< moved off its point's row: the plot draws a leader line
};

/// One label per point (`points_px[i]` = x, y in the plot area), placed in order: beside its
/// point, right then left, at growing vertical offsets, the first place whose box lies inside the
/// area and overlaps no placed box and no marker, of a labelled point or of `other_points_px`.
std::vector<PlacedLabel> place_labels(
    const std::vector<std::pair<double, double>>& points_px, const std::vector<std::string>& texts,
    const LabelMetrics& metrics,
    const std::vector<std::pair<double, double>>& other_points_px = {});

/// Whether two boxes (x0, y0, x1, y1) overlap (touching edges do not).
bool boxes_overlap(const double a[4], const double b[4]);

}  // namespace msfem::compare
