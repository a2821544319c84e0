// Lossless payload codecs for camera images (docs/messages.md). The simulator's label and RGB
// images are piecewise constant (one class, instance and flat-shaded colour per visible face),
// so a run-length code of whole pixels shrinks them ~20-50x at a fraction of a millisecond,
// where zlib costs several: on loopback the bytes, not the CPU, were the simulator's limit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace semx::runtime {

// Values of the *_compression fields of depth_image_t, rgb_image_t and label_image_t.
enum class ImageCompression : int8_t {
  kNone = 0,  // raw bytes
  kZlib = 1,  // zlib stream of the raw bytes
  kRle = 2,   // [uint8 pixel size], then runs [uint16 LE count >= 1][one pixel's bytes] covering the image
};

// Encodes `raw` (pixels of `pixel_bytes` each) with `wanted`; falls back to kNone when the
// encoding would not be smaller. Returns the payload and sets `used` to the codec applied.
std::vector<uint8_t> encode_image(const uint8_t* raw, std::size_t size, std::size_t pixel_bytes,
                                  ImageCompression wanted, ImageCompression& used);
inline std::vector<uint8_t> encode_image(const std::vector<uint8_t>& raw, std::size_t pixel_bytes,
                                         ImageCompression wanted, ImageCompression& used) {
  return encode_image(raw.data(), raw.size(), pixel_bytes, wanted, used);
}

// Decodes a payload into exactly `expected_bytes` raw bytes. False (with `error` set) for an
// unknown codec, a corrupt payload or a size mismatch: a hostile payload cannot make it write
// or allocate beyond `expected_bytes`.
bool decode_image(int8_t compression, const std::vector<uint8_t>& payload, std::size_t expected_bytes,
                  std::vector<uint8_t>& out, std::string* error = nullptr);

}  // namespace semx::runtime
