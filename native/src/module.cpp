// The Python module rns_viz_native._core (nanobind): the classes of closed_loop.hpp.

#include "closed_loop.hpp"

#include <pinocchio/config.hpp>

#include <nanobind/eigen/dense.h>
#include <nanobind/nanobind.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <exception>
#include <stdexcept>

namespace nb = nanobind;
using rns_native::ClosedLoop;
using rns_native::MatrixXd;
using rns_native::RobotModel;

NB_MODULE(_core, mod) {
  mod.attr("PINOCCHIO_VERSION") = PINOCCHIO_VERSION;
  // what rns_viz.sim.native expects of this module; raised when a call changes its arguments
  mod.attr("API_VERSION") = 3;
  nb::register_exception_translator([](const std::exception_ptr& p, void*) {
    try {
      std::rethrow_exception(p);
    } catch (const std::domain_error& e) {  // a non-finite step: the simulator keeps its last state
      PyErr_SetString(PyExc_FloatingPointError, e.what());
    }
  });
  nb::class_<RobotModel>(mod, "RobotModel")
      .def(nb::init<const std::string&, const Eigen::Vector3d&>(), nb::arg("urdf_xml"), nb::arg("gravity"))
      .def_prop_ro("nv", &RobotModel::nv)
      .def("mass_matrix", &RobotModel::mass_matrix)
      .def("nonlinear_effects", &RobotModel::nonlinear_effects)
      .def("com_jacobians", &RobotModel::com_jacobians)
      .def("centers_of_mass", &RobotModel::centers_of_mass);
  nb::class_<ClosedLoop>(mod, "ClosedLoop")
      .def(nb::init<const RobotModel&, const std::vector<int>&, const rns_native::VectorXd&, const MatrixXd&,
                    const MatrixXd&, const MatrixXd&, double, double, bool, const std::string&, int,
                    const std::vector<int>&>())
      .def("damped_control", &ClosedLoop::damped_control)
      .def("damped_step", &ClosedLoop::damped_step)
      .def("tracking_control", &ClosedLoop::tracking_control)
      .def("tracking_step", &ClosedLoop::tracking_step)
      .def("task_control", &ClosedLoop::task_control)
      .def("task_step", &ClosedLoop::task_step)
      .def("velocity_control", &ClosedLoop::velocity_control)
      .def("velocity_step", &ClosedLoop::velocity_step)
      .def("servo_control", &ClosedLoop::servo_control)
      .def("servo_step", &ClosedLoop::servo_step);
}
