// Random well-formed encodings of any LCM type, and hostile variants of them.
//
// Used by the tests (every type: the generated decoder accepts what the validator accepts) and
// by semx-hostile, which throws malformed bytes at running processes.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "semx/runtime/lcm_schema.hpp"

namespace semx::runtime {

// An encoding of `type` with random field values; variable arrays get 0..max_array elements.
std::vector<uint8_t> random_wire_message(const LcmSchema& schema, const LcmStruct& type, std::mt19937_64& rng,
                                         int max_array = 8);

enum class HostileKind {
  kTruncated,       // a valid message cut short
  kOversized,       // a valid message with junk appended
  kNegativeLength,  // an array length field set below zero
  kHugeLength,      // an array length field set to INT32_MAX (or the largest of its type)
  kWrongFingerprint,
  kRandomBytes,  // noise of random size
  kBitFlip,      // a valid message with random bits flipped
  // Decodable messages whose values are wrong, which only a node's own checks can catch:
  kNonFinite,  // every float or double field NaN, +inf or -inf
  kExtreme,    // integers 0..3, -1 or their type's extremes (utime INT64_MAX, tick 2^63-1, enum
               // values that mean DONE or EPISODE_END); reals 0, +-1, +-1e9, 1e300
};
const char* to_string(HostileKind k);
// The seven malformed kinds (bytes a decoder must refuse), not the decodable ones below them.
std::vector<HostileKind> all_hostile_kinds();
// kNonFinite and kExtreme: decodable, wrong in value.
std::vector<HostileKind> decodable_hostile_kinds();

// Whether `type` (or a struct inside it) has a float or double field: kNonFinite on a type
// without one is a plain random message, which may well be valid.
bool has_real_field(const LcmSchema& schema, const LcmStruct& type);

// A hostile variant of a random message of `type`. When the type has no array to abuse,
// kNegativeLength and kHugeLength fall back to a corrupted fingerprint-valid header.
std::vector<uint8_t> hostile_wire_message(const LcmSchema& schema, const LcmStruct& type, HostileKind kind,
                                          std::mt19937_64& rng);

}  // namespace semx::runtime
