#pragma once
// Device frame counters are narrow (GigE Vision 1.x block ids are 16 bits and skip 0; V4L2
// sequence numbers are 32 bits). FrameIdUnwrapper turns them into a 64-bit id that only grows,
// and tells how many frames were skipped in between.

#include <cstdint>

namespace facet {

class FrameIdUnwrapper {
 public:
  struct Step {
    std::uint64_t id = 0;    // unwrapped id of this frame
    std::uint64_t lost = 0;  // frames the device counted but we never received
  };

  // `bits`: width of the device counter (1..64). `zero_skipped`: the counter wraps from its
  // maximum to 1 instead of 0 (GigE Vision block ids). Both spellings are tolerated either way.
  explicit FrameIdUnwrapper(int bits = 16, bool zero_skipped = true)
      : mask_(bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1),
        zero_skipped_(zero_skipped) {}

  Step next(std::uint64_t raw) {
    raw &= mask_;
    if (!started_) {
      started_ = true;
      last_raw_ = raw;
      id_ = continue_from_ ? id_ + 1 : raw;
      continue_from_ = false;
      return {id_, 0};
    }
    std::uint64_t distance = (raw - last_raw_) & mask_;
    if (zero_skipped_ && raw < last_raw_ && raw != 0 && distance > 1) --distance;
    last_raw_ = raw;
    // A jump of more than half the counter range is a device restart, not a loss.
    if (distance == 0 || distance > mask_ / 2) {
      id_ += 1;
      return {id_, 0};
    }
    id_ += distance;
    return {id_, distance - 1};
  }

  // The device restarted its counter (e.g. after a reconnect): the next frame continues the
  // unwrapped ids instead of jumping to the device's new value.
  void restart() {
    if (started_) continue_from_ = true;
    started_ = false;
  }

 private:
  std::uint64_t mask_;
  bool zero_skipped_;
  bool started_ = false;
  bool continue_from_ = false;
  std::uint64_t last_raw_ = 0;
  std::uint64_t id_ = 0;
};

}  // namespace facet
