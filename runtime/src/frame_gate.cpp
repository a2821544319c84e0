#include "semx/runtime/frame_gate.hpp"

#include <cmath>
#include <limits>

namespace semx::runtime {

namespace {
constexpr int64_t kSlackUs = 1000;
}  // namespace

FrameGate::FrameGate(double period_s)
    : period_us_(period_s > 0 ? static_cast<int64_t>(std::llround(period_s * 1e6)) : 0) {}

bool FrameGate::due(int64_t utime) const {
  if (period_us_ <= 0 || last_ < 0 || utime < last_) return true;
  return utime >= next_ - kSlackUs;
}

int64_t FrameGate::next_due() const {
  if (period_us_ <= 0 || last_ < 0) return std::numeric_limits<int64_t>::min();
  return next_ - kSlackUs;
}

void FrameGate::taken(int64_t utime) {
  if (period_us_ <= 0) return;
  const bool restart = last_ < 0 || utime < last_ || utime - next_ >= period_us_;
  next_ = restart ? utime + period_us_ : next_ + period_us_;
  last_ = utime;
}

}  // namespace semx::runtime
