// The semantic class vocabulary shared by worlds, the label camera, semantics and the planner.
// Ids are part of the message contract (label images and semantic_region_t carry them): append
// new classes, never renumber.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace semx::runtime {

enum class SemanticClass : uint16_t {
  kNone = 0,  // background / no label
  kWall = 1,
  kFloor = 2,
  kCeiling = 3,
  kDoor = 4,
  kChair = 5,
  kTable = 6,
  kSofa = 7,
  kBed = 8,
  kCabinet = 9,
  kShelf = 10,
  kTv = 11,
  kPlant = 12,
  kLamp = 13,
  kDesk = 14,
  kToilet = 15,
  kSink = 16,
  kRefrigerator = 17,
  kBathtub = 18,
  kWindow = 19,
  kCount
};

struct SemanticClassInfo {
  SemanticClass id;
  std::string_view name;
  std::array<uint8_t, 3> rgb;  // default display colour
  bool structural;             // part of the building (not an object the planner rewards)
};

inline constexpr std::array<SemanticClassInfo, static_cast<size_t>(SemanticClass::kCount)> kSemanticClasses{{
    {SemanticClass::kNone, "none", {0, 0, 0}, true},
    {SemanticClass::kWall, "wall", {200, 200, 190}, true},
    {SemanticClass::kFloor, "floor", {150, 120, 90}, true},
    {SemanticClass::kCeiling, "ceiling", {235, 235, 235}, true},
    {SemanticClass::kDoor, "door", {140, 80, 30}, false},
    {SemanticClass::kChair, "chair", {230, 120, 40}, false},
    {SemanticClass::kTable, "table", {170, 110, 60}, false},
    {SemanticClass::kSofa, "sofa", {60, 90, 180}, false},
    {SemanticClass::kBed, "bed", {190, 60, 110}, false},
    {SemanticClass::kCabinet, "cabinet", {110, 70, 40}, false},
    {SemanticClass::kShelf, "shelf", {90, 140, 60}, false},
    {SemanticClass::kTv, "tv", {30, 30, 30}, false},
    {SemanticClass::kPlant, "plant", {40, 170, 60}, false},
    {SemanticClass::kLamp, "lamp", {250, 220, 80}, false},
    {SemanticClass::kDesk, "desk", {160, 130, 90}, false},
    {SemanticClass::kToilet, "toilet", {240, 240, 255}, false},
    {SemanticClass::kSink, "sink", {180, 200, 220}, false},
    {SemanticClass::kRefrigerator, "refrigerator", {210, 215, 220}, false},
    {SemanticClass::kBathtub, "bathtub", {220, 230, 240}, false},
    {SemanticClass::kWindow, "window", {120, 190, 230}, true},
}};

inline const SemanticClassInfo& class_info(SemanticClass c) {
  return kSemanticClasses[static_cast<size_t>(c)];
}

inline std::optional<SemanticClass> class_from_name(std::string_view name) {
  for (const auto& info : kSemanticClasses) {
    if (info.name == name) return info.id;
  }
  return std::nullopt;
}

inline std::optional<SemanticClass> class_from_id(int id) {
  if (id < 0 || id >= static_cast<int>(SemanticClass::kCount)) return std::nullopt;
  return static_cast<SemanticClass>(id);
}

}  // namespace semx::runtime
