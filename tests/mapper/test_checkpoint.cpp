// Checkpoint files and export to other tools.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>

#include "mapper_test_util.hpp"
#include "semx/mapper/map_export.hpp"

namespace semx::mapper {
namespace {

std::vector<char> read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void write_all(const std::string& path, const std::vector<char>& data) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
}

Mapper room_mapper(int frames) {
  const runtime::PinholeCamera cam = test::small_camera();
  Mapper mapper{MapperConfig{}};
  for (const auto& f : test::room_frames(frames, cam, frames))
    mapper.integrate(DepthFrame::view(cam, f.pose, f.depth));
  return mapper;
}

TEST(Checkpoint, SaveAndReloadRestoresEveryLogOdds) {
  Mapper a = room_mapper(4);
  const std::string path = test::temp_path("reload.map");
  const CheckpointInfo saved = a.save_checkpoint(path, 4200);
  EXPECT_EQ(saved.seq, 4);
  EXPECT_GT(saved.blocks, 0u);
  EXPECT_EQ(read_checkpoint_info(path).utime, 4200);

  Mapper b{MapperConfig{}};
  const CheckpointInfo info = b.load_checkpoint(path);
  EXPECT_EQ(info.seq, 4);
  EXPECT_EQ(info.file_bytes, saved.file_bytes);
  EXPECT_TRUE(a.map().grid().same_states(b.map().grid()));
  int64_t compared = 0;
  a.map().grid().for_each_block([&](const map::VoxelKey& bk, const map::VoxelBlock& blk) {
    for (int i = 0; i < map::kBlockVolume; ++i) {
      if (blk.state[i] == map::VoxelState::kUnknown) continue;
      const map::VoxelKey k = map::voxel_of(bk, i);
      ASSERT_EQ(b.map().log_odds(k), blk.log_odds[i]);
      ++compared;
    }
  });
  EXPECT_EQ(compared, a.map().grid().known_voxels());
  // The restored mapper keeps integrating on top (the map it builds equals one never stopped).
  const runtime::PinholeCamera cam = test::small_camera();
  const auto more = test::room_frames(5, cam, 5);
  Mapper c = room_mapper(4);
  for (Mapper* m : {&b, &c}) m->integrate(DepthFrame::view(cam, more[4].pose, more[4].depth));
  EXPECT_TRUE(b.map().grid().same_states(c.map().grid()));
  std::remove(path.c_str());
}

TEST(Checkpoint, CorruptOrTruncatedFilesGiveErrorsNamingTheFile) {
  Mapper a = room_mapper(2);
  const std::string path = test::temp_path("corrupt.map");
  a.save_checkpoint(path, 0);
  const std::vector<char> good = read_all(path);
  ASSERT_GT(good.size(), 200u);

  Mapper victim = room_mapper(1);
  const int64_t known_before = victim.map().grid().known_voxels();
  auto expect_error = [&](const std::vector<char>& bytes, const std::string& what) {
    write_all(path, bytes);
    try {
      victim.load_checkpoint(path);
      ADD_FAILURE() << "no error for: " << what;
    } catch (const MapIoError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(path), std::string::npos) << msg;
      EXPECT_NE(msg.find(what), std::string::npos) << msg;
    }
    EXPECT_EQ(victim.map().grid().known_voxels(), known_before) << "the map is unchanged";
    EXPECT_EQ(victim.seq(), 1);
  };
  std::vector<char> bad = good;
  bad.resize(good.size() - 10);
  expect_error(bad, "truncated");
  bad = good;
  bad.resize(50);
  expect_error(bad, "truncated");
  bad = good;
  bad[good.size() - 20] ^= 0x01;
  expect_error(bad, "payload checksum mismatch");
  bad = good;
  bad[20] ^= 0x40;
  expect_error(bad, "header checksum mismatch");
  bad = good;
  bad[0] = 'X';
  expect_error(bad, "bad magic");
  bad = good;
  bad.push_back(0);
  expect_error(bad, "unexpected bytes");
  expect_error({}, "truncated");

  std::remove(path.c_str());
  try {
    victim.load_checkpoint(path);
    ADD_FAILURE() << "no error for a missing file";
  } catch (const MapIoError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos) << e.what();
  }
}

TEST(Checkpoint, ResolutionMustMatch) {
  Mapper a = room_mapper(1);
  const std::string path = test::temp_path("res.map");
  a.save_checkpoint(path, 0);
  MapperConfig cfg;
  cfg.occupancy.resolution = 0.2;
  Mapper b(cfg);
  try {
    b.load_checkpoint(path);
    ADD_FAILURE();
  } catch (const MapIoError& e) {
    EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

TEST(Checkpoint, UnwritablePathIsAClearError) {
  Mapper a = room_mapper(1);
  try {
    a.save_checkpoint("/nonexistent-dir/x.map", 0);
    ADD_FAILURE();
  } catch (const MapIoError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.map"), std::string::npos) << e.what();
  }
}

TEST(Export, OctomapBinaryFileReadsBackWithTheSameStates) {
  Mapper a = room_mapper(3);
  const std::string path = test::temp_path("map.bt");
  const ExportReport rep = export_octomap_bt(a.map(), path);
  EXPECT_EQ(rep.voxels, a.map().grid().known_voxels());
  EXPECT_EQ(rep.skipped, 0);
  octomap::OcTree tree(0.1);
  ASSERT_TRUE(tree.readBinary(path));
  EXPECT_DOUBLE_EQ(tree.getResolution(), 0.1);
  tree.expand();
  EXPECT_EQ(static_cast<int64_t>(tree.getNumLeafNodes()), a.map().grid().known_voxels());
  octomap::OcTree copy(tree);
  EXPECT_DOUBLE_EQ(test::agreement(a.map().grid(), copy), 1.0);
  std::remove(path.c_str());
}

TEST(Export, PcdHoldsTheOccupiedVoxelCentres) {
  Mapper a = room_mapper(2);
  for (const bool binary : {true, false}) {
    const std::string path = test::temp_path(binary ? "occ_bin.pcd" : "occ_ascii.pcd");
    const ExportReport rep = export_occupied_pcd(a.map().grid(), path, binary);
    EXPECT_EQ(rep.voxels, a.map().grid().occupied_voxels());
    std::ifstream in(path, std::ios::binary);
    std::string line, data;
    int64_t points = -1;
    while (std::getline(in, line)) {
      if (line.rfind("POINTS ", 0) == 0) points = std::stoll(line.substr(7));
      if (line.rfind("DATA ", 0) == 0) {
        data = line.substr(5);
        break;
      }
    }
    EXPECT_EQ(points, rep.voxels);
    EXPECT_EQ(data, binary ? "binary" : "ascii");
    int64_t checked = 0;
    for (int64_t i = 0; i < points; ++i) {
      float p[3];
      if (binary) {
        in.read(reinterpret_cast<char*>(p), sizeof(p));
      } else {
        in >> p[0] >> p[1] >> p[2];
      }
      ASSERT_TRUE(in.good()) << i;
      const Eigen::Vector3d c(p[0], p[1], p[2]);
      const map::VoxelKey k = a.map().keys().key(c);
      ASSERT_EQ(a.map().state(k), map::VoxelState::kOccupied);
      ASSERT_LT((a.map().keys().center(k) - c).norm(), 1e-4);
      ++checked;
    }
    EXPECT_EQ(checked, a.map().grid().occupied_voxels());
    std::remove(path.c_str());
  }
}

}  // namespace
}  // namespace semx::mapper
