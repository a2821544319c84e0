#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>

#include "semx/runtime/config.hpp"

using namespace semx::runtime;

namespace {

struct Inner {
  int k = 3;
  std::vector<double> v{1.0, 2.0};
};
struct Demo {
  double rate = 30.0;
  int count = 5;
  bool flag = false;
  std::string mode = "a";
  Inner inner;
  std::vector<std::string> names;
};

void load(ConfigMap& m, Demo& d) {
  m.get("rate", d.rate, 1.0, 100.0);
  m.get("count", d.count);
  m.get("flag", d.flag);
  m.get_choice("mode", d.mode, {"a", "b"});
  auto inner = m.child("inner");
  inner.get("k", d.inner.k, 0, 10);
  inner.get("v", d.inner.v);
  for (auto& item : m.children("items")) {
    std::string name;
    item.get("name", name);
    d.names.push_back(name);
  }
}

std::string error_of(const std::string& yaml) {
  try {
    auto m = ConfigMap::from_string(yaml, "demo.yaml");
    Demo d;
    load(m, d);
    m.finish();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST(Config, DefaultsWhenEmpty) {
  const Demo d = load_config<Demo>("");
  EXPECT_EQ(d.rate, 30.0);
  EXPECT_EQ(d.inner.k, 3);
}

TEST(Config, ReadsEveryKind) {
  auto m = ConfigMap::from_string(
      "rate: 10\ncount: -2\nflag: true\nmode: b\ninner: {k: 7, v: [0.5]}\nitems:\n  - name: x\n  - name: y\n",
      "demo.yaml");
  Demo d;
  load(m, d);
  m.finish();
  EXPECT_EQ(d.rate, 10.0);
  EXPECT_EQ(d.count, -2);
  EXPECT_TRUE(d.flag);
  EXPECT_EQ(d.mode, "b");
  EXPECT_EQ(d.inner.k, 7);
  EXPECT_EQ(d.inner.v, std::vector<double>{0.5});
  EXPECT_EQ(d.names, (std::vector<std::string>{"x", "y"}));
}

TEST(Config, UnknownKeyIsNamedWithItsLine) {
  const auto e = error_of("rate: 10\nrat: 11\n");
  EXPECT_TRUE(contains(e, "demo.yaml:2")) << e;
  EXPECT_TRUE(contains(e, "unknown key 'rat'")) << e;
}

TEST(Config, UnknownNestedKeysAreFound) {
  EXPECT_TRUE(contains(error_of("inner:\n  k: 1\n  kk: 2\n"), "unknown key 'inner.kk'"));
  EXPECT_TRUE(contains(error_of("items:\n  - name: a\n    nme: b\n"), "unknown key 'items[0].nme'"));
}

TEST(Config, WrongTypeIsNamed) {
  const auto e = error_of("rate: 10\ncount: 1.5\n");
  EXPECT_TRUE(contains(e, "demo.yaml:2")) << e;
  EXPECT_TRUE(contains(e, "'count'")) << e;
  EXPECT_TRUE(contains(e, "integer")) << e;
  EXPECT_TRUE(contains(error_of("rate: fast\n"), "expected a number"));
  EXPECT_TRUE(contains(error_of("inner: 3\n"), "mapping"));
  EXPECT_TRUE(contains(error_of("rate: .nan\n"), "expected a number"));
}

TEST(Config, OutOfRangeIsNamed) {
  const auto e = error_of("rate: 1000\n");
  EXPECT_TRUE(contains(e, "outside [1, 100]")) << e;
  EXPECT_TRUE(contains(error_of("mode: c\n"), "not one of: a, b"));
}

TEST(Config, SyntaxErrorAndMissingFile) {
  EXPECT_TRUE(contains(error_of("rate: [1,\n"), "demo.yaml:"));
  try {
    ConfigMap::from_file("/nonexistent/semx.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_TRUE(contains(e.what(), "/nonexistent/semx.yaml")) << e.what();
  }
}

TEST(Config, OverridesApplyOnTopOfTheFile) {
  const std::string path = testing::TempDir() + "/semx_config_test.yaml";
  std::ofstream(path) << "rate: 10\ninner:\n  k: 1\n";
  const Demo d = load_config<Demo>(path, {"inner.k=9", "count=4"});
  EXPECT_EQ(d.rate, 10.0);
  EXPECT_EQ(d.inner.k, 9);
  EXPECT_EQ(d.count, 4);
  EXPECT_THROW(load_config<Demo>(path, {"nonsense"}), ConfigError);
  EXPECT_THROW(load_config<Demo>(path, {"inner.k=99"}), ConfigError);
  EXPECT_THROW(load_config<Demo>(path, {"typo=1"}), ConfigError);
}

TEST(Config, TheEffectiveConfigurationSaysWhereEveryValueCameFrom) {
  const std::string path = testing::TempDir() + "/semx_config_effective.yaml";
  std::ofstream(path) << "rate: 10\ninner:\n  k: 1\n";
  const std::string out = testing::TempDir() + "/semx_config_effective.out.yaml";
  setenv(kEffectiveConfigEnv, out.c_str(), 1);
  const std::size_t before = effective_config().size();
  testing::internal::CaptureStderr();
  const Demo d = load_config<Demo>(path, {"inner.k=9", "count=4", "rate=10"});
  const std::string note = testing::internal::GetCapturedStderr();
  unsetenv(kEffectiveConfigEnv);
  EXPECT_EQ(d.inner.k, 9);

  std::map<std::string, EffectiveValue> by_key;
  for (std::size_t i = before; i < effective_config().size(); ++i) by_key[effective_config()[i].key] = effective_config()[i];
  ASSERT_TRUE(by_key.count("rate") && by_key.count("count") && by_key.count("inner.k") && by_key.count("mode") &&
              by_key.count("inner.v"));
  EXPECT_EQ(by_key["rate"].value, "10");
  EXPECT_EQ(by_key["rate"].origin, "--set") << "set twice: the flag is what counts";
  EXPECT_EQ(by_key["inner.k"].value, "9");
  EXPECT_EQ(by_key["inner.k"].origin, "--set");
  EXPECT_EQ(by_key["count"].origin, "--set");
  EXPECT_EQ(by_key["mode"].value, "a");
  EXPECT_EQ(by_key["mode"].origin, "default");
  EXPECT_EQ(by_key["inner.v"].value, "[1, 2]");
  EXPECT_EQ(load_config<Demo>(path).rate, 10.0);
  EXPECT_EQ(effective_config().back().key, "inner.v");
  for (std::size_t i = 0; i < effective_config().size(); ++i) {
    if (effective_config()[i].key == "rate" && i >= before + by_key.size()) {
      EXPECT_EQ(effective_config()[i].origin, path) << "from the file when no flag sets it";
    }
  }
  // A flag that replaces the file's value says so; one that repeats it does not.
  EXPECT_TRUE(contains(note, "--set inner.k=9 replaces inner.k: 1 from " + path + ":3")) << note;
  EXPECT_FALSE(contains(note, "rate")) << note;
  // The file the launcher asks for.
  std::ifstream in(out);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_TRUE(contains(ss.str(), "inner.k: 9")) << ss.str();
  EXPECT_TRUE(contains(ss.str(), "# --set")) << ss.str();
  EXPECT_TRUE(contains(ss.str(), "# default")) << ss.str();
}
