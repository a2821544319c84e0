#include "semx/planner/roadmap.hpp"

#include <algorithm>
#include <cmath>
#include <queue>
#include <utility>

namespace semx::planner {

Roadmap::Roadmap(double cell_size) : cell_(cell_size > 0 ? cell_size : 1.0) {}

uint64_t Roadmap::pack(int64_t x, int64_t y, int64_t z) {
  constexpr uint64_t m = (uint64_t{1} << 21) - 1;
  return (static_cast<uint64_t>(x) & m) | ((static_cast<uint64_t>(y) & m) << 21) |
         ((static_cast<uint64_t>(z) & m) << 42);
}

uint64_t Roadmap::cell_of(const Eigen::Vector3d& p) const {
  return pack(static_cast<int64_t>(std::floor(p.x() / cell_)),
              static_cast<int64_t>(std::floor(p.y() / cell_)),
              static_cast<int64_t>(std::floor(p.z() / cell_)));
}

int64_t Roadmap::add_node(const Eigen::Vector3d& p) {
  RoadmapNode n;
  n.id = static_cast<int64_t>(nodes_.size());
  n.position = p;
  n.alive = true;
  nodes_.push_back(std::move(n));
  cells_[cell_of(p)].push_back(nodes_.back().id);
  ++alive_;
  return nodes_.back().id;
}

void Roadmap::remove_node(int64_t id) {
  if (!alive(id)) return;
  RoadmapNode& n = node(id);
  for (const RoadmapEdge& e : n.edges) {
    auto& back = node(e.to).edges;
    back.erase(std::remove_if(back.begin(), back.end(), [&](const RoadmapEdge& x) { return x.to == id; }),
               back.end());
    --edges_;
  }
  n.edges.clear();
  auto it = cells_.find(cell_of(n.position));
  if (it != cells_.end()) {
    auto& v = it->second;
    v.erase(std::remove(v.begin(), v.end(), id), v.end());
    if (v.empty()) cells_.erase(it);
  }
  n.alive = false;
  n.gain = NodeGain();
  --alive_;
}

void Roadmap::move_node(int64_t id, const Eigen::Vector3d& p) {
  if (!alive(id)) return;
  RoadmapNode& n = node(id);
  const uint64_t from = cell_of(n.position), to = cell_of(p);
  if (from != to) {
    auto it = cells_.find(from);
    if (it != cells_.end()) {
      auto& v = it->second;
      v.erase(std::remove(v.begin(), v.end(), id), v.end());
      if (v.empty()) cells_.erase(it);
    }
    cells_[to].push_back(id);
  }
  n.position = p;
}

bool Roadmap::has_edge(int64_t a, int64_t b) const {
  if (!alive(a)) return false;
  for (const RoadmapEdge& e : node(a).edges)
    if (e.to == b) return true;
  return false;
}

bool Roadmap::add_edge(int64_t a, int64_t b, double length) {
  if (a == b || !alive(a) || !alive(b) || has_edge(a, b)) return false;
  node(a).edges.push_back({b, length});
  node(b).edges.push_back({a, length});
  ++edges_;
  return true;
}

void Roadmap::remove_edge(int64_t a, int64_t b) {
  if (!has_edge(a, b)) return;
  auto drop = [](std::vector<RoadmapEdge>& v, int64_t to) {
    v.erase(std::remove_if(v.begin(), v.end(), [&](const RoadmapEdge& x) { return x.to == to; }), v.end());
  };
  drop(node(a).edges, b);
  drop(node(b).edges, a);
  --edges_;
}

std::vector<int64_t> Roadmap::nearest(const Eigen::Vector3d& p, int k, double radius, int64_t exclude) const {
  std::vector<std::pair<double, int64_t>> found;
  const int reach = static_cast<int>(std::ceil(radius / cell_));
  const int64_t cx = static_cast<int64_t>(std::floor(p.x() / cell_));
  const int64_t cy = static_cast<int64_t>(std::floor(p.y() / cell_));
  const int64_t cz = static_cast<int64_t>(std::floor(p.z() / cell_));
  const double r2 = radius * radius;
  for (int64_t z = cz - reach; z <= cz + reach; ++z) {
    for (int64_t y = cy - reach; y <= cy + reach; ++y) {
      for (int64_t x = cx - reach; x <= cx + reach; ++x) {
        auto it = cells_.find(pack(x, y, z));
        if (it == cells_.end()) continue;
        for (int64_t id : it->second) {
          if (id == exclude) continue;
          const double d2 = (node(id).position - p).squaredNorm();
          if (d2 <= r2) found.emplace_back(d2, id);
        }
      }
    }
  }
  std::sort(found.begin(), found.end());
  if (k >= 0 && static_cast<int>(found.size()) > k) found.resize(static_cast<size_t>(k));
  std::vector<int64_t> ids;
  ids.reserve(found.size());
  for (const auto& f : found) ids.push_back(f.second);
  return ids;
}

bool Roadmap::any_within(const Eigen::Vector3d& p, double radius, int64_t exclude) const {
  const int reach = static_cast<int>(std::ceil(radius / cell_));
  const int64_t cx = static_cast<int64_t>(std::floor(p.x() / cell_));
  const int64_t cy = static_cast<int64_t>(std::floor(p.y() / cell_));
  const int64_t cz = static_cast<int64_t>(std::floor(p.z() / cell_));
  const double r2 = radius * radius;
  for (int64_t z = cz - reach; z <= cz + reach; ++z) {
    for (int64_t y = cy - reach; y <= cy + reach; ++y) {
      for (int64_t x = cx - reach; x <= cx + reach; ++x) {
        auto it = cells_.find(pack(x, y, z));
        if (it == cells_.end()) continue;
        for (int64_t id : it->second) {
          if (id != exclude && (node(id).position - p).squaredNorm() < r2) return true;
        }
      }
    }
  }
  return false;
}

Roadmap::Search Roadmap::shortest_paths(int64_t source) const { return shortest_paths(source, {}); }

Roadmap::Search Roadmap::shortest_paths(int64_t source, const std::vector<int64_t>& targets) const {
  Search s;
  s.distance.assign(nodes_.size(), kInf);
  s.parent.assign(nodes_.size(), -1);
  if (!alive(source)) return s;
  // Targets not yet settled (none: search everything).
  std::vector<char> wanted;
  int64_t left = 0;
  if (!targets.empty()) {
    wanted.assign(nodes_.size(), 0);
    for (int64_t t : targets) {
      if (!alive(t) || wanted[static_cast<size_t>(t)]) continue;
      wanted[static_cast<size_t>(t)] = 1;
      ++left;
    }
    if (left == 0) return s;
  }
  using Item = std::pair<double, int64_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  s.distance[static_cast<size_t>(source)] = 0.0;
  queue.emplace(0.0, source);
  while (!queue.empty()) {
    const auto [d, id] = queue.top();
    queue.pop();
    if (d > s.distance[static_cast<size_t>(id)]) continue;
    ++s.settled;
    if (!wanted.empty() && wanted[static_cast<size_t>(id)]) {
      wanted[static_cast<size_t>(id)] = 0;
      if (--left == 0) break;
    }
    for (const RoadmapEdge& e : node(id).edges) {
      const double nd = d + e.length;
      double& cur = s.distance[static_cast<size_t>(e.to)];
      if (nd < cur) {
        cur = nd;
        s.parent[static_cast<size_t>(e.to)] = id;
        queue.emplace(nd, e.to);
      }
    }
  }
  return s;
}

std::vector<int64_t> Roadmap::path_to(const Search& s, int64_t target) {
  std::vector<int64_t> path;
  if (target < 0 || target >= static_cast<int64_t>(s.distance.size()) || !s.reached(target)) return path;
  for (int64_t id = target; id >= 0; id = s.parent[static_cast<size_t>(id)]) path.push_back(id);
  std::reverse(path.begin(), path.end());
  return path;
}

void Roadmap::clear() {
  nodes_.clear();
  cells_.clear();
  alive_ = edges_ = 0;
}

}  // namespace semx::planner
