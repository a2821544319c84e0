// A dense row-major image: the simulator's frame buffers and the camera's outputs.
#pragma once

#include <cstdint>
#include <vector>

namespace semx::simulator {

struct Rgb {
  uint8_t r = 0;
  uint8_t g = 0;
  uint8_t b = 0;
  friend bool operator==(const Rgb& a, const Rgb& b) { return a.r == b.r && a.g == b.g && a.b == b.b; }
  friend bool operator!=(const Rgb& a, const Rgb& b) { return !(a == b); }
};

template <class T>
struct Image {
  int width = 0;
  int height = 0;
  std::vector<T> data;  // row v starts at data[v * width]

  Image() = default;
  Image(int w, int h, T fill = T{}) : width(w), height(h), data(static_cast<size_t>(w) * h, fill) {}

  // Reallocates only when the size changes, so a frame reused every render costs no allocation.
  void resize(int w, int h) {
    width = w;
    height = h;
    data.resize(static_cast<size_t>(w) * h);
  }
  T& at(int u, int v) { return data[static_cast<size_t>(v) * width + u]; }
  const T& at(int u, int v) const { return data[static_cast<size_t>(v) * width + u]; }
  T* row(int v) { return data.data() + static_cast<size_t>(v) * width; }
  const T* row(int v) const { return data.data() + static_cast<size_t>(v) * width; }
  bool empty() const { return data.empty(); }
  friend bool operator==(const Image& a, const Image& b) {
    return a.width == b.width && a.height == b.height && a.data == b.data;
  }
  friend bool operator!=(const Image& a, const Image& b) { return !(a == b); }
};

}  // namespace semx::simulator
