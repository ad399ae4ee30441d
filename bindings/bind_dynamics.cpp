#include "bindings.hpp"
#include "petsc4py_interop.hpp"
#include "record_binding.hpp"
#include "problem/distributed_static.hpp"
#include "solvers/dynamic_relaxation.hpp"

#include <pybind11/stl.h>

namespace snede::bindings {

void bind_dynamics(py::module_& m) {
  bind_record<DynamicRelaxationOptions>(
      m, "DynamicRelaxationOptions",
      "A dynamic relaxation's settings (snede.DynamicRelaxation documents each; ``dt`` None takes the CFL\n"
      "estimate); the engine's struct. A negative or non-finite damping, or a step that is not positive\n"
      "and finite, is a ValueError.");

  py::class_<DynamicRelaxation>(m, "DynamicRelaxation")
      .def(py::init<Model&, const DynamicRelaxationOptions&>(), py::arg("model"), py::arg("options"),
           py::keep_alive<1, 2>())
      // The same solver over a distributed problem, on its communicator (collective).
      .def(py::init<Problem&, const DynamicRelaxationOptions&>(), py::arg("problem"), py::arg("options"),
           py::keep_alive<1, 2>())
      // Without the GIL (other Python threads run); the interrupt check and petsc4py's callbacks take it.
      .def("step", &DynamicRelaxation::step, py::arg("n"), py::call_guard<py::gil_scoped_release>())
      .def("run", &DynamicRelaxation::run, py::arg("rtol"), py::arg("max_steps"),
           py::call_guard<py::gil_scoped_release>())
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
