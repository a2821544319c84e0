#include "map_replay.hpp"

#include <lcm/lcm-cpp.hpp>
#include <semx/depth_image_t.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "map_messages.hpp"
#include "mapper_messages.hpp"
#include "semx/mapper/map_export.hpp"
#include "semx/runtime/frame_gate.hpp"
#include "semx/runtime/lcm_schema.hpp"
#include "semx/runtime/log_session.hpp"
#include "semx/runtime/wire_validator.hpp"

namespace semx::mapper {

namespace fs = std::filesystem;

ReplayReport replay_log(const ReplayOptions& options, Mapper& mapper) {
  ReplayReport r;
  r.layout = runtime::scan_log(options.log_path);
  std::unique_ptr<runtime::LogSession> session;
  try {
    const auto key = options.auth_key_file.empty() ? runtime::key_beside(options.log_path)
                                                   : runtime::AuthKey::from_file(options.auth_key_file);
    session = std::make_unique<runtime::LogSession>(options.log_path, r.layout, key);
  } catch (const std::exception& e) {
    throw ReplayError(e.what());
  }
  lcm::LogFile log(options.log_path, "r");
  if (!log.good()) throw ReplayError(options.log_path + ": lcm::LogFile cannot open it");

  const runtime::LcmSchema& schema = runtime::LcmSchema::semx();
  const runtime::LcmStruct* type = schema.find("semx.depth_image_t");
  if (!type) throw ReplayError("no .lcm layout for semx.depth_image_t");
  semx::depth_image_t msg;
  DecodedDepth decoded;
  runtime::FrameGate gate(mapper.config().integration.frame_period_s);
  auto note = [&](const std::string& why) {
    if (r.first_error.empty()) r.first_error = why;
  };
  // Only the events the scan found complete: LogFile's reader is not safe past them.
  for (int64_t i = 0; i < r.layout.events; ++i) {
    const lcm::LogEvent* e = log.readNextEvent();
    if (!e) throw ReplayError(options.log_path + ": lcm::LogFile stopped at event " + std::to_string(i));
    const auto* data = static_cast<const uint8_t*>(e->data);
    const auto payload = session->payload(e->channel, data, static_cast<size_t>(e->datalen));
    if (!payload) continue;
    const size_t size = *payload;
    ++r.channels[e->channel];
    if (e->channel != options.channel) continue;
    ++r.depth_events;
    const runtime::WireError we =
        runtime::validate_wire(schema, *type, semx::depth_image_t::getHash(), data, size);
    if (we != runtime::WireError::kNone) {
      ++r.malformed;
      note("event " + std::to_string(i) + ": " + runtime::to_string(we));
      continue;
    }
    try {
      if (msg.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) {
        ++r.malformed;
        note("event " + std::to_string(i) + ": decoder rejected it");
        continue;
      }
    } catch (const std::exception& ex) {
      ++r.malformed;
      note("event " + std::to_string(i) + ": decoder threw: " + ex.what());
      continue;
    }
    if (!gate.due(msg.utime)) {
      ++r.skipped;
      continue;
    }
    std::string why = decode_depth(msg, decoded);
    if (why.empty()) why = check_frame(decoded.frame());
    if (!why.empty()) {
      ++r.malformed;
      note("event " + std::to_string(i) + ": " + why);
      continue;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const FrameResult fr = mapper.integrate(decoded.frame());
    r.integrate_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!fr.report.accepted) {
      ++r.rejected;
      note("event " + std::to_string(i) + ": " + fr.report.error);
      continue;
    }
    gate.taken(msg.utime);
    ++r.integrated;
    if (r.first_utime < 0) r.first_utime = msg.utime;
    r.last_utime = std::max(r.last_utime, msg.utime);
  }
  r.left_out = session->summary();
  return r;
}

std::vector<std::string> write_map_files(const Mapper& mapper, const std::string& dir, int64_t utime) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw MapIoError(dir + ": cannot create the output directory" + (ec ? " (" + ec.message() + ")" : ""));
  }
  const std::string base = (fs::path(dir) / "map").string();
  std::vector<std::string> written;
  mapper.save_checkpoint(base + ".ckpt", utime);
  written.push_back(base + ".ckpt");
  export_octomap_bt(mapper.map(), base + ".bt");
  written.push_back(base + ".bt");
  export_occupied_pcd(mapper.map().grid(), base + ".pcd");
  written.push_back(base + ".pcd");
  return written;
}

}  // namespace semx::mapper
