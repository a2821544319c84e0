#include "ros_side.hpp"

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>
#include <tf2_msgs/TFMessage.h>

#include <array>
#include <chrono>
#include <deque>
#include <iostream>
#include <optional>

#include "ros_messages.hpp"
#include "semx/ros/camera_conversion.hpp"
#include "semx/ros/odometry_conversion.hpp"

namespace semx::rosbridge {

namespace {

using Clock = std::chrono::steady_clock;

bool is_frame(OutTopic t) { return t == OutTopic::kDepth || t == OutTopic::kLabels || t == OutTopic::kRgb; }
bool keeps_newest(OutTopic t) {
  return t == OutTopic::kMap || t == OutTopic::kMapFree || t == OutTopic::kEsdf || t == OutTopic::kRoadmap ||
         t == OutTopic::kRegions;
}

// Topics whose last message a late subscriber (rviz started after the run, or everyone after the
// master was replaced) should still get.
bool latched(OutTopic t) {
  return t == OutTopic::kMap || t == OutTopic::kRoadmap || t == OutTopic::kRegions || t == OutTopic::kPath ||
         t == OutTopic::kTrajectory || t == OutTopic::kStatus;
}

}  // namespace

// roscpp's objects. `handles` is rebuilt on every (re)connection; the rest lives as long as the
// thread.
struct RosSide::Ros {
  struct Handles {
    std::unique_ptr<::ros::NodeHandle> nh;
    std::array<::ros::Publisher, static_cast<int>(OutTopic::kCount)> pub;
    std::array<::ros::Publisher, 3> info;  // depth, labels, rgb CameraInfo
    ::ros::Publisher tf, tf_static, clock;
    std::vector<::ros::Subscriber> subs;
  };
  struct Pending {
    msg::Image image;
    bool labels = false;
    Clock::time_point since;
  };

  ::ros::CallbackQueue queue;
  Handles h;
  tf2::BufferCore tf_buffer{::ros::Duration(30.0)};
  std::optional<msg::CameraInfo> camera_info;
  std::deque<Pending> pending;
  std::map<OutTopic, OutItem> last_latched;  // re-sent after a reconnection
  bool resend_latched = false;
  std::map<int64_t, int64_t> frame_ids;  // image stamp -> semx frame id (depth and labels pair up)
  int64_t next_frame_id = 1;
  PoseDifferentiator differentiator;
  TimeBase time;
};

RosSide::RosSide(const BridgeConfig& config)
    : config_(config),
      frames_(static_cast<std::size_t>(config.queue_frames)),
      messages_(static_cast<std::size_t>(config.queue_messages)),
      inputs_(static_cast<std::size_t>(config.queue_messages)) {
  // Plans and status are cheap and latched: always converted, so a late viewer sees the last.
  for (OutTopic t : {OutTopic::kRoadmap, OutTopic::kRegions, OutTopic::kPath, OutTopic::kTrajectory,
                     OutTopic::kStatus, OutTopic::kVelocitySetpoint, OutTopic::kPositionSetpoint}) {
    wanted_[static_cast<int>(t)] = true;
  }
}

RosSide::~RosSide() { stop(); }

void RosSide::start() {
  if (thread_.joinable()) return;
  stop_ = false;
  thread_ = std::thread([this] { run(); });
}

void RosSide::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void RosSide::send(OutItem item) {
  if (is_frame(item.topic)) {
    frames_.push(std::move(item));
  } else if (keeps_newest(item.topic)) {
    std::lock_guard<std::mutex> lock(mutex_);
    latest_[item.topic] = std::move(item);
  } else {
    messages_.push(std::move(item));
  }
}

void RosSide::send_transform(msg::TransformStamped t) { messages_.push(OutItem{OutTopic::kCount, std::move(t)}); }

void RosSide::set_static_transform(msg::TransformStamped t) {
  std::lock_guard<std::mutex> lock(mutex_);
  statics_[t.child_frame_id] = std::move(t);
  statics_changed_ = true;
}

void RosSide::set_clock(int64_t ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  clock_ns_ = ns;
}

std::vector<InItem> RosSide::take_inputs() { return inputs_.take_all(); }

int64_t RosSide::sensor_time_ns(double max_ahead_s) const {
  const int64_t stamp = newest_stamp_ns_.load();
  if (stamp <= 0) return 0;
  const int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
  const int64_t ahead = std::min<int64_t>(now - newest_wall_ns_.load(), static_cast<int64_t>(max_ahead_s * 1e9));
  return stamp + std::max<int64_t>(0, ahead);
}

RosCounters RosSide::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  RosCounters c = counters_;
  c.dropped += frames_.dropped() + messages_.dropped() + inputs_.dropped();
  return c;
}

void RosSide::problem(const std::string& why) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++counters_.rejected;
  if (counters_.last_problem != why) {
    std::cerr << "semx-ros-bridge: input refused: " << why << std::endl;
    counters_.last_problem = why;
  }
}

void RosSide::run() {
  const bool external = config_.mode == BridgeMode::kExternal;
  ::ros::M_string remappings;
  ::ros::init(remappings, config_.node_name,
              ::ros::init_options::NoSigintHandler | ::ros::init_options::NoRosout);
  ros_ = std::make_unique<Ros>();
  Ros& R = *ros_;
  bool started = false, registered = false;
  auto next_check = Clock::now();
  auto next_wanted = Clock::now();
  const auto check_period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(config_.master_check_s));

  auto note_stamp = [&](int64_t ns) {
    if (ns <= 0) return;
    if (!R.time.known() && R.time.adopt(ns)) {
      origin_ns_ = R.time.origin_ns();
      origin_known_ = true;
    }
    if (ns > newest_stamp_ns_.load()) {
      newest_stamp_ns_ = ns;
      newest_wall_ns_ = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
    }
  };
  auto push_input = [&](InItem item) {
    inputs_.push(std::move(item));
    std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.inputs;
  };
  // An image waits here until the camera's transform at its stamp is known.
  auto try_image = [&](Ros::Pending& p) -> bool {
    if (!R.camera_info) return false;
    std::string error;
    const ::ros::Time stamp = to_ros_time(p.image.header.stamp_ns);
    if (!R.tf_buffer.canTransform(config_.frames.map, p.image.header.frame_id, stamp, &error)) return false;
    CameraShot shot;
    if (std::string why = camera_from_ros(*R.camera_info, config_.in.min_range, config_.in.max_range, shot.camera);
        !why.empty()) {
      problem(why);
      return true;
    }
    if (!R.time.to_utime(p.image.header.stamp_ns, shot.utime)) {
      problem("image stamp before the time origin");
      return true;
    }
    const geometry_msgs::TransformStamped T =
        R.tf_buffer.lookupTransform(config_.frames.map, p.image.header.frame_id, stamp);
    shot.T_world_optical.setIdentity();
    shot.T_world_optical.translation() =
        Eigen::Vector3d(T.transform.translation.x, T.transform.translation.y, T.transform.translation.z);
    shot.T_world_optical.linear() = Eigen::Quaterniond(T.transform.rotation.w, T.transform.rotation.x,
                                                       T.transform.rotation.y, T.transform.rotation.z)
                                        .normalized()
                                        .toRotationMatrix();
    auto [it, fresh] = R.frame_ids.emplace(p.image.header.stamp_ns, R.next_frame_id);
    if (fresh) ++R.next_frame_id;
    shot.frame_id = it->second;
    while (R.frame_ids.size() > 64) R.frame_ids.erase(R.frame_ids.begin());
    if (p.labels) {
      LabelFrame f;
      if (std::string why = from_ros(p.image, shot, f); !why.empty()) {
        problem(why);
      } else {
        push_input(std::move(f));
      }
    } else {
      DepthFrame f;
      if (std::string why = from_ros(p.image, shot, f); !why.empty()) {
        problem(why);
      } else {
        push_input(std::move(f));
      }
    }
    return true;
  };

  auto connect = [&]() {
    R.h = Ros::Handles();  // unadvertise and unsubscribe what the last master knew
    if (!external && config_.publish_clock) ::ros::param::set("/use_sim_time", true);
    if (!started) {
      ::ros::start();
      started = true;
    }
    R.h.nh = std::make_unique<::ros::NodeHandle>();
    ::ros::NodeHandle& nh = *R.h.nh;
    nh.setCallbackQueue(&R.queue);
    auto& pub = R.h.pub;
    auto idx = [](OutTopic t) { return static_cast<int>(t); };
    const OutputTopics& o = config_.out;
    if (!external) {
      pub[idx(OutTopic::kOdom)] = nh.advertise<nav_msgs::Odometry>(o.odom, 100);
      if (config_.camera) {
        pub[idx(OutTopic::kDepth)] = nh.advertise<sensor_msgs::Image>(o.depth, 5);
        pub[idx(OutTopic::kLabels)] = nh.advertise<sensor_msgs::Image>(o.labels, 5);
        pub[idx(OutTopic::kRgb)] = nh.advertise<sensor_msgs::Image>(o.rgb, 5);
        R.h.info[0] = nh.advertise<sensor_msgs::CameraInfo>(o.depth_info, 5);
        R.h.info[1] = nh.advertise<sensor_msgs::CameraInfo>(o.labels_info, 5);
        R.h.info[2] = nh.advertise<sensor_msgs::CameraInfo>(o.rgb_info, 5);
      }
      if (config_.publish_clock) R.h.clock = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
    }
    if (!external || config_.in.publish_body_tf) R.h.tf = nh.advertise<tf2_msgs::TFMessage>("/tf", 100);
    R.h.tf_static = nh.advertise<tf2_msgs::TFMessage>("/tf_static", 10, true);
    pub[idx(OutTopic::kMap)] = nh.advertise<sensor_msgs::PointCloud2>(o.map, 1, true);
    pub[idx(OutTopic::kMapFree)] = nh.advertise<sensor_msgs::PointCloud2>(o.map_free, 1);
    pub[idx(OutTopic::kEsdf)] = nh.advertise<sensor_msgs::PointCloud2>(o.esdf_slice, 1);
    pub[idx(OutTopic::kRoadmap)] = nh.advertise<visualization_msgs::MarkerArray>(o.roadmap, 1, true);
    pub[idx(OutTopic::kRegions)] = nh.advertise<visualization_msgs::MarkerArray>(o.regions, 1, true);
    pub[idx(OutTopic::kPath)] = nh.advertise<nav_msgs::Path>(o.path, 5, true);
    pub[idx(OutTopic::kTrajectory)] = nh.advertise<nav_msgs::Path>(o.trajectory, 5, true);
    pub[idx(OutTopic::kStatus)] = nh.advertise<diagnostic_msgs::DiagnosticArray>(o.planner_status, 5, true);
    if (external) {
      const std::string& mode = config_.setpoints.mode;
      if (mode == "velocity" || mode == "both") {
        pub[idx(OutTopic::kVelocitySetpoint)] =
            nh.advertise<geometry_msgs::TwistStamped>(config_.setpoints.velocity_topic, 10);
      }
      if (mode == "position" || mode == "both") {
        pub[idx(OutTopic::kPositionSetpoint)] =
            nh.advertise<geometry_msgs::PoseStamped>(config_.setpoints.position_topic, 10);
      }
      const InputTopics& in = config_.in;
      auto on_odometry = [&, this](const msg::Odometry& m) {
        note_stamp(m.header.stamp_ns);
        VehicleOdometry o;
        if (std::string why = from_ros(m, R.time, o); !why.empty()) return problem("odometry: " + why);
        push_input(o);
        if (config_.in.publish_body_tf && R.h.tf) {
          tf2_msgs::TFMessage tf;
          tf.transforms.push_back(to_ros_msg(body_transform(o, config_.frames, R.time)));
          R.h.tf.publish(tf);
        }
      };
      if (in.odom_type == "pose") {
        R.h.subs.push_back(nh.subscribe<geometry_msgs::PoseStamped>(
            in.odom, 50, [&, on_odometry](const geometry_msgs::PoseStamped::ConstPtr& m) {
              const msg::PoseStamped p = from_ros_msg(*m);
              note_stamp(p.header.stamp_ns);
              VehicleOdometry o;
              if (std::string why = R.differentiator.convert(p, R.time, o); !why.empty()) {
                return problem("pose: " + why);
              }
              push_input(o);
            }));
      } else {
        R.h.subs.push_back(nh.subscribe<nav_msgs::Odometry>(
            in.odom, 50, [on_odometry](const nav_msgs::Odometry::ConstPtr& m) { on_odometry(from_ros_msg(*m)); }));
      }
      R.h.subs.push_back(nh.subscribe<sensor_msgs::CameraInfo>(
          in.camera_info, 5, [&](const sensor_msgs::CameraInfo::ConstPtr& m) { R.camera_info = from_ros_msg(*m); }));
      auto image_sub = [&](const std::string& topic, bool labels) {
        R.h.subs.push_back(nh.subscribe<sensor_msgs::Image>(
            topic, 10, [&, labels](const sensor_msgs::Image::ConstPtr& m) {
              Ros::Pending p{from_ros_msg(*m), labels, Clock::now()};
              note_stamp(p.image.header.stamp_ns);
              R.pending.push_back(std::move(p));
              while (R.pending.size() > 2 * static_cast<std::size_t>(config_.queue_frames)) {
                R.pending.pop_front();
                std::lock_guard<std::mutex> lock(mutex_);
                ++counters_.tf_missing;
              }
            }));
      };
      image_sub(in.depth, false);
      if (!in.labels.empty()) image_sub(in.labels, true);
      auto on_tf = [&](const tf2_msgs::TFMessage::ConstPtr& m, bool is_static) {
        for (const auto& t : m->transforms) {
          try {
            R.tf_buffer.setTransform(t, "ros", is_static);
          } catch (const tf2::TransformException&) {
            // A malformed transform (empty frame, NaN) is tf2's to refuse; the rest goes on.
          }
        }
      };
      R.h.subs.push_back(nh.subscribe<tf2_msgs::TFMessage>(
          "/tf", 200, [on_tf](const tf2_msgs::TFMessage::ConstPtr& m) { on_tf(m, false); }));
      R.h.subs.push_back(nh.subscribe<tf2_msgs::TFMessage>(
          "/tf_static", 20, [on_tf](const tf2_msgs::TFMessage::ConstPtr& m) { on_tf(m, true); }));
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      statics_changed_ = true;  // the new master's subscribers need them
      ++counters_.connects;
    }
    R.resend_latched = true;
    registered = true;
    connected_ = true;
    std::cerr << "semx-ros-bridge: registered with the ROS master " << ::ros::master::getURI() << std::endl;
  };

  auto publish = [&](OutItem& item) {
    Ros::Handles& h = R.h;
    if (item.topic == OutTopic::kCount) {  // a /tf transform
      if (!h.tf) return false;
      tf2_msgs::TFMessage tf;
      tf.transforms.push_back(to_ros_msg(std::get<msg::TransformStamped>(item.payload)));
      h.tf.publish(tf);
      return true;
    }
    ::ros::Publisher& p = h.pub[static_cast<int>(item.topic)];
    if (!p) return false;
    std::visit(
        [&](auto& m) {
          using T = std::decay_t<decltype(m)>;
          if constexpr (std::is_same_v<T, ImagePair>) {
            p.publish(to_ros_msg(m.image));
            const int i = item.topic == OutTopic::kDepth ? 0 : item.topic == OutTopic::kLabels ? 1 : 2;
            if (h.info[i]) h.info[i].publish(to_ros_msg(m.info));
          } else {
            p.publish(to_ros_msg(m));
          }
        },
        item.payload);
    return true;
  };

  while (!stop_) {
    const auto wall = Clock::now();
    if (wall >= next_check) {
      next_check = wall + check_period;
      const bool up = ::ros::master::check();
      if (up && !registered) {
        connect();
      } else if (!up && registered) {
        registered = false;
        connected_ = false;
        std::cerr << "semx-ros-bridge: the ROS master does not answer; reconnecting when it does" << std::endl;
      }
    }

    // Outgoing: images and messages in order, the newest of the rest, the clock, statics.
    std::vector<OutItem> items = messages_.take_all(std::chrono::milliseconds(started ? 5 : 20));
    for (auto& f : frames_.take_all()) items.push_back(std::move(f));
    std::vector<msg::TransformStamped> statics;
    int64_t clock_ns = -1;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (auto& [topic, item] : latest_) items.push_back(std::move(item));
      latest_.clear();
      std::swap(clock_ns, clock_ns_);
      if (statics_changed_ && registered) {
        for (const auto& [child, t] : statics_) statics.push_back(t);
        statics_changed_ = false;
      }
    }
    int64_t published = 0, dropped = 0;
    if (started) {
      if (clock_ns >= 0 && R.h.clock) {
        rosgraph_msgs::Clock c;
        c.clock = to_ros_time(clock_ns);
        R.h.clock.publish(c);
      }
      if (!statics.empty() && R.h.tf_static) {
        tf2_msgs::TFMessage tf;
        for (const auto& t : statics) tf.transforms.push_back(to_ros_msg(t));
        R.h.tf_static.publish(tf);
      }
      if (R.resend_latched && registered) {
        R.resend_latched = false;
        for (auto& [topic, item] : R.last_latched) publish(item);
      }
      for (auto& item : items) {
        (publish(item) ? published : dropped) += 1;
        if (latched(item.topic)) R.last_latched[item.topic] = std::move(item);
      }
    } else {
      dropped = static_cast<int64_t>(items.size());
    }
    if (published || dropped) {
      std::lock_guard<std::mutex> lock(mutex_);
      counters_.published += published;
      counters_.dropped += dropped;
    }

    if (started) {
      R.queue.callAvailable(::ros::WallDuration(0.0));
      for (auto it = R.pending.begin(); it != R.pending.end();) {
        bool done = false;
        try {
          done = try_image(*it);
        } catch (const tf2::TransformException& e) {
          problem(std::string("camera transform: ") + e.what());
          done = true;
        }
        if (!done && Clock::now() - it->since > std::chrono::duration<double>(config_.in.tf_timeout_s)) {
          std::lock_guard<std::mutex> lock(mutex_);
          ++counters_.tf_missing;
          if (counters_.last_problem != "no camera transform") {
            std::cerr << "semx-ros-bridge: image dropped: no transform " << config_.frames.map << " <- "
                      << it->image.header.frame_id << " at its stamp (or no CameraInfo) within "
                      << config_.in.tf_timeout_s << " s" << std::endl;
            counters_.last_problem = "no camera transform";
          }
          done = true;
        }
        it = done ? R.pending.erase(it) : std::next(it);
      }
      if (wall >= next_wanted && registered) {
        next_wanted = wall + std::chrono::milliseconds(200);
        for (OutTopic t : {OutTopic::kOdom, OutTopic::kDepth, OutTopic::kLabels, OutTopic::kRgb, OutTopic::kMap,
                           OutTopic::kMapFree, OutTopic::kEsdf}) {
          const ::ros::Publisher& p = R.h.pub[static_cast<int>(t)];
          wanted_[static_cast<int>(t)] = p && p.getNumSubscribers() > 0;
        }
      }
    }
  }
  connected_ = false;
  ros_.reset();
  if (started) ::ros::shutdown();
}

}  // namespace semx::rosbridge
