#include "semx/runtime/wire_generator.hpp"

#include <cstring>
#include <limits>

namespace semx::runtime {

namespace {

enum class Values { kRandom, kNonFinite, kExtreme };

struct Emitter {
  const LcmSchema& schema;
  std::mt19937_64& rng;
  int max_array;
  std::vector<uint8_t> out;
  // Offsets of the array-size fields written so far, with their byte widths, so hostile
  // variants can rewrite one.
  std::vector<std::pair<std::size_t, std::size_t>> length_fields;
  Values values = Values::kRandom;

  void put_int(int64_t v, std::size_t bytes) {
    for (std::size_t i = 0; i < bytes; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * (bytes - 1 - i))));
  }

  // Finite values in kRandom: the decodable-but-wrong kinds are asked for by name.
  double real_value() {
    switch (values) {
      case Values::kNonFinite: {
        static constexpr double kBad[] = {std::numeric_limits<double>::quiet_NaN(),
                                          std::numeric_limits<double>::infinity(),
                                          -std::numeric_limits<double>::infinity()};
        return kBad[rng() % 3];
      }
      case Values::kExtreme: {
        static constexpr double kEdge[] = {0.0, 1.0, -1.0, 1e9, -1e9, 1e300};  // 1e300: inf as a float
        return kEdge[rng() % 6];
      }
      case Values::kRandom:
        break;
    }
    return std::uniform_real_distribution<double>(-1e3, 1e3)(rng);
  }

  int64_t extreme_int(std::size_t bytes) {
    const unsigned bits = static_cast<unsigned>(8 * bytes);
    const int64_t max = bits >= 64 ? std::numeric_limits<int64_t>::max() : (int64_t{1} << (bits - 1)) - 1;
    switch (rng() % 4) {
      case 0:
        return static_cast<int64_t>(rng() % 4);  // small enum values: DONE, EPISODE_END, ...
      case 1:
        return -1;
      case 2:
        return max;
      default:
        return -max - 1;
    }
  }

  void emit(const LcmStruct& s) {
    std::vector<int64_t> ints(s.fields.size(), 0);
    std::vector<bool> is_length(s.fields.size(), false);
    for (const auto& f : s.fields) {
      for (const auto& d : f.dims) {
        if (d.variable) is_length[static_cast<std::size_t>(d.field_index)] = true;
      }
    }
    for (std::size_t fi = 0; fi < s.fields.size(); ++fi) {
      const LcmField& f = s.fields[fi];
      std::size_t count = 1;
      for (const auto& d : f.dims) {
        count *=
            static_cast<std::size_t>(d.variable ? ints[static_cast<std::size_t>(d.field_index)] : d.size);
      }
      for (std::size_t k = 0; k < count; ++k) {
        switch (f.kind) {
          case LcmPrimitive::kString: {
            const std::size_t len = rng() % 12;
            put_int(static_cast<int64_t>(len + 1), 4);
            for (std::size_t c = 0; c < len; ++c) out.push_back(static_cast<uint8_t>('a' + rng() % 26));
            out.push_back(0);
            break;
          }
          case LcmPrimitive::kStruct:
            emit(schema.structs().at(f.struct_name));
            break;
          case LcmPrimitive::kBoolean:
            out.push_back(static_cast<uint8_t>(rng() % 2));
            break;
          default: {
            const std::size_t bytes = primitive_size(f.kind);
            if (f.dims.empty() && is_length[fi]) {
              ints[fi] = static_cast<int64_t>(rng() % static_cast<uint64_t>(max_array + 1));
              length_fields.emplace_back(out.size(), bytes);
              put_int(ints[fi], bytes);
            } else if (f.kind == LcmPrimitive::kFloat || f.kind == LcmPrimitive::kDouble) {
              const double v = real_value();
              if (f.kind == LcmPrimitive::kFloat) {
                const float fv = static_cast<float>(v);
                uint32_t bits;
                std::memcpy(&bits, &fv, 4);
                put_int(bits, 4);
              } else {
                uint64_t bits;
                std::memcpy(&bits, &v, 8);
                put_int(static_cast<int64_t>(bits), 8);
              }
            } else {
              const int64_t v = values == Values::kExtreme ? extreme_int(bytes) : static_cast<int64_t>(rng());
              put_int(v, bytes);
              if (f.dims.empty()) {
                // Keep the sign-extended value: it is what an array size would read back as.
                const unsigned shift = static_cast<unsigned>(64 - 8 * bytes);
                ints[fi] = static_cast<int64_t>(static_cast<uint64_t>(v) << shift) >> shift;
              }
            }
          }
        }
      }
    }
  }
};

}  // namespace

std::vector<uint8_t> random_wire_message(const LcmSchema& schema, const LcmStruct& type, std::mt19937_64& rng,
                                         int max_array) {
  Emitter e{schema, rng, max_array, {}, {}, Values::kRandom};
  e.put_int(schema.fingerprint(type), 8);
  e.emit(type);
  return std::move(e.out);
}

const char* to_string(HostileKind k) {
  switch (k) {
    case HostileKind::kTruncated:
      return "truncated";
    case HostileKind::kOversized:
      return "oversized";
    case HostileKind::kNegativeLength:
      return "negative-length";
    case HostileKind::kHugeLength:
      return "huge-length";
    case HostileKind::kWrongFingerprint:
      return "wrong-fingerprint";
    case HostileKind::kRandomBytes:
      return "random-bytes";
    case HostileKind::kBitFlip:
      return "bit-flip";
    case HostileKind::kNonFinite:
      return "non-finite";
    case HostileKind::kExtreme:
      return "extreme";
  }
  return "?";
}

std::vector<HostileKind> all_hostile_kinds() {
  return {HostileKind::kTruncated,  HostileKind::kOversized,        HostileKind::kNegativeLength,
          HostileKind::kHugeLength, HostileKind::kWrongFingerprint, HostileKind::kRandomBytes,
          HostileKind::kBitFlip};
}

bool has_real_field(const LcmSchema& schema, const LcmStruct& type) {
  for (const auto& f : type.fields) {
    if (f.kind == LcmPrimitive::kFloat || f.kind == LcmPrimitive::kDouble) return true;
    if (f.kind == LcmPrimitive::kStruct && has_real_field(schema, schema.structs().at(f.struct_name))) return true;
  }
  return false;
}

std::vector<HostileKind> decodable_hostile_kinds() { return {HostileKind::kNonFinite, HostileKind::kExtreme}; }

std::vector<uint8_t> hostile_wire_message(const LcmSchema& schema, const LcmStruct& type, HostileKind kind,
                                          std::mt19937_64& rng) {
  Emitter e{schema, rng, 4, {}, {}, Values::kRandom};
  if (kind == HostileKind::kNonFinite) e.values = Values::kNonFinite;
  if (kind == HostileKind::kExtreme) e.values = Values::kExtreme;
  e.put_int(schema.fingerprint(type), 8);
  e.emit(type);
  std::vector<uint8_t> m = std::move(e.out);
  auto rewrite_length = [&](bool negative) {
    if (e.length_fields.empty()) {
      m.resize(m.size() / 2);  // no array to abuse: the closest hostile thing is a cut
      return;
    }
    const auto [at, bytes] = e.length_fields[rng() % e.length_fields.size()];
    const int64_t v = negative ? -1 - static_cast<int64_t>(rng() % 1000)
                               : static_cast<int64_t>((uint64_t{1} << (8 * bytes - 1)) - 1);
    for (std::size_t i = 0; i < bytes; ++i) m[at + i] = static_cast<uint8_t>(v >> (8 * (bytes - 1 - i)));
  };
  switch (kind) {
    case HostileKind::kTruncated:
      m.resize(rng() % m.size());
      break;
    case HostileKind::kOversized:
      for (int i = 0, n = 1 + static_cast<int>(rng() % 64); i < n; ++i)
        m.push_back(static_cast<uint8_t>(rng()));
      break;
    case HostileKind::kNegativeLength:
      rewrite_length(true);
      break;
    case HostileKind::kHugeLength:
      rewrite_length(false);
      break;
    case HostileKind::kWrongFingerprint:
      m[rng() % 8] ^= static_cast<uint8_t>(1 + rng() % 255);
      break;
    case HostileKind::kRandomBytes:
      m.resize(rng() % 256);
      for (auto& b : m) b = static_cast<uint8_t>(rng());
      break;
    case HostileKind::kBitFlip:
      for (int i = 0; i < 4 && m.size() > 8; ++i)
        m[8 + rng() % (m.size() - 8)] ^= static_cast<uint8_t>(1u << (rng() % 8));
      break;
    case HostileKind::kNonFinite:
    case HostileKind::kExtreme:
      break;  // the values are the attack
  }
  return m;
}

}  // namespace semx::runtime
