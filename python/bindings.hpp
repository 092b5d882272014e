// The parts of the Python module crowddb._core, one translation unit each (pybind11 code is slow
// to compile): the simulation (module.cpp), the queries on arrays (queries.cpp), the SDF
// functions and the error classes (sdf_module.cpp).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <string>

namespace crowddb::python {

using Doubles = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

// A 1-D array argument of n values, or a number (or 1-element array) used for every one of them.
class Broadcast {
 public:
  Broadcast(const Doubles& a, std::size_t n, const char* name) : a_(a), one_(a.size() == 1) {
    if (a.ndim() > 1)
      throw pybind11::value_error(std::string(name) + ": expected a 1-D array or a number");
    if (!one_ && static_cast<std::size_t>(a.size()) != n)
      throw pybind11::value_error(std::string(name) + ": " + std::to_string(a.size()) +
                                  " values for " + std::to_string(n) + " agents (expected " +
                                  std::to_string(n) + " values or one number)");
  }
  double operator[](std::size_t i) const { return a_.data()[one_ ? 0 : i]; }

 private:
  const Doubles& a_;
  bool one_;
};

// The length of a 1-D array argument.
inline std::size_t length_of(const Doubles& a, const char* name) {
  if (a.ndim() != 1) throw pybind11::value_error(std::string(name) + ": expected a 1-D array");
  return static_cast<std::size_t>(a.size());
}

// crowddb.Error and its subclasses InputError (also a ValueError), InvalidRow (an InputError with
// .field), IOError_ (also an OSError), UsageError; crowddb::Error and sdf::Error become them with
// the same one-line messages.
void register_errors(pybind11::module_& m);
void bind_queries(pybind11::module_& m);
void bind_sdf(pybind11::module_& m);

}  // namespace crowddb::python
