#pragma once
// A small Levenberg-Marquardt loop for fits with a handful of parameters (a circle, a blurred
// rim's grey profile). Hand-written rather than Ceres or Eigen's unsupported module because the
// fits need what those hide: the problem supplies its own normal equations (weighted, with
// parameters held fixed, re-weighted between iterations) and the cost of a trial step can reuse
// what the evaluation computed (residuals, Jacobian rows) when the step is accepted.
//
// The problem (any type with these members; x is Eigen::Matrix<double, N, 1>):
//   double cost(const Vector& x);                        // at the start
//   void normalEquations(int iteration, const Vector& x, Matrix& jtj, Vector& jtr,
//                        double& cost);                   // at x: J^T W J and J^T W r, r = f(x) -
//                        y;
//                                                         // may re-weight (and then update cost)
//   std::optional<double> trialCost(const Vector& x);    // nullopt: x is outside the domain
//   void accept();                                       // the last trial becomes the current
//   point bool converged(int iteration, const Vector& step);   // after an accepted step
// The step solves (J^T W J + lambda diag(J^T W J)) step = -J^T W r (Marquardt's scaling, so that
// the damping does not depend on the units of the parameters).

#include <algorithm>
#include <optional>

#include <Eigen/Dense>

namespace facet {

struct LevenbergMarquardtSettings {
  int maxIterations = 20;
  int maxTries = 10;              // damping increases per iteration before giving up
  double initialDamping = 1e-6;   // lambda at the start
  double dampingDecrease = 0.1;   // lambda *= this after an accepted step ...
  double minDamping = 1e-12;      // ... but not below this
  double dampingIncrease = 10.0;  // lambda *= this after a rejected step
};

enum class LevenbergMarquardtStop {
  Converged,      // the problem's convergence test held after an accepted step
  NoImprovement,  // no damping in maxTries lowered the cost: at the minimum up to rounding
  IterationLimit,
  NonFiniteStep,  // the normal equations gave NaN or inf: the fit failed
};

// A problem made of five callables, for fits whose state lives in the caller's lambdas:
//   LevenbergMarquardtCallbacks problem{cost, normalEquations, trialCost, accept, converged};
template <class Cost, class Normal, class Trial, class Accept, class Converged>
struct LevenbergMarquardtCallbacks {
  Cost cost;
  Normal normalEquations;
  Trial trialCost;
  Accept accept;
  Converged converged;
};
// Spelled out: clang before 17 does not deduce an aggregate's template arguments (P1816).
template <class Cost, class Normal, class Trial, class Accept, class Converged>
LevenbergMarquardtCallbacks(Cost, Normal, Trial, Accept, Converged)
    -> LevenbergMarquardtCallbacks<Cost, Normal, Trial, Accept, Converged>;

// Minimises the problem's cost starting from x (updated in place to the last accepted point).
template <int N, class Problem>
LevenbergMarquardtStop levenbergMarquardt(Problem& problem, Eigen::Matrix<double, N, 1>& x,
                                          const LevenbergMarquardtSettings& settings = {}) {
  using Vector = Eigen::Matrix<double, N, 1>;
  using Matrix = Eigen::Matrix<double, N, N>;
  double current = problem.cost(x);
  double lambda = settings.initialDamping;
  Matrix jtj;
  Vector jtr;
  for (int it = 0; it < settings.maxIterations; ++it) {
    problem.normalEquations(it, x, jtj, jtr, current);
    bool accepted = false;
    Vector step;
    for (int tries = 0; tries < settings.maxTries && !accepted; ++tries) {
      Matrix a = jtj;
      a.diagonal() += lambda * jtj.diagonal().cwiseMax(1e-9);
      step = a.ldlt().solve(-jtr);
      if (!step.allFinite()) return LevenbergMarquardtStop::NonFiniteStep;
      const Vector next = x + step;
      const std::optional<double> cost = problem.trialCost(next);
      if (cost && *cost <= current) {
        accepted = true;
        problem.accept();
        x = next;
        current = *cost;
        lambda = std::max(lambda * settings.dampingDecrease, settings.minDamping);
      } else {
        lambda *= settings.dampingIncrease;
      }
    }
    if (!accepted) return LevenbergMarquardtStop::NoImprovement;
    if (problem.converged(it, step)) return LevenbergMarquardtStop::Converged;
  }
  return LevenbergMarquardtStop::IterationLimit;
}

}  // namespace facet
