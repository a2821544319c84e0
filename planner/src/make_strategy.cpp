#include "semx/planner/aep_strategy.hpp"
#include "semx/planner/dep_strategy.hpp"
#include "semx/planner/fuel_strategy.hpp"
#include "semx/planner/nbv_strategy.hpp"
#include "semx/planner/oracle_strategy.hpp"
#include "semx/planner/semantic_fuel_strategy.hpp"
#include "semx/planner/semantic_room_strategy.hpp"
#include "semx/planner/strategy.hpp"

namespace semx::planner {

std::unique_ptr<Strategy> make_strategy(const PlannerConfig& config) {
  switch (config.kind()) {
    case PlannerKind::kSemanticDep:
      return std::make_unique<DepStrategy>(config, true);
    case PlannerKind::kDep:
      return std::make_unique<DepStrategy>(config, false);
    case PlannerKind::kNbv:
      return std::make_unique<NbvStrategy>(config);
    case PlannerKind::kAep:
      return std::make_unique<AepStrategy>(config);
    case PlannerKind::kFuel:
      return std::make_unique<FuelStrategy>(config);
    case PlannerKind::kOracle:
      return std::make_unique<OracleStrategy>(config);
    case PlannerKind::kSemanticRoom:
      return std::make_unique<SemanticRoomStrategy>(config);
    case PlannerKind::kSemanticFuel:
      return std::make_unique<SemanticFuelStrategy>(config);
  }
  return nullptr;
}

}  // namespace semx::planner
