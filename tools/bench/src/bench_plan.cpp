#include "semx/bench/bench_plan.hpp"

#include <glob.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <thread>

#include "semx/runtime/args.hpp"

namespace semx::bench {

using runtime::ArgError;

namespace {

// "oracle" is the known-map reference (it reads the world's ground truth); the report divides
// the others' times by its own.
const std::vector<std::string> kPlanners = {"semantic-dep", "dep",    "nbv",           "aep",
                                            "fuel",         "oracle", "semantic-room", "semantic-fuel"};

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// `[[ $s =~ ^[0-9]+$ ]] && [ "$s" -ge 1 ]`, limited to int (a count of seeds or slots).
bool positive_integer(const std::string& s, int* value = nullptr) {
  if (s.empty() || !std::all_of(s.begin(), s.end(), is_digit)) return false;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), nullptr, 10);
  if (errno != 0 || v < 1 || v > INT_MAX) return false;
  if (value) *value = static_cast<int>(v);
  return true;
}

bool is_shipped_world(const std::string& w) { return w == "env1" || w == "env2" || w == "env3"; }

bool is_regular_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool is_directory(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

// The value of the last ",KEY=S," in `text` (",LIST,") whose S is digits and dots: what the bash
// bench's `sed -n 's/.*,KEY=\([0-9.]*\),.*/\1/p'` printed (its leading .* is greedy, so the last).
// KEY is matched as text, where sed read it as a pattern; world names are plain.
std::string last_value(const std::string& text, const std::string& key) {
  const std::string head = "," + key + "=";
  for (std::size_t pos = text.rfind(head); pos != std::string::npos;
       pos = pos == 0 ? std::string::npos : text.rfind(head, pos - 1)) {
    const std::size_t begin = pos + head.size();
    std::size_t end = begin;
    while (end < text.size() && (is_digit(text[end]) || text[end] == '.')) ++end;
    if (end < text.size() && text[end] == ',') return text.substr(begin, end - begin);
  }
  return "";
}

// The number `sort -n` reads at the start of a time limit (digits, a point, digits; "1.2.3" is
// 1.2, "." is 0), so that worlds are ordered as the bash bench's `sort -s -k1,1nr` ordered them.
double sort_key(const std::string& s) {
  std::size_t e = 0;
  while (e < s.size() && is_digit(s[e])) ++e;
  if (e < s.size() && s[e] == '.') {
    ++e;
    while (e < s.size() && is_digit(s[e])) ++e;
  }
  return std::strtod(s.substr(0, e).c_str(), nullptr);
}

}  // namespace

std::string GeneratedWorld::name() const {
  return "generated-s" + std::to_string(seed) + "-a" + std::to_string(area_m2) + "-r" + std::to_string(rooms);
}

const std::vector<GeneratedWorld>& generated_worlds() {
  // Areas roughly evenly on a log scale, rooms growing with them; time limits 300 s + 2 s per m²
  // (DEP took ~1.3 s per m² to DONE in env1-3).
  static const std::vector<GeneratedWorld> worlds = {
      {1, 50, 1, "400"},  {2, 90, 3, "480"},    {3, 140, 4, "580"},   {4, 200, 6, "700"},
      {5, 280, 8, "860"}, {6, 380, 10, "1060"}, {7, 480, 12, "1260"}, {8, 600, 14, "1500"},
  };
  return worlds;
}

std::vector<GeneratedWorld> generated_worlds_of(const BenchOptions& o) {
  for (const auto& w : list_words(o.worlds))
    if (w == kGeneratedWorlds) return generated_worlds();
  return {};
}

const std::vector<std::string>& reserved_launch_args() {
  static const std::vector<std::string> keys = {"world", "planner",    "seed", "samples",
                                                "clock", "time_limit", "out",  "progress"};
  return keys;
}

BenchOptions parse_bench_args(const std::vector<std::string>& args) {
  BenchOptions o;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    // The next word; an empty one counts as missing unless `may_be_empty` (--sweep "" is no sweep).
    auto value = [&](const char* missing, bool may_be_empty = false) {
      if (i + 1 >= args.size() || (!may_be_empty && args[i + 1].empty())) throw ArgError(missing);
      return args[++i];
    };
    if (a == "--worlds") {
      o.worlds = value("--worlds needs a list");
    } else if (a == "--planners") {
      o.planners = value("--planners needs a list");
    } else if (a == "--seeds") {
      o.seeds = value("--seeds needs a number");
    } else if (a == "--sweep") {
      o.sweep = value("--sweep needs a list (or \"\")", true);
    } else if (a == "--samples") {
      o.samples = value("--samples needs a number");
    } else if (a == "--time-limits") {
      o.time_limits = value("--time-limits needs WORLD=S,...");
    } else if (a == "--time-limit") {
      o.time_limits = "*=" + value("--time-limit needs seconds");
    } else if (a == "--out") {
      o.out = value("--out needs a directory");
    } else if (a == "--against") {
      o.against = value("--against needs a bench folder");
    } else if (a == "--logs") {
      o.keep_logs = true;
    } else if (a == "--arg") {
      const std::string kv = value("--arg needs KEY=VALUE");
      const std::string key = kv.substr(0, kv.find('='));
      const auto& reserved = reserved_launch_args();
      if (std::find(reserved.begin(), reserved.end(), key) != reserved.end()) {
        throw ArgError("--arg " + kv + ": the bench sets '" + key +
                       "' itself (use --worlds, --planners, --seeds, ...)");
      }
      if (kv.find('=') == std::string::npos) throw ArgError("--arg '" + kv + "': expected KEY=VALUE");
      o.launch_args.push_back(kv);
    } else if (a == "--jobs") {
      o.jobs = value("--jobs needs a number");
    } else if (a == "--base-port") {
      o.base_port = value("--base-port needs a port");
    } else if (a == "--quick") {
      o.worlds = "env1";
      o.seeds = "1";
      o.sweep = "";
      o.time_limits = "*=120";
    } else if (a == "--dry-run") {
      o.dry_run = true;
    } else if (a == "--help") {
      o.help = true;
      return o;
    } else {
      throw ArgError("unknown option '" + a + "' (see ./semx bench --help)");
    }
  }
  return o;
}

void validate_bench_options(const BenchOptions& o) {
  if (!positive_integer(o.seeds)) throw ArgError("--seeds '" + o.seeds + "': expected a positive integer");
  if (!o.against.empty() && !is_directory(o.against)) {
    throw ArgError("--against '" + o.against + "': not a directory (a bench's --out folder)");
  }
  if (!positive_integer(o.samples)) {
    throw ArgError("--samples '" + o.samples + "': expected a positive integer");
  }
  const int jobs = job_count(o);
  if (!o.base_port.empty() && (!positive_integer(o.base_port) || o.base_port.size() > 5 ||
                               std::stoi(o.base_port) < 1024 || std::stoi(o.base_port) + jobs - 1 > 65535)) {
    throw ArgError("--base-port '" + o.base_port +
                   "': expected a port from 1024 with --jobs ports free above it");
  }
  for (const auto& p : list_words(o.planners)) {
    if (std::find(kPlanners.begin(), kPlanners.end(), p) == kPlanners.end()) {
      throw ArgError("--planners: unknown planner '" + p + "'");
    }
  }
  if (o.sweep != "paper") {
    for (const auto& n : list_words(o.sweep)) {
      if (!positive_integer(n)) throw ArgError("--sweep: '" + n + "' is not a positive integer (or paper)");
    }
  }
  for (const auto& w : list_words(o.worlds)) {
    if (!is_shipped_world(w) && w != kGeneratedWorlds && !is_regular_file(w)) {
      throw ArgError("--worlds: '" + w + "' is no world file (or env1, env2, env3, generated)");
    }
  }
}

int seed_count(const BenchOptions& o) {
  int n = 0;
  if (!positive_integer(o.seeds, &n))
    throw ArgError("--seeds '" + o.seeds + "': expected a positive integer");
  return n;
}

int default_job_count() {
  const unsigned cores = std::thread::hardware_concurrency();
  return static_cast<int>(std::clamp(cores, 1u, 8u));
}

int job_count(const BenchOptions& o) {
  if (o.jobs.empty()) return default_job_count();
  int n = 0;
  if (!positive_integer(o.jobs, &n)) throw ArgError("--jobs '" + o.jobs + "': expected a positive integer");
  return n;
}

std::vector<std::string> list_words(const std::string& list) {
  std::vector<std::string> words;
  std::string word;
  auto flush = [&] {
    if (word.empty()) return;
    if (word.find_first_of("*?[") == std::string::npos) {
      words.push_back(word);
    } else {
      glob_t g{};
      if (::glob(word.c_str(), GLOB_NOCHECK, nullptr, &g) == 0) {
        for (std::size_t k = 0; k < g.gl_pathc; ++k) words.emplace_back(g.gl_pathv[k]);
      } else {
        words.push_back(word);
      }
      ::globfree(&g);
    }
    word.clear();
  };
  for (const char c : list) {
    if (c == ',' || c == ' ' || c == '\t' || c == '\n') {
      flush();
    } else {
      word += c;
    }
  }
  flush();
  return words;
}

std::string world_name(const std::string& world) {
  std::string s = world;
  while (s.size() > 1 && s.back() == '/') s.pop_back();
  if (s != "/") {
    const auto slash = s.rfind('/');
    if (slash != std::string::npos) s = s.substr(slash + 1);
  }
  const std::string suffix = ".yaml";
  if (s.size() > suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0) {
    s.erase(s.size() - suffix.size());
  }
  return s;
}

std::string time_limit_of(const std::string& time_limits, const std::string& world) {
  const std::string text = "," + time_limits + ",";
  std::string limit = last_value(text, world_name(world));
  if (limit.empty()) limit = last_value(text, "*");
  return limit.empty() ? "600" : limit;
}

std::string sweep_of(const std::string& sweep, const std::string& world) {
  if (sweep != "paper") return sweep;
  const std::string name = world_name(world);
  if (name == "env1" || name == "env2") return "25,30,35,40,45";
  if (name == "env3") return "30,35,40,45,50";
  return "25,30,35,40,45,50";
}

std::string BenchRun::name() const {
  return world_name(world) + "-" + planner + "-s" + samples + "-seed" + std::to_string(seed);
}

std::vector<BenchRun> bench_runs(const BenchOptions& o, const std::string& generated_dir) {
  struct World {
    std::string path, limit;
    double key;
  };
  std::vector<World> worlds;
  const std::string text = "," + o.time_limits + ",";
  for (const auto& w : list_words(o.worlds)) {
    if (w == kGeneratedWorlds) {
      for (const GeneratedWorld& g : generated_worlds()) {
        std::string limit = last_value(text, g.name());
        if (limit.empty()) limit = last_value(text, "*");
        if (limit.empty()) limit = g.time_limit;
        worlds.push_back({generated_dir + "/" + g.name() + ".yaml", limit, sort_key(limit)});
      }
      continue;
    }
    const std::string limit = time_limit_of(o.time_limits, w);
    worlds.push_back({w, limit, sort_key(limit)});
  }
  std::stable_sort(worlds.begin(), worlds.end(),
                   [](const World& a, const World& b) { return a.key > b.key; });
  const auto planners = list_words(o.planners);
  const bool compares_semantic_dep = ("," + o.planners + ",").find(",semantic-dep,") != std::string::npos;
  const int seeds = seed_count(o);
  std::vector<BenchRun> runs;
  for (const auto& w : worlds) {
    for (int seed = 1; seed <= seeds; ++seed) {
      for (const auto& p : planners) {
        // The oracle draws nothing at random and the seed reaches only the planner, so its seeds
        // fly one run to the digit (docs/evaluation.md): seed 1 stands for them all.
        if (p == "oracle" && seed > 1) continue;
        runs.push_back({w.path, p, o.samples, seed, w.limit});
      }
      for (const auto& n : list_words(sweep_of(o.sweep, w.path))) {
        if (n == o.samples && compares_semantic_dep) continue;
        runs.push_back({w.path, "semantic-dep", n, seed, w.limit});
      }
    }
  }
  return runs;
}

std::string dry_run_text(const std::vector<BenchRun>& runs) {
  std::string text;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    text += "[" + std::to_string(k + 1) + "/" + std::to_string(runs.size()) + "] " + runs[k].name() +
            ": time limit " + runs[k].time_limit + " s\n";
  }
  return text;
}

std::string bench_help() {
  return R"(usage: ./semx bench [--worlds LIST] [--planners LIST] [--seeds N] [--sweep LIST] [--samples N]
                    [--time-limits WORLD=S,...|--time-limit S] [--out DIR] [--logs] [--jobs N]
                    [--arg KEY=VALUE]... [--against BASE] [--quick] [--dry-run]

The paper's experiment, in LOCKSTEP (deterministic per seed): for every world and seeds 1..N,
(a) the sampling-density sweep of Table II for semantic-dep (--sweep LIST for every world; the
default, "paper", is the table's rows: env1 and env2 at 25,30,35,40,45, env3 at 30,35,40,45,50,
a world file at 25,30,35,40,45,50) and (b) the planner comparison of Table III (--planners, default nbv,aep,dep,semantic-dep,fuel,oracle) at
--samples (default 45); oracle is the known-map reference that reads the world's ground truth (the
report divides every planner's times by its own; it runs at seed 1 only, as its seeds fly the same
run), fuel the FUEL-class baseline. Each run is ./semx demo's process set writing a run folder under
DIR/runs/ (default DIR: runs/bench-DATE); a run whose folder already has the metrics of a run
that ended (DONE, time limit) is not run again, so an interrupted bench continues where it
stopped; one that was stopped before its end runs again, its old folder moved to
DIR/interrupted/ (not in the tables). At the end semx-bench-report
writes DIR/tables.md (mean ± std over seeds, the paper's layout), DIR/results.csv,
DIR/coverage_WORLD.png (every planner on one plot per world, min-max bands over seeds) and
DIR/maps_WORLD.png (each planner's map.png, the seed of median coverage).
--worlds generated: eight generated apartments of 50 to 600 m² and 1 to 14 rooms (semx-world gen,
seeds 1-8, written to DIR/worlds/), time limits 300 s + 2 s per m² unless --time-limits names them.
Time limits (simulated s): env1=300, env2=600, env3=900 by default. --logs keeps each run's
LCM log (about 100 MB per run). --jobs N runs N process sets at once (default: one per core, at
most 8), each on its own LCM port (a lockstep set leaves part of the machine idle while it waits
for acks; the metrics do not depend on it, only the wall times do): slot k talks on LCM_DEFAULT_URL (default
udpm://239.255.76.67:7667?ttl=0) with its port + k, or on --base-port P + k; recv_buf_size=4194304
is added when the URL has none. --arg KEY=VALUE goes to every run's process set
(tools/launch/demo.yaml), e.g. --arg semantics_config=FILE or --arg planner_config=FILE for an
ablation. --against BASE (another bench's --out folder, e.g. the same command without the
ablation or on main): the report also writes DIR/against.md, each run paired with BASE's of the
same world, planner and seed, with 95 % intervals. --quick: env1, one seed, no sweep, 120 s.
--dry-run prints the runs in the order they
would start (the worlds with the longest time limit first) and their time limits, and runs nothing.
)";
}

}  // namespace semx::bench
