// The wire layout of LCM types, read from the same .lcm files lcm-gen compiles.
//
// LCM 1.3.1's generated decoders trust the length fields of a message: they resize vectors
// before checking the buffer and misbehave on negative or huge lengths. Knowing each type's
// layout lets the runtime walk the bytes first (see wire_validator.hpp) and hand the generated
// decoder only messages it can decode within their own size.
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace semx::runtime {

class LcmSchemaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class LcmPrimitive { kInt8, kInt16, kInt32, kInt64, kFloat, kDouble, kString, kBoolean, kByte, kStruct };

struct LcmDimension {
  bool variable = false;  // size given by an earlier integer field of the same struct
  int64_t size = 0;       // fixed size (when !variable)
  std::string field;      // the size field's name (when variable)
  int field_index = -1;   // index of that field in LcmStruct::fields
};

struct LcmField {
  std::string name;
  std::string type_name;  // as written: "int32_t", "semantic_region_t", "semx.camera_info_t"
  LcmPrimitive kind = LcmPrimitive::kStruct;
  std::string struct_name;  // fully qualified, for kStruct
  std::vector<LcmDimension> dims;
};

struct LcmStruct {
  std::string package;
  std::string name;  // unqualified, as getTypeName() returns it
  std::string file;
  std::vector<LcmField> fields;
  int64_t base_hash = 0;  // lcm-gen's per-struct hash before nested types are folded in
  std::string full_name() const { return package.empty() ? name : package + "." + name; }
};

class LcmSchema {
 public:
  // Parses .lcm texts; `file` names each one in errors ("semx_ack_t.lcm:7: ...").
  static LcmSchema parse(const std::vector<std::pair<std::string, std::string>>& files);
  // The schema of semx's own message types, built once from the compiled-in .lcm files.
  static const LcmSchema& semx();

  // By fully qualified ("semx.ack_t") or unique unqualified ("ack_t") name; nullptr if absent.
  const LcmStruct* find(std::string_view name) const;
  const std::map<std::string, LcmStruct>& structs() const { return structs_; }

  // The fingerprint lcm-gen's getHash() returns, computed from the layout.
  int64_t fingerprint(const LcmStruct& s) const;
  // Fewest bytes one encoded instance can take (no fingerprint): fixed fields plus 5 per string.
  std::size_t min_encoded_size(const LcmStruct& s) const;

 private:
  uint64_t nested_hash(const LcmStruct& s, std::vector<const LcmStruct*>& parents) const;
  void resolve();

  std::map<std::string, LcmStruct> structs_;  // by full name
};

std::size_t primitive_size(LcmPrimitive p);  // 0 for strings and structs
bool is_integer(LcmPrimitive p);             // the kinds an array size may have

}  // namespace semx::runtime
