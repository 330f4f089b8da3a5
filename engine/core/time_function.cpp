#include "engine/core/time_function.hpp"

#include <algorithm>
#include <cmath>

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

TimeFunction TimeFunction::sinePulse(double duration) {
  TimeFunction f;
  f.kind_ = Kind::SinePulse;
  f.a_ = duration;
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
    case Kind::Constant:
      return a_;
    case Kind::Ramp:
      return t <= a_ ? 0.0 : t >= b_ ? 1.0 : (t - a_) / (b_ - a_);
    case Kind::Hat:
      return t <= 0.5 * a_ ? t : t <= a_ ? a_ - t : 0.0;
    case Kind::SinePulse:
      return t >= 0.0 && t <= a_ ? std::sin(M_PI * t / a_) : 0.0;
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

double TimeFunction::slope(double t) const {
  switch (kind_) {
    case Kind::Constant:
      return 0.0;
    case Kind::Ramp:
      return t >= a_ && t < b_ ? 1.0 / (b_ - a_) : 0.0;
    case Kind::Hat:
      return t < 0.5 * a_ ? 1.0 : t < a_ ? -1.0 : 0.0;
    case Kind::SinePulse:
      return t >= 0.0 && t < a_ ? M_PI / a_ * std::cos(M_PI * t / a_) : 0.0;
    case Kind::Table: {
      if (t < times_.front() || t >= times_.back()) return 0.0;
      const auto upper = std::upper_bound(times_.begin(), times_.end(), t) - times_.begin();
      return (values_[upper] - values_[upper - 1]) / (times_[upper] - times_[upper - 1]);
    }
  }
  return 0.0;
}

std::vector<double> TimeFunction::breakpoints() const {
  switch (kind_) {
    case Kind::Constant:
      return {};
    case Kind::Ramp:
      return {a_, b_};
    case Kind::Hat:
      return {0.5 * a_, a_};
    case Kind::SinePulse:
      return {0.0, a_};
    case Kind::Table:
      return times_;
  }
  return {};
}

}  // namespace mpx
