#include "semx/evaluator/run_folder.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <type_traits>

#include "semx/evaluator/coverage_plot.hpp"

namespace semx::evaluator {

namespace fs = std::filesystem;

namespace {

std::string number(double v, int digits = 9) {
  if (!std::isfinite(v)) return "null";
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

std::string json_string(const std::string& s) {
  std::string o = "\"";
  for (const unsigned char c : s) {
    switch (c) {
      case '"':
        o += "\\\"";
        break;
      case '\\':
        o += "\\\\";
        break;
      case '\n':
        o += "\\n";
        break;
      case '\r':
        o += "\\r";
        break;
      case '\t':
        o += "\\t";
        break;
      default:
        if (c < 0x20) {
          char b[8];
          std::snprintf(b, sizeof b, "\\u%04x", c);
          o += b;
        } else {
          o += static_cast<char>(c);
        }
    }
  }
  return o + "\"";
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string o = "\"";
  for (char c : s) {
    if (c == '"') o += '"';
    o += c;
  }
  return o + "\"";
}

template <class T>
std::string json_optional(const std::optional<T>& v) {
  if (!v) return "null";
  if constexpr (std::is_floating_point_v<T>) {
    return number(*v);
  } else {
    return std::to_string(*v);
  }
}

template <class T>
std::string csv_optional(const std::optional<T>& v) {
  if (!v) return "";
  if constexpr (std::is_floating_point_v<T>) {
    return number(*v);
  } else {
    return std::to_string(*v);
  }
}

}  // namespace

std::string metrics_json(const RunSummary& s) {
  std::ostringstream o;
  o << "{\n";
  auto field = [&o](const char* key, const std::string& value, bool last = false) {
    o << "  \"" << key << "\": " << value << (last ? "\n" : ",\n");
  };
  field("world", json_string(s.info.world));
  field("world_path", json_string(s.info.world_path));
  field("planner", json_string(s.info.planner));
  field("seed", json_optional(s.info.seed));
  field("samples", json_optional(s.info.samples));
  field("time_f_s", number(s.time_f_s));
  field("distance_m", number(s.distance_m));
  field("coverage_pct", number(s.coverage_pct));
  field("time_r_s", json_optional(s.time_r_s));
  field("time_95_s", json_optional(s.time_95_s));
  field("time_settled_s", json_optional(s.time_settled_s));
  field("end_game_s", json_optional(s.end_game_s));
  field("object_coverage_pct", number(s.object_coverage_pct));
  field("time_o_s", json_optional(s.time_o_s));
  field("collisions", std::to_string(s.collisions));
  field("wall_s", number(s.wall_s));
  field("termination", json_string(s.termination));
  field("valid", s.valid ? "true" : "false");
  field("invalid_reason", json_string(s.invalid_reason));
  field("planner_state", json_string(s.planner_state));
  field("planner_reason", json_string(s.planner_reason));
  field("sim_s", number(s.sim_s));
  field("realtime_factor", number(s.realtime_factor, 4));
  field("time_limit_s", json_optional(s.time_limit_s));
  field("coverage_threshold_pct", number(s.coverage_threshold_pct));
  field("object_threshold_pct", number(s.object_threshold_pct));
  field("resolution_m", number(s.resolution_m));
  field("target_voxels", std::to_string(s.target_voxels));
  field("covered_voxels", std::to_string(s.covered_voxels));
  field("object_voxels", std::to_string(s.object_voxels));
  field("map_seq", std::to_string(s.map_seq));
  field("coverage_samples", std::to_string(s.coverage.size()));
  // A process of the set died and was restarted: the figures are not an undisturbed run's.
  field("disturbed", s.restarts.empty() ? "false" : "true");
  std::string restarts = "[";
  for (size_t i = 0; i < s.restarts.size(); ++i) {
    const NodeRestart& r = s.restarts[i];
    restarts += std::string(i ? ", " : "") + "{\"node\": " + json_string(r.node) + ", \"t_s\": " + number(r.t_s) +
                ", \"restarts\": " + std::to_string(r.restarts) + "}";
  }
  field("restarts", restarts + "]");
  field("source", json_string(s.info.source), true);
  o << "}\n";
  return o.str();
}

std::string metrics_csv_header() {
  return "world,planner,seed,samples,time_f_s,distance_m,coverage_pct,time_r_s,collisions,wall_s,"
         "termination,sim_s,resolution_m,target_voxels,covered_voxels,source,object_coverage_pct,time_o_s,"
         "time_95_s,time_settled_s,end_game_s\n";
}

std::string metrics_csv_row(const RunSummary& s) {
  std::ostringstream o;
  o << csv_field(s.info.world) << ',' << csv_field(s.info.planner) << ',' << csv_optional(s.info.seed) << ','
    << csv_optional(s.info.samples) << ',' << number(s.time_f_s) << ',' << number(s.distance_m) << ','
    << number(s.coverage_pct) << ',' << csv_optional(s.time_r_s) << ',' << s.collisions << ','
    << number(s.wall_s) << ',' << csv_field(s.termination) << ',' << number(s.sim_s) << ','
    << number(s.resolution_m) << ',' << s.target_voxels << ',' << s.covered_voxels << ','
    << csv_field(s.info.source) << ',' << number(s.object_coverage_pct) << ',' << csv_optional(s.time_o_s)
    << ',' << csv_optional(s.time_95_s) << ',' << csv_optional(s.time_settled_s) << ','
    << csv_optional(s.end_game_s) << '\n';
  return o.str();
}

std::string coverage_csv(const RunSummary& s) {
  std::ostringstream o;
  // reached_95: 1 from Time_95 on; end_game: 1 from Time_settled on (the map within 0.5 points of
  // its final coverage), so the end game is the rows marked 1 up to Time_f.
  o << "t_s,coverage_pct,distance_m,covered_voxels,object_coverage_pct,reached_95,end_game\n";
  auto from = [](const std::optional<double>& t, double at) { return t && at >= *t - 1e-9 ? 1 : 0; };
  for (const auto& c : s.coverage) {
    o << number(c.t_s) << ',' << number(c.coverage_pct) << ',' << number(c.distance_m) << ',' << c.covered
      << ',' << number(c.object_coverage_pct) << ',' << from(s.time_95_s, c.t_s) << ','
      << from(s.time_settled_s, c.t_s) << '\n';
  }
  return o.str();
}

std::vector<CoverageSample> read_coverage_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw RunFolderError(path + ": cannot open (" + std::strerror(errno) + ")");
  std::string line;
  if (!std::getline(in, line) || line.rfind("t_s,coverage_pct", 0) != 0) {
    throw RunFolderError(path + ": not a coverage.csv (header 't_s,coverage_pct,...' expected)");
  }
  std::vector<CoverageSample> out;
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    CoverageSample c;
    long long covered = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lld", &c.t_s, &c.coverage_pct, &c.distance_m, &covered) < 2 ||
        !std::isfinite(c.t_s) || !std::isfinite(c.coverage_pct)) {
      throw RunFolderError(path + ":" + std::to_string(line_no) + ": not 't_s,coverage_pct,...' numbers");
    }
    c.covered = covered;
    out.push_back(c);
  }
  return out;
}

void write_text_file(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw RunFolderError(path + ": cannot write (" + std::strerror(errno) + ")");
    out << text;
    out.flush();
    if (!out) throw RunFolderError(path + ": write failed (" + std::strerror(errno) + ")");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) throw RunFolderError(path + ": cannot rename the temporary file (" + ec.message() + ")");
}

std::vector<std::string> write_run_metrics(const std::string& dir, const RunSummary& s) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw RunFolderError(dir + ": cannot create the run folder" + (ec ? " (" + ec.message() + ")" : ""));
  }
  const fs::path d(dir);
  std::vector<std::string> written;
  auto text = [&](const char* name, const std::string& content) {
    const std::string p = (d / name).string();
    write_text_file(p, content);
    written.push_back(p);
  };
  text("metrics.json", metrics_json(s));
  text("metrics.csv", metrics_csv_header() + metrics_csv_row(s));
  text("coverage.csv", coverage_csv(s));
  text("time_split.json", s.time_split.to_json());
  const CoverageFigure figure = coverage_figure(s);
  const std::string png = (d / "coverage.png").string();
  write_coverage_plot(png, figure.series, figure.options);
  written.push_back(png);
  return written;
}

CoverageFigure coverage_figure(const RunSummary& s) {
  CoverageFigure f;
  CoveragePlotOptions& po = f.options;
  po.title = "coverage over time: " + (s.info.world.empty() ? std::string("run") : s.info.world) +
             (s.info.planner.empty() ? "" : ", " + s.info.planner);
  po.threshold_pct = s.coverage_threshold_pct;
  po.t_max_s = std::max(s.time_f_s, s.coverage.empty() ? 0.0 : s.coverage.back().t_s);
  f.series.push_back(coverage_series(s.coverage, "map (target set)"));
  PlotSeries objects;
  objects.label = "objects (furniture surfaces)";
  for (const auto& c : s.coverage) objects.points.emplace_back(c.t_s, c.object_coverage_pct);
  f.series.push_back(std::move(objects));
  return f;
}

std::string format_metrics_table(const RunSummary& s) {
  std::ostringstream o;
  char b[256];
  auto row = [&](const char* name, const std::string& value) {
    std::snprintf(b, sizeof b, "  %-16s %s\n", name, value.c_str());
    o << b;
  };
  auto fmt = [&](const char* f, double v) {
    std::snprintf(b, sizeof b, f, v);
    return std::string(b);
  };
  row("world", s.info.world.empty() ? "?" : s.info.world);
  std::string planner = s.info.planner.empty() ? "?" : s.info.planner;
  if (s.info.seed) planner += "  seed " + std::to_string(*s.info.seed);
  if (s.info.samples) planner += "  samples " + std::to_string(*s.info.samples);
  row("planner", planner);
  row("ended", s.termination + " (planner " + s.planner_state +
                   (s.planner_reason.empty() ? "" : ": " + s.planner_reason) + ")");
  if (!s.valid) row("NOT VALID", "\033[31m" + s.invalid_reason + " (left out of the bench's tables)\033[0m");
  row("Time_f", fmt("%.2f s", s.time_f_s));
  row("Distance", fmt("%.2f m", s.distance_m));
  row("Coverage", fmt("%.2f %%", s.coverage_pct) + "  (" + std::to_string(s.covered_voxels) + " of " +
                      std::to_string(s.target_voxels) + " voxels at " + fmt("%g m)", s.resolution_m));
  const std::string tr = fmt("Time_r (%g %%)", s.coverage_threshold_pct);
  row(tr.c_str(), s.time_r_s ? fmt("%.2f s", *s.time_r_s) : std::string("N/A (never reached)"));
  row("Time_95 (95 %)", s.time_95_s ? fmt("%.2f s", *s.time_95_s) : std::string("N/A (never reached)"));
  if (s.time_settled_s && s.end_game_s) {
    row("end game", fmt("%.2f s", *s.end_game_s) + "  (the map stopped growing at " +
                        fmt("%.2f s", *s.time_settled_s) + ", within 0.5 points of its final coverage)");
  }
  const std::string to = fmt("Time_o (%g %%)", s.object_threshold_pct);
  row("Objects", fmt("%.2f %%", s.object_coverage_pct) + "  (of " + std::to_string(s.object_voxels) +
                     " surface voxels of furniture)");
  row(to.c_str(), s.time_o_s ? fmt("%.2f s", *s.time_o_s) : std::string("N/A (never reached)"));
  row("collisions", std::to_string(s.collisions));
  if (s.time_split.time_f > 0) {
    std::string split;
    for (int i = 0; i < core::kTimeUses; ++i) {
      const auto u = static_cast<core::TimeUse>(i);
      split += std::string(i ? ", " : "") + core::to_string(u) +
               fmt(" %.0f s", s.time_split.time_s[static_cast<size_t>(i)]) + fmt(" (%.0f %%)", 100.0 * s.time_split.share(u));
    }
    row("time split", split);
  }
  row("wall", fmt("%.1f s", s.wall_s) +
                  (s.realtime_factor > 0 ? fmt("  (%.1fx real time)", s.realtime_factor) : std::string()));
  return o.str();
}

std::string format_progress(double t_s, double coverage_pct, double object_coverage_pct, double distance_m,
                            const std::string& planner_state) {
  char b[256];
  std::snprintf(b, sizeof b, "t=%.1f s  coverage=%.1f%%  objects=%.1f%%  distance=%.2f m  planner=%s", t_s,
                coverage_pct, object_coverage_pct, distance_m, planner_state.c_str());
  return b;
}

}  // namespace semx::evaluator
