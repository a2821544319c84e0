#include "semx/runtime/wire_generator.hpp"

#include <cstring>
#include <limits>

namespace semx::runtime {

namespace {

struct Emitter {
  const LcmSchema& schema;
  std::mt19937_64& rng;
  int max_array;
  std::vector<uint8_t> out;
  // Offsets of the array-size fields written so far, with their byte widths, so hostile
  // variants can rewrite one.
  std::vector<std::pair<std::size_t, std::size_t>> length_fields;

  void put_int(int64_t v, std::size_t bytes) {
    for (std::size_t i = 0; i < bytes; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * (bytes - 1 - i))));
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
              // Finite values only: NaN payloads are tested separately by the consumers.
              std::uniform_real_distribution<double> u(-1e3, 1e3);
              if (f.kind == LcmPrimitive::kFloat) {
                const float v = static_cast<float>(u(rng));
                uint32_t bits;
                std::memcpy(&bits, &v, 4);
                put_int(bits, 4);
              } else {
                const double v = u(rng);
                uint64_t bits;
                std::memcpy(&bits, &v, 8);
                put_int(static_cast<int64_t>(bits), 8);
              }
            } else {
              const int64_t v = static_cast<int64_t>(rng());
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
  Emitter e{schema, rng, max_array, {}, {}};
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
  }
  return "?";
}

std::vector<HostileKind> all_hostile_kinds() {
  return {HostileKind::kTruncated,  HostileKind::kOversized,        HostileKind::kNegativeLength,
          HostileKind::kHugeLength, HostileKind::kWrongFingerprint, HostileKind::kRandomBytes,
          HostileKind::kBitFlip};
}

std::vector<uint8_t> hostile_wire_message(const LcmSchema& schema, const LcmStruct& type, HostileKind kind,
                                          std::mt19937_64& rng) {
  Emitter e{schema, rng, 4, {}, {}};
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
  }
  return m;
}

}  // namespace semx::runtime
