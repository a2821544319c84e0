// semx-viewer's LCM side: a TopDownView fed from the bus. A MapClient keeps the map (deltas,
// snapshots on gaps); ODOMETRY, ROADMAP, SEMANTIC_REGIONS, PLAN_PATH, TRAJECTORY and PLANNER_STATUS update
// the overlays; a frame is drawn once per `period_s` of message time and written as
// out_dir/frame_NNNNNN.png (N = the frame's index, message time / period) and/or handed to
// `on_frame` (the window).
//
// Time (docs/viewer.md): with a SIM_CLOCK, frames are drawn in the tick handler, after the map
// client applied what it held for the tick; a lockstep viewer (--lockstep) therefore draws the
// same pictures every run. Without a clock (a log of some channels, a test) each message's utime
// is the time, and a frame that falls due is drawn before the message that made it due is
// applied, so frame k shows everything stamped before k·period. Either way a log played into the
// viewer gives the pictures of the run it recorded.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "map_client.hpp"
#include "semx/evaluator/rgb.hpp"
#include "semx/runtime/node.hpp"
#include "semx/viewer/top_down_view.hpp"

namespace semx::viewer {

struct ViewerNodeOptions {
  TopDownViewOptions view;
  std::optional<simulator::World> world;  // walls drawn faintly, area and heights from it
  std::string out_dir;                    // "" writes no PNGs
  double period_s = 1.0;                  // message time between frames
  // Called with every frame drawn (the window), and its index (-1 for the final one).
  std::function<void(const evaluator::Image&, int64_t index)> on_frame;
  bool print = true;              // one line per written frame every 10 frames, and errors
  double max_time_jump_s = 3600;  // a message stamped further ahead does not move the time
};

class ViewerNode {
 public:
  // `node` must outlive this object. Creates out_dir (throws std::runtime_error if it cannot).
  ViewerNode(runtime::Node& node, ViewerNodeOptions options);
  ViewerNode(const ViewerNode&) = delete;
  ViewerNode& operator=(const ViewerNode&) = delete;

  // Spins until a signal, node.stop(), `idle` returning false (called between spins: the
  // window's events) or the end of a file:// log; then draws final.png. Returns 0, or 1 when the
  // LCM provider failed.
  int run(const std::function<bool()>& idle = nullptr);

  // Draws frame `index` of the current state now (index < 0: final.png).
  void draw_frame(int64_t index);

  int64_t frames_drawn() const { return frames_; }
  int64_t write_errors() const { return write_errors_; }
  const std::string& last_file() const { return last_file_; }
  int64_t now_utime() const { return time_; }
  const TopDownView& view() const { return view_; }
  const map::MapClient& map() const { return *map_; }

 private:
  // The time of a message (without a clock): draws the frame it makes due, then moves the time.
  void message_time(int64_t utime);
  void on_tick(int64_t tick, int64_t utime);
  void maybe_draw(int64_t utime);

  runtime::Node& node_;
  ViewerNodeOptions options_;
  TopDownView view_;
  FrameSchedule schedule_;
  std::unique_ptr<map::MapClient> map_;
  int64_t time_ = -1;
  int64_t last_tick_ = -1;
  int64_t frames_ = 0;
  int64_t write_errors_ = 0;
  bool degraded_ = false;
  std::string last_file_;
};

}  // namespace semx::viewer
