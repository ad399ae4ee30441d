// A report or options struct of the engine bound as a Python record, from the struct's one list
// of fields (`Record::visit_fields`): keyword construction, read-write attributes, repr,
// equality, `_asdict()`, pickling and, where the engine can combine two reports (`Record::add`), `+`. The
// engine's structs are the records Python sees; nothing spells their fields a second time
// (issue 36).
//
// visit_fields names each field by a data member pointer, or by a function of the record that
// returns a reference to the field (a field of a member struct). A field of an enum type the
// engine names (`enum_names(value)`, core/enum_names.hpp) reads and writes as its name. A
// record with `validate()` is checked whenever Python makes or changes one.
#pragma once

#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "core/enum_names.hpp"

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

// The field of `record` that `member` names (see the top of this file).
template <class Record, class Member>
decltype(auto) field_of(Record& record, const Member& member) {
  if constexpr (std::is_member_object_pointer_v<Member>)
    return (record.*member);
  else
    return member(record);
}

template <class Record, class Member>
using FieldType = std::remove_cvref_t<decltype(field_of(std::declval<Record&>(), std::declval<const Member&>()))>;

template <class T>
concept NamedEnum = std::is_enum_v<T> && requires(T value) { enum_names(value); };

// A field as Python reads it: a named enum as its name, a sequence as a tuple.
template <class Field>
py::object python_value(const Field& value) {
  if constexpr (NamedEnum<Field>) {
    return py::str(enum_name(enum_names(value), value));
  } else {
    py::object object = py::cast(value);
    return py::isinstance<py::list>(object) ? py::tuple(object) : object;
  }
}

// A field from a Python value: a named enum from its name (std::invalid_argument, a
// ValueError, for another name); a TypeError names the field a value cannot be.
template <class Field>
Field field_value(const char* type_name, const char* name, const py::handle& value) {
  try {
    if constexpr (NamedEnum<Field>)
      return enum_value(enum_names(Field{}), name, value.cast<std::string>());
    else
      return value.cast<Field>();
  } catch (const py::cast_error&) {
    throw py::type_error(std::string(type_name) + "(): " + name + " cannot be " +
                         py::cast<std::string>(py::repr(value)));
  }
}

template <class Record>
void validate(const Record& record) {
  if constexpr (requires { record.validate(); }) record.validate();
}

// The fields by name, as Python reads them.
template <class Record>
py::dict record_fields(const Record& record) {
  py::dict values;
  Record::visit_fields([&](const char* name, const auto& member) { values[name] = python_value(field_of(record, member)); });
  return values;
}

// The record from keyword values; a TypeError names an unknown field, as a dataclass's would.
template <class Record>
Record record_from(const char* type_name, const py::dict& values) {
  Record record;
  py::ssize_t used = 0;
  Record::visit_fields([&](const char* name, const auto& member) {
    if (!values.contains(name)) return;
    using Field = FieldType<Record, std::remove_cvref_t<decltype(member)>>;
    field_of(record, member) = field_value<Field>(type_name, name, values[name]);
    ++used;
  });
  if (used == static_cast<py::ssize_t>(values.size())) {
    validate(record);
    return record;
  }
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
  Record::visit_fields([&](const char* name, const auto& member) {
    using Field = FieldType<Record, std::remove_cvref_t<decltype(member)>>;
    // A record is a value: its sequences read as tuples, so changing one cannot go unseen; and
    // a change that validate() refuses leaves the record as it was.
    cls.def_property(
        name, [member](const Record& record) { return python_value(field_of(record, member)); },
        [type_name, name, member](Record& record, const py::object& value) {
          Record changed = record;
          field_of(changed, member) = field_value<Field>(type_name, name, value);
          validate(changed);
          record = std::move(changed);
        });
  });
  cls.def("_asdict", &record_fields<Record>, "The fields by name, as keyword construction takes them (as a namedtuple's).");
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
        Record::visit_fields([&](const char*, const auto& member) {
          same = same && same_value(field_of(a, member), field_of(b, member));
        });
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
