// A report struct of the engine bound as a Python record, from the struct's one list of fields
// (`Record::visit_fields`): keyword construction, read-write attributes, repr, equality,
// pickling and, where the engine can combine two reports (`Record::add`), `+`. The engine's
// structs are the records Python sees; nothing spells their fields a second time (issue 36).
#pragma once

#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "bindings.hpp"

namespace snede::bindings {

// A record equals itself field by field, NaN included (as a dataclass holding the same float
// objects does): a DIVERGED_NONFINITE_STATE result carries a NaN residual norm.
inline bool same_value(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }
inline bool same_value(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](double x, double y) { return same_value(x, y); });
}
template <class T>
bool same_value(const T& a, const T& b) {
  return a == b;
}

template <class T>
constexpr bool is_sequence = false;
template <class T, class Allocator>
constexpr bool is_sequence<std::vector<T, Allocator>> = true;
template <class T, std::size_t N>
constexpr bool is_sequence<std::array<T, N>> = true;

// The fields by name, as Python reads them (sequences as tuples).
template <class Record>
py::dict record_fields(const Record& record) {
  py::dict values;
  Record::visit_fields([&](const char* name, auto member) {
    py::object value = py::cast(record.*member);
    values[name] = py::isinstance<py::list>(value) ? py::tuple(value) : value;
  });
  return values;
}

// The record from keyword values; a TypeError names an unknown field, as a dataclass's would.
template <class Record>
Record record_from(const char* type_name, const py::dict& values) {
  Record record;
  py::ssize_t used = 0;
  Record::visit_fields([&](const char* name, auto member) {
    if (!values.contains(name)) return;
    using Field = std::remove_reference_t<decltype(record.*member)>;
    try {
      record.*member = values[name].template cast<Field>();
    } catch (const py::cast_error&) {
      throw py::type_error(std::string(type_name) + "(): " + name + " cannot be " +
                           py::cast<std::string>(py::repr(values[name])));
    }
    ++used;
  });
  if (used == static_cast<py::ssize_t>(values.size())) return record;
  for (const auto& [key, value] : values) {
    bool known = false;
    Record::visit_fields([&](const char* name, auto) { known = known || py::cast<std::string>(py::str(key)) == name; });
    if (!known)
      throw py::type_error(std::string(type_name) + "() got an unexpected keyword argument " + py::cast<std::string>(py::repr(key)));
  }
  return record;
}

template <class Record>
py::class_<Record> bind_record(py::module_& m, const char* type_name, const char* doc) {
  py::class_<Record> cls(m, type_name, doc);
  cls.def(py::init([type_name](const py::kwargs& values) { return record_from<Record>(type_name, values); }));
  Record::visit_fields([&](const char* name, auto member) {
    using Field = std::remove_reference_t<decltype(std::declval<Record&>().*member)>;
    if constexpr (is_sequence<Field>) {
      // A record is a value: its sequences read as tuples, so changing one cannot go unseen.
      cls.def_property(
          name, [member](const Record& record) { return py::tuple(py::cast(record.*member)); },
          [member](Record& record, const Field& value) { record.*member = value; });
    } else {
      cls.def_readwrite(name, member);
    }
  });
  cls.def("__repr__", [type_name](const Record& record) {
    std::string text = std::string(type_name) + "(";
    const char* separator = "";
    for (const auto& [name, value] : record_fields(record)) {
      text += separator + py::cast<std::string>(name) + "=" + py::cast<std::string>(py::repr(value));
      separator = ", ";
    }
    return text + ")";
  });
  cls.def(
      "__eq__",
      [](const Record& a, const py::object& other) -> py::object {
        if (!py::isinstance<Record>(other)) return py::reinterpret_borrow<py::object>(Py_NotImplemented);
        const Record& b = other.cast<const Record&>();
        bool same = true;
        Record::visit_fields([&](const char*, auto member) { same = same && same_value(a.*member, b.*member); });
        return py::bool_(same);
      },
      py::is_operator());
  // Pickling and copying rebuild the record from its type and fields, under every pickle
  // protocol (pybind11's own pickling needs protocol 2 and aborted the process below it).
  if (!py::hasattr(m, "_record_from_fields"))
    m.def("_record_from_fields", [](const py::object& type, const py::dict& values) { return type(**values); });
  cls.def("__reduce__", [m](const py::object& self) {
    return py::make_tuple(m.attr("_record_from_fields"),
                          py::make_tuple(py::type::of(self), record_fields(self.cast<const Record&>())));
  });
  if constexpr (requires(Record& a, const Record& b) { a.add(b); }) {
    cls.def("__add__", [](const Record& a, const Record& b) {
      Record sum = a;
      sum.add(b);
      return sum;
    });
  }
  return cls;
}

}  // namespace snede::bindings
