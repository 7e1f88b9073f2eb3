// The `sweep --plot` SVG (issue 16): every label stays inside the canvas,
// whatever the material's name, the rows' labels and their values.
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <pugixml.hpp>

#include "sweep/sweep.h"
#include "sweep/volume_sweep.h"

// A named namespace: cli_tests is a unity build.
namespace substratec::sweepplottest {

/// Code points of UTF-8 text.
double codePoints(const std::string& s) {
  double n = 0;
  for (unsigned char c : s) n += (c & 0xC0) != 0x80;
  return n;
}

struct Box {
  double x0, y0, x1, y1;
};

/// The estimated extent of a <text>: 0.6 font sizes per code point (a
/// sans-serif glyph's average width is about 0.5), as high as the font size
/// above its baseline and a quarter of it below; its anchor; a rotate(a cx cy)
/// transform turns the box about (cx, cy).
Box extentOf(const pugi::xml_node& text, double svgFont) {
  const double font = text.attribute("font-size") ? text.attribute("font-size").as_double() : svgFont;
  const double x = text.attribute("x").as_double(), y = text.attribute("y").as_double();
  const double w = 0.6 * font * codePoints(text.child_value());
  const std::string anchor = text.attribute("text-anchor") ? text.attribute("text-anchor").value() : "start";
  const double left = anchor == "middle" ? x - w / 2 : anchor == "end" ? x - w : x;
  Box b{left, y - font, left + w, y + 0.25 * font};
  const std::string transform = text.attribute("transform").value();
  if (!transform.empty()) {
    double angle = 0, cx = 0, cy = 0;
    EXPECT_EQ(std::sscanf(transform.c_str(), "rotate(%lf %lf %lf)", &angle, &cx, &cy), 3) << transform;
    const double a = angle * 3.14159265358979323846 / 180, c = std::cos(a), s = std::sin(a);
    Box r{1e300, 1e300, -1e300, -1e300};
    for (double px : {b.x0, b.x1})
      for (double py : {b.y0, b.y1}) {
        const double qx = cx + c * (px - cx) - s * (py - cy), qy = cy + s * (px - cx) + c * (py - cy);
        r = {std::min(r.x0, qx), std::min(r.y0, qy), std::max(r.x1, qx), std::max(r.y1, qy)};
      }
    b = r;
  }
  return b;
}

/// Parses `svg` and checks every text's extent against the viewBox; returns how many texts it checked.
int expectTextsInside(const std::string& svg) {
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_string(svg.c_str());
  EXPECT_TRUE(parsed) << parsed.description() << "\n" << svg;
  const pugi::xml_node root = doc.child("svg");
  double vx = 0, vy = 0, vw = 0, vh = 0;
  EXPECT_EQ(std::sscanf(root.attribute("viewBox").value(), "%lf %lf %lf %lf", &vx, &vy, &vw, &vh), 4) << svg;
  const double font = root.attribute("font-size").as_double();
  EXPECT_GT(font, 0);
  int checked = 0;
  for (const pugi::xml_node& text : root.children("text")) {
    const Box b = extentOf(text, font);
    ++checked;
    EXPECT_TRUE(std::isfinite(b.x0) && std::isfinite(b.y0) && std::isfinite(b.x1) && std::isfinite(b.y1))
        << text.child_value();
    EXPECT_GE(b.x0, vx) << "left of the canvas: " << text.child_value();
    EXPECT_LE(b.x1, vx + vw) << "right of the canvas: " << text.child_value();
    EXPECT_GE(b.y0, vy) << "above the canvas: " << text.child_value();
    EXPECT_LE(b.y1, vy + vh) << "below the canvas: " << text.child_value();
  }
  return checked;
}

sweep::Row row(const std::string& label, double ns, double relMse, int bytes = 1024, int closures = 8) {
  sweep::Row r;
  r.label = label;
  r.gpuNsPerPixel = ns;
  r.relMse = relMse;
  r.bytes = bytes;
  r.closures = closures;
  return r;
}

TEST(SweepPlot, EveryLabelOfATypicalSweepIsInsideTheCanvas) {
  // The rightmost point is the slowest: its label used to run off the right edge.
  const std::vector<sweep::Row> rows = {row("full budget", 950, 0), row("step 1", 700, 1e-4, 96, 4),
                                        row("step 2", 420, 3e-3, 48, 2), row("full simplification", 180, 0.2, 12, 1)};
  const std::string svg = sweep::plotSvg("row40_coating", rows);
  // Title, two axis titles, the decades, five ticks, four point labels.
  EXPECT_GE(expectTextsInside(svg), 1 + 2 + 1 + 5 + 4);
}

TEST(SweepPlot, ALongNameLabelsAtTheEdgesAndExtremeValuesStayInside) {
  const std::string name(128, 'm');  // the identifier-length limit
  std::vector<sweep::Row> rows = {row("full simplification", 1e9, 1e-30), row("full budget", 0, 1e6),
                                  row("step 999", 5e8, std::numeric_limits<double>::infinity()),
                                  row("step 1000", std::numeric_limits<double>::quiet_NaN(), 0.5)};
  for (int i = 0; i < 40; ++i) rows.push_back(row("step " + std::to_string(i), 1e9 - i, std::pow(10.0, -i % 9)));
  const std::string svg = sweep::plotSvg(name, rows);
  EXPECT_GE(expectTextsInside(svg), 1 + 2 + 5 + static_cast<int>(rows.size()));
  EXPECT_NE(svg.find("\u2026: error against cost"), std::string::npos) << "the cut title ends with an ellipsis";
}

TEST(SweepPlot, NonAsciiAndXmlSpecialNamesAreEscapedAndMeasuredByCodePoint) {
  const std::string name = "Öl & <Wasser> \"blau\" 油彩油彩油彩油彩油彩油彩油彩油彩油彩油彩油彩油彩油彩油彩油彩油彩油彩";
  const std::string svg = sweep::plotSvg(name, {row("full budget", 10, 0.01)});
  EXPECT_GE(expectTextsInside(svg), 1 + 2 + 5 + 1);
  EXPECT_NE(svg.find("&amp; &lt;Wasser&gt;"), std::string::npos) << svg;
}

TEST(SweepPlot, NoRowsStillGivesACanvasWithItsAxes) {
  EXPECT_GE(expectTextsInside(sweep::plotSvg("empty", {})), 1 + 2 + 5);
}

// A volume's sweep plots the march's largest error against ns per ray, one
// point per step count, on the same canvas.
TEST(SweepPlot, AVolumesPlotHasOnePointPerStepCountInsideTheCanvas) {
  std::vector<sweep::VolumeRow> rows;
  for (int steps = 4; steps <= 128; steps *= 2) {
    sweep::VolumeRow r;
    r.steps = steps;
    r.gpuNsPerRay = 2.3 * steps;
    r.error.maxError = 0.5 / (steps * steps);
    rows.push_back(r);
  }
  const std::string svg = sweep::plotVolumeSvg("fog_cloud_puff", rows);
  EXPECT_GE(expectTextsInside(svg), 1 + 2 + 5 + static_cast<int>(rows.size()));
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_string(svg.c_str()));
  int points = 0;
  for ([[maybe_unused]] const pugi::xml_node& c : doc.child("svg").children("circle")) ++points;
  EXPECT_EQ(points, static_cast<int>(rows.size()));
  EXPECT_NE(svg.find(">128 steps<"), std::string::npos) << svg;
  EXPECT_NE(svg.find("lavapipe ns per ray"), std::string::npos) << svg;
  EXPECT_NE(svg.find("fog_cloud_puff: error against cost"), std::string::npos) << svg;
}

}  // namespace substratec::sweepplottest
