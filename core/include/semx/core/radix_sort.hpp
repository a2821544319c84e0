// Unsigned 64-bit integers sorted by a band of their bits, least significant digit first (11
// bits a pass, stable): linear in the list, where std::sort is n log n. Its users sort 10^4 to
// 10^6 values that differ only in a few low bits (packed voxel keys, ids with flags beside them).
#pragma once

#include <cstdint>
#include <vector>

namespace semx::core {

// Sorts `values` by bits [from_bit, to_bit) (0 <= from_bit <= to_bit <= 64); values equal there
// keep their order. Short lists go to std::stable_sort on the same bits.
void radix_sort(std::vector<uint64_t>& values, int from_bit, int to_bit);

}  // namespace semx::core
