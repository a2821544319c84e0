#include <gtest/gtest.h>

#include "semx/tools/status_board.hpp"

using semx::tools::StatusBoard;

TEST(StatusBoard, TracksNodesAndCpuShare) {
  StatusBoard b;
  semx::node_status_t s{};
  s.node = "mapper";
  s.pid = 10;
  s.state = 1;
  s.cpu_s = 1.0;
  b.on_status(s, 100.0);
  s.cpu_s = 1.5;
  b.on_status(s, 101.0);
  EXPECT_NEAR(b.nodes().at("mapper").cpu_percent, 50.0, 1e-9);
  EXPECT_EQ(b.missing({"mapper", "planner"}), std::vector<std::string>{"planner"});
  s.state = 5;  // failed
  b.on_status(s, 102.0);
  EXPECT_EQ(b.missing({"mapper"}), std::vector<std::string>{"mapper"});
  const auto table = b.render_nodes(103.0);
  EXPECT_NE(table.find("mapper"), std::string::npos);
  EXPECT_NE(table.find("failed"), std::string::npos);
}

TEST(StatusBoard, ChannelRates) {
  StatusBoard b;
  b.update_rates(0.0);
  for (int i = 0; i < 30; ++i) b.on_message("CAMERA_DEPTH", 1024, i == 0);
  b.update_rates(1.0);
  const auto& row = b.channels().at("CAMERA_DEPTH");
  EXPECT_NEAR(row.hz, 30.0, 1e-9);
  EXPECT_NEAR(row.kbps, 30.0, 1e-9);
  EXPECT_EQ(row.malformed, 1);
  EXPECT_NE(b.render_channels().find("CAMERA_DEPTH"), std::string::npos);
}
