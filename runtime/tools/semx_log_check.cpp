// semx-log-check: whether a file is a whole lcm-logger log, before a tool that trusts it plays it
// (./semx replay runs it ahead of lcm-logplayer, which stops at a corrupt header without a word
// and exits 0). Exit 0: a log (a last event cut short is reported and is no error: the logger
// was killed while writing); 1: missing, empty, not a log or corrupt, with the byte offset.
#include <cstdio>

#include "semx/runtime/args.hpp"
#include "semx/runtime/log_scan.hpp"

int main(int argc, char** argv) {
  return semx::runtime::run_main("semx-log-check", [&] {
    std::string log;
    bool quiet = false;
    semx::runtime::ArgParser p("semx-log-check", "Checks that LOG is an lcm-logger log, event header by event header.");
    p.positional("LOG", "the log", &log).flag("quiet", "print nothing when the log is whole", &quiet);
    if (!p.parse(argc, argv)) return 0;
    try {
      const semx::runtime::LogLayout l = semx::runtime::scan_log(log);
      if (l.truncated) {
        std::printf("semx-log-check: %s: %lld events; the last one, at byte %llu, is cut short and is left out\n",
                    log.c_str(), static_cast<long long>(l.events), static_cast<unsigned long long>(l.truncated_at));
      } else if (!quiet) {
        std::printf("semx-log-check: %s: %lld events, %llu bytes\n", log.c_str(), static_cast<long long>(l.events),
                    static_cast<unsigned long long>(l.file_bytes));
      }
    } catch (const semx::runtime::LogError& e) {
      std::fprintf(stderr, "semx-log-check: %s\n", e.what());
      return 1;
    }
    return 0;
  });
}
