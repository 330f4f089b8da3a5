#pragma once
// Scalar functions of time that scale external loads.
#include <vector>

namespace mpx {

class TimeFunction {
 public:
  // f(t) = value.
  static TimeFunction constant(double value = 1.0);
  // 0 before tStart, rising linearly to 1 at tEnd, 1 after.
  static TimeFunction ramp(double tStart, double tEnd);
  // The tumbling L-block load: t for t <= T/2, T - t for T/2 < t <= T, 0 after.
  static TimeFunction hat(double period);
  // One sine arch: sin(pi t / duration) for 0 <= t <= duration, 0 otherwise.
  static TimeFunction sinePulse(double duration);
  // Piecewise linear through (times[i], values[i]), times increasing; constant outside.
  static TimeFunction table(std::vector<double> times, std::vector<double> values);

  double operator()(double t) const;
  // df/dt (the right derivative at kinks).
  double slope(double t) const;
  // The times where f or df/dt is not smooth, increasing; adaptive steps land on them.
  std::vector<double> breakpoints() const;

 private:
  enum class Kind { Constant, Ramp, Hat, SinePulse, Table };
  Kind kind_ = Kind::Constant;
  double a_ = 1.0, b_ = 0.0;
  std::vector<double> times_, values_;
};

}  // namespace mpx
