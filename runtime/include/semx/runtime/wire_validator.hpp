// Walks an encoded LCM message against its type's layout before anything decodes it.
//
// A message passes only if: it starts with the expected fingerprint; every array length is
// non-negative and its elements fit in the bytes left (so a decoder that resizes first can
// allocate no more than a small multiple of the message size); every string has a length of at
// least 1 that fits and ends in NUL; nesting is shallow; and no bytes are left over.
#pragma once

#include <cstddef>
#include <cstdint>

#include "semx/runtime/lcm_schema.hpp"

namespace semx::runtime {

enum class WireError {
  kNone,
  kTooShort,             // fewer bytes than the fixed fields need
  kFingerprint,          // not the expected type (or a different version of it)
  kNegativeLength,       // an array length field below zero
  kLengthExceedsBuffer,  // an array that cannot fit in the bytes left
  kBadString,            // string length < 1, past the end, or not NUL-terminated
  kTrailingBytes,        // bytes left after the last field
  kTooDeep,              // nesting deeper than any semx type
  kNonFinite,            // a float or double field is NaN or infinite (checked on request)
};

const char* to_string(WireError e);

// Checks `data[0, size)` as an encoded `type` whose fingerprint must equal `fingerprint`
// (pass the generated T::getHash()). With `finite_reals`, every float and double must also be
// finite: no semx message means anything by NaN or inf, and one NaN reaching a handler (a
// collision at (nan, inf, 1e300) counted by the evaluator) is a wrong run. Nodes check it for
// every message they receive and publish (node.hpp); it reads the exponent bits only.
WireError validate_wire(const LcmSchema& schema, const LcmStruct& type, int64_t fingerprint,
                        const uint8_t* data, std::size_t size, bool finite_reals = false);

}  // namespace semx::runtime
