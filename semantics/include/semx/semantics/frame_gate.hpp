// Which camera frames the semantics module processes: at most one per `detector.frame_period_s`
// of message time (docs/semantics.md, "Frame rate").
//
// Why: a frame costs ~4 ms of detection, lifting and tracking, and in LOCKSTEP every node acks
// every tick, so processing all 30 frames a second was a large share of a run's wall time, while
// objects are confirmed over half a second of views anyway (tracking.min_duration_s). The gate
// decides from the frame's utime alone, before anything is decoded, so both parts of a capture
// (depth and labels, same utime) get the same answer and a log replays identically.
#pragma once

#include <cstdint>

namespace semx::semantics {

class FrameGate {
 public:
  // period_s <= 0: every frame.
  explicit FrameGate(double period_s);

  // Would a frame with this utime be processed now? The first frame, and one older than the last
  // taken (a new episode), always are; otherwise the one at or after the next due time (1 ms of
  // slack absorbs frame times rounded to microseconds, e.g. 99999 for 0.1 s at 30 Hz).
  bool due(int64_t utime) const;
  // A frame with this utime was processed: the next is due one period after the previous due
  // time (so the average rate is exactly 1/period), or one period from now when it is later.
  void taken(int64_t utime);
  void reset() { last_ = next_ = -1; }
  int64_t period_us() const { return period_us_; }

 private:
  int64_t period_us_;
  int64_t last_ = -1;  // utime of the last frame taken
  int64_t next_ = -1;  // due time of the next frame
};

}  // namespace semx::semantics
