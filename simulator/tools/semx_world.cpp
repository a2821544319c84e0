// semx-world: look at, generate and check world files.
//   semx-world render WORLD [--pose x y z yaw_deg] [--out DIR] [--far M]
//   semx-world gen --seed N --area A [--rooms R] --out FILE
//   semx-world check WORLD [--resolution R]
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "semx/core/random.hpp"
#include "semx/simulator/ground_truth.hpp"
#include "semx/simulator/quadrotor.hpp"
#include "semx/simulator/rasterizer.hpp"
#include "semx/simulator/world.hpp"
#include "semx/simulator/world_generator.hpp"

namespace sim = semx::simulator;

namespace {

const char* kUsage =
    "usage: semx-world <command> [options]\n"
    "\n"
    "commands:\n"
    "  render WORLD [--pose X Y Z YAW_DEG] [--out DIR] [--far M]\n"
    "      Renders the camera (640x480, fx=fy=320) from the pose (default: the world's start) and\n"
    "      writes DIR/depth.png (16-bit mm), depth_color.png, rgb.png, class.png, instance.png and\n"
    "      topdown.png (plan view with labelled objects and the camera). DIR defaults to '.'.\n"
    "      --far sets how far the RGB image shows surfaces (default 20 m; depth stops at 5 m).\n"
    "  gen --seed N --area A [--rooms R] --out FILE\n"
    "      Writes a random furnished apartment of about A m² with R rooms (default A/25).\n"
    "  check WORLD [--resolution R]\n"
    "      Validates a world file and prints its area and ground-truth set sizes (R default 0.1 m).\n"
    "\n"
    "WORLD is a file path or the name of a shipped world (env1, env2, env3).\n";

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

double parse_number(const std::string& flag, const std::string& s) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v))
    throw UsageError(flag + ": '" + s + "' is not a number");
  return v;
}

long parse_integer(const std::string& flag, const std::string& s) {
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0') throw UsageError(flag + ": '" + s + "' is not an integer");
  return v;
}

// Splits arguments into positionals and --flags with their values.
struct Args {
  std::vector<std::string> positional;
  std::map<std::string, std::vector<std::string>> flags;
};

Args parse_args(int argc, char** argv, int first, const std::map<std::string, int>& arity) {
  Args a;
  for (int i = first; i < argc; ++i) {
    const std::string s = argv[i];
    if (s.rfind("--", 0) == 0) {
      const auto it = arity.find(s);
      if (it == arity.end()) throw UsageError("unknown option " + s);
      if (a.flags.count(s)) throw UsageError(s + " given twice");
      std::vector<std::string> vals;
      for (int k = 0; k < it->second; ++k) {
        if (i + 1 >= argc) throw UsageError(s + " needs " + std::to_string(it->second) + " value(s)");
        vals.push_back(argv[++i]);
      }
      a.flags[s] = vals;
    } else {
      a.positional.push_back(s);
    }
  }
  return a;
}

cv::Scalar bgr(const sim::Rgb& c) { return cv::Scalar(c.b, c.g, c.r); }

sim::Rgb instance_color(uint16_t id) {
  if (id == 0) return {0, 0, 0};
  const uint64_t h = semx::core::mix_seed(id);
  return {static_cast<uint8_t>(60 + (h & 0xFF) % 196), static_cast<uint8_t>(60 + ((h >> 8) & 0xFF) % 196),
          static_cast<uint8_t>(60 + ((h >> 16) & 0xFF) % 196)};
}

void ensure_dir(const std::string& dir) {
  struct stat st {};
  if (stat(dir.c_str(), &st) == 0) {
    if (!S_ISDIR(st.st_mode)) throw std::runtime_error(dir + ": exists and is not a directory");
    return;
  }
  if (mkdir(dir.c_str(), 0755) != 0) throw std::runtime_error(dir + ": cannot create directory");
}

void write_png(const std::string& path, const cv::Mat& m) {
  if (!cv::imwrite(path, m)) throw std::runtime_error(path + ": cannot write PNG");
  std::cout << "wrote " << path << "\n";
}

// Plan view: solids by descending top height hidden under taller ones, objects labelled.
cv::Mat top_down(const sim::World& w, const Eigen::Isometry3d* camera_pose, double hfov) {
  const double ppm = 60.0;  // pixels per metre
  const int margin = 30;
  const Eigen::Vector3d size = w.bounds.size();
  const int width = static_cast<int>(size.x() * ppm) + 2 * margin;
  const int height = static_cast<int>(size.y() * ppm) + 2 * margin + 24;
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  auto px = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround(margin + (x - w.bounds.min.x()) * ppm)),
                     static_cast<int>(std::lround(margin + (w.bounds.max.y() - y) * ppm)));
  };
  std::vector<size_t> order;
  for (size_t i = 0; i < w.solids.size(); ++i) {
    const auto c = w.solids[i].cls;
    if (c != sim::SemanticClass::kCeiling) order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return w.solids[a].z_max() < w.solids[b].z_max(); });
  for (size_t i : order) {
    const sim::Solid& s = w.solids[i];
    const sim::Rgb color = s.cls == sim::SemanticClass::kFloor ? sim::Rgb{235, 228, 215} : s.color;
    if (s.shape == sim::Shape::kCylinder) {
      cv::circle(img, px(s.center.x(), s.center.y()), static_cast<int>(s.radius() * ppm), bgr(color),
                 cv::FILLED, cv::LINE_AA);
      cv::circle(img, px(s.center.x(), s.center.y()), static_cast<int>(s.radius() * ppm),
                 cv::Scalar(60, 60, 60), 1, cv::LINE_AA);
      continue;
    }
    const double c = std::cos(s.yaw), sn = std::sin(s.yaw);
    std::vector<cv::Point> poly;
    for (int k = 0; k < 4; ++k) {
      const double lx = (k == 0 || k == 3 ? -0.5 : 0.5) * s.size.x(), ly = (k < 2 ? -0.5 : 0.5) * s.size.y();
      poly.push_back(px(s.center.x() + c * lx - sn * ly, s.center.y() + sn * lx + c * ly));
    }
    cv::fillConvexPoly(img, poly, bgr(color), cv::LINE_AA);
    if (s.cls != sim::SemanticClass::kFloor) {
      cv::polylines(img, poly, true, cv::Scalar(60, 60, 60), 1, cv::LINE_AA);
    }
  }
  for (const auto& o : sim::list_objects(w)) {
    const std::string text =
        std::string(semx::runtime::class_info(o.cls).name) + "#" + std::to_string(o.instance);
    cv::putText(img, text, px(o.center.x() - 0.3, o.center.y()), cv::FONT_HERSHEY_SIMPLEX, 0.33,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  auto arrow = [&](const Eigen::Vector3d& p, double yaw, const cv::Scalar& col) {
    cv::circle(img, px(p.x(), p.y()), 5, col, cv::FILLED, cv::LINE_AA);
    cv::arrowedLine(img, px(p.x(), p.y()), px(p.x() + 0.6 * std::cos(yaw), p.y() + 0.6 * std::sin(yaw)), col,
                    2, cv::LINE_AA, 0, 0.3);
  };
  arrow(w.start.position, w.start.yaw, cv::Scalar(0, 160, 0));
  if (camera_pose) {
    const Eigen::Vector3d p = camera_pose->translation();
    const Eigen::Vector3d fwd = camera_pose->linear().col(2);
    const double yaw = std::atan2(fwd.y(), fwd.x());
    for (double s : {-0.5, 0.5}) {
      const double a = yaw + s * hfov;
      cv::line(img, px(p.x(), p.y()), px(p.x() + 5.0 * std::cos(a), p.y() + 5.0 * std::sin(a)),
               cv::Scalar(0, 0, 220), 1, cv::LINE_AA);
    }
    arrow(p, yaw, cv::Scalar(0, 0, 220));
  }
  const std::string title = (w.name.empty() ? std::string("world") : w.name) +
                            "  (green: start, red: camera; " + std::to_string(static_cast<int>(ppm)) +
                            " px/m)";
  cv::putText(img, title, cv::Point(margin, height - 10), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0),
              1, cv::LINE_AA);
  return img;
}

int cmd_render(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {{"--pose", 4}, {"--out", 1}, {"--far", 1}});
  if (a.positional.size() != 1) throw UsageError("render needs exactly one WORLD");
  const sim::World w = sim::load_world(sim::shipped_world_path(a.positional[0]));
  sim::VehicleState st;
  st.position = w.start.position;
  st.yaw = w.start.yaw;
  if (a.flags.count("--pose")) {
    const auto& v = a.flags.at("--pose");
    st.position = {parse_number("--pose", v[0]), parse_number("--pose", v[1]), parse_number("--pose", v[2])};
    st.yaw = parse_number("--pose", v[3]) * M_PI / 180.0;
  }
  const std::string dir = a.flags.count("--out") ? a.flags.at("--out")[0] : ".";
  sim::RasterizerOptions opt;
  opt.rgb_far = a.flags.count("--far") ? parse_number("--far", a.flags.at("--far")[0]) : 20.0;
  if (opt.rgb_far <= 0) throw UsageError("--far must be positive");
  ensure_dir(dir);

  sim::Rasterizer r(w, opt);
  semx::runtime::PinholeCamera cam;
  sim::CameraFrame f;
  const Eigen::Isometry3d pose = st.camera_pose();
  r.render(cam, pose, sim::kRenderAll, f);
  if (const int hit = sim::first_solid_hit_by_body(w, st.position, st.yaw); hit >= 0) {
    std::cerr << "warning: the vehicle body at this pose intersects solid " << hit << "\n";
  }

  cv::Mat depth(cam.height, cam.width, CV_16UC1, f.depth.data.data());
  write_png(dir + "/depth.png", depth);
  cv::Mat vis(cam.height, cam.width, CV_8UC1);
  cv::Mat invalid(cam.height, cam.width, CV_8UC1);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const uint16_t d = f.depth.at(u, v);
      const bool bad = d == semx::runtime::kDepthInvalid || d == semx::runtime::kDepthNoReturn;
      invalid.at<uint8_t>(v, u) = bad;
      vis.at<uint8_t>(v, u) =
          bad ? 0 : static_cast<uint8_t>(std::clamp(255.0 * d / (cam.max_range * 1000.0), 0.0, 255.0));
    }
  }
  cv::Mat depth_color;
  cv::applyColorMap(vis, depth_color, cv::COLORMAP_TURBO);
  depth_color.setTo(cv::Scalar(0, 0, 0), invalid);
  write_png(dir + "/depth_color.png", depth_color);

  cv::Mat rgb(cam.height, cam.width, CV_8UC3), cls(cam.height, cam.width, CV_8UC3),
      inst(cam.height, cam.width, CV_8UC3);
  std::map<uint16_t, int> class_pixels;
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const sim::Rgb c = f.rgb.at(u, v);
      rgb.at<cv::Vec3b>(v, u) = {c.b, c.g, c.r};
      const uint16_t k = f.class_label.at(u, v);
      ++class_pixels[k];
      const sim::Rgb kc = k ? sim::class_color(static_cast<sim::SemanticClass>(k)) : sim::Rgb{0, 0, 0};
      cls.at<cv::Vec3b>(v, u) = {kc.b, kc.g, kc.r};
      const sim::Rgb ic = instance_color(f.instance_label.at(u, v));
      inst.at<cv::Vec3b>(v, u) = {ic.b, ic.g, ic.r};
    }
  }
  write_png(dir + "/rgb.png", rgb);
  write_png(dir + "/class.png", cls);
  write_png(dir + "/instance.png", inst);
  write_png(dir + "/topdown.png", top_down(w, &pose, cam.horizontal_fov()));
  std::cout << "pose: " << st.position.transpose() << " yaw " << st.yaw * 180.0 / M_PI
            << " deg\nclasses seen:";
  for (const auto& [k, n] : class_pixels) {
    std::cout << " " << (k ? semx::runtime::class_info(static_cast<sim::SemanticClass>(k)).name : "none")
              << "=" << n;
  }
  std::cout << " (pixels)\n";
  return 0;
}

int cmd_gen(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {{"--seed", 1}, {"--area", 1}, {"--rooms", 1}, {"--out", 1}});
  if (!a.positional.empty()) throw UsageError("gen takes no positional arguments");
  for (const char* req : {"--seed", "--area", "--out"}) {
    if (!a.flags.count(req)) throw UsageError(std::string("gen needs ") + req);
  }
  sim::GeneratorOptions o;
  const long seed = parse_integer("--seed", a.flags.at("--seed")[0]);
  if (seed < 0) throw UsageError("--seed must be non-negative");
  o.seed = static_cast<uint64_t>(seed);
  o.area = parse_number("--area", a.flags.at("--area")[0]);
  if (a.flags.count("--rooms")) {
    const long r = parse_integer("--rooms", a.flags.at("--rooms")[0]);
    if (r < 1) throw UsageError("--rooms must be at least 1");
    o.rooms = static_cast<int>(r);
  }
  sim::GeneratedWorld g = sim::generate_world(o);
  const std::string out = a.flags.at("--out")[0];
  sim::save_world(g.world, out);
  std::cout << "wrote " << out << ": " << g.rooms.size() << " rooms, " << g.world.solids.size() << " solids, "
            << g.world.object_count() << " objects\n";
  return 0;
}

int cmd_check(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {{"--resolution", 1}});
  if (a.positional.size() != 1) throw UsageError("check needs exactly one WORLD");
  const double res =
      a.flags.count("--resolution") ? parse_number("--resolution", a.flags.at("--resolution")[0]) : 0.1;
  if (res < 0.02 || res > 1.0) throw UsageError("--resolution must be within [0.02, 1] m");
  const sim::World w = sim::load_world(sim::shipped_world_path(a.positional[0]));
  const sim::GroundTruth gt(w, res);
  const sim::VehicleReachability vr(gt, w.start.position);
  std::set<sim::SemanticClass> classes;
  for (const auto& o : gt.objects()) classes.insert(o.cls);
  const Eigen::Vector3d b = w.bounds.size();
  std::printf("world: %s (%s)\n", w.name.c_str(), w.source.c_str());
  std::printf("bounds: %.2f x %.2f x %.2f m\n", b.x(), b.y(), b.z());
  std::printf("solids: %zu\nobjects: %zu in %zu classes\n", w.solids.size(), gt.objects().size(),
              classes.size());
  std::printf("area: %.1f m2 (floor plan of the reachable space)\n", gt.reachable_area());
  std::printf("resolution: %.3f m\n", res);
  std::printf("occupied voxels: %zu\n", gt.occupied_count());
  std::printf("reachable free voxels: %zu\n", gt.reachable_free_count());
  std::printf("occupied voxels adjacent to reachable free: %zu\n", gt.occupied_in_target_count());
  std::printf("target set T: %zu voxels\n", gt.target_count());
  std::printf("vehicle-reachable voxel centres: %zu\n", vr.count());
  std::printf("ok\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h" ||
      std::string(argv[1]) == "help") {
    std::cout << kUsage;
    return argc < 2 ? 2 : 0;
  }
  const std::string cmd = argv[1];
  try {
    for (int i = 2; i < argc; ++i) {
      if (std::string(argv[i]) == "--help") {
        std::cout << kUsage;
        return 0;
      }
    }
    if (cmd == "render") return cmd_render(argc, argv);
    if (cmd == "gen") return cmd_gen(argc, argv);
    if (cmd == "check") return cmd_check(argc, argv);
    throw UsageError("unknown command '" + cmd + "'");
  } catch (const UsageError& e) {
    std::cerr << "semx-world: " << e.what() << " (see semx-world --help)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "semx-world: " << e.what() << "\n";
    return 1;
  }
}
