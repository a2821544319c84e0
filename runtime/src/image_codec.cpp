#include "semx/runtime/image_codec.hpp"

#include <zlib.h>

#include <cstring>

namespace semx::runtime {

namespace {

// Fixed pixel sizes let the compiler turn the comparisons into single loads; output is written
// through a pointer into a buffer sized for the worst case we accept (the raw size).
template <std::size_t PX>
std::vector<uint8_t> rle_encode_fixed(const uint8_t* p, std::size_t size) {
  const std::size_t n = size / PX;
  // Sized for what we accept (smaller than raw), shrunk at the end.
  std::vector<uint8_t> out(size + 1);
  uint8_t* o = out.data();
  uint8_t* const limit = out.data() + size - (2 + PX);
  *o++ = static_cast<uint8_t>(PX);
  std::size_t i = 0;
  while (i < n) {
    const uint8_t* start = p + i * PX;
    std::size_t run = 1;
    while (i + run < n && run < 0xFFFF && std::memcmp(start, start + run * PX, PX) == 0) ++run;
    if (o > limit) return {};  // not worth it: the caller sends raw bytes
    *o++ = static_cast<uint8_t>(run & 0xFF);
    *o++ = static_cast<uint8_t>(run >> 8);
    std::memcpy(o, start, PX);
    o += PX;
    i += run;
  }
  out.resize(static_cast<std::size_t>(o - out.data()));
  return out;
}

std::vector<uint8_t> rle_encode(const uint8_t* raw, std::size_t size, std::size_t px) {
  if (size < 2 + px + 1) return {};
  switch (px) {
    case 1: return rle_encode_fixed<1>(raw, size);
    case 2: return rle_encode_fixed<2>(raw, size);
    case 3: return rle_encode_fixed<3>(raw, size);
    case 4: return rle_encode_fixed<4>(raw, size);
    default: return {};
  }
}

bool fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

}  // namespace

std::vector<uint8_t> encode_image(const uint8_t* raw, std::size_t size, std::size_t pixel_bytes,
                                  ImageCompression wanted, ImageCompression& used) {
  used = ImageCompression::kNone;
  if (wanted == ImageCompression::kRle && pixel_bytes > 0 && pixel_bytes < 256 && size % pixel_bytes == 0) {
    std::vector<uint8_t> out = rle_encode(raw, size, pixel_bytes);
    if (!out.empty()) {
      used = ImageCompression::kRle;
      return out;
    }
  } else if (wanted == ImageCompression::kZlib) {
    uLongf packed = compressBound(size);
    std::vector<uint8_t> out(packed);
    if (compress2(out.data(), &packed, raw, size, 1) == Z_OK && packed < size) {
      out.resize(packed);
      used = ImageCompression::kZlib;
      return out;
    }
  }
  return std::vector<uint8_t>(raw, raw + size);
}

bool decode_image(int8_t compression, const std::vector<uint8_t>& payload, std::size_t expected_bytes,
                  std::vector<uint8_t>& out, std::string* error) {
  switch (static_cast<ImageCompression>(compression)) {
    case ImageCompression::kNone:
      if (payload.size() != expected_bytes) {
        return fail(error, "raw image of " + std::to_string(payload.size()) + " bytes, expected " +
                               std::to_string(expected_bytes));
      }
      out = payload;
      return true;
    case ImageCompression::kZlib: {
      out.resize(expected_bytes);
      uLongf size = expected_bytes;
      if (uncompress(out.data(), &size, payload.data(), payload.size()) != Z_OK || size != expected_bytes) {
        return fail(error, "zlib payload does not decode to " + std::to_string(expected_bytes) + " bytes");
      }
      return true;
    }
    case ImageCompression::kRle: {
      if (payload.empty()) return fail(error, "empty RLE payload");
      const std::size_t pixel_bytes = payload[0];
      if (pixel_bytes == 0 || expected_bytes % pixel_bytes != 0) return fail(error, "bad RLE pixel size");
      out.resize(expected_bytes);
      std::size_t at = 1, written = 0;
      const std::size_t record = 2 + pixel_bytes;
      while (at < payload.size()) {
        if (payload.size() - at < record) return fail(error, "truncated run");
        const std::size_t run = payload[at] | static_cast<std::size_t>(payload[at + 1]) << 8;
        if (run == 0 || run * pixel_bytes > expected_bytes - written) return fail(error, "run overflows the image");
        const uint8_t* px = payload.data() + at + 2;
        for (std::size_t k = 0; k < run; ++k, written += pixel_bytes) {
          std::memcpy(out.data() + written, px, pixel_bytes);
        }
        at += record;
      }
      if (written != expected_bytes) return fail(error, "runs cover " + std::to_string(written) + " of " +
                                                            std::to_string(expected_bytes) + " bytes");
      return true;
    }
  }
  return fail(error, "unknown compression " + std::to_string(compression));
}

}  // namespace semx::runtime
