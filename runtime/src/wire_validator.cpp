#include "semx/runtime/wire_validator.hpp"

#include <limits>
#include <vector>

namespace semx::runtime {

const char* to_string(WireError e) {
  switch (e) {
    case WireError::kNone:
      return "ok";
    case WireError::kTooShort:
      return "too short";
    case WireError::kFingerprint:
      return "wrong fingerprint";
    case WireError::kNegativeLength:
      return "negative array length";
    case WireError::kLengthExceedsBuffer:
      return "array length exceeds message";
    case WireError::kBadString:
      return "malformed string";
    case WireError::kTrailingBytes:
      return "trailing bytes";
    case WireError::kTooDeep:
      return "nesting too deep";
    case WireError::kNonFinite:
      return "NaN or infinite value";
  }
  return "?";
}

namespace {

constexpr int kMaxDepth = 8;

class Walker {
 public:
  Walker(const LcmSchema& schema, const uint8_t* data, std::size_t size, bool finite_reals)
      : schema_(schema), data_(data), size_(size), finite_reals_(finite_reals) {}

  WireError walk(const LcmStruct& s, int depth) {
    if (depth > kMaxDepth) return WireError::kTooDeep;
    // Integer scalars read so far, by field index, for variable array sizes.
    std::vector<int64_t> ints(s.fields.size(), 0);
    for (std::size_t fi = 0; fi < s.fields.size(); ++fi) {
      const LcmField& f = s.fields[fi];
      uint64_t count = 1;
      for (const auto& d : f.dims) {
        const int64_t n = d.variable ? ints[static_cast<std::size_t>(d.field_index)] : d.size;
        if (n < 0) return WireError::kNegativeLength;
        if (n != 0 && count > std::numeric_limits<uint32_t>::max() / static_cast<uint64_t>(n)) {
          return WireError::kLengthExceedsBuffer;
        }
        count *= static_cast<uint64_t>(n);
      }
      const std::size_t left = size_ - pos_;
      if (f.kind == LcmPrimitive::kString) {
        if (count > left / 5)
          return left < 4 && count == 1 ? WireError::kTooShort : WireError::kLengthExceedsBuffer;
        for (uint64_t k = 0; k < count; ++k) {
          if (size_ - pos_ < 4) return WireError::kTooShort;
          const int64_t len = read_int(4);
          if (len < 1 || static_cast<uint64_t>(len) > size_ - pos_) return WireError::kBadString;
          if (data_[pos_ + static_cast<std::size_t>(len) - 1] != 0) return WireError::kBadString;
          pos_ += static_cast<std::size_t>(len);
        }
      } else if (f.kind == LcmPrimitive::kStruct) {
        const LcmStruct& sub = schema_.structs().at(f.struct_name);
        const std::size_t each = std::max<std::size_t>(1, schema_.min_encoded_size(sub));
        if (count > left / each)
          return f.dims.empty() ? WireError::kTooShort : WireError::kLengthExceedsBuffer;
        for (uint64_t k = 0; k < count; ++k) {
          const WireError e = walk(sub, depth + 1);
          if (e != WireError::kNone) return e;
        }
      } else {
        const std::size_t each = primitive_size(f.kind);
        if (count > left / each)
          return f.dims.empty() ? WireError::kTooShort : WireError::kLengthExceedsBuffer;
        if (f.dims.empty() && is_integer(f.kind)) {
          ints[fi] = read_int(each);
        } else if (finite_reals_ && (f.kind == LcmPrimitive::kFloat || f.kind == LcmPrimitive::kDouble)) {
          // Big-endian IEEE 754: the exponent is all ones for NaN and inf alone.
          const bool is_double = f.kind == LcmPrimitive::kDouble;
          for (uint64_t k = 0; k < count; ++k, pos_ += each) {
            const unsigned exponent = is_double ? ((data_[pos_] & 0x7Fu) << 4) | (data_[pos_ + 1] >> 4)
                                                : ((data_[pos_] & 0x7Fu) << 1) | (data_[pos_ + 1] >> 7);
            if (exponent == (is_double ? 0x7FFu : 0xFFu)) return WireError::kNonFinite;
          }
        } else {
          pos_ += static_cast<std::size_t>(count) * each;
        }
      }
    }
    return WireError::kNone;
  }

  std::size_t pos() const { return pos_; }
  void skip(std::size_t n) { pos_ += n; }

 private:
  // Big-endian two's complement, sign-extended.
  int64_t read_int(std::size_t bytes) {
    uint64_t v = 0;
    for (std::size_t i = 0; i < bytes; ++i) v = (v << 8) | data_[pos_ + i];
    pos_ += bytes;
    const unsigned shift = static_cast<unsigned>(64 - 8 * bytes);
    return static_cast<int64_t>(v << shift) >> shift;
  }

  const LcmSchema& schema_;
  const uint8_t* data_;
  std::size_t size_;
  bool finite_reals_;
  std::size_t pos_ = 0;
};

}  // namespace

WireError validate_wire(const LcmSchema& schema, const LcmStruct& type, int64_t fingerprint,
                        const uint8_t* data, std::size_t size, bool finite_reals) {
  if (data == nullptr || size < 8) return WireError::kTooShort;
  uint64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | data[i];
  if (static_cast<int64_t>(hash) != fingerprint) return WireError::kFingerprint;
  Walker w(schema, data, size, finite_reals);
  w.skip(8);
  const WireError e = w.walk(type, 0);
  if (e != WireError::kNone) return e;
  return w.pos() == size ? WireError::kNone : WireError::kTrailingBytes;
}

}  // namespace semx::runtime
