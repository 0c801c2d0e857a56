// One closed-loop step of an FSMS in C++: a control law of the paper realised by resolved
// acceleration (Fig. 1), then one RK4 step of the plant with that torque held (a digital controller).
// Laws: the composite law, Eq. (15), with the null-space input u = -G_u theta' (Fig. 3),
// u = theta_r'' + k_d (theta_r' - theta') + k_p (theta_r - theta), or reactionless end-effector
// tracking, Eq. (24); and the velocity-command law, Eq. (30), behind a velocity servo
// theta'' = w_s (theta'_cmd - theta').
//
// The same arithmetic as rns_viz.control (AccelerationLaw, VelocityLaw) and
// rns_viz.sim.Plant.rk4_state_step; the tests compare trajectories to 1e-12. Dynamics only through
// pinocchio (crba, nonLinearEffects, computeCoriolisMatrix, aba) on the model the Python side built
// from URDF: no inertia by hand. References theta_r(t) are evaluated in Python and passed in.
//
// Python: _closed_loop.ClosedLoop(pin_model, rows, K_b, D_b, D_m, threshold, max_damping,
// cb_is_hbm_dot, ee_frame_id, base_joint_id, task_rows). Each *_step writes the next state, the torque and the coupling momentum into the
// given float64 arrays and returns sigma_min(S H_bm) (FloatingPointError when they are not finite);
// each *_control computes the law alone.
//
// Also batch kernels for the reactionless-path tracer (rns_viz.paths.CouplingField):
// com_jacobians(pin_model, m, thetas, J, com) and centers_of_mass(pin_model, m, thetas, com) evaluate
// pinocchio's centre-of-mass Jacobian / position at K arm configurations (x_b = 0) in one call.

#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/center-of-mass.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include <Eigen/Dense>
#include <eigenpy/eigenpy.hpp>
#include <boost/python.hpp>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace bp = boost::python;
using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;
using pinocchio::Data;
using pinocchio::Model;
using ConstRef = Eigen::Ref<const VectorXd>;
using Ref = Eigen::Ref<VectorXd>;

namespace {

// lambda^2 of the damped inverse for smallest singular value sigma (rns_viz.rns.damping_squared).
double damping_squared(double sigma, double threshold, double max_damping) {
  if (sigma >= threshold) return 0.0;
  const double r = sigma / threshold;
  return (1.0 - r * r) * max_damping * max_damping;
}

class ClosedLoop {
 public:
  ClosedLoop(const Model& model, const std::vector<int>& rows, const MatrixXd& K_b, const MatrixXd& D_b,
                const MatrixXd& D_m, double threshold, double max_damping, bool cb_is_hbm_dot, int ee_frame,
                int base_joint, const std::vector<int>& task_rows)
      : model_(model),
        law_data_(model),
        plant_data_(model),
        task_data_(model),
        ee_frame_(ee_frame),
        base_joint_(base_joint),
        task_rows_(task_rows),
        rows_(rows),
        K_(K_b),
        D_(D_b),
        Dm_(D_m),
        threshold_(threshold),
        max_damping_(max_damping),
        cb_is_hbm_dot_(cb_is_hbm_dot) {
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
    if (ee_frame < 0 || ee_frame >= static_cast<int>(model.nframes) || base_joint < 1 || base_joint >= model.njoints)
      throw std::invalid_argument("the end-effector frame or the base joint is not in the model");
    for (int i : task_rows)
      if (i < 0 || i > 2) throw std::invalid_argument("task rows are 0 (x), 1 (y) or 2 (z)");
    arm_damped_ = Dm_.cwiseAbs().maxCoeff() > 0.0;
    u_.setZero(nv_);
    stage_.setZero(2 * nv_);
    slope_sum_.setZero(2 * nv_);
  }

  // Eq. (15) with u = -g_u theta'.
  double damped_control(const ConstRef& x, double g_b, double g_m, double g_u, Ref tau, Ref L) {
    check_sizes(x, tau, L);
    return composite(x, g_b, g_m, 0.0, g_u, nullptr, tau, L);
  }
  double damped_step(const ConstRef& x, double g_b, double g_m, double g_u, const ConstRef& f_ext, double dt,
                     Ref x_next, Ref tau, Ref L) {
    const double sigma = damped_control(x, g_b, g_m, g_u, tau, L);
    advance(x, tau, f_ext, dt, x_next);
    return sigma;
  }

  // Eq. (15) with u = theta_r'' + k_d (theta_r' - theta') + k_p (theta_r - theta).
  double tracking_control(const ConstRef& x, double g_b, double g_m, double k_p, double k_d, const ConstRef& theta_r,
                          const ConstRef& thetadot_r, const ConstRef& thetaddot_r, Ref tau, Ref L) {
    check_sizes(x, tau, L);
    check_reference(theta_r, thetadot_r, thetaddot_r);
    const Reference ref{&theta_r, &thetadot_r, &thetaddot_r};
    return composite(x, g_b, g_m, k_p, k_d, &ref, tau, L);
  }
  double tracking_step(const ConstRef& x, double g_b, double g_m, double k_p, double k_d, const ConstRef& theta_r,
                       const ConstRef& thetadot_r, const ConstRef& thetaddot_r, const ConstRef& f_ext, double dt,
                       Ref x_next, Ref tau, Ref L) {
    const double sigma = tracking_control(x, g_b, g_m, k_p, k_d, theta_r, thetadot_r, thetaddot_r, tau, L);
    advance(x, tau, f_ext, dt, x_next);
    return sigma;
  }

  // Eq. (15) with Eq. (24): P u = J-bar^+ [x_d'' + G_d e' + G_p e - J' theta' + J H_bm^+ H_bm' theta'],
  // e = x_d - x_e, J-bar = J P_RNS with the damped inverse (threshold = max damping, m/rad).
  // Returns (sigma_min(S H_bm), sigma_min(J-bar)).
  bp::tuple task_control(const ConstRef& x, double g_b, double g_m, double G_p, double G_d, double threshold,
                         const ConstRef& x_d, const ConstRef& xdot_d, const ConstRef& xddot_d, Ref tau, Ref L) {
    check_sizes(x, tau, L);
    const Index p = static_cast<Index>(task_rows_.size());
    if (p == 0 || x_d.size() != p || xdot_d.size() != p || xddot_d.size() != p)
      throw std::invalid_argument("the target has one entry per task axis");
    const auto q = x.head(nv_);
    const auto v = x.tail(nv_);
    const double sigma = coupling(q, v, L);
    const auto thetadot = v.tail(n_);
    // J, J' theta' and x_e relative to and in the base frame (rns_viz.model.FsmsModel.ee_kinematics)
    VectorXd v_rel = VectorXd::Zero(nv_);
    v_rel.tail(n_) = thetadot;
    pinocchio::forwardKinematics(model_, task_data_, q, v_rel, VectorXd::Zero(nv_));
    pinocchio::updateFramePlacement(model_, task_data_, ee_frame_);
    const Eigen::Matrix3d R = task_data_.oMi[base_joint_].rotation();
    const Eigen::Vector3d ee =
        R.transpose() * (task_data_.oMf[ee_frame_].translation() - task_data_.oMi[base_joint_].translation());
    const Eigen::Vector3d acc =
        R.transpose() *
        pinocchio::getFrameClassicalAcceleration(model_, task_data_, ee_frame_, pinocchio::LOCAL_WORLD_ALIGNED).linear();
    MatrixXd J6 = MatrixXd::Zero(6, nv_);
    pinocchio::computeFrameJacobian(model_, task_data_, q, ee_frame_, pinocchio::LOCAL_WORLD_ALIGNED, J6);
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
    const double sigma_jbar = Eigen::JacobiSVD<MatrixXd>(J_bar).singularValues()(std::min(p, n_) - 1);
    const double lam2 = damping_squared(sigma_jbar, threshold, threshold);
    const MatrixXd G = J_bar * J_bar.transpose() + lam2 * MatrixXd::Identity(p, p);
    const VectorXd rhs = xddot_d + G_d * edot + G_p * e - Jdot_thetadot + J * (pinv_ * hbm_dot_s_);
    const VectorXd Pu = J_bar.transpose() * G.partialPivLu().solve(rhs);
    realize(q, v, pinv_ * (g_b * (H_b_ * xdot_b_) - hbm_dot_s_ - g_m * L) + Pu, tau);
    return bp::make_tuple(sigma, sigma_jbar);
  }
  bp::tuple task_step(const ConstRef& x, double g_b, double g_m, double G_p, double G_d, double threshold,
                      const ConstRef& x_d, const ConstRef& xdot_d, const ConstRef& xddot_d, const ConstRef& f_ext,
                      double dt, Ref x_next, Ref tau, Ref L) {
    bp::tuple sigmas = task_control(x, g_b, g_m, G_p, G_d, threshold, x_d, xdot_d, xddot_d, tau, L);
    advance(x, tau, f_ext, dt, x_next);
    return sigmas;
  }

  // Eq. (30): theta'_cmd = H_bm^+ H_b g_b x_b + g_m (theta_r - theta) [+ theta_r'], then the servo.
  double velocity_control(const ConstRef& x, double g_b, double g_m, double w_s, bool feedforward,
                          const ConstRef& theta_r, const ConstRef& thetadot_r, Ref tau, Ref L) {
    check_sizes(x, tau, L);
    check_reference(theta_r, thetadot_r, thetadot_r);
    const auto q = x.head(nv_);
    const auto v = x.tail(nv_);
    const double sigma = coupling(q, v, L);
    VectorXd x_b(r_);
    for (Index i = 0; i < r_; ++i) x_b(i) = q(rows_[i]);
    VectorXd cmd = pinv_ * (g_b * (H_b_ * x_b)) + g_m * (theta_r - q.tail(n_));
    if (feedforward) cmd += thetadot_r;
    realize(q, v, w_s * (cmd - v.tail(n_)), tau);
    return sigma;
  }
  double velocity_step(const ConstRef& x, double g_b, double g_m, double w_s, bool feedforward, const ConstRef& theta_r,
                       const ConstRef& thetadot_r, const ConstRef& f_ext, double dt, Ref x_next, Ref tau, Ref L) {
    const double sigma = velocity_control(x, g_b, g_m, w_s, feedforward, theta_r, thetadot_r, tau, L);
    advance(x, tau, f_ext, dt, x_next);
    return sigma;
  }

 private:
  struct Reference {
    const ConstRef* theta;
    const ConstRef* thetadot;
    const ConstRef* thetaddot;
  };

  void check_sizes(const ConstRef& x, const Ref& tau, const Ref& L) const {
    if (x.size() != 2 * nv_ || tau.size() != n_ || L.size() != r_)
      throw std::invalid_argument("x has 2 nv entries, tau n, L one per selected base row");
  }
  void check_reference(const ConstRef& a, const ConstRef& b, const ConstRef& c) const {
    if (a.size() != n_ || b.size() != n_ || c.size() != n_) throw std::invalid_argument("references have n entries");
  }

  // One RK4 step with the torque held; the result must be finite.
  void advance(const ConstRef& x, const Ref& tau, const ConstRef& f_ext, double dt, Ref x_next) {
    if (f_ext.size() != m_ || x_next.size() != 2 * nv_) throw std::invalid_argument("f_ext has m entries, x_next 2 nv");
    rk4(x, tau, f_ext, dt, x_next);
    if (!(x_next.allFinite() && tau.allFinite())) throw std::domain_error("the state became non-finite");
  }

  // M, c = (c_b, c_m), H_bm' theta' (rns_viz.model.FsmsModel.dynamics), the selected rows S and the
  // damped H_bm^+ (rns_viz.rns.damped_pinv; closed form for one row). Writes L = S H_bm theta',
  // Eq. (8); returns sigma_min(S H_bm).
  template <typename Q, typename V>
  double coupling(const Q& q, const V& v, Ref L) {
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
    hbm_dot_s_.resize(r_);
    for (Index i = 0; i < r_; ++i) {
      H_bm_.row(i) = M_.row(rows_[i]).tail(n_);
      xdot_b_(i) = v(rows_[i]);
      hbm_dot_s_(i) = hbm_dot(rows_[i]);
      for (Index j = 0; j < r_; ++j) H_b_(i, j) = M_(rows_[i], rows_[j]);
    }
    L = H_bm_ * thetadot;
    pinv_.resize(n_, r_);
    double sigma;
    if (r_ == 1) {
      const double sigma2 = H_bm_.row(0).squaredNorm();
      sigma = std::sqrt(sigma2);
      pinv_.col(0) = H_bm_.row(0).transpose() / (sigma2 + damping_squared(sigma, threshold_, max_damping_));
    } else {
      sigma = Eigen::JacobiSVD<MatrixXd>(H_bm_).singularValues()(r_ - 1);
      const double lam2 = damping_squared(sigma, threshold_, max_damping_);
      const MatrixXd A = H_bm_ * H_bm_.transpose() + lam2 * MatrixXd::Identity(r_, r_);
      pinv_ = H_bm_.transpose() * A.partialPivLu().solve(MatrixXd::Identity(r_, r_));
    }
    return sigma;
  }

  // Eq. (15): theta'' = H_bm^+ (H_b G_b x_b' - H_bm' theta' - G_m L) + P u, P u = u - H_bm^+ (H_bm u).
  // Without a reference u = -k_d theta' (DampNullMotion; k_p unused).
  double composite(const ConstRef& x, double g_b, double g_m, double k_p, double k_d, const Reference* ref, Ref tau,
                   Ref L) {
    const auto q = x.head(nv_);
    const auto v = x.tail(nv_);
    const double sigma = coupling(q, v, L);
    const auto thetadot = v.tail(n_);
    VectorXd u = -k_d * thetadot;
    if (ref != nullptr) u += *ref->thetaddot + k_d * *ref->thetadot + k_p * (*ref->theta - q.tail(n_));
    const VectorXd Pu = u - pinv_ * (H_bm_ * u);
    realize(q, v, pinv_ * (g_b * (H_b_ * xdot_b_) - hbm_dot_s_ - g_m * L) + Pu, tau);
    return sigma;
  }

  // Resolved acceleration (Fig. 1; rns_viz.control.common.realize_acceleration): the base
  // acceleration predicted from the base rows of Eq. (1), then the arm rows give tau.
  template <typename Q, typename V>
  void realize(const Q& q, const V& v, const VectorXd& thetaddot, Ref tau) {
    const auto Hb_all = M_.topLeftCorner(m_, m_);
    const auto Hbm_all = M_.topRightCorner(m_, n_);
    const VectorXd rhs = -K_ * q.head(m_) - D_ * v.head(m_) - c_.head(m_) - Hbm_all * thetaddot;
    const VectorXd xddot_b = m_ == 1 ? VectorXd(rhs / Hb_all(0, 0)) : VectorXd(Hb_all.ldlt().solve(rhs));
    tau = Hbm_all.transpose() * xddot_b + M_.bottomRightCorner(n_, n_) * thetaddot + c_.tail(n_);
    if (arm_damped_) tau += Dm_ * v.tail(n_);
  }

  // The plant's acceleration at stage state s with the held inputs (rns_viz.sim.Plant.held_acceleration).
  template <typename S>
  const VectorXd& held_acceleration(const S& s, const ConstRef& tau, const ConstRef& f_ext) {
    const auto q = s.head(nv_);
    const auto v = s.tail(nv_);
    u_.head(m_) = -K_ * q.head(m_) - D_ * v.head(m_) + f_ext;
    u_.tail(n_) = tau;
    if (arm_damped_) u_.tail(n_) -= Dm_ * v.tail(n_);
    return pinocchio::aba(model_, plant_data_, q, v, u_);
  }

  // Classical RK4 on x = (q, v) with the inputs held (rns_viz.sim.Plant.rk4_state_step).
  void rk4(const ConstRef& x, const ConstRef& tau, const ConstRef& f_ext, double dt,
           Eigen::Ref<VectorXd> x_next) {
    static constexpr double stage_step[3] = {0.5, 0.5, 1.0};
    static constexpr double weight[4] = {1.0, 2.0, 2.0, 1.0};
    slope_sum_.setZero();
    stage_ = x;
    for (int s = 0; s < 4; ++s) {
      // slope k_s = (v_s, a_s) at the stage state
      const VectorXd& a = held_acceleration(stage_, tau, f_ext);
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

  Model model_;
  Data law_data_, plant_data_, task_data_;
  int ee_frame_, base_joint_;
  std::vector<int> task_rows_;
  std::vector<int> rows_;
  MatrixXd K_, D_, Dm_;
  double threshold_, max_damping_;
  bool cb_is_hbm_dot_, arm_damped_ = false;
  Index nv_ = 0, m_ = 0, n_ = 0, r_ = 0;
  VectorXd u_, stage_, slope_sum_;
  // the law's terms at the current state (coupling())
  MatrixXd M_, H_bm_, H_b_, pinv_;
  VectorXd c_, xdot_b_, hbm_dot_s_;
};

std::vector<int> int_list(const bp::object& seq) {
  std::vector<int> out;
  for (bp::ssize_t i = 0; i < bp::len(seq); ++i) out.push_back(bp::extract<int>(seq[i]));
  return out;
}

ClosedLoop* make_closed_loop(const Model& model, const bp::object& rows, const MatrixXd& K_b, const MatrixXd& D_b,
                             const MatrixXd& D_m, double threshold, double max_damping, bool cb_is_hbm_dot, int ee_frame,
                             int base_joint, const bp::object& task_rows) {
  return new ClosedLoop(model, int_list(rows), K_b, D_b, D_m, threshold, max_damping, cb_is_hbm_dot, ee_frame,
                        base_joint, int_list(task_rows));
}

// K configurations theta (K*n, row after row) with x_b = 0: writes J_com's arm columns (K*3*n,
// each 3 x n row-major) and, if com has 3*K entries, the centre of mass (pinocchio, world frame).
void com_jacobians(const Model& model, int m, const ConstRef& thetas, Ref J, Ref com) {
  const Index n = model.nv - m;
  if (m < 1 || n < 1 || model.nq != model.nv || thetas.size() % n != 0)
    throw std::invalid_argument("thetas must hold K rows of the arm's n joint angles");
  const Index K = thetas.size() / n;
  const bool want_com = com.size() == 3 * K;
  if (J.size() != 3 * n * K || !(want_com || com.size() == 0))
    throw std::invalid_argument("J has K*3*n entries and com 3*K (or none)");
  Data data(model);
  VectorXd q = VectorXd::Zero(model.nq);
  for (Index k = 0; k < K; ++k) {
    q.tail(n) = thetas.segment(k * n, n);
    const auto& Jc = pinocchio::jacobianCenterOfMass(model, data, q, false);
    for (Index r = 0; r < 3; ++r) J.segment(k * 3 * n + r * n, n) = Jc.row(r).tail(n).transpose();
    if (want_com) com.segment(3 * k, 3) = data.com[0];
  }
}

// The centre of mass alone (K*3 entries) at K arm configurations, x_b = 0.
void centers_of_mass(const Model& model, int m, const ConstRef& thetas, Ref com) {
  const Index n = model.nv - m;
  if (m < 1 || n < 1 || model.nq != model.nv || thetas.size() % n != 0 || com.size() != 3 * (thetas.size() / n))
    throw std::invalid_argument("thetas holds K rows of n angles, com 3*K entries");
  Data data(model);
  VectorXd q = VectorXd::Zero(model.nq);
  for (Index k = 0; k < thetas.size() / n; ++k) {
    q.tail(n) = thetas.segment(k * n, n);
    com.segment(3 * k, 3) = pinocchio::centerOfMass(model, data, q, false);
  }
}

void translate(const std::invalid_argument& e) { PyErr_SetString(PyExc_ValueError, e.what()); }
void translate_diverged(const std::domain_error& e) { PyErr_SetString(PyExc_FloatingPointError, e.what()); }

}  // namespace

BOOST_PYTHON_MODULE(_closed_loop) {
  eigenpy::enableEigenPy();
  bp::import("pinocchio");  // registers pinocchio.Model with boost.python
  bp::register_exception_translator<std::invalid_argument>(&translate);
  bp::register_exception_translator<std::domain_error>(&translate_diverged);
  bp::class_<ClosedLoop, boost::noncopyable>("ClosedLoop", bp::no_init)
      .def("__init__", bp::make_constructor(&make_closed_loop))
      .def("damped_control", &ClosedLoop::damped_control)
      .def("damped_step", &ClosedLoop::damped_step)
      .def("tracking_control", &ClosedLoop::tracking_control)
      .def("tracking_step", &ClosedLoop::tracking_step)
      .def("task_control", &ClosedLoop::task_control)
      .def("task_step", &ClosedLoop::task_step)
      .def("velocity_control", &ClosedLoop::velocity_control)
      .def("velocity_step", &ClosedLoop::velocity_step);
  bp::def("com_jacobians", &com_jacobians);
  bp::def("centers_of_mass", &centers_of_mass);
}
