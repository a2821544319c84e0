#include "semx/controller/trajectory_optimizer.hpp"

#include <LBFGS.h>

#include <array>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace semx::controller {
namespace {

using Vec = Eigen::VectorXd;
using Points = PositionSpline::Points;

constexpr int kFixed = 3;  // control points fixed at each end

class Cost {
 public:
  Cost(const Points& initial, double dt, const DistanceField& field, const OptimizerConfig& cfg, double v_max,
       double a_max, double target)
      : q0_(initial),
        q_(initial),
        g_(initial.size()),
        dt_(dt),
        field_(field),
        cfg_(cfg),
        inv_v2_(1.0 / (v_max * v_max)),
        inv_a2_(1.0 / (a_max * a_max)),
        target_(target) {
    const int s = cfg.samples_per_segment;
    basis_.resize(static_cast<std::size_t>(s));
    for (int k = 0; k < s; ++k)
      cubic_basis(static_cast<double>(k) / s, 0, basis_[static_cast<std::size_t>(k)].data());
  }

  int free_points() const { return static_cast<int>(q0_.size()) - 2 * kFixed; }

  double operator()(const Vec& x, Vec& grad) {
    ++evaluations_;
    const int n = static_cast<int>(q_.size());
    for (int i = 0; i < free_points(); ++i) q_[kFixed + i] = q0_[kFixed + i] + x.segment<3>(3 * i);
    for (auto& g : g_) g.setZero();
    double f = 0.0;

    const double ws = cfg_.weight_smoothness;
    if (ws > 0) {
      for (int i = 0; i + 3 < n; ++i) {
        const Eigen::Vector3d j = q_[i + 3] - 3.0 * q_[i + 2] + 3.0 * q_[i + 1] - q_[i];
        f += ws * j.squaredNorm();
        const Eigen::Vector3d d = 2.0 * ws * j;
        g_[i + 3] += d;
        g_[i + 2] -= 3.0 * d;
        g_[i + 1] += 3.0 * d;
        g_[i] -= d;
      }
    }

    const double wc = cfg_.weight_clearance;
    if (wc > 0) {
      Eigen::Vector3d grad_d;
      for (int j = 0; j + 3 < n; ++j) {
        for (const auto& b : basis_) {
          const Eigen::Vector3d p = b[0] * q_[j] + b[1] * q_[j + 1] + b[2] * q_[j + 2] + b[3] * q_[j + 3];
          const double d = field_.distance(p, &grad_d);
          if (d >= target_) continue;
          const double e = target_ - d;
          f += wc * e * e;
          const Eigen::Vector3d dp = -2.0 * wc * e * grad_d;
          for (int m = 0; m < 4; ++m) g_[j + m] += b[static_cast<std::size_t>(m)] * dp;
        }
      }
    }

    const double wf = cfg_.weight_feasibility;
    if (wf > 0) {
      const double idt = 1.0 / dt_, idt2 = idt * idt;
      for (int i = 0; i + 1 < n; ++i) {
        const Eigen::Vector3d v = (q_[i + 1] - q_[i]) * idt;
        const double r = v.squaredNorm() * inv_v2_ - 1.0;
        if (r <= 0) continue;
        f += wf * r * r;
        const Eigen::Vector3d dv = wf * 4.0 * r * inv_v2_ * v * idt;
        g_[i + 1] += dv;
        g_[i] -= dv;
      }
      for (int i = 0; i + 2 < n; ++i) {
        const Eigen::Vector3d a = (q_[i + 2] - 2.0 * q_[i + 1] + q_[i]) * idt2;
        const double r = a.squaredNorm() * inv_a2_ - 1.0;
        if (r <= 0) continue;
        f += wf * r * r;
        const Eigen::Vector3d da = wf * 4.0 * r * inv_a2_ * a * idt2;
        g_[i + 2] += da;
        g_[i + 1] -= 2.0 * da;
        g_[i] += da;
      }
    }

    // Fidelity: control points pulled more than fidelity_tolerance from the initial curve (which
    // follows the path) pay for it, so that smoothness cuts no corner beyond what the deviation
    // rule flies.
    const double wd = cfg_.weight_fidelity;
    if (wd > 0) {
      for (int i = 0; i < free_points(); ++i) {
        const Eigen::Vector3d off = x.segment<3>(3 * i);
        const double len = off.norm();
        const double r = len - cfg_.fidelity_tolerance;
        if (r <= 0) continue;
        f += wd * r * r;
        g_[kFixed + i] += 2.0 * wd * r / len * off;
      }
    }

    for (int i = 0; i < free_points(); ++i) grad.segment<3>(3 * i) = g_[kFixed + i];
    if (std::isfinite(f) && f < best_f_) {
      best_f_ = f;
      best_x_ = x;
    }
    return f;
  }

  double best_cost() const { return best_f_; }
  const Vec& best_x() const { return best_x_; }
  int evaluations() const { return evaluations_; }

  void apply(const Vec& x, Points& out) const {
    out = q0_;
    for (int i = 0; i < free_points(); ++i) out[kFixed + i] = q0_[kFixed + i] + x.segment<3>(3 * i);
  }

 private:
  const Points& q0_;
  Points q_, g_;
  double dt_;
  const DistanceField& field_;
  const OptimizerConfig& cfg_;
  double inv_v2_, inv_a2_, target_;
  std::vector<std::array<double, 4>> basis_;
  double best_f_ = std::numeric_limits<double>::infinity();
  Vec best_x_;
  int evaluations_ = 0;
};

}  // namespace

OptimizerReport TrajectoryOptimizer::optimize(PositionSpline& spline, const DistanceField& field,
                                              double max_velocity, double max_acceleration,
                                              double clearance_target) const {
  OptimizerReport report;
  const Points initial = spline.control_points();
  Cost cost(initial, spline.knot_interval(), field, config_, max_velocity, max_acceleration,
            clearance_target);
  if (cost.free_points() <= 0 || config_.max_iterations <= 0) return report;
  report.ran = true;

  LBFGSpp::LBFGSParam<double> param;
  param.m = 6;
  param.epsilon = 1e-4;
  param.epsilon_rel = 0.0;  // offsets start at zero: a relative test would be meaningless
  param.past = 3;
  param.delta = 1e-4;
  param.max_iterations = config_.max_iterations;
  param.max_linesearch = 30;
  param.linesearch = LBFGSpp::LBFGS_LINESEARCH_BACKTRACKING_STRONG_WOLFE;
  LBFGSpp::LBFGSSolver<double, LBFGSpp::LineSearchNocedalWright> solver(param);

  Vec x = Vec::Zero(3 * cost.free_points());
  Vec g(x.size());
  report.initial_cost = cost(x, g);
  double fx = report.initial_cost;
  try {
    report.iterations = solver.minimize(cost, x, fx);
  } catch (const std::exception& e) {
    // Line-search failures near a minimum are common with a piecewise-smooth field; the best
    // point visited is still an improvement, and the clearance check judges it.
    report.message = e.what();
  }
  report.evaluations = cost.evaluations();
  if (!std::isfinite(cost.best_cost()) || !cost.best_x().allFinite()) {
    report.failed = true;
    if (report.message.empty()) report.message = "non-finite cost";
    return report;
  }
  report.final_cost = cost.best_cost();
  Points out;
  cost.apply(cost.best_x(), out);
  spline.control_points() = std::move(out);
  return report;
}

}  // namespace semx::controller
