#include <gtest/gtest.h>

#include "semx/runtime/args.hpp"

using namespace semx::runtime;

namespace {
bool parse(ArgParser& p, std::vector<const char*> argv) {
  argv.insert(argv.begin(), "prog");
  return p.parse(static_cast<int>(argv.size()), argv.data());
}
}  // namespace

TEST(Args, ParsesEveryKind) {
  std::string world;
  double speed = 1;
  int64_t seed = 0;
  bool lockstep = false;
  std::vector<std::string> sets;
  std::string pos;
  ArgParser p("prog", "test");
  p.option("world", "FILE", "world", &world)
      .option("speed", "X", "speed", &speed)
      .option("seed", "N", "seed", &seed)
      .flag("lockstep", "lockstep", &lockstep)
      .repeated("set", "K=V", "override", &sets)
      .positional("INPUT", "input", &pos);
  ASSERT_TRUE(parse(p, {"--world", "w.yaml", "--speed=2.5", "--seed", "-3", "--lockstep", "--set", "a=1",
                        "--set=b=2", "in"}));
  EXPECT_EQ(world, "w.yaml");
  EXPECT_EQ(speed, 2.5);
  EXPECT_EQ(seed, -3);
  EXPECT_TRUE(lockstep);
  EXPECT_EQ(sets, (std::vector<std::string>{"a=1", "b=2"}));
  EXPECT_EQ(pos, "in");
}

TEST(Args, ErrorsNameTheFlag) {
  double speed = 1;
  std::string pos;
  ArgParser p("prog", "test");
  p.option("speed", "X", "speed", &speed).positional("INPUT", "input", &pos, false);
  auto message = [&](std::vector<const char*> argv) -> std::string {
    try {
      parse(p, argv);
    } catch (const ArgError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message({"--sped", "1"}).find("unknown flag '--sped'"), std::string::npos);
  EXPECT_NE(message({"--speed"}).find("--speed needs a value"), std::string::npos);
  EXPECT_NE(message({"--speed", "fast"}).find("'fast' is not a number"), std::string::npos);
  EXPECT_NE(message({"a", "b"}).find("unexpected argument 'b'"), std::string::npos);
}

TEST(Args, HelpStopsParsingAndRunMainMapsErrorsToExitCodes) {
  ArgParser p("prog", "does things");
  testing::internal::CaptureStdout();
  EXPECT_FALSE(parse(p, {"--help"}));
  EXPECT_NE(testing::internal::GetCapturedStdout().find("does things"), std::string::npos);
  testing::internal::CaptureStderr();
  EXPECT_EQ(run_main("prog", []() -> int { throw ArgError("bad flag"); }), 2);
  EXPECT_EQ(run_main("prog", []() -> int { throw std::runtime_error("boom"); }), 1);
  EXPECT_EQ(run_main("prog", [] { return 0; }), 0);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("prog: bad flag"), std::string::npos);
}
