// The pinocchio model built from URDF text, and the path tracer's centre-of-mass kernels (see
// closed_loop.hpp).

#include "closed_loop.hpp"

#include <pinocchio/algorithm/center-of-mass.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/parsers/urdf.hpp>

#include <stdexcept>

namespace rns_native {

RobotModel::RobotModel(const std::string& urdf_xml, const Eigen::Vector3d& gravity) {
  pinocchio::urdf::buildModelFromXML(urdf_xml, model_);
  model_.gravity.linear(gravity);
}

void RobotModel::check_q(const ConstRef& q) const {
  if (q.size() != model_.nq) throw std::invalid_argument("q has nq entries");
}

MatrixXd RobotModel::mass_matrix(const ConstRef& q) const {
  check_q(q);
  Data data(model_);
  pinocchio::crba(model_, data, q);  // fills the upper half
  data.M.triangularView<Eigen::StrictlyLower>() = data.M.transpose().triangularView<Eigen::StrictlyLower>();
  return data.M;
}

VectorXd RobotModel::nonlinear_effects(const ConstRef& q, const ConstRef& v) const {
  check_q(q);
  if (v.size() != model_.nv) throw std::invalid_argument("v has nv entries");
  Data data(model_);
  return pinocchio::nonLinearEffects(model_, data, q, v);
}

void RobotModel::com_jacobians(int m, const ConstRef& thetas, Ref J, Ref com) const {
  const Index n = model_.nv - m;
  if (m < 1 || n < 1 || model_.nq != model_.nv || thetas.size() % n != 0)
    throw std::invalid_argument("thetas must hold K rows of the arm's n joint angles");
  const Index K = thetas.size() / n;
  const bool want_com = com.size() == 3 * K;
  if (J.size() != 3 * n * K || !(want_com || com.size() == 0))
    throw std::invalid_argument("J has K*3*n entries and com 3*K (or none)");
  Data data(model_);
  VectorXd q = VectorXd::Zero(model_.nq);
  for (Index k = 0; k < K; ++k) {
    q.tail(n) = thetas.segment(k * n, n);
    const auto& Jc = pinocchio::jacobianCenterOfMass(model_, data, ConstRef(q), false);
    for (Index r = 0; r < 3; ++r) J.segment(k * 3 * n + r * n, n) = Jc.row(r).tail(n).transpose();
    if (want_com) com.segment(3 * k, 3) = data.com[0];
  }
}

void RobotModel::centers_of_mass(int m, const ConstRef& thetas, Ref com) const {
  const Index n = model_.nv - m;
  if (m < 1 || n < 1 || model_.nq != model_.nv || thetas.size() % n != 0 || com.size() != 3 * (thetas.size() / n))
    throw std::invalid_argument("thetas holds K rows of n angles, com 3*K entries");
  Data data(model_);
  VectorXd q = VectorXd::Zero(model_.nq);
  for (Index k = 0; k < thetas.size() / n; ++k) {
    q.tail(n) = thetas.segment(k * n, n);
    com.segment(3 * k, 3) = pinocchio::centerOfMass(model_, data, ConstRef(q), false);
  }
}

}  // namespace rns_native
