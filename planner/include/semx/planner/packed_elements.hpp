// A list of masked elements (set_cover.hpp) packed for keeping: sorted by element, each element
// as the varint of its gap from the one before, its member mask as the start and length of its
// run of set bits, circularly (what a camera's yaw bins give: a voxel is seen from a run of
// neighbouring yaws), or as four raw bytes when it is not one run. About 3 bytes an element
// against 8 unpacked: the oracle keeps its candidates' views this way, and a view it cannot keep is
// cast again at every use (oracle_strategy.hpp, oracle.cache_mb).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "semx/planner/set_cover.hpp"

namespace semx::planner {

class PackedElements {
 public:
  PackedElements() = default;
  // Elements must be distinct and non-negative; their order does not matter (they are sorted).
  explicit PackedElements(const std::vector<MaskedElement>& elements);

  // The elements in ascending order.
  void unpack(std::vector<MaskedElement>& out) const;
  size_t size() const { return count_; }
  size_t bytes() const { return data_.size(); }

 private:
  std::vector<uint8_t> data_;
  size_t count_ = 0;
};

}  // namespace semx::planner
