// The two neighbour filters of lifting, on nanoflann's k-d tree: statistical outlier removal and
// Euclidean clustering. They give PCL's StatisticalOutlierRemoval and EuclideanClusterExtraction
// results (the same survivors, the same clusters in the same order), without PCL's FLANN search,
// which enters an OpenMP region and a system call per query: half of the lifting time
// (docs/semantics.md, "Cost per frame").
#pragma once
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace semx::semantics {

// The indices, in order, of the points whose mean distance to their k nearest neighbours is at
// most mean + stddev_mul * stddev of that distance over the cloud. A cloud of k points or fewer is
// returned whole: its points have no k neighbours.
std::vector<uint32_t> remove_statistical_outliers(const std::vector<Eigen::Vector3f>& points, int k,
                                                  double stddev_mul);

// The connected components of the points under "closer than tolerance" (strictly), each as
// ascending indices, largest first (ties in the order PCL's std::sort leaves them).
std::vector<std::vector<uint32_t>> euclidean_clusters(const std::vector<Eigen::Vector3f>& points,
                                                      double tolerance);

}  // namespace semx::semantics
