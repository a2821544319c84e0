// The nanoflann neighbour filters against PCL's StatisticalOutlierRemoval and
// EuclideanClusterExtraction, which they replace: the same survivors and the same clusters on
// clouds like the lifter's (voxel-grid centres, blobs, stray points), and known small cases.
#include <gtest/gtest.h>
#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <random>

#include "semx/semantics/cloud_filters.hpp"

namespace semx::semantics {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr to_pcl(const std::vector<Eigen::Vector3f>& points) {
  Cloud::Ptr cloud(new Cloud);
  for (const auto& p : points) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return cloud;
}

// Blobs of points on a 5 cm lattice (as the voxel grid leaves them, so that many neighbour
// distances tie), each point jittered by a little, and some stray points around them.
std::vector<Eigen::Vector3f> lifter_like_cloud(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_int_distribution<int> blobs_of(1, 4);
  std::uniform_int_distribution<int> size_of(2, 6);
  std::vector<Eigen::Vector3f> points;
  const int blobs = blobs_of(rng);
  const float jitter = (seed % 2 == 0) ? 0.0f : 0.004f;
  for (int b = 0; b < blobs; ++b) {
    const Eigen::Vector3f centre(unit(rng) * 2, unit(rng) * 2, 1.0f + unit(rng) * 0.5f);
    const int nx = size_of(rng), ny = size_of(rng), nz = size_of(rng);
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < ny; ++j)
        for (int k = 0; k < nz; ++k) {
          if (unit(rng) < -0.6f) continue;  // holes, as a partly seen surface has
          const Eigen::Vector3f jit(unit(rng) * jitter, unit(rng) * jitter, unit(rng) * jitter);
          points.push_back(centre + 0.05f * Eigen::Vector3f(i, j, k) + jit);
        }
  }
  const int strays = static_cast<int>(points.size() / 20) + 1;
  for (int s = 0; s < strays; ++s) points.emplace_back(unit(rng) * 3, unit(rng) * 3, 1.0f + unit(rng));
  return points;
}

TEST(CloudFilters, OutlierRemovalKeepsThePointsPclKeeps) {
  for (uint32_t seed = 1; seed <= 60; ++seed) {
    const auto points = lifter_like_cloud(seed);
    for (const int k : {4, 8}) {
      // PCL reads past its neighbour list when a cloud has k points or fewer; the lifter never
      // filters those.
      if (points.size() <= static_cast<std::size_t>(k) + 1) continue;
      for (const double mul : {0.5, 1.0, 2.0}) {
        pcl::StatisticalOutlierRemoval<pcl::PointXYZ> pcl_filter;
        pcl_filter.setMeanK(k);
        pcl_filter.setStddevMulThresh(mul);
        pcl_filter.setInputCloud(to_pcl(points));
        pcl::Indices expected;
        pcl_filter.filter(expected);
        const auto kept = remove_statistical_outliers(points, k, mul);
        ASSERT_EQ(std::vector<uint32_t>(expected.begin(), expected.end()), kept)
            << "seed " << seed << ", k " << k << ", stddev x" << mul << ", " << points.size() << " points";
      }
    }
  }
}

TEST(CloudFilters, ClustersArePclsClustersInPclsOrder) {
  for (uint32_t seed = 1; seed <= 60; ++seed) {
    const auto points = lifter_like_cloud(seed);
    for (const double tolerance : {0.06, 0.12, 0.5}) {
      const auto cloud = to_pcl(points);
      pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>(false));
      tree->setInputCloud(cloud);
      pcl::EuclideanClusterExtraction<pcl::PointXYZ> pcl_clusters;
      pcl_clusters.setClusterTolerance(tolerance);
      pcl_clusters.setMinClusterSize(1);
      pcl_clusters.setMaxClusterSize(std::numeric_limits<int>::max());
      pcl_clusters.setSearchMethod(tree);
      pcl_clusters.setInputCloud(cloud);
      std::vector<pcl::PointIndices> expected;
      pcl_clusters.extract(expected);
      const auto found = euclidean_clusters(points, tolerance);
      ASSERT_EQ(expected.size(), found.size()) << "seed " << seed << ", tolerance " << tolerance;
      for (std::size_t c = 0; c < found.size(); ++c) {
        ASSERT_EQ(std::vector<uint32_t>(expected[c].indices.begin(), expected[c].indices.end()), found[c])
            << "seed " << seed << ", tolerance " << tolerance << ", cluster " << c;
      }
    }
  }
}

TEST(CloudFilters, AFarPointIsAnOutlierAndALineIsNot) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 20; ++i) points.emplace_back(0.05f * i, 0.0f, 0.0f);
  points.emplace_back(5.0f, 5.0f, 5.0f);
  const auto kept = remove_statistical_outliers(points, 3, 1.0);
  ASSERT_EQ(kept.size(), 20u);
  for (uint32_t i = 0; i < 20; ++i) EXPECT_EQ(kept[i], i);
  // Too few points to have k neighbours: nothing is judged.
  EXPECT_EQ(remove_statistical_outliers({{0, 0, 0}, {9, 9, 9}}, 3, 1.0).size(), 2u);
}

TEST(CloudFilters, PointsCloserThanTheToleranceJoinAndTheLargestComesFirst) {
  // Two rows 1 m apart: 3 points and 5 points 0.1 m apart; a lone point far away.
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 3; ++i) points.emplace_back(0.1f * i, 0.0f, 0.0f);
  for (int i = 0; i < 5; ++i) points.emplace_back(0.1f * i, 1.0f, 0.0f);
  points.emplace_back(10.0f, 0.0f, 0.0f);
  const auto clusters = euclidean_clusters(points, 0.15);
  ASSERT_EQ(clusters.size(), 3u);
  EXPECT_EQ(clusters[0], (std::vector<uint32_t>{3, 4, 5, 6, 7}));
  EXPECT_EQ(clusters[1], (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(clusters[2], (std::vector<uint32_t>{8}));
  // Closer than, not as close as: at a tolerance of exactly the spacing rows fall apart.
  EXPECT_EQ(euclidean_clusters({{0, 0, 0}, {0.5f, 0, 0}}, 0.5).size(), 2u);
  EXPECT_TRUE(euclidean_clusters({}, 0.1).empty());
}

}  // namespace
}  // namespace semx::semantics
