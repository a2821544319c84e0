// ChannelPattern: liblcm's channel regexes (whole-name, POSIX extended), remembered per name.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "semx/runtime/channel_pattern.hpp"

using semx::runtime::ChannelPattern;

TEST(ChannelPattern, MatchesWholeNamesAndKeepsAnsweringPastItsMemory) {
  const ChannelPattern p("CAMERA_.*|ESDF_LOCAL");
  EXPECT_TRUE(p.matches("CAMERA_DEPTH"));
  EXPECT_TRUE(p.matches("ESDF_LOCAL"));
  EXPECT_FALSE(p.matches("ESDF_LOCAL_2"));  // whole name, not a prefix
  EXPECT_FALSE(p.matches("MY_CAMERA_DEPTH"));
  EXPECT_TRUE(p.matches("CAMERA_DEPTH"));  // the remembered answer is the same
  // More names than it remembers: answers stay right after the memory is cleared.
  for (int i = 0; i < 3000; ++i) {
    EXPECT_EQ(p.matches("CAMERA_" + std::to_string(i)), true);
    EXPECT_EQ(p.matches("OTHER_" + std::to_string(i)), false);
  }
  EXPECT_TRUE(p.matches("ESDF_LOCAL"));
}

TEST(ChannelPattern, ABadPatternIsAnErrorNamingIt) {
  try {
    ChannelPattern p("CAMERA_(");
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'CAMERA_('"), std::string::npos) << e.what();
  }
}
