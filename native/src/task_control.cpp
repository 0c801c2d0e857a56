// Reactionless end-effector tracking, Eq. (24), as the null-space input of law (15) (see
// closed_loop.hpp).

#include "closed_loop.hpp"

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/kinematics.hpp>

#include <Eigen/Dense>

#include <stdexcept>

namespace rns_native {

std::pair<double, double> ClosedLoop::task_control(const ConstRef& x, double g_b, double g_m, double G_p, double G_d, double threshold,
                       const ConstRef& x_d, const ConstRef& xdot_d, const ConstRef& xddot_d, Ref tau, Ref L) {
  check_sizes(x, tau, L);
  const Index p = static_cast<Index>(task_rows_.size());
  if (p == 0 || x_d.size() != p || xdot_d.size() != p || xddot_d.size() != p)
    throw std::invalid_argument("the target has one entry per task axis");
  const ConstRef q = x.head(nv_);
  const ConstRef v = x.tail(nv_);
  const double sigma = coupling(q, v, L);
  const auto thetadot = v.tail(n_);
  // J, J' theta' and x_e relative to and in the base frame (rns_viz.model.FsmsModel.ee_kinematics)
  VectorXd v_rel = VectorXd::Zero(nv_);
  v_rel.tail(n_) = thetadot;
  const VectorXd zero = VectorXd::Zero(nv_);
  pinocchio::forwardKinematics(model_, task_data_, q, ConstRef(v_rel), ConstRef(zero));
  pinocchio::updateFramePlacement(model_, task_data_, ee_frame_);
  const Eigen::Matrix3d R = task_data_.oMi[base_joint_].rotation();
  const Eigen::Vector3d ee =
      R.transpose() * (task_data_.oMf[ee_frame_].translation() - task_data_.oMi[base_joint_].translation());
  const Eigen::Vector3d acc =
      R.transpose() *
      pinocchio::getFrameClassicalAcceleration(model_, task_data_, ee_frame_, pinocchio::LOCAL_WORLD_ALIGNED).linear();
  const VectorXd q_full = q;  // computeFrameJacobian is compiled for a VectorXd and a Matrix6x
  Matrix6x J6 = Matrix6x::Zero(6, nv_);
  pinocchio::computeFrameJacobian(model_, task_data_, q_full, ee_frame_, pinocchio::LOCAL_WORLD_ALIGNED, J6);
  const MatrixXd J_base = R.transpose() * J6.topRows(3).rightCols(n_);
  MatrixXd J(p, n_);
  VectorXd Jdot_thetadot(p), e(p);
  for (Index i = 0; i < p; ++i) {
    J.row(i) = J_base.row(task_rows_[i]);
    Jdot_thetadot(i) = acc(task_rows_[i]);
    e(i) = x_d(i) - ee(task_rows_[i]);
  }
  const VectorXd edot = xdot_d - J * thetadot;
  const MatrixXd J_bar = J * (MatrixXd::Identity(n_, n_) - pinv_ * H_bm_);
  const double sigma_jbar = smallest_singular_value(J_bar);
  const double lam2 = damping_squared(sigma_jbar, threshold, threshold);
  const MatrixXd G = J_bar * J_bar.transpose() + lam2 * MatrixXd::Identity(p, p);
  const VectorXd rhs = xddot_d + G_d * edot + G_p * e - Jdot_thetadot + J * (pinv_ * hbm_dot_s_);
  const VectorXd Pu = J_bar.transpose() * G.partialPivLu().solve(rhs);
  realize(q, v, pinv_ * (g_b * base_momentum_ - hbm_dot_s_ - g_m * L) + Pu, tau);
  return {sigma, sigma_jbar};
}

std::pair<double, double> ClosedLoop::task_step(const ConstRef& x, const ConstRef& g_b, double g_m, double G_p, double G_d, double threshold,
                    const ConstRef& x_d, const ConstRef& xdot_d, const ConstRef& xddot_d, const ConstRef& forces,
                    double dt, bool staged, Ref x_next, Ref tau, Ref L) {
  const Index p = static_cast<Index>(task_rows_.size());
  const auto at = [&](const ConstRef& r, Index k) { return stage_sample(r, k, p); };
  const auto gain = [&](Index k) { return stage_sample(g_b, k, 1)(0); };
  const auto sigmas =
      task_control(x, gain(0), g_m, G_p, G_d, threshold, at(x_d, 0), at(xdot_d, 0), at(xddot_d, 0), tau, L);
  const StageLaw law = [&](Index k, const ConstRef& x_s, Ref tau_s, Ref L_s) {
    task_control(x_s, gain(k), g_m, G_p, G_d, threshold, at(x_d, k), at(xdot_d, k), at(xddot_d, k), tau_s, L_s);
  };
  advance(x, tau, forces, dt, x_next, staged ? &law : nullptr);
  return sigmas;
}

}  // namespace rns_native
