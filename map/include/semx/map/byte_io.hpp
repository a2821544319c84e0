// zlib helpers shared by the snapshot and checkpoint codecs (the byte packing is core's).
#pragma once

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "semx/core/byte_io.hpp"

namespace semx::map::detail {

using core::ByteReader;
using core::ByteWriter;

inline std::vector<uint8_t> zlib_compress(const std::vector<uint8_t>& raw, int level) {
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::vector<uint8_t> out(size);
  if (compress2(out.data(), &size, raw.data(), static_cast<uLong>(raw.size()), level) != Z_OK) {
    throw std::runtime_error("zlib compression failed");
  }
  out.resize(size);
  return out;
}

// Inflates exactly `expected` bytes; false if the stream is corrupt or of another length.
inline bool zlib_decompress(const uint8_t* data, size_t size, size_t expected, std::vector<uint8_t>& out) {
  out.resize(expected);
  uLongf got = static_cast<uLongf>(expected);
  const int rc = uncompress(out.data(), &got, data, static_cast<uLong>(size));
  return rc == Z_OK && got == expected;
}

inline uint32_t crc32_of(const uint8_t* data, size_t size) {
  return static_cast<uint32_t>(crc32(crc32(0L, Z_NULL, 0), data, static_cast<uInt>(size)));
}

}  // namespace semx::map::detail
