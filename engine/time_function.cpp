#include "time_function.hpp"

#include <algorithm>

namespace mpx {

TimeFunction TimeFunction::constant(double value) {
  TimeFunction f;
  f.kind_ = Kind::Constant;
  f.a_ = value;
  return f;
}

TimeFunction TimeFunction::ramp(double tStart, double tEnd) {
  TimeFunction f;
  f.kind_ = Kind::Ramp;
  f.a_ = tStart;
  f.b_ = tEnd;
  return f;
}

TimeFunction TimeFunction::hat(double period) {
  TimeFunction f;
  f.kind_ = Kind::Hat;
  f.a_ = period;
  return f;
}

TimeFunction TimeFunction::table(std::vector<double> times, std::vector<double> values) {
  TimeFunction f;
  f.kind_ = Kind::Table;
  f.times_ = std::move(times);
  f.values_ = std::move(values);
  return f;
}

double TimeFunction::operator()(double t) const {
  switch (kind_) {
    case Kind::Constant: return a_;
    case Kind::Ramp: return t <= a_ ? 0.0 : t >= b_ ? 1.0 : (t - a_) / (b_ - a_);
    case Kind::Hat: return t <= 0.5 * a_ ? t : t <= a_ ? a_ - t : 0.0;
    case Kind::Table: {
      if (t <= times_.front()) return values_.front();
      if (t >= times_.back()) return values_.back();
      const auto upper = std::upper_bound(times_.begin(), times_.end(), t) - times_.begin();
      const double s = (t - times_[upper - 1]) / (times_[upper] - times_[upper - 1]);
      return (1.0 - s) * values_[upper - 1] + s * values_[upper];
    }
  }
  return 0.0;
}

}  // namespace mpx
