#include "bindings.hpp"
#include "petsc4py_interop.hpp"
#include "solve/distributed_static.hpp"
#include "solve/dynamic_relaxation.hpp"

#include <pybind11/stl.h>

namespace snede::bindings {

void bind_dynamics(py::module_& m) {
  py::class_<DynamicRelaxation>(m, "DynamicRelaxation")
      .def(py::init<Model&, double, double, const std::string&, const OptionList&>(), py::arg("model"),
           py::arg("damping"), py::arg("dt"), py::arg("options_prefix"), py::arg("petsc_options"),
           py::keep_alive<1, 2>())
      // The same solver over a distributed problem, on its communicator (collective).
      .def(py::init<Problem&, double, double, const std::string&, const OptionList&>(), py::arg("problem"),
           py::arg("damping"), py::arg("dt"), py::arg("options_prefix"), py::arg("petsc_options"),
           py::keep_alive<1, 2>())
      .def("step", &DynamicRelaxation::step, py::arg("n"))
      .def("run", &DynamicRelaxation::run, py::arg("rtol"), py::arg("max_steps"))
      .def("cfl_time_step", &DynamicRelaxation::cfl_time_step)
      .def("critical_time_step", &DynamicRelaxation::critical_time_step, py::arg("flop_budget"), py::arg("initial"),
           py::arg("reduction"), py::arg("min_steps"))
      .def_property("dt", &DynamicRelaxation::time_step, &DynamicRelaxation::set_time_step)
      .def_property_readonly("damping", &DynamicRelaxation::damping)
      .def_property(
          "velocity", [](DynamicRelaxation& s) { return to_array(s.velocity(), s.problem().dim()); },
          [](DynamicRelaxation& s, const DoubleArray& v) {
            s.set_velocity({v.data(), static_cast<std::size_t>(v.size())});
          })
      .def_property_readonly("ts", [](const DynamicRelaxation& s) { return to_petsc4py(s.ts()); });
}

}  // namespace snede::bindings
