#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "all_types.hpp"
#include "semx/runtime/lcm_schema.hpp"
#include "semx/runtime/wire_generator.hpp"
#include "semx/runtime/wire_validator.hpp"

using namespace semx::runtime;

namespace {

template <class T>
void check_random_messages_round_trip(std::mt19937_64& rng) {
  const auto& schema = LcmSchema::semx();
  const auto* type = schema.find(std::string("semx.") + T::getTypeName());
  ASSERT_NE(type, nullptr);
  for (int i = 0; i < 100; ++i) {
    const auto bytes = random_wire_message(schema, *type, rng);
    ASSERT_EQ(validate_wire(schema, *type, T::getHash(), bytes.data(), bytes.size()), WireError::kNone)
        << T::getTypeName();
    ASSERT_EQ(validate_wire(schema, *type, T::getHash(), bytes.data(), bytes.size(), true), WireError::kNone)
        << T::getTypeName() << ": finite values are not refused";
    T msg;
    ASSERT_EQ(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()))
        << T::getTypeName();
    std::vector<uint8_t> again(static_cast<std::size_t>(msg.getEncodedSize()));
    ASSERT_EQ(msg.encode(again.data(), 0, static_cast<int>(again.size())), static_cast<int>(again.size()));
    EXPECT_EQ(again, bytes) << T::getTypeName() << ": the layout walked is not the layout lcm-gen encodes";
  }
}

template <class T>
void check_hostile_messages(std::mt19937_64& rng) {
  const auto& schema = LcmSchema::semx();
  const auto* type = schema.find(std::string("semx.") + T::getTypeName());
  ASSERT_NE(type, nullptr);
  for (auto kind : all_hostile_kinds()) {
    for (int i = 0; i < 50; ++i) {
      const auto bytes = hostile_wire_message(schema, *type, kind, rng);
      const WireError e = validate_wire(schema, *type, T::getHash(), bytes.data(), bytes.size());
      switch (kind) {
        case HostileKind::kTruncated:
        case HostileKind::kWrongFingerprint:
        case HostileKind::kOversized:
        case HostileKind::kNegativeLength:
        case HostileKind::kHugeLength:
          EXPECT_NE(e, WireError::kNone) << T::getTypeName() << " " << to_string(kind);
          break;
        default:
          break;  // noise and bit flips may happen to be well-formed
      }
      if (e == WireError::kNone) {
        // Whatever passes must decode within its own bytes: the validator is never laxer than
        // the generated decoder.
        T msg;
        EXPECT_EQ(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()))
            << T::getTypeName() << " " << to_string(kind);
      }
    }
  }
}

// The decodable kinds are well-formed: only a node's own checks can refuse them. non-finite
// carries a non-finite value wherever the type has a real field.
template <class T>
void check_decodable_hostile_messages(std::mt19937_64& rng) {
  const auto& schema = LcmSchema::semx();
  const auto* type = schema.find(std::string("semx.") + T::getTypeName());
  ASSERT_NE(type, nullptr);
  for (auto kind : decodable_hostile_kinds()) {
    int with_bad_value = 0, refused_non_finite = 0;
    for (int i = 0; i < 20; ++i) {
      const auto bytes = hostile_wire_message(schema, *type, kind, rng);
      ASSERT_EQ(validate_wire(schema, *type, T::getHash(), bytes.data(), bytes.size()), WireError::kNone)
          << T::getTypeName() << " " << to_string(kind);
      T msg;
      ASSERT_EQ(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()))
          << T::getTypeName() << " " << to_string(kind);
      // Nodes check reals: a non-finite message never reaches a handler; the others do.
      const WireError strict = validate_wire(schema, *type, T::getHash(), bytes.data(), bytes.size(), true);
      // Reals in arrays may be absent (length 0); 1e300 (extreme) in a float field is inf.
      EXPECT_TRUE(strict == WireError::kNone || strict == WireError::kNonFinite) << T::getTypeName();
      if (kind == HostileKind::kNonFinite && strict == WireError::kNonFinite) ++refused_non_finite;
      // utime, the first field of every message type: the extreme kind's integers reach it.
      if (kind == HostileKind::kNonFinite && has_real_field(schema, *type)) {
      EXPECT_GT(refused_non_finite, 0) << T::getTypeName();
    }
    if (kind == HostileKind::kExtreme && type->fields.front().name == "utime") {
        int64_t utime = 0;
        for (int b = 0; b < 8; ++b) utime = static_cast<int64_t>(static_cast<uint64_t>(utime) << 8 | bytes[8 + b]);
        if (utime < 0 || utime > 3) ++with_bad_value;
      }
    }
    if (kind == HostileKind::kNonFinite && has_real_field(schema, *type)) {
      EXPECT_GT(refused_non_finite, 0) << T::getTypeName();
    }
    if (kind == HostileKind::kExtreme && type->fields.front().name == "utime") {
      EXPECT_GT(with_bad_value, 0) << T::getTypeName();
    }
  }
}

}  // namespace

TEST(WireValidator, DecodableHostileMessagesOfEveryTypeDecode) {
  std::mt19937_64 rng(3);
#define DH(T) check_decodable_hostile_messages<semx::T>(rng);
  SEMX_ALL_TYPES(DH)
#undef DH
}

TEST(WireValidator, NonFiniteMessagesCarryNonFiniteValues) {
  const auto& schema = LcmSchema::semx();
  const auto* type = schema.find("semx.odometry_t");
  ASSERT_NE(type, nullptr);
  ASSERT_TRUE(has_real_field(schema, *type));
  std::mt19937_64 rng(4);
  for (int i = 0; i < 20; ++i) {
    const auto bytes = hostile_wire_message(schema, *type, HostileKind::kNonFinite, rng);
    semx::odometry_t o;
    ASSERT_EQ(o.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
    for (double v : o.position) EXPECT_FALSE(std::isfinite(v));
    for (double v : o.velocity) EXPECT_FALSE(std::isfinite(v));
  }
}

TEST(WireValidator, RandomMessagesOfEveryTypeValidateDecodeAndReencodeIdentically) {
  std::mt19937_64 rng(1);
#define RT(T) check_random_messages_round_trip<semx::T>(rng);
  SEMX_ALL_TYPES(RT)
#undef RT
}

TEST(WireValidator, HostileMessagesOfEveryTypeAreRejectedOrDecodable) {
  std::mt19937_64 rng(2);
#define HM(T) check_hostile_messages<semx::T>(rng);
  SEMX_ALL_TYPES(HM)
#undef HM
}

TEST(WireValidator, NamesTheDefect) {
  const auto& schema = LcmSchema::semx();
  const auto& type = *schema.find("semx.map_update_t");
  semx::map_update_t m;
  m.utime = 1;
  m.seq = 2;
  m.resolution = 0.1;
  m.num_voxels = 2;
  m.key_x = {1, 2};
  m.key_y = {3, 4};
  m.key_z = {5, 6};
  m.state = {1, 2};
  std::vector<uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  const int64_t h = semx::map_update_t::getHash();
  EXPECT_EQ(validate_wire(schema, type, h, b.data(), b.size()), WireError::kNone);
  EXPECT_EQ(validate_wire(schema, type, h, b.data(), 4), WireError::kTooShort);
  EXPECT_EQ(validate_wire(schema, type, h, b.data(), b.size() - 1), WireError::kLengthExceedsBuffer);
  EXPECT_EQ(validate_wire(schema, type, h + 1, b.data(), b.size()), WireError::kFingerprint);
  auto longer = b;
  longer.push_back(0);
  EXPECT_EQ(validate_wire(schema, type, h, longer.data(), longer.size()), WireError::kTrailingBytes);
  // num_voxels sits after fingerprint (8), utime (8), seq (8), resolution (8).
  auto neg = b;
  neg[32] = 0xFF;
  EXPECT_EQ(validate_wire(schema, type, h, neg.data(), neg.size()), WireError::kNegativeLength);
  auto huge = b;
  huge[32] = 0x7F;
  huge[33] = huge[34] = huge[35] = 0xFF;
  EXPECT_EQ(validate_wire(schema, type, h, huge.data(), huge.size()), WireError::kLengthExceedsBuffer);
}

TEST(WireValidator, RejectsBadStrings) {
  const auto& schema = LcmSchema::semx();
  const auto& type = *schema.find("semx.ack_t");
  semx::ack_t a{};
  a.utime = 5;
  a.node = "mapper";
  a.tick = 7;
  std::vector<uint8_t> b(static_cast<std::size_t>(a.getEncodedSize()));
  a.encode(b.data(), 0, static_cast<int>(b.size()));
  const int64_t h = semx::ack_t::getHash();
  ASSERT_EQ(validate_wire(schema, type, h, b.data(), b.size()), WireError::kNone);
  auto zero_len = b;  // string length at offset 16; a length of 0 makes the decoder assign -1 bytes
  zero_len[16] = zero_len[17] = zero_len[18] = zero_len[19] = 0;
  EXPECT_NE(validate_wire(schema, type, h, zero_len.data(), zero_len.size()), WireError::kNone);
  auto no_nul = b;
  no_nul[16 + 4 + 6] = 'x';
  EXPECT_EQ(validate_wire(schema, type, h, no_nul.data(), no_nul.size()), WireError::kBadString);
}

TEST(GeneratedCode, InlinedDecodeOfDoublesIsReadBack) {
  // lcm_coretypes.h writes doubles through int64_t*; without -fno-strict-aliasing GCC -O2 may
  // read the double from before the decode. This is the pattern every handler uses.
  semx::odometry_t in{};
  in.utime = 5;
  in.position[0] = 2.0;
  in.position[1] = 3.0;
  in.velocity[2] = -1.5;
  std::vector<uint8_t> b(static_cast<std::size_t>(in.getEncodedSize()));
  in.encode(b.data(), 0, static_cast<int>(b.size()));
  semx::odometry_t out{};
  ASSERT_EQ(out.decode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
  EXPECT_EQ(out.position[0], 2.0);
  EXPECT_EQ(out.position[1], 3.0);
  EXPECT_EQ(out.velocity[2], -1.5);
}
