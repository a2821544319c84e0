#include <gtest/gtest.h>

#include <set>

#include "all_types.hpp"
#include "semx/runtime/channels.hpp"
#include "semx/runtime/lcm_schema.hpp"

using semx::runtime::LcmSchema;
using semx::runtime::LcmSchemaError;

TEST(LcmSchema, FingerprintOfEveryTypeMatchesLcmGen) {
  const auto& schema = LcmSchema::semx();
  int checked = 0;
#define CHECK_TYPE(T)                                            \
  {                                                              \
    const auto* s = schema.find("semx." #T);                     \
    ASSERT_NE(s, nullptr) << #T;                                 \
    EXPECT_EQ(schema.fingerprint(*s), semx::T::getHash()) << #T; \
    ++checked;                                                   \
  }
  SEMX_ALL_TYPES(CHECK_TYPE)
#undef CHECK_TYPE
  EXPECT_EQ(checked, static_cast<int>(schema.structs().size())) << "a type is missing from all_types.hpp";
}

TEST(LcmSchema, NoTwoTypesShareAFingerprint) {
  // LCM's fingerprint ignores type names: equal field lists would make one type decode as another.
  const auto& schema = LcmSchema::semx();
  std::set<int64_t> seen;
  for (const auto& [name, s] : schema.structs()) {
    EXPECT_TRUE(seen.insert(schema.fingerprint(s)).second) << name << " collides with another type";
  }
}

TEST(LcmSchema, EveryChannelHasAKnownTypeWithUtimeFirst) {
  const auto& schema = LcmSchema::semx();
  std::set<std::string_view> types;
  for (const auto& c : semx::channels::kAll) {
    const auto* s = schema.find(c.type);
    ASSERT_NE(s, nullptr) << c.channel;
    ASSERT_FALSE(s->fields.empty());
    EXPECT_EQ(s->fields.front().name, "utime") << c.type;
    EXPECT_EQ(s->fields.front().type_name, "int64_t") << c.type;
    EXPECT_TRUE(types.insert(c.type).second) << "one type per channel: " << c.type << " is used twice";
  }
}

TEST(LcmSchema, ParsesDimensionsAndConstants) {
  const auto schema = LcmSchema::parse({{"t.lcm", R"(package p;
    /* block
       comment */
    struct a_t {
      int64_t utime;   // trailing comment
      const int8_t X = 1, Y = -2;
      int16_t n;
      double m[n][3];
      string names[2];
    })"}});
  const auto* s = schema.find("p.a_t");
  ASSERT_NE(s, nullptr);
  ASSERT_EQ(s->fields.size(), 4u);
  const auto& m = s->fields[2];
  ASSERT_EQ(m.dims.size(), 2u);
  EXPECT_TRUE(m.dims[0].variable);
  EXPECT_EQ(m.dims[0].field_index, 1);
  EXPECT_FALSE(m.dims[1].variable);
  EXPECT_EQ(m.dims[1].size, 3);
  EXPECT_EQ(schema.min_encoded_size(*s), 8u + 2u + 2u * 5u);
}

TEST(LcmSchema, ErrorsNameFileAndLine) {
  try {
    LcmSchema::parse({{"bad.lcm", "package p;\nstruct a_t {\n  int32_t x[n];\n}\n"}});
    FAIL() << "expected an error";
  } catch (const LcmSchemaError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.lcm:3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LcmSchema::parse({{"u.lcm", "package p; struct a_t { q_t x; }"}}), LcmSchemaError);
  EXPECT_THROW(LcmSchema::parse({{"e.lcm", "package p; struct a_t { int32_t x;"}}), LcmSchemaError);
}

#include <fstream>
#include <sstream>

TEST(LcmSchema, MessagesDocNamesEveryChannelAndType) {
  std::ifstream in(std::string(SEMX_SOURCE_DIR) + "/docs/messages.md");
  ASSERT_TRUE(in.good());
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string doc = ss.str();
  for (const auto& c : semx::channels::kAll) {
    EXPECT_NE(doc.find("`" + std::string(c.channel) + "`"), std::string::npos)
        << c.channel << " undocumented";
  }
  for (const auto& [name, s] : LcmSchema::semx().structs()) {
    EXPECT_NE(doc.find("**`" + s.name + "`**"), std::string::npos) << s.name << " undocumented";
  }
}
