#pragma once
// When frame outputs (bodies.csv, joints.csv, solid frames) write: at multiples of an interval,
// at every record without one, and always at the first record a writer sees (t = 0, or the
// checkpoint's step after a restart).
#include <cmath>

namespace mpx {

class OutputSchedule {
 public:
  explicit OutputSchedule(double interval) : interval_(interval) {}
  bool due(double time) {
    if (interval_ <= 0.0) return true;
    if (started_ && time < next_ - 1e-9 * interval_) return false;
    started_ = true;
    next_ = (std::floor(time / interval_ + 1e-9) + 1.0) * interval_;
    return true;
  }

 private:
  double interval_, next_ = 0.0;
  bool started_ = false;
};

}  // namespace mpx
