// The Pareto plot's labels: every placed box inside the plot area, no two overlapping and none on
// a labelled point, on fronts as crowded as a sweep's.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "msfem/compare/writers/plot_labels.hpp"

namespace msfem::compare {
namespace {

LabelMetrics area(double width, double height) {
  LabelMetrics m;
  m.area_width_px = width;
  m.area_height_px = height;
  return m;
}

// Every placed label lies inside the area, clear of every other label and of every point's
// 12-pixel marker; returns how many were placed.
int check_layout(const std::vector<std::pair<double, double>>& at,
                 const std::vector<std::string>& texts, const LabelMetrics& m,
                 const std::vector<std::pair<double, double>>& others = {}) {
  const std::vector<PlacedLabel> labels = place_labels(at, texts, m, others);
  EXPECT_EQ(labels.size(), at.size());
  int placed = 0;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (!labels[i].placed) continue;
    ++placed;
    const double* b = labels[i].box;
    EXPECT_GE(b[0], 0.0) << texts[i];
    EXPECT_GE(b[1], 0.0) << texts[i];
    EXPECT_LE(b[2], m.area_width_px) << texts[i];
    EXPECT_LE(b[3], m.area_height_px) << texts[i];
    EXPECT_NEAR(b[2] - b[0], m.char_width_px * static_cast<double>(texts[i].size()), 1e-9);
    for (std::size_t j = 0; j < labels.size(); ++j) {
      if (j != i && labels[j].placed) {
        EXPECT_FALSE(boxes_overlap(b, labels[j].box)) << texts[i] << " on " << texts[j];
      }
      const double marker[4] = {at[j].first - 6, at[j].second - 6, at[j].first + 6,
                                at[j].second + 6};
      EXPECT_FALSE(boxes_overlap(b, marker)) << texts[i] << " on the point of " << texts[j];
    }
    for (const auto& [x, y] : others) {
      const double marker[4] = {x - 6, y - 6, x + 6, y + 6};
      EXPECT_FALSE(boxes_overlap(b, marker)) << texts[i] << " on the point at " << x << ", " << y;
    }
  }
  return placed;
}

TEST(PlotLabels, AnUncrowdedFrontIsLabelledBesideEachPoint) {
  const LabelMetrics m = area(783, 396);
  const std::vector<std::pair<double, double>> at = {{100, 300}, {400, 200}, {700, 100}};
  const std::vector<std::string> texts = {"three_tier rk4 @ 3", "skeleton symplectic_euler @ 2",
                                          "single_layer implicit_euler @ 4"};
  EXPECT_EQ(check_layout(at, texts, m), 3);
  const std::vector<PlacedLabel> labels = place_labels(at, texts, m);
  EXPECT_TRUE(labels[0].right_of_point);
  EXPECT_FALSE(labels[0].displaced);
  // Near the right edge the text goes to the left of its point instead of leaving the plot.
  EXPECT_FALSE(labels[2].right_of_point);
  EXPECT_NEAR(labels[2].x_px, 700 - m.gap_px, 1e-9);
}

TEST(PlotLabels, ACrowdedFrontNeverOverlaps) {
  const LabelMetrics m = area(783, 396);
  // Twelve points on a short diagonal, each label longer than the gap between points: the layout
  // must move labels off their rows (with leader lines) or leave some out, never overprint.
  std::vector<std::pair<double, double>> at;
  std::vector<std::string> texts;
  for (int i = 0; i < 12; ++i) {
    at.emplace_back(300 + 12.0 * i, 150 + 6.0 * i);
    texts.push_back("skeleton central_difference @ " + std::to_string(i));
  }
  const int placed = check_layout(at, texts, m);
  EXPECT_GE(placed, 6);
  int displaced = 0;
  for (const PlacedLabel& l : place_labels(at, texts, m))
    displaced += l.placed && l.displaced ? 1 : 0;
  EXPECT_GT(displaced, 0);
}

TEST(PlotLabels, LabelsStepAroundTheUnlabelledPoints) {
  // The sphere sweep's front: two configurations at the fast end, with the other configurations
  // scattered where their labels would go.
  const LabelMetrics m = area(783, 396);
  const std::vector<std::pair<double, double>> at = {{708, 74}, {698, 70}};
  const std::vector<std::string> texts = {"single_layer symplectic_euler @2",
                                          "skeleton central_difference @2"};
  std::vector<std::pair<double, double>> others;
  for (int i = 0; i < 40; ++i)
    others.emplace_back(500 + 5.0 * i, 40 + 4.0 * (i % 9));
  EXPECT_EQ(check_layout(at, texts, m, others), 2);
}

TEST(PlotLabels, LabelsInCornersStayInside) {
  const LabelMetrics m = area(400, 200);
  const std::vector<std::pair<double, double>> at = {{2, 2}, {398, 198}, {398, 2}, {2, 198}};
  const std::vector<std::string> texts = {"bottom left", "top right", "bottom right", "top left"};
  EXPECT_EQ(check_layout(at, texts, m), 4);
}

TEST(PlotLabels, ALabelWiderThanTheAreaIsLeftOut) {
  const LabelMetrics m = area(100, 100);
  const std::vector<PlacedLabel> labels = place_labels({{50, 50}}, {std::string(40, 'x')}, m);
  EXPECT_FALSE(labels.front().placed);
}

}  // namespace
}  // namespace msfem::compare
