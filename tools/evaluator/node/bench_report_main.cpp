// semx-bench-report: the paper's tables and plots from the run folders of ./semx bench.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "semx/evaluator/bench_report.hpp"
#include "semx/runtime/args.hpp"

using namespace semx;

namespace {
void write_text(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp);
    f << text;
    if (!f) throw std::runtime_error("cannot write '" + tmp + "'");
  }
  std::filesystem::rename(tmp, path);
}
}  // namespace

int main(int argc, char** argv) {
  return runtime::run_main("semx-bench-report", [&] {
    std::string root, out, against;
    evaluator::BenchReportOptions o;
    int64_t samples = o.comparison_samples;
    runtime::ArgParser p(
        "semx-bench-report",
        "Summarises every run folder under DIR (metrics.json, coverage.csv) as the paper's\n"
        "tables (mean ± std over seeds): the sampling-density sweep, the planner comparison and\n"
        "the margins of semantic-dep over each baseline; writes DIR/tables.md, DIR/results.csv,\n"
        "DIR/coverage_WORLD.png (mean curves, min-max bands over seeds) and DIR/maps_WORLD.png\n"
        "(each planner's map.png, the seed of median coverage), and prints the tables. With\n"
        "--against BASE, also DIR/against.md: each run paired with BASE's run of the same world,\n"
        "planner and seed (a change judged run by run, with 95 % intervals).");
    p.positional("DIR", "a ./semx bench output folder (run folders anywhere below it)", &root)
        .option("out", "DIR", "where to write the report (default: DIR)", &out)
        .option("sweep-planner", "NAME", "the planner of the sampling-density table (default semantic-dep)",
                &o.sweep_planner)
        .option("samples", "N", "the sampling density the planners are compared at (default 45)", &samples)
        .option("against", "BASE", "a bench output folder to pair this one's runs with (writes against.md)",
                &against);
    if (!p.parse(argc, argv)) return 0;
    if (samples < 1) throw runtime::ArgError("--samples must be positive");
    o.comparison_samples = static_cast<int>(samples);
    if (!std::filesystem::is_directory(root)) throw runtime::ArgError("DIR '" + root + "': not a directory");
    if (!against.empty() && !std::filesystem::is_directory(against))
      throw runtime::ArgError("--against '" + against + "': not a directory");
    if (out.empty()) out = root;
    std::filesystem::create_directories(out);
    const auto runs = evaluator::load_bench_runs(root);
    if (runs.empty()) {
      std::cerr << "semx-bench-report: no run folder (metrics.json) under '" << root << "'\n";
      return 1;
    }
    const std::string md = evaluator::bench_markdown(runs, o);
    write_text((std::filesystem::path(out) / "tables.md").string(), md);
    write_text((std::filesystem::path(out) / "results.csv").string(), evaluator::bench_csv(runs));
    auto plots = evaluator::write_bench_plots(runs, out, o);
    std::vector<std::string> missing;
    for (const auto& f : evaluator::write_bench_montages(runs, out, o, &missing)) plots.push_back(f);
    for (const auto& m : missing) std::cerr << "semx-bench-report: map montage without " << m << "\n";
    std::string against_md;
    if (!against.empty()) {
      const auto base = evaluator::load_bench_runs(against);
      if (base.empty()) throw runtime::ArgError("--against '" + against + "': no run folder (metrics.json)");
      against_md = evaluator::bench_against_markdown(runs, base, o);
      write_text((std::filesystem::path(out) / "against.md").string(), against_md);
    }
    std::cout << md << (against_md.empty() ? "" : "\n" + against_md) << "\nsemx-bench-report: " << out
              << "/tables.md, results.csv" << (against_md.empty() ? "" : ", against.md");
    for (const auto& f : plots) std::cout << ", " << std::filesystem::path(f).filename().string();
    std::cout << "\n";
    return 0;
  });
}
