#pragma once
// Independent reference for planar one-dof closed-loop linkages, in reduced coordinates: the
// links' absolute coordinates are partitioned into one independent angle theta and dependent
// coordinates solved from the pin equations, and theta obeys a scalar equation of motion
// integrated by classical RK4. It shares no code with the engine, so it can judge the engine's
// handling of the redundant conditions that 3D revolute joints put on a planar loop.
#include <Eigen/Dense>

#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

namespace mpx::test {

// A rigid link: mass, planar inertia about its centre of mass, centre at t = 0.
struct PlanarLink {
  double mass = 0.0, inertia = 0.0;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
};

// A revolute pin joining links a and b (index -1 = ground) at a world point at t = 0.
struct PlanarPin {
  int a = -1, b = -1;
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
};

// The configuration at one sample time: q = (x_i, y_i, phi_i) per link, and q'.
struct PlanarSample {
  double time = 0.0;
  Eigen::VectorXd q, qdot;
};

class PlanarLinkage {
 public:
  // `independentLink`'s angle phi is theta. Every phi_i is measured from the link's orientation
  // at t = 0, so the body-fixed pin offsets are the t = 0 offsets from the centres.
  PlanarLinkage(std::vector<PlanarLink> links, std::vector<PlanarPin> pins, const Eigen::Vector2d& gravity,
                int independentLink)
      : links_(std::move(links)), pins_(std::move(pins)), gravity_(gravity), theta_(3 * independentLink + 2) {
    if (independentLink < 0 || independentLink >= static_cast<int>(links_.size()))
      throw std::invalid_argument("PlanarLinkage: no such independent link");
    for (const PlanarPin& pin : pins_) offsets_.push_back({offset(pin.a, pin.point), offset(pin.b, pin.point)});
    if (constraints(initialCoordinates()).lpNorm<Eigen::Infinity>() > 1e-12)
      throw std::invalid_argument("PlanarLinkage: pins do not close at t = 0");
  }

  const std::vector<PlanarLink>& links() const { return links_; }
  const std::vector<PlanarPin>& pins() const { return pins_; }
  int coordinateCount() const { return 3 * static_cast<int>(links_.size()); }
  int thetaIndex() const { return theta_; }

  // q at t = 0: the centres, every angle 0.
  Eigen::VectorXd initialCoordinates() const {
    Eigen::VectorXd q = Eigen::VectorXd::Zero(coordinateCount());
    for (std::size_t i = 0; i < links_.size(); ++i) q.segment<2>(3 * i) = links_[i].centre;
    return q;
  }

  // Pin equations Phi(q): the two sides of every pin at the same world point.
  Eigen::VectorXd constraints(const Eigen::VectorXd& q) const {
    Eigen::VectorXd phi(2 * pins_.size());
    for (std::size_t k = 0; k < pins_.size(); ++k)
      phi.segment<2>(2 * k) =
          sidePoint(q, pins_[k].a, offsets_[k].first) - sidePoint(q, pins_[k].b, offsets_[k].second);
    return phi;
  }

  // Phi_q: identity in the centre, perp(R(phi) s) (R' s) in the angle; sign +1 for side a, -1 for b.
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& q) const {
    Eigen::MatrixXd jac = Eigen::MatrixXd::Zero(2 * pins_.size(), coordinateCount());
    for (std::size_t k = 0; k < pins_.size(); ++k) {
      addSide(jac, q, k, pins_[k].a, offsets_[k].first, 1.0);
      addSide(jac, q, k, pins_[k].b, offsets_[k].second, -1.0);
    }
    return jac;
  }

  // Phi_q without the theta column: square for a one-dof closed chain.
  Eigen::MatrixXd dependentJacobian(const Eigen::VectorXd& q) const { return withoutTheta(jacobian(q)); }

  // The dependent coordinates at theta, by Newton from `guess` until |Phi| <= 1e-14.
  Eigen::VectorXd positionsAt(double theta, const Eigen::VectorXd& guess) const {
    Eigen::VectorXd q = guess;
    q[theta_] = theta;
    for (int iteration = 0; iteration < 30; ++iteration) {
      const Eigen::VectorXd phi = constraints(q);
      if (phi.lpNorm<Eigen::Infinity>() <= 1e-14) return q;
      q -= withTheta(solveDependent(dependentJacobian(q), phi), 0.0);
    }
    throw std::runtime_error("PlanarLinkage: position Newton did not converge");
  }

  // q' = B theta': Phi_q B = 0 with B[theta] = 1.
  Eigen::VectorXd velocityBasis(const Eigen::VectorXd& q) const {
    const Eigen::MatrixXd jac = jacobian(q);
    return withTheta(solveDependent(withoutTheta(jac), -jac.col(theta_)), 1.0);
  }

  // c = dB/dtheta (so q'' = B theta'' + c theta'^2), exactly: differentiating Phi_q B = 0 along B
  // gives Phi_q c = -gamma, gamma = sum over pin sides of sign * (-R(phi_i) s_i B_phi_i^2); c[theta] = 0.
  Eigen::VectorXd basisDerivative(const Eigen::VectorXd& q, const Eigen::VectorXd& basis) const {
    Eigen::VectorXd gamma = Eigen::VectorXd::Zero(2 * pins_.size());
    for (std::size_t k = 0; k < pins_.size(); ++k) {
      if (pins_[k].a >= 0) gamma.segment<2>(2 * k) += curvature(q, basis, pins_[k].a, offsets_[k].first);
      if (pins_[k].b >= 0) gamma.segment<2>(2 * k) -= curvature(q, basis, pins_[k].b, offsets_[k].second);
    }
    return withTheta(solveDependent(dependentJacobian(q), -gamma), 0.0);
  }

  // theta'' from M_eff theta'' = B^T Q - (B^T M c) theta'^2, M_eff = B^T M B; q is solved at
  // theta, warm-started from and written back to `q`.
  double acceleration(double theta, double thetaRate, Eigen::VectorXd& q) const {
    q = positionsAt(theta, q);
    const Eigen::VectorXd basis = velocityBasis(q);
    const Eigen::VectorXd curv = basisDerivative(q, basis);
    const Eigen::VectorXd mass = massDiagonal();
    const double effectiveMass = basis.dot(mass.cwiseProduct(basis));
    return (basis.dot(gravityForces()) - basis.dot(mass.cwiseProduct(curv)) * thetaRate * thetaRate) / effectiveMass;
  }

  // From theta = 0 and theta' = thetaRate0 by RK4 at fixed dt, positions re-solved at every stage.
  // `sampleTimes` must be ascending multiples of dt within [0, tEnd] (the states exist only at the
  // steps); the result holds q and q' at each of them, and stepping stops at the last one.
  std::vector<PlanarSample> integrate(double thetaRate0, double tEnd, double dt,
                                      const std::vector<double>& sampleTimes) const {
    const long steps = std::lround(tEnd / dt);
    std::vector<long> sampleSteps;
    for (double t : sampleTimes) {
      const long n = std::lround(t / dt);
      if (std::abs(n * dt - t) > 1e-9 * dt || n < 0 || n > steps || (!sampleSteps.empty() && n < sampleSteps.back()))
        throw std::invalid_argument("PlanarLinkage: sample times must be ascending multiples of dt in [0, tEnd]");
      sampleSteps.push_back(n);
    }
    std::vector<PlanarSample> samples;
    Eigen::VectorXd q = initialCoordinates();
    double theta = 0.0, rate = thetaRate0;
    for (long n = 0;; ++n) {
      // Record before stepping, so that step n is the state at t = n dt.
      while (samples.size() < sampleSteps.size() && sampleSteps[samples.size()] == n) {
        q = positionsAt(theta, q);
        samples.push_back({n * dt, q, velocityBasis(q) * rate});
      }
      if (samples.size() == sampleSteps.size()) return samples;
      const double a1 = acceleration(theta, rate, q);
      const double a2 = acceleration(theta + 0.5 * dt * rate, rate + 0.5 * dt * a1, q);
      const double a3 = acceleration(theta + 0.5 * dt * (rate + 0.5 * dt * a1), rate + 0.5 * dt * a2, q);
      const double a4 = acceleration(theta + dt * (rate + 0.5 * dt * a2), rate + dt * a3, q);
      theta += dt * (rate + dt * (a1 + a2 + a3) / 6.0);
      rate += dt * (a1 + 2.0 * a2 + 2.0 * a3 + a4) / 6.0;
    }
  }

  // Kinetic energy plus the gravity potential -m g.x of every centre.
  double energy(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot) const {
    return 0.5 * qdot.dot(massDiagonal().cwiseProduct(qdot)) - gravityForces().dot(q);
  }

 private:
  static Eigen::Matrix2d rotation(double angle) {
    return (Eigen::Matrix2d() << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle)).finished();
  }
  static Eigen::Vector2d perp(const Eigen::Vector2d& v) { return {-v.y(), v.x()}; }

  Eigen::Vector2d offset(int link, const Eigen::Vector2d& point) const {
    if (link < -1 || link >= static_cast<int>(links_.size()))
      throw std::invalid_argument("PlanarLinkage: no such link");
    return link < 0 ? point : Eigen::Vector2d(point - links_[link].centre);
  }

  // World point of one side of a pin: the ground point itself, or x_i + R(phi_i) s_i.
  Eigen::Vector2d sidePoint(const Eigen::VectorXd& q, int link, const Eigen::Vector2d& s) const {
    if (link < 0) return s;
    return q.segment<2>(3 * link) + rotation(q[3 * link + 2]) * s;
  }

  // One side's columns of Phi_q in pin k's rows.
  static void addSide(Eigen::MatrixXd& jac, const Eigen::VectorXd& q, std::size_t k, int link, const Eigen::Vector2d& s,
                      double sign) {
    if (link < 0) return;
    jac.block<2, 2>(2 * k, 3 * link) += sign * Eigen::Matrix2d::Identity();
    jac.block<2, 1>(2 * k, 3 * link + 2) += sign * perp(rotation(q[3 * link + 2]) * s);
  }

  // Second derivative of x_i + R(phi_i) s_i along q' = B (the part without c): -R(phi_i) s_i B_phi_i^2.
  Eigen::Vector2d curvature(const Eigen::VectorXd& q, const Eigen::VectorXd& basis, int link,
                            const Eigen::Vector2d& s) const {
    const double spin = basis[3 * link + 2];
    return -rotation(q[3 * link + 2]) * s * spin * spin;
  }

  Eigen::VectorXd massDiagonal() const {
    Eigen::VectorXd mass(coordinateCount());
    for (std::size_t i = 0; i < links_.size(); ++i)
      mass.segment<3>(3 * i) << links_[i].mass, links_[i].mass, links_[i].inertia;
    return mass;
  }

  Eigen::VectorXd gravityForces() const {
    Eigen::VectorXd forces = Eigen::VectorXd::Zero(coordinateCount());
    for (std::size_t i = 0; i < links_.size(); ++i) forces.segment<2>(3 * i) = links_[i].mass * gravity_;
    return forces;
  }

  // The coordinate-partitioning split and merge: drop the theta column, insert a theta entry.
  Eigen::MatrixXd withoutTheta(const Eigen::MatrixXd& jac) const {
    Eigen::MatrixXd dep(jac.rows(), jac.cols() - 1);
    dep << jac.leftCols(theta_), jac.rightCols(jac.cols() - theta_ - 1);
    return dep;
  }
  Eigen::VectorXd withTheta(const Eigen::VectorXd& dependent, double thetaEntry) const {
    Eigen::VectorXd full(dependent.size() + 1);
    full << dependent.head(theta_), thetaEntry, dependent.tail(dependent.size() - theta_);
    return full;
  }

  // Least-squares (minimum-norm) solve, so that a non-square or rank-deficient dependent Jacobian
  // also works; the equations must still hold, or the configuration is singular.
  static Eigen::VectorXd solveDependent(const Eigen::MatrixXd& dep, const Eigen::VectorXd& rhs) {
    const Eigen::VectorXd x = dep.completeOrthogonalDecomposition().solve(rhs);
    if ((dep * x - rhs).norm() > 1e-10 * (1.0 + rhs.norm()))
      throw std::runtime_error("PlanarLinkage: dependent equations have no solution (singular configuration)");
    return x;
  }

  std::vector<PlanarLink> links_;
  std::vector<PlanarPin> pins_;
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> offsets_;  // s on side a, s on side b
  Eigen::Vector2d gravity_;
  int theta_;
};

// A uniform bar of 1 kg per metre and square cross-section a = 0.05 m: m = L, I = m (L^2 + a^2)/12.
// L is the nominal length (not a distance of computed points), so the masses are those of the scenes.
inline PlanarLink uniformBar(double length, const Eigen::Vector2d& centre) {
  const double a = 0.05;
  return {length, length * (length * length + a * a) / 12.0, centre};
}

// The intersection with the larger y of the circles (c1, r1) and (c2, r2).
inline Eigen::Vector2d upperIntersection(const Eigen::Vector2d& c1, double r1, const Eigen::Vector2d& c2, double r2) {
  const double d = (c2 - c1).norm();
  const double along = (d * d + r1 * r1 - r2 * r2) / (2.0 * d), across = std::sqrt(r1 * r1 - along * along);
  const Eigen::Vector2d u = (c2 - c1) / d, foot = c1 + along * u, normal(-u.y(), u.x());
  const Eigen::Vector2d p = foot + across * normal, q = foot - across * normal;
  return p.y() > q.y() ? p : q;
}

// Crank-rocker four-bar, at rest at t = 0, gravity (0, -9.81), theta = the crank's angle.
// Ground pivots O1 = (0, 0), O2 = (2, 0); links (uniform bars): 0 crank O1 -> A = (0, 0.5)
// (length 0.5, pointing up), 1 coupler A -> B (2.0), 2 rocker O2 -> B (1.5), with B the upper
// intersection of the circles (A, 2.0) and (O2, 1.5). Pins in order: O1, A, B, O2.
inline PlanarLinkage fourBarCrankRocker() {
  const Eigen::Vector2d o1(0.0, 0.0), o2(2.0, 0.0), a(0.0, 0.5);
  const Eigen::Vector2d b = upperIntersection(a, 2.0, o2, 1.5);
  return PlanarLinkage(
      {uniformBar(0.5, 0.5 * (o1 + a)), uniformBar(2.0, 0.5 * (a + b)), uniformBar(1.5, 0.5 * (o2 + b))},
      {{-1, 0, o1}, {0, 1, a}, {1, 2, b}, {-1, 2, o2}}, Eigen::Vector2d(0.0, -9.81), 0);
}

// Watt six-bar (two loops, one dof), at rest at t = 0, gravity (0, -9.81), theta = the crank's
// angle. The four-bar above, but the rocker is a uniform bar of length 3.0 from O2 through B (its
// midpoint and centre) to C = O2 + 2 (B - O2); then 3 coupler C -> D (2.0) and 4 rocker
// O3 = (3.5, 0) -> D (2.5), with D the upper intersection of the circles (C, 2.0) and (O3, 2.5).
// Pins in order: O1, A, B, O2, C, D, O3.
inline PlanarLinkage wattSixBar() {
  const Eigen::Vector2d o1(0.0, 0.0), o2(2.0, 0.0), o3(3.5, 0.0), a(0.0, 0.5);
  const Eigen::Vector2d b = upperIntersection(a, 2.0, o2, 1.5), c = o2 + 2.0 * (b - o2);
  const Eigen::Vector2d d = upperIntersection(c, 2.0, o3, 2.5);
  return PlanarLinkage({uniformBar(0.5, 0.5 * (o1 + a)), uniformBar(2.0, 0.5 * (a + b)), uniformBar(3.0, b),
                        uniformBar(2.0, 0.5 * (c + d)), uniformBar(2.5, 0.5 * (o3 + d))},
                       {{-1, 0, o1}, {0, 1, a}, {1, 2, b}, {-1, 2, o2}, {2, 3, c}, {3, 4, d}, {-1, 4, o3}},
                       Eigen::Vector2d(0.0, -9.81), 0);
}

}  // namespace mpx::test
