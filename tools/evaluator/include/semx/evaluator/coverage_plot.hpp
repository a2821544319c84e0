// Coverage-over-time plots (coverage.png; several runs on one plot for the benchmark): axes
// with ticks at 1-2-5 steps, axis labels, a dashed line at the Time_r threshold (85 %), a
// legend when there is more than one series (or a label), and a title.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "semx/evaluator/rgb.hpp"
#include "semx/evaluator/run_metrics.hpp"

namespace semx::evaluator {

// A shaded band around a series (the spread over seeds): at time t, from lo to hi percent.
struct BandPoint {
  double t = 0, lo = 0, hi = 0;
};

struct PlotSeries {
  std::string label;                              // legend text ("" for none)
  std::vector<std::pair<double, double>> points;  // (t s, coverage %), t increasing
  Rgb color{0, 0, 0};                             // {0,0,0}: palette(index)
  int thickness = 2;
  std::vector<BandPoint> band;  // drawn faded in the series' colour under every curve; t increasing
};

// The series of one run's coverage samples.
PlotSeries coverage_series(const std::vector<CoverageSample>& samples, const std::string& label = "");

struct CoveragePlotOptions {
  std::string title = "coverage over time";
  std::string x_label = "simulated time [s]";
  std::string y_label = "coverage [%]";
  double threshold_pct = 85.0;  // dashed line; <= 0: none
  double t_max_s = 0.0;         // right end of the x axis; 0: the longest series
  double y_max_pct = 100.0;
  int width = 900;
  int height = 560;
};

Image render_coverage_plot(const std::vector<PlotSeries>& series, const CoveragePlotOptions& options = {});
void write_coverage_plot(const std::string& path, const std::vector<PlotSeries>& series,
                         const CoveragePlotOptions& options = {});

// Tick positions for an axis from 0 to `max`: a 1-2-5 step giving about `target` intervals.
std::vector<double> nice_ticks(double max, int target = 8);

}  // namespace semx::evaluator
