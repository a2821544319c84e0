// The files of a run folder that describe the run's results (issue 8), and the text the
// evaluator prints:
//
//   metrics.json   one object: world, planner, seed, samples, time_f_s, distance_m, coverage_pct,
//                  time_r_s (null when the threshold was never reached), collisions, wall_s, then
//                  context (termination, sim_s, resolution_m, target_voxels, ...);
//   metrics.csv    a header and one row with the same scalar keys (runs concatenate into a table);
//   coverage.csv   t_s,coverage_pct,distance_m,covered_voxels,object_coverage_pct,reached_95,end_game: over time;
//   coverage.png   the coverage-over-time plot (coverage_plot.hpp);
//   map.png        the top-down map with the flown trajectory (map_picture.hpp).
//
// Writers throw RunFolderError naming the file when it cannot be written.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "semx/evaluator/run_summary.hpp"

namespace semx::evaluator {

class RunFolderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The metrics.json text (keys in a fixed order; numbers with enough digits to round-trip the
// figures that matter; non-finite numbers as null).
std::string metrics_json(const RunSummary& s);
// The metrics.csv text: header line and one row.
std::string metrics_csv_header();
std::string metrics_csv_row(const RunSummary& s);
// The coverage.csv text.
std::string coverage_csv(const RunSummary& s);
// Reads a coverage.csv back (for plots of several runs); throws RunFolderError on a bad file.
std::vector<CoverageSample> read_coverage_csv(const std::string& path);

// Creates `dir` if needed and writes metrics.json, metrics.csv, coverage.csv and coverage.png.
// Returns the paths written. (map.png needs the map: see write_map_png in map_picture.hpp.)
std::vector<std::string> write_run_metrics(const std::string& dir, const RunSummary& s);

// The final metrics table people read at the end of a run.
std::string format_metrics_table(const RunSummary& s);
// One progress line: "t=12.0 s  coverage=34.5%  objects=20.1%  distance=8.12 m  planner=EXECUTING".
std::string format_progress(double t_s, double coverage_pct, double object_coverage_pct, double distance_m,
                            const std::string& planner_state);

// Writes `text` to `path` atomically (path.tmp, then rename); throws RunFolderError.
void write_text_file(const std::string& path, const std::string& text);

}  // namespace semx::evaluator
