// Laws (15) and (30) realised by resolved acceleration, and the RK4 step of the plant (see
// closed_loop.hpp).

#include "closed_loop.hpp"

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rns_native {

double smallest_singular_value(const MatrixXd& A) {
  return Eigen::JacobiSVD<MatrixXd>(A).singularValues()(std::min(A.rows(), A.cols()) - 1);
}

ClosedLoop::ClosedLoop(const RobotModel& robot, const std::vector<int>& rows, const VectorXd& row_weights,
           const MatrixXd& K_b, const MatrixXd& D_b,
           const MatrixXd& D_m, double threshold, double max_damping, bool cb_is_hbm_dot, const std::string& ee_frame,
           int base_joint, const std::vector<int>& task_rows)
    : model_(robot.model()),
      law_data_(model_),
      plant_data_(model_),
      task_data_(model_),
      ee_frame_(0),
      base_joint_(base_joint),
      task_rows_(task_rows),
      rows_(rows),
      weights_(row_weights),
      K_(K_b),
      D_(D_b),
      Dm_(D_m),
      threshold_(threshold),
      max_damping_(max_damping),
      cb_is_hbm_dot_(cb_is_hbm_dot) {
  const Model& model = model_;
  if (!model.existFrame(ee_frame)) throw std::invalid_argument("the end-effector frame is not in the model");
  ee_frame_ = static_cast<int>(model.getFrameId(ee_frame));
  if (model.nq != model.nv) throw std::invalid_argument("the model must have nq == nv (no free-flyer or SO(3) joints)");
  nv_ = model.nv;
  m_ = K_b.rows();
  n_ = nv_ - m_;
  r_ = static_cast<Index>(rows.size());
  if (m_ < 1 || n_ < 1 || K_b.cols() != m_ || D_b.rows() != m_ || D_b.cols() != m_ || D_m.rows() != n_ ||
      D_m.cols() != n_ || r_ < 1 || r_ > m_)
    throw std::invalid_argument("K_b, D_b (m x m), D_m (n x n) and 1..m selected rows must fit the model");
  for (int i : rows)
    if (i < 0 || i >= m_) throw std::invalid_argument("a selected row is not a base row");
  if (weights_.size() != r_ || !(weights_.array() > 0.0).all())
    throw std::invalid_argument("one positive weight per selected row");
  if (base_joint < 1 || base_joint >= model.njoints) throw std::invalid_argument("the base joint is not in the model");
  for (int i : task_rows)
    if (i < 0 || i > 2) throw std::invalid_argument("task rows are 0 (x), 1 (y) or 2 (z)");
  arm_damped_ = Dm_.cwiseAbs().maxCoeff() > 0.0;
  u_.setZero(nv_);
  stage_.setZero(2 * nv_);
  slope_sum_.setZero(2 * nv_);
  stage_tau_.setZero(n_);
  stage_L_.setZero(r_);
}

// Eq. (15) with u = -g_u theta'.

double ClosedLoop::damped_control(const ConstRef& x, double g_b, double g_m, double g_u, Ref tau, Ref L) {
  check_sizes(x, tau, L);
  return composite(x, g_b, g_m, 0.0, g_u, nullptr, tau, L);
}

double ClosedLoop::damped_step(const ConstRef& x, const ConstRef& g_b, double g_m, double g_u, const ConstRef& forces, double dt,
                   bool staged, Ref x_next, Ref tau, Ref L) {
  const auto gain = [&](Index k) { return stage_sample(g_b, k, 1)(0); };
  const double sigma = damped_control(x, gain(0), g_m, g_u, tau, L);
  const StageLaw law = [&](Index k, const ConstRef& x_s, Ref tau_s, Ref L_s) {
    damped_control(x_s, gain(k), g_m, g_u, tau_s, L_s);
  };
  advance(x, tau, forces, dt, x_next, staged ? &law : nullptr);
  return sigma;
}

// Eq. (15) with u = theta_r'' + k_d (theta_r' - theta') + k_p (theta_r - theta).

double ClosedLoop::tracking_control(const ConstRef& x, double g_b, double g_m, double k_p, double k_d, const ConstRef& theta_r,
                        const ConstRef& thetadot_r, const ConstRef& thetaddot_r, Ref tau, Ref L) {
  check_sizes(x, tau, L);
  check_reference(theta_r, thetadot_r, thetaddot_r);
  const Reference ref{&theta_r, &thetadot_r, &thetaddot_r};
  return composite(x, g_b, g_m, k_p, k_d, &ref, tau, L);
}

double ClosedLoop::tracking_step(const ConstRef& x, const ConstRef& g_b, double g_m, double k_p, double k_d, const ConstRef& theta_r,
                     const ConstRef& thetadot_r, const ConstRef& thetaddot_r, const ConstRef& forces, double dt,
                     bool staged, Ref x_next, Ref tau, Ref L) {
  const auto at = [&](const ConstRef& r, Index k) { return stage_sample(r, k, n_); };
  const auto gain = [&](Index k) { return stage_sample(g_b, k, 1)(0); };
  const double sigma =
      tracking_control(x, gain(0), g_m, k_p, k_d, at(theta_r, 0), at(thetadot_r, 0), at(thetaddot_r, 0), tau, L);
  const StageLaw law = [&](Index k, const ConstRef& x_s, Ref tau_s, Ref L_s) {
    tracking_control(x_s, gain(k), g_m, k_p, k_d, at(theta_r, k), at(thetadot_r, k), at(thetaddot_r, k), tau_s, L_s);
  };
  advance(x, tau, forces, dt, x_next, staged ? &law : nullptr);
  return sigma;
}

// Eq. (15) with Eq. (24): P u = J-bar^+ [x_d'' + G_d e' + G_p e - J' theta' + J H_bm^+ H_bm' theta'],

// e = x_d - x_e, J-bar = J P_RNS with the damped inverse (threshold = max damping, m/rad).

// Returns (sigma_min(S H_bm), sigma_min(J-bar)).

// Eq. (30): theta'_cmd = H_bm^+ S H_b g_b x_b + g_m (theta_r - theta) [+ theta_r'], then the servo.

double ClosedLoop::velocity_control(const ConstRef& x, double g_b, double g_m, double w_s, bool feedforward,
                        const ConstRef& theta_r, const ConstRef& thetadot_r, Ref tau, Ref L) {
  check_sizes(x, tau, L);
  check_reference(theta_r, thetadot_r, thetadot_r);
  const ConstRef q = x.head(nv_);
  const ConstRef v = x.tail(nv_);
  const double sigma = coupling(q, v, L);
  VectorXd Hb_x_b(r_);  // S H_b x_b with every base coordinate: S selects rows only, as in (15)
  for (Index i = 0; i < r_; ++i) Hb_x_b(i) = M_.row(rows_[i]).head(m_).dot(q.head(m_));
  VectorXd cmd = pinv_ * (g_b * Hb_x_b) + g_m * (theta_r - q.tail(n_));
  if (feedforward) cmd += thetadot_r;
  realize(q, v, w_s * (cmd - v.tail(n_)), tau);
  return sigma;
}

double ClosedLoop::velocity_step(const ConstRef& x, const ConstRef& g_b, double g_m, double w_s, bool feedforward, const ConstRef& theta_r,
                     const ConstRef& thetadot_r, const ConstRef& forces, double dt, bool staged, Ref x_next, Ref tau,
                     Ref L) {
  const auto at = [&](const ConstRef& r, Index k) { return stage_sample(r, k, n_); };
  const auto gain = [&](Index k) { return stage_sample(g_b, k, 1)(0); };
  const double sigma = velocity_control(x, gain(0), g_m, w_s, feedforward, at(theta_r, 0), at(thetadot_r, 0), tau, L);
  const StageLaw law = [&](Index k, const ConstRef& x_s, Ref tau_s, Ref L_s) {
    velocity_control(x_s, gain(k), g_m, w_s, feedforward, at(theta_r, k), at(thetadot_r, k), tau_s, L_s);
  };
  advance(x, tau, forces, dt, x_next, staged ? &law : nullptr);
  return sigma;
}

// The joint servo: theta'' = theta_r'' + k_d (theta_r' - theta') + k_p (theta_r - theta), realised.

double ClosedLoop::servo_control(const ConstRef& x, double k_p, double k_d, const ConstRef& theta_r,
                                 const ConstRef& thetadot_r, const ConstRef& thetaddot_r, Ref tau, Ref L) {
  check_sizes(x, tau, L);
  check_reference(theta_r, thetadot_r, thetaddot_r);
  const ConstRef q = x.head(nv_);
  const ConstRef v = x.tail(nv_);
  const double sigma = coupling(q, v, L);
  realize(q, v, thetaddot_r + k_d * (thetadot_r - v.tail(n_)) + k_p * (theta_r - q.tail(n_)), tau);
  return sigma;
}

double ClosedLoop::servo_step(const ConstRef& x, double k_p, double k_d, const ConstRef& theta_r,
                              const ConstRef& thetadot_r, const ConstRef& thetaddot_r, const ConstRef& forces, double dt,
                              bool staged, Ref x_next, Ref tau, Ref L) {
  const auto at = [&](const ConstRef& r, Index k) { return stage_sample(r, k, n_); };
  const double sigma = servo_control(x, k_p, k_d, at(theta_r, 0), at(thetadot_r, 0), at(thetaddot_r, 0), tau, L);
  const StageLaw law = [&](Index k, const ConstRef& x_s, Ref tau_s, Ref L_s) {
    servo_control(x_s, k_p, k_d, at(theta_r, k), at(thetadot_r, k), at(thetaddot_r, k), tau_s, L_s);
  };
  advance(x, tau, forces, dt, x_next, staged ? &law : nullptr);
  return sigma;
}

void ClosedLoop::check_sizes(const ConstRef& x, const Ref& tau, const Ref& L) const {
  if (x.size() != 2 * nv_ || tau.size() != n_ || L.size() != r_)
    throw std::invalid_argument("x has 2 nv entries, tau n, L one per selected base row");
}

void ClosedLoop::check_reference(const ConstRef& a, const ConstRef& b, const ConstRef& c) const {
  if (a.size() != n_ || b.size() != n_ || c.size() != n_) throw std::invalid_argument("references have n entries");
}

// One RK4 step, the torque held or the law's at each stage; forces = (f(t), f(t + dt/2), f(t + dt)).

// The result must be finite.

void ClosedLoop::advance(const ConstRef& x, const Ref& tau, const ConstRef& forces, double dt, Ref x_next,
                         const StageLaw* law) {
  if (forces.size() != 3 * m_ || x_next.size() != 2 * nv_)
    throw std::invalid_argument("forces has 3 m entries (f at t, t + dt/2, t + dt), x_next 2 nv");
  rk4(x, tau, forces, dt, x_next, law);
  if (!(x_next.allFinite() && tau.allFinite())) throw std::domain_error("the state became non-finite");
}

// M, c = (c_b, c_m), H_bm' theta' (rns_viz.model.FsmsModel.dynamics), the selected rows S and the

// damped H_bm^+ (rns_viz.rns.damped_pinv; closed form for one row). Writes L = S H_bm theta',

// Eq. (8); returns sigma_min(S H_bm).

double ClosedLoop::coupling(const ConstRef& q, const ConstRef& v, Ref L) {
  pinocchio::crba(model_, law_data_, q);  // fills the upper half
  law_data_.M.triangularView<Eigen::StrictlyLower>() = law_data_.M.transpose().triangularView<Eigen::StrictlyLower>();
  M_ = law_data_.M;
  c_ = pinocchio::nonLinearEffects(model_, law_data_, q, v);
  const auto thetadot = v.tail(n_);
  VectorXd hbm_dot(m_);
  if (cb_is_hbm_dot_) {
    hbm_dot = c_.head(m_);
  } else {
    const MatrixXd& C = pinocchio::computeCoriolisMatrix(model_, law_data_, q, v);
    hbm_dot = (C + C.transpose()).topRightCorner(m_, n_) * thetadot;
  }
  H_bm_.resize(r_, n_);
  H_b_.resize(r_, r_);
  xdot_b_.resize(r_);
  base_momentum_.resize(r_);
  hbm_dot_s_.resize(r_);
  for (Index i = 0; i < r_; ++i) {
    H_bm_.row(i) = M_.row(rows_[i]).tail(n_);
    xdot_b_(i) = v(rows_[i]);
    base_momentum_(i) = M_.row(rows_[i]).head(m_).dot(v.head(m_));  // all m velocities: S selects rows only
    hbm_dot_s_(i) = hbm_dot(rows_[i]);
    for (Index j = 0; j < r_; ++j) H_b_(i, j) = M_(rows_[i], rows_[j]);
  }
  L = H_bm_ * thetadot;
  pinv_.resize(n_, r_);
  double sigma;
  if (r_ == 1) {  // the column h w^2 / (w^2 |h|^2 + lambda^2)
    const double w2 = weights_(0) * weights_(0);
    const double sigma2 = w2 * H_bm_.row(0).squaredNorm();
    sigma = std::sqrt(sigma2);
    pinv_.col(0) = H_bm_.row(0).transpose() * (w2 / (sigma2 + damping_squared(sigma, threshold_, max_damping_)));
  } else {  // (W H)^T (W H (W H)^T + lambda^2 E)^-1 W
    const MatrixXd WH = weights_.asDiagonal() * H_bm_;
    sigma = smallest_singular_value(WH);
    const double lam2 = damping_squared(sigma, threshold_, max_damping_);
    const MatrixXd A = WH * WH.transpose() + lam2 * MatrixXd::Identity(r_, r_);
    pinv_ = WH.transpose() * A.partialPivLu().solve(MatrixXd::Identity(r_, r_)) * weights_.asDiagonal();
  }
  return sigma;
}

// Eq. (15): theta'' = H_bm^+ (S H_b G_b x_b' - H_bm' theta' - G_m L) + P u, P u = u - H_bm^+ (H_bm u).

// Without a reference u = -k_d theta' (DampNullMotion; k_p unused).

double ClosedLoop::composite(const ConstRef& x, double g_b, double g_m, double k_p, double k_d, const Reference* ref, Ref tau,
                 Ref L) {
  const ConstRef q = x.head(nv_);
  const ConstRef v = x.tail(nv_);
  const double sigma = coupling(q, v, L);
  const auto thetadot = v.tail(n_);
  VectorXd u = -k_d * thetadot;
  if (ref != nullptr) u += *ref->thetaddot + k_d * *ref->thetadot + k_p * (*ref->theta - q.tail(n_));
  const VectorXd Pu = u - pinv_ * (H_bm_ * u);
  realize(q, v, pinv_ * (g_b * base_momentum_ - hbm_dot_s_ - g_m * L) + Pu, tau);
  return sigma;
}

// Resolved acceleration (Fig. 1; rns_viz.control.common.realize_acceleration): the base

// acceleration predicted from the base rows of Eq. (1), then the arm rows give tau.

void ClosedLoop::realize(const ConstRef& q, const ConstRef& v, const VectorXd& thetaddot, Ref tau) {
  const auto Hb_all = M_.topLeftCorner(m_, m_);
  const auto Hbm_all = M_.topRightCorner(m_, n_);
  const VectorXd rhs = -K_ * q.head(m_) - D_ * v.head(m_) - c_.head(m_) - Hbm_all * thetaddot;
  const VectorXd xddot_b = m_ == 1 ? VectorXd(rhs / Hb_all(0, 0)) : VectorXd(Hb_all.ldlt().solve(rhs));
  tau = Hbm_all.transpose() * xddot_b + M_.bottomRightCorner(n_, n_) * thetaddot + c_.tail(n_);
  if (arm_damped_) tau += Dm_ * v.tail(n_);
}

// The plant's acceleration at stage state s with the held torque and the base force f_ext

// (rns_viz.sim.Plant.held_acceleration).

const VectorXd& ClosedLoop::held_acceleration(const ConstRef& q, const ConstRef& v, const ConstRef& tau, const ConstRef& f_ext) {
  u_.head(m_) = -K_ * q.head(m_) - D_ * v.head(m_) + f_ext;
  u_.tail(n_) = tau;
  if (arm_damped_) u_.tail(n_) -= Dm_ * v.tail(n_);
  return pinocchio::aba(model_, plant_data_, q, v, ConstRef(u_));
}

// Classical RK4 on x = (q, v) with the force at the stage times: k_1 at t, k_2 and k_3 at t + dt/2,

// k_4 at t + dt, and the torque held or the law's at each stage (rns_viz.sim.Plant.rk4_state_step).

void ClosedLoop::rk4(const ConstRef& x, const ConstRef& tau, const ConstRef& forces, double dt,
         Eigen::Ref<VectorXd> x_next, const StageLaw* law) {
  static constexpr double stage_step[3] = {0.5, 0.5, 1.0};
  static constexpr double weight[4] = {1.0, 2.0, 2.0, 1.0};
  static constexpr Index force_sample[4] = {0, 1, 1, 2};
  slope_sum_.setZero();
  stage_ = x;
  for (int s = 0; s < 4; ++s) {
    if (law != nullptr && s > 0) (*law)(force_sample[s], stage_, stage_tau_, stage_L_);  // the law at this stage
    // slope k_s = (v_s, a_s) at the stage state
    const ConstRef tau_s = (law != nullptr && s > 0) ? ConstRef(stage_tau_) : tau;
    const VectorXd& a =
        held_acceleration(stage_.head(nv_), stage_.tail(nv_), tau_s, forces.segment(force_sample[s] * m_, m_));
    slope_sum_.head(nv_) += weight[s] * stage_.tail(nv_);
    slope_sum_.tail(nv_) += weight[s] * a;
    if (s < 3) {
      const double h = stage_step[s] * dt;
      const VectorXd k_v = stage_.tail(nv_);
      stage_.head(nv_) = x.head(nv_) + h * k_v;
      stage_.tail(nv_) = x.tail(nv_) + h * a;
    }
  }
  x_next = x + (dt / 6.0) * slope_sum_;
}

}  // namespace rns_native
