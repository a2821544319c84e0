// Which camera frames a node processes: at most one per `period_s` of message time (the
// semantics module's detector.frame_period_s, the mapper's integration.frame_period_s).
//
// Why: in LOCKSTEP every node acks every tick, so a node that processes all 30 frames a second
// takes a large share of a run's wall time, while consecutive frames 33 ms apart add little (the
// vehicle moves 3 cm at 1 m/s). The gate decides from the frame's utime alone, before anything
// is decoded, so every part of one capture (depth, labels, RGB: same utime) gets the same answer
// and a log replays identically.
#pragma once

#include <cstdint>

namespace semx::runtime {

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
  // The earliest utime a due frame can have from now on (while time does not go back); the
  // lowest int64 when any frame would do.
  int64_t next_due() const;
  int64_t period_us() const { return period_us_; }

 private:
  int64_t period_us_;
  int64_t last_ = -1;  // utime of the last frame taken
  int64_t next_ = -1;  // due time of the next frame
};

}  // namespace semx::runtime
