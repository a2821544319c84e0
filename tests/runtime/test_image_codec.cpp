#include <gtest/gtest.h>

#include <random>

#include "semx/runtime/image_codec.hpp"

using namespace semx::runtime;

namespace {

// A label-like image: constant runs with a few changes per row.
std::vector<uint8_t> blocky(std::size_t pixels, std::size_t px, std::mt19937& rng) {
  std::vector<uint8_t> raw(pixels * px);
  uint8_t value = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    if (rng() % 97 == 0) value = static_cast<uint8_t>(rng());
    for (std::size_t b = 0; b < px; ++b) raw[i * px + b] = static_cast<uint8_t>(value + b);
  }
  return raw;
}

}  // namespace

TEST(ImageCodec, EveryCodecRoundTrips) {
  std::mt19937 rng(4);
  for (std::size_t px : {2u, 3u, 4u}) {
    const auto raw = blocky(640 * 48, px, rng);
    for (auto codec : {ImageCompression::kNone, ImageCompression::kZlib, ImageCompression::kRle}) {
      ImageCompression used;
      const auto payload = encode_image(raw, px, codec, used);
      EXPECT_EQ(used, codec);
      std::vector<uint8_t> back;
      std::string error;
      ASSERT_TRUE(decode_image(static_cast<int8_t>(used), payload, raw.size(), back, &error)) << error;
      EXPECT_EQ(back, raw);
      if (codec == ImageCompression::kRle) {
        EXPECT_LT(payload.size() * 10, raw.size()) << "runs shrink it";
      }
    }
  }
}

TEST(ImageCodec, RunsLongerThanACountSplit) {
  const std::vector<uint8_t> raw(200000 * 4, 7);
  ImageCompression used;
  const auto payload = encode_image(raw, 4, ImageCompression::kRle, used);
  ASSERT_EQ(used, ImageCompression::kRle);
  std::vector<uint8_t> back;
  ASSERT_TRUE(decode_image(2, payload, raw.size(), back));
  EXPECT_EQ(back, raw);
}

TEST(ImageCodec, NoiseFallsBackToRaw) {
  std::mt19937 rng(5);
  std::vector<uint8_t> raw(30000);
  for (auto& b : raw) b = static_cast<uint8_t>(rng());
  ImageCompression used;
  const auto payload = encode_image(raw, 2, ImageCompression::kRle, used);
  EXPECT_EQ(used, ImageCompression::kNone);
  EXPECT_EQ(payload, raw);
}

TEST(ImageCodec, HostilePayloadsAreRejectedWithinTheExpectedSize) {
  std::vector<uint8_t> out;
  std::string error;
  const std::size_t expected = 640 * 480 * 4;
  EXPECT_FALSE(decode_image(2, {}, expected, out, &error));
  EXPECT_FALSE(decode_image(2, {4, 0xFF, 0xFF, 1, 2, 3}, expected, out, &error)) << "truncated run";
  EXPECT_FALSE(decode_image(2, {4, 0, 0, 1, 2, 3, 4}, expected, out, &error)) << "zero-length run";
  EXPECT_FALSE(decode_image(2, {4, 0xFF, 0xFF, 1, 2, 3, 4}, 8, out, &error)) << "run past the image";
  EXPECT_FALSE(decode_image(2, {0, 1, 0}, expected, out, &error)) << "pixel size 0";
  EXPECT_FALSE(decode_image(2, {3, 1, 0, 1, 2, 3}, 8, out, &error)) << "pixel size not dividing the image";
  EXPECT_FALSE(decode_image(2, {4, 1, 0, 1, 2, 3, 4}, expected, out, &error)) << "runs short of the image";
  EXPECT_FALSE(decode_image(1, {1, 2, 3, 4, 5}, expected, out, &error)) << "zlib garbage";
  EXPECT_FALSE(decode_image(0, {1, 2, 3}, expected, out, &error)) << "raw of the wrong size";
  EXPECT_FALSE(decode_image(9, {1, 2, 3}, expected, out, &error));
  EXPECT_NE(error.find("unknown compression 9"), std::string::npos) << error;
  EXPECT_LE(out.size(), expected);
}
