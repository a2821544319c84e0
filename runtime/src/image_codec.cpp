#include "semx/runtime/image_codec.hpp"

#include <zlib.h>

#include <algorithm>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#define SEMX_CODEC_SSE2 1
#else
#define SEMX_CODEC_SSE2 0
#endif

namespace semx::runtime {

namespace {

// Pixels [0, run) starting at `a` are all equal exactly when a[k] == a[k + PX] for every k below
// (run - 1) * PX, so the end of a run is the first byte that differs from the one PX bytes on.
// Compared 16 or 32 bytes at a time, that is a few instructions for the ~100-pixel runs of a
// label or RGB image, where a pixel-by-pixel compare took most of the encoding time. `check` is
// how many such bytes may be compared (the cap on the run and the image end); returns the run
// in pixels, at most check / PX + 1.
template <std::size_t PX>
std::size_t run_length(const uint8_t* a, std::size_t check) {
  std::size_t k = 0;
#if SEMX_CODEC_SSE2
  auto same = [a](std::size_t at) {
    return _mm_cmpeq_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + at)),
                          _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + at + PX)));
  };
  // 32 bytes per test while the run goes on, which is most of the time.
  for (; k + 32 <= check; k += 32) {
    if (_mm_movemask_epi8(_mm_and_si128(same(k), same(k + 16))) != 0xFFFF) break;
  }
  for (; k + 16 <= check; k += 16) {
    const unsigned differ = static_cast<unsigned>(_mm_movemask_epi8(same(k))) ^ 0xFFFFu;
    if (differ) return 1 + (k + static_cast<std::size_t>(__builtin_ctz(differ))) / PX;
  }
#endif
  for (; k < check; ++k) {
    if (a[k] != a[k + PX]) return 1 + k / PX;
  }
  return 1 + check / PX;
}

// Fixed pixel sizes let the compiler turn the divisions and copies into a few instructions.
// Encodes into `out` (grown, never shrunk, so a caller's reused buffer costs no allocation and
// no zeroing) and returns the payload size, or 0 when it would not be smaller than the raw bytes.
template <std::size_t PX>
std::size_t rle_encode_fixed(const uint8_t* p, std::size_t size, std::vector<uint8_t>& out) {
  constexpr std::size_t kMaxRun = 0xFFFF;
  if (out.size() < size + 1) out.resize(size + 1);
  uint8_t* o = out.data();
  // Past this point a record would make the payload no smaller than the raw image.
  uint8_t* const limit = out.data() + size - (2 + PX);
  *o++ = static_cast<uint8_t>(PX);
  std::size_t at = 0;  // byte offset of the current run
  while (at < size) {
    const std::size_t check = std::min(size - at - PX, (kMaxRun - 1) * PX);
    const std::size_t run = run_length<PX>(p + at, check);
    if (o > limit) return 0;  // not worth it: the caller sends raw bytes
    *o++ = static_cast<uint8_t>(run & 0xFF);
    *o++ = static_cast<uint8_t>(run >> 8);
    std::memcpy(o, p + at, PX);
    o += PX;
    at += run * PX;
  }
  return static_cast<std::size_t>(o - out.data());
}

std::size_t rle_encode(const uint8_t* raw, std::size_t size, std::size_t px, std::vector<uint8_t>& out) {
  if (size < 2 + px + 1) return 0;
  switch (px) {
    case 1: return rle_encode_fixed<1>(raw, size, out);
    case 2: return rle_encode_fixed<2>(raw, size, out);
    case 3: return rle_encode_fixed<3>(raw, size, out);
    case 4: return rle_encode_fixed<4>(raw, size, out);
    default: return 0;
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
    // The worst case we accept is the raw size, far above the typical ~2 %: encoding into a
    // reused buffer and copying out the result spares zeroing a megabyte per frame.
    thread_local std::vector<uint8_t> scratch;
    const std::size_t n = rle_encode(raw, size, pixel_bytes, scratch);
    if (n > 0) {
      used = ImageCompression::kRle;
      return std::vector<uint8_t>(scratch.begin(), scratch.begin() + static_cast<std::ptrdiff_t>(n));
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
