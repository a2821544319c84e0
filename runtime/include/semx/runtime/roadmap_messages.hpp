// roadmap_t and semantic_regions_t -> core's plain values (core/roadmap_values.hpp), for the
// processes that draw or forward them (viewer, ROS bridge). The values are as received: the wire
// validator has checked them, and each reader sanitises what it draws.
#pragma once

#include <semx/roadmap_t.hpp>
#include <semx/semantic_regions_t.hpp>

#include <vector>

#include "semx/core/roadmap_values.hpp"

namespace semx::runtime {

core::Roadmap roadmap_from(const semx::roadmap_t& m);
std::vector<core::Region> regions_from(const semx::semantic_regions_t& m);

}  // namespace semx::runtime
