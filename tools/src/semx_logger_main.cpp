// semx-logger: records LCM traffic to an LCM log file (the format lcm-logger writes, which
// lcm-logplayer, lcm-spy and semx-eval read), like lcm-logger with the flags the launch sets use.
//
// Why not lcm-logger itself: liblcm queues at most 30 messages per subscription and drops the
// rest silently, and lcm-logger keeps that default; on a loaded 2-core machine it lost 0.4 % of
// a lockstep env3 run's odometry, more as the set ran faster (docs/launch.md). This recorder reads
// the group through the node runtime, whose only queue is the socket's, drops the channels it
// excludes in the kernel, and counts what it could not read.
#include <lcm/eventlog.h>
#include <sys/time.h>

#include <filesystem>
#include <iostream>

#include "semx/runtime/log_scan.hpp"
#include "semx/runtime/node_flags.hpp"
#include "semx/runtime/restart_count.hpp"
#include "semx/tools/channel_selection.hpp"

using namespace semx::runtime;

namespace {

int64_t wall_utime() {
  timeval tv{};
  gettimeofday(&tv, nullptr);
  return int64_t{tv.tv_sec} * 1000000 + tv.tv_usec;
}

}  // namespace

int main(int argc, char** argv) {
  return run_main("semx-logger", [&] {
    NodeFlags flags("logger");
    std::string channel = ".*", file;
    bool invert = false, force = false;
    ArgParser p("semx-logger",
                "Records the LCM messages of the channels matching --channel (all by default) to FILE,\n"
                "an LCM log, until SIGINT or SIGTERM.");
    flags.add_to(p);
    p.option("channel", "REGEX",
             "channels to record, a regular expression matching the whole name (default .*)", &channel)
        .flag("invert-channels", "record every channel that does not match --channel", &invert)
        .flag("force", "overwrite FILE if it exists", &force)
        .positional("FILE", "the log to write", &file);
    if (!p.parse(argc, argv)) return 0;
    semx::tools::ChannelSelection selection = [&] {
      try {
        return semx::tools::ChannelSelection(channel, invert);
      } catch (const std::invalid_argument& e) {
        throw ArgError(std::string("--channel: ") + e.what());
      }
    }();
    std::error_code ec;
    // Restarted by the launcher after a crash: the run's log goes on, it is not begun again. A
    // last event the crash cut short is cut off first, so the log stays readable end to end.
    int64_t events = 0;
    const char* mode = "w";
    if (restart_count() > 0 && std::filesystem::exists(file, ec)) {
      try {
        const LogLayout layout = scan_log(file);
        if (layout.truncated) std::filesystem::resize_file(file, layout.truncated_at);
        events = layout.events;
        mode = "a";
        std::cerr << "semx-logger: restart " << restart_count() << ": appending to " << file << " after its "
                  << events << " events" << (layout.truncated ? " (a last event cut short was removed)" : "")
                  << "\n";
      } catch (const LogError& e) {
        // Nothing readable was written before the crash (an empty file): begin it.
        std::cerr << "semx-logger: restart " << restart_count() << ": " << e.what() << "; writing it anew\n";
      }
    } else if (!force && std::filesystem::exists(file, ec)) {
      throw ArgError(file + ": exists (--force overwrites it)");
    }

    lcm_eventlog_t* log = lcm_eventlog_create(file.c_str(), mode);
    if (!log) throw std::runtime_error(file + ": cannot open for writing");
    auto options = flags.options();
    options.follow_clock = false;  // a recorder keeps no time of its own
    options.announce = false;
    options.observer = true;
    Node node(options);
    install_shutdown_handlers();
    int64_t failed = 0;
    node.subscribe_raw(".*", [&](const std::string& ch, const uint8_t* data, std::size_t size) {
      if (!selection.wants(ch)) return;
      lcm_eventlog_event_t ev{};
      ev.eventnum = events;
      ev.timestamp = wall_utime();
      ev.channellen = static_cast<int32_t>(ch.size());
      ev.datalen = static_cast<int32_t>(size);
      ev.channel = const_cast<char*>(ch.c_str());
      ev.data = const_cast<uint8_t*>(data);
      if (lcm_eventlog_write_event(log, &ev) == 0) {
        ++events;
      } else if (failed++ == 0) {
        std::cerr << "semx-logger: " << file << ": write failed (disk full?); later events are counted\n";
      }
    }, /*with_trailer=*/true);
    node.never_wanted(selection.refused_known());
    const int rc = node.run();
    node.drain();  // what arrived before the signal is part of the run
    lcm_eventlog_destroy(log);
    const auto& c = node.counters();
    if (!options.quiet || failed > 0 || c.dropped > 0 || c.malformed > 0) {
      std::cerr << "semx-logger: " << events << " events in " << file << "; " << failed << " not written, "
                << c.dropped << " messages lost in transit, " << c.malformed << " bad datagrams\n";
    }
    return failed > 0 ? 1 : rc;
  });
}
