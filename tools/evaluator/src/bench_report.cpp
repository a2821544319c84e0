#include "semx/evaluator/bench_report.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "semx/core/time_split.hpp"
#include "semx/evaluator/coverage_plot.hpp"
#include "semx/evaluator/montage.hpp"
#include "semx/tools/process_usage.hpp"

namespace semx::evaluator {

namespace fs = std::filesystem;

namespace {

// The paper's rows, then the references: the FUEL-class baseline and the known-map oracle.
const std::vector<std::string> kPlannerOrder = {"nbv",           "aep",  "dep",           "semantic-dep",
                                                "semantic-room", "fuel", "semantic-fuel", "oracle"};
// The planner every other row is divided by in the "× oracle" table.
const char* const kOraclePlanner = "oracle";

int planner_rank(const std::string& p) {
  const auto it = std::find(kPlannerOrder.begin(), kPlannerOrder.end(), p);
  return it == kPlannerOrder.end() ? static_cast<int>(kPlannerOrder.size())
                                   : static_cast<int>(it - kPlannerOrder.begin());
}

std::vector<std::string> planners_of(const std::vector<const BenchRun*>& runs) {
  std::vector<std::string> out;
  for (const auto* r : runs)
    if (std::find(out.begin(), out.end(), r->planner) == out.end()) out.push_back(r->planner);
  std::stable_sort(out.begin(), out.end(), [](const std::string& a, const std::string& b) {
    return planner_rank(a) != planner_rank(b) ? planner_rank(a) < planner_rank(b) : a < b;
  });
  return out;
}

std::vector<std::string> worlds_of(const std::vector<BenchRun>& runs) {
  std::set<std::string> s;
  for (const auto& r : runs) s.insert(r.world);
  return {s.begin(), s.end()};
}

// The runs of one world at one sampling density.
std::vector<const BenchRun*> runs_in(const std::vector<BenchRun>& runs, const std::string& world,
                                     int samples) {
  std::vector<const BenchRun*> out;
  for (const auto& r : runs)
    if (r.world == world && r.samples == samples) out.push_back(&r);
  return out;
}

std::string fmt(double v, int decimals = 2) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}

std::string pm(const Stat& s, int decimals = 2) {
  if (s.n == 0) return "N/A";
  return s.n == 1 ? fmt(s.mean, decimals) : fmt(s.mean, decimals) + " ± " + fmt(s.std, decimals);
}

struct Group {
  std::vector<const BenchRun*> runs;
  Stat metric(double BenchRun::*field) const {
    std::vector<double> v;
    for (const auto* r : runs) v.push_back(r->*field);
    return stat_of(v);
  }
  // A time to a threshold (Time_r, Time_o) over the runs that reached it; `reached` of
  // `runs.size()` did.
  Stat reached_time(std::optional<double> BenchRun::*field, int* reached) const {
    std::vector<double> v;
    for (const auto* r : runs)
      if (r->*field) v.push_back(*(r->*field));
    *reached = static_cast<int>(v.size());
    return stat_of(v);
  }
  int64_t collisions() const {
    int64_t c = 0;
    for (const auto* r : runs) c += r->collisions;
    return c;
  }
};

std::string reached_time_cell(const Group& g, std::optional<double> BenchRun::*field) {
  int reached = 0;
  const Stat s = g.reached_time(field, &reached);
  if (reached == 0) return "N/A";
  std::string cell = pm(s);
  if (reached < static_cast<int>(g.runs.size()))
    cell += " (" + std::to_string(reached) + "/" + std::to_string(g.runs.size()) + ")";
  return cell;
}

Group select(const std::vector<BenchRun>& runs, const std::string& world, const std::string& planner,
             int samples) {
  Group g;
  for (const auto& r : runs)
    if (r.world == world && r.planner == planner && r.samples == samples) g.runs.push_back(&r);
  std::sort(g.runs.begin(), g.runs.end(),
            [](const BenchRun* a, const BenchRun* b) { return a->seed < b->seed; });
  return g;
}

std::string csv_escape(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string o = "\"";
  for (char c : s) o += c == '"' ? std::string("\"\"") : std::string(1, c);
  return o + "\"";
}

double number_of(const YAML::Node& n, const char* key, const std::string& file) {
  const YAML::Node v = n[key];
  if (!v || v.IsNull()) throw std::runtime_error(file + ": no '" + key + "'");
  try {
    return v.as<double>();
  } catch (const std::exception&) {
    throw std::runtime_error(file + ": '" + key + "' is not a number");
  }
}

// Two-sided 95 % quantile of Student's t with `df` degrees of freedom (the normal's past 30).
double t975(int df) {
  static const double table[] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                                 2.201,  2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
                                 2.080,  2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
  return df < 1 ? 0.0 : df <= 30 ? table[df - 1] : 1.960;
}

std::string signed_fmt(double v, int decimals) { return (v >= 0 ? "+" : "") + fmt(v, decimals); }

// The mean of `d` and its 95 % interval (Student's t), as "[lo, hi]" ("–" for fewer than 2).
std::string interval_of(const Stat& s, int decimals) {
  if (s.n < 2) return "–";
  const double h = t975(s.n - 1) * s.std / std::sqrt(static_cast<double>(s.n));
  return "[" + fmt(s.mean - h, decimals) + ", " + fmt(s.mean + h, decimals) + "]";
}

// A time (Time_r, Time_95, Time_o) run by run: the pairs (same world and seed) in which both
// planners reached its threshold, how many ours reached sooner, at the same time (within 0.05 s:
// the same flight to the threshold) or later, the paired mean difference with its 95 % interval
// (Student's t over the pairs), and the mean relative difference (ours / theirs - 1) with its
// interval. A margin of the means says which mean is lower; this says whether the runs could tell.
// Last, the mean difference as a share of the baseline's mean over the same pairs: the mean
// relative difference weighs a pair whose time is 4 s as much as one of 400 s, this weighs each
// by its time (the paper gives its env1-3 figures so, as differences of mean times).
std::string paired_cells(const std::vector<std::pair<double, double>>& pairs) {
  std::vector<double> d, rel;
  int sooner = 0, same = 0, later = 0;
  double base = 0;
  for (const auto& [a, b] : pairs) {
    const double x = a - b;
    d.push_back(x);
    base += b;
    if (b > 0) rel.push_back(100.0 * x / b);
    (x < -0.05 ? sooner : x > 0.05 ? later : same)++;
  }
  if (d.empty()) return "0 | – | – | – | – | – | – | – |";
  const Stat s = stat_of(d), r = stat_of(rel);
  base /= static_cast<double>(d.size());
  Stat share = s;  // the difference's mean and spread over the baseline's mean, in %
  if (base > 0) share.mean *= 100.0 / base, share.std *= 100.0 / base;
  return std::to_string(s.n) + " | " + std::to_string(sooner) + " / " + std::to_string(same) + " / " +
         std::to_string(later) + " | " + signed_fmt(s.mean, 2) + " | " + interval_of(s, 2) + " | " +
         (r.n ? signed_fmt(r.mean, 1) : std::string("–")) + " | " + interval_of(r, 1) + " | " +
         (base > 0 ? signed_fmt(share.mean, 1) + " | " + interval_of(share, 1) : std::string("– | –")) + " |";
}

std::vector<std::pair<double, double>> pairs_of(const Group& ours, const Group& theirs,
                                                std::optional<double> BenchRun::*field) {
  std::vector<std::pair<double, double>> pairs;
  for (const BenchRun* a : ours.runs)
    for (const BenchRun* b : theirs.runs) {
      if (a->world != b->world || a->seed != b->seed || !(a->*field) || !(b->*field)) continue;
      pairs.emplace_back(*(a->*field), *(b->*field));
    }
  return pairs;
}

std::string paired_row(const Group& ours, const Group& theirs, std::optional<double> BenchRun::*field) {
  return paired_cells(pairs_of(ours, theirs, field));
}

bool is_generated(const std::string& world) { return world.rfind(kGeneratedPrefix, 0) == 0; }
}  // namespace

Stat stat_of(const std::vector<double>& values) {
  Stat s;
  s.n = static_cast<int>(values.size());
  if (s.n == 0) return s;
  for (double v : values) s.mean += v;
  s.mean /= s.n;
  if (s.n > 1) {
    double ss = 0;
    for (double v : values) ss += (v - s.mean) * (v - s.mean);
    s.std = std::sqrt(ss / (s.n - 1));
  }
  return s;
}

BenchRun load_bench_run(const std::string& dir) {
  BenchRun r;
  r.dir = dir;
  const std::string file = (fs::path(dir) / "metrics.json").string();
  YAML::Node m;
  try {
    m = YAML::LoadFile(file);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(file + ": " + e.what());
  }
  if (!m.IsMap()) throw std::runtime_error(file + ": not a JSON object");
  auto text = [&](const char* key) {
    return m[key] && m[key].IsScalar() ? m[key].as<std::string>() : std::string();
  };
  r.world = text("world");
  r.planner = text("planner");
  r.termination = text("termination");
  if (m["valid"] && m["valid"].IsScalar()) r.valid = m["valid"].as<bool>();
  r.invalid_reason = text("invalid_reason");
  if (r.world.empty() || r.planner.empty()) throw std::runtime_error(file + ": no world or planner");
  r.seed = m["seed"] && !m["seed"].IsNull() ? m["seed"].as<int64_t>() : 0;
  r.samples = m["samples"] && !m["samples"].IsNull() ? m["samples"].as<int>() : 0;
  r.time_f_s = number_of(m, "time_f_s", file);
  r.distance_m = number_of(m, "distance_m", file);
  r.coverage_pct = number_of(m, "coverage_pct", file);
  r.wall_s = number_of(m, "wall_s", file);
  r.sim_s = m["sim_s"] && !m["sim_s"].IsNull() ? m["sim_s"].as<double>() : r.time_f_s;
  r.collisions = static_cast<int64_t>(number_of(m, "collisions", file));
  if (m["time_r_s"] && !m["time_r_s"].IsNull()) r.time_r_s = m["time_r_s"].as<double>();
  if (m["time_o_s"] && !m["time_o_s"].IsNull()) r.time_o_s = number_of(m, "time_o_s", file);
  if (m["time_95_s"] && !m["time_95_s"].IsNull()) r.time_95_s = number_of(m, "time_95_s", file);
  if (m["time_settled_s"] && !m["time_settled_s"].IsNull())
    r.time_settled_s = number_of(m, "time_settled_s", file);
  if (m["end_game_s"] && !m["end_game_s"].IsNull()) r.end_game_s = number_of(m, "end_game_s", file);
  if (m["object_coverage_pct"] && !m["object_coverage_pct"].IsNull())
    r.object_coverage_pct = number_of(m, "object_coverage_pct", file);
  r.disturbed = m["disturbed"] && m["disturbed"].IsScalar() && m["disturbed"].as<std::string>() == "true";
  if (m["restarts"] && m["restarts"].IsSequence()) {
    for (const auto& x : m["restarts"]) {
      if (!x.IsMap() || !x["node"] || !x["t_s"]) continue;
      r.restarts += (r.restarts.empty() ? "" : ", ") + x["node"].as<std::string>() + " " +
                    x["t_s"].as<std::string>() + " s";
    }
  }

  const std::string split_file = (fs::path(dir) / "time_split.json").string();
  if (fs::exists(split_file)) {
    try {
      const YAML::Node t = YAML::LoadFile(split_file);
      for (int u = 0; u < core::kTimeUses; ++u)
        r.split_s.push_back(t["uses"][core::to_string(static_cast<core::TimeUse>(u))]["time_s"].as<double>());
      r.revisit_by_place_m = t["revisit_by_place_m"].as<double>();
      if (r.time_r_s && t["slices"] && t["slice_s"]) {
        const double dt = t["slice_s"].as<double>();
        const std::string letters = t["slices"].as<std::string>();
        const std::string use_letters = core::kTimeUseLetters;
        r.split_to_r_s.assign(use_letters.size(), 0.0);
        for (size_t k = 0; k < letters.size(); ++k) {
          const double in = std::min(dt, *r.time_r_s - static_cast<double>(k) * dt);
          if (!(in > 0)) break;
          const size_t u = use_letters.find(letters[k]);
          if (u == std::string::npos)
            throw std::runtime_error(split_file + ": unknown slice use '" + letters[k] + "'");
          r.split_to_r_s[u] += in;
        }
      }
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(split_file + ": " + e.what());
    }
  }
  std::ifstream launch_log(fs::path(dir) / "launch.log");
  for (std::string line; std::getline(launch_log, line);) {
    if (const auto exit = tools::parse_exit_line(line)) r.cpu_s[exit->first] += exit->second.cpu_s();
  }
  const std::string csv = (fs::path(dir) / "coverage.csv").string();
  std::ifstream in(csv);
  if (in) {
    std::string line;
    int line_no = 0;
    while (std::getline(in, line)) {
      ++line_no;
      if (line_no == 1 || line.empty()) continue;  // header
      double t = 0, c = 0;
      if (std::sscanf(line.c_str(), "%lf,%lf", &t, &c) != 2 || !std::isfinite(t) || !std::isfinite(c))
        throw std::runtime_error(csv + ":" + std::to_string(line_no) + ": expected t_s,coverage_pct,...");
      r.coverage.emplace_back(t, c);
    }
  }
  return r;
}

std::vector<BenchRun> load_bench_runs(const std::string& root) {
  std::vector<std::string> dirs;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
    // semx-bench keeps runs it had to start again under DIR/interrupted/: not part of the tables.
    if (it->is_directory() && it->path().filename() == "interrupted") {
      it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file() && it->path().filename() == "metrics.json")
      dirs.push_back(it->path().parent_path().string());
  }
  if (ec) throw std::runtime_error(root + ": " + ec.message());
  std::sort(dirs.begin(), dirs.end());
  std::vector<BenchRun> runs;
  for (const auto& d : dirs) runs.push_back(load_bench_run(d));
  return runs;
}

// Calls f(world, ours, theirs) for every world with runs of the sweep planner at the comparison
// density and every other planner there, in the tables' order.
template <class F>
void for_each_baseline(const std::vector<BenchRun>& runs, const BenchReportOptions& o, F&& f) {
  for (const auto& w : worlds_of(runs)) {
    const Group ours = select(runs, w, o.sweep_planner, o.comparison_samples);
    if (ours.runs.empty()) continue;
    const std::vector<const BenchRun*> here = runs_in(runs, w, o.comparison_samples);
    for (const auto& p : planners_of(here)) {
      if (p == o.sweep_planner) continue;
      f(w, p, ours, select(runs, w, p, o.comparison_samples));
    }
  }
}

// The runs the tables summarise: valid (no message lost or mixed) and undisturbed (no process
// restarted during the run).
static std::vector<BenchRun> tabled_only(const std::vector<BenchRun>& runs) {
  std::vector<BenchRun> out;
  for (const auto& r : runs)
    if (r.valid && !r.disturbed) out.push_back(r);
  return out;
}

static std::string tables_markdown(const std::vector<BenchRun>& runs, const BenchReportOptions& o);

// What the bench cost and who spent it: CPU seconds by process, summed over each planner's runs
// (every run, at every density), with the wall and simulated seconds. Where a bench's time goes
// when its sets keep every core busy; nothing when no run folder has the launcher's CPU figures.
static std::string cost_markdown(const std::vector<BenchRun>& all) {
  // The set's processes in the order they appear in a set; any other after them, by name.
  const std::vector<std::string> order = {"simulator",  "mapper",    "semantics", "planner",
                                          "controller", "evaluator", "logger"};
  std::set<std::string> names;
  for (const auto& r : all)
    for (const auto& [name, s] : r.cpu_s) names.insert(name);
  if (names.empty()) return "";
  std::vector<std::string> columns;
  for (const auto& n : order)
    if (names.count(n)) columns.push_back(n);
  for (const auto& n : names)
    if (std::find(order.begin(), order.end(), n) == order.end()) columns.push_back(n);

  struct Row {
    int runs = 0;
    double wall = 0, sim = 0, total = 0;
    std::map<std::string, double> cpu;
  };
  std::map<std::string, Row> by_planner;
  Row sum;
  for (const auto& r : all) {
    if (r.cpu_s.empty()) continue;
    for (Row* row : {&by_planner[r.planner], &sum}) {
      ++row->runs;
      row->wall += r.wall_s;
      row->sim += r.sim_s;
      for (const auto& [name, s] : r.cpu_s) {
        row->cpu[name] += s;
        row->total += s;
      }
    }
  }
  std::vector<std::string> planners;
  for (const auto& [p, row] : by_planner) planners.push_back(p);
  std::stable_sort(planners.begin(), planners.end(), [](const std::string& a, const std::string& b) {
    return planner_rank(a) < planner_rank(b);
  });

  std::ostringstream md;
  md << "\n### What the runs cost (CPU s by process, summed over the runs; every run, disturbed or not)\n\n"
     << "| Algorithm | runs | simulated s | wall s (exploration) |";
  for (const auto& c : columns) md << " " << c << " |";
  md << " CPU s | CPU s per simulated s |\n|---|---|---|---|";
  for (std::size_t i = 0; i < columns.size(); ++i) md << "---|";
  md << "---|---|\n";
  auto row_line = [&](const std::string& label, const Row& row) {
    md << "| " << label << " | " << row.runs << " | " << fmt(row.sim, 0) << " | " << fmt(row.wall, 0) << " |";
    for (const auto& c : columns) {
      const auto it = row.cpu.find(c);
      md << " " << (it == row.cpu.end() ? std::string("-") : fmt(it->second, 1)) << " |";
    }
    md << " " << fmt(row.total, 1) << " | " << (row.sim > 0 ? fmt(row.total / row.sim, 3) : "N/A") << " |\n";
  };
  for (const auto& p : planners) row_line(p, by_planner[p]);
  row_line("all", sum);
  return md.str();
}

std::string bench_markdown(const std::vector<BenchRun>& all, const BenchReportOptions& o) {
  std::string md = tables_markdown(tabled_only(all), o);
  std::string left_out;
  for (const auto& r : all) {
    if (r.valid || r.disturbed) continue;  // a disturbed run is listed with the disturbed ones
    left_out += "- " + r.dir + " (" + r.world + ", " + r.planner + ", seed " + std::to_string(r.seed) +
                "): " + r.invalid_reason + "\n";
  }
  if (!left_out.empty()) {
    md += "\n### Runs left out of the tables (not valid: lost or mixed messages)\n\n" + left_out;
  }
  std::ostringstream d;
  for (const auto& r : all) {
    if (!r.disturbed) continue;
    d << "| " << r.world << " | " << r.planner << " | " << r.samples << " | " << r.seed << " | "
      << (r.restarts.empty() ? "?" : r.restarts) << " | " << fmt(r.time_f_s, 2) << " | "
      << fmt(r.coverage_pct, 2) << " | " << r.termination << " | " << (r.valid ? "" : r.invalid_reason)
      << " | " << r.dir << " |\n";
  }
  if (!d.str().empty()) {
    md +=
        "\n### Disturbed runs (a process died and was restarted): not in the tables\n\n"
        "| Env. | Algorithm | no. S. | seed | restarted (simulated time) | Time_f (s) | Coverage (%) | "
        "termination | not valid | folder |\n|---|---|---|---|---|---|---|---|---|---|\n" +
        d.str();
  }
  md += cost_markdown(all);
  return md;
}

static std::string tables_markdown(const std::vector<BenchRun>& runs, const BenchReportOptions& o) {
  std::ostringstream md;
  const auto worlds = worlds_of(runs);
  std::set<int> densities;
  for (const auto& r : runs)
    if (r.planner == o.sweep_planner) densities.insert(r.samples);

  md << "### Sampling density (" << o.sweep_planner << "), mean ± std over seeds\n\n"
     << "| Env. | no. S. | seeds | Time_f (s) | Distance (m) | Coverage (%) | Time_r (s) | collisions |\n"
     << "|---|---|---|---|---|---|---|---|\n";
  for (const auto& w : worlds) {
    for (int n : densities) {
      const Group g = select(runs, w, o.sweep_planner, n);
      if (g.runs.empty()) continue;
      md << "| " << w << " | " << n << " | " << g.runs.size() << " | " << pm(g.metric(&BenchRun::time_f_s))
         << " | " << pm(g.metric(&BenchRun::distance_m)) << " | " << pm(g.metric(&BenchRun::coverage_pct))
         << " | " << reached_time_cell(g, &BenchRun::time_r_s) << " | " << g.collisions() << " |\n";
    }
  }

  md << "\n### Planners at " << o.comparison_samples << " samples, mean ± std over seeds\n\n"
     << "Time_95: first time coverage ≥ 95 %; end game: Time_f minus the time the coverage came within "
        "0.5 points of its final value (how long DONE came after the map stopped growing).\n\n"
     << "| Env. | Algorithm | seeds | Time_f (s) | Distance (m) | Coverage (%) | Time_r (s) | collisions | "
        "Time_o (s) | Time_95 (s) | End game (s) |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& w : worlds) {
    const std::vector<const BenchRun*> here = runs_in(runs, w, o.comparison_samples);
    for (const auto& p : planners_of(here)) {
      const Group g = select(runs, w, p, o.comparison_samples);
      md << "| " << w << " | " << p << " | " << g.runs.size() << " | " << pm(g.metric(&BenchRun::time_f_s))
         << " | " << pm(g.metric(&BenchRun::distance_m)) << " | " << pm(g.metric(&BenchRun::coverage_pct))
         << " | " << reached_time_cell(g, &BenchRun::time_r_s) << " | " << g.collisions() << " | "
         << reached_time_cell(g, &BenchRun::time_o_s) << " | " << reached_time_cell(g, &BenchRun::time_95_s)
         << " | " << reached_time_cell(g, &BenchRun::end_game_s) << " |\n";
    }
  }

  // Every planner against the physical limit: the oracle's means divide the others' (a mean over
  // the seeds that reached the threshold, as in the table above).
  bool any_oracle = false;
  for (const auto& r : runs) any_oracle |= r.planner == kOraclePlanner && r.samples == o.comparison_samples;
  if (any_oracle) {
    md << "\n### Against the known-map oracle (× oracle: the planner's mean over the oracle's)\n\n"
       << "The oracle is a reference, not a bound: its one flight per world is chosen for the sum of its "
          "model's times to 85 % and 95 % of T, and a run may be sooner on either (docs/planner.md, \"The "
          "known-map oracle\"). The last column counts the runs sooner than the oracle's mean.\n\n"
       << "| Env. | Algorithm | Time_r × oracle | Time_95 × oracle | Distance × oracle | runs sooner (Time_r "
          "/ "
          "Time_95) |\n"
       << "|---|---|---|---|---|---|\n";
    for (const auto& w : worlds) {
      const Group oracle = select(runs, w, kOraclePlanner, o.comparison_samples);
      if (oracle.runs.empty()) continue;
      const std::vector<const BenchRun*> here = runs_in(runs, w, o.comparison_samples);
      auto ratio_of = [&](const Group& g, std::optional<double> BenchRun::*field) {
        int rg = 0, ro = 0;
        const Stat sg = g.reached_time(field, &rg), so = oracle.reached_time(field, &ro);
        if (rg == 0 || ro == 0 || !(so.mean > 0)) return std::string("N/A");
        std::string cell = fmt(sg.mean / so.mean, 2);
        if (rg < static_cast<int>(g.runs.size()))
          cell += " (" + std::to_string(rg) + "/" + std::to_string(g.runs.size()) + ")";
        return cell;
      };
      for (const auto& p : planners_of(here)) {
        if (p == kOraclePlanner) continue;
        const Group g = select(runs, w, p, o.comparison_samples);
        const double od = oracle.metric(&BenchRun::distance_m).mean;
        // Runs whose time is below the oracle's mean (a run that never reached the share is not).
        auto sooner = [&](std::optional<double> BenchRun::*field) {
          int ro = 0;
          const Stat so = oracle.reached_time(field, &ro);
          int n = 0;
          for (const auto* r : g.runs) n += ro > 0 && r->*field && *(r->*field) < so.mean;
          return n;
        };
        md << "| " << w << " | " << p << " | " << ratio_of(g, &BenchRun::time_r_s) << " | "
           << ratio_of(g, &BenchRun::time_95_s) << " | "
           << (od > 0 ? fmt(g.metric(&BenchRun::distance_m).mean / od, 2) : std::string("N/A")) << " | "
           << sooner(&BenchRun::time_r_s) << " / " << sooner(&BenchRun::time_95_s) << " of " << g.runs.size()
           << " |\n";
      }
    }
  }

  md << "\n### " << o.sweep_planner << " against each baseline (difference of the means; negative time and "
     << "distance are better)\n\n"
     << "| Env. | vs | Time_f | Time_r | Time_o | Distance | Coverage (points) "
        "|\n|---|---|---|---|---|---|---|\n";
  auto pct = [](double ours, double theirs) {
    if (!(std::fabs(theirs) > 1e-9)) return std::string("–");
    const double d = 100.0 * (ours - theirs) / theirs;
    return (d >= 0 ? "+" : "") + fmt(d, 1) + " %";
  };
  for_each_baseline(
      runs, o, [&](const std::string& w, const std::string& p, const Group& ours, const Group& theirs) {
        auto margin = [&](std::optional<double> BenchRun::*field, const char* threshold) {
          int ro = 0, rt = 0;
          const Stat so = ours.reached_time(field, &ro), st = theirs.reached_time(field, &rt);
          if (ro > 0 && rt > 0) return pct(so.mean, st.mean);
          return ro > 0   ? "only ours reached " + std::string(threshold)
                 : rt > 0 ? "only theirs reached " + std::string(threshold)
                          : std::string("–");
        };
        const std::string time_r = margin(&BenchRun::time_r_s, "85 %");
        const std::string time_o = margin(&BenchRun::time_o_s, "75 %");
        const double dc =
            ours.metric(&BenchRun::coverage_pct).mean - theirs.metric(&BenchRun::coverage_pct).mean;
        md << "| " << w << " | " << p << " | "
           << pct(ours.metric(&BenchRun::time_f_s).mean, theirs.metric(&BenchRun::time_f_s).mean) << " | "
           << time_r << " | " << time_o << " | "
           << pct(ours.metric(&BenchRun::distance_m).mean, theirs.metric(&BenchRun::distance_m).mean) << " | "
           << (dc >= 0 ? "+" : "") << fmt(dc, 2) << " |\n";
      });

  md << "\n### " << o.sweep_planner << " against each baseline, seed by seed\n\n"
     << "Over the seeds where both reached the threshold (Time_r: 85 % of the volume; Time_o: 75 % of "
        "the objects): how many "
     << o.sweep_planner
     << " reached it sooner / at the same time (±0.05 s) / later, the mean of its time minus the baseline's, "
        "and that mean's 95 % interval (Student's t over the seeds; an interval across 0: these seeds "
        "do not tell the two apart); then the mean relative difference, which weighs every pair the same, "
        "and the mean difference as a share of the baseline's mean time, which weighs each pair by its "
        "time.\n\n"
     << "| Env. | vs | time | pairs | sooner / same / later | mean difference (s) | 95 % interval (s) | "
        "mean relative difference (%) | 95 % interval (%) | mean difference (% of the baseline's mean) | "
        "95 % interval (%) |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  const std::vector<std::pair<const char*, std::optional<double> BenchRun::*>> times = {
      {"Time_r", &BenchRun::time_r_s}, {"Time_95", &BenchRun::time_95_s}, {"Time_o", &BenchRun::time_o_s}};
  // The generated worlds pooled: each run paired with the baseline's of the same world and seed.
  std::map<std::string, std::pair<Group, Group>> pooled;
  std::set<std::string> pooled_worlds;
  for_each_baseline(
      runs, o, [&](const std::string& w, const std::string& p, const Group& ours, const Group& theirs) {
        for (const auto& [name, field] : times)
          md << "| " << w << " | " << p << " | " << name << " | " << paired_row(ours, theirs, field) << "\n";
        if (!is_generated(w)) return;
        pooled_worlds.insert(w);
        auto& [po, pt] = pooled[p];
        po.runs.insert(po.runs.end(), ours.runs.begin(), ours.runs.end());
        pt.runs.insert(pt.runs.end(), theirs.runs.begin(), theirs.runs.end());
      });
  for (const auto& [p, groups] : pooled) {
    const std::string w =
        std::string(kGeneratedPrefix) + " (" + std::to_string(pooled_worlds.size()) + " worlds)";
    for (const auto& [name, field] : times)
      md << "| " << w << " | " << p << " | " << name << " | "
         << paired_row(groups.first, groups.second, field) << "\n";
  }

  // Where the time went (time_split.json; core/time_split.hpp), mean seconds per run.
  bool any_split = false;
  for (const auto& r : runs) any_split |= !r.split_s.empty();
  if (any_split) {
    md << "\n### Where the time went (time_split.json), mean s per run\n\n"
       << "new: flying while the map grows ≥ 0.25 m³/s; revisit: flying while it grows less (through mapped "
          "space); turn: turning in place; hover: neither; end game: after the map settled. By place: metres "
          "flown within 1 m of where the vehicle was 10 s or more before.\n\n"
       << "| Env. | Algorithm | runs | new | revisit | turn | hover | end game | Time_f | revisit by place "
          "(m) |\n"
       << "|---|---|---|---|---|---|---|---|---|---|\n";
    // The whole run (to Time_f, with the place measure) or up to Time_r (its first four uses).
    auto split_row = [&](const std::string& w, const std::string& p, const std::vector<const BenchRun*>& g,
                         bool to_r) {
      std::vector<std::vector<double>> v(to_r ? 4 : 5);
      std::vector<double> total, place;
      for (const auto* r : g) {
        const std::vector<double>& s = to_r ? r->split_to_r_s : r->split_s;
        if (s.size() != 5) continue;
        for (size_t i = 0; i < v.size(); ++i) v[i].push_back(s[i]);
        total.push_back(to_r ? *r->time_r_s : r->time_f_s);
        place.push_back(r->revisit_by_place_m);
      }
      if (total.empty()) return;
      md << "| " << w << " | " << p << " | " << total.size();
      for (const auto& x : v) md << " | " << fmt(stat_of(x).mean, 1);
      md << " | " << fmt(stat_of(total).mean, 1);
      if (!to_r) md << " | " << fmt(stat_of(place).mean, 1);
      md << " |\n";
    };
    auto split_table = [&](bool to_r) {
      std::map<std::string, std::vector<const BenchRun*>> generated;
      std::set<std::string> generated_worlds;
      for (const auto& w : worlds) {
        const std::vector<const BenchRun*> here = runs_in(runs, w, o.comparison_samples);
        for (const auto& p : planners_of(here)) {
          const Group g = select(runs, w, p, o.comparison_samples);
          split_row(w, p, g.runs, to_r);
          if (is_generated(w)) {
            generated_worlds.insert(w);
            generated[p].insert(generated[p].end(), g.runs.begin(), g.runs.end());
          }
        }
      }
      for (const auto& [p, g] : generated)
        split_row(std::string(kGeneratedPrefix) + " (" + std::to_string(generated_worlds.size()) + " worlds)",
                  p, g, to_r);
    };
    split_table(false);
    bool any_to_r = false;
    for (const auto& r : runs) any_to_r |= !r.split_to_r_s.empty();
    if (any_to_r) {
      md << "\nUp to Time_r (85 % of the volume; the runs that reached it): where the time to 85 % went. "
            "Revisits here are transits that delayed 85 %, not the end game's.\n\n"
         << "| Env. | Algorithm | runs | new | revisit | turn | hover | Time_r |\n"
         << "|---|---|---|---|---|---|---|---|\n";
      split_table(true);
    }
  }
  double wall = 0, sim = 0;
  for (const auto& r : runs) {
    wall += r.wall_s;
    sim += r.sim_s;
  }
  md << "\n"
     << runs.size() << " runs, " << fmt(sim, 0) << " simulated s in " << fmt(wall, 0)
     << " wall s of exploration (" << fmt(wall > 0 ? sim / wall : 0, 1) << "x real time).\n";
  return md.str();
}

std::string bench_csv(const std::vector<BenchRun>& runs) {
  std::ostringstream c;
  c << "world,planner,seed,samples,time_f_s,distance_m,coverage_pct,time_r_s,collisions,wall_s,sim_s,"
       "termination,dir,object_coverage_pct,time_o_s,time_95_s,time_settled_s,end_game_s,disturbed\n";
  for (const auto& r : runs) {
    c << csv_escape(r.world) << ',' << csv_escape(r.planner) << ',' << r.seed << ',' << r.samples << ','
      << fmt(r.time_f_s, 3) << ',' << fmt(r.distance_m, 3) << ',' << fmt(r.coverage_pct, 3) << ','
      << (r.time_r_s ? fmt(*r.time_r_s, 3) : std::string()) << ',' << r.collisions << ',' << fmt(r.wall_s, 2)
      << ',' << fmt(r.sim_s, 3) << ',' << csv_escape(r.termination) << ',' << csv_escape(r.dir) << ','
      << (r.object_coverage_pct ? fmt(*r.object_coverage_pct, 3) : std::string()) << ','
      << (r.time_o_s ? fmt(*r.time_o_s, 3) : std::string()) << ','
      << (r.time_95_s ? fmt(*r.time_95_s, 3) : std::string()) << ','
      << (r.time_settled_s ? fmt(*r.time_settled_s, 3) : std::string()) << ','
      << (r.end_game_s ? fmt(*r.end_game_s, 3) : std::string()) << ',' << (r.disturbed ? "true" : "false")
      << '\n';
  }
  return c.str();
}

SeedSpread spread_over_seeds(const std::vector<std::vector<std::pair<double, double>>>& curves,
                             double t_max_s, double step_s) {
  SeedSpread out;
  if (curves.empty() || !(step_s > 0) || !(t_max_s >= 0) || !std::isfinite(t_max_s)) return out;
  std::vector<size_t> next(curves.size(), 0);  // per curve: its first sample after t
  std::vector<double> held(curves.size(), 0.0);
  const auto steps = static_cast<int64_t>(std::floor(t_max_s / step_s + 1e-9));
  for (int64_t k = 0; k <= steps; ++k) {
    const double t = static_cast<double>(k) * step_s;
    double sum = 0, lo = 0, hi = 0;
    for (size_t i = 0; i < curves.size(); ++i) {
      const auto& c = curves[i];
      while (next[i] < c.size() && c[next[i]].first <= t + 1e-9) held[i] = c[next[i]++].second;
      sum += held[i];
      lo = i == 0 ? held[i] : std::min(lo, held[i]);
      hi = i == 0 ? held[i] : std::max(hi, held[i]);
    }
    out.t.push_back(t);
    out.mean.push_back(sum / static_cast<double>(curves.size()));
    out.lo.push_back(lo);
    out.hi.push_back(hi);
  }
  return out;
}

std::vector<std::string> write_bench_plots(const std::vector<BenchRun>& all, const std::string& dir,
                                           const BenchReportOptions& o) {
  const std::vector<BenchRun> runs = tabled_only(all);
  std::vector<std::string> written;
  for (const auto& w : worlds_of(runs)) {
    const std::vector<const BenchRun*> here = runs_in(runs, w, o.comparison_samples);
    if (here.empty()) continue;
    std::vector<PlotSeries> series;
    double t_max = 0;
    for (const auto* r : here) t_max = std::max(t_max, r->coverage.empty() ? 0.0 : r->coverage.back().first);
    for (const auto& p : planners_of(here)) {
      const Group g = select(runs, w, p, o.comparison_samples);
      std::vector<std::vector<std::pair<double, double>>> curves;
      for (const auto* r : g.runs) curves.push_back(r->coverage);
      const SeedSpread spread = spread_over_seeds(curves, t_max, 1.0);
      PlotSeries s;
      const size_t n = g.runs.size();
      s.label = p + " (" + std::to_string(n) + (n == 1 ? " seed)" : " seeds, mean; band: min-max)");
      for (size_t i = 0; i < spread.t.size(); ++i) {
        s.points.emplace_back(spread.t[i], spread.mean[i]);
        if (n > 1) s.band.push_back({spread.t[i], spread.lo[i], spread.hi[i]});
      }
      series.push_back(std::move(s));
    }
    CoveragePlotOptions po;
    po.title =
        w + ": coverage over time, mean over seeds (" + std::to_string(o.comparison_samples) + " samples)";
    po.threshold_pct = o.threshold_pct;
    const std::string file = (fs::path(dir) / ("coverage_" + w + ".png")).string();
    write_coverage_plot(file, series, po);
    written.push_back(file);
  }
  return written;
}

const BenchRun* median_coverage_run(std::vector<const BenchRun*> runs) {
  if (runs.empty()) return nullptr;
  std::sort(runs.begin(), runs.end(), [](const BenchRun* a, const BenchRun* b) {
    return a->coverage_pct != b->coverage_pct ? a->coverage_pct < b->coverage_pct : a->seed < b->seed;
  });
  return runs[(runs.size() - 1) / 2];
}

std::vector<std::string> write_bench_montages(const std::vector<BenchRun>& all, const std::string& dir,
                                              const BenchReportOptions& o,
                                              std::vector<std::string>* missing) {
  const std::vector<BenchRun> runs = tabled_only(all);
  std::vector<std::string> written;
  for (const auto& w : worlds_of(runs)) {
    const std::vector<const BenchRun*> here = runs_in(runs, w, o.comparison_samples);
    if (here.empty()) continue;
    std::vector<MontageTile> tiles;
    for (const auto& p : planners_of(here)) {
      const Group g = select(runs, w, p, o.comparison_samples);
      const BenchRun* r = median_coverage_run(g.runs);
      std::string title = p + ", seed " + std::to_string(r->seed);
      if (g.runs.size() > 1) title += " (median of " + std::to_string(g.runs.size()) + ")";
      title += ": " + fmt(r->coverage_pct, 1) + " %, Time_95 " +
               (r->time_95_s ? fmt(*r->time_95_s, 1) + " s" : std::string("not reached"));
      tiles.push_back({(fs::path(r->dir) / "map.png").string(), title});
    }
    MontageOptions mo;
    mo.title = w + ": each planner's map.png at " + std::to_string(o.comparison_samples) +
               " samples (the seed of median coverage)";
    const Montage m = render_montage(tiles, mo);
    if (missing) missing->insert(missing->end(), m.missing.begin(), m.missing.end());
    const std::string file = (fs::path(dir) / ("maps_" + w + ".png")).string();
    write_png(m.image, file);
    written.push_back(file);
  }
  return written;
}

std::string bench_against_markdown(const std::vector<BenchRun>& a_all, const std::vector<BenchRun>& b_all,
                                   const BenchReportOptions& o) {
  const std::vector<BenchRun> a = tabled_only(a_all), b = tabled_only(b_all);
  using Key = std::tuple<std::string, std::string, int64_t>;  // world, planner, seed
  auto key_of = [](const BenchRun& r) { return Key{r.world, r.planner, r.seed}; };
  std::map<Key, const BenchRun*> in_b;
  for (const auto& r : b)
    if (r.samples == o.comparison_samples) in_b[key_of(r)] = &r;
  struct Pair {
    const BenchRun *a, *b;
  };
  std::vector<Pair> pairs;
  std::vector<const BenchRun*> only_a;
  std::set<Key> paired;
  for (const auto& r : a) {
    if (r.samples != o.comparison_samples) continue;
    const auto it = in_b.find(key_of(r));
    if (it == in_b.end()) {
      only_a.push_back(&r);
      continue;
    }
    pairs.push_back({&r, it->second});
    paired.insert(it->first);
  }
  std::sort(pairs.begin(), pairs.end(), [&](const Pair& x, const Pair& y) {
    if (x.a->world != y.a->world) return x.a->world < y.a->world;
    if (x.a->planner != y.a->planner) return planner_rank(x.a->planner) < planner_rank(y.a->planner);
    return x.a->seed < y.a->seed;
  });
  std::vector<std::string> planners;
  for (const auto& p : pairs)
    if (std::find(planners.begin(), planners.end(), p.a->planner) == planners.end())
      planners.push_back(p.a->planner);
  std::stable_sort(planners.begin(), planners.end(), [](const std::string& x, const std::string& y) {
    return planner_rank(x) < planner_rank(y);
  });
  const std::string all_planners = "all planners";
  auto in_group = [&](const Pair& p, const std::string& planner) {
    return planner == all_planners || p.a->planner == planner;
  };
  std::vector<std::string> groups = planners;
  if (planners.size() > 1) groups.push_back(all_planners);

  std::ostringstream md;
  md << "### A against B, run by run (A: this bench, B: the baseline bench)\n\n"
     << "Each run of A paired with B's run of the same world, planner and seed at " << o.comparison_samples
     << " samples (valid, undisturbed runs only). DONE: the planner ended the run.\n\n"
     << "| planner | pairs | collisions A / B | DONE A / B | least coverage A / B (%) "
        "|\n|---|---|---|---|---|\n";
  for (const auto& g : groups) {
    int n = 0, done_a = 0, done_b = 0;
    int64_t col_a = 0, col_b = 0;
    double least_a = 1e9, least_b = 1e9;
    for (const auto& p : pairs) {
      if (!in_group(p, g)) continue;
      ++n;
      col_a += p.a->collisions;
      col_b += p.b->collisions;
      done_a += p.a->termination == "planner_done";
      done_b += p.b->termination == "planner_done";
      least_a = std::min(least_a, p.a->coverage_pct);
      least_b = std::min(least_b, p.b->coverage_pct);
    }
    md << "| " << g << " | " << n << " | " << col_a << " / " << col_b << " | " << done_a << " / " << done_b
       << " | " << fmt(least_a, 2) << " / " << fmt(least_b, 2) << " |\n";
  }

  using Field = std::function<std::optional<double>(const BenchRun&)>;
  const std::vector<std::pair<const char*, Field>> times = {
      {"Time_r", [](const BenchRun& r) { return r.time_r_s; }},
      {"Time_95", [](const BenchRun& r) { return r.time_95_s; }},
      {"Time_o", [](const BenchRun& r) { return r.time_o_s; }},
      {"Time_f", [](const BenchRun& r) { return std::optional<double>(r.time_f_s); }}};
  // The sets: every world, the generated ones pooled, and each other world.
  std::vector<std::pair<std::string, std::function<bool(const std::string&)>>> sets;
  std::set<std::string> generated, others;
  for (const auto& p : pairs) (is_generated(p.a->world) ? generated : others).insert(p.a->world);
  sets.emplace_back("all (" + std::to_string(generated.size() + others.size()) + " worlds)",
                    [](const std::string&) { return true; });
  if (!generated.empty() && !others.empty())
    sets.emplace_back(std::string(kGeneratedPrefix) + " (" + std::to_string(generated.size()) + " worlds)",
                      [](const std::string& w) { return is_generated(w); });
  for (const auto& w : others) sets.emplace_back(w, [w](const std::string& x) { return x == w; });
  md << "\n### A against B, paired\n\n"
     << "Over the pairs where both runs reached the time's threshold: how many A reached it sooner / at the "
        "same time (±0.05 s) / later, the mean of A's time minus B's, the mean relative difference "
        "(A / B − 1), which weighs every pair the same, and the mean difference as a share of B's mean "
        "time, which weighs each pair by its time, each with its 95 % interval (Student's t over the "
        "pairs).\n\n"
     << "| worlds | planner | time | pairs | sooner / same / later | mean difference (s) | 95 % interval (s) "
        "| "
        "mean relative difference (%) | 95 % interval (%) | mean difference (% of B's mean) | 95 % interval "
        "(%) |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& [set_name, in_set] : sets) {
    for (const auto& g : groups) {
      for (const auto& [name, field] : times) {
        std::vector<std::pair<double, double>> v;
        for (const auto& p : pairs) {
          if (!in_group(p, g) || !in_set(p.a->world)) continue;
          const std::optional<double> x = field(*p.a), y = field(*p.b);
          if (x && y) v.emplace_back(*x, *y);
        }
        md << "| " << set_name << " | " << g << " | " << name << " | " << paired_cells(v) << "\n";
      }
    }
  }

  auto opt = [](std::optional<double> v) { return v ? fmt(*v, 1) : std::string("–"); };
  md << "\n### Every pair (A / B)\n\n"
     << "| Env. | Algorithm | seed | Time_r (s) | Time_95 (s) | Time_o (s) | Time_f (s) | Coverage (%) | "
        "collisions | termination |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& p : pairs) {
    md << "| " << p.a->world << " | " << p.a->planner << " | " << p.a->seed << " | " << opt(p.a->time_r_s)
       << " / " << opt(p.b->time_r_s) << " | " << opt(p.a->time_95_s) << " / " << opt(p.b->time_95_s) << " | "
       << opt(p.a->time_o_s) << " / " << opt(p.b->time_o_s) << " | " << fmt(p.a->time_f_s, 1) << " / "
       << fmt(p.b->time_f_s, 1) << " | " << fmt(p.a->coverage_pct, 2) << " / " << fmt(p.b->coverage_pct, 2)
       << " | " << p.a->collisions << " / " << p.b->collisions << " | " << p.a->termination << " / "
       << p.b->termination << " |\n";
  }
  std::string unpaired;
  for (const auto* r : only_a)
    unpaired += "- only in A: " + r->world + ", " + r->planner + ", seed " + std::to_string(r->seed) + " (" +
                r->dir + ")\n";
  for (const auto& [k, r] : in_b)
    if (!paired.count(k))
      unpaired += "- only in B: " + r->world + ", " + r->planner + ", seed " + std::to_string(r->seed) +
                  " (" + r->dir + ")\n";
  const size_t left_out = (a_all.size() - a.size()) + (b_all.size() - b.size());
  if (left_out > 0)
    unpaired +=
        "- " + std::to_string(left_out) + " runs not valid or disturbed (see each bench's tables.md)\n";
  if (!unpaired.empty()) md << "\n### Runs without a partner\n\n" << unpaired;
  return md.str();
}

}  // namespace semx::evaluator
