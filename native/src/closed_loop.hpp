// One closed-loop step of an FSMS in C++: a control law of the paper realised by resolved
// acceleration (Fig. 1), then one RK4 step of the plant with that torque held (a digital controller)
// or, with ``staged``, the law evaluated again at every RK4 stage (its state and time: a joint servo,
// rns_viz.control.ControlLaw.sampled), and the external base force sampled at the stage times t,
// t + dt/2, t + dt.
// Laws: the composite law, Eq. (15), with the null-space input u = -G_u theta' (Fig. 3),
// u = theta_r'' + k_d (theta_r' - theta') + k_p (theta_r - theta), or reactionless end-effector
// tracking, Eq. (24); the velocity-command law, Eq. (30), behind a velocity servo
// theta'' = w_s (theta'_cmd - theta'); and the joint servo that holds or moves the arm,
// theta'' = theta_r'' + k_d (theta_r' - theta') + k_p (theta_r - theta).
//
// The same arithmetic as rns_viz.control (AccelerationLaw, VelocityLaw, JointServo) and
// rns_viz.sim.Plant.rk4_state_step; the tests compare trajectories to 1e-12. Dynamics only through
// pinocchio (crba, nonLinearEffects, computeCoriolisMatrix, aba) on a model built here from the
// same URDF text and gravity as rns_viz.model (pinocchio's URDF parser): no inertia by hand, and
// no pinocchio Python object crosses the boundary (only str, float and float64 arrays).
// References theta_r(t) are evaluated in Python and passed in.
//
// Python (module rns_viz_native._core, bound with nanobind in module.cpp):
//   RobotModel(urdf_xml, gravity): mass_matrix(q), nonlinear_effects(q, v), nv, and the batch
//     kernels of the reactionless-path tracer (rns_viz.paths.CouplingField):
//     com_jacobians(m, thetas, J, com) and centers_of_mass(m, thetas, com) evaluate pinocchio's
//     centre-of-mass Jacobian / position at K arm configurations (x_b = 0) in one call.
//   ClosedLoop(robot, rows, row_weights, K_b, D_b, D_m, threshold, max_damping, cb_is_hbm_dot, ee_frame,
//     base_joint, task_rows): row_weights W weigh the selected rows of S H_bm into one unit (its moment
//     rows divided by the arm's reach, rns_viz.rns.singularity_distance) for sigma_min and the damping. Each *_step (..., forces, dt, staged, x_next, tau, L) writes the next
//     state, the torque and the coupling momentum at the step's start into the given float64
//     arrays and returns sigma_min(S H_bm) (FloatingPointError when they are not finite); its
//     time-varying inputs, g_b and the reference (theta_r, ..., or x_d, ...), hold one sample, or
//     with ``staged`` may hold three, at t, t + dt/2 and t + dt, stacked like the forces. Each
//     *_control computes the law alone at one sample.
//   PINOCCHIO_VERSION: the pinocchio release whose headers this was compiled against.

// Files: this header; robot_model.cpp (the URDF parser), closed_loop.cpp (laws (15), (30), RK4),
// task_control.cpp (Eq. 24), module.cpp (bindings). Split so that no file needs more than ~1.5 GB
// of memory to compile, and CMake compiles them one at a time.
//
// Every vector handed to pinocchio is a ConstRef: its algorithms are then the instantiations
// compiled into libpinocchio_default (declared extern with PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION),
// the code pinocchio's Python bindings run, and they are not instantiated again here.
#pragma once

#include <pinocchio/multibody.hpp>

#include <Eigen/Core>

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace rns_native {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;
using pinocchio::Data;
using pinocchio::Model;
using ConstRef = Eigen::Ref<const VectorXd>;
using Ref = Eigen::Ref<VectorXd>;
using Matrix6x = Data::Matrix6x;

// lambda^2 of the damped inverse for smallest singular value sigma (rns_viz.rns.damping_squared).
inline double damping_squared(double sigma, double threshold, double max_damping) {
  if (sigma >= threshold) return 0.0;
  const double r = sigma / threshold;
  return (1.0 - r * r) * max_damping * max_damping;
}

// Sample k (0: t, 1: t + dt/2, 2: t + dt) of a reference given at the three stage times (3 size
// entries), or the one sample given (size entries) at every stage.
inline ConstRef stage_sample(const ConstRef& r, Index k, Index size) {
  return r.size() == 3 * size ? ConstRef(r.segment(k * size, size)) : r;
}

// sigma_min of A by Eigen's JacobiSVD (in closed_loop.cpp only: one instantiation to compile).
double smallest_singular_value(const MatrixXd& A);

// The model of rns_viz.model._build_pinocchio_model: pinocchio's URDF parser on the same text, then
// the gravity of the parameter file.
class RobotModel {
 public:
  RobotModel(const std::string& urdf_xml, const Eigen::Vector3d& gravity);
  const Model& model() const { return model_; }
  int nv() const { return model_.nv; }

  // M(q) of Eq. (1), full and symmetric (what pinocchio's Python crba returns).
  MatrixXd mass_matrix(const ConstRef& q) const;
  // c(q, v) of Eq. (1): Coriolis, centrifugal and gravity terms.
  VectorXd nonlinear_effects(const ConstRef& q, const ConstRef& v) const;

  // K configurations theta (K*n, row after row) with x_b = 0: writes J_com's arm columns (K*3*n,
  // each 3 x n row-major) and, if com has 3*K entries, the centre of mass (pinocchio, world frame).
  void com_jacobians(int m, const ConstRef& thetas, Ref J, Ref com) const;
  // The centre of mass alone (K*3 entries) at K arm configurations, x_b = 0.
  void centers_of_mass(int m, const ConstRef& thetas, Ref com) const;

 private:
  void check_q(const ConstRef& q) const;
  Model model_;
};

class ClosedLoop {
 public:
  ClosedLoop(const RobotModel& robot, const std::vector<int>& rows, const VectorXd& row_weights, const MatrixXd& K_b,
             const MatrixXd& D_b,
             const MatrixXd& D_m, double threshold, double max_damping, bool cb_is_hbm_dot, const std::string& ee_frame,
             int base_joint, const std::vector<int>& task_rows);

  // Eq. (15) with u = -g_u theta'.
  double damped_control(const ConstRef& x, double g_b, double g_m, double g_u, Ref tau, Ref L);
  double damped_step(const ConstRef& x, const ConstRef& g_b, double g_m, double g_u, const ConstRef& forces, double dt,
                     bool staged, Ref x_next, Ref tau, Ref L);

  // Eq. (15) with u = theta_r'' + k_d (theta_r' - theta') + k_p (theta_r - theta).
  double tracking_control(const ConstRef& x, double g_b, double g_m, double k_p, double k_d, const ConstRef& theta_r,
                          const ConstRef& thetadot_r, const ConstRef& thetaddot_r, Ref tau, Ref L);
  double tracking_step(const ConstRef& x, const ConstRef& g_b, double g_m, double k_p, double k_d, const ConstRef& theta_r,
                       const ConstRef& thetadot_r, const ConstRef& thetaddot_r, const ConstRef& forces, double dt,
                       bool staged, Ref x_next, Ref tau, Ref L);

  // Eq. (15) with Eq. (24): P u = J-bar^+ [x_d'' + G_d e' + G_p e - J' theta' + J H_bm^+ H_bm' theta'],
  // e = x_d - x_e, J-bar = J P_RNS with the damped inverse (threshold = max damping, m/rad).
  // Returns (sigma_min(S H_bm), sigma_min(J-bar)).
  std::pair<double, double> task_control(const ConstRef& x, double g_b, double g_m, double G_p, double G_d, double threshold,
                         const ConstRef& x_d, const ConstRef& xdot_d, const ConstRef& xddot_d, Ref tau, Ref L);
  std::pair<double, double> task_step(const ConstRef& x, const ConstRef& g_b, double g_m, double G_p, double G_d, double threshold,
                      const ConstRef& x_d, const ConstRef& xdot_d, const ConstRef& xddot_d, const ConstRef& forces,
                      double dt, bool staged, Ref x_next, Ref tau, Ref L);

  // Eq. (30): theta'_cmd = H_bm^+ H_b g_b x_b + g_m (theta_r - theta) [+ theta_r'], then the servo.
  double velocity_control(const ConstRef& x, double g_b, double g_m, double w_s, bool feedforward,
                          const ConstRef& theta_r, const ConstRef& thetadot_r, Ref tau, Ref L);
  double velocity_step(const ConstRef& x, const ConstRef& g_b, double g_m, double w_s, bool feedforward, const ConstRef& theta_r,
                       const ConstRef& thetadot_r, const ConstRef& forces, double dt, bool staged, Ref x_next, Ref tau,
                       Ref L);

  // The joint servo (rns_viz.control.JointServo): theta'' = theta_r'' + k_d (theta_r' - theta') + k_p (theta_r - theta).
  double servo_control(const ConstRef& x, double k_p, double k_d, const ConstRef& theta_r, const ConstRef& thetadot_r,
                       const ConstRef& thetaddot_r, Ref tau, Ref L);
  double servo_step(const ConstRef& x, double k_p, double k_d, const ConstRef& theta_r, const ConstRef& thetadot_r,
                    const ConstRef& thetaddot_r, const ConstRef& forces, double dt, bool staged, Ref x_next, Ref tau,
                    Ref L);

 private:
  struct Reference {
    const ConstRef* theta;
    const ConstRef* thetadot;
    const ConstRef* thetaddot;
  };

  void check_sizes(const ConstRef& x, const Ref& tau, const Ref& L) const;
  void check_reference(const ConstRef& a, const ConstRef& b, const ConstRef& c) const;

  // The law at a stage: reference sample k (0: t, 1: t + dt/2, 2: t + dt) and state x_s; writes its
  // torque (its coupling momentum goes to a scratch vector).
  using StageLaw = std::function<void(Index k, const ConstRef& x_s, Ref tau_s, Ref L_s)>;

  // One RK4 step, forces = (f(t), f(t + dt/2), f(t + dt)), 3 m entries: the torque tau held over it
  // (law == nullptr) or tau at the first stage and the law's torque at the others. The result must be
  // finite.
  void advance(const ConstRef& x, const Ref& tau, const ConstRef& forces, double dt, Ref x_next,
               const StageLaw* law = nullptr);

  // M, c = (c_b, c_m), H_bm' theta' (rns_viz.model.FsmsModel.dynamics), the selected rows S and the
  // damped H_bm^+ = (W S H_bm)^+ W (rns_viz.rns.weighted_damped_pinv; closed form for one row). Writes
  // L = S H_bm theta', Eq. (8); returns sigma_min(W S H_bm).
  double coupling(const ConstRef& q, const ConstRef& v, Ref L);

  // Eq. (15): theta'' = H_bm^+ (H_b G_b x_b' - H_bm' theta' - G_m L) + P u, P u = u - H_bm^+ (H_bm u).
  // Without a reference u = -k_d theta' (DampNullMotion; k_p unused).
  double composite(const ConstRef& x, double g_b, double g_m, double k_p, double k_d, const Reference* ref, Ref tau,
                   Ref L);

  // Resolved acceleration (Fig. 1; rns_viz.control.common.realize_acceleration): the base
  // acceleration predicted from the base rows of Eq. (1), then the arm rows give tau.
  void realize(const ConstRef& q, const ConstRef& v, const VectorXd& thetaddot, Ref tau);

  // The plant's acceleration at stage state s with the held torque and the base force f_ext
  // (rns_viz.sim.Plant.held_acceleration).
  const VectorXd& held_acceleration(const ConstRef& q, const ConstRef& v, const ConstRef& tau, const ConstRef& f_ext);

  // Classical RK4 on x = (q, v) with the force at the stage times: k_1 at t, k_2 and k_3 at t + dt/2,
  // k_4 at t + dt, and the torque held or from the law at each stage (rns_viz.sim.Plant.rk4_state_step).
  void rk4(const ConstRef& x, const ConstRef& tau, const ConstRef& forces, double dt, Eigen::Ref<VectorXd> x_next,
           const StageLaw* law);

  Model model_;
  Data law_data_, plant_data_, task_data_;
  int ee_frame_, base_joint_;
  std::vector<int> task_rows_;
  std::vector<int> rows_;
  VectorXd weights_;  // W over the selected rows
  MatrixXd K_, D_, Dm_;
  double threshold_, max_damping_;
  bool cb_is_hbm_dot_, arm_damped_ = false;
  Index nv_ = 0, m_ = 0, n_ = 0, r_ = 0;
  VectorXd u_, stage_, slope_sum_, stage_tau_, stage_L_;
  // the law's terms at the current state (coupling())
  MatrixXd M_, H_bm_, H_b_, pinv_;
  VectorXd c_, xdot_b_, hbm_dot_s_, base_momentum_;  // base_momentum_: S H_b x_b' (Eq. 15, S on rows)
};

}  // namespace rns_native
