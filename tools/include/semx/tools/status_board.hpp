// What semx-monitor shows: the latest NODE_STATUS of every node and the traffic per channel.
// Logic only (fed decoded statuses and raw message sizes), so it is tested without a network.
#pragma once

#include <semx/node_status_t.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace semx::tools {

class StatusBoard {
 public:
  struct NodeRow {
    semx::node_status_t status;
    double last_seen_s = 0;  // wall seconds
    double prev_cpu_s = 0;
    double prev_seen_s = -1;
    double cpu_percent = 0;
  };
  struct ChannelRow {
    int64_t messages = 0;
    int64_t bytes = 0;
    int64_t malformed = 0;  // failed validation against the channel's type
    // For rates: counts at the previous report.
    int64_t window_messages = 0;
    int64_t window_bytes = 0;
    double hz = 0;
    double kbps = 0;
  };

  void on_status(const semx::node_status_t& s, double wall_s);
  void on_message(const std::string& channel, std::size_t bytes, bool malformed);
  // Closes a rate window (call once per report).
  void update_rates(double wall_s);

  // Nodes named in `names` that have reported and are not failed or stopping.
  std::vector<std::string> missing(const std::vector<std::string>& names) const;

  std::string render_nodes(double wall_s) const;
  std::string render_channels() const;

  const std::map<std::string, NodeRow>& nodes() const { return nodes_; }
  const std::map<std::string, ChannelRow>& channels() const { return channels_; }

 private:
  std::map<std::string, NodeRow> nodes_;
  std::map<std::string, ChannelRow> channels_;
  double window_start_s_ = -1;
};

}  // namespace semx::tools
