// semx-viewer: a top-down picture of a run (map, trail, roadmap, regions, path, pose), live from
// the bus or from a log played into it, as PNG frames on message time or in a window
// (docs/viewer.md).
#include <cmath>
#include <iostream>
#include <sstream>
#include <vector>

#include "frame_window.hpp"
#include "semx/runtime/node_flags.hpp"
#include "semx/simulator/world.hpp"
#include "viewer_node.hpp"

using namespace semx;

namespace {

std::vector<double> numbers(const std::string& flag, const std::string& text, size_t n) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw runtime::ArgError("--" + flag + ": '" + item + "' is not a number");
    }
    if (!std::isfinite(v.back())) throw runtime::ArgError("--" + flag + ": numbers must be finite");
  }
  if (v.size() != n)
    throw runtime::ArgError("--" + flag + " needs " + std::to_string(n) + " numbers, comma-separated");
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  return runtime::run_main("semx-viewer", [&] {
    runtime::NodeFlags flags("viewer");
    std::string out, world, area, heights;
    double period = 1.0, scale = 0;
    bool window = false, no_legend = false;
    runtime::ArgParser p(
        "semx-viewer",
        "Draws the run top-down: the map's columns (free / occupied / unknown) in a height band, the\n"
        "flown trail, the planner's roadmap coloured by score, the semantic regions, the current path\n"
        "and the vehicle's pose, with sim time, known volume and planner state in the header. Frames\n"
        "follow message time, so a log played into it (./semx replay LOG, or --lcm-url\n"
        "'file://LOG?speed=0') gives the run's pictures (docs/viewer.md).");
    flags.add_to(p);
    p.option("out", "DIR",
             "write frame_NNNNNN.png here every --period (default: viewer-frames, unless --window)", &out)
        .option("period", "S", "message time between frames, s (default 1)", &period)
        .flag("window", "show the frames in an OpenCV window (needs a display; else PNGs)", &window)
        .option("world", "FILE|NAME",
                "draw this world's walls faintly and show its area (env1/env2/env3 or a file)", &world)
        .option("scale", "PX_PER_M",
                "pixels per metre, rounded to whole pixels per voxel (default: fit 900 px)", &scale)
        .option("area", "X0,Y0,X1,Y1", "area shown, m (default: the world's, else all seen so far)", &area)
        .option("heights", "LO,HI",
                "heights projected into the columns, m (default: the world's, else 0.15,2.2)", &heights)
        .flag("no-legend", "leave out the legend", &no_legend);
    if (!p.parse(argc, argv)) return 0;
    if (!(period > 0) || period > 1e6) throw runtime::ArgError("--period must be positive");
    if (!(scale >= 0) || scale > 1e4) throw runtime::ArgError("--scale must be between 0 and 10000");

    viewer::ViewerNodeOptions o;
    o.period_s = period;
    o.view.scale_px_per_m = scale;
    o.view.legend = !no_legend;
    if (!area.empty()) {
      const auto a = numbers("area", area, 4);
      if (!(a[2] > a[0] && a[3] > a[1])) throw runtime::ArgError("--area: X1 > X0 and Y1 > Y0, please");
      o.view.area = std::make_pair(Eigen::Vector2d(a[0], a[1]), Eigen::Vector2d(a[2], a[3]));
    }
    if (!heights.empty()) {
      const auto h = numbers("heights", heights, 2);
      if (!(h[1] > h[0])) throw runtime::ArgError("--heights: HI > LO, please");
      o.view.z_band = std::make_pair(h[0], h[1]);
    }
    if (!world.empty()) {
      const std::string path =
          world.find('/') == std::string::npos && world.find(".yaml") == std::string::npos
              ? simulator::shipped_world_path(world)
              : world;
      o.world = simulator::load_world(path);
    }

    std::unique_ptr<viewer::FrameWindow> win;
    if (window) {
      std::string why;
      win = viewer::FrameWindow::open("semx-viewer", &why);
      if (!win) {
        std::cerr << "semx-viewer: no window (" << why << "); writing PNG frames instead" << std::endl;
      }
    }
    if (out.empty() && !win) out = "viewer-frames";
    o.out_dir = out;
    if (win) {
      viewer::FrameWindow* w = win.get();
      o.on_frame = [w](const evaluator::Image& img, int64_t) { w->show(img); };
    }

    auto node_options = flags.options();
    node_options.observer = true;  // it draws the run, it does not change it
    runtime::Node node(node_options);
    runtime::install_shutdown_handlers();
    viewer::ViewerNode v(node, std::move(o));
    std::cout << "semx-viewer: on " << node.url() << (flags.lockstep ? " (lockstep)" : "")
              << ", a frame every " << period << " s of message time"
              << (out.empty() ? "" : " -> " + out + "/frame_NNNNNN.png")
              << (win ? ", in a window (q or Esc closes it)" : "") << std::endl;
    if (win) return v.run([w = win.get()] { return w->poll(); });
    return v.run();
  });
}
