#include "semx/semantics/cloud_filters.hpp"

#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>

namespace semx::semantics {

namespace {

struct PointsAdaptor {
  const std::vector<Eigen::Vector3f>& points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return points[i][static_cast<Eigen::Index>(dim)];
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointsAdaptor>,
                                                 PointsAdaptor, 3, uint32_t>;
// PCL's leaf size: it changes the speed, never the result of an exact search.
constexpr std::size_t kLeafSize = 15;

}  // namespace

std::vector<uint32_t> remove_statistical_outliers(const std::vector<Eigen::Vector3f>& points, int k,
                                                  double stddev_mul) {
  std::vector<uint32_t> kept;
  const std::size_t n = points.size();
  if (k < 1 || n <= static_cast<std::size_t>(k)) {
    kept.resize(n);
    for (std::size_t i = 0; i < n; ++i) kept[i] = static_cast<uint32_t>(i);
    return kept;
  }
  const PointsAdaptor adaptor{points};
  const Tree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize));
  const std::size_t searched = static_cast<std::size_t>(k) + 1;  // the point itself comes first
  std::vector<uint32_t> idx(searched);
  std::vector<float> d2(searched);
  std::vector<float> mean_distance(n, 0.0f);
  int valid = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!points[i].allFinite()) continue;
    const std::size_t found = tree.knnSearch(points[i].data(), searched, idx.data(), d2.data());
    if (found < searched) continue;
    // Summed as PCL sums it (float roots into a double), so that a point on the threshold falls
    // on the same side.
    double sum = 0.0;
    for (std::size_t j = 1; j < searched; ++j) sum += std::sqrt(d2[j]);
    mean_distance[i] = static_cast<float>(sum / k);
    ++valid;
  }
  double sum = 0.0;
  double sq_sum = 0.0;
  for (const float d : mean_distance) {
    sum += d;
    sq_sum += d * d;
  }
  const double mean = sum / valid;
  const double variance = (sq_sum - sum * sum / valid) / (valid - 1.0);
  const double threshold = mean + stddev_mul * std::sqrt(variance);
  kept.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!(mean_distance[i] > threshold)) kept.push_back(static_cast<uint32_t>(i));
  }
  return kept;
}

std::vector<std::vector<uint32_t>> euclidean_clusters(const std::vector<Eigen::Vector3f>& points,
                                                      double tolerance) {
  std::vector<std::vector<uint32_t>> clusters;
  const std::size_t n = points.size();
  if (n == 0) return clusters;
  const PointsAdaptor adaptor{points};
  const Tree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize));
  const float radius_sq = static_cast<float>(tolerance * tolerance);
  const nanoflann::SearchParams unsorted(32, 0.0f, false);
  std::vector<std::pair<uint32_t, float>> matches;
  std::vector<char> done(n, 0);
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (done[seed]) continue;
    std::vector<uint32_t> cluster{static_cast<uint32_t>(seed)};
    done[seed] = 1;
    for (std::size_t q = 0; q < cluster.size(); ++q) {
      matches.clear();
      tree.radiusSearch(points[cluster[q]].data(), radius_sq, matches, unsorted);
      for (const auto& m : matches) {
        if (done[m.first]) continue;
        done[m.first] = 1;
        cluster.push_back(m.first);
      }
    }
    std::sort(cluster.begin(), cluster.end());
    clusters.push_back(std::move(cluster));
  }
  // PCL sorts the reversed list by ascending size with the same (unstable) sort; doing the same
  // keeps equal-sized clusters in its order.
  std::sort(
      clusters.rbegin(), clusters.rend(),
      [](const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) { return a.size() < b.size(); });
  return clusters;
}

}  // namespace semx::semantics
