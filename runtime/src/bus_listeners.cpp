#include "semx/runtime/bus_listeners.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace semx::runtime {

namespace fs = std::filesystem;

namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

double foreign_hold_from_env() {
  const char* env = std::getenv("SEMX_FOREIGN_HOLD");
  if (!env || !*env) return 0.1;
  char* end = nullptr;
  const double s = std::strtod(env, &end);
  if (*end != '\0' || !(s >= 0) || s > 60)
    throw std::runtime_error(std::string("SEMX_FOREIGN_HOLD='") + env + "': expected seconds (0 to 60)");
  return s;
}

uint32_t foreign_room_bytes() {
  std::ifstream in("/proc/sys/net/core/rmem_default");
  long bytes = 0;
  if (!(in >> bytes) || bytes < 65536) bytes = 212992;
  return static_cast<uint32_t>(bytes / 4);
}

std::vector<UdpSocketInfo> udp_sockets_on_port(const std::string& table, int port) {
  // "  sl  local_address rem_address   st tx_queue rx_queue tr tm->when retrnsmt   uid  timeout inode ..."
  std::vector<UdpSocketInfo> out;
  std::istringstream in(table);
  std::string line;
  std::getline(in, line);  // the header
  while (std::getline(in, line)) {
    std::istringstream f(line);
    std::string sl, local, remote, st, queues, tr, retr, uid, timeout;
    uint64_t inode = 0;
    if (!(f >> sl >> local >> remote >> st >> queues >> tr >> retr >> uid >> timeout >> inode)) continue;
    std::string ref, pointer;
    uint64_t drops = 0;
    f >> ref >> pointer >> drops;  // drops, the last column, is absent on old kernels
    const auto colon = local.find(':');
    const auto qcolon = queues.find(':');
    if (colon == std::string::npos || qcolon == std::string::npos) continue;
    try {
      if (std::stoi(local.substr(colon + 1), nullptr, 16) != port) continue;
      out.push_back(
          {inode, static_cast<uint32_t>(std::stoul(queues.substr(qcolon + 1), nullptr, 16)), drops});
    } catch (const std::exception&) {
    }
  }
  return out;
}

BusListeners::BusListeners(int port, std::string own_exe_dir, double max_hold_s, double rescan_s,
                           std::string proc)
    : port_(port),
      own_exe_dir_(std::move(own_exe_dir)),
      max_hold_s_(max_hold_s),
      rescan_s_(rescan_s),
      proc_(std::move(proc)) {}

void BusListeners::rescan() {
  foreign_inodes_.clear();
  pids_.clear();
  if (inodes_.empty()) return;
  const pid_t self = getpid();
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(proc_, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || !std::all_of(name.begin(), name.end(), ::isdigit)) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(name));
    if (pid == self) continue;
    std::vector<uint64_t> found;
    std::error_code fe;
    for (const auto& fd : fs::directory_iterator(entry.path() / "fd", fe)) {
      std::error_code le;
      const std::string target = fs::read_symlink(fd.path(), le).string();
      if (le || target.rfind("socket:[", 0) != 0) continue;
      const uint64_t inode = std::strtoull(target.c_str() + 8, nullptr, 10);
      if (inodes_.count(inode)) found.push_back(inode);
    }
    if (found.empty()) continue;
    std::error_code xe;
    const fs::path exe = fs::read_symlink(entry.path() / "exe", xe);
    if (!xe && exe.parent_path() == fs::path(own_exe_dir_)) continue;
    pids_.push_back(pid);
    foreign_inodes_.insert(found.begin(), found.end());
  }
}

std::vector<UdpSocketInfo> BusListeners::refresh(double wall_s, bool* read) {
  std::vector<UdpSocketInfo> sockets;
  *read = false;
  if (wall_s >= next_scan_s_) {
    sockets = udp_sockets_on_port(read_text(proc_ + "/net/udp"), port_);
    *read = true;
    std::set<uint64_t> now;
    for (const auto& s : sockets) now.insert(s.inode);
    if (now != inodes_) {
      inodes_ = std::move(now);
      rescan();
    }
    next_scan_s_ = wall_s + rescan_s_;
  }
  return sockets;
}

bool BusListeners::hold(double wall_s, bool behind) {
  if (!behind) {
    holding_since_s_ = -1;
    return true;
  }
  ++holds_;
  if (holding_since_s_ < 0) holding_since_s_ = wall_s;
  if (wall_s - holding_since_s_ >= max_hold_s_) {
    ++gave_up_;
    holding_since_s_ = -1;
    return true;
  }
  return false;
}

bool BusListeners::has_room(double wall_s, uint32_t max_queued) {
  bool read = false;
  auto sockets = refresh(wall_s, &read);
  if (pids_.empty()) return true;
  if (!read) sockets = udp_sockets_on_port(read_text(proc_ + "/net/udp"), port_);
  bool behind = false;
  for (const auto& s : sockets) behind |= foreign_inodes_.count(s.inode) && s.rx_queue >= max_queued;
  return hold(wall_s, behind);
}

bool BusListeners::caught_up(double wall_s) {
  bool read = false;
  auto sockets = refresh(wall_s, &read);
  if (pids_.empty()) return true;
  if (!read) sockets = udp_sockets_on_port(read_text(proc_ + "/net/udp"), port_);
  bool behind = false;
  for (const auto& s : sockets) behind |= foreign_inodes_.count(s.inode) && s.rx_queue > 0;
  for (pid_t pid : pids_) {
    if (behind) break;
    std::error_code ec;
    for (const auto& task : fs::directory_iterator(proc_ + "/" + std::to_string(pid) + "/task", ec)) {
      // "pid (comm) S ...": the state follows the last ')'.
      const std::string stat = read_text((task.path() / "stat").string());
      const auto paren = stat.rfind(')');
      if (paren != std::string::npos && paren + 2 < stat.size() && stat[paren + 2] == 'R') {
        behind = true;
        break;
      }
    }
  }
  return hold(wall_s, behind);
}

}  // namespace semx::runtime
