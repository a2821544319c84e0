// The bridge's ROS side: roscpp on a thread of its own, fed and drained through bounded queues,
// so nothing ROS does (a slow subscriber, a master that is gone, roscpp's blocking calls to the
// master) ever holds up the LCM side, whose node keeps the set's time.
//
// The thread connects when the master answers (ros::master::check every master_check_s),
// advertises and subscribes, and publishes what the LCM side queued. When the master goes away
// it keeps its existing connections (peers keep receiving) and drops nothing on purpose; when a
// master answers again (the same or a new one) it advertises and subscribes anew and re-sends its
// static transforms and parameters, because a roscpp node does not re-register by itself.
// Queues: images (per capacity queue_frames), other messages (queue_messages) drop their oldest;
// the map, ESDF slice, roadmap, regions and /clock keep only their newest.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <variant>
#include <vector>

#include "semx/ros/bounded_queue.hpp"
#include "semx/ros/bridge_config.hpp"
#include "semx/ros/bridge_values.hpp"
#include "semx/ros/ros_types.hpp"

namespace semx::rosbridge {

enum class OutTopic : int {
  kOdom,
  kDepth,
  kLabels,
  kRgb,
  kMap,
  kMapFree,
  kEsdf,
  kRoadmap,
  kRegions,
  kPath,
  kTrajectory,
  kStatus,
  kVelocitySetpoint,
  kPositionSetpoint,
  kCount
};

struct ImagePair {
  msg::Image image;
  msg::CameraInfo info;
};
using OutPayload = std::variant<msg::Odometry, ImagePair, msg::PointCloud2, msg::MarkerArray, msg::Path,
                                msg::DiagnosticArray, msg::TwistStamped, msg::PoseStamped, msg::TransformStamped>;
struct OutItem {
  OutTopic topic = OutTopic::kOdom;
  OutPayload payload;
};
// A transform for /tf travels as an OutItem whose topic is ignored.
using InItem = std::variant<VehicleOdometry, DepthFrame, LabelFrame>;

struct RosCounters {
  int64_t published = 0;     // messages handed to roscpp
  int64_t dropped = 0;       // queued messages dropped (full queue, or no ROS yet)
  int64_t connects = 0;      // times the thread (re)registered with a master
  int64_t inputs = 0;        // external: ROS messages turned into semx inputs
  int64_t rejected = 0;      // external: ROS messages refused (encoding, size, stamp, values)
  int64_t tf_missing = 0;    // external: images dropped for want of the camera's transform
  std::string last_problem;  // why the last input was refused
};

class RosSide {
 public:
  explicit RosSide(const BridgeConfig& config);
  ~RosSide();
  RosSide(const RosSide&) = delete;
  RosSide& operator=(const RosSide&) = delete;

  void start();
  void stop();

  // ---- from the LCM thread: never blocks ----
  void send(OutItem item);
  void send_transform(msg::TransformStamped t);    // /tf
  void set_static_transform(msg::TransformStamped t);  // /tf_static, kept and re-sent on reconnect
  void set_clock(int64_t ns);                      // /clock (mirror), newest only
  std::vector<InItem> take_inputs();
  // Someone subscribes to the topic (a viewer, a bag recorder): worth converting for.
  bool wants(OutTopic t) const { return wanted_[static_cast<int>(t)].load(std::memory_order_relaxed); }
  bool connected() const { return connected_.load(); }
  // External: the sensors' time: the newest stamp received (0 before any), advanced by the wall
  // time since it arrived, at most `max_ahead_s` (so the set's clock runs in real time between
  // sensor messages and stops with them). The time base's origin is fixed by the first stamp.
  int64_t sensor_time_ns(double max_ahead_s) const;
  bool time_known() const { return origin_known_.load(); }
  TimeBase time() const { return time_known() ? TimeBase(origin_ns_.load()) : TimeBase(); }
  RosCounters counters() const;

 private:
  struct Ros;  // roscpp's objects, only on the thread
  void run();
  void problem(const std::string& why);

  BridgeConfig config_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> connected_{false};
  std::atomic<int64_t> newest_stamp_ns_{0};
  std::atomic<int64_t> newest_wall_ns_{0};  // steady clock when it arrived
  std::atomic<bool> origin_known_{false};
  std::atomic<int64_t> origin_ns_{0};
  std::atomic<bool> wanted_[static_cast<int>(OutTopic::kCount)] = {};

  BoundedQueue<OutItem> frames_;
  BoundedQueue<OutItem> messages_;
  BoundedQueue<InItem> inputs_;
  mutable std::mutex mutex_;  // latest_, statics_, clock_ns_, counters_
  std::map<OutTopic, OutItem> latest_;
  std::map<std::string, msg::TransformStamped> statics_;  // by child frame
  bool statics_changed_ = false;
  int64_t clock_ns_ = -1;
  RosCounters counters_;
  std::unique_ptr<Ros> ros_;
};

}  // namespace semx::rosbridge
